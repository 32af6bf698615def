/*
 * test_rt_probe.c: the runtime bugs a new-user probe found (branch rtfix):
 * a static prop (no joints) opens, poses to nothing and skins its static
 * parts by their offsets; a corrupt chunk fails its own level and every
 * level that needs it, and the others still load as fallbacks; on a pack
 * without a mesh, mlod_rt_skin checks the instance and mlod_rt_palette
 * after it poses in full; mlod_rt_update refuses distances that are not
 * finite and >= 0 and a dt that is not finite, changing nothing; stats
 * report budget 0 for no limit. A valid pack under each failing
 * allocation in turn gives MLOD_ERR_NOMEM only (a second probe).
 *
 * The tests on packs run mlod-pack (MLOD_PACK, else build/release/bin/
 * mlod-pack from the repository's root, where tests/run.sh runs) on the
 * committed samples and on a box glb written here; without mlod-pack or
 * the samples they print SKIP. The others use decoded views (rt_test.h).
 * This program links libmlodrt.a alone, as every tests/rt program.
 */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <stdint.h>
#include <unistd.h>

#include "rt_test.h"
#include "rt_packer.h"

/* ---------------------------------------------------------------- */
/* A static box glb, written here: 8 corners of the unit cube at the  */
/* origin, 12 triangles, one node translated by BOX_T; no skin, no    */
/* animation.                                                         */
/* ---------------------------------------------------------------- */

static const float BOX_T[3] = { 1.0f, 2.0f, 3.0f };

static void le32(uint8_t *p, uint32_t v)
{
	p[0] = (uint8_t)v, p[1] = (uint8_t)(v >> 8), p[2] = (uint8_t)(v >> 16), p[3] = (uint8_t)(v >> 24);
}

static int write_box_glb(const char *path)
{
	static const float pos[8][3] = { { 0, 0, 0 }, { 1, 0, 0 }, { 1, 1, 0 }, { 0, 1, 0 },
		                         { 0, 0, 1 }, { 1, 0, 1 }, { 1, 1, 1 }, { 0, 1, 1 } };
	static const uint16_t idx[36] = { 0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
		                          1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7 };
	uint8_t bin[96 + 72];
	memcpy(bin, pos, 96);
	memcpy(bin + 96, idx, 72);
	char json[1024];
	int jn = snprintf(json, sizeof json,
	                  "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
	                  "\"nodes\":[{\"name\":\"box\",\"mesh\":0,\"translation\":[%g,%g,%g]}],"
	                  "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1}]}],"
	                  "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":8,\"type\":\"VEC3\","
	                  "\"min\":[0,0,0],\"max\":[1,1,1]},"
	                  "{\"bufferView\":1,\"componentType\":5123,\"count\":36,\"type\":\"SCALAR\"}],"
	                  "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":96,\"target\":34962},"
	                  "{\"buffer\":0,\"byteOffset\":96,\"byteLength\":72,\"target\":34963}],"
	                  "\"buffers\":[{\"byteLength\":168}]}",
	                  (double)BOX_T[0], (double)BOX_T[1], (double)BOX_T[2]);
	while (jn % 4)
		json[jn++] = ' ';
	uint8_t head[20], binhead[8];
	memcpy(head, "glTF", 4);
	le32(head + 4, 2);
	le32(head + 8, (uint32_t)(12 + 8 + jn + 8 + sizeof bin));
	le32(head + 12, (uint32_t)jn);
	memcpy(head + 16, "JSON", 4);
	le32(binhead, sizeof bin);
	memcpy(binhead + 4, "BIN\0", 4);
	FILE *f = fopen(path, "wb");
	if (!f)
		return -1;
	int ok = fwrite(head, 1, 20, f) == 20 && fwrite(json, 1, (size_t)jn, f) == (size_t)jn &&
	         fwrite(binhead, 1, 8, f) == 8 && fwrite(bin, 1, sizeof bin, f) == sizeof bin;
	return fclose(f) == 0 && ok ? 0 : -1;
}

/* ---------------------------------------------------------------- */
/* 1. Static props                                                    */
/* ---------------------------------------------------------------- */

