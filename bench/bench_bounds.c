/*
 * bench_bounds.c: mlod_rt_bounds (mlod_rt_info(3), issue 12) on packs:
 * what it costs per instance next to mlod_rt_pose and mlod_rt_skin, how
 * tight its box is against the box of the vertices mlod_rt_skin writes,
 * and the bytes its tables add to each resident mesh level.
 *
 *   bench_bounds [-r ROUNDS] [-n INSTANCES] PACK...
 *
 * Per pack: every level resident; INSTANCES instances (default 64) over
 * the clips at times spread over each clip, every layer at level 0 (the
 * costliest); ROUNDS rounds (default 200) of each call on every instance
 * (mlod_rt_bounds, mlod_rt_skin with normals, mlod_rt_pose, and a cull's
 * mlod_rt_bounds then mlod_rt_skin of each instance), timed per round:
 * the median ns per instance and the CPU seconds of all rounds.
 * Under callgrind (valgrind --tool=callgrind), the inclusive instruction
 * counts of the functions over the calls made give the cost per
 * call independent of the load (callgrind_annotate --inclusive=yes).
 * Tightness: each clip at 25 times, at mesh levels 0 and the coarsest
 * (skeleton and motion at the same level, clamped): the box's volume and
 * its largest extent over those of the skinned vertices' box (median and
 * largest), and how often the vertices leave INFO's rest-pose box.
 */
#define _POSIX_C_SOURCE 200809L
#include "bench.h"

#include <float.h>
#include <math.h>
#include <time.h>

#include "rt/mlod_rt.h"

