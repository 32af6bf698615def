/*
 * test_rt_stream.c: the resident-level cache under a memory budget:
 * coarse levels at open, wanted levels loaded only in mlod_rt_stream,
 * bounded work per call, LRU eviction, coarsest levels never evicted,
 * resident bytes never above the budget, every instance always showing a
 * resident level (the best one no finer than wanted) and saying when it
 * falls back, a corrupt level failing alone. Level costs are fixed
 * (rt_test.h, fx_build(1)): coarse levels 500 + 1000 + 2 * 700 = 2900,
 * plus the runtime's table of a skeleton level (73 bytes per joint and 4
 * per palette entry: 365 + 20, SKEL_PLAN)
 * and its lists of a mesh level (4 bytes per palette entry and joint: 40,
 * MESH_PLAN) with its skinned parts' influence-count buckets (4 bytes per
 * part, and per skinned part 1 per vertex and 5 per run of 64: levels 0,
 * 1 and 2 have 3, 2 and 1 parts, their skinned part 4, 2 and 1 vertices:
 * 21, 15 and 10 bytes; MESH_ORDER1 and MESH_ORDER2 below) and its
 * tables for mlod_rt_bounds (13 floats per palette entry, 7 per part, no
 * morph target, an offset per part and one more: 296, 328 and 360 bytes
 * for levels 2, 1 and 0, MESH_BOUND(parts)) and the tables
 * of a motion level (4 bytes per joint and per channel of a joint with a
 * channel of several keys, every one here, and 64 per joint whose channels
 * all have one key, none here: MOTION_PLAN(channels) below; clip 0's
 * levels have 5, 2 and 1 channels, clip 1's 1 each).
 */
#include "rt_test.h"

#define SKEL_PLAN (365u + 20u)
#define MESH_PLAN 40u
#define MESH_ORDER1 15u
#define MESH_ORDER2 10u
#define MESH_BOUND(parts) (4u * (13u * 5u + 8u * (parts) + 1u))
#define MOTION_PLAN(c) (4u * 5u + 4u * (c))
#define COARSE (2900u + SKEL_PLAN + MESH_PLAN + MESH_ORDER2 + MESH_BOUND(1u) + 2u * MOTION_PLAN(1u))

static mlod_rt_ctx *open_budget(size_t budget, mlod_error *e)
{
	mlod_rt_config cfg = { budget, 256, NULL };
	mlod_rt_ctx *ctx = NULL;
	mlod_rt_open_views(&fx_views, &cfg, &ctx, e);
	return ctx;
}

static int resident(const mlod_rt_ctx *ctx, mlod_rt_layer layer, uint32_t level, uint32_t item)
{
	mlod_rt_level_info li;
	return mlod_rt_level_info_get(ctx, layer, level, item, &li, NULL) == MLOD_OK && li.resident;
}

/* The instance shows, per layer, the finest resident level no finer than
 * wanted, and flags the fallback. Returns NULL or what is wrong. */
static const char *check_shown(const mlod_rt_ctx *ctx, const mlod_rt_state *st)
{
	static char why[200];
	for (int layer = 0; layer < MLOD_RT_LAYERS; layer++) {
		uint32_t item = layer == MLOD_RT_MOTION ? st->clip : 0, best = 9999;
		for (uint32_t l = st->wanted[layer]; l < mlod_rt_level_count(ctx, (mlod_rt_layer)layer); l++)
			if (resident(ctx, (mlod_rt_layer)layer, l, item)) {
				best = l;
				break;
			}
		if (st->level[layer] != best || !resident(ctx, (mlod_rt_layer)layer, st->level[layer], item)) {
			snprintf(why, sizeof why, "layer %d: wanted %u, shows %u, best resident %u", layer, st->wanted[layer],
			         st->level[layer], best);
			return why;
		}
		if (!!(st->fallback & (1u << layer)) != (st->level[layer] != st->wanted[layer])) {
			snprintf(why, sizeof why, "layer %d: fallback flag wrong", layer);
			return why;
		}
	}
	return NULL;
}

