/*
 * test_rt_integrate.c: an engine's integration of the runtime written
 * from its documentation alone (mlod_rt.h, mlod_rt(3) and its pages;
 * issue 12's probe), kept as a test. On the packs of tubeman,
 * RobotExpressive and the BVH walk (no mesh): each opens from a path,
 * from memory and through read callbacks under a memory budget, and
 * every open error the docs name happens as they say (LIMIT, PARSE,
 * INVALID_ARG, IO, NOMEM), holding nothing after; 100 instances on
 * different clips and times are updated in two batches per frame, one by
 * distance (alpha) and one by pixel error, streamed 32 KB a frame, bounded
 * and skinned into an interleaved vertex buffer (stride 32: position,
 * normal, UV from the level's part arrays), every vertex inside its box,
 * the palette the size the docs give; once the camera stops, every
 * instance that falls back says why (its wanted level failed or found no
 * room: none still waits); the memory the allocator hooks hold stays
 * within the budget plus what open held plus 256 bytes; evaluation's
 * errors; a corrupt mesh level fails with its finer ones, which then say
 * failed; a read error while streaming is tried again. Everything is
 * destroyed and the hooks hold nothing at the end.
 *
 * The packs come from mlod-pack on the committed samples (rt_packer.h);
 * without it the tests print SKIP. Links libmlodrt.a alone.
 */
#define _POSIX_C_SOURCE 200809L
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "rt_test.h"
#include "rt_packer.h"

#define N 100

static struct pk {
	const char *sample, *file;
	char path[512];
	uint8_t *data;
	size_t size;
} packs[] = { { "samples/tubeman.glb", "int-tube.mlod", "", NULL, 0 },
	      { "samples/RobotExpressive.glb", "int-robot.mlod", "", NULL, 0 },
	      { "samples/cmu_12_01_walk.bvh", "int-bvh.mlod", "", NULL, 0 } };
#define PACKS (sizeof packs / sizeof packs[0])

static int packs_ready(void)
{
	for (size_t p = 0; p < PACKS; p++) {
		if (packs[p].data)
			continue;
		if (run_pack(packs[p].sample, "", packs[p].file, packs[p].path, sizeof packs[p].path) != 0 ||
		    !(packs[p].data = read_all(packs[p].path, &packs[p].size)))
			return 0;
	}
	return 1;
}

/* expr fails with code (the message is not checked here: the docs name codes). */
#define CHECK_CODE(expr, code)                                                                     \
	do {                                                                                       \
		mlod_result r_ = (expr);                                                           \
		CHECK(r_ == (code), "%s: %s (want %s): %s", #expr, mlod_strerror(r_), mlod_strerror(code), \
		      e.message);                                                                  \
	} while (0)

TEST(open_three_ways_and_their_errors)
{
	SKIP_IF_NO_PACK(open_three_ways_and_their_errors);
	CHECK(packs_ready(), "mlod-pack failed");
	for (size_t p = 0; p < PACKS; p++) {
		mlod_error e = { 0 };
		mlod_rt_ctx *ctx = NULL;
		const struct pk *k = &packs[p];
		CHECK_OK(mlod_rt_open_path(k->path, NULL, &ctx, &e), e);
		mlod_rt_stats st;
		mlod_rt_stats_get(ctx, &st);
		const size_t open_bytes = st.resident_bytes;
		mlod_rt_close(ctx);
		mlod_rt_config cfg = { open_bytes / 2, 0, NULL };
		ctx = (mlod_rt_ctx *)&cfg; /* *out is NULL on failure */
		CHECK_CODE(mlod_rt_open_memory(k->data, k->size, &cfg, &ctx, &e), MLOD_ERR_LIMIT);
		CHECK(ctx == NULL, "%s: *out not NULL after a failed open", k->file);
		CHECK_CODE(mlod_rt_open_memory(k->data, k->size / 2, NULL, &ctx, &e), MLOD_ERR_PARSE);
		CHECK_CODE(mlod_rt_open_memory(NULL, k->size, NULL, &ctx, &e), MLOD_ERR_INVALID_ARG);
		CHECK_CODE(mlod_rt_open_path("/nonexistent/x.mlod", NULL, &ctx, &e), MLOD_ERR_IO);
		rt_mem_source s = { k->data, k->size, 1, 0 };
		CHECK_CODE(mlod_rt_open_read(rt_mem_read, &s, k->size, NULL, &ctx, &e), MLOD_ERR_IO);
		s.fail = 0;
		CHECK_CODE(mlod_rt_open_read(rt_mem_read, &s, k->size - 100, NULL, &ctx, &e), MLOD_ERR_PARSE);
		mlod_rt_allocator half = { rt_counter_malloc, NULL, NULL };
		cfg.budget_bytes = 0, cfg.allocator = &half;
		CHECK_CODE(mlod_rt_open_memory(k->data, k->size, &cfg, &ctx, &e), MLOD_ERR_INVALID_ARG);
		/* every allocation of open failing in turn: NOMEM, nothing held */
		for (long f = 0;; f++) {
			rt_counter c = { 0, 0, f };
			mlod_rt_allocator a = { rt_counter_malloc, rt_counter_free, &c };
			cfg.allocator = &a;
			mlod_result r = mlod_rt_open_memory(k->data, k->size, &cfg, &ctx, &e);
			if (r == MLOD_OK) {
				mlod_rt_close(ctx);
				CHECK(c.held == 0, "%s: %zu bytes held after close", k->file, c.held);
				break;
			}
			CHECK(r == MLOD_ERR_NOMEM && c.held == 0 && ctx == NULL,
			      "%s, allocation %ld failing: %s, %zu bytes held: %s", k->file, f, mlod_strerror(r), c.held,
			      e.message);
		}
	}
}

