/*
 * bench/crowd (built as build/<config>/bench/crowd; `make demo` and
 * bench/crowd.sh run it): the crowd benchmark of the runtime (paper 4.4, Figures 15
 * and 16) on any .mlod pack.
 *
 * Metres. The character is taken as --height metres tall (default 1.8):
 * the scale is the pack's height (INFO, the skeleton height of mlod(5))
 * over --height, in scene units per metre, so --near and --far (2 and 200
 * m) and the walking speeds mean the same for every pack; --height 0 keeps
 * scene units. The header line prints the scale.
 *
 * For each N (1, 10, 50, 250, 1000, 10000 by default) it places N
 * instances at distances in [near, far], each with its own clip and time
 * offset, walking at 0.8 to 2 m/s towards or away from the camera, and
 * runs a few simulated seconds several times in one run, on the same walk:
 * every instance at full detail (level 0 of every layer), then with LoD
 * by each selection rule of --mode: alpha (the paper's alpha =
 * (d - near) / (far - near), every layer over [0, 1]), pixels (the
 * runtime's projected error: the coarsest level whose measured error
 * projects to at most --pixels pixels, default 1, at 1080 lines and 60
 * degrees of vertical field of view) and toc (the pack's baked switch
 * distances); all (the default) is alpha and pixels. It measures the CPU
 * time of one frame: the update (selection), motion sampling, pose and
 * linear blend skinning of every instance into one buffer, on one core.
 * With --work pose it measures what a caller that skins on the GPU pays on
 * the CPU instead: the update, motion sampling, the pose (mlod_rt_pose)
 * and the skinning palette (mlod_rt_palette), no skinning. The paper's
 * Figure 15 measures such a crowd of skeletons; a skeleton level saves
 * the joints it removes that are not ancestors of kept ones (mlod_rt(3),
 * "Skeleton levels").
 * The stale and split modes (--mode) select by pixels and skin with
 * mlod_rt_skin_stale: each instance is skinned again only when the
 * vertices it kept are provably more than a staleness in pixels off
 * (mlod_rt_eval(3)); stale selects at --pixels P and allows --stale-pixels
 * Q (default 1: 2 px from level 0 in all), split at P / 2 and P / 2 (the
 * pixel rule's P in all). Their frames time the update, motion sampling,
 * pose, the bound and the skins it asks for (into the one buffer, as the
 * other modes: a caller drawing them keeps a buffer per instance, which
 * the time does not depend on); each instance's record (mlod_rt_stale_size
 * bytes) is zeroed before the mode's first frame, which therefore skins
 * every instance. Their lines end with the fraction of calls that skinned.
 * The frame's dt is 1 / --fps (default 1/30 s): the gain depends on it.
 * Streaming happens between frames, outside the measured time (its cost
 * is printed apart). It prints per N one line per mode: ms per frame, the
 * speed-up over full detail, the instances per skeleton, mesh and motion
 * level at the last measured frame, and the resident bytes.
 *
 * Spread: by default the instances stand evenly over the ground around
 * the camera, the ring between near and far (so the density of distances
 * grows with the distance, as in a crowd filling a square: instance i of n
 * at d = sqrt(near^2 + (i + 1/2)/n (far^2 - near^2)), azimuth i times the
 * golden angle); --spread line puts them evenly along one line instead
 * (d = near + (i + 1/2)/n (far - near)), which gives the near levels many
 * more instances.
 *
 * The picture (--png FILE): the last measured frame of one N (the largest,
 * or --png-count) under one rule (the first measured, or --png-mode),
 * drawn after that frame outside the measured time by a small software
 * rasteriser: the runtime skins each instance in view again from the same
 * state into a buffer (the levels and poses measured), and the triangles
 * of its shown mesh level are z-buffered with two-sided Lambert shading
 * from the skinned normals, coloured by mesh level (0, the finest, red;
 * then orange, yellow, green, light blue, blue, purple; a legend strip at
 * the bottom left), 2x2 supersampled. The camera stands at the crowd's
 * centre at eye height (0.9 of the character's height), 60 degrees of
 * vertical field of view, pitched 8 degrees down; the ground is a checker
 * of 5 m tiles (thin dark rings at near and far) fading into haze. libpng
 * writes the file.
 *
 * The paper's figures (--figures, --plot FILE): Figure 15 (a crowd's frame
 * rate with and without skeletal LoD against N) as the frames per second
 * (1 / the CPU frame time) per N at full detail, under the skeleton mode
 * (the paper's skeletal LoD alone: the alpha rule on the skeleton layer,
 * mesh and motion at level 0; always measured with --figures) and under
 * each measured rule; Figure 16 (mesh LoD on one character) as one
 * instance at each mesh level, skeleton and motion at level 0, placed at
 * the distance where the mesh layer's alpha picks that level: its
 * triangles, vertices, CPU time and frame rate of one update and skin per
 * frame (the best of 5 runs of 0.05 s), and the speed-up over level 0.
 * --plot draws both as line plots side by side (1280x560: Figure 15
 * log-log, one line per mode; Figure 16 frames per second against the
 * level's triangles), with libpng.
 *
 * It also measures the runtime's skinning kernel against the plain scalar
 * loop, in vertices per second on one core, on the pack's finest mesh.
 *
 * Uses only the runtime (mlod_rt.h), its pack reader (mlod_pack.h) and
 * libpng.
 */
#define _GNU_SOURCE /* getopt_long, clock_gettime */

#include <errno.h>
#include <fcntl.h>
#include <getopt.h>
#include <math.h>
#include <png.h>
#include <setjmp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "rt/mlod_rt.h"

static const char usage_text[] =
	"usage: crowd [options] PACK\n"
	"\n"
	"Runs crowds of N instances of the character in PACK (.mlod) at full detail\n"
	"and with level of detail by each selection rule, and prints the CPU frame\n"
	"time of motion sampling, pose and skinning for each, on one core, the\n"
	"speed-up and the instances per level.\n"
	"\n"
	"options:\n"
	"  -n, --counts LIST     crowd sizes (default 1,10,50,250,1000,10000)\n"
	"  -s, --seconds S       simulated seconds per size and mode (default 2)\n"
	"      --fps F           simulated frames per second (default 30)\n"
	"      --max-wall S      stop a measurement after S seconds of CPU time,\n"
	"                        keeping the frames done (default 10)\n"
	"  -b, --budget BYTES    the runtime's memory budget (K, M suffixes; default\n"
	"                        none)\n"
	"      --height H        the character is H metres tall (default 1.8): scale =\n"
	"                        the pack's height / H scene units per metre; 0 keeps\n"
	"                        scene units\n"
	"      --near D, --far D the distance range in metres (scene units with\n"
	"                        --height 0; default 2, 200)\n"
	"      --spread HOW      ground (default: evenly over the ground between\n"
	"                        near and far) or line (evenly over the distances)\n"
	"      --mode MODE       the LoD rules measured against full detail: alpha\n"
	"                        (the paper's), pixels (projected error), toc (the\n"
	"                        pack's switch distances), skeleton (alpha on the\n"
	"                        skeleton layer alone, mesh and motion at level 0),\n"
	"                        stale (pixels, and each instance skinned again only\n"
	"                        when its kept vertices are more than --stale-pixels\n"
	"                        off: mlod_rt_skin_stale), split (the same with P/2\n"
	"                        for each, P in all), a comma list of them, or all\n"
	"                        (default: alpha and pixels)\n"
	"      --pixels P        pixels mode: the largest projected error in pixels\n"
	"                        (default 1, at 1080 lines and 60 degrees)\n"
	"      --stale-pixels Q  stale mode: the largest staleness in pixels (default\n"
	"                        1; the selection's P adds to it)\n"
	"      --interval TS,TE  the alpha interval of every layer (default 0,1)\n"
	"      --hysteresis H    relative hysteresis (default 0.1)\n"
	"      --work WORK       skin (default: motion sampling, pose and skinning)\n"
	"                        or pose (motion sampling, pose and palette, as a\n"
	"                        caller that skins on the GPU; the paper's Figure 15)\n"
	"      --png FILE        writes a picture of the last measured frame, each\n"
	"                        character coloured by its mesh level\n"
	"      --png-count N     the crowd size pictured (one of --counts; default the\n"
	"                        largest)\n"
	"      --png-mode MODE   the rule pictured (default the first measured; stale\n"
	"                        and split are drawn from fresh skins)\n"
	"      --png-size WxH    the picture's size (default 960x540)\n"
	"      --figures         also prints the paper's Figures 15 and 16 as data:\n"
	"                        frames per second against N for full detail, the\n"
	"                        skeleton mode (added) and each rule; one character\n"
	"                        at each mesh level (skeleton and motion at level 0)\n"
	"      --plot FILE       --figures, and writes both as a line plot (PNG)\n"
	"      --no-skin-bench   skip the kernel measurement\n"
	"  -h, --help            show this help\n"
	"\n"
	"exit status: 0 success, 1 usage (also a --png or --plot FILE that is a\n"
	"terminal), 2 bad input, 3 unsupported input, 4 a picture could not be\n"
	"written\n";

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