TEST(open_loads_coarse_only)
{
	mlod_error e;
	mlod_rt_ctx *ctx = open_budget(0, &e);
	CHECK(ctx, "open: %s", e.message);
	mlod_rt_stats s;
	mlod_rt_stats_get(ctx, &s);
	CHECK(s.resident_bytes == COARSE, "%zu bytes resident after open", s.resident_bytes);
	CHECK(resident(ctx, MLOD_RT_MESH, 2, 0) && !resident(ctx, MLOD_RT_MESH, 0, 0) &&
	          resident(ctx, MLOD_RT_MOTION, 2, 1) && !resident(ctx, MLOD_RT_MOTION, 1, 1) &&
	          resident(ctx, MLOD_RT_SKELETON, 0, 0) && resident(ctx, MLOD_RT_SKELETON, 2, 0),
	      "wrong levels resident after open");
	/* A near instance wants level 0 but shows the coarsest until streamed. */
	uint32_t id;
	mlod_rt_select sel;
	mlod_rt_select_default(&sel);
	float d = 0;
	CHECK_OK(mlod_rt_instance_create(ctx, 0, 0, 0, &id, &e), e);
	CHECK_OK(mlod_rt_update(ctx, &sel, &id, &d, 1, 0, &e), e);
	const mlod_rt_state *st = mlod_rt_instance_state(ctx, id);
	CHECK(st->wanted[MLOD_RT_MESH] == 0 && st->level[MLOD_RT_MESH] == 2 &&
	          st->fallback == ((1u << MLOD_RT_MESH) | (1u << MLOD_RT_MOTION)),
	      "before streaming: wanted %u shows %u fallback %#x", st->wanted[MLOD_RT_MESH], st->level[MLOD_RT_MESH],
	      st->fallback);
	/* Bounded work: a byte budget of 1 loads one level per call (views count 1 byte each). */
	uint32_t n;
	CHECK_OK(mlod_rt_stream(ctx, 1, &n, &e), e);
	CHECK(n == 1, "%u levels loaded by one call of budget 1", n);
	CHECK_OK(mlod_rt_stream(ctx, 0, &n, &e), e);
	CHECK(n == 0, "a budget of 0 loaded %u", n);
	CHECK_OK(mlod_rt_stream(ctx, SIZE_MAX, &n, &e), e);
	CHECK(n == 1, "then %u", n);
	CHECK(st->fallback == 0 && st->level[MLOD_RT_MESH] == 0, "after streaming: fallback %#x", st->fallback);
	mlod_rt_close(ctx);
	CHECK(open_budget(COARSE - 1, &e) == NULL && e.code == MLOD_ERR_LIMIT, "open under a budget below the coarse levels");
}

TEST(budget_never_exceeded)
{
	static const size_t budgets[] = { COARSE, COARSE + 1600, COARSE + 3500, COARSE + 9000, 100000 };
	for (size_t b = 0; b < sizeof budgets / sizeof budgets[0]; b++) {
		mlod_error e;
		mlod_rt_ctx *ctx = open_budget(budgets[b], &e);
		CHECK(ctx, "open: %s", e.message);
		enum { N = 100 };
		uint32_t ids[N];
		float d[N];
		unsigned seed = 7;
		for (int i = 0; i < N; i++) {
			CHECK_OK(mlod_rt_instance_create(ctx, (uint32_t)i % 2, 0, MLOD_RT_LOOP, &ids[i], &e), e);
			d[i] = 2.0f + (float)(i * 2);
		}
		mlod_rt_select sel;
		mlod_rt_select_default(&sel);
		sel.mode = MLOD_RT_SELECT_PIXELS;
		int pending_frames = 0;
		for (int f = 0; f < 400; f++) {
			for (int i = 0; i < N; i++) { /* a random walk over 0.5 .. 60 */
				seed = seed * 1103515245u + 12345u;
				d[i] += ((float)((seed >> 9) % 200) - 100.0f) * 0.02f;
				d[i] = d[i] < 0.5f ? 0.5f : d[i] > 60 ? 60 : d[i];
			}
			CHECK_OK(mlod_rt_update(ctx, &sel, ids, d, N, 1.0f / 30, &e), e);
			mlod_rt_stats s;
			mlod_rt_stats_get(ctx, &s);
			CHECK(s.resident_bytes <= budgets[b], "budget %zu frame %d: %zu bytes resident", budgets[b], f,
			      s.resident_bytes);
			CHECK_OK(mlod_rt_stream(ctx, 2, NULL, &e), e);
			mlod_rt_stats_get(ctx, &s);
			pending_frames += s.pending_levels > 0;
			CHECK(s.resident_bytes <= budgets[b] && s.peak_resident_bytes <= budgets[b],
			      "budget %zu frame %d: %zu bytes resident (peak %zu)", budgets[b], f, s.resident_bytes,
			      s.peak_resident_bytes);
			for (int i = 0; i < N; i++) {
				const char *why = check_shown(ctx, mlod_rt_instance_state(ctx, ids[i]));
				CHECK(!why, "budget %zu frame %d instance %d: %s", budgets[b], f, i, why);
			}
		}
		mlod_rt_stats s;
		mlod_rt_stats_get(ctx, &s);
		if (budgets[b] == 100000)
			CHECK(s.evictions == 0, "evictions under an ample budget");
		if (budgets[b] < 100000)
			CHECK(pending_frames > 0, "budget %zu: no level ever waited", budgets[b]);
		else
			CHECK(pending_frames < 400, "an ample budget kept levels waiting");
		mlod_rt_close(ctx);
	}
}

