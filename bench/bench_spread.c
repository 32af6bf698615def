/*
 * bench_spread.c: how much the posed-error comparison of bench_mesh
 * quality depends on its pose seed and its sampling density (issue 13).
 *
 *   bench_spread [-s SEEDS] [-d DENSITIES] FILE [GLTFPACK50 GLTFPACK25 GLTFPACK10]
 *
 * Levels at 50/25/10% of the triangles: mlod's default chain (the
 * library's mlod_mesh_levels with mlod-bgm's defaults: posed cost,
 * character budget, ratios MLOD_MESH_RATIOS_DEFAULT), meshopt_simplify on
 * each primitive from the full mesh (no error limit), and gltfpack's
 * files when given. Each is measured against the full character over
 * SEEDS pose seeds (default 5: 2008, 2009, ...) of 8 random poses each (up
 * to 40 degrees per joint, as bench_mesh quality and mlod-bgm), at each of
 * the sampling densities D (default 1,4,16): both posed meshes are split
 * into D triangles per triangle (midpoint subdivision, log4 D times; the
 * surfaces are unchanged) before mlod_surface_deviation, whose samples are
 * the used vertices and the triangle centroids. D = 1 is what
 * mlod_posed_error measures (checked: the program fails when they differ);
 * D = 4 samples each input triangle at its 3 corners, 3 edge midpoints
 * and 4 centroids, close to the "4 samples per triangle plus every
 * vertex". The mean error is the mean over a seed's poses of the mean;
 * the Hausdorff the largest over its poses. Prints, per level and
 * density, each method's mean over seeds with the min-max over seeds, and
 * the ratio mlod / peer (computed per seed) with its min-max.
 */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <meshoptimizer.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench.h"
#include "mlod.h"

#define MAX_SEEDS 16
#define MAX_DENS 4
#define LEVELS 3
#define METHODS 3 /* mlod, meshopt_simplify, gltfpack */

static const double ratios[] = {MLOD_MESH_RATIOS_DEFAULT}; /* the first LEVELS measured */
static const char *method_name[METHODS] = {"mlod", "meshopt_simplify", "gltfpack"};

static void die(const char *path, const char *what)
{
	fprintf(stderr, "bench_spread: %s: %s\n", path, what);
	exit(2);
}

/* ---------------------------------------------------------------- */
/* meshopt_simplify levels                                           */
/* ---------------------------------------------------------------- */

/* A view of c whose instance i uses its own copy of c's mesh, with the
 * primitives meshopt_simplify changed owning their indices. */
struct mo_level {
	mlod_character view;
	mlod_mesh *meshes;
	unsigned char **owned;
};

static void mo_level_free(struct mo_level *L)
{
	for (int i = 0; i < L->view.instance_count; i++) {
		for (int p = 0; p < L->meshes[i].primitive_count; p++)
			if (L->owned[i][p])
				free(L->meshes[i].primitives[p].indices);
		free(L->meshes[i].primitives);
		free(L->owned[i]);
	}
	free(L->meshes);
	free(L->owned);
	free(L->view.instances);
}

/* meshopt_simplify on each primitive of an instance on a joint or skin,
 * from the full mesh (as gltfpack does), positions only, no error limit,
 * as bench_mesh quality does. */
static void mo_level_make(const mlod_character *c, double ratio, struct mo_level *L)
{
	int n = c->instance_count;
	L->view = *c;
	L->meshes = calloc((size_t)n + 1, sizeof *L->meshes);
	L->owned = calloc((size_t)n + 1, sizeof *L->owned);
	L->view.instances = calloc((size_t)n + 1, sizeof *L->view.instances);
	if (!L->meshes || !L->owned || !L->view.instances)
		die("meshopt", "out of memory");
	L->view.meshes = L->meshes;
	L->view.mesh_count = n;
	for (int i = 0; i < n; i++) {
		const mlod_mesh *m = &c->meshes[c->instances[i].mesh];
		L->view.instances[i] = c->instances[i];
		L->view.instances[i].mesh = i;
		L->meshes[i] = *m;
		L->meshes[i].primitives = calloc((size_t)m->primitive_count + 1, sizeof(mlod_primitive));
		L->owned[i] = calloc((size_t)m->primitive_count + 1, 1);
		if (!L->meshes[i].primitives || !L->owned[i])
			die("meshopt", "out of memory");
		for (int p = 0; p < m->primitive_count; p++) {
			const mlod_primitive *pr = &m->primitives[p];
			L->meshes[i].primitives[p] = *pr;
			int T = bench_triangles(pr);
			if ((c->instances[i].skin < 0 && c->instances[i].joint < 0) || T < 4)
				continue;
			uint32_t *idx = pr->indices, *own = NULL;
			if (pr->index_count == 0) {
				own = idx = malloc(sizeof(uint32_t) * (size_t)(3 * T));
				if (!own)
					die("meshopt", "out of memory");
				for (int v = 0; v < 3 * T; v++)
					idx[v] = (uint32_t)v;
			}
			uint32_t *dst = malloc(sizeof(uint32_t) * (size_t)(3 * T));
			if (!dst)
				die("meshopt", "out of memory");
			float err = 0.0f;
			size_t got = meshopt_simplify(dst, idx, (size_t)(3 * T), pr->positions, (size_t)pr->vertex_count,
			                              3 * sizeof(float), (size_t)floor(ratio * T) * 3, 1.0f, 0, &err);
			L->meshes[i].primitives[p].indices = dst;
			L->meshes[i].primitives[p].index_count = (int)got;
			L->owned[i][p] = 1;
			free(own);
		}
	}
}

