/*
 * test_rt_stale.c: mlod_rt_skin_stale (mlod_rt.h, "Skinning only when the
 * vertices shown went stale") checked independently of its bound: along a
 * scripted path (instances at several distances, walking, several clips,
 * time advancing by 1/30 s a frame, pixel selection switching levels)
 * each instance keeps its own buffer; whenever the call skips, a fresh
 * mlod_rt_skin into another buffer with another scratch must lie within
 * max_stale_pixels of the kept one at every vertex, projected at the
 * instance's distance. Skips must happen (an implementation that always
 * skins fails), and a change of mesh or skeleton level, of clip and of
 * morph weights must skin. On tubeman and RobotExpressive (packed with
 * mlod-pack, rt_packer.h) and, when MLOD_SHARED_DATA names ../shared/data,
 * Ely (SKIP otherwise). Also: no allocation per frame (counting
 * allocator hooks), and the fuzz regress corpus (tests/fuzz/regress/pack)
 * through it, where a bound that comes to NaN must skin every time.
 */
#define _POSIX_C_SOURCE 200809L
#include <sys/stat.h>

#include "rt_test.h"
#include "rt_packer.h"

#define FRAMES 90
#define NI 12

typedef struct path_stats {
	unsigned long calls, skips, checked_vertices;
	unsigned long level_changes, clip_changes, morph_changes; /* each of which skinned */
	double worst_px;                                          /* the largest measured staleness, pixels */
	double worst_ratio;                                       /* measured over the call's own bound */
} path_stats;

static uint8_t *pack_sample(const char *sample, const char *file, size_t *size)
{
	char path[600];
	if (run_pack(sample, "", file, path, sizeof path) != 0)
		return NULL;
	return read_all(path, size);
}

