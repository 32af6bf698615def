/*
 * test_rt_edges.c: the runtime's edges a new-user probe found (branch
 * fixrt): a pack's mesh level loads with exactly its resident bytes free
 * (its part records size it), and one that does not fit is not decoded
 * again in every call; a failed load spends none of mlod_rt_stream's
 * byte budget, so the fallback loads in the same call; API edges:
 * mlod_rt_stats_get on a NULL context, an allocator of one hook refused,
 * time kept finite, a morph part out of range refused, a level failed
 * for lack of memory tried again by the next mlod_rt_stream; INFO's
 * counts checked against the chunks at open.
 *
 * The tests on packs run mlod-pack (MLOD_PACK, else build/release/bin/
 * mlod-pack from the repository's root, where tests/run.sh runs) on the
 * committed samples; without mlod-pack or the samples they print SKIP.
 * This program links libmlodrt.a alone, as every tests/rt program.
 */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <stdint.h>
#include <unistd.h>

#include "rt_test.h"
#include "rt_packer.h"


static const char *room_pass(const char *what, rt_mem_source *m, char *msg, size_t cap)
{
	mlod_error e = { 0 };
	mlod_rt_ctx *ctx = NULL;
	mlod_result r0 = mlod_rt_open_read(rt_mem_read, m, m->size, NULL, &ctx, &e);
	if (r0 == MLOD_ERR_UNSUPPORTED && strstr(what, "draco")) {
		printf("# %s: %s (a runtime built with MLOD_DRACO=0): not measured\n", what, e.message);
		return NULL;
	}
	if (r0) {
		snprintf(msg, cap, "%s: open: %s", what, e.message);
		return msg;
	}
	mlod_rt_stats s;
	mlod_rt_stats_get(ctx, &s);
	const size_t base = s.resident_bytes;
	const uint32_t L = mlod_rt_level_count(ctx, MLOD_RT_MESH);
	size_t bytes[64] = { 0 };
	for (uint32_t l = 0; l + 1 < L && l < 64; l++) {
		mlod_rt_level_info li;
		mlod_rt_request(ctx, MLOD_RT_MESH, l, 0, NULL);
		mlod_rt_stream(ctx, SIZE_MAX, NULL, NULL);
		mlod_rt_level_info_get(ctx, MLOD_RT_MESH, l, 0, &li, NULL);
		bytes[l] = li.bytes;
	}
	mlod_rt_close(ctx);
	if (L < 3) {
		snprintf(msg, cap, "%s: %u mesh levels", what, L);
		return msg;
	}
	for (uint32_t l = 0; l + 1 < L && l < 64; l++)
		for (int less = 0; less <= 1; less++) {
			mlod_rt_config cfg = { base + bytes[l] - (size_t)less, 4, NULL };
			if (mlod_rt_open_read(rt_mem_read, m, m->size, &cfg, &ctx, &e)) {
				snprintf(msg, cap, "%s: open under %zu: %s", what, cfg.budget_bytes, e.message);
				return msg;
			}
			mlod_rt_level_info li;
			uint32_t loaded = 99;
			mlod_rt_request(ctx, MLOD_RT_MESH, l, 0, NULL);
			mlod_result r = mlod_rt_stream(ctx, SIZE_MAX, &loaded, &e);
			mlod_rt_level_info_get(ctx, MLOD_RT_MESH, l, 0, &li, NULL);
			mlod_rt_stats_get(ctx, &s);
			const char *bad = NULL;
			if (r != MLOD_OK)
				bad = e.message;
			else if (less ? li.resident : !li.resident || loaded != 1)
				bad = less ? "loaded with a byte less than its size free" : "not loaded with its size free";
			else if (less && loaded > (l + 2 < L ? 1u : 0u))
				bad = "more than its fallback loaded with a byte less than its size free";
			else if (less && loaded && (mlod_rt_level_info_get(ctx, MLOD_RT_MESH, l + 1, 0, &li, NULL) != MLOD_OK ||
			                            !li.resident))
				bad = "a level other than its fallback (the next coarser) loaded with a byte less than its size free";
			else if (li.failed || s.failures)
				bad = "marked failed";
			else if (s.peak_resident_bytes > cfg.budget_bytes)
				bad = "peak above the budget";
			if (!bad && less) {
				/* wanted again: its size is known, nothing is read (its
				 * fallback, the next coarser level, is resident) */
				const unsigned long before = m->reads;
				mlod_rt_request(ctx, MLOD_RT_MESH, l, 0, NULL);
				mlod_rt_stream(ctx, SIZE_MAX, &loaded, NULL);
				if (m->reads != before || loaded)
					bad = "decoded again though its size does not fit";
			}
			mlod_rt_close(ctx);
			if (bad) {
				snprintf(msg, cap, "%s mesh level %u (%zu bytes), budget %zu above the open's %zu: %s", what, l,
				         bytes[l], bytes[l] - (size_t)less, base, bad);
				return msg;
			}
		}
	return NULL;
}