/* ---------------------------------------------------------------- */
/* Sampling density: midpoint subdivision of a posed mesh            */
/* ---------------------------------------------------------------- */

struct edge {
	uint64_t key;
	int slot; /* 3 * triangle + corner */
};

static int edge_cmp(const void *a, const void *b)
{
	uint64_t x = ((const struct edge *)a)->key, y = ((const struct edge *)b)->key;
	return (x > y) - (x < y);
}

/* out = in with every triangle split into 4 at its edge midpoints (shared
 * edges share their midpoint): the same surface, 4 times the triangles. */
static void subdivide(const mlod_posed *in, mlod_posed *out)
{
	long T = in->triangle_count;
	struct edge *e = malloc(sizeof *e * (size_t)(3 * T + 1));
	int *mid = malloc(sizeof *mid * (size_t)(3 * T + 1));
	if (!e || !mid)
		die("subdivide", "out of memory");
	for (long t = 0; t < T; t++)
		for (int k = 0; k < 3; k++) {
			uint32_t a = in->indices[3 * t + k], b = in->indices[3 * t + (k + 1) % 3];
			uint32_t lo = a < b ? a : b, hi = a < b ? b : a;
			e[3 * t + k].key = (uint64_t)lo << 32 | hi;
			e[3 * t + k].slot = (int)(3 * t + k);
		}
	qsort(e, (size_t)(3 * T), sizeof *e, edge_cmp);
	long unique = 0;
	for (long i = 0; i < 3 * T; i++) {
		if (i == 0 || e[i].key != e[i - 1].key)
			unique++;
		mid[e[i].slot] = in->vertex_count + (int)(unique - 1);
	}
	mlod_posed o = {0};
	o.vertex_count = in->vertex_count + (int)unique;
	o.triangle_count = (int)(4 * T);
	o.positions = malloc(sizeof(float) * 3 * (size_t)o.vertex_count);
	o.indices = malloc(sizeof(uint32_t) * 3 * (size_t)o.triangle_count);
	if (!o.positions || !o.indices)
		die("subdivide", "out of memory");
	memcpy(o.positions, in->positions, sizeof(float) * 3 * (size_t)in->vertex_count);
	for (long i = 0; i < 3 * T; i++) {
		int m = mid[e[i].slot];
		uint32_t a = (uint32_t)(e[i].key >> 32), b = (uint32_t)(e[i].key & 0xffffffffu);
		for (int x = 0; x < 3; x++)
			o.positions[3 * (size_t)m + x] = 0.5f * (in->positions[3 * (size_t)a + x] + in->positions[3 * (size_t)b + x]);
	}
	for (long t = 0; t < T; t++) {
		uint32_t v0 = in->indices[3 * t], v1 = in->indices[3 * t + 1], v2 = in->indices[3 * t + 2];
		uint32_t m01 = (uint32_t)mid[3 * t], m12 = (uint32_t)mid[3 * t + 1], m20 = (uint32_t)mid[3 * t + 2];
		uint32_t q[12] = {v0, m01, m20, m01, v1, m12, m20, m12, v2, m01, m12, m20};
		memcpy(o.indices + 12 * t, q, sizeof q);
	}
	free(e);
	free(mid);
	*out = o;
}