/* The frames of one context: see the file's comment. */
static void crowd(mlod_rt_ctx *ctx, rt_counter *cnt, size_t budget, const char *what)
{
	mlod_error e = { 0 };
	const uint32_t clips = mlod_rt_clip_count(ctx);
	uint32_t ids[N], extra;
	float pos[3 * N], dist[N];
	for (uint32_t i = 0; i < N; i++) {
		const uint32_t clip = clips ? i % clips : 0;
		const float dur = clips ? mlod_rt_clip_duration(ctx, clip) : 0;
		CHECK_OK(mlod_rt_instance_create(ctx, clip, dur * (float)i / N, MLOD_RT_LOOP, &ids[i], &e), e);
		pos[3 * i] = (float)(i % 10) * 3.0f, pos[3 * i + 1] = 0, pos[3 * i + 2] = 1.0f + (float)(i / 10) * 8.0f;
	}
	CHECK_CODE(mlod_rt_instance_create(ctx, 0, 0, 0, &extra, &e), MLOD_ERR_LIMIT);
	CHECK_CODE(mlod_rt_instance_set(ctx, ids[0], clips + 1, 0, 0, &e), MLOD_ERR_INVALID_ARG);
	CHECK_CODE(mlod_rt_instance_set(ctx, ids[0], 0, NAN, 0, &e), MLOD_ERR_INVALID_ARG);
	mlod_rt_select dsel, psel, bad;
	mlod_rt_select_default(&dsel);
	mlod_rt_select_default(&psel);
	psel.mode = MLOD_RT_SELECT_PIXELS, psel.max_pixels = 2;
	bad = psel, bad.fov_y = 4;
	float cam[3] = { 0, 1.5f, 0 };
	const float neg[2] = { 1, -1 };
	CHECK_CODE(mlod_rt_update_positions(ctx, &bad, cam, ids, pos, N, 0.016f, &e), MLOD_ERR_INVALID_ARG);
	CHECK_CODE(mlod_rt_update(ctx, &dsel, ids, neg, 2, 0.016f, &e), MLOD_ERR_INVALID_ARG);
	CHECK_CODE(mlod_rt_update(ctx, NULL, ids, neg, 1, 0.016f, &e), MLOD_ERR_INVALID_ARG);
	mlod_rt_scratch *sc = mlod_rt_scratch_create(ctx);
	CHECK(sc, "%s: no scratch", what);
	mlod_rt_stats st;
	mlod_rt_stats_get(ctx, &st);
	const size_t beyond = cnt->held - st.resident_bytes; /* the pool and the scratch */
	const uint32_t cap = mlod_rt_max_vertex_count(ctx);
	struct vertex {
		float pos[3], nrm[3], uv[2];
	} *vb = calloc(cap ? cap : 1, sizeof *vb);
	CHECK(vb, "out of memory");
	for (int frame = 0; frame < 90; frame++) {
		for (int i = 0; i < N; i++) {
			const float dx = pos[3 * i] - cam[0], dy = pos[3 * i + 1] - cam[1], dz = pos[3 * i + 2] - cam[2];
			dist[i] = sqrtf(dx * dx + dy * dy + dz * dz);
		}
		CHECK_OK(mlod_rt_update(ctx, &dsel, ids, dist, N / 2, 0.016f, &e), e);
		CHECK_OK(mlod_rt_update_positions(ctx, &psel, cam, ids + N / 2, pos + 3 * (N / 2), N / 2, 0.016f, &e), e);
		CHECK_OK(mlod_rt_stream(ctx, 32 * 1024, NULL, &e), e);
		mlod_rt_stats_get(ctx, &st);
		CHECK(st.resident_bytes <= budget && cnt->held <= budget + beyond + 256,
		      "%s, frame %d: resident %zu, held %zu beyond the %zu held besides, budget %zu", what, frame,
		      st.resident_bytes, cnt->held - beyond, beyond, budget);
		for (int i = 0; i < N; i++) {
			float lo[3], hi[3];
			uint32_t n = 0, pc = 0;
			CHECK_OK(mlod_rt_bounds(ctx, sc, ids[i], lo, hi, &e), e);
			CHECK_OK(mlod_rt_skin(ctx, sc, ids[i], vb[0].pos, sizeof *vb, vb[0].nrm, sizeof *vb, cap, &n, &e), e);
			const mlod_rt_state *is = mlod_rt_instance_state(ctx, ids[i]);
			const uint32_t ml = is->level[MLOD_RT_MESH];
			CHECK(n == mlod_rt_mesh_vertex_count(ctx, ml), "%s: %u vertices skinned, level %u has %u", what, n, ml,
			      mlod_rt_mesh_vertex_count(ctx, ml));
			for (uint32_t p = 0; p < mlod_rt_mesh_part_count(ctx, ml); p++) {
				mlod_rt_part_info pi;
				CHECK_OK(mlod_rt_mesh_part(ctx, ml, p, &pi, &e), e);
				for (uint32_t v = 0; v < pi.vertex_count; v++) {
					struct vertex *x = &vb[pi.first_vertex + v];
					for (int a = 0; a < 3; a++)
						CHECK(x->pos[a] >= lo[a] && x->pos[a] <= hi[a], "%s: vertex outside its box", what);
					if (pi.attributes->rec.uv_sets)
						memcpy(x->uv, pi.attributes->uvs[0] + 2 * v, sizeof x->uv);
				}
			}
			const float *W, *pal;
			CHECK_OK(mlod_rt_pose(ctx, sc, ids[i], &W, NULL, NULL, &e), e);
			CHECK_OK(mlod_rt_palette(ctx, sc, &pal, &pc, &e), e);
			CHECK(pc == mlod_rt_palette_size(ctx), "%s: palette %u, palette_size %u", what, pc,
			      mlod_rt_palette_size(ctx));
		}
		if (frame < 60)
			cam[2] += 0.5f; /* then it stops: what can load has loaded */
	}
	/* Every fallback says why; none waits after 30 still frames. */
	for (int i = 0; i < N; i++) {
		const mlod_rt_state *is = mlod_rt_instance_state(ctx, ids[i]);
		for (int l = 0; l < MLOD_RT_LAYERS; l++) {
			if (!(is->fallback & (1u << l)))
				continue;
			mlod_rt_level_info li;
			CHECK_OK(mlod_rt_level_info_get(ctx, (mlod_rt_layer)l, is->wanted[l], is->clip, &li, &e), e);
			CHECK(!li.resident && (li.failed || li.no_room), "%s: instance %d layer %d wants %u, shows %u: %s", what,
			      i, l, is->wanted[l], is->level[l], li.resident ? "resident" : "still waiting");
		}
	}
	/* evaluation's errors */
	uint32_t n;
	const mlod_rt_state *s0 = mlod_rt_instance_state(ctx, ids[0]);
	if (mlod_rt_mesh_vertex_count(ctx, s0->level[MLOD_RT_MESH]) > 1)
		CHECK_CODE(mlod_rt_skin(ctx, sc, ids[0], vb[0].pos, sizeof *vb, NULL, 0, 1, &n, &e), MLOD_ERR_LIMIT);
	CHECK_CODE(mlod_rt_skin(ctx, sc, ids[0], vb[0].pos, 6, NULL, 0, cap, &n, &e), MLOD_ERR_INVALID_ARG);
	CHECK_CODE(mlod_rt_request(ctx, MLOD_RT_MESH, 99, 0, &e), MLOD_ERR_INVALID_ARG);
	mlod_rt_level_info li;
	CHECK_CODE(mlod_rt_level_info_get(ctx, MLOD_RT_MOTION, 0, clips, &li, &e), MLOD_ERR_INVALID_ARG);
	uint32_t cl;
	CHECK_CODE(mlod_rt_clip_find(ctx, "no such clip", &cl, &e), MLOD_ERR_INVALID_ARG);
	mlod_rt_instance_destroy(ctx, ids[0]);
	CHECK_CODE(mlod_rt_skin(ctx, sc, ids[0], vb[0].pos, sizeof *vb, NULL, 0, cap, &n, &e), MLOD_ERR_INVALID_ARG);
	CHECK(mlod_rt_instance_state(ctx, ids[0]) == NULL, "%s: a destroyed instance has a state", what);
	for (int i = 1; i < N; i++)
		mlod_rt_instance_destroy(ctx, ids[i]);
	free(vb);
	mlod_rt_scratch_destroy(ctx, sc);
}

