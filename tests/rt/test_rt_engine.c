/*
 * test_rt_engine.c: the runtime as an engine uses it, where a probe that
 * embedded it found it wanting (session 9): wants gathered over several
 * update batches of one frame; a level that never fits passing its want
 * to the finest coarser level that does; a read callback that misreads
 * once healing on the next mlod_rt_stream; the memory held between
 * frames, counted by the allocator hooks, within the resident bytes the
 * runtime reports; a scratch used with another context refused; NULL
 * arguments named; a level's part attributes and the palette skinning
 * on the GPU as mlod_rt_skin does; the names, hierarchy and bounds calls
 * (mlod_rt_info(3)) allocating nothing; an id kept past its instance's
 * destroy refused; mlod_rt_skin after mlod_rt_bounds posing once, with the
 * floats of a fresh scratch.
 *
 * The packs come from mlod-pack on the committed samples (rt_packer.h);
 * without it the tests print SKIP. Links libmlodrt.a alone.
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "rt_test.h"
#include "rt_packer.h"

static char robot_path[512], tube_path[512];
static uint8_t *robot, *tube;
static size_t robot_size, tube_size;

static int packs_ready(void)
{
	if (robot && tube)
		return 1;
	if (run_pack("samples/RobotExpressive.glb", "", "engine-robot.mlod", robot_path, sizeof robot_path) != 0 ||
	    run_pack("samples/tubeman.glb", "", "engine-tube.mlod", tube_path, sizeof tube_path) != 0)
		return 0;
	robot = read_all(robot_path, &robot_size);
	tube = read_all(tube_path, &tube_size);
	return robot && tube;
}

/* expr fails with code and a message holding text. */
#define CHECK_ERR(expr, code, text)                                                                  \
	do {                                                                                         \
		mlod_result r_ = (expr);                                                             \
		CHECK(r_ == (code) && strstr(e.message, (text)), "%s: %d '%s'", #expr, (int)r_, e.message); \
	} while (0)

static mlod_rt_select pixels(void)
{
	mlod_rt_select sel;
	mlod_rt_select_default(&sel);
	sel.mode = MLOD_RT_SELECT_PIXELS;
	return sel;
}

/* Two update calls per frame, a near instance in the first and a far one
 * in the second: the near one's levels load. Before, each update cleared
 * the wants of the ones before it, so the near instance showed the
 * coarsest mesh level for good while no level was pending. */
TEST(wants_of_every_batch)
{
	SKIP_IF_NO_PACK(wants_of_every_batch);
	CHECK(packs_ready(), "mlod-pack failed");
	mlod_error e = { 0 };
	mlod_rt_ctx *ctx = NULL;
	CHECK_OK(mlod_rt_open_memory(robot, robot_size, NULL, &ctx, &e), e);
	uint32_t near_id, far_id;
	CHECK_OK(mlod_rt_instance_create(ctx, 0, 0, MLOD_RT_LOOP, &near_id, &e), e);
	CHECK_OK(mlod_rt_instance_create(ctx, 0, 0, MLOD_RT_LOOP, &far_id, &e), e);
	const mlod_rt_select sel = pixels();
	const float dn = 1.0f, df = 5000.0f;
	for (int f = 0; f < 3; f++) {
		CHECK_OK(mlod_rt_update(ctx, &sel, &near_id, &dn, 1, 1.0f / 60, &e), e);
		CHECK_OK(mlod_rt_update(ctx, &sel, &far_id, &df, 1, 1.0f / 60, &e), e);
		CHECK_OK(mlod_rt_stream(ctx, SIZE_MAX, NULL, &e), e);
	}
	const mlod_rt_state *st = mlod_rt_instance_state(ctx, near_id);
	CHECK(st->wanted[MLOD_RT_MESH] == 0 && st->level[MLOD_RT_MESH] == 0 && !st->fallback,
	      "near instance: mesh wanted %u, shown %u, fallback 0x%x", st->wanted[MLOD_RT_MESH],
	      st->level[MLOD_RT_MESH], st->fallback);
	const mlod_rt_state *fs = mlod_rt_instance_state(ctx, far_id);
	CHECK(fs->level[MLOD_RT_MESH] == mlod_rt_level_count(ctx, MLOD_RT_MESH) - 1, "far instance shows mesh %u",
	      fs->level[MLOD_RT_MESH]);
	mlod_rt_close(ctx);
}

/* The robot opened under a 400,000-byte budget, which cannot hold mesh
 * level 0, and one instance at 3 units streamed for 5 frames by pixels
 * (the two fallback tests below). */
static void robot_near_under_budget(mlod_rt_ctx **ctx, uint32_t *id)
{
	CHECK(packs_ready(), "mlod-pack failed");
	mlod_error e = { 0 };
	mlod_rt_config cfg = { 400000, 16, NULL };
	CHECK_OK(mlod_rt_open_memory(robot, robot_size, &cfg, ctx, &e), e);
	CHECK_OK(mlod_rt_instance_create(*ctx, 0, 0, MLOD_RT_LOOP, id, &e), e);
	const mlod_rt_select sel = pixels();
	const float d = 3.0f;
	for (int f = 0; f < 5; f++) {
		CHECK_OK(mlod_rt_update(*ctx, &sel, id, &d, 1, 1.0f / 60, &e), e);
		CHECK_OK(mlod_rt_stream(*ctx, SIZE_MAX, NULL, &e), e);
	}
}

/* A budget that cannot hold mesh level 0 (robot: 400,000 bytes) with an
 * instance at 3 units: level 0 and 1 never fit, level 2 does and is
 * shown, where before the instance showed the coarsest level (4, 27% of
 * the robot's height in error) for good. */
TEST(fallback_the_finest_that_fits)
{
	SKIP_IF_NO_PACK(fallback_the_finest_that_fits);
	mlod_error e = { 0 };
	mlod_rt_ctx *ctx = NULL;
	uint32_t id;
	robot_near_under_budget(&ctx, &id);
	if (t_failed_)
		return;
	const mlod_rt_state *st = mlod_rt_instance_state(ctx, id);
	const uint32_t L = mlod_rt_level_count(ctx, MLOD_RT_MESH);
	uint32_t finest = L - 1; /* the finest resident level, which must be the one shown */
	for (uint32_t l = L; l-- > 0;) {
		mlod_rt_level_info li;
		CHECK_OK(mlod_rt_level_info_get(ctx, MLOD_RT_MESH, l, 0, &li, &e), e);
		if (li.resident)
			finest = l;
	}
	mlod_rt_stats s;
	mlod_rt_stats_get(ctx, &s);
	CHECK(st->wanted[MLOD_RT_MESH] == 0 && st->level[MLOD_RT_MESH] == finest && finest < L - 1 &&
	          s.resident_bytes <= 400000,
	      "mesh wanted %u, shown %u, finest resident %u of %u, resident %zu", st->wanted[MLOD_RT_MESH],
	      st->level[MLOD_RT_MESH], finest, L, s.resident_bytes);
	/* nothing finer than what it shows fits: level finest - 1 alone does not */
	mlod_rt_level_info li;
	CHECK_OK(mlod_rt_level_info_get(ctx, MLOD_RT_MESH, finest - 1, 0, &li, &e), e);
	CHECK(!li.resident && !li.failed, "mesh level %u: resident %d failed %d", finest - 1, li.resident, li.failed);
	mlod_rt_close(ctx);
}


/* Why an instance falls back (a probe of issue 12 could not tell): under
 * the 400,000-byte budget above, the mesh levels finer than the one shown
 * say no_room after mlod_rt_stream, the one shown does not; a frame whose
 * mlod_rt_stream has no byte budget left for the wanted level (here 0:
 * it loads nothing) leaves it waiting, neither failed nor no_room, which
 * is what a stream budget too small per frame shows. Before, the three
 * causes (no room, failed, not streamed yet) looked alike but for failed. */
TEST(fallback_says_why)
{
	SKIP_IF_NO_PACK(fallback_says_why);
	mlod_error e = { 0 };
	mlod_rt_ctx *ctx = NULL;
	uint32_t id;
	robot_near_under_budget(&ctx, &id);
	if (t_failed_)
		return;
	const mlod_rt_state *st = mlod_rt_instance_state(ctx, id);
	const uint32_t shown = st->level[MLOD_RT_MESH];
	CHECK(st->wanted[MLOD_RT_MESH] == 0 && shown > 0 && (st->fallback & (1u << MLOD_RT_MESH)),
	      "mesh wanted %u, shown %u, fallback 0x%x", st->wanted[MLOD_RT_MESH], shown, st->fallback);
	for (uint32_t l = 0; l <= shown; l++) {
		mlod_rt_level_info li;
		CHECK_OK(mlod_rt_level_info_get(ctx, MLOD_RT_MESH, l, 0, &li, &e), e);
		CHECK(li.no_room == (l < shown) && !li.failed && li.resident == (l == shown),
		      "mesh level %u (shown %u): no_room %d, failed %d, resident %d", l, shown, li.no_room, li.failed,
		      li.resident);
	}
	/* the next call says only what it found: byte_budget 0 reaches no level */
	const mlod_rt_select sel = pixels();
	const float d = 3.0f;
	CHECK_OK(mlod_rt_update(ctx, &sel, &id, &d, 1, 1.0f / 60, &e), e);
	CHECK_OK(mlod_rt_stream(ctx, 0, NULL, &e), e);
	mlod_rt_level_info li;
	CHECK_OK(mlod_rt_level_info_get(ctx, MLOD_RT_MESH, 0, 0, &li, &e), e);
	CHECK(!li.no_room && !li.resident && !li.failed, "after a stream of 0 bytes: no_room %d", li.no_room);
	mlod_rt_close(ctx);

	/* no budget, a stream of 0 bytes: the wanted level waits, for no lack of room */
	CHECK_OK(mlod_rt_open_memory(robot, robot_size, NULL, &ctx, &e), e);
	CHECK_OK(mlod_rt_instance_create(ctx, 0, 0, MLOD_RT_LOOP, &id, &e), e);
	CHECK_OK(mlod_rt_update(ctx, &sel, &id, &d, 1, 1.0f / 60, &e), e);
	CHECK_OK(mlod_rt_stream(ctx, 0, NULL, &e), e);
	st = mlod_rt_instance_state(ctx, id);
	CHECK_OK(mlod_rt_level_info_get(ctx, MLOD_RT_MESH, st->wanted[MLOD_RT_MESH], 0, &li, &e), e);
	CHECK((st->fallback & (1u << MLOD_RT_MESH)) && !li.resident && !li.failed && !li.no_room,
	      "waiting level: fallback 0x%x resident %d failed %d no_room %d", st->fallback, li.resident, li.failed,
	      li.no_room);
	mlod_rt_close(ctx);
}
/* A read callback that returns damaged bytes during one mlod_rt_stream
 * call only. The coarsest mesh level's chunk, read fine at open, now
 * fails its CRC twice: the read is blamed (MLOD_ERR_IO, naming that
 * chunk), and the next call loads the levels. Before, the levels failed
 * for good with "MESH level 4: CRC mismatch", a level resident and fine. */
typedef struct glitch_src {
	const uint8_t *d;
	size_t n;
	int bad;
} glitch_src;

static int glitch_read(void *user, uint64_t offset, size_t size, void *dst)
{
	glitch_src *g = user;
	if (offset > g->n || size > g->n - offset)
		return -1;
	memcpy(dst, g->d + offset, size);
	if (g->bad)
		memset(dst, 0, size / 2);
	return 0;
}

TEST(misread_tried_again)
{
	SKIP_IF_NO_PACK(misread_tried_again);
	CHECK(packs_ready(), "mlod-pack failed");
	glitch_src g = { robot, robot_size, 0 };
	mlod_error e = { 0 };
	mlod_rt_ctx *ctx = NULL;
	CHECK_OK(mlod_rt_open_read(glitch_read, &g, robot_size, NULL, &ctx, &e), e);
	uint32_t id;
	CHECK_OK(mlod_rt_instance_create(ctx, 0, 0, 0, &id, &e), e);
	mlod_rt_select sel;
	mlod_rt_select_default(&sel);
	const float d = 0.0f;
	g.bad = 1;
	CHECK_OK(mlod_rt_update(ctx, &sel, &id, &d, 1, 0, &e), e);
	mlod_result r = mlod_rt_stream(ctx, SIZE_MAX, NULL, &e);
	const uint32_t coarsest = mlod_rt_level_count(ctx, MLOD_RT_MESH) - 1;
	char want[96];
	snprintf(want, sizeof want, "(MESH level %u): read twice, its bytes fail the CRC they matched", coarsest);
	CHECK(r == MLOD_ERR_IO && strstr(e.message, want) && strstr(e.message, "tried again by the next mlod_rt_stream"),
	      "a misread: %d '%s'", (int)r, e.message);
	g.bad = 0;
	for (int f = 0; f < 2; f++) {
		CHECK_OK(mlod_rt_update(ctx, &sel, &id, &d, 1, 0, &e), e);
		CHECK_OK(mlod_rt_stream(ctx, SIZE_MAX, NULL, &e), e);
	}
	const mlod_rt_state *st = mlod_rt_instance_state(ctx, id);
	CHECK(st->level[MLOD_RT_MESH] == 0 && st->level[MLOD_RT_MOTION] == 0 && !st->fallback,
	      "after good reads: mesh %u motion %u fallback 0x%x", st->level[MLOD_RT_MESH], st->level[MLOD_RT_MOTION],
	      st->fallback);
	for (uint32_t l = 0; l <= coarsest; l++) {
		mlod_rt_level_info li;
		CHECK_OK(mlod_rt_level_info_get(ctx, MLOD_RT_MESH, l, 0, &li, &e), e);
		CHECK(!li.failed, "mesh level %u still failed", l);
	}
	mlod_rt_close(ctx);
}

/* What the hooks hold (rt_test.h's counting allocator). */
static rt_counter cnt = { 0, 0, -1 };
static size_t open_live;

/* Under budgets from tight to ample, 32 instances walking through every
 * distance: after each mlod_rt_stream, what the hooks hold beyond what
 * they held at open minus the resident bytes then is within 256 bytes
 * of the resident bytes the runtime reports (before: a motion level's
 * block counted from its arrays, 1.7x less on RobotExpressive, and zstd's
 * dictionary object kept after a prefix-coded level, 27,352 bytes on
 * tubeman: 76,168 bytes held beyond the count). */
TEST(held_memory_is_counted)
{
	SKIP_IF_NO_PACK(held_memory_is_counted);
	CHECK(packs_ready(), "mlod-pack failed");
	mlod_rt_allocator a = { rt_counter_malloc, rt_counter_free, &cnt };
	const struct { const uint8_t *d; size_t n; const char *name; } packs[] = { { robot, robot_size, "robot" },
		                                                                     { tube, tube_size, "tubeman" } };
	const size_t budgets[] = { 300000, 500000, 0 };
	for (size_t p = 0; p < 2; p++)
		for (size_t b = 0; b < 3; b++) {
			mlod_rt_config cfg = { budgets[b], 32, &a };
			mlod_error e = { 0 };
			mlod_rt_ctx *ctx = NULL;
			cnt.held = 0;
			CHECK_OK(mlod_rt_open_memory(packs[p].d, packs[p].n, &cfg, &ctx, &e), e);
			mlod_rt_stats s;
			mlod_rt_stats_get(ctx, &s);
			open_live = cnt.held - s.resident_bytes; /* the instance pool and what else is not a level */
			uint32_t ids[32];
			float d[32];
			const uint32_t clips = mlod_rt_clip_count(ctx) ? mlod_rt_clip_count(ctx) : 1;
			for (uint32_t i = 0; i < 32; i++)
				CHECK_OK(mlod_rt_instance_create(ctx, i % clips, 0, MLOD_RT_LOOP, &ids[i], &e), e);
			const mlod_rt_select sel = pixels();
			long worst = 0;
			for (int f = 0; f < 120; f++) {
				for (int i = 0; i < 32; i++)
					d[i] = 0.5f * (float)((i * 37 + f * 3) % 400);
				CHECK_OK(mlod_rt_update(ctx, &sel, ids, d, 32, 1.0f / 60, &e), e);
				mlod_rt_stream(ctx, 32768, NULL, &e);
				mlod_rt_stats_get(ctx, &s);
				const long over = (long)(cnt.held - open_live) - (long)s.resident_bytes;
				worst = over > worst ? over : worst;
				if (budgets[b])
					CHECK(cnt.held - open_live <= budgets[b] + 256, "%s, budget %zu, frame %d: %zu held", packs[p].name,
					      budgets[b], f, cnt.held - open_live);
			}
			CHECK(worst <= 256, "%s, budget %zu: %ld bytes held beyond the resident bytes reported", packs[p].name,
			      budgets[b], worst);
			mlod_rt_close(ctx);
			CHECK(cnt.held == 0, "%s: %zu bytes left after close", packs[p].name, cnt.held);
		}
}

/* Engines keep a scratch per thread: one made for another context is
 * refused, where it read past its arrays (ASan: heap-buffer-overflow in
 * palette_entries). */
TEST(scratch_of_another_context)
{
	SKIP_IF_NO_PACK(scratch_of_another_context);
	CHECK(packs_ready(), "mlod-pack failed");
	mlod_error e = { 0 };
	mlod_rt_ctx *a = NULL, *b = NULL;
	CHECK_OK(mlod_rt_open_memory(tube, tube_size, NULL, &a, &e), e);
	CHECK_OK(mlod_rt_open_memory(robot, robot_size, NULL, &b, &e), e);
	mlod_rt_scratch *sa = mlod_rt_scratch_create(a);
	CHECK(sa, "scratch");
	uint32_t id;
	CHECK_OK(mlod_rt_instance_create(b, 0, 0, 0, &id, &e), e);
	mlod_rt_select sel;
	mlod_rt_select_default(&sel);
	const float d = 1.0f;
	CHECK_OK(mlod_rt_update(b, &sel, &id, &d, 1, 0, &e), e);
	float buf[3 * 16];
	uint32_t nv = 0;
	const float *pal;
	uint32_t np;
	CHECK_ERR(mlod_rt_pose(b, sa, id, NULL, NULL, NULL, &e), MLOD_ERR_INVALID_ARG,
	          "mlod_rt_pose: the scratch was made for another context");
	CHECK_ERR(mlod_rt_palette(b, sa, &pal, &np, &e), MLOD_ERR_INVALID_ARG,
	          "mlod_rt_palette: the scratch was made for another context");
	CHECK_ERR(mlod_rt_skin(b, sa, id, buf, 12, NULL, 0, 16, &nv, &e), MLOD_ERR_INVALID_ARG,
	          "mlod_rt_skin: the scratch was made for another context");
	float mn[3], mx[3];
	CHECK_ERR(mlod_rt_bounds(b, sa, id, mn, mx, &e), MLOD_ERR_INVALID_ARG,
	          "mlod_rt_bounds: the scratch was made for another context");
	mlod_rt_scratch_destroy(a, sa);
	mlod_rt_close(a);
	mlod_rt_close(b);
}

/* An id kept past its instance's destroy names nothing, even once the
 * pool has given its slot to a new instance (before, ids had no
 * generation: the old id reached the new instance, and a destroy through
 * it took that instance away). */
TEST(stale_id_refused)
{
	SKIP_IF_NO_PACK(stale_id_refused);
	CHECK(packs_ready(), "mlod-pack failed");
	mlod_error e = { 0 };
	mlod_rt_config cfg = { .max_instances = 2 };
	mlod_rt_ctx *ctx = NULL;
	CHECK_OK(mlod_rt_open_memory(robot, robot_size, &cfg, &ctx, &e), e);
	mlod_rt_scratch *s = mlod_rt_scratch_create(ctx);
	CHECK(s, "scratch");
	uint32_t old, now, other;
	CHECK_OK(mlod_rt_instance_create(ctx, 0, 0, 0, &old, &e), e);
	CHECK_OK(mlod_rt_instance_create(ctx, 1, 0, 0, &other, &e), e);
	mlod_rt_instance_destroy(ctx, old);
	CHECK_OK(mlod_rt_instance_create(ctx, 2, 0.5f, 0, &now, &e), e);
	CHECK(now != old && now != other, "ids %#x %#x %#x", old, other, now);
	CHECK(mlod_rt_instance_state(ctx, old) == NULL, "the old id %#x names an instance", old);
	CHECK_ERR(mlod_rt_instance_set(ctx, old, 0, 0, 0, &e), MLOD_ERR_INVALID_ARG, "is not alive");
	float buf[3 * 8000], mn[3], mx[3], w = 1.0f;
	uint32_t nv = 0;
	CHECK_ERR(mlod_rt_pose(ctx, s, old, NULL, NULL, NULL, &e), MLOD_ERR_INVALID_ARG, "is not alive");
	CHECK_ERR(mlod_rt_skin(ctx, s, old, buf, 12, NULL, 0, 8000, &nv, &e), MLOD_ERR_INVALID_ARG, "is not alive");
	CHECK_ERR(mlod_rt_bounds(ctx, s, old, mn, mx, &e), MLOD_ERR_INVALID_ARG, "is not alive");
	CHECK_ERR(mlod_rt_instance_set_morph_weights(ctx, old, 0, &w, 1, &e), MLOD_ERR_INVALID_ARG, "is not alive");
	/* an update through the old id leaves the new instance as it was */
	mlod_rt_select sel;
	mlod_rt_select_default(&sel);
	const float d = 50.0f;
	CHECK_OK(mlod_rt_update(ctx, &sel, &old, &d, 1, 0.25f, &e), e);
	const mlod_rt_state *st = mlod_rt_instance_state(ctx, now);
	CHECK(st && st->clip == 2 && st->time == 0.5f && st->distance == 0.0f, "the new instance moved");
	/* a destroy through it leaves the new instance alive */
	mlod_rt_instance_destroy(ctx, old);
	CHECK(mlod_rt_instance_state(ctx, now) != NULL, "destroying the old id took the new instance");
	CHECK_OK(mlod_rt_skin(ctx, s, now, buf, 12, NULL, 0, 8000, &nv, &e), e);
	/* one slot reused 1,000 times gives 1,000 different ids */
	uint32_t seen[1000];
	int repeats = 0;
	for (int k = 0; k < 1000; k++) {
		mlod_rt_instance_destroy(ctx, now);
		CHECK_OK(mlod_rt_instance_create(ctx, 0, 0, 0, &now, &e), e);
		for (int j = 0; j < k; j++)
			repeats += seen[j] == now || now == old || now == other;
		seen[k] = now;
	}
	CHECK(repeats == 0, "%d ids given twice", repeats);
	CHECK(mlod_rt_instance_state(ctx, other) != NULL, "the other instance is gone");
	mlod_rt_scratch_destroy(ctx, s);
	mlod_rt_close(ctx);
}

/* Skinned n vertices (positions and normals) of id on a fresh scratch. */
static int skin_fresh(mlod_rt_ctx *ctx, uint32_t id, float *pos, float *nrm, uint32_t cap, uint32_t *n)
{
	mlod_error e = { 0 };
	mlod_rt_scratch *f = mlod_rt_scratch_create(ctx);
	const int ok = f && mlod_rt_skin(ctx, f, id, pos, 12, nrm, 12, cap, n, &e) == MLOD_OK;
	mlod_rt_scratch_destroy(ctx, f);
	return ok;
}

/* A cull's mlod_rt_bounds then mlod_rt_skin of the same instance poses
 * once; the skin is float for float a fresh scratch's, and a change
 * between the two (an update, a new clip or time, another instance, a
 * stream) is never missed. */
TEST(skin_after_bounds_same_floats)
{
	SKIP_IF_NO_PACK(skin_after_bounds_same_floats);
	CHECK(packs_ready(), "mlod-pack failed");
	mlod_error e = { 0 };
	mlod_rt_ctx *ctx = NULL;
	CHECK_OK(mlod_rt_open_memory(tube, tube_size, NULL, &ctx, &e), e);
	mlod_rt_scratch *s = mlod_rt_scratch_create(ctx);
	CHECK(s, "scratch");
	uint32_t a, b;
	CHECK_OK(mlod_rt_instance_create(ctx, 0, 0.2f, MLOD_RT_LOOP, &a, &e), e);
	CHECK_OK(mlod_rt_instance_create(ctx, 0, 0.9f, MLOD_RT_LOOP, &b, &e), e);
	const mlod_rt_select sel = pixels();
	const uint32_t ids[2] = { a, b };
	const float ds[2] = { 1.0f, 1.0f };
	CHECK_OK(mlod_rt_update(ctx, &sel, ids, ds, 2, 0, &e), e);
	CHECK_OK(mlod_rt_stream(ctx, SIZE_MAX, NULL, &e), e);
	const uint32_t cap = mlod_rt_max_vertex_count(ctx);
	float *p = malloc(4 * 3 * sizeof(float) * cap), *n = p + 3 * cap, *fp = n + 3 * cap, *fn = fp + 3 * cap;
	CHECK(p && cap, "buffers");
	float mn[3], mx[3], before = 0;
	uint32_t c = 0, fc = 0;
	for (int step = 0; step < 6; step++) {
		uint32_t id = step == 3 ? b : a;
		CHECK_OK(mlod_rt_bounds(ctx, s, a, mn, mx, &e), e);
		if (step == 1)
			CHECK_OK(mlod_rt_update(ctx, &sel, &a, &ds[0], 1, 0.25f, &e), e);
		if (step == 2)
			CHECK_OK(mlod_rt_instance_set(ctx, a, 1 % mlod_rt_clip_count(ctx), 0.6f, MLOD_RT_LOOP, &e), e);
		if (step == 4)
			CHECK_OK(mlod_rt_stream(ctx, SIZE_MAX, NULL, &e), e);
		CHECK_OK(mlod_rt_skin(ctx, s, id, p, 12, n, 12, cap, &c, &e), e);
		CHECK(skin_fresh(ctx, id, fp, fn, cap, &fc), "fresh skin");
		CHECK(c == fc && !memcmp(p, fp, 12 * (size_t)c) && !memcmp(n, fn, 12 * (size_t)c),
		      "step %d: the skin after bounds is not a fresh scratch's", step);
		if (step == 1)
			CHECK(p[0] != before, "step 1: the update did not move the skin");
		before = p[0];
	}
	free(p);
	mlod_rt_scratch_destroy(ctx, s);
	mlod_rt_close(ctx);
}

/* NULL where the docs say MLOD_ERR_INVALID_ARG: a NULL pack of size 0
 * (was MLOD_ERR_PARSE, "no header"), a NULL level_info (was "no such
 * level"). */
TEST(null_arguments_named)
{
	SKIP_IF_NO_PACK(null_arguments_named);
	CHECK(packs_ready(), "mlod-pack failed");
	mlod_error e = { 0 };
	mlod_rt_ctx *ctx = NULL;
	CHECK_ERR(mlod_rt_open_memory(NULL, 0, NULL, &ctx, &e), MLOD_ERR_INVALID_ARG,
	          "mlod_rt_open_memory: NULL argument");
	CHECK_OK(mlod_rt_open_memory(tube, tube_size, NULL, &ctx, &e), e);
	CHECK_ERR(mlod_rt_level_info_get(ctx, MLOD_RT_MESH, 0, 0, NULL, &e), MLOD_ERR_INVALID_ARG,
	          "mlod_rt_level_info_get: NULL argument");
	mlod_rt_level_info li;
	CHECK_ERR(mlod_rt_level_info_get(ctx, MLOD_RT_MESH, 99, 0, &li, &e), MLOD_ERR_INVALID_ARG, "no such level");
	uint32_t k;
	mlod_rt_joint_level jl;
	CHECK_ERR(mlod_rt_character_get(ctx, NULL, &e), MLOD_ERR_INVALID_ARG, "mlod_rt_character_get: NULL argument");
	CHECK_ERR(mlod_rt_clip_find(ctx, NULL, &k, &e), MLOD_ERR_INVALID_ARG, "mlod_rt_clip_find: NULL argument");
	CHECK_ERR(mlod_rt_joint_find(ctx, "x", NULL, &e), MLOD_ERR_INVALID_ARG, "mlod_rt_joint_find: NULL argument");
	CHECK_ERR(mlod_rt_joint_level_get(ctx, 0, 0, NULL, &e), MLOD_ERR_INVALID_ARG,
	          "mlod_rt_joint_level_get: NULL argument");
	/* tubeman's skeleton levels but the coarsest load when wanted */
	CHECK(mlod_rt_level_count(ctx, MLOD_RT_SKELETON) > 2, "tubeman: %u skeleton levels",
	      mlod_rt_level_count(ctx, MLOD_RT_SKELETON));
	CHECK_ERR(mlod_rt_joint_level_get(ctx, 1, 0, &jl, &e), MLOD_ERR_INVALID_ARG, "skeleton level 1 is not resident");
	CHECK_OK(mlod_rt_joint_level_get(ctx, mlod_rt_level_count(ctx, MLOD_RT_SKELETON) - 1, 0, &jl, &e), e);
	float mn[3], mx[3];
	CHECK_ERR(mlod_rt_bounds(ctx, NULL, 0, mn, mx, &e), MLOD_ERR_INVALID_ARG, "mlod_rt_bounds: NULL argument");
	CHECK(mlod_rt_clip_name(NULL, 0) == NULL && mlod_rt_joint_name(NULL, 0) == NULL &&
	          mlod_rt_joint_parent(NULL, 0) == -1,
	      "NULL context");
	mlod_rt_close(ctx);
}

/* An engine asks names, the hierarchy and bounds every frame: none of
 * these calls allocates (counted by the allocator hooks), with every
 * level resident, after they ran once. */
TEST(info_calls_allocate_nothing)
{
	SKIP_IF_NO_PACK(info_calls_allocate_nothing);
	CHECK(packs_ready(), "mlod-pack failed");
	mlod_rt_allocator a = { rt_counter_malloc, rt_counter_free, &cnt };
	const struct { const uint8_t *d; size_t n; const char *name; } packs[] = { { robot, robot_size, "robot" },
		                                                                     { tube, tube_size, "tubeman" } };
	for (size_t p = 0; p < 2; p++) {
		mlod_rt_config cfg = { 0, 4, &a };
		mlod_error e = { 0 };
		mlod_rt_ctx *ctx = NULL;
		cnt.held = 0;
		CHECK_OK(mlod_rt_open_memory(packs[p].d, packs[p].n, &cfg, &ctx, &e), e);
		for (int layer = 0; layer < MLOD_RT_LAYERS; layer++)
			for (uint32_t l = 0; l < mlod_rt_level_count(ctx, (mlod_rt_layer)layer); l++)
				CHECK_OK(mlod_rt_request(ctx, (mlod_rt_layer)layer, l, 0, &e), e);
		CHECK_OK(mlod_rt_stream(ctx, SIZE_MAX, NULL, &e), e);
		mlod_rt_scratch *s = mlod_rt_scratch_create(ctx);
		uint32_t id;
		CHECK(s, "scratch");
		CHECK_OK(mlod_rt_instance_create(ctx, 0, 0.3f, MLOD_RT_LOOP, &id, &e), e);
		mlod_rt_select sel;
		mlod_rt_select_default(&sel);
		const size_t before = cnt.mallocs;
		size_t names = 0;
		for (int round = 0; round < 2; round++)
			for (uint32_t l = 0; l < mlod_rt_level_count(ctx, MLOD_RT_MESH); l++) {
				sel.force_level = (int)l;
				const float d = 1;
				CHECK_OK(mlod_rt_update(ctx, &sel, &id, &d, 1, 0.01f, &e), e);
				mlod_rt_character ch;
				CHECK_OK(mlod_rt_character_get(ctx, &ch, &e), e);
				names += strlen(ch.name);
				for (uint32_t k = 0; k < mlod_rt_clip_count(ctx); k++) {
					uint32_t f;
					CHECK_OK(mlod_rt_clip_find(ctx, mlod_rt_clip_name(ctx, k), &f, &e), e);
					names += f;
				}
				uint32_t none = 0;
				CHECK(mlod_rt_clip_find(ctx, "?", &none, &e) == MLOD_ERR_INVALID_ARG, "unknown clip found");
				for (uint32_t j = 0; j < mlod_rt_joint_count(ctx); j++) {
					uint32_t f;
					mlod_rt_joint_level jl;
					CHECK_OK(mlod_rt_joint_find(ctx, mlod_rt_joint_name(ctx, j), &f, &e), e);
					names += f + (size_t)(mlod_rt_joint_parent(ctx, j) + 1);
					for (uint32_t sl = 0; sl < mlod_rt_level_count(ctx, MLOD_RT_SKELETON); sl++)
						CHECK_OK(mlod_rt_joint_level_get(ctx, sl, j, &jl, &e), e);
				}
				float mn[3], mx[3];
				CHECK_OK(mlod_rt_bounds(ctx, s, id, mn, mx, &e), e);
				CHECK(mn[0] <= mx[0] && mn[1] <= mx[1] && mn[2] <= mx[2], "%s: empty box", packs[p].name);
			}
		CHECK(cnt.mallocs == before, "%s: %zu allocations by the names, hierarchy and bounds calls", packs[p].name,
		      cnt.mallocs - before);
		(void)names;
		mlod_rt_scratch_destroy(ctx, s);
		mlod_rt_close(ctx);
		CHECK(cnt.held == 0, "%s: %zu bytes left after close", packs[p].name, cnt.held);
	}
}

/* A GPU-skinning engine: a resident level's part attributes and
 * mlod_rt_palette's matrices skin the skinned parts to what mlod_rt_skin
 * writes (within 4e-3 scene units), with its UV sets (when the input has
 * them; neither sample does) there to draw with. Before, mlod_rt gave neither the bind-pose
 * arrays nor the UVs: an engine decoded the chunk a second time. */
TEST(gpu_skinning_from_part_attributes)
{
	SKIP_IF_NO_PACK(gpu_skinning_from_part_attributes);
	CHECK(packs_ready(), "mlod-pack failed");
	const struct { const uint8_t *d; size_t n; const char *name; } packs[] = { { robot, robot_size, "robot" },
		                                                                     { tube, tube_size, "tubeman" } };
	for (size_t k = 0; k < 2; k++) {
		mlod_error e = { 0 };
		mlod_rt_ctx *ctx = NULL;
		CHECK_OK(mlod_rt_open_memory(packs[k].d, packs[k].n, NULL, &ctx, &e), e);
		uint32_t id;
		CHECK_OK(mlod_rt_instance_create(ctx, 0, 0.4f, MLOD_RT_LOOP, &id, &e), e);
		mlod_rt_select sel;
		mlod_rt_select_default(&sel);
		sel.force_level = 0;
		const float d = 1.0f;
		for (int f = 0; f < 2; f++) {
			CHECK_OK(mlod_rt_update(ctx, &sel, &id, &d, 1, 0.0f, &e), e);
			CHECK_OK(mlod_rt_stream(ctx, SIZE_MAX, NULL, &e), e);
		}
		CHECK(mlod_rt_instance_state(ctx, id)->level[MLOD_RT_MESH] == 0, "%s: mesh level 0 not shown", packs[k].name);
		const uint32_t nv = mlod_rt_mesh_vertex_count(ctx, 0);
		float *out = malloc(sizeof(float) * 3 * (nv + 1));
		mlod_rt_scratch *s = mlod_rt_scratch_create(ctx);
		CHECK(out && s, "memory");
		uint32_t got = 0;
		CHECK_OK(mlod_rt_skin(ctx, s, id, out, 12, NULL, 0, nv, &got, &e), e);
		CHECK_OK(mlod_rt_pose(ctx, s, id, NULL, NULL, NULL, &e), e);
		const float *pal;
		uint32_t np;
		CHECK_OK(mlod_rt_palette(ctx, s, &pal, &np, &e), e);
		uint32_t skinned = 0, with_uv = 0;
		double worst = 0.0;
		for (uint32_t i = 0; i < mlod_rt_mesh_part_count(ctx, 0); i++) {
			mlod_rt_part_info pi;
			CHECK_OK(mlod_rt_mesh_part(ctx, 0, i, &pi, &e), e);
			const mlod_pack_part *a = pi.attributes;
			CHECK(a && a->positions && a->rec.vertex_count == pi.vertex_count, "%s part %u: no attributes",
			      packs[k].name, i);
			with_uv += a->uvs[0] != NULL;
			if (pi.skin < 0 || !a->joints || !a->weights)
				continue;
			skinned++;
			for (uint32_t v = 0; v < pi.vertex_count; v++) {
				double o[3] = { 0, 0, 0 };
				for (int q = 0; q < 4; q++) {
					const float w = a->weights[4 * v + q];
					const uint32_t entry = pi.palette_first + a->joints[4 * v + q];
					CHECK(entry < np, "%s part %u: palette entry %u of %u", packs[k].name, i, entry, np);
					const float *m = pal + 16 * (size_t)entry, *p = a->positions + 3 * (size_t)v;
					for (int r = 0; r < 3; r++)
						o[r] += w * ((double)m[r] * p[0] + (double)m[4 + r] * p[1] + (double)m[8 + r] * p[2] +
						             m[12 + r]);
				}
				for (int r = 0; r < 3; r++) {
					const double dv = fabs(o[r] - out[3 * (size_t)(pi.first_vertex + v) + (size_t)r]);
					worst = dv > worst ? dv : worst;
				}
			}
		}
		CHECK(skinned > 0 && worst <= 1e-4 * 40.0, "%s: %u skinned parts, worst %g", packs[k].name, skinned, worst);
		(void)with_uv; /* neither sample has texture coordinates */
		mlod_rt_scratch_destroy(ctx, s);
		free(out);
		mlod_rt_close(ctx);
	}
}

int main(int argc, char **argv)
{
	(void)argc;
	static const char *const samples[] = { "samples/RobotExpressive.glb", "samples/tubeman.glb", NULL };
	rt_packer_setup(argv[0], "rt_engine", samples);
	RUN(wants_of_every_batch);
	RUN(fallback_the_finest_that_fits);
	RUN(fallback_says_why);
	RUN(misread_tried_again);
	RUN(held_memory_is_counted);
	RUN(scratch_of_another_context);
	RUN(stale_id_refused);
	RUN(skin_after_bounds_same_floats);
	RUN(null_arguments_named);
	RUN(gpu_skinning_from_part_attributes);
	RUN(info_calls_allocate_nothing);
	free(robot);
	free(tube);
	rt_packer_cleanup();
	TEST_EXIT();
}