/* Views of a prop without joints: one mesh level, one static part. */
TEST(static_views_open_and_skin)
{
	static mlod_pack_skeleton sk;
	static float p[] = { 0, 0, 0, 1, 0, 0, 0, 1, 0 };
	static uint32_t ix[] = { 0, 1, 2 };
	static mlod_pack_part part;
	static mlod_pack_mesh mesh;
	static mlod_rt_view_level vs[1], vm[1];
	memset(&sk, 0, sizeof sk);
	memset(&part, 0, sizeof part);
	memset(&mesh, 0, sizeof mesh);
	memset(vs, 0, sizeof vs);
	memset(vm, 0, sizeof vm);
	part.rec.vertex_count = 3, part.rec.index_count = 3, part.rec.skin = -1, part.rec.joint = -1;
	fx_identity(part.rec.offset);
	part.rec.offset[12] = 5, part.rec.offset[13] = 6, part.rec.offset[14] = 7;
	part.positions = p, part.indices = ix;
	mesh.part_count = 1, mesh.parts = &part;
	vm[0].data = &mesh;
	mlod_rt_views v = { &sk, 1, vs, 1, vm, 0, 0, NULL };
	mlod_error e = { 0 };
	mlod_rt_ctx *ctx = NULL;
	CHECK_OK(mlod_rt_open_views(&v, NULL, &ctx, &e), e);
	CHECK(mlod_rt_joint_count(ctx) == 0 && mlod_rt_palette_size(ctx) == 0, "joints %u palette %u",
	      mlod_rt_joint_count(ctx), mlod_rt_palette_size(ctx));
	uint32_t id;
	CHECK_OK(mlod_rt_instance_create(ctx, 0, 0, 0, &id, &e), e);
	mlod_rt_select sel;
	mlod_rt_select_default(&sel);
	float d = 10;
	CHECK_OK(mlod_rt_update(ctx, &sel, &id, &d, 1, 0.1f, &e), e);
	CHECK_OK(mlod_rt_stream(ctx, 1 << 20, NULL, &e), e);
	mlod_rt_scratch *s = mlod_rt_scratch_create(ctx);
	CHECK(s, "no scratch");
	const float *w;
	const uint32_t *js;
	uint32_t jc = 99, pc = 99, vc = 0;
	CHECK_OK(mlod_rt_pose(ctx, s, id, &w, &js, &jc, &e), e);
	CHECK(jc == 0, "posed %u joints", jc);
	const float *pal;
	CHECK_OK(mlod_rt_palette(ctx, s, &pal, &pc, &e), e);
	CHECK(pc == 0, "palette %u", pc);
	float out[9];
	CHECK_OK(mlod_rt_skin(ctx, s, id, out, 12, NULL, 0, 3, &vc, &e), e);
	CHECK(vc == 3, "%u vertices", vc);
	for (int i = 0; i < 3; i++)
		for (int k = 0; k < 3; k++)
			CHECK(out[3 * i + k] == p[3 * i + k] + part.rec.offset[12 + k], "vertex %d coord %d: %g", i, k,
			      (double)out[3 * i + k]);
	mlod_rt_scratch_destroy(ctx, s);
	mlod_rt_close(ctx);
}