static double cpu_now(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void *read_all(const char *path, size_t *size)
{
	FILE *f = fopen(path, "rb");
	if (!f)
		return NULL;
	fseek(f, 0, SEEK_END);
	long n = ftell(f);
	fseek(f, 0, SEEK_SET);
	void *d = n > 0 ? malloc((size_t)n) : NULL;
	*size = d ? fread(d, 1, (size_t)n, f) : 0;
	fclose(f);
	return d;
}

static void force(mlod_rt_ctx *ctx, const uint32_t *ids, uint32_t n, int level)
{
	mlod_rt_select sel;
	mlod_rt_select_default(&sel);
	sel.force_level = level;
	float *d = calloc(n + 1, sizeof *d);
	mlod_error e;
	if (mlod_rt_update(ctx, &sel, ids, d, n, 0, &e) != MLOD_OK)
		fprintf(stderr, "bench_bounds: update: %s\n", e.message);
	free(d);
}

static int one_pack(const char *path, int rounds, uint32_t ninst)
{
	size_t size;
	void *data = read_all(path, &size);
	mlod_rt_ctx *ctx = NULL;
	mlod_error e = { 0 };
	mlod_rt_config cfg = { 0, ninst, NULL };
	if (!data || mlod_rt_open_memory(data, size, &cfg, &ctx, &e) != MLOD_OK) {
		fprintf(stderr, "bench_bounds: %s: %s\n", path, data ? e.message : "cannot read");
		free(data);
		return -1;
	}
	const uint32_t clips = mlod_rt_clip_count(ctx) ? mlod_rt_clip_count(ctx) : 1;
	for (int layer = 0; layer < MLOD_RT_LAYERS; layer++)
		for (uint32_t it = 0; it < (layer == MLOD_RT_MOTION ? clips : 1u); it++)
			for (uint32_t l = 0; l < mlod_rt_level_count(ctx, (mlod_rt_layer)layer); l++)
				mlod_rt_request(ctx, (mlod_rt_layer)layer, l, it, NULL);
	mlod_rt_stream(ctx, SIZE_MAX, NULL, NULL);
	mlod_rt_character ch;
	mlod_rt_character_get(ctx, &ch, NULL);
	const uint32_t nv = mlod_rt_max_vertex_count(ctx);
	float *pos = malloc(12 * (size_t)nv + 12), *nrm = malloc(12 * (size_t)nv + 12);
	uint32_t *ids = calloc(ninst, sizeof *ids);
	mlod_rt_scratch *s = mlod_rt_scratch_create(ctx);
	if (!pos || !nrm || !ids || !s)
		return -1;
	for (uint32_t i = 0; i < ninst; i++)
		mlod_rt_instance_create(ctx, i % clips,
		                        mlod_rt_clip_duration(ctx, i % clips) * (float)(i / clips) * clips / (float)ninst,
		                        MLOD_RT_LOOP, &ids[i], NULL);
	force(ctx, ids, ninst, 0);
	/* the bound tables' bytes per mesh level: 13 floats per palette entry,
	 * 7 per part, one per morph target, an offset per part and one more */
	const uint32_t P = mlod_rt_palette_size(ctx), parts = mlod_rt_mesh_part_count(ctx, 0);
	uint32_t T = 0;
	for (uint32_t p = 0; p < parts; p++)
		T += mlod_rt_morph_target_count(ctx, p);
	printf("%s: '%s', %u joints, %u palette entries, %u parts, %u morph targets, %u clips; mesh levels %u; "
	       "bound tables %u bytes per resident mesh level",
	       bench_base_name(path), ch.name, mlod_rt_joint_count(ctx), P, parts, T, mlod_rt_clip_count(ctx),
	       mlod_rt_level_count(ctx, MLOD_RT_MESH),
	       mlod_rt_level_count(ctx, MLOD_RT_MESH) ? 4 * (13 * P + 8 * parts + 1 + T) : 0);
	if (mlod_rt_level_count(ctx, MLOD_RT_MESH)) {
		mlod_rt_level_info li;
		mlod_rt_level_info_get(ctx, MLOD_RT_MESH, 0, 0, &li, NULL);
		printf(" (level 0 resident: %zu bytes)", li.bytes);
	}
	printf("\n");
	/* cost */
	const char *names[4] = { "mlod_rt_bounds", "mlod_rt_skin", "mlod_rt_pose", "bounds+skin" };
	double *t = malloc(sizeof(double) * (size_t)rounds);
	for (int op = 0; op < 4; op++) {
		const double c0 = cpu_now();
		for (int r = 0; r < rounds; r++) {
			const double w0 = bench_now();
			for (uint32_t i = 0; i < ninst; i++) {
				float mn[3], mx[3];
				uint32_t n;
				if (op == 0)
					mlod_rt_bounds(ctx, s, ids[i], mn, mx, NULL);
				else if (op == 1)
					mlod_rt_skin(ctx, s, ids[i], pos, 12, nrm, 12, nv, &n, NULL);
				else if (op == 2)
					mlod_rt_pose(ctx, s, ids[i], NULL, NULL, NULL, NULL);
				else { /* a cull: the box, then the skin of the same instance */
					mlod_rt_bounds(ctx, s, ids[i], mn, mx, NULL);
					mlod_rt_skin(ctx, s, ids[i], pos, 12, nrm, 12, nv, &n, NULL);
				}
			}
			t[r] = (bench_now() - w0) / ninst;
		}
		const double cpu = cpu_now() - c0;
		printf("  %-15s %9.0f ns per instance (median of %d rounds of %u; CPU %.3f s in all)\n", names[op],
		       1e9 * bench_median(t, rounds), rounds, ninst, cpu);
	}
	free(t);
	/* tightness */
	const uint32_t LM = mlod_rt_level_count(ctx, MLOD_RT_MESH);
	for (uint32_t pass = 0; LM && pass < 2; pass++) {
		const int level = pass ? (int)LM - 1 : 0;
		force(ctx, ids, 1, level);
		enum { TIMES = 25 };
		double *vr = malloc(sizeof(double) * clips * TIMES), *er = malloc(sizeof(double) * clips * TIMES);
		int n = 0, outside_rest = 0;
		for (uint32_t c = 0; c < clips; c++)
			for (int k = 0; k < TIMES; k++) {
				mlod_rt_instance_set(ctx, ids[0], c, mlod_rt_clip_duration(ctx, c) * (float)k / (TIMES - 1), 0,
				                     NULL);
				float mn[3], mx[3];
				uint32_t cnt = 0;
				mlod_rt_bounds(ctx, s, ids[0], mn, mx, NULL);
				mlod_rt_skin(ctx, s, ids[0], pos, 12, NULL, 12, nv, &cnt, NULL);
				double lo[3] = { INFINITY, INFINITY, INFINITY }, hi[3] = { -INFINITY, -INFINITY, -INFINITY };
				int out = 0;
				for (uint32_t v = 0; v < cnt; v++)
					for (int a = 0; a < 3; a++) {
						lo[a] = fmin(lo[a], pos[3 * v + a]), hi[a] = fmax(hi[a], pos[3 * v + a]);
						out |= pos[3 * v + a] < mn[a] || pos[3 * v + a] > mx[a];
					}
				if (out)
					fprintf(stderr, "bench_bounds: %s: a vertex outside its box\n", path);
				double vb = 1, vs = 1, emax = 0;
				for (int a = 0; a < 3; a++) {
					vb *= (double)mx[a] - mn[a], vs *= hi[a] - lo[a];
					emax = fmax(emax, ((double)mx[a] - mn[a]) / fmax(hi[a] - lo[a], 1e-30));
					outside_rest += a == 0 && (lo[0] < ch.bounds_min[0] || lo[1] < ch.bounds_min[1] ||
					                           lo[2] < ch.bounds_min[2] || hi[0] > ch.bounds_max[0] ||
					                           hi[1] > ch.bounds_max[1] || hi[2] > ch.bounds_max[2]);
				}
				vr[n] = vb / fmax(vs, 1e-30), er[n] = emax, n++;
			}
		const double vmed = bench_median(vr, n), vmax = vr[n - 1], emed = bench_median(er, n), emx = er[n - 1];
		printf("  mesh level %d: box volume / skinned vertices' box: median %.3f, max %.3f; largest extent ratio: "
		       "median %.3f, max %.3f (%d poses); vertices outside INFO's rest box in %d of them\n",
		       level, vmed, vmax, emed, emx, n, outside_rest);
		free(vr), free(er);
	}
	mlod_rt_scratch_destroy(ctx, s);
	mlod_rt_close(ctx);
	free(pos), free(nrm), free(ids), free(data);
	return 0;
}

int main(int argc, char **argv)
{
	int rounds = 200, ninst = 64, i = 1, rc = 0;
	for (; i + 1 < argc && argv[i][0] == '-'; i += 2) {
		if (strcmp(argv[i], "-r") == 0)
			rounds = atoi(argv[i + 1]);
		else if (strcmp(argv[i], "-n") == 0)
			ninst = atoi(argv[i + 1]);
		else
			break;
	}
	if (i >= argc || rounds < 1 || ninst < 1) {
		fprintf(stderr, "usage: bench_bounds [-r ROUNDS] [-n INSTANCES] PACK...\n");
		return 2;
	}
	for (; i < argc; i++)
		rc |= one_pack(argv[i], rounds, (uint32_t)ninst) != 0;
	return rc;
}