TEST(crowd_from_memory_and_read_callbacks)
{
	SKIP_IF_NO_PACK(crowd_from_memory_and_read_callbacks);
	CHECK(packs_ready(), "mlod-pack failed");
	for (size_t p = 0; p < PACKS; p++) {
		mlod_error e = { 0 };
		const struct pk *k = &packs[p];
		mlod_rt_ctx *ctx = NULL;
		CHECK_OK(mlod_rt_open_memory(k->data, k->size, NULL, &ctx, &e), e);
		mlod_rt_stats st;
		mlod_rt_stats_get(ctx, &st);
		mlod_rt_close(ctx);
		/* room for some finer levels, not all (tubeman: mesh level 0 never fits) */
		const size_t budget = st.resident_bytes + st.resident_bytes / 2 + 200000;
		for (int way = 0; way < 2; way++) {
			rt_counter c = { 0, 0, -1 };
			mlod_rt_allocator a = { rt_counter_malloc, rt_counter_free, &c };
			mlod_rt_config cfg = { budget, N, &a };
			rt_mem_source s = { k->data, k->size, 0, 0 };
			ctx = NULL;
			if (way == 0)
				CHECK_OK(mlod_rt_open_memory(k->data, k->size, &cfg, &ctx, &e), e);
			else
				CHECK_OK(mlod_rt_open_read(rt_mem_read, &s, k->size, &cfg, &ctx, &e), e);
			crowd(ctx, &c, budget, k->file);
			mlod_rt_close(ctx);
			if (t_failed_)
				return;
			CHECK(c.held == 0, "%s: %zu bytes held after close", k->file, c.held);
		}
	}
}