/* The scripted path on one pack with max_stale_pixels q. */
static void stale_path(const uint8_t *data, size_t size, float q, path_stats *ps)
{
	mlod_error e = { 0 };
	mlod_rt_ctx *ctx = NULL;
	CHECK_OK(mlod_rt_open_memory(data, size, NULL, &ctx, &e), e);
	const uint32_t cap = mlod_rt_max_vertex_count(ctx), clips = mlod_rt_clip_count(ctx);
	const size_t rec_size = mlod_rt_stale_size(ctx);
	mlod_rt_scratch *s = mlod_rt_scratch_create(ctx), *s2 = mlod_rt_scratch_create(ctx);
	float *kept = malloc((size_t)NI * cap * 3 * sizeof *kept), *fresh = malloc((size_t)cap * 3 * sizeof *fresh);
	uint8_t *rec = calloc(NI, rec_size);
	uint32_t ids[NI], last_level[NI][MLOD_RT_LAYERS], last_clip[NI];
	float dist[NI], speed[NI];
	int ok = s && s2 && kept && fresh && rec && rec_size % 4 == 0 && cap > 0;
	/* a part with morph targets, if any */
	uint32_t morph_part = UINT32_MAX;
	for (uint32_t p = 0; ok && morph_part == UINT32_MAX && p < mlod_rt_mesh_part_count(ctx, mlod_rt_level_count(ctx, MLOD_RT_MESH) - 1); p++)
		if (mlod_rt_morph_target_count(ctx, p) > 0)
			morph_part = p;
	/* metres as bench/crowd takes them: the character 1.8 m tall */
	mlod_rt_character ch;
	ok = ok && mlod_rt_character_get(ctx, &ch, &e) == MLOD_OK;
	const float scale = ok && ch.height > 0 ? ch.height / 1.8f : 1.0f;
	static const float d0[NI] = { 0.5f, 2, 4, 7, 12, 20, 35, 50, 80, 120, 180, 260 };
	for (uint32_t i = 0; ok && i < NI; i++) {
		ok = mlod_rt_instance_create(ctx, clips ? i % clips : 0, 0.37f * (float)i, MLOD_RT_LOOP, &ids[i], &e) ==
		     MLOD_OK;
		/* walking (0.5 to 1.7 m/s), faster far away so that levels switch */
		dist[i] = d0[i] * scale;
		speed[i] = (i % 2 ? -1.0f : 1.0f) * (0.5f + 0.3f * (float)(i % 5)) * (1.0f + d0[i] / 20) * scale;
		last_clip[i] = UINT32_MAX;
		for (int l = 0; l < MLOD_RT_LAYERS; l++)
			last_level[i][l] = UINT32_MAX;
	}
	mlod_rt_select sel;
	mlod_rt_select_default(&sel);
	sel.mode = MLOD_RT_SELECT_PIXELS;
	sel.hysteresis = 0;
	const float dt = 1.0f / 30;
	const double tanh_ = tan(0.5 * (double)sel.fov_y);
	for (int f = 0; ok && f < FRAMES; f++) {
		for (uint32_t i = 0; i < NI; i++) {
			dist[i] += speed[i] * dt;
			if (dist[i] < 0.5f * scale || dist[i] > 300.0f * scale)
				speed[i] = -speed[i], dist[i] += 2 * speed[i] * dt;
		}
		/* a clip change and morph weights on some frames */
		int clip_set = -1, morph_set = -1;
		if (clips > 1 && f % 20 == 10) {
			clip_set = (int)((uint32_t)f / 20 % NI);
			const mlod_rt_state *st = mlod_rt_instance_state(ctx, ids[clip_set]);
			ok = mlod_rt_instance_set(ctx, ids[clip_set], (st->clip + 1) % clips, st->time, MLOD_RT_LOOP, &e) ==
			     MLOD_OK;
		}
		if (morph_part != UINT32_MAX && f % 15 == 7) {
			morph_set = (int)((uint32_t)f / 15 % NI);
			float w[1] = { 0.25f * (float)(f % 4 + 1) };
			ok = ok && mlod_rt_instance_set_morph_weights(ctx, ids[morph_set], morph_part, w, 1, &e) == MLOD_OK;
		}
		ok = ok && mlod_rt_update(ctx, &sel, ids, dist, NI, dt, &e) == MLOD_OK;
		if (!ok)
			break;
		(void)mlod_rt_stream(ctx, f % 3 ? 0 : SIZE_MAX, NULL, &e); /* levels arrive now and then: fallbacks */
		for (uint32_t i = 0; ok && i < NI; i++) {
			const mlod_rt_state *st = mlod_rt_instance_state(ctx, ids[i]);
			uint32_t vc = 0, vc2 = 0;
			int skinned = -1;
			float bound_px = -1;
			float *kb = kept + (size_t)i * cap * 3;
			ok = mlod_rt_skin_stale(ctx, s, ids[i], &sel, q, rec + i * rec_size, rec_size, kb, 12, NULL, 0, cap, &vc,
			                        &skinned, &bound_px, &e) == MLOD_OK;
			if (!ok)
				break;
			ps->calls++;
			const int level_changed = st->level[MLOD_RT_MESH] != last_level[i][MLOD_RT_MESH] ||
			                          st->level[MLOD_RT_SKELETON] != last_level[i][MLOD_RT_SKELETON];
			const int clip_changed = st->clip != last_clip[i];
			if (level_changed || clip_changed || (int)i == morph_set) {
				CHECK(skinned == 1, "instance %u frame %d: %s changed, not skinned", i, f,
				      level_changed ? "a level" : clip_changed ? "the clip" : "the morph weights");
				if (last_clip[i] != UINT32_MAX) {
					ps->level_changes += level_changed;
					ps->clip_changes += !level_changed && clip_changed;
					ps->morph_changes += !level_changed && !clip_changed && (int)i == morph_set;
				}
			}
			if (skinned) {
				for (int l = 0; l < MLOD_RT_LAYERS; l++)
					last_level[i][l] = st->level[l];
				last_clip[i] = st->clip;
				continue;
			}
			ps->skips++;
			/* independent: another scratch, a plain skin now */
			ok = mlod_rt_skin(ctx, s2, ids[i], fresh, 12, NULL, 0, cap, &vc2, &e) == MLOD_OK;
			CHECK(ok && vc2 == vc, "fresh skin: %u vertices against %u kept (%s)", vc2, vc, e.message);
			const double px = (double)sel.lines / (2.0 * (double)st->distance * tanh_);
			double worst = 0;
			for (uint32_t v = 0; v < vc; v++) {
				const double dx = (double)fresh[3 * v] - kb[3 * v], dy = (double)fresh[3 * v + 1] - kb[3 * v + 1],
				             dz = (double)fresh[3 * v + 2] - kb[3 * v + 2];
				const double m = sqrt(dx * dx + dy * dy + dz * dz) * px;
				CHECK(m <= (double)q, "instance %u frame %d at %g: vertex %u is %g px off, more than %g", i, f,
				      (double)st->distance, v, m, (double)q);
				worst = m > worst ? m : worst;
			}
			CHECK(worst <= (double)bound_px * (1 + 1e-6) + 1e-9, "measured %g px over the call's bound %g", worst,
			      (double)bound_px);
			ps->checked_vertices += vc;
			ps->worst_px = worst > ps->worst_px ? worst : ps->worst_px;
			if (bound_px > 0 && worst / bound_px > ps->worst_ratio)
				ps->worst_ratio = worst / bound_px;
		}
	}
	if (s)
		mlod_rt_scratch_destroy(ctx, s);
	if (s2)
		mlod_rt_scratch_destroy(ctx, s2);
	mlod_rt_close(ctx);
	free(kept), free(fresh), free(rec);
	CHECK(ok, "%s", e.message);
}