/* A box glb packed by mlod-pack: open (memory and path), select, skin. */
TEST(static_pack_opens)
{
	SKIP_IF_NO_PACK(static_pack_opens);
	char glb[512], pk[512];
	snprintf(glb, sizeof glb, "%s/box.glb", tmpdir);
	CHECK(write_box_glb(glb) == 0, "writing %s", glb);
	CHECK(run_pack(glb, "", "box.mlod", pk, sizeof pk) == 0, "mlod-pack on %s failed", glb);
	mlod_error e = { 0 };
	mlod_rt_ctx *ctx = NULL;
	CHECK_OK(mlod_rt_open_path(pk, NULL, &ctx, &e), e);
	CHECK(mlod_rt_joint_count(ctx) == 0 && mlod_rt_palette_size(ctx) == 0 && mlod_rt_clip_count(ctx) == 0,
	      "joints %u palette %u clips %u", mlod_rt_joint_count(ctx), mlod_rt_palette_size(ctx),
	      mlod_rt_clip_count(ctx));
	const uint32_t L = mlod_rt_level_count(ctx, MLOD_RT_MESH);
	CHECK(L >= 1, "no mesh level");
	uint32_t id;
	CHECK_OK(mlod_rt_instance_create(ctx, 0, 0, MLOD_RT_LOOP, &id, &e), e);
	mlod_rt_select sel;
	mlod_rt_select_default(&sel);
	mlod_rt_scratch *s = mlod_rt_scratch_create(ctx);
	CHECK(s, "no scratch");
	float out[3 * 64];
	for (uint32_t l = 0; l < L; l++) {
		sel.force_level = (int)l;
		float d = 1;
		CHECK_OK(mlod_rt_update(ctx, &sel, &id, &d, 1, 1.0f / 30, &e), e);
		CHECK_OK(mlod_rt_stream(ctx, SIZE_MAX, NULL, &e), e);
		const mlod_rt_state *st = mlod_rt_instance_state(ctx, id);
		CHECK(st->wanted[MLOD_RT_MESH] == l && st->level[MLOD_RT_MESH] == l && !st->fallback,
		      "level %u: wanted %u shown %u fallback %x", l, st->wanted[MLOD_RT_MESH], st->level[MLOD_RT_MESH],
		      st->fallback);
		uint32_t vc = 0, pc = 9;
		const uint32_t want = mlod_rt_mesh_vertex_count(ctx, l);
		CHECK(want >= 4 && want <= 64, "level %u: %u vertices", l, want);
		CHECK_OK(mlod_rt_skin(ctx, s, id, out, 12, NULL, 0, 64, &vc, &e), e);
		CHECK(vc == want, "level %u: skinned %u of %u", l, vc, want);
		for (uint32_t v = 0; v < vc; v++)
			for (int k = 0; k < 3; k++) {
				const double x = out[3 * v + k] - BOX_T[k];
				/* level 0 is the box; coarser levels move vertices
				 * inside it (edge collapses) */
				CHECK(l ? x > -1e-3 && x < 1 + 1e-3 : NEAR(x, 0, 1e-3) || NEAR(x, 1, 1e-3),
				      "level %u vertex %u: %g %g %g, not %s", l, v, (double)out[3 * v],
				      (double)out[3 * v + 1], (double)out[3 * v + 2], l ? "in the box" : "a corner + t");
			}
		const float *pal;
		CHECK_OK(mlod_rt_palette(ctx, s, &pal, &pc, &e), e);
		CHECK(pc == 0, "palette %u", pc);
	}
	mlod_rt_scratch_destroy(ctx, s);
	mlod_rt_close(ctx);
}

/* ---------------------------------------------------------------- */
/* 2. A corrupt chunk                                                 */
/* ---------------------------------------------------------------- */

static uint8_t *robot;
static size_t robot_size;

static int mem_read(void *user, uint64_t offset, size_t size, void *dst)
{
	(void)user;
	if (offset > robot_size || size > robot_size - offset)
		return -1;
	memcpy(dst, robot + offset, size);
	return 0;
}

static int level_failed(const mlod_rt_ctx *ctx, uint32_t level)
{
	mlod_rt_level_info li;
	return mlod_rt_level_info_get(ctx, MLOD_RT_MESH, level, 0, &li, NULL) == MLOD_OK && li.failed;
}

static int level_resident(const mlod_rt_ctx *ctx, uint32_t level)
{
	mlod_rt_level_info li;
	return mlod_rt_level_info_get(ctx, MLOD_RT_MESH, level, 0, &li, NULL) == MLOD_OK && li.resident;
}

/* One pass: the instance wants mesh level want; checks what fails and
 * what it shows. */