/* An empty update: a new frame in which nothing is wanted but requests. */
static void frame(mlod_rt_ctx *ctx)
{
	mlod_rt_select sel;
	mlod_rt_select_default(&sel);
	mlod_rt_update(ctx, &sel, NULL, NULL, 0, 0, NULL);
}

TEST(lru_eviction)
{
	mlod_error e;
	mlod_rt_ctx *ctx = open_budget(COARSE + 3500 + MESH_PLAN + MESH_ORDER1 + MESH_BOUND(2u) + MOTION_PLAN(2u), &e);
	CHECK(ctx, "open: %s", e.message);
	frame(ctx);
	CHECK_OK(mlod_rt_request(ctx, MLOD_RT_MESH, 1, 0, &e), e); /* 2000 + MESH_PLAN + MESH_ORDER1 + MESH_BOUND(2) */
	CHECK_OK(mlod_rt_stream(ctx, SIZE_MAX, NULL, &e), e);
	frame(ctx);
	CHECK_OK(mlod_rt_request(ctx, MLOD_RT_MOTION, 1, 0, &e), e); /* 1500 + MOTION_PLAN(2): exactly full */
	CHECK_OK(mlod_rt_stream(ctx, SIZE_MAX, NULL, &e), e);
	CHECK(resident(ctx, MLOD_RT_MESH, 1, 0) && resident(ctx, MLOD_RT_MOTION, 1, 0), "both should fit");
	frame(ctx);
	CHECK_OK(mlod_rt_request(ctx, MLOD_RT_MOTION, 1, 1, &e), e); /* 1500 + MOTION_PLAN(1) more: evict the LRU */
	CHECK_OK(mlod_rt_stream(ctx, SIZE_MAX, NULL, &e), e);
	CHECK(!resident(ctx, MLOD_RT_MESH, 1, 0) && resident(ctx, MLOD_RT_MOTION, 1, 0) &&
	          resident(ctx, MLOD_RT_MOTION, 1, 1),
	      "LRU: mesh level 1 (wanted first) should have gone");
	/* A level wanted now is never evicted for another. */
	frame(ctx);
	CHECK_OK(mlod_rt_request(ctx, MLOD_RT_MOTION, 1, 0, &e), e);
	CHECK_OK(mlod_rt_request(ctx, MLOD_RT_MOTION, 1, 1, &e), e);
	CHECK_OK(mlod_rt_request(ctx, MLOD_RT_MESH, 0, 0, &e), e); /* 4000: cannot fit */
	uint32_t n;
	CHECK_OK(mlod_rt_stream(ctx, SIZE_MAX, &n, &e), e);
	CHECK(n == 0 && resident(ctx, MLOD_RT_MOTION, 1, 0) && resident(ctx, MLOD_RT_MOTION, 1, 1) &&
	          !resident(ctx, MLOD_RT_MESH, 0, 0),
	      "a wanted level was evicted (%u loaded)", n);
	/* mesh level 0 waits, and its want passed to mesh level 1 (evicted
	 * above), which cannot fit either: both wait */
	mlod_rt_stats s;
	mlod_rt_stats_get(ctx, &s);
	CHECK(s.pending_levels == 2, "%u pending", s.pending_levels);
	mlod_rt_close(ctx);
}