TEST(mesh_room_is_its_size)
{
	SKIP_IF_NO_PACK(mesh_room_is_its_size);
	static const struct {
		const char *in, *opts, *out;
	} packs[] = { { "samples/tubeman.glb", "", "tubeman.mlod" },
		      { "samples/RobotExpressive.glb", "", "robot.mlod" },
		      { "samples/tubeman.glb", "--codec draco", "tubeman-draco.mlod" } };
	for (size_t i = 0; i < sizeof packs / sizeof packs[0]; i++) {
		char pk[512], msg[768];
		CHECK(run_pack(packs[i].in, packs[i].opts, packs[i].out, pk, sizeof pk) == 0, "mlod-pack on %s failed",
		      packs[i].in);
		rt_mem_source m = { NULL, 0, 0, 0 };
		m.data = read_all(pk, &m.size);
		CHECK(m.data, "reading %s", pk);
		const char *why = room_pass(packs[i].out, &m, msg, sizeof msg);
		free((void *)m.data);
		CHECK(!why, "%s", why);
	}
}

/* ---------------------------------------------------------------- */
/* Issue 6: a failed load counts nothing of byte_budget               */
/* ---------------------------------------------------------------- */

/* The robot with MESH level 1's payload corrupt (CRC stale): an instance
 * wanting level 0 makes levels 0 and 1 fail; its want passes to level 2,
 * which loads in the same call even with a byte budget of 1 (the failed
 * load spent none of it) and is shown. */
TEST(failed_load_spends_no_budget)
{
	SKIP_IF_NO_PACK(failed_load_spends_no_budget);
	char pk[512];
	CHECK(run_pack("samples/RobotExpressive.glb", "", "robot.mlod", pk, sizeof pk) == 0, "mlod-pack failed");
	rt_mem_source m = { NULL, 0, 0, 0 };
	uint8_t *d = read_all(pk, &m.size);
	CHECK(d, "reading %s", pk);
	m.data = d;
	mlod_pack p;
	mlod_error e = { 0 };
	mlod_result r = mlod_pack_open(d, m.size, &p, &e);
	int k = r == MLOD_OK ? mlod_pack_find(&p, MLOD_CHUNK_MESH, 1, 0) : -1;
	uint64_t off = k >= 0 ? p.chunks[k].offset : 0;
	uint32_t n = k >= 0 ? p.chunks[k].stored_size : 0;
	if (r == MLOD_OK)
		mlod_pack_close(&p);
	if (k < 0 || n <= 64)
		free(d);
	CHECK(k >= 0 && n > 64, "no MESH level 1 chunk");
	for (uint32_t i = n / 2; i < n / 2 + 8; i++)
		d[off + i] ^= 0x5a;
	mlod_rt_ctx *ctx = NULL;
	r = mlod_rt_open_read(rt_mem_read, &m, m.size, NULL, &ctx, &e);
	if (r)
		free(d);
	CHECK_OK(r, e);
	uint32_t id, loaded = 99;
	mlod_rt_instance_create(ctx, 0, 0, 0, &id, &e);
	mlod_rt_select sel;
	mlod_rt_select_default(&sel);
	sel.force_level = 0;
	float dist = 1;
	mlod_rt_update(ctx, &sel, &id, &dist, 1, 0, &e);
	r = mlod_rt_stream(ctx, 1, &loaded, &e);
	const mlod_rt_state *st = mlod_rt_instance_state(ctx, id);
	const unsigned shown = st->level[MLOD_RT_MESH];
	mlod_rt_close(ctx);
	free(d);
	CHECK(r == MLOD_ERR_PARSE, "stream: %d, want the parse error of level 1", (int)r);
	CHECK(loaded == 1 && shown == 2, "byte budget 1: %u loaded, mesh level %u shown; want 1 and level 2", loaded,
	      shown);
}