static const char *corrupt_pass(int through_read, char *msg, size_t cap)
{
	mlod_error e = { 0 };
	mlod_rt_ctx *ctx = NULL;
	mlod_result r = through_read ? mlod_rt_open_read(mem_read, NULL, robot_size, NULL, &ctx, &e)
	                             : mlod_rt_open_memory(robot, robot_size, NULL, &ctx, &e);
	if (r) {
		snprintf(msg, cap, "open: %s", e.message);
		return msg;
	}
	const char *bad = NULL;
	const uint32_t L = mlod_rt_level_count(ctx, MLOD_RT_MESH);
	uint32_t id, id2;
	mlod_rt_instance_create(ctx, 0, 0, 0, &id, &e);
	mlod_rt_instance_create(ctx, 0, 0, 0, &id2, &e);
	mlod_rt_select sel;
	mlod_rt_select_default(&sel);
	sel.force_level = 0;
	float d = 1;
	mlod_rt_update(ctx, &sel, &id, &d, 1, 0, &e);
	e.message[0] = 0;
	r = mlod_rt_stream(ctx, SIZE_MAX, NULL, &e);
	const mlod_rt_state *st = mlod_rt_instance_state(ctx, id);
	if (r != MLOD_ERR_PARSE || !strstr(e.message, "level 1"))
		snprintf(msg, cap, "stream: %d '%s', want a parse error naming level 1", (int)r, e.message), bad = msg;
	else if (!level_failed(ctx, 0) || !level_failed(ctx, 1))
		snprintf(msg, cap, "failed: level 0 %d, level 1 %d; want both", level_failed(ctx, 0), level_failed(ctx, 1)),
		    bad = msg;
	else if (level_failed(ctx, 2) || level_failed(ctx, 3))
		snprintf(msg, cap, "levels 2 and 3 marked failed"), bad = msg;
	else if (st->wanted[MLOD_RT_MESH] != 0 || st->level[MLOD_RT_MESH] != 2 || !level_resident(ctx, 2) ||
	         !(st->fallback & (1u << MLOD_RT_MESH)))
		snprintf(msg, cap, "wants %u, shows %u (resident %d), fallback %x; want 0, 2 (the finest intact), set",
		         st->wanted[MLOD_RT_MESH], st->level[MLOD_RT_MESH], level_resident(ctx, 2), st->fallback),
		    bad = msg;
	if (!bad) {
		mlod_rt_stats stt;
		mlod_rt_stats_get(ctx, &stt);
		if (stt.failures != 2 || stt.pending_levels != 0)
			snprintf(msg, cap, "stats: %llu failures, %u pending; want 2, 0", (unsigned long long)stt.failures,
			         stt.pending_levels),
			    bad = msg;
	}
	if (!bad) {
		/* Another instance wanting level 3 loads it; nothing more fails;
		 * wanting level 1 then does not try it again: level 2 shows. */
		sel.force_level = 3;
		mlod_rt_update(ctx, &sel, &id2, &d, 1, 0, &e);
		sel.force_level = 1;
		r = mlod_rt_stream(ctx, SIZE_MAX, NULL, &e);
		st = mlod_rt_instance_state(ctx, id2);
		mlod_rt_stats stt;
		mlod_rt_stats_get(ctx, &stt);
		if (r != MLOD_OK || st->level[MLOD_RT_MESH] != 3 || stt.failures != 2)
			snprintf(msg, cap, "level 3: stream %d, shown %u, %llu failures", (int)r, st->level[MLOD_RT_MESH],
			         (unsigned long long)stt.failures),
			    bad = msg;
		mlod_rt_update(ctx, &sel, &id, &d, 1, 0, &e);
		r = mlod_rt_stream(ctx, SIZE_MAX, NULL, &e);
		st = mlod_rt_instance_state(ctx, id);
		mlod_rt_stats_get(ctx, &stt);
		if (!bad && (r != MLOD_OK || st->wanted[MLOD_RT_MESH] != 1 || st->level[MLOD_RT_MESH] != 2 ||
		             stt.failures != 2))
			snprintf(msg, cap, "wanting 1: stream %d, wants %u shows %u, %llu failures", (int)r,
			         st->wanted[MLOD_RT_MESH], st->level[MLOD_RT_MESH], (unsigned long long)stt.failures),
			    bad = msg;
	}
	if (!bad && L < 5)
		snprintf(msg, cap, "%u mesh levels", L), bad = msg;
	mlod_rt_close(ctx);
	return bad;
}

TEST(corrupt_chunk_fails_its_dependents_only)
{
	SKIP_IF_NO_PACK(corrupt_chunk_fails_its_dependents_only);
	char pk[512];
	CHECK(run_pack("samples/RobotExpressive.glb", "", "robot.mlod", pk, sizeof pk) == 0, "mlod-pack on the robot failed");
	robot = read_all(pk, &robot_size);
	CHECK(robot, "reading %s", pk);
	mlod_pack p;
	mlod_error e = { 0 };
	CHECK_OK(mlod_pack_open(robot, robot_size, &p, &e), e);
	int k = mlod_pack_find(&p, MLOD_CHUNK_MESH, 1, 0);
	uint64_t off = k >= 0 ? p.chunks[k].offset : 0;
	uint32_t n = k >= 0 ? p.chunks[k].stored_size : 0;
	mlod_pack_close(&p);
	CHECK(k >= 0 && n > 64, "no MESH level 1 chunk");
	/* Flip bytes in the middle of its payload; the CRC is left stale. */
	for (uint32_t i = n / 2; i < n / 2 + 8; i++)
		robot[off + i] ^= 0x5a;
	char msg[1024];
	const char *why = corrupt_pass(0, msg, sizeof msg);
	if (!why)
		why = corrupt_pass(1, msg, sizeof msg);
	free(robot);
	robot = NULL;
	CHECK(!why, "%s", why);
}