/* The whole file, or NULL (with *size 0) when it cannot be read. */
static void *read_file(const char *path, size_t *size)
{
	*size = 0;
	FILE *f = fopen(path, "rb");
	if (!f)
		return NULL;
	void *data = NULL;
	long n = fseek(f, 0, SEEK_END) == 0 ? ftell(f) : -1;
	if (n > 0 && fseek(f, 0, SEEK_SET) == 0 && (data = malloc((size_t)n)) != NULL &&
	    fread(data, 1, (size_t)n, f) != (size_t)n) {
		free(data);
		data = NULL;
	}
	fclose(f);
	if (data)
		*size = (size_t)n;
	return data;
}

/* The pack's INFO record (the character's height and rest bounds); 0 when
 * it cannot be read (the runtime's open then says why). */
static int read_info(const void *data, size_t size, mlod_pack_info_rec *out)
{
	mlod_pack p;
	mlod_pack_info info = { 0 };
	mlod_error e;
	int ok = 0;
	memset(out, 0, sizeof *out);
	if (data && mlod_pack_open(data, size, &p, &e) == MLOD_OK) {
		if (mlod_pack_decode_info(&p, data, size, &info, &e) == MLOD_OK) {
			*out = info.rec;
			ok = 1;
		}
		mlod_pack_info_free(&info);
		mlod_pack_close(&p);
	}
	return ok;
}

static void skin_bench(const void *data, size_t size)
{
	if (!data)
		return;
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
}

/* ---------------------------------------------------------------- */
/* The crowd                                                         */
/* ---------------------------------------------------------------- */

typedef struct crowd {
	mlod_rt_ctx *ctx;
	mlod_rt_scratch *scratch;
	uint32_t *ids;
	float *dist, *speed, *azimuth; /* scene units, scene units per second, radians */
	float *buf;
	uint32_t cap;
	uint32_t cap0;    /* cap after open (grow's first call) */
	uint32_t regrows; /* reallocations after that: 0 for a pack of format 8.1 on */
	uint32_t n;
	int pose_only; /* --work pose */
	/* stale and split modes: skin_stale >= 0 is the staleness allowed
	 * (pixels), each instance's record at rec + i * rec_size (the caller's
	 * memory, mlod_rt_stale_size), stale_sel the view it is measured in;
	 * calls and skins count mlod_rt_skin_stale's calls and re-skins. */
	float skin_stale;
	uint8_t *rec;
	size_t rec_size;
	const mlod_rt_select *stale_sel;
	uint64_t calls, skins;
} crowd;

/* The skinning buffers: sized once, right after open, from
 * mlod_rt_max_vertex_count, the largest mesh level the pack can stream in
 * (format 8.1, mlod(5) INFO). A pack of format 8.0 or older states none:
 * the count is then the largest resident level's, and the buffers grow
 * when a larger level loads (the calls after open, counted in regrows). */
static void grow(crowd *c)
{
	uint32_t need = mlod_rt_max_vertex_count(c->ctx);
	need = need ? need : 1; /* a buffer even without a mesh: mlod_rt_skin wants one */
	if (c->buf && need <= c->cap)
		return;
	c->regrows += c->buf != NULL;
	free(c->buf);
	c->buf = malloc((size_t)need * 24);
	if (!c->buf)
		die(2, "%s", "out of memory");
	c->cap = need;
}

