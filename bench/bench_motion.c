/*
 * bench_motion.c: motion layer benchmarks.
 *
 *   bench_motion convert IN OUT.glb      writes IN (BVH, glTF) as glb
 *   bench_motion peers ORIG LABEL=FILE[@KEYS]...
 *                                        compares other tools' outputs of ORIG
 *                                        (gltfpack) with mlod's levels at the
 *                                        same error: per output, the keys, key
 *                                        bytes raw and compressed (gzip -9,
 *                                        zstd -19 on the same layout: times,
 *                                        then values as stored), and the max
 *                                        joint position error measured by
 *                                        mlod_joint_deviation; mlod's levels use
 *                                        per clip the peer's own error as bound.
 *                                        KEYS: the peer's key data as its file
 *                                        stores it (bench/anim-keys.mjs)
 *   bench_motion precision FILE...       the value precision modes and shares
 *                                        of the bound at 1% and 0.2%
 *   bench_motion methods FILE...         both methods (and both merges of the
 *                                        tree) at 0.2%, 1% and 3% of the height
 *   bench_motion speed FILE...           time to build the default levels
 *                                        (0.2%, 1%, 3%): clips/s and frames/s
 *   bench_motion pointerr ORIG LABEL=FILE...
 *                                        per clip of ORIG, the point error
 *                                        (mlod_motion_point_error, radius the
 *                                        point distance mlod-motion uses) of
 *                                        FILE's clip of that name against it,
 *                                        every joint (by name) at ORIG's common
 *                                        timeline frames and midpoints; End
 *                                        Sites are not points here. FILE may
 *                                        be a gltfpack output or an unpacked
 *                                        pack (mlod-pack -x), whose level 0
 *                                        carries the clip's own name; with
 *                                        POINTERR_DEBUG=E in the environment,
 *                                        each error above E (clip, time,
 *                                        joint) goes to stderr
 *   bench_motion rtlevels ORIG PACK      per clip and motion level of PACK
 *                                        (made from ORIG), its TOC error and
 *                                        the point error of the level as the
 *                                        runtime returns it (mlod_rt_pose,
 *                                        the level forced) against ORIG's
 *                                        clip, every joint the level poses,
 *                                        at ORIG's frames and midpoints (a
 *                                        pack made with --no-skeleton-levels
 *                                        poses every joint at every level)
 *
 * Prints Markdown tables. Times are medians of repeated runs. Clips and
 * joints of a peer's output are matched to the original by name.
 */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "bench.h"
#include "mlod.h"
#include "rt/mlod_rt.h"

#define MAX_PEERS 8
#define SPEED_RUNS 5

static int load(const char *path, mlod_character *c, mlod_gltf **doc)
{
	return bench_load("bench_motion", path, c, doc);
}

/* load, plus the skeleton height and the point distance mlod-motion uses
 * (mlod_motion_point_distance: height / 18 for BVH, 10 cm for glTF). */
static int load_sized(const char *path, mlod_character *c, double *h, double *pd)
{
	if (load(path, c, NULL) != 0)
		return -1;
	*h = mlod_skeleton_height(&c->skeleton);
	*pd = mlod_motion_point_distance(&c->skeleton, !strstr(path, ".bvh"));
	return 0;
}

/* ---------------------------------------------------------------- */
/* Key data: raw layout and compressed sizes                         */
/* ---------------------------------------------------------------- */

/* Appends a clip's key data as glTF holds it (times shared by channels
 * written once, then values) to f. */
static void write_keys(FILE *f, const mlod_clip *clip)
{
	for (int i = 0; i < clip->channel_count; i++) {
		const mlod_channel *ch = &clip->channels[i];
		int shared = 0;
		for (int k = 0; k < i && !shared; k++)
			shared = clip->channels[k].key_count == ch->key_count &&
			         memcmp(clip->channels[k].times, ch->times, sizeof(float) * (size_t)ch->key_count) == 0;
		if (!shared)
			fwrite(ch->times, sizeof(float), (size_t)ch->key_count, f);
	}
	for (int i = 0; i < clip->channel_count; i++) {
		const mlod_channel *ch = &clip->channels[i];
		size_t per = (ch->path == MLOD_PATH_ROTATION ? 4 : 3) * (ch->interp == MLOD_INTERP_CUBICSPLINE ? 3 : 1);
		for (size_t k = 0; ch->short_values && k < per * (size_t)ch->key_count; k++) {
			/* normalised shorts, little-endian, as the glTF writer stores them */
			long n = lrint((double)ch->values[k] * 32767.0);
			unsigned char b[2] = {(unsigned char)(n & 0xff), (unsigned char)((unsigned long)n >> 8 & 0xff)};
			fwrite(b, 1, 2, f);
		}
		if (!ch->short_values)
			fwrite(ch->values, sizeof(float), per * (size_t)ch->key_count, f);
	}
}

/* Compressed size of a file by a command ("gzip -9 -c"), or -1. */
static long compressed(const char *cmd, const char *path)
{
	char line[1024];
	snprintf(line, sizeof line, "%s < '%s' 2>/dev/null | wc -c", cmd, path);
	FILE *p = popen(line, "r");
	long n = -1;
	if (!p)
		return -1;
	if (fscanf(p, "%ld", &n) != 1)
		n = -1;
	if (pclose(p) != 0)
		n = -1;
	return n;
}