/* ---------------------------------------------------------------- */
/* 4. No mesh: skin and palette                                       */
/* ---------------------------------------------------------------- */

static const char *no_mesh_checks(mlod_rt_ctx *ctx, char *msg, size_t cap)
{
	mlod_error e = { 0 };
	uint32_t id;
	if (mlod_rt_instance_create(ctx, 0, 0.25f, MLOD_RT_LOOP, &id, &e))
		return snprintf(msg, cap, "create: %s", e.message), msg;
	mlod_rt_scratch *s = mlod_rt_scratch_create(ctx);
	const char *bad = NULL;
	float out[3];
	uint32_t vc = 7, pc = 0;
	const float *pal = NULL, *w = NULL;
	mlod_result r = mlod_rt_skin(ctx, s, id + 1000, out, 12, NULL, 0, 1, &vc, &e);
	if (r != MLOD_ERR_INVALID_ARG)
		snprintf(msg, cap, "skin of an id not alive: %d", (int)r), bad = msg;
	else if ((r = mlod_rt_skin(ctx, s, id, out, 12, NULL, 0, 1, &vc, &e)) != MLOD_OK || vc != 0)
		snprintf(msg, cap, "skin: %d %s, %u vertices", (int)r, e.message, vc), bad = msg;
	else if ((r = mlod_rt_palette(ctx, s, &pal, &pc, &e)) != MLOD_OK || pc != mlod_rt_palette_size(ctx))
		snprintf(msg, cap, "palette after skin: %d %s", (int)r, e.message), bad = msg;
	else {
		/* that palette is the one of the instance's full pose */
		static float ref[16 * 64];
		const uint32_t P = pc < 64 ? pc : 64;
		memcpy(ref, pal, 16 * sizeof(float) * P);
		mlod_rt_scratch *s2 = mlod_rt_scratch_create(ctx);
		if (!s2 || mlod_rt_pose(ctx, s2, id, &w, NULL, NULL, &e) || mlod_rt_palette(ctx, s2, &pal, &pc, &e))
			snprintf(msg, cap, "pose then palette: %s", e.message), bad = msg;
		else if (P && fx_maxdiff(ref, pal, 16 * (int)P) != 0)
			snprintf(msg, cap, "the palette after skin differs from the pose's"), bad = msg;
		mlod_rt_scratch_destroy(ctx, s2);
	}
	mlod_rt_scratch_destroy(ctx, s);
	return bad;
}

TEST(no_mesh_views_skin_then_palette)
{
	fx_build(0);
	mlod_rt_views v = fx_views;
	v.mesh_levels = 0, v.mesh = NULL;
	mlod_error e = { 0 };
	mlod_rt_ctx *ctx = NULL;
	CHECK_OK(mlod_rt_open_views(&v, NULL, &ctx, &e), e);
	char msg[1024];
	const char *why = no_mesh_checks(ctx, msg, sizeof msg);
	mlod_rt_close(ctx);
	CHECK(!why, "%s", why);
}

TEST(walk_pack_skin_then_palette)
{
	SKIP_IF_NO_PACK(walk_pack_skin_then_palette);
	char pk[512];
	CHECK(run_pack("samples/cmu_12_01_walk.bvh", "", "walk.mlod", pk, sizeof pk) == 0, "mlod-pack on the walk failed");
	mlod_error e = { 0 };
	mlod_rt_ctx *ctx = NULL;
	CHECK_OK(mlod_rt_open_path(pk, NULL, &ctx, &e), e);
	CHECK(mlod_rt_level_count(ctx, MLOD_RT_MESH) == 0, "the walk has a mesh");
	char msg[1024];
	const char *why = no_mesh_checks(ctx, msg, sizeof msg);
	mlod_rt_close(ctx);
	CHECK(!why, "%s", why);
}

/* ---------------------------------------------------------------- */
/* 5. Distances and dt                                                */
/* ---------------------------------------------------------------- */