/* The mesh at density d (1, 4, 16, ...): a fresh copy subdivided log4 d times. */
static void densify(const mlod_posed *in, int d, mlod_posed *out)
{
	mlod_posed cur = {0};
	cur.vertex_count = in->vertex_count;
	cur.triangle_count = in->triangle_count;
	cur.positions = malloc(sizeof(float) * 3 * (size_t)in->vertex_count + 1);
	cur.indices = malloc(sizeof(uint32_t) * 3 * (size_t)in->triangle_count + 1);
	if (!cur.positions || !cur.indices)
		die("densify", "out of memory");
	memcpy(cur.positions, in->positions, sizeof(float) * 3 * (size_t)in->vertex_count);
	memcpy(cur.indices, in->indices, sizeof(uint32_t) * 3 * (size_t)in->triangle_count);
	for (int k = 1; k < d; k *= 4) {
		mlod_posed next;
		subdivide(&cur, &next);
		mlod_posed_free(&cur);
		cur = next;
	}
	*out = cur;
}

/* ---------------------------------------------------------------- */
/* Measuring                                                         */
/* ---------------------------------------------------------------- */

/* Error of level against full over the poses at each density: mean over
 * poses of the mean, largest max. Returns -1 on failure. */
static int measure(const mlod_character *full, const mlod_character *level, const int *map,
                   const mlod_pose_set *poses, const mlod_posed *full_posed_dense, const int *dens, int nd,
                   mlod_deviation *out)
{
	int J = level->skeleton.joint_count;
	mlod_mat4 *world = malloc(sizeof *world * (size_t)(J + 1));
	if (!world)
		die("measure", "out of memory");
	mlod_posed b = {0};
	for (int d = 0; d < nd; d++)
		memset(&out[d], 0, sizeof out[d]);
	int r = 0;
	for (int k = 0; k < poses->count && r == 0; k++) {
		const mlod_mat4 *w = poses->world + (size_t)k * (size_t)poses->joint_count;
		if (map)
			for (int j = 0; j < J; j++)
				world[j] = w[map[j]];
		mlod_error err = {0};
		if (mlod_pose_character(level, map ? world : w, &b, &err) != MLOD_OK) {
			fprintf(stderr, "bench_spread: posing a level: %s\n", err.message);
			r = -1;
			break;
		}
		for (int d = 0; d < nd; d++) {
			mlod_posed bd;
			densify(&b, dens[d], &bd);
			mlod_deviation dv;
			mlod_error err = {0};
			if (mlod_surface_deviation(&full_posed_dense[(size_t)k * nd + d], &bd, &dv, &err) != MLOD_OK) {
				fprintf(stderr, "bench_spread: measuring at D = %d: %s\n", dens[d], err.message);
				r = -1;
			}
			mlod_posed_free(&bd);
			if (r)
				break;
			out[d].mean += dv.mean / poses->count;
			out[d].max = dv.max > out[d].max ? dv.max : out[d].max;
		}
	}
	mlod_posed_free(&b);
	free(world);
	(void)full;
	return r;
}

static void usage(void)
{
	fprintf(stderr, "usage: bench_spread [-s SEEDS] [-d D,D,...] FILE [GLTFPACK50 GLTFPACK25 GLTFPACK10]\n");
	exit(1);
}