typedef struct sizes {
	long keys, raw, gz, zst;
} sizes;

static sizes clip_sizes(const mlod_clip *const *clips, int n)
{
	/* NULL entries are clips a peer lacks. */
	sizes s = {0, 0, -1, -1};
	char path[] = "/tmp/bench_motion.XXXXXX";
	int fd = mkstemp(path);
	FILE *f = fd >= 0 ? fdopen(fd, "wb") : NULL;
	for (int k = 0; k < n; k++) {
		if (!clips[k])
			continue;
		s.keys += mlod_clip_key_count(clips[k]);
		s.raw += mlod_clip_key_bytes(clips[k]);
		if (f)
			write_keys(f, clips[k]);
	}
	if (f) {
		fclose(f);
		s.gz = compressed("gzip -9 -c", path);
		s.zst = compressed("zstd -19 -c -q", path);
		unlink(path);
	}
	return s;
}

/* ---------------------------------------------------------------- */
/* Error of a peer's clip against the original, joints by name        */
/* ---------------------------------------------------------------- */

static int find_clip(const mlod_character *c, const char *name)
{
	for (int k = 0; k < c->clip_count; k++)
		if (strcmp(c->clips[k].name, name) == 0)
			return k;
	return -1;
}

static int *joint_map(const mlod_character *a, const mlod_character *b)
{
	int *map = malloc(sizeof(int) * (size_t)a->skeleton.joint_count);
	for (int j = 0; map && j < a->skeleton.joint_count; j++) {
		map[j] = -1;
		for (int k = 0; k < b->skeleton.joint_count && map[j] < 0; k++)
			if (strcmp(a->skeleton.joints[j].name, b->skeleton.joints[k].name) == 0)
				map[j] = k;
	}
	return map;
}

/* Max joint position error of clip kb of b against clip ka of a. */
static double clip_error(const mlod_character *a, int ka, const mlod_character *b, int kb, const int *map)
{
	mlod_character x = *a, y = *b;
	x.clip_count = y.clip_count = 1;
	x.clips = &a->clips[ka];
	y.clips = &b->clips[kb];
	mlod_deviation d;
	mlod_error err = {0};
	if (mlod_joint_deviation(&x, &y, NULL, map, 0, &d, &err) != MLOD_OK) {
		fprintf(stderr, "bench_motion: %s\n", err.message);
		return NAN;
	}
	return d.max;
}

/* Max and mean joint position error of clips (one per clip of a, in a's
 * order; NULL entries are a's own) carried by skeleton b (map: a's joint
 * -> b's; NULL when b is a). */
static mlod_deviation all_error(const mlod_character *a, const mlod_character *b, const mlod_clip *const *clips,
                                const int *map)
{
	mlod_character y = *b;
	mlod_clip *copy = malloc(sizeof *copy * (size_t)a->clip_count);
	mlod_deviation d = {NAN, NAN, 0};
	for (int k = 0; k < a->clip_count; k++)
		copy[k] = clips[k] ? *clips[k] : a->clips[k];
	y.clip_count = a->clip_count;
	y.clips = copy;
	mlod_error err = {0};
	if (mlod_joint_deviation(a, &y, NULL, map, 0, &d, &err) != MLOD_OK)
		fprintf(stderr, "bench_motion: %s\n", err.message);
	free(copy);
	return d;
}

/* Sizes of key data stored in a file (a peer's, as bench/anim-keys.mjs
 * extracts it from its glb); keys as counted in clips. */
static sizes file_sizes(const char *path, long keys)
{
	sizes s = {keys, -1, -1, -1};
	FILE *f = fopen(path, "rb");
	if (f) {
		fseek(f, 0, SEEK_END);
		s.raw = ftell(f);
		fclose(f);
		s.gz = compressed("gzip -9 -c", path);
		s.zst = compressed("zstd -19 -c -q", path);
	}
	return s;
}

/* mlod's level of clip k within bound, by method (-1: auto). */
static int our_level(const mlod_character *c, int k, int method, mlod_motion_precision precision, double bound,
                     double point_distance, mlod_motion_level *out)
{
	mlod_motion_options opt = {0};
	opt.point_distance = point_distance;
	opt.precision = precision;
	int have = 0;
	for (int m = 0; m < 2; m++) {
		if (method >= 0 && m != method)
			continue;
		mlod_motion *mo;
		mlod_motion_level l;
		mlod_error err = {0};
		if (mlod_motion_create(c, k, &opt, &mo, &err) != MLOD_OK)
			return -1;
		mlod_result r = mlod_motion_next_level(mo, (mlod_motion_method)m, MLOD_MOTION_MAX_ERROR, bound, &l, &err);
		mlod_motion_free(mo);
		if (r != MLOD_OK)
			continue;
		if (!have || l.bytes < out->bytes) {
			if (have)
				mlod_motion_level_free(out);
			*out = l;
			have = 1;
		} else {
			mlod_motion_level_free(&l);
		}
	}
	return have ? 0 : -1;
}