TEST(update_refuses_bad_distances_and_dt)
{
	fx_build(0);
	mlod_error e = { 0 };
	mlod_rt_ctx *ctx = NULL;
	CHECK_OK(mlod_rt_open_views(&fx_views, NULL, &ctx, &e), e);
	uint32_t ids[2];
	CHECK_OK(mlod_rt_instance_create(ctx, 0, 0.5f, 0, &ids[0], &e), e);
	CHECK_OK(mlod_rt_instance_create(ctx, 0, 0.5f, 0, &ids[1], &e), e);
	mlod_rt_select sel;
	mlod_rt_select_default(&sel);
	float ok[2] = { 150, 150 };
	CHECK_OK(mlod_rt_update(ctx, &sel, ids, ok, 2, 0.25f, &e), e);
	const mlod_rt_state before0 = *mlod_rt_instance_state(ctx, ids[0]);
	const mlod_rt_state before1 = *mlod_rt_instance_state(ctx, ids[1]);
	CHECK(before0.time == 0.75f && before0.wanted[MLOD_RT_MESH] > 0, "time %g wanted %u", (double)before0.time,
	      before0.wanted[MLOD_RT_MESH]);
	mlod_rt_stats s0;
	mlod_rt_stats_get(ctx, &s0);
	const float bad[] = { NAN, -1.0f, INFINITY, -INFINITY };
	for (int b = 0; b < 4; b++) {
		float d[2] = { 1, bad[b] };
		e.message[0] = 0;
		mlod_result r = mlod_rt_update(ctx, &sel, ids, d, 2, 0.25f, &e);
		CHECK(r == MLOD_ERR_INVALID_ARG && strstr(e.message, "index 1"), "distance %g: %d '%s'", (double)bad[b],
		      (int)r, e.message);
		CHECK(memcmp(mlod_rt_instance_state(ctx, ids[0]), &before0, sizeof before0) == 0 &&
		      memcmp(mlod_rt_instance_state(ctx, ids[1]), &before1, sizeof before1) == 0,
		      "distance %g: an instance changed", (double)bad[b]);
		mlod_rt_stats s1;
		mlod_rt_stats_get(ctx, &s1);
		CHECK(s1.pending_levels == s0.pending_levels, "distance %g: the wanted levels changed", (double)bad[b]);
	}
	const float baddt[] = { NAN, INFINITY, -INFINITY };
	for (int b = 0; b < 3; b++) {
		mlod_result r = mlod_rt_update(ctx, &sel, ids, ok, 2, baddt[b], &e);
		CHECK(r == MLOD_ERR_INVALID_ARG, "dt %g: %d", (double)baddt[b], (int)r);
		CHECK(memcmp(mlod_rt_instance_state(ctx, ids[0]), &before0, sizeof before0) == 0, "dt %g: changed",
		      (double)baddt[b]);
		const float cam[3] = { 0, 0, 0 }, posn[6] = { 1, 0, 0, 2, 0, 0 };
		r = mlod_rt_update_positions(ctx, &sel, cam, ids, posn, 2, baddt[b], &e);
		CHECK(r == MLOD_ERR_INVALID_ARG, "positions, dt %g: %d", (double)baddt[b], (int)r);
	}
	const float cam[3] = { 0, 0, 0 }, posn[6] = { 1, 0, 0, INFINITY, 0, 0 };
	mlod_result r = mlod_rt_update_positions(ctx, &sel, cam, ids, posn, 2, 0.25f, &e);
	CHECK(r == MLOD_ERR_INVALID_ARG && strstr(e.message, "index 1"), "positions at infinity: %d '%s'", (int)r,
	      e.message);
	CHECK(memcmp(mlod_rt_instance_state(ctx, ids[0]), &before0, sizeof before0) == 0, "positions: changed");
	/* 0 and -0 are fine */
	float z[2] = { 0.0f, -0.0f };
	CHECK_OK(mlod_rt_update(ctx, &sel, ids, z, 2, -0.25f, &e), e);
	CHECK(mlod_rt_instance_state(ctx, ids[0])->time == 0.5f, "time %g", (double)mlod_rt_instance_state(ctx, ids[0])->time);
	mlod_rt_close(ctx);
}

/* Times that are not finite: create and set refuse them and leave the
 * instance as it was. */