/* ---------------------------------------------------------------- */
/* Issue 10: API edges                                                */
/* ---------------------------------------------------------------- */

static char tube_path[512];
static uint8_t *tube;
static size_t tube_size;

/* tubeman packed once, for the tests below; 0 when it could not be. */
static int tube_ready(void)
{
	if (tube)
		return 1;
	if (run_pack("samples/tubeman.glb", "", "tube10.mlod", tube_path, sizeof tube_path) != 0)
		return 0;
	tube = read_all(tube_path, &tube_size);
	return tube != NULL;
}

TEST(stats_of_null_context)
{
	mlod_rt_stats s;
	memset(&s, 0xab, sizeof s);
	mlod_rt_stats_get(NULL, &s);
	CHECK(s.resident_bytes == 0 && s.loads == 0 && s.budget_bytes == 0 && s.resident_levels == 0,
	      "mlod_rt_stats_get(NULL, &s) left bytes in s");
	mlod_rt_stats_get(NULL, NULL);
}

static void *only_malloc(void *user, size_t size)
{
	(void)user;
	return malloc(size);
}

TEST(allocator_both_or_neither)
{
	SKIP_IF_NO_PACK(allocator_both_or_neither);
	CHECK(tube_ready(), "mlod-pack on tubeman failed");
	mlod_rt_allocator half = { only_malloc, NULL, NULL };
	mlod_rt_config cfg = { 0, 0, &half };
	rt_mem_source m = { tube, tube_size, 0, 0 };
	for (int k = 0; k < 4; k++) {
		mlod_error e = { 0 };
		mlod_rt_ctx *ctx = (mlod_rt_ctx *)&e; /* *out is set to NULL */
		mlod_result r = k == 0   ? mlod_rt_open_memory(tube, tube_size, &cfg, &ctx, &e)
		                : k == 1 ? mlod_rt_open_path(tube_path, &cfg, &ctx, &e)
		                : k == 2 ? mlod_rt_open_read(rt_mem_read, &m, tube_size, &cfg, &ctx, &e)
		                         : MLOD_ERR_INVALID_ARG;
		if (k == 3) { /* neither hook: the defaults */
			mlod_rt_allocator other = { NULL, NULL, NULL };
			mlod_rt_config c2 = { 0, 0, &other };
			r = mlod_rt_open_memory(tube, tube_size, &c2, &ctx, &e);
			CHECK(r == MLOD_OK, "an allocator of neither: %s", e.message);
			mlod_rt_close(ctx);
			break;
		}
		if (r == MLOD_OK)
			mlod_rt_close(ctx);
		CHECK(r == MLOD_ERR_INVALID_ARG && ctx == NULL && strstr(e.message, "allocator"),
		      "open %d with malloc but no free: %d '%s'", k, (int)r, e.message);
	}
}

/* A looping instance's time stays finite and wrapped whatever dt; a
 * non-looping one's saturates at FLT_MAX. */
TEST(time_stays_finite)
{
	SKIP_IF_NO_PACK(time_stays_finite);
	CHECK(tube_ready(), "mlod-pack on tubeman failed");
	mlod_error e = { 0 };
	mlod_rt_ctx *ctx = NULL;
	CHECK_OK(mlod_rt_open_memory(tube, tube_size, NULL, &ctx, &e), e);
	const float dur = mlod_rt_clip_duration(ctx, 0);
	uint32_t ids[2];
	mlod_rt_instance_create(ctx, 0, 3e38f, MLOD_RT_LOOP, &ids[0], &e);
	mlod_rt_instance_create(ctx, 0, 3e38f, 0, &ids[1], &e);
	mlod_rt_select sel;
	mlod_rt_select_default(&sel);
	float d[2] = { 1, 1 };
	mlod_result r = MLOD_OK;
	for (int f = 0; f < 3 && r == MLOD_OK; f++)
		r = mlod_rt_update(ctx, &sel, ids, d, 2, 3e38f, &e);
	const float t0 = mlod_rt_instance_state(ctx, ids[0])->time, t1 = mlod_rt_instance_state(ctx, ids[1])->time;
	mlod_rt_close(ctx);
	CHECK(r == MLOD_OK, "update: %s", e.message);
	CHECK(dur > 0 && t0 >= 0 && t0 < dur, "looping: time %g after overflowing dt, want in [0, %g)", (double)t0,
	      (double)dur);
	CHECK(t1 == 3.4028234663852886e38f, "not looping: time %g, want FLT_MAX", (double)t1);
}