static void row(const char *label, sizes s, mlod_deviation e, double h, const sizes *ref, double ref_err)
{
	double err_pct = 100.0 * e.max / h;
	printf("| %s | %ld | %ld | %ld | %ld | %.4f | %.4f |", label, s.keys, s.raw, s.gz, s.zst, err_pct, 100.0 * e.mean / h);
	if (ref)
		printf(" %.2fx | %.2fx | %.2fx | %s |\n", (double)s.raw / (double)ref->raw, (double)s.gz / (double)ref->gz,
		       (double)s.zst / (double)ref->zst, err_pct <= ref_err + 1e-9 ? "yes" : "no");
	else
		printf(" | | | |\n");
}

static int cmd_peers(int argc, char **argv)
{
	mlod_character a;
	if (argc < 2 || load(argv[0], &a, NULL) != 0)
		return 1;
	double h = mlod_skeleton_height(&a.skeleton);
	double pd = mlod_motion_point_distance(&a.skeleton, !strstr(argv[0], ".bvh"));
	const mlod_clip **clips = malloc(sizeof *clips * (size_t)a.clip_count);
	for (int k = 0; k < a.clip_count; k++)
		clips[k] = &a.clips[k];
	sizes s0 = clip_sizes(clips, a.clip_count);
	printf("%s: %d clips, %d joints, height %.4g. Key data in bytes as each file stores it; "
	       "error: max world joint position error over all clips, %% of the height, measured by mlod.\n\n",
	       bench_base_name(argv[0]), a.clip_count, a.skeleton.joint_count, h);
	printf("| output | keys | raw | gzip -9 | zstd -19 | max error %% | mean error %% | raw vs peer | gzip vs peer | zstd vs peer | max error <= peer |\n");
	printf("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|:---:|\n");
	mlod_deviation zero = {0, 0, 0};
	row("input", s0, zero, h, NULL, 0.0);
	for (int p = 1; p < argc; p++) {
		char label[256], file[1024];
		const char *eq = strchr(argv[p], '='), *at = eq ? strchr(eq, '@') : NULL;
		if (!eq)
			continue;
		snprintf(label, sizeof label, "%.*s", (int)(eq - argv[p]), argv[p]);
		snprintf(file, sizeof file, "%.*s", (int)(at ? at - eq - 1 : (long)strlen(eq + 1)), eq + 1);
		mlod_character b;
		if (load(file, &b, NULL) != 0)
			continue;
		int *map = joint_map(&a, &b);
		const mlod_clip **pc = calloc((size_t)a.clip_count, sizeof *pc);
		double *bound = malloc(sizeof(double) * (size_t)a.clip_count);
		for (int k = 0; k < a.clip_count; k++) {
			int kb = find_clip(&b, a.clips[k].name);
			bound[k] = -1.0;
			if (kb < 0) {
				fprintf(stderr, "bench_motion: %s has no clip \"%s\"\n", label, a.clips[k].name);
				continue;
			}
			pc[k] = &b.clips[kb];
			bound[k] = clip_error(&a, k, &b, kb, map);
		}
		sizes sp = clip_sizes(pc, a.clip_count);
		if (at) /* the bytes the peer stores (gltfpack keeps rotations as normalised shorts) */
			sp = file_sizes(at + 1, sp.keys);
		mlod_deviation pe = all_error(&a, &b, pc, map);
		row(label, sp, pe, h, NULL, 0.0);
		/* mlod at the peer's own max error, clip by clip, then at fixed bounds:
		 * mlod-motion's default method and precision (auto, auto), then variants. */
		static const struct {
			const char *name;
			int method;
			mlod_motion_precision precision;
		} runs[] = {
			{"mlod", -1, MLOD_MOTION_PRECISION_AUTO},
			{"mlod --precision float", -1, MLOD_MOTION_PRECISION_FLOAT},
			{"mlod --precision full", -1, MLOD_MOTION_PRECISION_FULL},
			{"mlod -m frames", MLOD_MOTION_FRAMES, MLOD_MOTION_PRECISION_AUTO},
			{"mlod -m keys", MLOD_MOTION_KEYS, MLOD_MOTION_PRECISION_AUTO},
		};
		static const double fixed[] = {-1.0, 0.01, 0.002};
		for (int f = 0; f < 3; f++)
			for (int v = 0; v < (int)(sizeof runs / sizeof runs[0]); v++) {
				if (f > 0 && v > 1)
					continue;
				mlod_motion_level *lv = calloc((size_t)a.clip_count, sizeof *lv);
				const mlod_clip **oc = calloc((size_t)a.clip_count, sizeof *oc);
				for (int k = 0; k < a.clip_count; k++) {
					double bk = fixed[f] > 0.0 ? fixed[f] * h : bound[k];
					if (bk >= 0.0 && our_level(&a, k, runs[v].method, runs[v].precision, bk, pd, &lv[k]) == 0)
						oc[k] = &lv[k].clip;
					else
						oc[k] = &a.clips[k]; /* no level: the clip as read */
				}
				char l2[320];
				/* Say the options: -e per clip (the peer's max error on it, not
				 * a default level) or a fixed -e in % of the height. */
				if (f == 0)
					snprintf(l2, sizeof l2, "%s -e (%s's max error on each clip)", runs[v].name, label);
				else
					snprintf(l2, sizeof l2, "%s -e %g%%", runs[v].name, 100.0 * fixed[f]);
				row(l2, clip_sizes(oc, a.clip_count), all_error(&a, &a, oc, NULL), h, &sp, 100.0 * pe.max / h);
				for (int k = 0; k < a.clip_count; k++)
					mlod_motion_level_free(&lv[k]);
				free(lv);
				free(oc);
			}
		free(map);
		free(pc);
		free(bound);
		mlod_character_free(&b);
	}
	printf("\n");
	free(clips);
	mlod_character_free(&a);
	return 0;
}