static void stale_on(const char *name, const uint8_t *data, size_t size, path_stats *total)
{
	static const float qs[] = { 0.5f, 1.0f };
	for (int k = 0; k < 2 && !t_failed_; k++) {
		path_stats ps;
		memset(&ps, 0, sizeof ps);
		stale_path(data, size, qs[k], &ps);
		if (t_failed_)
			return;
		printf("# %s, %g px: %lu calls, %lu skipped (%lu vertices checked, worst %.3g px, at most %.3g of the "
		       "bound); skinned on %lu level, %lu clip, %lu morph changes\n",
		       name, (double)qs[k], ps.calls, ps.skips, ps.checked_vertices, ps.worst_px, ps.worst_ratio,
		       ps.level_changes, ps.clip_changes, ps.morph_changes);
		CHECK(ps.skips > 0, "%s: no call skipped", name);
		CHECK(ps.skips < ps.calls, "%s: every call skipped", name);
		total->level_changes += ps.level_changes, total->clip_changes += ps.clip_changes;
		total->morph_changes += ps.morph_changes, total->skips += ps.skips;
	}
}

static path_stats totals;
static int skipped; /* the test printed SKIP: RUN_S prints no PASS after it */
#define RUN_S(name)                                                                                     \
	do {                                                                                            \
		skipped = 0, t_failed_ = 0;                                                             \
		test_##name();                                                                          \
		if (t_failed_) {                                                                        \
			printf("FAIL %s: %s\n", #name, t_msg_);                                         \
			t_total_fail_++;                                                                \
		} else if (!skipped) {                                                                  \
			printf("PASS %s\n", #name);                                                     \
		}                                                                                       \
		fflush(stdout);                                                                         \
	} while (0)

TEST(stale_vertices_within_the_bound)
{
	SKIP_IF_NO_PACK(stale_vertices_within_the_bound);
	static const char *const samples[][2] = { { "samples/tubeman.glb", "stale-tube.mlod" },
		                                  { "samples/RobotExpressive.glb", "stale-robot.mlod" } };
	for (int k = 0; k < 2 && !t_failed_; k++) {
		size_t size = 0;
		uint8_t *data = pack_sample(samples[k][0], samples[k][1], &size);
		CHECK(data, "mlod-pack %s failed", samples[k][0]);
		stale_on(samples[k][0], data, size, &totals);
		free(data);
	}
	if (t_failed_)
		return;
	CHECK(totals.level_changes > 0 && totals.clip_changes > 0, "no level (%lu) or clip (%lu) change seen",
	      totals.level_changes, totals.clip_changes);
}

TEST(ely_stale_vertices_within_the_bound)
{
	SKIP_IF_NO_PACK(ely_stale_vertices_within_the_bound);
	const char *dir = getenv("MLOD_SHARED_DATA");
	struct stat sb;
	if (!dir || !*dir || stat(dir, &sb) != 0 || !S_ISDIR(sb.st_mode)) {
		printf("SKIP ely_stale_vertices_within_the_bound: needs ../shared/data: MLOD_SHARED_DATA %s\n",
		       dir && *dir ? "is not a directory" : "is not set (make test-extended sets it when ../shared/data exists)");
		skipped = 1;
		return;
	}
	char sample[600];
	snprintf(sample, sizeof sample, "%.500s/Ely.glb", dir);
	size_t size = 0;
	uint8_t *data = pack_sample(sample, "stale-ely.mlod", &size);
	CHECK(data, "mlod-pack %s failed", sample);
	path_stats t;
	memset(&t, 0, sizeof t);
	stale_on("Ely", data, size, &t);
	free(data);
}

/* Morph weights on the hand-built views (rt_test.h's character has
 * targets on no part; the samples may have none either): a part with a
 * target, weights set between two calls at the same pose must skin, the
 * same weights again later skip. */
TEST(morph_weights_force_a_skin)
{
	SKIP_IF_NO_PACK(morph_weights_force_a_skin);
	size_t size = 0;
	uint8_t *data = pack_sample("samples/RobotExpressive.glb", "stale-robot-m.mlod", &size);
	CHECK(data, "mlod-pack failed");
	mlod_error e = { 0 };
	mlod_rt_ctx *ctx = NULL;
	mlod_result r = mlod_rt_open_memory(data, size, NULL, &ctx, &e);
	if (r != MLOD_OK)
		free(data);
	CHECK_OK(r, e);
	uint32_t part = UINT32_MAX, parts = mlod_rt_mesh_part_count(ctx, mlod_rt_level_count(ctx, MLOD_RT_MESH) - 1);
	for (uint32_t p = 0; p < parts && part == UINT32_MAX; p++)
		if (mlod_rt_morph_target_count(ctx, p) > 0)
			part = p;
	if (part == UINT32_MAX) {
		mlod_rt_close(ctx);
		free(data);
		printf("SKIP morph_weights_force_a_skin: RobotExpressive's pack has no morph target\n");
		skipped = 1;
		return;
	}
	const uint32_t cap = mlod_rt_max_vertex_count(ctx);
	float *buf = malloc((size_t)cap * 12);
	const size_t rs = mlod_rt_stale_size(ctx);
	void *rec = calloc(1, rs);
	mlod_rt_scratch *s = mlod_rt_scratch_create(ctx);
	uint32_t id;
	int sk[4] = { -1, -1, -1, -1 };
	mlod_rt_select sel;
	mlod_rt_select_default(&sel);
	const float d = 100, w1 = 0.5f;
	int ok = buf && rec && s && mlod_rt_instance_create(ctx, 0, 0.1f, 0, &id, &e) == MLOD_OK &&
	         mlod_rt_update(ctx, &sel, &id, &d, 1, 0, &e) == MLOD_OK;
	/* dt 0: the pose stays; only the weights change */
	ok = ok && mlod_rt_skin_stale(ctx, s, id, &sel, 1, rec, rs, buf, 12, NULL, 0, cap, NULL, &sk[0], NULL, &e) == MLOD_OK;
	ok = ok && mlod_rt_skin_stale(ctx, s, id, &sel, 1, rec, rs, buf, 12, NULL, 0, cap, NULL, &sk[1], NULL, &e) == MLOD_OK;
	ok = ok && mlod_rt_instance_set_morph_weights(ctx, id, part, &w1, 1, &e) == MLOD_OK;
	ok = ok && mlod_rt_skin_stale(ctx, s, id, &sel, 1, rec, rs, buf, 12, NULL, 0, cap, NULL, &sk[2], NULL, &e) == MLOD_OK;
	ok = ok && mlod_rt_skin_stale(ctx, s, id, &sel, 1, rec, rs, buf, 12, NULL, 0, cap, NULL, &sk[3], NULL, &e) == MLOD_OK;
	if (s)
		mlod_rt_scratch_destroy(ctx, s);
	mlod_rt_close(ctx);
	free(buf), free(rec), free(data);
	CHECK(ok, "%s", e.message);
	CHECK(sk[0] == 1 && sk[1] == 0 && sk[2] == 1 && sk[3] == 0,
	      "skinned %d %d %d %d: want 1 (empty record) 0 (nothing changed) 1 (weights) 0", sk[0], sk[1], sk[2], sk[3]);
}

/* No allocation per frame with the feature on: a crowd's frames of
 * update and mlod_rt_skin_stale (the levels streamed first). */
TEST(no_allocation_per_frame)
{
	SKIP_IF_NO_PACK(no_allocation_per_frame);
	size_t size = 0;
	uint8_t *data = pack_sample("samples/RobotExpressive.glb", "stale-robot-a.mlod", &size);
	CHECK(data, "mlod-pack failed");
	static rt_counter cnt = { 0, 0, -1 };
	mlod_rt_allocator a = { rt_counter_malloc, rt_counter_free, &cnt };
	mlod_rt_config cfg = { 0, 0, &a };
	mlod_error e = { 0 };
	mlod_rt_ctx *ctx = NULL;
	mlod_result r = mlod_rt_open_memory(data, size, &cfg, &ctx, &e);
	if (r != MLOD_OK)
		free(data);
	CHECK_OK(r, e);
	enum { N = 40 };
	const uint32_t cap = mlod_rt_max_vertex_count(ctx), clips = mlod_rt_clip_count(ctx);
	const size_t rs = mlod_rt_stale_size(ctx);
	float *buf = malloc((size_t)cap * 24);
	uint8_t *rec = calloc(N, rs);
	mlod_rt_scratch *s = mlod_rt_scratch_create(ctx);
	uint32_t ids[N];
	float dist[N];
	int ok = buf && rec && s;
	for (uint32_t i = 0; ok && i < N; i++) {
		ok = mlod_rt_instance_create(ctx, clips ? i % clips : 0, 0.1f * (float)i, MLOD_RT_LOOP, &ids[i], &e) ==
		     MLOD_OK;
		dist[i] = 2.0f + 5.0f * (float)i;
	}
	mlod_rt_select sel;
	mlod_rt_select_default(&sel);
	sel.mode = MLOD_RT_SELECT_PIXELS;
	ok = ok && mlod_rt_update(ctx, &sel, ids, dist, N, 0, &e) == MLOD_OK &&
	     mlod_rt_stream(ctx, SIZE_MAX, NULL, &e) == MLOD_OK;
	const size_t before = cnt.mallocs;
	unsigned long skinned = 0, calls = 0;
	for (int f = 0; ok && f < 30; f++) {
		ok = mlod_rt_update(ctx, &sel, ids, dist, N, 1.0f / 30, &e) == MLOD_OK;
		for (uint32_t i = 0; ok && i < N; i++) {
			int sk = 0;
			ok = mlod_rt_skin_stale(ctx, s, ids[i], &sel, 1, rec + i * rs, rs, buf, 12, buf + 3 * (size_t)cap, 12, cap,
			                        NULL, &sk, NULL, &e) == MLOD_OK;
			skinned += (unsigned long)sk, calls++;
		}
	}
	const size_t during = cnt.mallocs - before;
	if (s)
		mlod_rt_scratch_destroy(ctx, s);
	mlod_rt_close(ctx);
	free(buf), free(rec), free(data);
	CHECK(ok, "%s", e.message);
	CHECK(during == 0, "%zu allocations in 30 frames", during);
	CHECK(skinned < calls, "every call skinned");
	printf("# 30 frames of %d instances: %lu of %lu calls skinned, no allocation\n", N, skinned, calls);
}

/* The fuzz regress corpus through mlod_rt_skin_stale at every level it
 * loads: no crash under the sanitizers, and when the pose is not finite
 * (bounds-nan-bound.mlod: mlod_rt_bounds gives all of space) every call
 * skins, never keeps. */
TEST(hostile_packs_never_skip_a_nan)
{
	static const char *const files[] = { "bounds-nan-bound.mlod", "oom-draco-part-counts.mlod",
		                             "oom-toc-raw-size.mlod", "oom-unknown-codec-raw-size.mlod" };
	unsigned long nan_calls = 0, opened = 0;
	for (size_t k = 0; k < sizeof files / sizeof *files; k++) {
		char path[256];
		snprintf(path, sizeof path, "tests/fuzz/regress/pack/%s", files[k]);
		size_t size = 0;
		uint8_t *data = read_all(path, &size);
		CHECK(data, "cannot read %s (run from the repository's root)", path);
		mlod_error e = { 0 };
		mlod_rt_ctx *ctx = NULL;
		if (mlod_rt_open_memory(data, size, NULL, &ctx, &e) != MLOD_OK) {
			free(data);
			continue;
		}
		opened++;
		const uint32_t cap = mlod_rt_max_vertex_count(ctx) < (1u << 20) ? mlod_rt_max_vertex_count(ctx) : (1u << 20);
		const uint32_t levels = mlod_rt_level_count(ctx, MLOD_RT_MESH);
		float *pos = malloc(((size_t)cap + 1) * 3 * sizeof *pos);
		const size_t rs = mlod_rt_stale_size(ctx) + 4;
		void *rec = calloc(1, rs);
		mlod_rt_scratch *s = mlod_rt_scratch_create(ctx);
		uint32_t id;
		int ok = pos && rec && s && mlod_rt_instance_create(ctx, 0, 0.25f, MLOD_RT_LOOP, &id, &e) == MLOD_OK;
		for (uint32_t l = levels; ok && l-- > 0;) {
			mlod_rt_select sel;
			mlod_rt_select_default(&sel);
			sel.force_level = (int)l;
			const float d = 10.0f;
			ok = mlod_rt_update(ctx, &sel, &id, &d, 1, 1.0f / 30, &e) == MLOD_OK;
			(void)mlod_rt_stream(ctx, SIZE_MAX, NULL, &e);
			for (int f = 0; ok && f < 4; f++) {
				float lo[3], hi[3];
				int sk = -1;
				ok = mlod_rt_update(ctx, &sel, &id, &d, 1, f % 2 ? 1.0f / 30 : 0, &e) == MLOD_OK &&
				     mlod_rt_bounds(ctx, s, id, lo, hi, &e) == MLOD_OK;
				mlod_result r = ok ? mlod_rt_skin_stale(ctx, s, id, &sel, 1000, rec, rs, pos, 12, NULL, 0, cap, NULL,
				                                        &sk, NULL, &e)
				                   : MLOD_OK;
				if (r == MLOD_ERR_LIMIT || r == MLOD_ERR_INVALID_ARG)
					break; /* a level too large for the capped buffer, or none resident */
				ok = ok && r == MLOD_OK;
				if (ok && f > 0 && (isinf(lo[0]) && lo[0] < 0)) { /* the bound is NaN */
					nan_calls++;
					if (sk != 1) {
						ok = 0;
						snprintf(e.message, sizeof e.message, "%s level %u frame %d: a NaN pose kept", files[k], l, f);
					}
				}
			}
		}
		if (s)
			mlod_rt_scratch_destroy(ctx, s);
		free(pos), free(rec);
		mlod_rt_close(ctx);
		free(data);
		CHECK(ok, "%s: %s", files[k], e.message);
	}
#if MLOD_DRACO
	CHECK(nan_calls > 0, "no call met a pose that is not finite (%lu packs opened)", opened);
#endif
	printf("# %lu packs opened, %lu calls on a pose that is not finite, all skinned\n", opened, nan_calls);
}

/* Arguments: a record is of one instance; bad selections are refused. */
TEST(arguments)
{
	mlod_rt_ctx *ctx = NULL;
	mlod_error e = { 0 };
	fx_build(0);
	CHECK_OK(mlod_rt_open_views(&fx_views, NULL, &ctx, &e), e);
	mlod_rt_scratch *s = mlod_rt_scratch_create(ctx);
	const uint32_t cap = mlod_rt_max_vertex_count(ctx);
	float buf[3 * 64];
	uint8_t rec[4096];
	const size_t rs = mlod_rt_stale_size(ctx);
	uint32_t a, b;
	mlod_rt_select sel;
	mlod_rt_select_default(&sel);
	const float d[2] = { 10, 10 };
	int sk = -1;
	memset(rec, 0, sizeof rec);
	int ok = s && cap <= 64 && mlod_rt_stale_size(ctx) <= sizeof rec &&
	         mlod_rt_instance_create(ctx, 0, 0, 0, &a, &e) == MLOD_OK &&
	         mlod_rt_instance_create(ctx, 0, 0, 0, &b, &e) == MLOD_OK;
	const uint32_t ids[2] = { a, b };
	ok = ok && mlod_rt_update(ctx, &sel, ids, d, 2, 0, &e) == MLOD_OK;
	ok = ok && mlod_rt_skin_stale(ctx, s, a, &sel, 1, rec, rs, buf, 12, NULL, 0, cap, NULL, &sk, NULL, &e) == MLOD_OK &&
	     sk == 1;
	ok = ok && mlod_rt_skin_stale(ctx, s, a, &sel, 1, rec, rs, buf, 12, NULL, 0, cap, NULL, &sk, NULL, &e) == MLOD_OK &&
	     sk == 0;
	/* the same record for another instance at the same pose: skins */
	ok = ok && mlod_rt_skin_stale(ctx, s, b, &sel, 1, rec, rs, buf, 12, NULL, 0, cap, NULL, &sk, NULL, &e) == MLOD_OK &&
	     sk == 1;
	/* distance 0, the pose unchanged: keeps, and the bound in pixels is
	 * 0 (not 0 times an infinite scale, NaN) */
	const float d0[2] = { 0, 0 };
	float px = -1;
	int sk0 = -1;
	ok = ok && mlod_rt_update(ctx, &sel, ids, d0, 2, 0, &e) == MLOD_OK && /* may switch levels: skins */
	     mlod_rt_skin_stale(ctx, s, b, &sel, 1, rec, rs, buf, 12, NULL, 0, cap, NULL, &sk0, &px, &e) == MLOD_OK &&
	     mlod_rt_skin_stale(ctx, s, b, &sel, 1, rec, rs, buf, 12, NULL, 0, cap, NULL, &sk0, &px, &e) == MLOD_OK;
	const int kept_at_0 = sk0 == 0 && px == 0.0f;
	mlod_rt_select bad = sel;
	bad.fov_y = 0;
	mlod_result r1 = mlod_rt_skin_stale(ctx, s, b, &bad, 1, rec, rs, buf, 12, NULL, 0, cap, NULL, &sk, NULL, &e);
	mlod_result r2 = mlod_rt_skin_stale(ctx, s, b, &sel, -1, rec, rs, buf, 12, NULL, 0, cap, NULL, &sk, NULL, &e);
	mlod_result r3 = mlod_rt_skin_stale(ctx, s, b, &sel, NAN, rec, rs, buf, 12, NULL, 0, cap, NULL, &sk, NULL, &e);
	mlod_result r4 = mlod_rt_skin_stale(ctx, s, b, NULL, 1, rec, rs, buf, 12, NULL, 0, cap, NULL, &sk, NULL, &e);
	mlod_result r5 = mlod_rt_skin_stale(ctx, s, b, &sel, 1, NULL, rs, buf, 12, NULL, 0, cap, NULL, &sk, NULL, &e);
	/* a record one byte short: refused, saying so, and nothing written */
	uint8_t before[4096];
	memcpy(before, rec, sizeof rec);
	mlod_error e6 = { 0 };
	mlod_result r6 = mlod_rt_skin_stale(ctx, s, b, &sel, 1, rec, rs - 1, buf, 12, NULL, 0, cap, NULL, &sk, NULL, &e6);
	const int untouched = memcmp(before, rec, sizeof rec) == 0;
	if (s)
		mlod_rt_scratch_destroy(ctx, s);
	mlod_rt_close(ctx);
	CHECK(ok, "skins 1 0 1 expected: %s", e.message);
	CHECK(kept_at_0, "at distance 0 with the pose unchanged: skinned %d, %g pixels (want 0, 0)", sk0, (double)px);
	CHECK(r1 == MLOD_ERR_INVALID_ARG && r2 == MLOD_ERR_INVALID_ARG && r3 == MLOD_ERR_INVALID_ARG &&
	              r4 == MLOD_ERR_INVALID_ARG && r5 == MLOD_ERR_INVALID_ARG,
	      "bad arguments accepted: %d %d %d %d %d", (int)r1, (int)r2, (int)r3, (int)r4, (int)r5);
	CHECK(r6 == MLOD_ERR_INVALID_ARG && strstr(e6.message, "mlod_rt_stale_size") && untouched,
	      "a record too small: %d, \"%s\", record %s", (int)r6, e6.message, untouched ? "untouched" : "written");
	printf("# a record too small: %s\n", e6.message);
	CHECK(mlod_rt_stale_size(NULL) == 0, "a size for no context");
}

/* One instance each in several contexts, at the same id, state and
 * distance (dt 0: the pose stays), sharing one record: a record written
 * through one context holds no skin for another, whether another open of
 * the same pack (alive at once, or opened after the first closed, which
 * may reuse its memory) or another pack. */
static uint32_t the_id; /* the one instance's, the same in each context */

static int skin_with(mlod_rt_ctx *ctx, void *rec, size_t rs, float *buf, int *sk, mlod_error *e)
{
	mlod_rt_select sel;
	mlod_rt_select_default(&sel);
	mlod_rt_scratch *s = mlod_rt_scratch_create(ctx);
	const uint32_t cap = mlod_rt_max_vertex_count(ctx);
	int ok = s != NULL;
	*sk = -1;
	ok = ok && mlod_rt_skin_stale(ctx, s, the_id, &sel, 1, rec, rs, buf, 12, NULL, 0, cap, NULL, sk, NULL, e) == MLOD_OK;
	if (s)
		mlod_rt_scratch_destroy(ctx, s);
	return ok;
}

static mlod_rt_ctx *open_one(const uint8_t *data, size_t size, mlod_error *e)
{
	mlod_rt_ctx *ctx = NULL;
	uint32_t id = UINT32_MAX;
	const float d = 10;
	mlod_rt_select sel;
	mlod_rt_select_default(&sel);
	if (mlod_rt_open_memory(data, size, NULL, &ctx, e) != MLOD_OK)
		return NULL;
	if (mlod_rt_instance_create(ctx, 0, 0.25f, MLOD_RT_LOOP, &id, e) != MLOD_OK ||
	    mlod_rt_update(ctx, &sel, &id, &d, 1, 0, e) != MLOD_OK) {
		mlod_rt_close(ctx);
		return NULL;
	}
	if (the_id == UINT32_MAX)
		the_id = id;
	if (id != the_id) {
		snprintf(e->message, sizeof e->message, "instance ids %u and %u in two fresh contexts", the_id, id);
		mlod_rt_close(ctx);
		return NULL;
	}
	return ctx;
}

TEST(record_of_another_context_skins)
{
	SKIP_IF_NO_PACK(record_of_another_context_skins);
	size_t rsize = 0, tsize = 0;
	uint8_t *robot = pack_sample("samples/RobotExpressive.glb", "stale-robot-c.mlod", &rsize);
	uint8_t *tube = pack_sample("samples/tubeman.glb", "stale-tube-c.mlod", &tsize);
	CHECK(robot && tube, "mlod-pack failed");
	mlod_error e = { 0 };
	the_id = UINT32_MAX;
	mlod_rt_ctx *a = open_one(robot, rsize, &e), *b = open_one(robot, rsize, &e), *t = open_one(tube, tsize, &e);
	int ok = a && b && t;
	const size_t ra = ok ? mlod_rt_stale_size(a) : 0, rt = ok ? mlod_rt_stale_size(t) : 0;
	const size_t rs = ra > rt ? ra : rt;
	uint32_t cap = 0;
	if (ok) {
		cap = mlod_rt_max_vertex_count(a);
		if (mlod_rt_max_vertex_count(t) > cap)
			cap = mlod_rt_max_vertex_count(t);
	}
	void *rec = calloc(1, rs + 1);
	float *buf = malloc((size_t)cap * 12 + 12);
	ok = ok && rec && buf && ra == mlod_rt_stale_size(b);
	int sk[8] = { -1, -1, -1, -1, -1, -1, -1, -1 };
	ok = ok && skin_with(a, rec, ra, buf, &sk[0], &e) && skin_with(a, rec, ra, buf, &sk[1], &e); /* 1 0 */
	ok = ok && skin_with(b, rec, ra, buf, &sk[2], &e) && skin_with(b, rec, ra, buf, &sk[3], &e); /* 1 0 */
	ok = ok && skin_with(a, rec, ra, buf, &sk[4], &e);                                            /* 1 */
	ok = ok && skin_with(t, rec, rt, buf, &sk[5], &e) && skin_with(t, rec, rt, buf, &sk[6], &e); /* 1 0 */
	/* a closes; a new open of the same pack (often at a's address) with a's record */
	ok = ok && skin_with(a, rec, ra, buf, &sk[7], &e);
	mlod_rt_close(a);
	a = ok ? open_one(robot, rsize, &e) : NULL;
	int sk_new = -1;
	ok = ok && a && skin_with(a, rec, ra, buf, &sk_new, &e);
	mlod_rt_close(a), mlod_rt_close(b), mlod_rt_close(t);
	free(rec), free(buf), free(robot), free(tube);
	CHECK(ok, "%s", e.message);
	CHECK(sk[0] == 1 && sk[1] == 0 && sk[2] == 1 && sk[3] == 0 && sk[4] == 1 && sk[5] == 1 && sk[6] == 0 &&
	              sk[7] == 1 && sk_new == 1,
	      "skinned %d %d | %d %d | %d | %d %d | %d | %d: want 1 0 | 1 0 | 1 | 1 0 | 1 | 1", sk[0], sk[1], sk[2],
	      sk[3], sk[4], sk[5], sk[6], sk[7], sk_new);
	printf("# one record through two opens of the robot, the tubeman and a new open: skinned at each change\n");
}

int main(int argc, char **argv)
{
	(void)argc;
	static const char *const samples[] = { "samples/tubeman.glb", "samples/RobotExpressive.glb", NULL };
	rt_packer_setup(argv[0], "rt_stale", samples);
	RUN(arguments);
	RUN(stale_vertices_within_the_bound);
	RUN_S(ely_stale_vertices_within_the_bound);
	RUN_S(morph_weights_force_a_skin);
	RUN(no_allocation_per_frame);
	RUN(record_of_another_context_skins);
	RUN(hostile_packs_never_skip_a_nan);
	rt_packer_cleanup();
	TEST_EXIT();
}