TEST(morph_part_out_of_range)
{
	SKIP_IF_NO_PACK(morph_part_out_of_range);
	CHECK(tube_ready(), "mlod-pack on tubeman failed");
	mlod_error e = { 0 };
	mlod_rt_ctx *ctx = NULL;
	CHECK_OK(mlod_rt_open_memory(tube, tube_size, NULL, &ctx, &e), e);
	uint32_t id;
	mlod_rt_instance_create(ctx, 0, 0, 0, &id, &e);
	const uint32_t parts = mlod_rt_mesh_part_count(ctx, mlod_rt_level_count(ctx, MLOD_RT_MESH) - 1);
	mlod_result in = mlod_rt_instance_set_morph_weights(ctx, id, 0, NULL, 0, &e);
	mlod_result out = mlod_rt_instance_set_morph_weights(ctx, id, parts, NULL, 0, &e);
	mlod_rt_close(ctx);
	CHECK(parts == 1 && in == MLOD_OK, "part 0 of %u, no weights: %d", parts, (int)in);
	CHECK(out == MLOD_ERR_INVALID_ARG && strstr(e.message, "out of range"), "part %u of %u, no weights: %d '%s'",
	      parts, parts, (int)out, e.message);
}

/* An allocator that fails every allocation of at least fail_at bytes
 * while fail_at is not 0. */
static size_t fail_at;
static void *big_fails(void *user, size_t size)
{
	(void)user;
	return fail_at && size >= fail_at ? NULL : malloc(size);
}
static void big_free(void *user, void *p)
{
	(void)user;
	free(p);
}

/* Mesh level 0 fails for lack of memory (its 371 KB block): the
 * instance shows level 1, loaded in the same call; with memory back, the
 * next mlod_rt_stream tries level 0 again and it loads. A level failed
 * by a parse error is never tried again (corrupt_chunk_fails_its_
 * dependents_only, test_rt_probe). */
TEST(nomem_level_tried_again)
{
	SKIP_IF_NO_PACK(nomem_level_tried_again);
	CHECK(tube_ready(), "mlod-pack on tubeman failed");
	mlod_rt_allocator a = { big_fails, big_free, NULL };
	mlod_rt_config cfg = { 0, 4, &a };
	mlod_error e = { 0 };
	mlod_rt_ctx *ctx = NULL;
	CHECK_OK(mlod_rt_open_memory(tube, tube_size, &cfg, &ctx, &e), e);
	uint32_t id;
	mlod_rt_instance_create(ctx, 0, 0, 0, &id, &e);
	mlod_rt_select sel;
	mlod_rt_select_default(&sel);
	sel.force_level = 0;
	float d = 1;
	fail_at = 300000;
	mlod_rt_update(ctx, &sel, &id, &d, 1, 0, &e);
	mlod_result r1 = mlod_rt_stream(ctx, SIZE_MAX, NULL, &e);
	mlod_rt_level_info li;
	mlod_rt_level_info_get(ctx, MLOD_RT_MESH, 0, 0, &li, NULL);
	const unsigned shown1 = mlod_rt_instance_state(ctx, id)->level[MLOD_RT_MESH];
	const int failed1 = li.failed;
	fail_at = 0;
	mlod_result r2 = MLOD_OK;
	for (int f = 0; f < 2 && r2 == MLOD_OK; f++) {
		mlod_rt_update(ctx, &sel, &id, &d, 1, 0, &e);
		r2 = mlod_rt_stream(ctx, SIZE_MAX, NULL, &e);
	}
	mlod_rt_level_info_get(ctx, MLOD_RT_MESH, 0, 0, &li, NULL);
	const unsigned shown2 = mlod_rt_instance_state(ctx, id)->level[MLOD_RT_MESH];
	mlod_rt_close(ctx);
	CHECK(r1 == MLOD_ERR_NOMEM && failed1 && shown1 == 1, "short of memory: stream %d, failed %d, shows %u; want "
	      "NOMEM, 1, level 1", (int)r1, failed1, shown1);
	CHECK(r2 == MLOD_OK && li.resident && !li.failed && shown2 == 0,
	      "memory back: stream %d '%s', level 0 resident %d failed %d, shows %u", (int)r2, e.message, li.resident,
	      li.failed, shown2);
}

