/*
 * bench/crowd (built as build/<config>/bench/crowd; `make demo` and
 * bench/crowd.sh run it): the crowd benchmark of the runtime (paper 4.4, Figures 15
 * and 16) on any .mlod pack.
 *
 * For each N (1, 10, 50, 250, 1000, 10000 by default) it places N
 * instances at distances in [near, far] (2 to 200 m), each with
 * its own clip and time offset, walking towards or away from the camera,
 * and runs a few simulated seconds twice in one run: every instance at
 * full detail (level 0 of every layer), then with LoD by distance. It
 * measures the CPU time of one frame: the update (selection), motion
 * sampling, pose and linear blend skinning of every instance into one
 * buffer, on one core. Streaming happens between frames, outside the
 * measured time (its cost is printed apart). It prints per N: ms per frame
 * in each mode, the speed-up, the instances per mesh level (and skeleton
 * and motion level) at the last frame, and the resident bytes.
 *
 * Spread: by default the instances stand evenly over the ground around
 * the camera, the ring between near and far (so the density of distances
 * grows with the distance, as in a crowd filling a square: instance i of n
 * at d = sqrt(near^2 + (i + 1/2)/n (far^2 - near^2))); --spread line puts
 * them evenly along one line instead (d = near + (i + 1/2)/n (far - near)),
 * which gives the near levels many more instances.
 *
 * It also measures the runtime's skinning kernel against the plain scalar
 * loop, in vertices per second on one core, on the pack's finest mesh.
 *
 * Uses only the runtime (mlod_rt.h) and its pack reader (mlod_pack.h).
 */
#define _GNU_SOURCE /* getopt_long, clock_gettime */

#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "rt/mlod_rt.h"

static const char usage_text[] =
	"usage: crowd [options] PACK\n"
	"\n"
	"Runs crowds of N instances of the character in PACK (.mlod) at full detail\n"
	"and with level of detail by distance, and prints the CPU frame time of\n"
	"motion sampling, pose and skinning for each, on one core.\n"
	"\n"
	"options:\n"
	"  -n, --counts LIST     crowd sizes (default 1,10,50,250,1000,10000)\n"
	"  -s, --seconds S       simulated seconds per size and mode (default 2)\n"
	"      --fps F           simulated frames per second (default 30)\n"
	"      --max-wall S      stop a measurement after S seconds of CPU time,\n"
	"                        keeping the frames done (default 10)\n"
	"  -b, --budget BYTES    the runtime's memory budget (K, M suffixes; default\n"
	"                        none)\n"
	"      --near D, --far D the distance range in scene units (default 2, 200)\n"
	"      --spread HOW      ground (default: evenly over the ground between\n"
	"                        near and far) or line (evenly over the distances)\n"
	"      --mode MODE       alpha (the paper's, default), pixels or toc\n"
	"      --interval TS,TE  the alpha interval of every layer (default 0,1)\n"
	"      --hysteresis H    relative hysteresis (default 0.1)\n"
	"      --no-skin-bench   skip the kernel measurement\n"
	"  -h, --help            show this help\n"
	"\n"
	"exit status: 0 success, 1 usage, 2 bad input, 3 unsupported input\n";

static const char *tool = "crowd";

static _Noreturn void die(int code, const char *fmt, const char *msg)
{
	fprintf(stderr, "%s: ", tool);
	fprintf(stderr, fmt, msg);
	fputc('\n', stderr);
	exit(code);
}

static int exit_code(mlod_result r)
{
	return r == MLOD_ERR_UNSUPPORTED ? 3 : r == MLOD_ERR_INVALID_ARG ? 1 : 2;
}