/* ---------------------------------------------------------------- */
/* Value precision: modes and the share of the bound left to rounding */
/* ---------------------------------------------------------------- */

static int cmd_precision(int argc, char **argv)
{
	static const double pct[2] = {1.0, 0.2};
	static const struct {
		mlod_motion_precision precision;
		double share;
	} runs[] = {
		{MLOD_MOTION_PRECISION_FULL, 0.0},   {MLOD_MOTION_PRECISION_FLOAT, 0.05}, {MLOD_MOTION_PRECISION_FLOAT, 0.1},
		{MLOD_MOTION_PRECISION_FLOAT, 0.2},  {MLOD_MOTION_PRECISION_FLOAT, 0.3},  {MLOD_MOTION_PRECISION_FLOAT, 0.5},
		{MLOD_MOTION_PRECISION_AUTO, 0.05},  {MLOD_MOTION_PRECISION_AUTO, 0.1},   {MLOD_MOTION_PRECISION_AUTO, 0.2},
		{MLOD_MOTION_PRECISION_AUTO, 0.3},   {MLOD_MOTION_PRECISION_AUTO, 0.5},
	};
	static const char *const names[] = {"auto", "float", "full"};
	printf("| character | precision | share | keys at 1%% | raw | gzip -9 | zstd -19 | keys at 0.2%% | raw | gzip -9 | zstd -19 |\n");
	printf("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
	for (int i = 0; i < argc; i++) {
		mlod_character c;
		double h, pd;
		if (load_sized(argv[i], &c, &h, &pd) != 0)
			continue;
		for (int v = 0; v < (int)(sizeof runs / sizeof runs[0]); v++) {
			printf("| %s | %s | %s", bench_base_name(argv[i]), names[runs[v].precision], runs[v].share > 0.0 ? "" : "-");
			if (runs[v].share > 0.0)
				printf("%g", runs[v].share);
			printf(" |");
			for (int b = 0; b < 2; b++) {
				mlod_motion_level *lv = calloc((size_t)c.clip_count, sizeof *lv);
				const mlod_clip **oc = calloc((size_t)c.clip_count, sizeof *oc);
				for (int k = 0; k < c.clip_count; k++) {
					mlod_motion_options opt = {0};
					opt.point_distance = pd;
					opt.precision = runs[v].precision;
					opt.precision_share = runs[v].share;
					mlod_motion *m;
					mlod_error err = {0};
					oc[k] = &c.clips[k];
					if (mlod_motion_create(&c, k, &opt, &m, &err) != MLOD_OK)
						continue;
					if (mlod_motion_next_level(m, MLOD_MOTION_KEYS, MLOD_MOTION_MAX_ERROR, pct[b] * h / 100.0, &lv[k],
					                           &err) == MLOD_OK)
						oc[k] = &lv[k].clip;
					mlod_motion_free(m);
				}
				sizes sz = clip_sizes(oc, c.clip_count);
				printf(" %ld | %ld | %ld | %ld |", sz.keys, sz.raw, sz.gz, sz.zst);
				for (int k = 0; k < c.clip_count; k++)
					mlod_motion_level_free(&lv[k]);
				free(lv);
				free(oc);
			}
			printf("\n");
		}
		mlod_character_free(&c);
	}
	printf("\n");
	return 0;
}

/* ---------------------------------------------------------------- */
/* Methods at fixed bounds                                           */
/* ---------------------------------------------------------------- */

static int cmd_methods(int argc, char **argv)
{
	static const double pct[3] = {0.2, 1.0, 3.0};
	printf("| character | clips | keys | method | keys at 0.2%% | bytes | keys at 1%% | bytes | keys at 3%% | bytes | vs tree (remove) at 1%% |\n");
	printf("|---|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|\n");
	for (int i = 0; i < argc; i++) {
		mlod_character c;
		double h, pd;
		if (load_sized(argv[i], &c, &h, &pd) != 0)
			continue;
		long keys0 = 0, ref = 0;
		for (int k = 0; k < c.clip_count; k++)
			keys0 += mlod_clip_key_count(&c.clips[k]);
		static const char *const names[] = {"tree, remove", "tree, average", "keys"};
		for (int v = 0; v < 3; v++) {
			long keys[3] = {0}, bytes[3] = {0};
			for (int k = 0; k < c.clip_count; k++) {
				mlod_motion_options opt = {0};
				opt.point_distance = pd;
				opt.merge = v == 1 ? MLOD_MOTION_AVERAGE : MLOD_MOTION_REMOVE;
				mlod_motion *m;
				mlod_error err = {0};
				if (mlod_motion_create(&c, k, &opt, &m, &err) != MLOD_OK)
					continue;
				for (int l = 0; l < 3; l++) {
					mlod_motion_level lv;
					if (mlod_motion_next_level(m, v == 2 ? MLOD_MOTION_KEYS : MLOD_MOTION_FRAMES, MLOD_MOTION_MAX_ERROR,
					                           pct[l] * h / 100.0, &lv, &err) != MLOD_OK)
						continue;
					keys[l] += lv.keys;
					bytes[l] += lv.bytes;
					mlod_motion_level_free(&lv);
				}
				mlod_motion_free(m);
			}
			if (v == 0)
				ref = bytes[1];
			printf("| %s | %d | %ld | %s | %ld | %ld | %ld | %ld | %ld | %ld | %.2fx |\n", bench_base_name(argv[i]),
			       c.clip_count, keys0, names[v], keys[0], bytes[0], keys[1], bytes[1], keys[2], bytes[2],
			       (double)bytes[1] / (double)ref);
		}
		mlod_character_free(&c);
	}
	printf("\n");
	return 0;
}

/* ---------------------------------------------------------------- */
/* Speed                                                             */
/* ---------------------------------------------------------------- */

static int cmd_speed(int argc, char **argv)
{
	static const double pct[3] = {0.2, 1.0, 3.0};
	printf("| file | clips | frames | joints | method | ms per clip (3 levels) | clips/s | input frames/s |\n");
	printf("|---|---:|---:|---:|---|---:|---:|---:|\n");
	for (int i = 0; i < argc; i++) {
		mlod_character c;
		if (load(argv[i], &c, NULL) != 0)
			continue;
		double h = mlod_skeleton_height(&c.skeleton);
		long frames = 0;
		for (int k = 0; k < c.clip_count; k++) {
			float *t = NULL;
			int n = mlod_clip_times(&c.clips[k], 0, &t);
			mlod_free(t);
			frames += n > 0 ? n : 0;
		}
		static const char *const names[] = {"frames", "keys", "auto (as mlod-motion)"};
		for (int v = 0; v < 3; v++) {
			double runs[SPEED_RUNS];
			for (int r = 0; r < SPEED_RUNS; r++) {
				double t0 = bench_now();
				for (int k = 0; k < c.clip_count && v == 2; k++) {
					/* The tool's default: mlod_motion_next_level_best, the keys
					 * level first, the frames level stopping where it cannot win. */
					static const mlod_motion_method both[2] = {MLOD_MOTION_FRAMES, MLOD_MOTION_KEYS};
					mlod_motion_options opt = {0};
					opt.point_distance = mlod_motion_point_distance(&c.skeleton, !strstr(argv[i], ".bvh"));
					mlod_motion *mo[2] = {NULL, NULL};
					mlod_error err = {0};
					if (mlod_motion_create(&c, k, &opt, &mo[0], &err) == MLOD_OK &&
					    mlod_motion_create(&c, k, &opt, &mo[1], &err) == MLOD_OK)
						for (int l = 0; l < 3; l++) {
							mlod_motion_level lv;
							if (mlod_motion_next_level_best(mo, both, 2, MLOD_MOTION_MAX_ERROR, pct[l] * h / 100.0, &lv,
							                                &err) == MLOD_OK)
								mlod_motion_level_free(&lv);
						}
					mlod_motion_free(mo[0]);
					mlod_motion_free(mo[1]);
				}
				for (int k = 0; k < c.clip_count && v < 2; k++)
					for (int m = 0; m < 2; m++) {
						if (m != v)
							continue;
						mlod_motion_options opt = {0};
						opt.point_distance = mlod_motion_point_distance(&c.skeleton, !strstr(argv[i], ".bvh"));
						mlod_motion *mo;
						mlod_error err = {0};
						if (mlod_motion_create(&c, k, &opt, &mo, &err) != MLOD_OK)
							continue;
						for (int l = 0; l < 3; l++) {
							mlod_motion_level lv;
							if (mlod_motion_next_level(mo, (mlod_motion_method)m, MLOD_MOTION_MAX_ERROR, pct[l] * h / 100.0,
							                           &lv, &err) == MLOD_OK)
								mlod_motion_level_free(&lv);
						}
						mlod_motion_free(mo);
					}
				runs[r] = bench_now() - t0;
			}
			double t = bench_median(runs, SPEED_RUNS);
			printf("| %s | %d | %ld | %d | %s | %.1f | %.1f | %.0f |\n", bench_base_name(argv[i]), c.clip_count, frames,
			       c.skeleton.joint_count, names[v], 1000.0 * t / c.clip_count, c.clip_count / t, (double)frames / t);
		}
		mlod_character_free(&c);
	}
	printf("\n");
	return 0;
}

/* ---------------------------------------------------------------- */
/* Between frames                                                     */
/* ---------------------------------------------------------------- */

#define DENSE 16 /* samples per frame interval of the dense error */

/* Max joint position error of a level of clip k of c, DENSE samples per
 * interval of the clip's own key times. */
static double dense_error(const mlod_character *c, int k, const mlod_clip *level)
{
	float *t = NULL, *st;
	int n = mlod_clip_times(&c->clips[k], 0, &t);
	if (n <= 0)
		return NAN;
	st = malloc(sizeof(float) * ((size_t)(n - 1) * DENSE + 1));
	mlod_motion_sample_times(t, n, DENSE, st);
	mlod_character a = *c, b = *c;
	a.clip_count = b.clip_count = 1;
	a.clips = &c->clips[k];
	b.clips = (mlod_clip *)level;
	mlod_deviation d = {NAN, NAN, 0};
	mlod_error err = {0};
	if (mlod_joint_deviation_at(&a, &b, st, (n - 1) * DENSE + 1, &d, &err) != MLOD_OK)
		fprintf(stderr, "bench_motion: %s\n", err.message);
	mlod_free(t);
	free(st);
	return d.max;
}

/* Levels (auto: the method with fewer bytes) checked at the frames only
 * and with samples between them: keys, bytes, time, and the error found
 * between frames (DENSE samples per interval) against the bound. */
static int cmd_between(int argc, char **argv)
{
	static const double pct[3] = {0.2, 1.0, 3.0};
	static const int subs[3] = {1, 2, 4};
	printf("Default levels (0.2%%, 1%%, 3%% of the height; auto method) with the bound checked at the frames only "
	       "(subdivide 1), also at the midpoints (2) or at 3 times between frames (4). Dense error: the largest joint "
	       "position error at %d samples per frame interval, over the bound; levels over: how many of the levels "
	       "exceed their bound there.\n\n", DENSE);
	printf("| file | clips | subdivide | keys | bytes | ms (3 levels, all clips) | dense error / bound, worst | levels over |\n");
	printf("|---|---:|---:|---:|---:|---:|---:|---:|\n");
	for (int i = 0; i < argc; i++) {
		mlod_character c;
		double h, pd;
		if (load_sized(argv[i], &c, &h, &pd) != 0)
			continue;
		for (int v = 0; v < 3; v++) {
			long keys = 0, bytes = 0;
			int over = 0, levels = 0;
			double worst = 0.0, ms = 0.0;
			for (int k = 0; k < c.clip_count; k++) {
				mlod_motion_options opt = {0};
				opt.point_distance = pd;
				opt.subdivide = subs[v];
				mlod_motion *mo[2];
				mlod_error err = {0};
				double t0 = bench_now();
				if (mlod_motion_create(&c, k, &opt, &mo[0], &err) != MLOD_OK)
					continue;
				if (mlod_motion_create(&c, k, &opt, &mo[1], &err) != MLOD_OK) {
					mlod_motion_free(mo[0]);
					continue;
				}
				mlod_motion_level best[3];
				int have[3] = {0, 0, 0};
				for (int l = 0; l < 3; l++)
					for (int m = 0; m < 2; m++) {
						mlod_motion_level lv;
						if (mlod_motion_next_level(mo[m], (mlod_motion_method)m, MLOD_MOTION_MAX_ERROR, pct[l] * h / 100.0,
						                           &lv, &err) != MLOD_OK)
							continue;
						if (!have[l] || lv.bytes < best[l].bytes) {
							if (have[l])
								mlod_motion_level_free(&best[l]);
							best[l] = lv;
							have[l] = 1;
						} else {
							mlod_motion_level_free(&lv);
						}
					}
				ms += 1000.0 * (bench_now() - t0);
				for (int l = 0; l < 3; l++) {
					if (!have[l])
						continue;
					double e = dense_error(&c, k, &best[l].clip) / (pct[l] * h / 100.0);
					keys += best[l].keys;
					bytes += best[l].bytes;
					levels++;
					over += e > 1.0;
					if (!(e <= worst))
						worst = e;
					mlod_motion_level_free(&best[l]);
				}
				mlod_motion_free(mo[0]);
				mlod_motion_free(mo[1]);
			}
			printf("| %s | %d | %d | %ld | %ld | %.0f | %.4f | %d of %d |\n", bench_base_name(argv[i]), c.clip_count, subs[v],
			       keys, bytes, ms, worst, over, levels);
		}
		mlod_character_free(&c);
	}
	printf("\n");
	return 0;
}

static int cmd_convert(int argc, char **argv)
{
	mlod_character c;
	mlod_gltf *doc = NULL;
	if (argc != 2 || load(argv[0], &c, &doc) != 0)
		return 1;
	void *data = NULL;
	size_t size = 0;
	mlod_error err = {0};
	int rc = 1;
	if (mlod_gltf_write(doc, 1, &data, &size, &err) == MLOD_OK) {
		FILE *f = fopen(argv[1], "wb");
		if (f && fwrite(data, 1, size, f) == size)
			rc = 0;
		if (f)
			fclose(f);
	}
	if (rc)
		fprintf(stderr, "bench_motion: %s: cannot write\n", argv[1]);
	mlod_free(data);
	mlod_gltf_free(doc);
	mlod_character_free(&c);
	return rc;
}

/* ---------------------------------------------------------------- */
/* Point error of another file's clips, sampled independently         */
/* ---------------------------------------------------------------- */

static int cmp_double(const void *x, const void *y)
{
	double a = *(const double *)x, b = *(const double *)y;
	return (a > b) - (a < b);
}

static int cmd_pointerr(int argc, char **argv)
{
	mlod_character a;
	double h, pd;
	if (argc < 2 || load_sized(argv[0], &a, &h, &pd) != 0)
		return 1;
	printf("%s: %d clips, %d joints, height %.4g, point distance %.4g. Point error per clip at the frames and "
	       "midpoints: max and mean over joints and samples, p99 of each sample's largest; scene units and %% of "
	       "the height.\n\n",
	       bench_base_name(argv[0]), a.clip_count, a.skeleton.joint_count, h, pd);
	printf("| file | clip | samples | max | max %% | p99 %% | mean %% |\n|---|---|---:|---:|---:|---:|---:|\n");
	int rc = 0;
	for (int p = 1; p < argc; p++) {
		const char *eq = strchr(argv[p], '=');
		mlod_character b;
		if (!eq || load(eq + 1, &b, NULL) != 0) {
			rc = 1;
			continue;
		}
		int label_len = (int)(eq - argv[p]);
		int *map = joint_map(&a, &b);
		int nj = a.skeleton.joint_count, njb = b.skeleton.joint_count;
		mlod_trs *la = malloc(sizeof *la * (size_t)nj), *lb = malloc(sizeof *lb * (size_t)njb);
		mlod_mat4 *wa = malloc(sizeof *wa * (size_t)nj), *wb = malloc(sizeof *wb * (size_t)njb);
		double all_max = 0;
		for (int k = 0; k < a.clip_count; k++) {
			int kb = find_clip(&b, a.clips[k].name);
			mlod_motion_options mo = {0};
			mlod_clip common;
			mlod_error err = {0};
			if (kb < 0 || mlod_motion_common_clip(&a.clips[k], &mo, &common, NULL, &err) != MLOD_OK) {
				printf("| %.*s | %s | - | - | - | - | - |\n", label_len, argv[p], a.clips[k].name);
				rc = 1;
				continue;
			}
			int frames = common.channels[0].key_count, n = (frames - 1) * 2 + 1;
			float *t = malloc(sizeof *t * (size_t)n);
			double *peak = malloc(sizeof *peak * (size_t)n), mx = 0, sum = 0;
			long cnt = 0;
			mlod_motion_sample_times(common.channels[0].times, frames, 2, t);
			for (int i = 0; i < n; i++) {
				mlod_pose_rest(&a.skeleton, la);
				mlod_clip_sample(&a.clips[k], t[i], la);
				mlod_pose_world(&a.skeleton, la, wa);
				mlod_pose_rest(&b.skeleton, lb);
				mlod_clip_sample(&b.clips[kb], t[i], lb);
				mlod_pose_world(&b.skeleton, lb, wb);
				peak[i] = 0;
				for (int j = 0; j < nj; j++) {
					if (map[j] < 0)
						continue;
					double e = mlod_motion_point_error(&wa[j], &wb[map[j]], pd);
					if (getenv("POINTERR_DEBUG") && e > atof(getenv("POINTERR_DEBUG")))
						fprintf(stderr, "clip %s t %.5f joint %s err %g\n", a.clips[k].name, t[i],
						        a.skeleton.joints[j].name, e);
					peak[i] = e > peak[i] ? e : peak[i];
					sum += e;
					cnt++;
				}
				mx = peak[i] > mx ? peak[i] : mx;
			}
			qsort(peak, (size_t)n, sizeof *peak, cmp_double);
			double p99 = peak[(size_t)floor(0.99 * (n - 1))];
			printf("| %.*s | %s | %d | %.6g | %.4f | %.4f | %.5f |\n", label_len, argv[p], a.clips[k].name, n, mx,
			       100.0 * mx / h, 100.0 * p99 / h, cnt ? 100.0 * sum / (double)cnt / h : 0.0);
			all_max = mx > all_max ? mx : all_max;
			free(t);
			free(peak);
			mlod_clip_free(&common);
		}
		printf("| %.*s | all | | %.6g | %.4f | | |\n", label_len, argv[p], all_max, 100.0 * all_max / h);
		free(la), free(lb), free(wa), free(wb), free(map);
		mlod_character_free(&b);
	}
	printf("\n");
	mlod_character_free(&a);
	return rc;
}

static int cmd_rtlevels(int argc, char **argv)
{
	mlod_character a;
	double h, pd;
	if (argc != 2 || load_sized(argv[0], &a, &h, &pd) != 0)
		return 1;
	mlod_rt_ctx *ctx = NULL;
	mlod_error err = {0};
	if (mlod_rt_open_path(argv[1], NULL, &ctx, &err) != MLOD_OK) {
		fprintf(stderr, "bench_motion: %s: %s\n", argv[1], err.message);
		mlod_character_free(&a);
		return 1;
	}
	int nj = a.skeleton.joint_count, rc = 0;
	if ((int)mlod_rt_joint_count(ctx) != nj || (int)mlod_rt_clip_count(ctx) != a.clip_count) {
		fprintf(stderr, "bench_motion: %s: %u joints and %u clips, %s %d and %d\n", argv[1],
		        mlod_rt_joint_count(ctx), mlod_rt_clip_count(ctx), argv[0], nj, a.clip_count);
		mlod_rt_close(ctx);
		mlod_character_free(&a);
		return 1;
	}
	printf("%s (%s): height %.4g, point distance %.4g. Per clip and motion level: the TOC error and the point "
	       "error of the level as mlod_rt_pose returns it against the input, at its frames and midpoints; scene "
	       "units and %% of the height.\n\n",
	       bench_base_name(argv[1]), bench_base_name(argv[0]), h, pd);
	printf("| clip | level | TOC error | TOC %% | measured | measured %% | measured / TOC |\n"
	       "|---|---:|---:|---:|---:|---:|---:|\n");
	mlod_rt_scratch *sc = mlod_rt_scratch_create(ctx);
	mlod_trs *la = malloc(sizeof *la * (size_t)nj);
	mlod_mat4 *wa = malloc(sizeof *wa * (size_t)nj);
	for (int k = 0; sc && la && wa && k < a.clip_count && rc == 0; k++) {
		mlod_motion_options mo = {0};
		mlod_clip common;
		if (mlod_motion_common_clip(&a.clips[k], &mo, &common, NULL, &err) != MLOD_OK) {
			rc = 1;
			break;
		}
		int frames = common.channels[0].key_count, n = (frames - 1) * 2 + 1;
		float *t = malloc(sizeof *t * (size_t)n);
		mlod_motion_sample_times(common.channels[0].times, frames, 2, t);
		for (uint32_t l = 0; t && l < mlod_rt_level_count(ctx, MLOD_RT_MOTION) && rc == 0; l++) {
			mlod_rt_level_info li;
			mlod_rt_select sel;
			mlod_rt_select_default(&sel);
			sel.force_level = (int)l;
			uint32_t id = 0;
			float d = 0;
			double mx = 0;
			if (mlod_rt_level_info_get(ctx, MLOD_RT_MOTION, l, (uint32_t)k, &li, &err) != MLOD_OK ||
			    mlod_rt_instance_create(ctx, (uint32_t)k, 0.0f, 0, &id, &err) != MLOD_OK ||
			    mlod_rt_update(ctx, &sel, &id, &d, 1, 0.0f, &err) != MLOD_OK ||
			    mlod_rt_stream(ctx, SIZE_MAX, NULL, &err) != MLOD_OK ||
			    mlod_rt_update(ctx, &sel, &id, &d, 1, 0.0f, &err) != MLOD_OK) {
				rc = 1;
				break;
			}
			for (int i = 0; i < n && rc == 0; i++) {
				const float *W = NULL;
				const uint32_t *kept = NULL;
				uint32_t nk = 0;
				if (mlod_rt_instance_set(ctx, id, (uint32_t)k, t[i], 0, &err) != MLOD_OK ||
				    mlod_rt_pose(ctx, sc, id, &W, &kept, &nk, &err) != MLOD_OK) {
					rc = 1;
					break;
				}
				mlod_pose_rest(&a.skeleton, la);
				mlod_clip_sample(&a.clips[k], t[i], la);
				mlod_pose_world(&a.skeleton, la, wa);
				for (uint32_t q = 0; q < nk; q++) {
					mlod_mat4 r;
					memcpy(r.m, W + 16 * (size_t)kept[q], sizeof r.m);
					double e = mlod_motion_point_error(&wa[kept[q]], &r, pd);
					mx = e > mx ? e : mx;
				}
			}
			mlod_rt_instance_destroy(ctx, id);
			printf("| %s | %u | %.6g | %.5f | %.6g | %.5f | %.4f |\n", a.clips[k].name, l, (double)li.error,
			       100.0 * li.error / h, mx, 100.0 * mx / h, li.error > 0 ? mx / li.error : 0.0);
		}
		free(t);
		mlod_clip_free(&common);
	}
	if (rc)
		fprintf(stderr, "bench_motion: %s: %s\n", argv[1], err.message);
	printf("\n");
	free(la), free(wa);
	if (sc)
		mlod_rt_scratch_destroy(ctx, sc);
	mlod_rt_close(ctx);
	mlod_character_free(&a);
	return rc;
}

int main(int argc, char **argv)
{
	if (argc >= 2 && strcmp(argv[1], "convert") == 0)
		return cmd_convert(argc - 2, argv + 2);
	if (argc >= 2 && strcmp(argv[1], "peers") == 0)
		return cmd_peers(argc - 2, argv + 2);
	if (argc >= 2 && strcmp(argv[1], "precision") == 0)
		return cmd_precision(argc - 2, argv + 2);
	if (argc >= 2 && strcmp(argv[1], "methods") == 0)
		return cmd_methods(argc - 2, argv + 2);
	if (argc >= 2 && strcmp(argv[1], "speed") == 0)
		return cmd_speed(argc - 2, argv + 2);
	if (argc >= 2 && strcmp(argv[1], "between") == 0)
		return cmd_between(argc - 2, argv + 2);
	if (argc >= 2 && strcmp(argv[1], "pointerr") == 0)
		return cmd_pointerr(argc - 2, argv + 2);
	if (argc >= 2 && strcmp(argv[1], "rtlevels") == 0)
		return cmd_rtlevels(argc - 2, argv + 2);
	fprintf(stderr, "usage: bench_motion convert IN OUT.glb | peers ORIG LABEL=FILE[@KEYS]... | precision FILE... | "
	                "methods FILE... | speed FILE... | between FILE... | pointerr ORIG LABEL=FILE... | rtlevels ORIG PACK\n");
	return 1;
}