TEST(coarsest_never_evicted)
{
	mlod_error e;
	mlod_rt_ctx *ctx = open_budget(COARSE, &e);
	CHECK(ctx, "open: %s", e.message);
	for (int f = 0; f < 10; f++) {
		frame(ctx);
		for (uint32_t l = 0; l < 2; l++) {
			mlod_rt_request(ctx, MLOD_RT_MESH, l, 0, NULL);
			mlod_rt_request(ctx, MLOD_RT_SKELETON, l, 0, NULL);
			mlod_rt_request(ctx, MLOD_RT_MOTION, l, 1, NULL);
		}
		uint32_t n;
		CHECK_OK(mlod_rt_stream(ctx, SIZE_MAX, &n, &e), e);
		CHECK(n == 0, "loaded %u levels with no room", n);
	}
	CHECK(resident(ctx, MLOD_RT_MESH, 2, 0) && resident(ctx, MLOD_RT_SKELETON, 2, 0) &&
	          resident(ctx, MLOD_RT_MOTION, 2, 0) && resident(ctx, MLOD_RT_MOTION, 2, 1),
	      "a coarsest level went");
	mlod_rt_close(ctx);
}

TEST(corrupt_level_fails_alone)
{
	/* Mesh level 1 refers to joint 9 of a 5-joint skin. */
	static uint16_t bad_joints[8] = { 9, 0, 0, 0, 9, 0, 0, 0 };
	mlod_pack_part parts[2];
	memcpy(parts, fx_m1_parts, sizeof parts);
	parts[0].joints = bad_joints;
	mlod_pack_mesh bad = { 2, parts, NULL };
	mlod_rt_view_level mesh[3];
	memcpy(mesh, fx_vmesh, sizeof mesh);
	mesh[1].data = &bad;
	mlod_rt_views v = fx_views;
	v.mesh = mesh;
	mlod_error e;
	mlod_rt_ctx *ctx = NULL;
	CHECK_OK(mlod_rt_open_views(&v, NULL, &ctx, &e), e);
	frame(ctx);
	mlod_rt_request(ctx, MLOD_RT_MESH, 1, 0, NULL);
	mlod_rt_request(ctx, MLOD_RT_MESH, 0, 0, NULL);
	uint32_t n;
	mlod_result r = mlod_rt_stream(ctx, SIZE_MAX, &n, &e);
	CHECK(r == MLOD_ERR_PARSE && strstr(e.message, "mesh level 1"), "stream: %d %s", (int)r, e.message);
	mlod_rt_level_info li;
	CHECK_OK(mlod_rt_level_info_get(ctx, MLOD_RT_MESH, 1, 0, &li, &e), e);
	CHECK(li.failed && !li.resident && n == 1 && resident(ctx, MLOD_RT_MESH, 0, 0), "failed %d, %u loaded",
	      li.failed, n);
	/* An instance wanting level 1 falls back to the coarser resident level 2. */
	mlod_rt_select sel;
	mlod_rt_select_default(&sel);
	sel.force_level = 1;
	uint32_t id;
	float d = 1;
	CHECK_OK(mlod_rt_instance_create(ctx, 0, 0, 0, &id, &e), e);
	CHECK_OK(mlod_rt_update(ctx, &sel, &id, &d, 1, 0, &e), e);
	CHECK_OK(mlod_rt_stream(ctx, SIZE_MAX, &n, &e), e);
	const mlod_rt_state *st = mlod_rt_instance_state(ctx, id);
	CHECK(st->level[MLOD_RT_MESH] == 2 && (st->fallback & (1u << MLOD_RT_MESH)), "shows mesh level %u",
	      st->level[MLOD_RT_MESH]);
	mlod_rt_scratch *s = mlod_rt_scratch_create(ctx);
	float buf[3 * 7];
	CHECK_OK(mlod_rt_skin(ctx, s, id, buf, 12, NULL, 0, 7, &n, &e), e);
	CHECK(n == 1, "%u vertices from mesh level 2", n);
	mlod_rt_scratch_destroy(ctx, s);
	mlod_rt_close(ctx);
}

int main(void)
{
	fx_build(1);
	RUN(open_loads_coarse_only);
	RUN(budget_never_exceeded);
	RUN(lru_eviction);
	RUN(coarsest_never_evicted);
	RUN(corrupt_level_fails_alone);
	TEST_EXIT();
}