TEST(instance_refuses_bad_times)
{
	fx_build(0);
	mlod_error e = { 0 };
	mlod_rt_ctx *ctx = NULL;
	CHECK_OK(mlod_rt_open_views(&fx_views, NULL, &ctx, &e), e);
	uint32_t id;
	CHECK_OK(mlod_rt_instance_create(ctx, 0, 0.5f, 0, &id, &e), e);
	const mlod_rt_state before = *mlod_rt_instance_state(ctx, id);
	const float bad[] = { NAN, INFINITY, -INFINITY };
	for (int b = 0; b < 3; b++) {
		uint32_t other = 12345;
		e.message[0] = 0;
		mlod_result r = mlod_rt_instance_create(ctx, 0, bad[b], 0, &other, &e);
		CHECK(r == MLOD_ERR_INVALID_ARG && strstr(e.message, "not finite") && other == 12345,
		      "create at %g: %d '%s'", (double)bad[b], (int)r, e.message);
		e.message[0] = 0;
		r = mlod_rt_instance_set(ctx, id, 0, bad[b], MLOD_RT_LOOP, &e);
		CHECK(r == MLOD_ERR_INVALID_ARG && strstr(e.message, "not finite"), "set at %g: %d '%s'", (double)bad[b],
		      (int)r, e.message);
		CHECK(memcmp(mlod_rt_instance_state(ctx, id), &before, sizeof before) == 0, "set at %g: the instance changed",
		      (double)bad[b]);
	}
	CHECK_OK(mlod_rt_instance_set(ctx, id, 0, 1.5f, 0, &e), e);
	CHECK(mlod_rt_instance_state(ctx, id)->time == 1.5f, "a finite time was not taken");
	mlod_rt_close(ctx);
}

/* ---------------------------------------------------------------- */
/* 6. The budget in the stats                                          */
/* ---------------------------------------------------------------- */

TEST(stats_budget)
{
	fx_build(0);
	mlod_error e = { 0 };
	const size_t budgets[2] = { 0, 1u << 24 };
	for (int i = 0; i < 2; i++) {
		mlod_rt_config cfg = { budgets[i], 0, NULL };
		mlod_rt_ctx *ctx = NULL;
		CHECK_OK(mlod_rt_open_views(&fx_views, &cfg, &ctx, &e), e);
		mlod_rt_stats st;
		mlod_rt_stats_get(ctx, &st);
		mlod_rt_close(ctx);
		CHECK(st.budget_bytes == budgets[i], "budget %zu reported as %zu", budgets[i], st.budget_bytes);
	}
}

/* ---------------------------------------------------------------- */
/* 7. Out of memory is NOMEM                                         */
/* ---------------------------------------------------------------- */

/* An allocator that fails its fail_at-th call (1-based), and only it. */
static unsigned long oom_calls, oom_fail_at;

static void *oom_malloc(void *user, size_t size)
{
	(void)user;
	if (++oom_calls == oom_fail_at)
		return NULL;
	return malloc(size);
}

static void oom_free(void *user, void *p)
{
	(void)user;
	free(p);
}

/* A valid pack opened and streamed in full with each one allocation
 * failing in turn: every error is MLOD_ERR_NOMEM (three mesh paths of
 * the reader said MLOD_ERR_PARSE, "out of memory for ... bytes of
 * scratch": a caller could not tell low memory from a corrupt pack). */
TEST(out_of_memory_is_nomem)
{
	SKIP_IF_NO_PACK(out_of_memory_is_nomem);
	char pk[512];
	CHECK(run_pack("samples/tubeman.glb", "", "oom.mlod", pk, sizeof pk) == 0, "mlod-pack on the tubeman failed");
	size_t size = 0;
	uint8_t *data = read_all(pk, &size);
	CHECK(data, "cannot read %s", pk);
	const mlod_rt_allocator al = { oom_malloc, oom_free, NULL };
	unsigned long total = 0, failures = 0;
	for (unsigned long at = 1;; at++) {
		mlod_rt_config cfg = { 0, 4, &al };
		mlod_error e = { 0 };
		mlod_rt_ctx *ctx = NULL;
		oom_calls = 0, oom_fail_at = at;
		mlod_result r = mlod_rt_open_memory(data, size, &cfg, &ctx, &e);
		if (r == MLOD_OK) {
			for (int l = 0; l < MLOD_RT_LAYERS; l++)
				for (uint32_t k = 0; k < mlod_rt_level_count(ctx, (mlod_rt_layer)l); k++)
					for (uint32_t item = 0; item < (l == MLOD_RT_MOTION ? mlod_rt_clip_count(ctx) : 1u); item++)
						mlod_rt_request(ctx, (mlod_rt_layer)l, k, item, NULL);
			r = mlod_rt_stream(ctx, SIZE_MAX, NULL, &e);
			mlod_rt_close(ctx);
		}
		if (oom_calls < at) { /* no allocation failed: every one was tried */
			CHECK(r == MLOD_OK, "no failed allocation, yet: %s", e.message);
			total = at - 1;
			break;
		}
		failures += r != MLOD_OK;
		if (r != MLOD_OK && r != MLOD_ERR_NOMEM) {
			free(data);
			CHECK(0, "allocation %lu failing: code %d, %s", at, (int)r, e.message);
		}
	}
	free(data);
	CHECK(failures > 0, "no failed allocation reported an error");
	printf("# %lu allocations, each failing in turn: %lu errors, all MLOD_ERR_NOMEM\n", total, failures);
}