/* Skins instance id into c->buf (positions, then normals at c->buf + 3 cap). */
static mlod_result skin_one(crowd *c, uint32_t id, uint32_t *nv, mlod_error *e)
{
	return mlod_rt_skin(c->ctx, c->scratch, id, c->buf, 12, c->buf + 3 * (size_t)c->cap, 12, c->cap, nv, e);
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

/* Poses instance id and builds its palette (--work pose); *count gets the
 * palette's matrices. */
static mlod_result pose_one(crowd *c, uint32_t id, uint32_t *count, mlod_error *e)
{
	const float *palette;
	mlod_result r = mlod_rt_pose(c->ctx, c->scratch, id, NULL, NULL, NULL, e);
	return r != MLOD_OK ? r : mlod_rt_palette(c->ctx, c->scratch, &palette, count, e);
}

/* One measured frame: update, then pose and skin every instance (or pose
 * it and build its palette, --work pose). *vertices counts the vertices
 * skinned (the palette matrices built). */
#if defined(__GNUC__)
__attribute__((noinline)) /* a function of its own, for callgrind --toggle-collect=frame */
#endif
static double frame(crowd *c, const mlod_rt_select *sel, float dt, uint64_t *vertices)
{
	mlod_error e;
	double t0 = cpu_seconds();
	if (mlod_rt_update(c->ctx, sel, c->ids, c->dist, c->n, dt, &e) != MLOD_OK)
		die(2, "%s", e.message);
	if (c->pose_only) {
		for (uint32_t i = 0; i < c->n; i++) {
			uint32_t count = 0;
			if (pose_one(c, c->ids[i], &count, &e) != MLOD_OK)
				die(2, "%s", e.message);
			*vertices += count;
		}
		return cpu_seconds() - t0;
	}
	if (c->skin_stale >= 0) {
		/* Every instance's skin goes to the one buffer, as in the other
		 * modes (the time is the same: a caller drawing them keeps a buffer
		 * per instance, N x vertices x 24 bytes, which this does not
		 * allocate); the records are per instance. */
		for (uint32_t i = 0; i < c->n; i++) {
			uint32_t nv = 0;
			int skinned = 0;
			mlod_result r = mlod_rt_skin_stale(c->ctx, c->scratch, c->ids[i], c->stale_sel, c->skin_stale,
			                                   c->rec + (size_t)i * c->rec_size, c->rec_size, c->buf, 12,
			                                   c->buf + 3 * (size_t)c->cap, 12, c->cap, &nv, &skinned, NULL, &e);
			if (r == MLOD_ERR_LIMIT) {
				t0 -= cpu_seconds();
				grow(c);
				t0 += cpu_seconds();
				r = mlod_rt_skin_stale(c->ctx, c->scratch, c->ids[i], c->stale_sel, c->skin_stale,
				                       c->rec + (size_t)i * c->rec_size, c->rec_size, c->buf, 12,
				                       c->buf + 3 * (size_t)c->cap, 12, c->cap, &nv, &skinned, NULL, &e);
			}
			if (r != MLOD_OK)
				die(2, "%s", e.message);
			c->calls++, c->skins += (uint64_t)skinned;
			*vertices += skinned ? nv : 0;
		}
		return cpu_seconds() - t0;
	}
	for (uint32_t i = 0; i < c->n; i++) {
		uint32_t nv = 0;
		mlod_result r = skin_one(c, c->ids[i], &nv, &e);
		if (r == MLOD_ERR_LIMIT) { /* a larger level arrived: not in the measured time */
			t0 -= cpu_seconds();
			grow(c);
			t0 += cpu_seconds();
			r = skin_one(c, c->ids[i], &nv, &e);
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

/* ---------------------------------------------------------------- */
/* The picture: a small software rasteriser                          */
/* ---------------------------------------------------------------- */

/* The camera stands at the centre of the crowd at eye height (0.9 of the
 * character's height), looks along -z, pitched down by PITCH so that the
 * horizon sits above the middle; 60 degrees of vertical field of view.
 * The world is y up (glTF); instance i stands at distance d and azimuth a
 * (from the view direction) at (d sin a, 0, -d cos a), facing the way it
 * walks (its model +z along the radius, out or in). */
#define PITCH_DEG 8.0
#define FOV_Y_DEG 60.0
#define SS 2 /* supersampling per axis */

typedef struct picture {
	const char *path;
	uint32_t count;          /* the crowd size pictured */
	int mode;                /* the selection mode pictured (index in modes[]) */
	int width, height;       /* the PNG's */
	float scale;             /* scene units per metre */
	float char_height;       /* scene units */
	float center[3], radius; /* the rest bounds' centre (x, z), floor (y), bounding radius */
	float near, far;         /* scene units */
	uint32_t mesh_levels;
	int done;
	uint32_t drawn, triangles; /* instances drawn, triangles rasterised */
	uint32_t drawn_level[16];
} picture;

typedef struct raster {
	int w, h;          /* supersampled size */
	float *rgb;        /* 3 per pixel */
	float *inv_z;      /* 1 / view depth, 0 = nothing */
	float f;           /* focal length in pixels */
	float eye[3], right[3], up[3], fwd[3];
} raster;

static const float level_rgb[8][3] = {
	{ 0.86f, 0.20f, 0.18f }, /* 0: finest, red */
	{ 0.96f, 0.58f, 0.12f }, /* 1: orange */
	{ 0.93f, 0.86f, 0.20f }, /* 2: yellow */
	{ 0.30f, 0.72f, 0.30f }, /* 3: green */
	{ 0.20f, 0.62f, 0.88f }, /* 4: light blue */
	{ 0.33f, 0.33f, 0.90f }, /* 5: blue */
	{ 0.66f, 0.34f, 0.86f }, /* 6: purple */
	{ 0.55f, 0.55f, 0.55f }, /* 7 and coarser: grey */
};

static const float *level_colour(uint32_t l)
{
	return level_rgb[l < 7 ? l : 7];
}

static float dot3(const float *a, const float *b)
{
	return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* Sky above the horizon, a checkered ground of 5 m tiles below it, fading
 * into haze with the distance. */
static void draw_background(raster *R, const picture *P)
{
	const float haze[3] = { 0.78f, 0.82f, 0.86f }, sky[3] = { 0.42f, 0.60f, 0.85f };
	const float tile = 5.0f * P->scale, fog = 1.5f * P->far;
	for (int y = 0; y < R->h; y++)
		for (int x = 0; x < R->w; x++) {
			/* the ray through the pixel's centre */
			float u = ((float)x + 0.5f - 0.5f * (float)R->w) / R->f, v = (0.5f * (float)R->h - (float)y - 0.5f) / R->f;
			float d[3];
			for (int k = 0; k < 3; k++)
				d[k] = R->fwd[k] + u * R->right[k] + v * R->up[k];
			float *px = R->rgb + 3 * ((size_t)y * R->w + x);
			if (d[1] >= -1e-6f) {
				float t = d[1] / sqrtf(dot3(d, d));
				t = t > 1 ? 1 : t < 0 ? 0 : sqrtf(t);
				for (int k = 0; k < 3; k++)
					px[k] = haze[k] + (sky[k] - haze[k]) * t;
				continue;
			}
			float s = -R->eye[1] / d[1]; /* to y = 0 */
			float gx = R->eye[0] + s * d[0], gz = R->eye[2] + s * d[2];
			float dist = sqrtf(gx * gx + gz * gz);
			int check = ((int)floorf(gx / tile) + (int)floorf(gz / tile)) & 1;
			float g[3] = { check ? 0.50f : 0.44f, check ? 0.52f : 0.46f, check ? 0.47f : 0.41f };
			/* the near and far rings of the crowd, as thin dark lines */
			float ring = fabsf(dist - P->near) < 0.05f * P->scale || fabsf(dist - P->far) < 0.4f * P->scale;
			float t = 1.0f - expf(-dist / fog);
			for (int k = 0; k < 3; k++)
				px[k] = (ring ? 0.25f : g[k]) * (1 - t) + haze[k] * t;
		}
}

/* One triangle in screen space (x, y in pixels, iz = 1 / depth, c the
 * shade), z-buffered, colours interpolated affinely. */
static void draw_triangle(raster *R, float s[3][3], const float shade[3], const float *rgb)
{
	float area = (s[1][0] - s[0][0]) * (s[2][1] - s[0][1]) - (s[2][0] - s[0][0]) * (s[1][1] - s[0][1]);
	if (fabsf(area) < 1e-12f)
		return;
	float minx = fminf(s[0][0], fminf(s[1][0], s[2][0])), maxx = fmaxf(s[0][0], fmaxf(s[1][0], s[2][0]));
	float miny = fminf(s[0][1], fminf(s[1][1], s[2][1])), maxy = fmaxf(s[0][1], fmaxf(s[1][1], s[2][1]));
	if (!(maxx >= 0 && minx < (float)R->w && maxy >= 0 && miny < (float)R->h))
		return; /* off screen (or not a number) */
	int x0 = minx < 0 ? 0 : (int)minx, x1 = maxx >= (float)R->w - 1 ? R->w - 1 : (int)maxx;
	int y0 = miny < 0 ? 0 : (int)miny, y1 = maxy >= (float)R->h - 1 ? R->h - 1 : (int)maxy;
	const float inv = 1.0f / area;
	for (int y = y0; y <= y1; y++)
		for (int x = x0; x <= x1; x++) {
			float px = (float)x + 0.5f, py = (float)y + 0.5f;
			float w0 = ((s[1][0] - px) * (s[2][1] - py) - (s[2][0] - px) * (s[1][1] - py)) * inv;
			float w1 = ((s[2][0] - px) * (s[0][1] - py) - (s[0][0] - px) * (s[2][1] - py)) * inv;
			float w2 = 1.0f - w0 - w1;
			if (w0 < 0 || w1 < 0 || w2 < 0)
				continue;
			float iz = w0 * s[0][2] + w1 * s[1][2] + w2 * s[2][2];
			size_t o = (size_t)y * R->w + x;
			if (iz <= R->inv_z[o])
				continue;
			R->inv_z[o] = iz;
			float k = w0 * shade[0] + w1 * shade[1] + w2 * shade[2];
			for (int j = 0; j < 3; j++)
				R->rgb[3 * o + j] = rgb[j] * k;
		}
}

/* Draws every instance in view at the levels it showed in the last
 * measured frame, skinned again by the runtime from the same state. */
static void draw_crowd(crowd *c, raster *R, picture *P)
{
	const float light[3] = { 0.40f, 0.80f, 0.45f }; /* towards the light (normalised below) */
	float L[3], ln = sqrtf(dot3(light, light));
	for (int k = 0; k < 3; k++)
		L[k] = light[k] / ln;
	const float tx = 0.5f * (float)R->w / R->f, ty = 0.5f * (float)R->h / R->f;
	const float sx = sqrtf(1 + tx * tx), sy = sqrtf(1 + ty * ty), znear = 0.05f * P->scale;
	mlod_error e;
	for (uint32_t i = 0; i < c->n; i++) {
		const mlod_rt_state *st = mlod_rt_instance_state(c->ctx, c->ids[i]);
		float sa = sinf(c->azimuth[i]), ca = cosf(c->azimuth[i]);
		float pos[3] = { c->dist[i] * sa, 0, -c->dist[i] * ca };
		/* facing: model +z along the walk (out when the distance grows) */
		float dir = c->speed[i] >= 0 ? 1.0f : -1.0f;
		float fz[3] = { dir * sa, 0, -dir * ca }, fx[3] = { fz[2], 0, -fz[0] }; /* model x, z in the world */
		/* cull by a bounding sphere around the body */
		float ctr[3] = { pos[0], 0.5f * P->radius, pos[2] }, q[3];
		for (int k = 0; k < 3; k++)
			q[k] = ctr[k] - R->eye[k];
		float xv = dot3(q, R->right), yv = dot3(q, R->up), zv = dot3(q, R->fwd), r = P->radius;
		if (zv + r < znear || fabsf(xv) - r * sx > zv * tx || fabsf(yv) - r * sy > zv * ty)
			continue;
		uint32_t nv = 0;
		mlod_result res = skin_one(c, c->ids[i], &nv, &e);
		if (res == MLOD_ERR_LIMIT) {
			grow(c);
			res = skin_one(c, c->ids[i], &nv, &e);
		}
		if (res != MLOD_OK)
			die(2, "%s", e.message);
		const uint32_t level = st->level[MLOD_RT_MESH];
		const float *rgb = level_colour(level);
		const float *vp = c->buf, *vn = c->buf + 3 * (size_t)c->cap;
		const uint32_t parts = mlod_rt_mesh_part_count(c->ctx, level);
		uint32_t tris = 0;
		for (uint32_t p = 0; p < parts; p++) {
			mlod_rt_part_info pi;
			if (mlod_rt_mesh_part(c->ctx, level, p, &pi, &e) != MLOD_OK)
				die(2, "%s", e.message);
			for (uint32_t t = 0; t + 2 < pi.index_count; t += 3) {
				float s[3][3], shade[3], nrm[3][3];
				int ok = 1;
				for (int k = 0; k < 3 && ok; k++) {
					uint32_t v = pi.first_vertex + pi.indices[t + k];
					if (v >= nv) {
						ok = 0;
						break;
					}
					const float *a = vp + 3 * (size_t)v, *n = vn + 3 * (size_t)v;
					float m[3] = { a[0] - P->center[0], a[1] - P->center[1], a[2] - P->center[2] };
					float w[3], d[3];
					for (int j = 0; j < 3; j++) {
						w[j] = pos[j] + m[0] * fx[j] + m[2] * fz[j] + (j == 1 ? m[1] : 0);
						nrm[k][j] = n[0] * fx[j] + n[2] * fz[j] + (j == 1 ? n[1] : 0);
						d[j] = w[j] - R->eye[j];
					}
					float z = dot3(d, R->fwd);
					if (z < znear) {
						ok = 0;
						break;
					}
					s[k][0] = 0.5f * (float)R->w + R->f * dot3(d, R->right) / z;
					s[k][1] = 0.5f * (float)R->h - R->f * dot3(d, R->up) / z;
					s[k][2] = 1.0f / z;
				}
				if (!ok)
					continue;
				/* two-sided Lambert: the normal turned towards the eye */
				float fn[3], tocam[3];
				for (int j = 0; j < 3; j++) {
					fn[j] = nrm[0][j] + nrm[1][j] + nrm[2][j];
					tocam[j] = R->eye[j] - pos[j];
				}
				for (int k = 0; k < 3; k++) {
					float *n = nrm[k];
					if (dot3(n, n) < 1e-12f) /* a part without normals: the face's */
						n = fn;
					float nl = sqrtf(dot3(n, n)), ndl = nl > 0 ? dot3(n, L) / nl : 0;
					if (nl > 0 && dot3(n, tocam) < 0)
						ndl = -ndl;
					shade[k] = 0.35f + 0.65f * (ndl > 0 ? ndl : 0);
				}
				draw_triangle(R, s, shade, rgb);
				tris++;
			}
		}
		P->drawn++;
		P->drawn_level[level < 15 ? level : 15]++;
		P->triangles += tris;
	}
}

/* 3x5 digit glyphs, one row per 3 bits (top row first), for the legend. */
static const unsigned short digit_glyph[10] = {
	075557, 026227, 071747, 071717, 055711, 074717, 074757, 071111, 075757, 075717,
};

static void put(unsigned char *img, int w, int h, int x, int y, const unsigned char rgb[3])
{
	if (x >= 0 && y >= 0 && x < w && y < h)
		memcpy(img + 3 * ((size_t)y * w + x), rgb, 3);
}

/* The legend: one swatch per mesh level, with its number, bottom left. */
static void draw_legend(unsigned char *img, int w, int h, uint32_t levels)
{
	const int sw = 28, sh = 18, pad = 6, z = 2; /* swatch size, gap, glyph zoom */
	const unsigned char frame[3] = { 20, 20, 20 };
	for (uint32_t l = 0; l < levels && l < 16; l++) {
		int x0 = pad + (int)l * (sw + pad), y0 = h - pad - sh;
		unsigned char col[3];
		for (int k = 0; k < 3; k++)
			col[k] = (unsigned char)(255.0f * level_colour(l)[k] + 0.5f);
		for (int y = -1; y <= sh; y++)
			for (int x = -1; x <= sw; x++)
				put(img, w, h, x0 + x, y0 + y, x < 0 || y < 0 || x == sw || y == sh ? frame : col);
		/* the level's number, centred (one or two digits) */
		int nd = l >= 10 ? 2 : 1, gx = x0 + (sw - (nd * 4 - 1) * z) / 2, gy = y0 + (sh - 5 * z) / 2;
		for (int d = 0; d < nd; d++) {
			unsigned g = digit_glyph[nd == 2 ? (d ? l % 10 : l / 10) : l];
			for (int row = 0; row < 5; row++)
				for (int col3 = 0; col3 < 3; col3++)
					if (g >> (3 * (4 - row) + (2 - col3)) & 1)
						for (int a = 0; a < z; a++)
							for (int b = 0; b < z; b++)
								put(img, w, h, gx + (d * 4 + col3) * z + b, gy + row * z + a, frame);
		}
	}
}

/* A picture's path is checked up front, before seconds of measuring: a
 * terminal (/dev/tty, /dev/stdout on one) is refused, as the tools refuse
 * binary output to one (exit 1); a file that cannot be opened for writing,
 * or a new one whose directory does not let it be made, exits 4 with the
 * reason. (A FIFO without a reader yet is left to write_png.) */
static void check_output(const char *path)
{
	char msg[4096];
	if (!path)
		return;
	int fd = open(path, O_WRONLY | O_NOCTTY | O_NONBLOCK);
	if (fd < 0 && errno == ENOENT) { /* a new file: its directory must take it */
		const char *slash = strrchr(path, '/');
		int n = slash ? (int)(slash - path) + (slash == path) : 1;
		snprintf(msg, sizeof msg, "%.*s", n, slash ? path : ".");
		if (access(msg, W_OK | X_OK) == 0)
			return;
	} else if (fd < 0 && errno == ENXIO) {
		return;
	}
	if (fd < 0) {
		snprintf(msg, sizeof msg, "%s: cannot open for writing: %s", path, strerror(errno));
		die(4, "%s", msg);
	}
	int tty = isatty(fd);
	close(fd);
	if (tty)
		die(1, "%s: refusing to write binary output to a terminal", path);
}

static void write_png(const char *path, const unsigned char *img, int w, int h)
{
	FILE *f = fopen(path, "wb");
	if (!f) {
		char msg[4096];
		snprintf(msg, sizeof msg, "%s: cannot open for writing: %s", path, strerror(errno));
		die(4, "%s", msg);
	}
	png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
	png_infop info = png ? png_create_info_struct(png) : NULL;
	if (!png || !info) {
		fclose(f);
		die(4, "%s: libpng could not start", path);
	}
	if (setjmp(png_jmpbuf(png))) {
		png_destroy_write_struct(&png, &info);
		fclose(f);
		remove(path);
		die(4, "%s: writing the PNG failed", path);
	}
	png_init_io(png, f);
	png_set_compression_level(png, 9);
	png_set_IHDR(png, info, (png_uint_32)w, (png_uint_32)h, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
	             PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
	png_write_info(png, info);
	for (int y = 0; y < h; y++)
		png_write_row(png, (png_const_bytep)(img + 3 * (size_t)y * w));
	png_write_end(png, NULL);
	png_destroy_write_struct(&png, &info);
	if (fclose(f) != 0)
		die(4, "%s: writing the PNG failed", path);
}

static void render(crowd *c, picture *P)
{
	raster R;
	memset(&R, 0, sizeof R);
	R.w = P->width * SS, R.h = P->height * SS;
	R.rgb = malloc((size_t)R.w * R.h * 3 * sizeof(float));
	R.inv_z = calloc((size_t)R.w * R.h, sizeof(float));
	unsigned char *img = malloc((size_t)P->width * P->height * 3);
	if (!R.rgb || !R.inv_z || !img)
		die(2, "%s", "out of memory");
	const double pitch = PITCH_DEG * 3.14159265358979323846 / 180.0;
	R.f = 0.5f * (float)R.h / tanf((float)(0.5 * FOV_Y_DEG * 3.14159265358979323846 / 180.0));
	R.eye[1] = 0.9f * P->char_height;
	R.fwd[1] = -(float)sin(pitch), R.fwd[2] = -(float)cos(pitch);
	R.up[1] = (float)cos(pitch), R.up[2] = -(float)sin(pitch);
	R.right[0] = 1;
	draw_background(&R, P);
	draw_crowd(c, &R, P);
	for (int y = 0; y < P->height; y++)
		for (int x = 0; x < P->width; x++)
			for (int k = 0; k < 3; k++) {
				float s = 0;
				for (int a = 0; a < SS; a++)
					for (int b = 0; b < SS; b++)
						s += R.rgb[3 * ((size_t)(SS * y + a) * R.w + SS * x + b) + k];
				s /= SS * SS;
				img[3 * ((size_t)y * P->width + x) + k] = (unsigned char)(s <= 0 ? 0 : s >= 1 ? 255 : 255.0f * s + 0.5f);
			}
	draw_legend(img, P->width, P->height, P->mesh_levels);
	write_png(P->path, img, P->width, P->height);
	free(R.rgb), free(R.inv_z), free(img);
	P->done = 1;
}

/* ---------------------------------------------------------------- */
/* The figures' plot (--plot FILE)                                   */
/* ---------------------------------------------------------------- */

/* 3x5 glyphs, one octal digit per row (top first, the high bit left), for
 * the plot's labels: letters (lower case drawn as upper case), digits and
 * a little punctuation. */
static unsigned glyph(int c)
{
	static const unsigned short letters[26] = {
		025755, 065656, 034443, 065556, 074647, 074644, 034553, 055755, 072227, 011152, 055655, 044447, 057755,
		065555, 025552, 065644, 025563, 065655, 034216, 072222, 055557, 055552, 055775, 055255, 055222, 071247,
	};
	if (c >= 'a' && c <= 'z')
		c -= 'a' - 'A';
	if (c >= 'A' && c <= 'Z')
		return letters[c - 'A'];
	if (c >= '0' && c <= '9')
		return digit_glyph[c - '0'];
	switch (c) {
	case '.': return 000002;
	case ',': return 000024;
	case ':': return 002020;
	case '/': return 011244;
	case '(': return 012221;
	case ')': return 042224;
	case '-': return 000700;
	case '%': return 051245;
	case '=': return 007070;
	case '+': return 002720;
	default: return 0;
	}
}

typedef struct canvas {
	unsigned char *img;
	int w, h;
} canvas;

static void dot(canvas *C, int x, int y, const unsigned char rgb[3])
{
	put(C->img, C->w, C->h, x, y, rgb);
}

/* Text at (x, y) (top left), glyphs zoomed z times; returns its width. */
static int text(canvas *C, int x, int y, int z, const char *s, const unsigned char rgb[3])
{
	int x0 = x;
	for (; *s; s++, x += 4 * z) {
		unsigned g = glyph((unsigned char)*s);
		for (int row = 0; row < 5; row++)
			for (int col = 0; col < 3; col++)
				if (g >> (3 * (4 - row) + (2 - col)) & 1)
					for (int a = 0; a < z; a++)
						for (int b = 0; b < z; b++)
							dot(C, x + col * z + b, y + row * z + a, rgb);
	}
	return x - x0;
}

static void rect(canvas *C, int x0, int y0, int x1, int y1, const unsigned char rgb[3])
{
	for (int y = y0; y <= y1; y++)
		for (int x = x0; x <= x1; x++)
			dot(C, x, y, rgb);
}

/* A line 2 pixels thick. */
static void line(canvas *C, double x0, double y0, double x1, double y1, const unsigned char rgb[3])
{
	const int n = (int)(fmax(fabs(x1 - x0), fabs(y1 - y0)) + 1);
	for (int i = 0; i <= n; i++) {
		const double t = (double)i / n;
		const int x = (int)floor(x0 + t * (x1 - x0)), y = (int)floor(y0 + t * (y1 - y0));
		rect(C, x, y, x + 1, y + 1, rgb);
	}
}

/* One panel: up to PANEL_SERIES series of n points (x[k], y[k][s]; y <= 0:
 * none), in the box (bx, by, bw, bh) of the canvas, log or linear axes.
 * Figure 15 draws full detail and every mode (MODES + 1, checked below). */
#define PANEL_SERIES 8
typedef struct panel {
	const char *title, *xlabel, *ylabel;
	int logx, logy;
	int n, series;
	double x[32], y[32][PANEL_SERIES];
	const char *name[PANEL_SERIES];
	const unsigned char *colour[PANEL_SERIES];
	const char *point_label[32]; /* written beside the first series' points, or NULL */
} panel;

static void fmt_tick(char *buf, size_t n, double v)
{
	if (v >= 1e4 && fabs(v - 1e3 * floor(v / 1e3 + 0.5)) < 1e-9 * v)
		snprintf(buf, n, "%gK", v / 1e3);
	else
		snprintf(buf, n, "%g", v);
}

/* 1, 2 or 5 times a power of 10, at least v (> 0). */
static double nice_step(double v)
{
	if (!(v > 0))
		return 1;
	const double p = pow(10, floor(log10(v))), f = v / p;
	return (f <= 1 ? 1 : f <= 2 ? 2 : f <= 5 ? 5 : 10) * p;
}

static void draw_panel(canvas *C, const panel *P, int bx, int by, int bw, int bh)
{
	static const unsigned char ink[3] = { 30, 30, 30 }, grid[3] = { 222, 222, 222 };
	const int L = bx + 80, R = bx + bw - 25, T = by + 64, B = by + bh - 45; /* the plot area */
	text(C, bx + 10, by + 10, 2, P->title, ink);
	/* the ranges */
	double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
	for (int k = 0; k < P->n; k++) {
		x0 = fmin(x0, P->x[k]), x1 = fmax(x1, P->x[k]);
		for (int s = 0; s < P->series; s++)
			if (P->y[k][s] > 0)
				y0 = fmin(y0, P->y[k][s]), y1 = fmax(y1, P->y[k][s]);
	}
	if (!(x1 >= x0) || !(y1 >= y0))
		return;
	if (P->logx)
		x0 = log10(x0), x1 = log10(x1);
	else
		x0 = 0;
	/* linear axes from 0 in round steps (1, 2 or 5 times a power of 10) */
	double xstep = 0, ystep = 0;
	if (P->logy) {
		y0 = floor(log10(y0)), y1 = ceil(log10(y1));
	} else {
		y0 = 0, ystep = nice_step(y1 / 5), y1 = ystep * ceil(y1 * 1.05 / ystep);
	}
	if (!P->logx)
		xstep = nice_step(x1 / 5), x1 = xstep * ceil(x1 * 1.05 / xstep);
	if (x1 - x0 < 1e-9)
		x0 -= 0.5, x1 += 0.5;
	if (y1 - y0 < 1e-9)
		y1 = y0 + 1;
#define PX(v) (L + ((P->logx ? log10(v) : (v)) - x0) / (x1 - x0) * (R - L))
#define PY(v) (B - ((P->logy ? log10(v) : (v)) - y0) / (y1 - y0) * (B - T))
	char buf[32];
	/* y ticks: decades (log) or 5 steps (linear) */
	const int yt = P->logy ? (int)(y1 - y0) : (int)(y1 / ystep + 0.5);
	for (int k = 0; k <= yt; k++) {
		const double v = P->logy ? pow(10, y0 + k) : ystep * k;
		const int y = (int)PY(v);
		rect(C, L, y, R, y, grid);
		fmt_tick(buf, sizeof buf, P->logy ? v : floor(v + 0.5));
		text(C, L - 8 - 8 * (int)strlen(buf), y - 5, 2, buf, ink);
	}
	/* x ticks: at the points (log) or 5 steps (linear) */
	const int xt = P->logx ? P->n : (int)(x1 / xstep + 0.5);
	for (int k = 0; k < xt + (P->logx ? 0 : 1); k++) {
		const double v = P->logx ? P->x[k] : xstep * k;
		const int x = (int)PX(v);
		rect(C, x, T, x, B, grid);
		fmt_tick(buf, sizeof buf, P->logx ? v : floor(v + 0.5));
		text(C, x - 4 * (int)strlen(buf), B + 8, 2, buf, ink);
	}
	rect(C, L, T, L + 1, B, ink), rect(C, L, B, R, B + 1, ink);
	text(C, (L + R) / 2 - 4 * (int)strlen(P->xlabel), B + 26, 2, P->xlabel, ink);
	text(C, bx + 10, by + 34, 2, P->ylabel, ink);
	/* the series: lines between the points, a square on each */
	for (int s = 0; s < P->series; s++) {
		double px = 0, py = 0;
		int have = 0;
		for (int k = 0; k < P->n; k++) {
			if (!(P->y[k][s] > 0))
				continue;
			const double x = PX(P->x[k]), y = PY(P->y[k][s]);
			if (have)
				line(C, px, py, x, y, P->colour[s]);
			rect(C, (int)x - 3, (int)y - 3, (int)x + 3, (int)y + 3, P->colour[s]);
			if (s == 0 && P->point_label[k])
				text(C, (int)x + 6, (int)y - 16, 2, P->point_label[k], ink);
			px = x, py = y, have = 1;
		}
	}
#undef PX
#undef PY
	/* the legend, top right */
	for (int s = 0; s < P->series && P->series > 1; s++) {
		const int y = T + 8 + 16 * s, x = R - 150;
		rect(C, x, y + 3, x + 20, y + 5, P->colour[s]);
		text(C, x + 28, y, 2, P->name[s], ink);
	}
}

static void write_plot(const char *path, const panel *p15, const panel *p16)
{
	canvas C = { NULL, 1280, 560 };
	C.img = malloc((size_t)C.w * C.h * 3);
	if (!C.img)
		die(2, "%s", "out of memory");
	memset(C.img, 255, (size_t)C.w * C.h * 3);
	draw_panel(&C, p15, 0, 0, C.w / 2, C.h);
	draw_panel(&C, p16, C.w / 2, 0, C.w / 2, C.h);
	write_png(path, C.img, C.w, C.h);
	free(C.img);
}

/* ---------------------------------------------------------------- */
/* Measuring                                                         */
/* ---------------------------------------------------------------- */

typedef struct result {
	double ms;
	int frames;
	uint64_t vertices;
	uint32_t hist[MLOD_RT_LAYERS][16];
	uint32_t fallbacks;
	size_t resident;
	double reskin; /* stale and split: the fraction of calls that skinned; -1 otherwise */
} result;

/* Runs the walk under sel; the histogram is the last measured frame's, and
 * so is the picture when pic is not NULL (drawn outside the measured time,
 * before any more streaming). */
static result run_mode(crowd *c, const mlod_rt_select *sel, double seconds, double fps, double max_wall, float near,
                       float far, picture *pic, float stale)
{
	result res;
	memset(&res, 0, sizeof res);
	res.reskin = -1;
	c->skin_stale = stale, c->stale_sel = sel, c->calls = c->skins = 0;
	if (stale >= 0) /* every instance never skinned (not measured) */
		memset(c->rec, 0, (size_t)c->n * c->rec_size);
	const float dt = (float)(1.0 / fps);
	const int frames = (int)(seconds * fps + 0.5) > 0 ? (int)(seconds * fps + 0.5) : 1;
	settle(c, sel);
	double total = 0;
	for (int f = 0; f < frames; f++) {
		walk(c, dt, near, far);
		total += frame(c, sel, dt, &res.vertices);
		res.frames++;
		if (f + 1 == frames || total > max_wall)
			break;
		/* streaming between frames, not measured */
		mlod_rt_stream(c->ctx, 256 * 1024, NULL, NULL);
		grow(c);
	}
	res.ms = 1000.0 * total / res.frames;
	if (stale >= 0)
		res.reskin = c->calls ? (double)c->skins / (double)c->calls : 0;
	c->skin_stale = -1;
	for (uint32_t i = 0; i < c->n; i++) {
		const mlod_rt_state *st = mlod_rt_instance_state(c->ctx, c->ids[i]);
		for (int l = 0; l < MLOD_RT_LAYERS; l++)
			res.hist[l][st->level[l] < 15 ? st->level[l] : 15]++;
		res.fallbacks += st->fallback != 0;
	}
	mlod_rt_stats s;
	mlod_rt_stats_get(c->ctx, &s);
	res.resident = s.resident_bytes;
	if (pic)
		render(c, pic);
	return res;
}

static void print_hist(const uint32_t *h, uint32_t levels)
{
	for (uint32_t l = 0; l < levels && l < 16; l++)
		printf(" %u", h[l]);
}

/* The LoD modes measured besides full detail: the runtime's rules
 * (mlod_rt_select_mode), then skeleton (the paper's Figure 15: the alpha
 * rule on the skeleton layer alone, mesh and motion at level 0). */
#define MODES 6
#define MODE_SKELETON 3
#define MODE_STALE 4 /* pixels at P, staleness Q (mlod_rt_skin_stale) */
#define MODE_SPLIT 5 /* pixels at P / 2, staleness P / 2 */
static const char *const mode_name[MODES] = { "alpha", "pixels", "toc", "skeleton", "stale", "split" };
_Static_assert(MODES + 1 <= PANEL_SERIES, "figure 15's panel holds full detail and every mode");

/* "alpha", "pixels", "toc", "skeleton", a comma list of them, or "all"
 * (every one): a bit per mode. */
static unsigned parse_modes(const char *s)
{
	if (!strcmp(s, "all"))
		return (1u << MODES) - 1;
	unsigned m = 0;
	for (const char *p = s; *p;) {
		size_t n = strcspn(p, ",");
		int k;
		for (k = 0; k < MODES; k++)
			if (strlen(mode_name[k]) == n && !strncmp(p, mode_name[k], n))
				break;
		if (k == MODES || n == 0)
			die(1, "unknown --mode '%s' (alpha, pixels, toc, skeleton, stale, split, a comma list of them, or all)", s);
		m |= 1u << k;
		p += n;
		if (*p == ',' && *++p == '\0')
			die(1, "unknown --mode '%s' (alpha, pixels, toc, skeleton, stale, split, a comma list of them, or all)", s);
	}
	return m;
}

/* The paper's Figures 15 and 16 as data (and, with plot_path, as a PNG
 * plot): Figure 15, the crowd's frame rate against N at full detail and
 * with LoD (fig15: frames per second per N and mode, full last, from the
 * runs above); Figure 16, one character at each mesh level with skeleton
 * and motion at level 0 (the paper's mesh LoD on one character), measured
 * here: the best of 5 runs of 0.05 s CPU each, one update and one skin
 * per frame. */
static void print_figures(crowd *c, const uint32_t *L, float near, float far, const uint32_t *sizes, uint32_t nsizes,
                          unsigned modes, double fig15[][MODES + 1], const char *plot_path)
{
	static const unsigned char colours[MODES + 1][3] = {
		{ 40, 150, 60 },  /* alpha: green */
		{ 40, 90, 200 },  /* pixels: blue */
		{ 150, 60, 170 }, /* toc: purple */
		{ 235, 140, 20 }, /* skeleton: orange */
		{ 20, 170, 190 }, /* stale: cyan */
		{ 110, 110, 110 }, /* split: grey */
		{ 200, 30, 30 },  /* full: red */
	};
	panel p15, p16;
	memset(&p15, 0, sizeof p15), memset(&p16, 0, sizeof p16);
	p15.title = "FIG 15: CROWD FRAME RATE, FULL AND LOD";
	p15.xlabel = "N (INSTANCES)", p15.ylabel = "FRAMES/S (CPU, ONE CORE)";
	p15.logx = p15.logy = 1;
	p15.n = nsizes < 32 ? (int)nsizes : 32;
	int order[MODES + 1], ns = 0;
	order[ns++] = MODES; /* full first */
	order[ns++] = MODE_SKELETON;
	for (int m = 0; m < 3; m++)
		order[ns++] = m;
	order[ns++] = MODE_STALE;
	order[ns++] = MODE_SPLIT;
	printf("\nfigure 15 (the crowd's frame rate against N: frames per second of CPU time, one core)\n%7s", "N");
	for (int i = 0; i < ns; i++)
		if (order[i] == MODES || (modes >> order[i] & 1)) {
			p15.name[p15.series] = order[i] == MODES ? "FULL" : mode_name[order[i]];
			p15.colour[p15.series] = colours[order[i]];
			for (int k = 0; k < p15.n; k++)
				p15.y[k][p15.series] = fig15[k][order[i]];
			p15.series++;
			printf(" %9s", order[i] == MODES ? "full" : mode_name[order[i]]);
		}
	printf("\n");
	for (int k = 0; k < p15.n; k++) {
		p15.x[k] = sizes[k];
		printf("%7u", sizes[k]);
		for (int i = 0; i < p15.series; i++)
			printf(" %9.2f", p15.y[k][i]);
		printf("\n");
	}

	/* Figure 16 */
	const uint32_t Lm = L[MLOD_RT_MESH];
	mlod_error e;
	mlod_rt_select sel;
	mlod_rt_select_default(&sel);
	sel.d_near = near, sel.d_far = far, sel.hysteresis = 0;
	for (int l = 0; l < MLOD_RT_LAYERS; l++)
		sel.t_start[l] = l == MLOD_RT_MESH ? 0.0f : 2.0f, sel.t_end[l] = l == MLOD_RT_MESH ? 1.0f : 2.0f;
	printf("\nfigure 16 (one character at each mesh level, skeleton and motion at level 0)\n"
	       "%5s %9s %9s %10s %10s %8s\n", "level", "triangles", "vertices", "us/frame", "frames/s", "speedup");
	p16.title = "FIG 16: ONE CHARACTER, MESH LEVELS";
	p16.xlabel = "TRIANGLES", p16.ylabel = "FRAMES/S (CPU, ONE CORE)";
	p16.series = 1, p16.name[0] = "MESH LOD", p16.colour[0] = colours[MLOD_RT_SELECT_PIXELS];
	static char labels[32][8];
	double us0 = 0;
	for (uint32_t k = 0; k < Lm && k < 32; k++) {
		uint32_t id;
		if (mlod_rt_instance_create(c->ctx, 0, 0, MLOD_RT_LOOP, &id, &e) != MLOD_OK)
			die(2, "%s", e.message);
		float d = Lm > 1 ? near + (far - near) * (float)k / (float)(Lm - 1) : near;
		c->ids[0] = id, c->dist[0] = d, c->n = 1;
		settle(c, &sel);
		const mlod_rt_state *st = mlod_rt_instance_state(c->ctx, id);
		double best = INFINITY;
		for (int rep = 0; rep < 5; rep++) {
			int frames = 0;
			double t0 = cpu_seconds(), t1;
			do {
				uint32_t nv;
				if (mlod_rt_update(c->ctx, &sel, &id, &d, 1, 1.0f / 30, &e) != MLOD_OK ||
				    skin_one(c, id, &nv, &e) != MLOD_OK)
					die(2, "%s", e.message);
				frames++;
				t1 = cpu_seconds();
			} while (t1 - t0 < 0.05);
			best = fmin(best, (t1 - t0) / frames);
		}
		const uint32_t shown = st->level[MLOD_RT_MESH];
		uint32_t tris = 0;
		for (uint32_t p = 0; p < mlod_rt_mesh_part_count(c->ctx, shown); p++) {
			mlod_rt_part_info pi;
			if (mlod_rt_mesh_part(c->ctx, shown, p, &pi, &e) == MLOD_OK)
				tris += pi.index_count / 3;
		}
		if (k == 0)
			us0 = 1e6 * best;
		printf("%5u %9u %9u %10.2f %10.0f %7.2fx%s\n", shown, tris, mlod_rt_mesh_vertex_count(c->ctx, shown),
		       1e6 * best, 1.0 / best, us0 / (1e6 * best), shown != k ? "  (not the level asked: not resident)" : "");
		p16.x[p16.n] = tris;
		p16.y[p16.n][0] = 1.0 / best;
		snprintf(labels[p16.n], sizeof labels[p16.n], "L%u", shown);
		p16.point_label[p16.n] = labels[p16.n];
		p16.n++;
		mlod_rt_instance_destroy(c->ctx, id);
	}
	c->n = 0;
	if (plot_path) {
		write_plot(plot_path, &p15, &p16);
		printf("plot: %s, 1280x560: figure 15 (frames per second against N, log-log) and figure 16 (frames per "
		       "second of one character against its mesh level's triangles)\n", plot_path);
	}
}

int main(int argc, char **argv)
{
	const char *counts = "1,10,50,250,1000,10000", *png_path = NULL, *plot_path = NULL;
	int figures = 0;
	double seconds = 2, fps = 30, max_wall = 10, hyst = 0.1, height = 1.8, pixels = -1, stale_px = 1;
	float near = 2, far = 200, ts = 0, te = 1;
	size_t budget = 0;
	int bench = 1, line = 0, png_w = 960, png_h = 540, png_mode = -1, pose_only = 0;
	unsigned long png_count = 0;
	unsigned modes = 1u << MLOD_RT_SELECT_ALPHA | 1u << MLOD_RT_SELECT_PIXELS;
	static const struct option longopts[] = {
		{ "counts", required_argument, NULL, 'n' },   { "seconds", required_argument, NULL, 's' },
		{ "fps", required_argument, NULL, 'f' },      { "max-wall", required_argument, NULL, 'w' },
		{ "budget", required_argument, NULL, 'b' },   { "near", required_argument, NULL, 'N' },
		{ "far", required_argument, NULL, 'F' },      { "mode", required_argument, NULL, 'm' },
		{ "hysteresis", required_argument, NULL, 'H' }, { "no-skin-bench", no_argument, NULL, 'k' },
		{ "interval", required_argument, NULL, 'I' }, { "spread", required_argument, NULL, 'S' },
		{ "height", required_argument, NULL, 'E' },   { "pixels", required_argument, NULL, 'P' },
		{ "png", required_argument, NULL, 'G' },      { "png-count", required_argument, NULL, 'C' },
		{ "png-size", required_argument, NULL, 'Z' }, { "png-mode", required_argument, NULL, 'M' },
		{ "figures", no_argument, NULL, 'g' },        { "plot", required_argument, NULL, 'p' },
		{ "work", required_argument, NULL, 'W' },     { "stale-pixels", required_argument, NULL, 'Q' },
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
		case 'E': {
			char *end;
			height = strtod(optarg, &end);
			if (end == optarg || *end || !isfinite(height) || height < 0)
				die(1, "bad --height '%s' (the character's height in metres, or 0 for scene units)", optarg);
			break;
		}
		case 'Q': {
			char *end;
			stale_px = strtod(optarg, &end);
			if (end == optarg || *end || !isfinite(stale_px) || !(stale_px >= 0))
				die(1, "bad --stale-pixels '%s' (a staleness in pixels, >= 0)", optarg);
			break;
		}
		case 'P': {
			char *end;
			pixels = strtod(optarg, &end);
			if (end == optarg || *end || !isfinite(pixels) || !(pixels > 0))
				die(1, "bad --pixels '%s' (a projected error in pixels, > 0)", optarg);
			break;
		}
		case 'G': png_path = optarg; break;
		case 'g': figures = 1; break;
		case 'p': plot_path = optarg, figures = 1; break;
		case 'C': {
			char *end;
			png_count = strtoul(optarg, &end, 10);
			if (end == optarg || *end || png_count == 0)
				die(1, "bad --png-count '%s'", optarg);
			break;
		}
		case 'Z':
			if (sscanf(optarg, "%dx%d", &png_w, &png_h) != 2 || png_w < 16 || png_h < 16 || png_w > 8192 ||
			    png_h > 8192)
				die(1, "bad --png-size '%s' (WxH, 16..8192 each)", optarg);
			break;
		case 'M': {
			int k;
			for (k = 0; k < MODES && strcmp(optarg, mode_name[k]); k++)
				;
			if (k == MODES)
				die(1, "unknown --png-mode '%s' (alpha, pixels, toc or skeleton)", optarg);
			png_mode = k;
			break;
		}
		case 'W':
			if (strcmp(optarg, "skin") && strcmp(optarg, "pose"))
				die(1, "unknown --work '%s' (skin or pose)", optarg);
			pose_only = !strcmp(optarg, "pose");
			break;
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
		case 'm': modes = parse_modes(optarg); break;
		case 'h': fputs(usage_text, stdout); return 0;
		case ':': die(1, "option '%s' needs a value", argv[optind - 1]);
		default: die(1, "unknown option '%s' (see --help)", argv[optind - 1]);
		}
	}
	if (optind + 1 != argc)
		die(1, "%s", "one PACK is needed (see --help)");
	check_output(png_path);
	check_output(plot_path);
	if (!(seconds > 0) || !(fps > 0) || !(far > near) || near < 0 || hyst < 0)
		die(1, "%s", "bad --seconds, --fps, --near/--far or --hysteresis");
	if (figures)
		modes |= 1u << MODE_SKELETON;
	if (png_mode >= 0 && !(modes >> png_mode & 1))
		die(1, "--png-mode %s is not among the measured --mode", mode_name[png_mode]);
	if (png_mode < 0)
		for (png_mode = 0; !(modes >> png_mode & 1); png_mode++)
			;
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
	if (png_count) {
		uint32_t k = 0;
		while (k < nsizes && sizes[k] != png_count)
			k++;
		if (k == nsizes)
			die(1, "--png-count is not one of the --counts '%s'", counts);
	} else
		png_count = maxn;

	mlod_rt_config cfg = { budget, maxn, NULL };
	mlod_error e;
	crowd c;
	memset(&c, 0, sizeof c);
	c.pose_only = pose_only;
	double t0 = cpu_seconds();
	mlod_result r = mlod_rt_open_path(path, &cfg, &c.ctx, &e);
	if (r != MLOD_OK)
		die(exit_code(r), "%s", e.message);
	double open_ms = 1000 * (cpu_seconds() - t0);
	if (!pose_only && mlod_rt_level_count(c.ctx, MLOD_RT_MESH) == 0) {
		/* Nothing to skin (a BVH's pack): measure the pose instead. */
		fprintf(stderr, "crowd: %s: no mesh to skin: measuring --work pose\n", path);
		pose_only = c.pose_only = 1;
	}
	size_t file_size = 0;
	void *file = read_file(path, &file_size);
	mlod_pack_info_rec info;
	if (!read_info(file, file_size, &info))
		die(2, "%s: cannot read the pack's INFO", path);
	/* Metres: the character is --height metres tall. */
	float scale = 1.0f;
	if (height > 0) {
		if (!(info.height > 0))
			die(2, "%s: the pack gives no character height: use --height 0 (scene units)", path);
		scale = info.height / (float)height;
	}
	const float near_u = near * scale, far_u = far * scale;
	c.scratch = mlod_rt_scratch_create(c.ctx);
	c.ids = malloc(sizeof *c.ids * maxn);
	c.dist = malloc(sizeof *c.dist * maxn);
	c.speed = malloc(sizeof *c.speed * maxn);
	c.azimuth = malloc(sizeof *c.azimuth * maxn);
	c.skin_stale = -1;
	c.rec_size = mlod_rt_stale_size(c.ctx);
	if (modes & (1u << MODE_STALE | 1u << MODE_SPLIT))
		c.rec = malloc(c.rec_size * maxn);
	if (!c.scratch || !c.ids || !c.dist || !c.speed || !c.azimuth ||
	    (modes & (1u << MODE_STALE | 1u << MODE_SPLIT) && !c.rec))
		die(2, "%s", "out of memory");
	grow(&c);
	c.cap0 = c.cap;

	const uint32_t clips = mlod_rt_clip_count(c.ctx);
	uint32_t L[MLOD_RT_LAYERS];
	for (int l = 0; l < MLOD_RT_LAYERS; l++)
		L[l] = mlod_rt_level_count(c.ctx, (mlod_rt_layer)l);
	mlod_rt_stats st;
	mlod_rt_stats_get(c.ctx, &st);
	mlod_rt_select lod;
	mlod_rt_select_default(&lod);
	if (pixels > 0)
		lod.max_pixels = (float)pixels;
	printf("%s: %u joints, %u clips; levels: skeleton %u, mesh %u, motion %u; open %.2f ms CPU, %zu bytes resident\n",
	       path, mlod_rt_joint_count(c.ctx), clips, L[0], L[1], L[2], open_ms, st.resident_bytes);
	const char *unit = height > 0 ? " m" : " scene units";
	if (height > 0)
		printf("scale %.4g scene units per metre (the character, %.4g units in the pack, taken as %g m tall); ", scale,
		       info.height, height);
	else
		printf("scale 1 (scene units; the character is %.4g units tall); ", info.height);
	printf("distances %g..%g%s spread %s\n", near, far, unit, line ? "along a line" : "over the ground");
	printf("budget %s%zu, hysteresis %g, %g s at %g fps per measurement; work: %s; modes: full",
	       budget ? "" : "none ", budget, hyst, seconds, fps,
	       pose_only ? "pose (motion sampling, pose and palette; no skinning)" : "skin (motion sampling, pose and skinning)");
	for (int k = 0; k < MODES; k++)
		if (modes >> k & 1) {
			if (k == MODE_SKELETON)
				printf(", skeleton (alpha on the skeleton layer alone, interval %g,%g)", ts, te);
			else if (k == MLOD_RT_SELECT_ALPHA)
				printf(", alpha (interval %g,%g)", ts, te);
			else if (k == MLOD_RT_SELECT_PIXELS)
				printf(", pixels (%g px at %g lines, fov %g deg)", lod.max_pixels, lod.lines,
				       lod.fov_y * 180.0 / 3.14159265358979323846);
			else if (k == MLOD_RT_SELECT_TOC)
				printf(", toc (the pack's switch distances)");
			else if (k == MODE_STALE)
				printf(", stale (pixels at %g px, skinned again when over %g px stale)", lod.max_pixels, stale_px);
			else
				printf(", split (pixels at %g px, skinned again when over %g px stale)", 0.5 * lod.max_pixels,
				       0.5 * lod.max_pixels);
		}
	printf("\n");
	if (modes & (1u << MODE_STALE | 1u << MODE_SPLIT))
		printf("stale and split: a record of %zu bytes per instance (mlod_rt_stale_size: 48 per joint, 4 per "
		       "morph weight, 32); frame dt %g s\n", c.rec_size, 1.0 / fps);
	/* Open to the first frame (one instance, the coarse levels open gave),
	 * then the decoding of every other level. */
	float bmin[3], bmax[3];
	{
		uint32_t id, nv = 0;
		float d = 0;
		mlod_rt_select sel;
		mlod_rt_select_default(&sel);
		t0 = cpu_seconds();
		if (mlod_rt_instance_create(c.ctx, 0, 0, 0, &id, &e) != MLOD_OK ||
		    mlod_rt_update(c.ctx, &sel, &id, &d, 1, 0, &e) != MLOD_OK || skin_one(&c, id, &nv, &e) != MLOD_OK)
			die(2, "%s", e.message);
		double first_ms = open_ms + 1000 * (cpu_seconds() - t0);
		mlod_rt_instance_destroy(c.ctx, id);
		/* The picture stands the characters on the ground by this frame's
		 * skinned bounds (clip 0 at time 0). */
		for (int k = 0; k < 3; k++)
			bmin[k] = nv ? INFINITY : 0, bmax[k] = nv ? -INFINITY : 0;
		for (uint32_t v = 0; v < nv; v++)
			for (int k = 0; k < 3; k++)
				bmin[k] = fminf(bmin[k], c.buf[3 * v + k]), bmax[k] = fmaxf(bmax[k], c.buf[3 * v + k]);
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
		printf("vertices skinned per mesh level:");
		for (uint32_t k = 0; k < L[MLOD_RT_MESH]; k++)
			printf(" %u", mlod_rt_mesh_vertex_count(c.ctx, k));
		printf("\n");
		if (c.regrows == 0)
			printf("skinning buffers: %u vertices, sized once at open (mlod_rt_max_vertex_count)\n", c.cap0);
		else
			printf("skinning buffers: %u vertices at open, %u once every level loaded (a pack before format 8.1 "
			       "states no largest level)\n", c.cap0, c.cap);
	}
	if (bench && L[MLOD_RT_MESH] > 0)
		skin_bench(file, file_size);

	mlod_rt_select full, sel[MODES];
	mlod_rt_select_default(&full);
	full.force_level = 0;
	lod.d_near = near_u, lod.d_far = far_u;
	lod.hysteresis = (float)hyst;
	for (int l = 0; l < MLOD_RT_LAYERS; l++)
		lod.t_start[l] = ts, lod.t_end[l] = te;
	for (int k = 0; k < 3; k++)
		sel[k] = lod, sel[k].mode = (mlod_rt_select_mode)k;
	/* skeleton: alpha over the interval for the skeleton layer; an
	 * interval past 1 keeps mesh and motion at level 0 */
	sel[MODE_SKELETON] = lod;
	sel[MODE_SKELETON].mode = MLOD_RT_SELECT_ALPHA;
	for (int l = 0; l < MLOD_RT_LAYERS; l++)
		if (l != MLOD_RT_SKELETON)
			sel[MODE_SKELETON].t_start[l] = sel[MODE_SKELETON].t_end[l] = 2.0f;
	/* stale: the pixel rule and a staleness of stale_px; split: half of
	 * --pixels for each, so that the sum is the pixel rule's */
	sel[MODE_STALE] = sel[MLOD_RT_SELECT_PIXELS];
	sel[MODE_SPLIT] = sel[MLOD_RT_SELECT_PIXELS];
	sel[MODE_SPLIT].max_pixels = 0.5f * lod.max_pixels;
	const float stale_of[MODES] = { -1, -1, -1, -1, (float)stale_px, 0.5f * lod.max_pixels };
	/* Figure 15's data: frames per second (CPU, one core) per N and mode
	 * (full last). */
	double fig15[32][MODES + 1];
	memset(fig15, 0, sizeof fig15);

	picture pic;
	memset(&pic, 0, sizeof pic);
	pic.path = png_path, pic.count = (uint32_t)png_count, pic.mode = png_mode;
	pic.width = png_w, pic.height = png_h, pic.scale = scale;
	pic.char_height = info.height > 0 ? info.height : bmax[1] - bmin[1];
	pic.center[0] = 0.5f * (bmin[0] + bmax[0]);
	pic.center[1] = bmin[1];
	pic.center[2] = 0.5f * (bmin[2] + bmax[2]);
	/* room for the limbs' motion */
	pic.radius = 0.75f * sqrtf((bmax[0] - bmin[0]) * (bmax[0] - bmin[0]) + (bmax[1] - bmin[1]) * (bmax[1] - bmin[1]) +
	                           (bmax[2] - bmin[2]) * (bmax[2] - bmin[2]));
	pic.near = near_u, pic.far = far_u, pic.mesh_levels = L[MLOD_RT_MESH];

	printf("\n%7s %-8s %11s %8s %8s  %-s\n", "N", "mode", "ms/frame", "speedup", pose_only ? "Mpal/s" : "Mvert/s",
	       "instances per level (skeleton | mesh | motion), resident bytes");
	for (uint32_t k = 0; k < nsizes; k++) {
		const uint32_t n = sizes[k];
		rng = 2463534242u;
		for (uint32_t i = 0; i < n; i++) {
			float t = frand() * 10;
			if (mlod_rt_instance_create(c.ctx, clips ? i % clips : 0, t, MLOD_RT_LOOP, &c.ids[i], &e) != MLOD_OK)
				die(2, "%s", e.message);
			float u = ((float)i + 0.5f) / (float)n;
			c.dist[i] = line ? near_u + (far_u - near_u) * u
			                 : sqrtf(near_u * near_u + u * (far_u * far_u - near_u * near_u));
			/* walking at 0.8..2 m/s, towards or away from the camera */
			c.speed[i] = (frand() < 0.5f ? -1.0f : 1.0f) * (0.8f + 1.2f * frand()) * scale;
			c.azimuth[i] = 2.39996323f * (float)i; /* the golden angle: even over the ring */
		}
		c.n = n;
		float *d0 = malloc(sizeof *d0 * n), *s0 = malloc(sizeof *s0 * n);
		memcpy(d0, c.dist, sizeof *d0 * n);
		memcpy(s0, c.speed, sizeof *s0 * n);
		result res[MODES + 1];
		res[MODES] = run_mode(&c, &full, seconds, fps, max_wall, near_u, far_u, NULL, -1);
		for (int m = 0; m < MODES; m++) {
			if (!(modes >> m & 1))
				continue;
			memcpy(c.dist, d0, sizeof *d0 * n); /* the same walk for every mode */
			memcpy(c.speed, s0, sizeof *s0 * n);
			res[m] = run_mode(&c, &sel[m], seconds, fps, max_wall, near_u, far_u,
			                  png_path && n == png_count && m == png_mode && !pic.done ? &pic : NULL, stale_of[m]);
		}
		free(d0), free(s0);
		const int want = (int)(seconds * fps + 0.5);
		for (int mm = 0; mm <= MODES; mm++) { /* full, then alpha, pixels, toc, skeleton */
			const int m = (mm + MODES) % (MODES + 1);
			if (m < MODES && !(modes >> m & 1))
				continue;
			const result *b = &res[m];
			if (k < 32)
				fig15[k][m] = 1000.0 / b->ms;
			if (m == MODES)
				printf("%7u %-8s %11.3f %8s", n, "full", b->ms, "");
			else
				printf("%7s %-8s %11.3f %7.2fx", "", mode_name[m], b->ms, res[MODES].ms / b->ms);
			printf(" %8.1f ", b->vertices / (b->ms * b->frames) / 1e3);
			print_hist(b->hist[0], L[0]);
			printf(" |");
			print_hist(b->hist[1], L[1]);
			printf(" |");
			print_hist(b->hist[2], L[2]);
			printf("  %zu B", b->resident);
			if (b->reskin >= 0)
				printf("  reskinned %.1f%%", 100 * b->reskin);
			if (b->fallbacks)
				printf("  (fallbacks %u)", b->fallbacks);
			if (b->frames < want)
				printf("  (frames %d of %d)", b->frames, want);
			printf("\n");
		}
		for (uint32_t i = 0; i < n; i++)
			mlod_rt_instance_destroy(c.ctx, c.ids[i]);
		fflush(stdout);
	}
	mlod_rt_stats_get(c.ctx, &st);
	printf("\nstreaming: %llu loads, %llu evictions, %llu failures; peak resident %zu bytes\n",
	       (unsigned long long)st.loads, (unsigned long long)st.evictions, (unsigned long long)st.failures,
	       st.peak_resident_bytes);
	if (figures)
		print_figures(&c, L, near_u, far_u, sizes, nsizes, modes, fig15, plot_path);
	if (png_path) {
		printf("picture: %s, %dx%d, N = %u, mode %s, the last measured frame: %u instances drawn (mesh levels",
		       png_path, png_w, png_h, pic.count, mode_name[pic.mode], pic.drawn);
		print_hist(pic.drawn_level, L[MLOD_RT_MESH]);
		printf("), %u triangles\n", pic.triangles);
	}
	mlod_rt_scratch_destroy(c.ctx, c.scratch);
	mlod_rt_close(c.ctx);
	free(c.ids), free(c.dist), free(c.speed), free(c.azimuth), free(c.buf), free(c.rec), free(file);
	return 0;
}