static double cpu_seconds(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* A deterministic generator (xorshift32). */
static uint32_t rng = 2463534242u;
static float frand(void)
{
	rng ^= rng << 13;
	rng ^= rng >> 17;
	rng ^= rng << 5;
	return (float)(rng >> 8) / 16777216.0f;
}

static size_t parse_bytes(const char *s)
{
	char *end;
	double v = strtod(s, &end);
	if (end == s || v < 0)
		die(1, "bad byte count '%s'", s);
	if (*end == 'K' || *end == 'k')
		v *= 1024, end++;
	else if (*end == 'M' || *end == 'm')
		v *= 1024 * 1024, end++;
	else if (*end == 'G' || *end == 'g')
		v *= 1024.0 * 1024 * 1024, end++;
	if (*end)
		die(1, "bad byte count '%s'", s);
	return (size_t)v;
}

static double parse_num(const char *s, const char *what)
{
	char *end;
	double v = strtod(s, &end);
	if (end == s || *end || !isfinite(v))
		die(1, "bad %s", what);
	return v;
}

/* ---------------------------------------------------------------- */
/* Skinning kernel vs scalar                                         */
/* ---------------------------------------------------------------- */

static void skin_bench(const char *path)
{
	FILE *f = fopen(path, "rb");
	if (!f)
		return;
	fseek(f, 0, SEEK_END);
	long size = ftell(f);
	fseek(f, 0, SEEK_SET);
	void *data = malloc((size_t)size);
	if (!data || fread(data, 1, (size_t)size, f) != (size_t)size) {
		fclose(f);
		free(data);
		return;
	}
	fclose(f);
	mlod_pack p;
	mlod_pack_skeleton sk = { 0 };
	mlod_pack_mesh m = { 0 };
	mlod_error e;
	int c = -1;
	if (mlod_pack_open(data, (size_t)size, &p, &e) == MLOD_OK) {
		c = mlod_pack_find(&p, MLOD_CHUNK_MESH, 0, 0);
		if (c < 0 || mlod_pack_decode_skeleton(&p, data, (size_t)size, &sk, &e) != MLOD_OK ||
		    mlod_pack_decode_mesh(&p, (uint32_t)c, data, (size_t)size, &sk, &m, &e) != MLOD_OK)
			c = -1;
		mlod_pack_close(&p);
	}
	size_t n = 0;
	uint32_t pal = 1;
	for (uint32_t k = 0; k < sk.skin_count; k++)
		if (sk.skins[k].joint_count > pal)
			pal = sk.skins[k].joint_count;
	for (uint32_t i = 0; c >= 0 && i < m.part_count; i++)
		if (m.parts[i].joints)
			n += m.parts[i].rec.vertex_count;
	if (n == 0) {
		printf("skinning kernel: no skinned part in mesh level 0\n");
	} else {
		/* The finest level's skinned vertices, gathered, under a palette of
		 * small random rigid motions. */
		float *pos = malloc(n * 12), *nrm = malloc(n * 12), *w = malloc(n * 16), *out = malloc(n * 12),
		      *outn = malloc(n * 12), *palette = malloc((size_t)pal * 64);
		uint16_t *j = malloc(n * 8);
		size_t v = 0;
		for (uint32_t i = 0; i < m.part_count; i++) {
			const mlod_pack_part *q = &m.parts[i];
			if (!q->joints)
				continue;
			size_t k = q->rec.vertex_count;
			memcpy(pos + 3 * v, q->positions, k * 12);
			if (q->normals)
				memcpy(nrm + 3 * v, q->normals, k * 12);
			else
				for (size_t t = 0; t < 3 * k; t++)
					nrm[3 * v + t] = t % 3 == 1;
			memcpy(j + 4 * v, q->joints, k * 8);
			memcpy(w + 4 * v, q->weights, k * 16);
			v += k;
		}
		for (uint32_t k = 0; k < pal; k++) {
			mlod_trs t = { { frand(), frand(), frand() },
			               mlod_quat_normalize((mlod_quat){ frand() - 0.5f, frand() - 0.5f, frand() - 0.5f, 2 }),
			               { 1, 1, 1 } };
			mlod_mat4 M = mlod_mat4_from_trs(&t);
			memcpy(palette + 16 * k, M.m, 64);
		}
		double rate[2];
		for (int which = 0; which < 2; which++) {
			double best = 1e30;
			for (int rep = 0; rep < 5; rep++) {
				int iters = 0;
				double t0 = cpu_seconds(), t1;
				do {
					if (which == 0)
						mlod_rt_skin_lbs(n, pos, nrm, j, w, palette, out, 12, outn, 12);
					else
						mlod_rt_skin_lbs_scalar(n, pos, nrm, j, w, palette, out, 12, outn, 12);
					iters++;
					t1 = cpu_seconds();
				} while (t1 - t0 < 0.1);
				if ((t1 - t0) / iters < best)
					best = (t1 - t0) / iters;
			}
			rate[which] = (double)n / best;
		}
		printf("skinning kernel (positions and normals, %zu vertices of mesh level 0, one core):\n"
		       "  runtime loop %.1f Mvertices/s, plain scalar loop %.1f Mvertices/s: %.2fx\n",
		       n, rate[0] / 1e6, rate[1] / 1e6, rate[0] / rate[1]);
		free(pos), free(nrm), free(w), free(out), free(outn), free(palette), free(j);
	}
	mlod_pack_mesh_free(&m);
	mlod_pack_skeleton_free(&sk);
	free(data);
}

/* ---------------------------------------------------------------- */
/* The crowd                                                         */
/* ---------------------------------------------------------------- */

typedef struct crowd {
	mlod_rt_ctx *ctx;
	mlod_rt_scratch *scratch;
	uint32_t *ids;
	float *dist, *speed;
	float *buf;
	uint32_t cap;
	uint32_t n;
} crowd;

static void grow(crowd *c)
{
	uint32_t need = mlod_rt_max_vertex_count(c->ctx);
	if (need <= c->cap)
		return;
	free(c->buf);
	c->buf = malloc((size_t)need * 24);
	if (!c->buf)
		die(2, "%s", "out of memory");
	c->cap = need;
}

static void walk(crowd *c, float dt, float near, float far)
{
	for (uint32_t i = 0; i < c->n; i++) {
		c->dist[i] += c->speed[i] * dt;
		if (c->dist[i] < near)
			c->dist[i] = 2 * near - c->dist[i], c->speed[i] = -c->speed[i];
		if (c->dist[i] > far)
			c->dist[i] = 2 * far - c->dist[i], c->speed[i] = -c->speed[i];
	}
}

/* One measured frame: update, then pose and skin every instance. */
static double frame(crowd *c, const mlod_rt_select *sel, float dt, uint64_t *vertices)
{
	mlod_error e;
	double t0 = cpu_seconds();
	if (mlod_rt_update(c->ctx, sel, c->ids, c->dist, c->n, dt, &e) != MLOD_OK)
		die(2, "%s", e.message);
	for (uint32_t i = 0; i < c->n; i++) {
		uint32_t nv = 0;
		mlod_result r = mlod_rt_skin(c->ctx, c->scratch, c->ids[i], c->buf, 12, c->buf + 3 * (size_t)c->cap, 12,
		                             c->cap, &nv, &e);
		if (r == MLOD_ERR_LIMIT) { /* a larger level arrived: not in the measured time */
			t0 -= cpu_seconds();
			grow(c);
			t0 += cpu_seconds();
			r = mlod_rt_skin(c->ctx, c->scratch, c->ids[i], c->buf, 12, c->buf + 3 * (size_t)c->cap, 12, c->cap,
			                 &nv, &e);
		}
		if (r != MLOD_OK)
			die(2, "%s", e.message);
		*vertices += nv;
	}
	return cpu_seconds() - t0;
}

/* Streams until nothing wanted is pending (or nothing more fits). */
static double settle(crowd *c, const mlod_rt_select *sel)
{
	mlod_error e;
	double t = 0;
	for (int k = 0; k < 64; k++) {
		if (mlod_rt_update(c->ctx, sel, c->ids, c->dist, c->n, 0.0f, &e) != MLOD_OK)
			die(2, "%s", e.message);
		uint32_t loaded = 0;
		double t0 = cpu_seconds();
		mlod_result r = mlod_rt_stream(c->ctx, SIZE_MAX, &loaded, &e);
		t += cpu_seconds() - t0;
		if (r != MLOD_OK)
			fprintf(stderr, "%s: warning: %s\n", tool, e.message);
		grow(c);
		if (loaded == 0)
			break;
	}
	return t;
}

typedef struct result {
	double ms;
	int frames;
	uint64_t vertices;
	uint32_t hist[MLOD_RT_LAYERS][16];
	uint32_t fallbacks;
	size_t resident;
} result;

static result run_mode(crowd *c, const mlod_rt_select *sel, double seconds, double fps, double max_wall, float near,
                       float far)
{
	result res;
	memset(&res, 0, sizeof res);
	const float dt = (float)(1.0 / fps);
	const int frames = (int)(seconds * fps + 0.5) > 0 ? (int)(seconds * fps + 0.5) : 1;
	settle(c, sel);
	double total = 0;
	for (int f = 0; f < frames; f++) {
		walk(c, dt, near, far);
		total += frame(c, sel, dt, &res.vertices);
		res.frames++;
		/* streaming between frames, not measured */
		mlod_rt_stream(c->ctx, 256 * 1024, NULL, NULL);
		grow(c);
		if (total > max_wall)
			break;
	}
	res.ms = 1000.0 * total / res.frames;
	for (uint32_t i = 0; i < c->n; i++) {
		const mlod_rt_state *st = mlod_rt_instance_state(c->ctx, c->ids[i]);
		for (int l = 0; l < MLOD_RT_LAYERS; l++)
			res.hist[l][st->level[l] < 15 ? st->level[l] : 15]++;
		res.fallbacks += st->fallback != 0;
	}
	mlod_rt_stats s;
	mlod_rt_stats_get(c->ctx, &s);
	res.resident = s.resident_bytes;
	return res;
}

static void print_hist(const char *name, const uint32_t *h, uint32_t levels)
{
	printf("  %s", name);
	for (uint32_t l = 0; l < levels && l < 16; l++)
		printf(" %u", h[l]);
}

int main(int argc, char **argv)
{
	const char *counts = "1,10,50,250,1000,10000";
	double seconds = 2, fps = 30, max_wall = 10, hyst = 0.1;
	float near = 2, far = 200, ts = 0, te = 1;
	size_t budget = 0;
	int bench = 1, line = 0;
	mlod_rt_select_mode mode = MLOD_RT_SELECT_ALPHA;
	static const struct option longopts[] = {
		{ "counts", required_argument, NULL, 'n' },   { "seconds", required_argument, NULL, 's' },
		{ "fps", required_argument, NULL, 'f' },      { "max-wall", required_argument, NULL, 'w' },
		{ "budget", required_argument, NULL, 'b' },   { "near", required_argument, NULL, 'N' },
		{ "far", required_argument, NULL, 'F' },      { "mode", required_argument, NULL, 'm' },
		{ "hysteresis", required_argument, NULL, 'H' }, { "no-skin-bench", no_argument, NULL, 'k' },
		{ "interval", required_argument, NULL, 'I' }, { "spread", required_argument, NULL, 'S' },
		{ "help", no_argument, NULL, 'h' },           { NULL, 0, NULL, 0 },
	};
	int ch;
	opterr = 0;
	while ((ch = getopt_long(argc, argv, ":n:s:b:h", longopts, NULL)) != -1) {
		switch (ch) {
		case 'n': counts = optarg; break;
		case 's': seconds = parse_num(optarg, "--seconds"); break;
		case 'f': fps = parse_num(optarg, "--fps"); break;
		case 'w': max_wall = parse_num(optarg, "--max-wall"); break;
		case 'b': budget = parse_bytes(optarg); break;
		case 'N': near = (float)parse_num(optarg, "--near"); break;
		case 'F': far = (float)parse_num(optarg, "--far"); break;
		case 'H': hyst = parse_num(optarg, "--hysteresis"); break;
		case 'k': bench = 0; break;
		case 'S':
			if (!strcmp(optarg, "ground") || !strcmp(optarg, "line"))
				line = !strcmp(optarg, "line");
			else
				die(1, "unknown spread '%s' (ground or line)", optarg);
			break;
		case 'I':
			if (sscanf(optarg, "%f,%f", &ts, &te) != 2 || !(ts >= 0) || !(te <= 1))
				die(1, "bad --interval '%s' (TS,TE within 0..1)", optarg);
			break;
		case 'm':
			if (!strcmp(optarg, "alpha"))
				mode = MLOD_RT_SELECT_ALPHA;
			else if (!strcmp(optarg, "pixels"))
				mode = MLOD_RT_SELECT_PIXELS;
			else if (!strcmp(optarg, "toc"))
				mode = MLOD_RT_SELECT_TOC;
			else
				die(1, "unknown mode '%s' (alpha, pixels or toc)", optarg);
			break;
		case 'h': fputs(usage_text, stdout); return 0;
		case ':': die(1, "option '%s' needs a value", argv[optind - 1]);
		default: die(1, "unknown option '%s' (see --help)", argv[optind - 1]);
		}
	}
	if (optind + 1 != argc)
		die(1, "%s", "one PACK is needed (see --help)");
	if (!(seconds > 0) || !(fps > 0) || !(far > near) || near < 0 || hyst < 0)
		die(1, "%s", "bad --seconds, --fps, --near/--far or --hysteresis");
	const char *path = argv[optind];

	/* The crowd sizes. */
	uint32_t sizes[32], nsizes = 0, maxn = 0;
	for (const char *s = counts; *s;) {
		char *end;
		unsigned long v = strtoul(s, &end, 10);
		if (end == s || v == 0 || v > 1000000 || nsizes == 32 || (*end && *end != ','))
			die(1, "bad --counts '%s'", counts);
		sizes[nsizes++] = (uint32_t)v;
		if (v > maxn)
			maxn = (uint32_t)v;
		s = *end ? end + 1 : end;
	}

	mlod_rt_config cfg = { budget, maxn, NULL };
	mlod_error e;
	crowd c;
	memset(&c, 0, sizeof c);
	double t0 = cpu_seconds();
	mlod_result r = mlod_rt_open_path(path, &cfg, &c.ctx, &e);
	if (r != MLOD_OK)
		die(exit_code(r), "%s", e.message);
	double open_ms = 1000 * (cpu_seconds() - t0);
	c.scratch = mlod_rt_scratch_create(c.ctx);
	c.ids = malloc(sizeof *c.ids * maxn);
	c.dist = malloc(sizeof *c.dist * maxn);
	c.speed = malloc(sizeof *c.speed * maxn);
	if (!c.scratch || !c.ids || !c.dist || !c.speed)
		die(2, "%s", "out of memory");
	grow(&c);

	const uint32_t clips = mlod_rt_clip_count(c.ctx);
	uint32_t L[MLOD_RT_LAYERS];
	for (int l = 0; l < MLOD_RT_LAYERS; l++)
		L[l] = mlod_rt_level_count(c.ctx, (mlod_rt_layer)l);
	mlod_rt_stats st;
	mlod_rt_stats_get(c.ctx, &st);
	printf("%s: %u joints, %u clips; levels: skeleton %u, mesh %u, motion %u; open %.2f ms CPU, %zu bytes resident\n",
	       path, mlod_rt_joint_count(c.ctx), clips, L[0], L[1], L[2], open_ms, st.resident_bytes);
	printf("budget %s%zu, distances %g..%g spread %s, mode %s (alpha interval %g,%g), hysteresis %g, %g s at %g fps per "
	       "measurement\n",
	       budget ? "" : "none ", budget, near, far, line ? "along a line" : "over the ground",
	       mode == MLOD_RT_SELECT_ALPHA ? "alpha" : mode == MLOD_RT_SELECT_PIXELS ? "pixels" : "toc", ts, te, hyst,
	       seconds, fps);
	/* Open to the first frame (one instance, the coarse levels open gave),
	 * then the decoding of every other level. */
	{
		uint32_t id, nv = 0;
		float d = 0;
		mlod_rt_select sel;
		mlod_rt_select_default(&sel);
		t0 = cpu_seconds();
		if (mlod_rt_instance_create(c.ctx, 0, 0, 0, &id, &e) != MLOD_OK ||
		    mlod_rt_update(c.ctx, &sel, &id, &d, 1, 0, &e) != MLOD_OK ||
		    mlod_rt_skin(c.ctx, c.scratch, id, c.buf, 12, c.buf + 3 * (size_t)c.cap, 12, c.cap, &nv, &e) != MLOD_OK)
			die(2, "%s", e.message);
		double first_ms = open_ms + 1000 * (cpu_seconds() - t0);
		mlod_rt_instance_destroy(c.ctx, id);
		size_t before = st.resident_bytes;
		uint64_t stored = 0;
		for (int l = 0; l < MLOD_RT_LAYERS; l++)
			for (uint32_t k = 0; k < L[l]; k++)
				for (uint32_t item = 0; item < (l == MLOD_RT_MOTION ? clips : 1u); item++) {
					mlod_rt_level_info li;
					mlod_rt_level_info_get(c.ctx, (mlod_rt_layer)l, k, item, &li, NULL);
					if (!li.resident && mlod_rt_request(c.ctx, (mlod_rt_layer)l, k, item, NULL) == MLOD_OK)
						stored += li.stored_size;
				}
		uint32_t loaded = 0;
		t0 = cpu_seconds();
		r = mlod_rt_stream(c.ctx, SIZE_MAX, &loaded, &e);
		double dec = cpu_seconds() - t0;
		if (r != MLOD_OK)
			fprintf(stderr, "%s: warning: %s\n", tool, e.message);
		grow(&c);
		mlod_rt_stats_get(c.ctx, &st);
		printf("open to first frame (coarse levels, %u vertices): %.2f ms CPU; decoding the other %u levels: "
		       "%llu stored bytes to %zu resident in %.2f ms CPU (%.0f MB/s stored)\n",
		       nv, first_ms, loaded, (unsigned long long)stored, st.resident_bytes - before, 1000 * dec,
		       dec > 0 ? (double)stored / dec / 1e6 : 0.0);
	}
	if (bench)
		skin_bench(path);

	mlod_rt_select full, lod;
	mlod_rt_select_default(&full);
	full.force_level = 0;
	mlod_rt_select_default(&lod);
	lod.mode = mode;
	lod.d_near = near, lod.d_far = far;
	lod.hysteresis = (float)hyst;
	for (int l = 0; l < MLOD_RT_LAYERS; l++)
		lod.t_start[l] = ts, lod.t_end[l] = te;

	printf("\n%7s %12s %12s %8s  %-s\n", "N", "full ms/fr", "LoD ms/fr", "speedup",
	       "LoD instances per level (skeleton | mesh | motion), resident bytes");
	for (uint32_t k = 0; k < nsizes; k++) {
		const uint32_t n = sizes[k];
		rng = 2463534242u;
		for (uint32_t i = 0; i < n; i++) {
			float t = frand() * 10;
			if (mlod_rt_instance_create(c.ctx, clips ? i % clips : 0, t, MLOD_RT_LOOP, &c.ids[i], &e) != MLOD_OK)
				die(2, "%s", e.message);
			float u = ((float)i + 0.5f) / (float)n;
			c.dist[i] = line ? near + (far - near) * u : sqrtf(near * near + u * (far * far - near * near));
			c.speed[i] = (frand() < 0.5f ? -1.0f : 1.0f) * (0.8f + 1.2f * frand()); /* walking, m/s */
		}
		c.n = n;
		float *d0 = malloc(sizeof *d0 * n), *s0 = malloc(sizeof *s0 * n);
		memcpy(d0, c.dist, sizeof *d0 * n);
		memcpy(s0, c.speed, sizeof *s0 * n);
		result a = run_mode(&c, &full, seconds, fps, max_wall, near, far);
		memcpy(c.dist, d0, sizeof *d0 * n); /* the same walk for both modes */
		memcpy(c.speed, s0, sizeof *s0 * n);
		result b = run_mode(&c, &lod, seconds, fps, max_wall, near, far);
		free(d0), free(s0);
		printf("%7u %12.3f %12.3f %7.2fx ", n, a.ms, b.ms, a.ms / b.ms);
		print_hist("", b.hist[0], L[0]);
		printf(" |");
		print_hist("", b.hist[1], L[1]);
		printf(" |");
		print_hist("", b.hist[2], L[2]);
		printf("  %zu B", b.resident);
		if (b.fallbacks || a.fallbacks)
			printf("  (fallbacks: full %u, LoD %u)", a.fallbacks, b.fallbacks);
		if (a.frames < (int)(seconds * fps + 0.5) || b.frames < (int)(seconds * fps + 0.5))
			printf("  (frames: full %d, LoD %d)", a.frames, b.frames);
		printf("\n");
		printf("%7s %12.1f %12.1f %8s  Mvertices skinned per second\n", "", a.vertices / (a.ms * a.frames) / 1e3,
		       b.vertices / (b.ms * b.frames) / 1e3, "");
		for (uint32_t i = 0; i < n; i++)
			mlod_rt_instance_destroy(c.ctx, c.ids[i]);
		fflush(stdout);
	}
	mlod_rt_stats_get(c.ctx, &st);
	printf("\nstreaming: %llu loads, %llu evictions, %llu failures; peak resident %zu bytes\n",
	       (unsigned long long)st.loads, (unsigned long long)st.evictions, (unsigned long long)st.failures,
	       st.peak_resident_bytes);
	mlod_rt_scratch_destroy(c.ctx, c.scratch);
	mlod_rt_close(c.ctx);
	free(c.ids), free(c.dist), free(c.speed), free(c.buf);
	return 0;
}