/* A fuzzed pack (tests/fuzz/regress/pack/bounds-nan-bound.mlod: one byte
 * of a tubeman pack's SKELETON changed, CRCs made right) poses some
 * palette entries to huge matrices whose bound comes to NaN: the NaN was
 * washed out by the next entry's bound, so mlod_rt_bounds gave the empty
 * box while mlod_rt_skin wrote finite vertices (-1.4e20) outside it. Now
 * such a bound is all of space, and every finite skinned vertex of every
 * forced level lies in the box. */
TEST(bounds_hold_a_hostile_pose)
{
	size_t size = 0;
	uint8_t *data = read_all("tests/fuzz/regress/pack/bounds-nan-bound.mlod", &size);
	CHECK(data, "cannot read tests/fuzz/regress/pack/bounds-nan-bound.mlod (run from the repository's root)");
	mlod_error e = { 0 };
	mlod_rt_ctx *ctx = NULL;
	mlod_result r = mlod_rt_open_memory(data, size, NULL, &ctx, &e);
	if (r != MLOD_OK)
		free(data);
#if !MLOD_DRACO
	/* its mutated chunk says Draco: a runtime without the decoder refuses it */
	CHECK(r == MLOD_ERR_UNSUPPORTED && strstr(e.message, "Draco"), "without Draco: %s", e.message);
	printf("# a runtime built with MLOD_DRACO=0: %s\n", e.message);
	mlod_rt_close(ctx);
	return;
#endif
	CHECK_OK(r, e);
	const uint32_t cap = mlod_rt_max_vertex_count(ctx), levels = mlod_rt_level_count(ctx, MLOD_RT_MESH);
	float *pos = malloc(((size_t)cap + 1) * 3 * sizeof *pos);
	mlod_rt_scratch *s = mlod_rt_scratch_create(ctx);
	uint32_t id, outside = 0, checked = 0;
	int ok = pos && s && mlod_rt_instance_create(ctx, 0, 0.25f, MLOD_RT_LOOP, &id, &e) == MLOD_OK;
	for (uint32_t k = levels; ok && k-- > 0;) {
		mlod_rt_select sel;
		mlod_rt_select_default(&sel);
		sel.force_level = (int)k;
		const float d = 10.0f;
		float lo[3], hi[3];
		uint32_t vc = 0;
		ok = mlod_rt_update(ctx, &sel, &id, &d, 1, 1.0f / 30, &e) == MLOD_OK;
		(void)mlod_rt_stream(ctx, SIZE_MAX, NULL, &e); /* a corrupt level fails: a coarser one stands in */
		ok = ok && mlod_rt_bounds(ctx, s, id, lo, hi, &e) == MLOD_OK &&
		     mlod_rt_skin(ctx, s, id, pos, 12, NULL, 0, cap, &vc, &e) == MLOD_OK;
		for (uint32_t v = 0; ok && v < 3 * vc; v++)
			if (isfinite(pos[v]))
				checked++, outside += !(pos[v] >= lo[v % 3] && pos[v] <= hi[v % 3]);
	}
	if (s)
		mlod_rt_scratch_destroy(ctx, s);
	free(pos);
	mlod_rt_close(ctx);
	free(data);
	CHECK(ok, "%s", e.message);
	CHECK(checked > 0 && outside == 0, "%u of %u finite coordinates outside their box", outside, checked);
}

int main(int argc, char **argv)
{
	(void)argc;
	static const char *const samples[] = { "samples/RobotExpressive.glb", "samples/cmu_12_01_walk.bvh", NULL };
	rt_packer_setup(argv[0], "rt_probe", samples);
	RUN(static_views_open_and_skin);
	RUN(static_pack_opens);
	RUN(corrupt_chunk_fails_its_dependents_only);
	RUN(no_mesh_views_skin_then_palette);
	RUN(walk_pack_skin_then_palette);
	RUN(update_refuses_bad_distances_and_dt);
	RUN(instance_refuses_bad_times);
	RUN(stats_budget);
	RUN(out_of_memory_is_nomem);
	RUN(bounds_hold_a_hostile_pose);
	rt_packer_cleanup();
	TEST_EXIT();
}