/* ---------------------------------------------------------------- */
/* Issue 5: INFO's counts against the chunks                          */
/* ---------------------------------------------------------------- */

static void wr32(uint8_t *p, uint32_t v)
{
	p[0] = (uint8_t)v, p[1] = (uint8_t)(v >> 8), p[2] = (uint8_t)(v >> 16), p[3] = (uint8_t)(v >> 24);
}

/* A copy of tubeman's pack with the u32 at byte at of INFO's record set
 * to v and every CRC made to match; NULL when INFO is not a plain
 * container (the test then fails). */
static uint8_t *info_edit(uint32_t at, uint32_t v)
{
	mlod_pack p;
	mlod_error e;
	if (mlod_pack_open(tube, tube_size, &p, &e))
		return NULL;
	uint8_t *d = malloc(tube_size);
	int ci = mlod_pack_find(&p, MLOD_CHUNK_INFO, 0, 0);
	if (!d || ci < 0 || p.chunks[ci].entropy || p.chunks[ci].stored_size < 100) {
		mlod_pack_close(&p);
		free(d);
		return NULL;
	}
	memcpy(d, tube, tube_size);
	const uint64_t off = p.chunks[ci].offset;
	const uint32_t ns = d[off];
	wr32(d + off + 4 + 16 * ns + at, v);
	for (uint32_t i = 0; i < p.chunk_count; i++)
		wr32(d + 32 + 48 * i + 32, mlod_pack_crc32(0, d + p.chunks[i].offset, p.chunks[i].stored_size));
	wr32(d + 24, mlod_pack_crc32(0, d + 32, 48 * (size_t)p.chunk_count));
	wr32(d + 28, mlod_pack_crc32(0, d, 28));
	mlod_pack_close(&p);
	return d;
}

/* INFO saying 1000 or 0 joints (SKELETON has 31), 2 instances (MESH has
 * 1 part), first_drawable 0: the runtime's open refuses each, from memory
 * and through a read callback, with MLOD_ERR_PARSE naming INFO; the pack
 * as written opens. */
TEST(info_counts_checked)
{
	SKIP_IF_NO_PACK(info_counts_checked);
	CHECK(tube_ready(), "mlod-pack on tubeman failed");
	static const struct {
		uint32_t at, v;
	} edits[] = { { 0, 1000 }, { 0, 0 }, { 24, 2 }, { 64, 0 }, { 4, 1 } };
	for (size_t k = 0; k < sizeof edits / sizeof edits[0]; k++) {
		uint8_t *d = info_edit(edits[k].at, edits[k].v);
		CHECK(d, "editing INFO");
		rt_mem_source m = { d, tube_size, 0, 0 };
		for (int src = 0; src < 2; src++) {
			mlod_error e = { 0 };
			mlod_rt_ctx *ctx = NULL;
			mlod_result r = src ? mlod_rt_open_read(rt_mem_read, &m, m.size, NULL, &ctx, &e)
			                    : mlod_rt_open_memory(d, tube_size, NULL, &ctx, &e);
			mlod_rt_close(ctx);
			const int valid = edits[k].at == 4; /* skin_count 1: as written */
			if (valid ? r != MLOD_OK : (r != MLOD_ERR_PARSE || strncmp(e.message, "INFO: ", 6) != 0)) {
				free(d);
				CHECK(0, "INFO field at %u set to %u, %s: open gave %d '%s'", edits[k].at, edits[k].v,
				      src ? "read" : "memory", (int)r, e.message);
			}
		}
		free(d);
	}
}

int main(int argc, char **argv)
{
	(void)argc;
	static const char *const samples[] = { "samples/RobotExpressive.glb", "samples/tubeman.glb", NULL };
	rt_packer_setup(argv[0], "rt_edges", samples);
	RUN(mesh_room_is_its_size);
	RUN(failed_load_spends_no_budget);
	RUN(stats_of_null_context);
	RUN(allocator_both_or_neither);
	RUN(time_stays_finite);
	RUN(morph_part_out_of_range);
	RUN(nomem_level_tried_again);
	RUN(info_counts_checked);
	free(tube);
	rt_packer_cleanup();
	TEST_EXIT();
}