/* A byte flipped in mesh level 1's chunk: a close instance's stream fails
 * with PARSE; levels 0 and 1 say failed, level 2 is shown. */
TEST(corrupt_level_says_failed)
{
	SKIP_IF_NO_PACK(corrupt_level_says_failed);
	CHECK(packs_ready(), "mlod-pack failed");
	const struct pk *k = &packs[0];
	mlod_error e = { 0 };
	uint8_t *bad = malloc(k->size);
	CHECK(bad, "out of memory");
	memcpy(bad, k->data, k->size);
	mlod_pack pk;
	CHECK_OK(mlod_pack_open(k->data, k->size, &pk, &e), e);
	int flipped = 0;
	for (uint32_t c = 0; c < pk.chunk_count; c++)
		if (pk.chunks[c].layer == MLOD_LAYER_MESH && pk.chunks[c].level == 1) /* not MLOD_RT_MESH */
			bad[pk.chunks[c].offset + pk.chunks[c].stored_size / 2] ^= 0x55, flipped = 1;
	mlod_pack_close(&pk);
	mlod_rt_ctx *ctx = NULL;
	mlod_result r = flipped ? mlod_rt_open_memory(bad, k->size, NULL, &ctx, &e) : MLOD_ERR_LIMIT;
	if (r) {
		free(bad);
		CHECK(0, "no mesh level 1 chunk, or open failed: %s", e.message);
	}
	uint32_t id;
	CHECK_OK(mlod_rt_instance_create(ctx, 0, 0, 0, &id, &e), e);
	mlod_rt_select sel;
	mlod_rt_select_default(&sel);
	const float d = 0;
	mlod_result first = MLOD_OK;
	for (int f = 0; f < 3; f++) {
		CHECK_OK(mlod_rt_update(ctx, &sel, &id, &d, 1, 0, &e), e);
		r = mlod_rt_stream(ctx, SIZE_MAX, NULL, &e);
		if (f == 0)
			first = r;
	}
	const mlod_rt_state *st = mlod_rt_instance_state(ctx, id);
	mlod_rt_level_info l0, l1;
	CHECK_OK(mlod_rt_level_info_get(ctx, MLOD_RT_MESH, 0, 0, &l0, &e), e);
	CHECK_OK(mlod_rt_level_info_get(ctx, MLOD_RT_MESH, 1, 0, &l1, &e), e);
	CHECK(first == MLOD_ERR_PARSE && r == MLOD_OK && st->wanted[MLOD_RT_MESH] == 0 && st->level[MLOD_RT_MESH] == 2 &&
	          l0.failed && l1.failed && !l0.no_room,
	      "first stream %s, last %s, mesh wanted %u shown %u, failed %d %d", mlod_strerror(first), mlod_strerror(r),
	      st->wanted[MLOD_RT_MESH], st->level[MLOD_RT_MESH], l0.failed, l1.failed);
	mlod_rt_close(ctx);
	free(bad);
}