int main(int argc, char **argv)
{
	int nseeds = 5, dens[MAX_DENS] = {1, 4, 16}, nd = 3, a = 1;
	for (; a < argc && argv[a][0] == '-'; a++) {
		if (strcmp(argv[a], "-s") == 0 && a + 1 < argc) {
			nseeds = atoi(argv[++a]);
			if (nseeds < 1 || nseeds > MAX_SEEDS)
				usage();
		} else if (strcmp(argv[a], "-d") == 0 && a + 1 < argc) {
			nd = 0;
			for (char *s = argv[++a]; *s && nd < MAX_DENS;) {
				char *end;
				long v = strtol(s, &end, 10);
				if (end == s || !(v == 1 || v == 4 || v == 16 || v == 64))
					usage();
				dens[nd++] = (int)v;
				s = *end == ',' ? end + 1 : end;
				if (*end && *end != ',')
					usage();
			}
			if (nd == 0)
				usage();
		} else
			usage();
	}
	if (argc - a != 1 && argc - a != 4)
		usage();
	const char *path = argv[a];
	mlod_character c;
	if (bench_load("bench_spread", path, &c, NULL) != 0)
		return 2;
	int T = bench_character_triangles(&c);
	if (T == 0)
		die(path, "no triangles");

	/* The levels: lv[method][level] (NULL: none). */
	const mlod_character *lv[METHODS][LEVELS] = {{0}};
	int tris[METHODS][LEVELS] = {{0}};
	int *maps[METHODS][LEVELS] = {{0}};
	mlod_bgm_options opt = {0};
	mlod_mesh_budget budget = MLOD_BUDGET_DEFAULT;
	mlod_mesh_resolve(&opt, &budget);
	mlod_mesh_levels ml;
	mlod_error err = {0};
	int nr = (int)(sizeof ratios / sizeof *ratios);
	if (mlod_mesh_levels_init(&ml, &c, &opt, budget, ratios[nr - 1], &err) != MLOD_OK ||
	    mlod_mesh_levels_by_ratio(&ml, ratios, nr, &err) != MLOD_OK)
		die(path, err.message);
	for (int k = 0; k < LEVELS && k < ml.count; k++)
		lv[0][k] = &ml.levels[k].view, tris[0][k] = ml.levels[k].triangles;
	struct mo_level mo[LEVELS];
	for (int k = 0; k < LEVELS; k++) {
		mo_level_make(&c, ratios[k], &mo[k]);
		lv[1][k] = &mo[k].view, tris[1][k] = bench_character_triangles(&mo[k].view);
	}
	mlod_character gp[LEVELS];
	int gp_ok[LEVELS] = {0};
	for (int k = 0; k < LEVELS && argc - a == 4; k++) {
		if (bench_load("bench_spread", argv[a + 1 + k], &gp[k], NULL) != 0)
			continue;
		if (!(maps[2][k] = bench_joint_map(&c, &gp[k]))) {
			fprintf(stderr, "bench_spread: %s: a joint is not in %s\n", argv[a + 1 + k], path);
			mlod_character_free(&gp[k]);
			continue;
		}
		gp_ok[k] = 1;
		lv[2][k] = &gp[k], tris[2][k] = bench_character_triangles(&gp[k]);
	}

	/* Check: at density 1 this is mlod_posed_error, to the bit. */
	{
		mlod_pose_set ps = {0};
		if (mlod_pose_set_make(&c, 0, 0, MLOD_MESH_RANDOM_POSES, MLOD_MESH_MEASURE_SEED, MLOD_MESH_RANDOM_ANGLE, &ps,
		                       &err) != MLOD_OK)
			die(path, err.message);
		mlod_posed *fp = calloc((size_t)ps.count + 1, sizeof *fp);
		mlod_posed full_one = {0};
		for (int k = 0; k < ps.count; k++) {
			if (mlod_pose_character(&c, ps.world + (size_t)k * (size_t)ps.joint_count, &full_one, &err) != MLOD_OK)
				die(path, err.message);
			densify(&full_one, 1, &fp[k]);
		}
		mlod_deviation mine, lib;
		int one = 1;
		if (measure(&c, lv[0][1], NULL, &ps, fp, &one, 1, &mine) != 0 ||
		    mlod_posed_error(&c, lv[0][1], &ps, &lib, &err) != MLOD_OK)
			die(path, "measuring the check failed");
		if (mine.mean != lib.mean || mine.max != lib.max) {
			fprintf(stderr, "bench_spread: %s: density 1 (%.17g, %.17g) is not mlod_posed_error (%.17g, %.17g)\n", path,
			        mine.mean, mine.max, lib.mean, lib.max);
			return 2;
		}
		for (int k = 0; k < ps.count; k++)
			mlod_posed_free(&fp[k]);
		free(fp);
		mlod_posed_free(&full_one);
		mlod_pose_set_free(&ps);
	}

	/* res[method][level][density][seed] */
	static mlod_deviation res[METHODS][LEVELS][MAX_DENS][MAX_SEEDS];
	int failed[METHODS][LEVELS] = {{0}};
	for (int s = 0; s < nseeds; s++) {
		mlod_pose_set ps = {0};
		if (mlod_pose_set_make(&c, 0, 0, MLOD_MESH_RANDOM_POSES, (uint64_t)(MLOD_MESH_MEASURE_SEED + s),
		                       MLOD_MESH_RANDOM_ANGLE, &ps, &err) != MLOD_OK)
			die(path, err.message);
		mlod_posed *fp = calloc((size_t)ps.count * (size_t)nd + 1, sizeof *fp);
		mlod_posed one = {0};
		if (!fp)
			die(path, "out of memory");
		for (int k = 0; k < ps.count; k++) {
			if (mlod_pose_character(&c, ps.world + (size_t)k * (size_t)ps.joint_count, &one, &err) != MLOD_OK)
				die(path, err.message);
			for (int d = 0; d < nd; d++)
				densify(&one, dens[d], &fp[(size_t)k * nd + d]);
		}
		for (int m = 0; m < METHODS; m++)
			for (int k = 0; k < LEVELS; k++) {
				if (!lv[m][k])
					continue;
				mlod_deviation out[MAX_DENS];
				if (failed[m][k])
					continue;
				if (measure(&c, lv[m][k], maps[m][k], &ps, fp, dens, nd, out) != 0) {
					/* as bench_mesh quality: the cell is left out ("-") */
					fprintf(stderr, "bench_spread: %s: measuring %s at %g failed\n", path, method_name[m], ratios[k]);
					failed[m][k] = 1;
					continue;
				}
				for (int d = 0; d < nd; d++)
					res[m][k][d][s] = out[d];
			}
		for (size_t k = 0; k < (size_t)ps.count * (size_t)nd; k++)
			mlod_posed_free(&fp[k]);
		free(fp);
		mlod_posed_free(&one);
		mlod_pose_set_free(&ps);
	}

	printf("\n**%s, %d triangles: %d seeds (%d..%d) x %d random poses, up to 40 degrees per joint** (%% of the diagonal; "
	       "mean over seeds [min-max over seeds])\n\n",
	       bench_base_name(path), T, nseeds, MLOD_MESH_MEASURE_SEED, MLOD_MESH_MEASURE_SEED + nseeds - 1, MLOD_MESH_RANDOM_POSES);
	printf("| level | D | method | tris | mean error | Hausdorff | mlod/peer mean | mlod/peer Hausdorff | mean verdict |\n"
	       "|---|---:|---|---:|---|---|---|---|---|\n");
	for (int k = 0; k < LEVELS; k++)
		for (int d = 0; d < nd; d++)
			for (int m = 0; m < METHODS; m++) {
				if (!lv[m][k])
					continue;
				if (failed[m][k]) {
					printf("| %d%% | %d | %s | %d | - | - | - | - | not measured (mlod_surface_deviation failed) |\n",
					       (int)(100 * ratios[k] + 0.5), dens[d], method_name[m], tris[m][k]);
					continue;
				}
				double v[2][3]; /* [mean|max][avg,min,max] */
				double q[2][3];
				for (int f = 0; f < 2; f++) {
					v[f][0] = 0.0, v[f][1] = HUGE_VAL, v[f][2] = -HUGE_VAL;
					q[f][0] = 0.0, q[f][1] = HUGE_VAL, q[f][2] = -HUGE_VAL;
					for (int s = 0; s < nseeds; s++) {
						double x = f ? res[m][k][d][s].max : res[m][k][d][s].mean;
						double y = f ? res[0][k][d][s].max : res[0][k][d][s].mean;
						v[f][0] += x / nseeds;
						v[f][1] = fmin(v[f][1], x), v[f][2] = fmax(v[f][2], x);
						double ratio = y / fmax(x, 1e-12);
						q[f][0] += ratio / nseeds;
						q[f][1] = fmin(q[f][1], ratio), q[f][2] = fmax(q[f][2], ratio);
					}
				}
				printf("| %d%% | %d | %s | %d | %.4f [%.4f-%.4f] | %.3f [%.3f-%.3f]", (int)(100 * ratios[k] + 0.5),
				       dens[d], method_name[m], tris[m][k], v[0][0], v[0][1], v[0][2], v[1][0], v[1][1], v[1][2]);
				if (m == 0)
					printf(" | | | |\n");
				else if (failed[0][k] || fabs((double)tris[0][k] - tris[m][k]) > 0.01 * tris[m][k] + 1)
					printf(" | - | - | unequal triangle counts: no ratio (as bench_mesh) |\n");
				else {
					/* mlod wins (loses) beyond the spread when every seed's ratio is
					 * below (above) 1; a tie when the seeds' ratios straddle 1. */
					const char *verdict = q[0][2] < 1.0 ? "mlod better, every seed"
					                      : q[0][1] > 1.0 ? "mlod worse, every seed"
					                                      : "tie (seeds straddle 1)";
					printf(" | %.3f [%.3f-%.3f] | %.3f [%.3f-%.3f] | %s |\n", q[0][0], q[0][1], q[0][2], q[1][0],
					       q[1][1], q[1][2], verdict);
				}
			}
	printf("\nD: triangles per input triangle after midpoint subdivision of both posed meshes before measuring (D = 1 is "
	       "mlod_posed_error: used vertices and triangle centroids, both directions). Ratios are computed per seed and "
	       "their average and min-max given.\n");

	for (int k = 0; k < LEVELS; k++) {
		mo_level_free(&mo[k]);
		free(maps[2][k]);
		if (gp_ok[k])
			mlod_character_free(&gp[k]);
	}
	mlod_mesh_levels_free(&ml);
	mlod_character_free(&c);
	return 0;
}