/* A read callback failing while streaming: IO, the levels failed for
 * now; the next stream with reads working loads them. */
TEST(read_error_tried_again)
{
	SKIP_IF_NO_PACK(read_error_tried_again);
	CHECK(packs_ready(), "mlod-pack failed");
	for (size_t p = 0; p < 2; p++) {
		const struct pk *k = &packs[p];
		mlod_error e = { 0 };
		rt_mem_source s = { k->data, k->size, 0, 0 };
		mlod_rt_ctx *ctx = NULL;
		CHECK_OK(mlod_rt_open_read(rt_mem_read, &s, k->size, NULL, &ctx, &e), e);
		uint32_t id;
		CHECK_OK(mlod_rt_instance_create(ctx, 0, 0, 0, &id, &e), e);
		mlod_rt_select sel;
		mlod_rt_select_default(&sel);
		const float d = 0;
		CHECK_OK(mlod_rt_update(ctx, &sel, &id, &d, 1, 0, &e), e);
		s.fail = 1;
		CHECK_CODE(mlod_rt_stream(ctx, SIZE_MAX, NULL, &e), MLOD_ERR_IO);
		mlod_rt_level_info li;
		CHECK_OK(mlod_rt_level_info_get(ctx, MLOD_RT_MESH, 0, 0, &li, &e), e);
		CHECK(li.failed && !li.resident, "%s: mesh level 0 after a read error: failed %d", k->file, li.failed);
		s.fail = 0;
		CHECK_OK(mlod_rt_update(ctx, &sel, &id, &d, 1, 0, &e), e);
		CHECK_OK(mlod_rt_stream(ctx, SIZE_MAX, NULL, &e), e);
		const mlod_rt_state *st = mlod_rt_instance_state(ctx, id);
		CHECK(st->fallback == 0 && st->level[MLOD_RT_MESH] == 0, "%s: fallback 0x%x, mesh level %u", k->file,
		      st->fallback, st->level[MLOD_RT_MESH]);
		mlod_rt_close(ctx);
	}
}

int main(int argc, char **argv)
{
	(void)argc;
	static const char *const samples[] = { "samples/tubeman.glb", "samples/RobotExpressive.glb",
		                               "samples/cmu_12_01_walk.bvh", NULL };
	rt_packer_setup(argv[0], "rt_integrate", samples);
	RUN(open_three_ways_and_their_errors);
	RUN(crowd_from_memory_and_read_callbacks);
	RUN(corrupt_level_says_failed);
	RUN(read_error_tried_again);
	for (size_t p = 0; p < PACKS; p++)
		free(packs[p].data);
	rt_packer_cleanup();
	TEST_EXIT();
}
