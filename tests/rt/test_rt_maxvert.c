/*
 * test_rt_maxvert.c: INFO's max_vertex_count (format 8.1, mlod(5) INFO):
 * mlod_rt_max_vertex_count is the largest mesh level's vertex count from
 * open on, before any level streams in, on packs mlod-pack writes of the
 * samples (tubeman, RobotExpressive, tubeman with --codec draco (a runtime
 * built with MLOD_DRACO=1) and RobotExpressive with --codec none)
 * and of a generated character (gen_tubeman, another mesh); a pack whose
 * INFO says less than a level has fails that level's load (and the whole
 * pack's check), one that says more than its MESH chunks can hold fails
 * its open, and a pack of the previous minor version (8.0: the field 0,
 * reserved) still opens and gives the largest resident level, as before.
 * The hostile packs are the written ones with INFO's bytes edited and
 * every CRC made to match again.
 */
#define _POSIX_C_SOURCE 200809L
#include <stdint.h>

#include "rt_test.h"
#include "rt_packer.h"

static void wr32(uint8_t *p, uint32_t v)
{
	for (int k = 0; k < 4; k++)
		p[k] = (uint8_t)(v >> (8 * k));
}

/* A pack as mlod-pack wrote it (read into memory), or NULL. */
typedef struct packed {
	const char *what;
	uint8_t *d;
	size_t n;
} packed;

static packed packs[5];
static int npacks;
/* The generated character of a one-frame walk: each joint one key, so its
 * MOTION chunks are the same bytes in 8.x as in 9.0 (each channel's first
 * key stored as it is, nested keys on their base's as zero differences). */
static packed still;
/* the tubeman Draco pack only where the runtime decodes Draco */
static const int want_packs = MLOD_DRACO ? 5 : 4;

static void pack_one(const char *what, const char *in, const char *opts, const char *out)
{
	char path[600];
	if (run_pack(in, opts, out, path, sizeof path) != 0)
		return;
	packed *p = &packs[npacks];
	p->what = what;
	if ((p->d = read_all(path, &p->n)) != NULL)
		npacks++;
}

/* The bytes of INFO's record in d (its 'INFO' stream, stored raw first in
 * the chunk), or NULL. */
static uint8_t *info_rec(uint8_t *d, size_t n)
{
	mlod_pack p;
	mlod_error e;
	if (mlod_pack_open(d, n, &p, &e))
		return NULL;
	int ci = mlod_pack_find(&p, MLOD_CHUNK_INFO, 0, 0);
	uint8_t *r = NULL;
	if (ci >= 0 && !p.chunks[ci].entropy && p.chunks[ci].stored_size >= 4 + 32 + 80)
		r = d + p.chunks[ci].offset + 4 + 16 * (size_t)d[p.chunks[ci].offset];
	mlod_pack_close(&p);
	return r;
}

/* Every CRC of d made to match its bytes again (each chunk's, the TOC's,
 * the header's). */
static void restamp(uint8_t *d, size_t n)
{
	/* the TOC's entries as they are (the CRCs change, not the layout) */
	uint32_t count = (uint32_t)d[12] | (uint32_t)d[13] << 8 | (uint32_t)d[14] << 16 | (uint32_t)d[15] << 24;
	for (uint32_t i = 0; i < count && 32 + 48 * (size_t)(i + 1) <= n; i++) {
		const uint8_t *t = d + 32 + 48 * (size_t)i;
		uint64_t off = 0;
		for (int k = 7; k >= 0; k--)
			off = off << 8 | t[16 + k];
		uint32_t size = (uint32_t)t[24] | (uint32_t)t[25] << 8 | (uint32_t)t[26] << 16 | (uint32_t)t[27] << 24;
		if (off <= n && size <= n - off)
			wr32(d + 32 + 48 * (size_t)i + 32, mlod_pack_crc32(0, d + off, size));
	}
	wr32(d + 24, mlod_pack_crc32(0, d + 32, 48 * (size_t)count));
	wr32(d + 28, mlod_pack_crc32(0, d, 28));
}

/* A copy of pk with INFO's max_vertex_count set to v (and, when minor >=
 * 0, the header's version set to 8.minor), CRCs restamped. */
static uint8_t *edited(const packed *pk, uint32_t v, int minor)
{
	uint8_t *d = malloc(pk->n);
	if (!d)
		return NULL;
	memcpy(d, pk->d, pk->n);
	uint8_t *r = info_rec(d, pk->n);
	if (!r) {
		free(d);
		return NULL;
	}
	wr32(r + 68, v);
	if (minor >= 0)
		d[4] = 8, d[5] = 0, d[6] = (uint8_t)minor, d[7] = (uint8_t)(minor >> 8);
	restamp(d, pk->n);
	return d;
}

/* Loads every mesh level, coarsest first; *max gets the largest
 * mlod_rt_mesh_vertex_count, *stated the largest vertex count
 * mlod_rt_max_vertex_count gave along the way, *failed the levels that
 * failed (the first failure's message in e). */
static void load_all(mlod_rt_ctx *ctx, uint32_t *max, uint32_t *stated, uint32_t *failed, mlod_error *first)
{
	*max = 0, *stated = mlod_rt_max_vertex_count(ctx), *failed = 0;
	first->message[0] = '\0';
	const uint32_t L = mlod_rt_level_count(ctx, MLOD_RT_MESH);
	for (uint32_t k = L; k-- > 0;) {
		mlod_error e = { 0 };
		if (mlod_rt_request(ctx, MLOD_RT_MESH, k, 0, &e) != MLOD_OK ||
		    mlod_rt_stream(ctx, SIZE_MAX, NULL, &e) != MLOD_OK) {
			if (!*failed)
				*first = e;
			++*failed;
		}
		uint32_t v = mlod_rt_mesh_vertex_count(ctx, k);
		*max = v > *max ? v : *max;
		if (mlod_rt_max_vertex_count(ctx) > *stated)
			*stated = mlod_rt_max_vertex_count(ctx);
	}
}

/* Opens d from memory (src 0) or through a read callback (src 1). */
static mlod_result open_src(int src, const uint8_t *d, size_t n, rt_mem_source *m, mlod_rt_ctx **ctx, mlod_error *e)
{
	*m = (rt_mem_source){ d, n, 0, 0 };
	return src ? mlod_rt_open_read(rt_mem_read, m, n, NULL, ctx, e) : mlod_rt_open_memory(d, n, NULL, ctx, e);
}

/* The value at open is the largest level's, and stays it as every level
 * loads; a buffer of that many vertices skins every level. */
TEST(known_at_open)
{
	SKIP_IF_NO_PACK(known_at_open);
	CHECK(npacks == want_packs, "mlod-pack or gen_tubeman failed (%d packs of %d)", npacks, want_packs);
	for (int i = 0; i < npacks; i++)
		for (int src = 0; src < 2; src++) {
			mlod_error e = { 0 };
			mlod_rt_ctx *ctx = NULL;
			rt_mem_source m;
			CHECK_OK(open_src(src, packs[i].d, packs[i].n, &m, &ctx, &e), e);
			const uint32_t at_open = mlod_rt_max_vertex_count(ctx);
			const uint32_t L = mlod_rt_level_count(ctx, MLOD_RT_MESH);
			uint32_t max, stated, failed;
			load_all(ctx, &max, &stated, &failed, &e);
			/* level 0 at that capacity, written whole */
			mlod_rt_scratch *s = mlod_rt_scratch_create(ctx);
			float *buf = malloc(24 * (size_t)at_open + 24);
			uint32_t id = 0, nv = 0;
			mlod_rt_select sel;
			mlod_rt_select_default(&sel);
			sel.force_level = 0;
			float d = 1.0f;
			mlod_error se = { 0 };
			mlod_result sr = s && buf ? mlod_rt_instance_create(ctx, 0, 0.0f, 0, &id, &se) : MLOD_ERR_NOMEM;
			if (sr == MLOD_OK)
				sr = mlod_rt_update(ctx, &sel, &id, &d, 1, 0.0f, &se);
			if (sr == MLOD_OK)
				sr = mlod_rt_skin(ctx, s, id, buf, 12, buf + 3 * (size_t)at_open, 12, at_open, &nv, &se);
			const uint32_t v0 = mlod_rt_mesh_vertex_count(ctx, 0);
			free(buf);
			mlod_rt_scratch_destroy(ctx, s);
			mlod_rt_close(ctx);
			CHECK(L >= 2, "%s: %u mesh levels", packs[i].what, L);
			CHECK(failed == 0, "%s: %u levels failed: %s", packs[i].what, failed, e.message);
			CHECK(at_open == max && stated == max,
			      "%s (%s): mlod_rt_max_vertex_count %u at open, %u at most as levels loaded, the levels' largest %u",
			      packs[i].what, src ? "read" : "memory", at_open, stated, max);
			CHECK(sr == MLOD_OK && nv == v0 && v0 > 0, "%s: level 0 at capacity %u: %d '%s', %u of %u vertices",
			      packs[i].what, at_open, (int)sr, se.message, nv, v0);
		}
}

/* A pack whose INFO says one vertex fewer than its largest level: it opens
 * (the coarsest level fits), the largest level's load fails with
 * MLOD_ERR_PARSE naming the level and INFO's field, and no other; the
 * pack's whole check fails too. Saying more than the largest level: the
 * levels load, the check fails. */
TEST(smaller_fails_the_level)
{
	SKIP_IF_NO_PACK(smaller_fails_the_level);
	CHECK(npacks == want_packs, "mlod-pack or gen_tubeman failed (%d packs of %d)", npacks, want_packs);
	for (int i = 0; i < npacks; i++) {
		mlod_error e = { 0 };
		mlod_rt_ctx *ctx = NULL;
		CHECK_OK(mlod_rt_open_memory(packs[i].d, packs[i].n, NULL, &ctx, &e), e);
		const uint32_t max = mlod_rt_max_vertex_count(ctx);
		/* the levels of max vertices: the ones that must fail */
		uint32_t of_max = 0, max2, stated, failed;
		load_all(ctx, &max2, &stated, &failed, &e);
		for (uint32_t k = 0; k < mlod_rt_level_count(ctx, MLOD_RT_MESH); k++)
			of_max += mlod_rt_mesh_vertex_count(ctx, k) == max;
		mlod_rt_close(ctx);
		CHECK(of_max >= 1 && max > 0, "%s: %u levels of %u vertices", packs[i].what, of_max, max);
		for (int more = 0; more < 2; more++) {
			uint8_t *d = edited(&packs[i], more ? max + 1 : max - 1, -1);
			CHECK(d, "editing %s", packs[i].what);
			for (int src = 0; src < 2; src++) {
				rt_mem_source m;
				ctx = NULL;
				mlod_result r = open_src(src, d, packs[i].n, &m, &ctx, &e);
				if (r != MLOD_OK) {
					free(d);
					CHECK(0, "%s, INFO %u: open %d '%s'", packs[i].what, more ? max + 1 : max - 1, (int)r,
					      e.message);
				}
				load_all(ctx, &max2, &stated, &failed, &e);
				mlod_rt_level_info li;
				mlod_rt_level_info_get(ctx, MLOD_RT_MESH, 0, 0, &li, NULL);
				mlod_rt_close(ctx);
				char want[96];
				snprintf(want, sizeof want, "vertices, more than INFO's max_vertex_count %u", max - 1);
				if (more ? failed != 0 || stated != max + 1
				         : failed != of_max || !li.failed || !strstr(e.message, "MESH level 0: ") ||
				               !strstr(e.message, want)) {
					free(d);
					CHECK(0, "%s (%s), INFO %u: %u levels failed (want %u), level 0 failed %d, stated %u: '%s'",
					      packs[i].what, src ? "read" : "memory", more ? max + 1 : max - 1, failed,
					      more ? 0 : of_max, li.failed, stated, e.message);
				}
			}
			mlod_pack p;
			mlod_result r = mlod_pack_open(d, packs[i].n, &p, &e);
			if (r == MLOD_OK) {
				r = mlod_pack_check(&p, d, packs[i].n, &e);
				mlod_pack_close(&p);
			}
			free(d);
			CHECK(r == MLOD_ERR_PARSE && strstr(e.message, "max_vertex_count"), "%s: mlod_pack_check %d '%s'",
			      packs[i].what, (int)r, e.message);
		}
	}
}

/* The most vertices the TOC allows (mlod_pack.h: half a b2 level's raw
 * size, an eighth of it and the coarser MESH chunks' raw sizes; a Draco
 * level's 1024 / 12 of its raw size), as the reader bounds INFO's field. */
static uint64_t toc_bound(const uint8_t *d, size_t n, uint64_t *mesh_raw, int *draco)
{
	mlod_pack p;
	mlod_error e;
	*mesh_raw = 0, *draco = 0;
	if (mlod_pack_open(d, n, &p, &e))
		return 0;
	uint64_t best = 0, prefix = 0;
	for (uint32_t i = 0; i < p.chunk_count; i++) {
		const mlod_pack_chunk *c = &p.chunks[i];
		if (c->type != MLOD_CHUNK_MESH)
			continue;
		prefix += c->raw_size;
		*draco |= c->codec == MLOD_CODEC_DRACO;
		uint64_t v = c->codec == MLOD_CODEC_DRACO ? 1024 * (uint64_t)c->raw_size / 12
		             : c->raw_size / 2 < prefix / 8 ? c->raw_size / 2
		                                              : prefix / 8;
		best = v > best ? v : best;
	}
	*mesh_raw = prefix;
	mlod_pack_close(&p);
	return best;
}

/* A field past what the MESH chunks can hold fails the open (memory and
 * read), naming INFO: one past the bound, a billion, UINT32_MAX; at the
 * bound it opens (the levels, smaller, load). The bound is small: for a
 * caller's positions and normals at most 3 times the MESH chunks' raw
 * bytes. */
TEST(hostile_value_refused)
{
	SKIP_IF_NO_PACK(hostile_value_refused);
	CHECK(npacks == want_packs, "mlod-pack or gen_tubeman failed (%d packs of %d)", npacks, want_packs);
	for (int i = 0; i < npacks; i++) {
		uint64_t mesh_raw;
		int draco;
		const uint64_t bound = toc_bound(packs[i].d, packs[i].n, &mesh_raw, &draco);
		CHECK(bound > 0 && bound < UINT32_MAX / 2, "%s: bound %llu", packs[i].what, (unsigned long long)bound);
		/* positions and normals sized from it: at most 3 times the MESH
		 * chunks' raw bytes (layout b2) */
		CHECK(draco || 24 * bound <= 3 * mesh_raw, "%s: bound %llu for %llu raw MESH bytes", packs[i].what,
		      (unsigned long long)bound, (unsigned long long)mesh_raw);
		mlod_error oe = { 0 };
		mlod_rt_ctx *oc = NULL;
		CHECK_OK(mlod_rt_open_memory(packs[i].d, packs[i].n, NULL, &oc, &oe), oe);
		printf("# %s: %zu bytes, largest mesh level %u vertices, INFO's bound %llu (MESH raw %llu bytes)\n",
		       packs[i].what, packs[i].n, mlod_rt_max_vertex_count(oc), (unsigned long long)bound,
		       (unsigned long long)mesh_raw);
		mlod_rt_close(oc);
		const uint32_t vals[4] = { (uint32_t)bound, (uint32_t)bound + 1, 1000000000u, UINT32_MAX };
		for (int k = 0; k < 4; k++) {
			uint8_t *d = edited(&packs[i], vals[k], -1);
			CHECK(d, "editing %s", packs[i].what);
			for (int src = 0; src < 2; src++) {
				mlod_error e = { 0 };
				mlod_rt_ctx *ctx = NULL;
				rt_mem_source m;
				mlod_result r = open_src(src, d, packs[i].n, &m, &ctx, &e);
				const uint32_t got = ctx ? mlod_rt_max_vertex_count(ctx) : 0;
				mlod_rt_close(ctx);
				if (k == 0 ? r != MLOD_OK || got != vals[k]
				           : r != MLOD_ERR_PARSE || !strstr(e.message, "INFO: max_vertex_count")) {
					free(d);
					CHECK(0, "%s (%s), INFO %u (bound %llu): open %d '%s', max %u", packs[i].what,
					      src ? "read" : "memory", vals[k], (unsigned long long)bound, (int)r, e.message, got);
				}
			}
			free(d);
		}
	}
}

/* A pack of format 8.0 (the field 0 and the version 8.0, as 8.0's
 * mlod-pack wrote it; of one key per joint, so that its MOTION chunks
 * read the same in 8.0: see still) opens and gives what 8.0's runtime gave: the
 * largest level resident so far (the coarsest at open), growing as
 * levels load; with any bytes in the field (reserved in 8.0: ignored) the
 * same. The 8.1 pack gives the largest level at open. */
TEST(previous_minor_opens)
{
	SKIP_IF_NO_PACK(previous_minor_opens);
	CHECK(still.d, "mlod-pack or gen_tubeman failed on the one-frame walk");
	packed *packs = &still;
	for (int i = 0; i < 1; i++) {
		uint32_t at_open81 = 0, max81 = 0;
		for (int v = 0; v < 3; v++) {
			uint8_t *d = v == 0 ? packs[i].d : edited(&packs[i], v == 1 ? 0 : 12345678u, 0);
			CHECK(d, "editing %s", packs[i].what);
			for (int src = 0; src < 2; src++) {
				mlod_error e = { 0 };
				mlod_rt_ctx *ctx = NULL;
				rt_mem_source m;
				mlod_result r = open_src(src, d, packs[i].n, &m, &ctx, &e);
				if (r != MLOD_OK) {
					if (v)
						free(d);
					CHECK(0, "%s, format 8.%d: open %d '%s'", packs[i].what, v ? 0 : 1, (int)r, e.message);
				}
				const uint32_t L = mlod_rt_level_count(ctx, MLOD_RT_MESH);
				const uint32_t coarsest = mlod_rt_mesh_vertex_count(ctx, L - 1);
				const uint32_t at_open = mlod_rt_max_vertex_count(ctx);
				uint32_t max, stated, failed;
				load_all(ctx, &max, &stated, &failed, &e);
				const uint32_t after = mlod_rt_max_vertex_count(ctx);
				mlod_rt_close(ctx);
				if (v == 0)
					at_open81 = at_open, max81 = max;
				const int ok = failed == 0 && after == max && max == max81 &&
				               (v == 0 ? at_open == max : at_open == coarsest && coarsest < max);
				if (!ok) {
					if (v)
						free(d);
					CHECK(0, "%s (%s), format 8.%d%s: at open %u (coarsest level %u), after loading %u, levels' "
					      "largest %u (8.1's %u at open), %u failed: %s",
					      packs[i].what, src ? "read" : "memory", v ? 0 : 1, v == 2 ? " with reserved bytes set" : "",
					      at_open, coarsest, after, max, at_open81, failed, e.message);
				}
			}
			mlod_pack p;
			mlod_error e = { 0 };
			mlod_pack_info info;
			memset(&info, 0, sizeof info);
			mlod_result r = mlod_pack_open(d, packs[i].n, &p, &e);
			if (r == MLOD_OK) {
				r = mlod_pack_check(&p, d, packs[i].n, &e);
				if (r == MLOD_OK)
					r = mlod_pack_decode_info(&p, d, packs[i].n, &info, &e);
				mlod_pack_close(&p);
			}
			const int has = info.has_max_vertices;
			const uint32_t field = info.rec.max_vertex_count;
			mlod_pack_info_free(&info);
			if (v)
				free(d);
			CHECK(r == MLOD_OK && has == (v == 0) && field == (v == 0 ? max81 : 0),
			      "%s, format 8.%d: check %d '%s', INFO states %d, %u", packs[i].what, v ? 0 : 1, (int)r,
			      e.message, has, field);
		}
	}
}

int main(int argc, char **argv)
{
	(void)argc;
	static const char *const samples[] = { "samples/RobotExpressive.glb", "samples/tubeman.glb",
		                               "samples/cmu_12_01_walk.bvh", NULL };
	rt_packer_setup(argv[0], "rt_maxvert", samples);
	if (mlod_pack_bin) {
		pack_one("tubeman", "samples/tubeman.glb", "", "tubeman.mlod");
		pack_one("RobotExpressive", "samples/RobotExpressive.glb", "", "robot.mlod");
		if (MLOD_DRACO)
			pack_one("tubeman --codec draco", "samples/tubeman.glb", "--codec draco", "tubeman.draco.mlod");
		pack_one("RobotExpressive --codec none", "samples/RobotExpressive.glb", "--codec none --entropy none",
		         "robot.none.mlod");
		/* a generated character: gen_tubeman beside mlod-pack's build
		 * (build/<config>/tests/helpers), another mesh of the walk */
		char gen[1200], glb[600], cmd[2600];
		snprintf(gen, sizeof gen, "%s", mlod_pack_bin);
		char *slash = strrchr(gen, '/');
		if (slash && strlen(gen) < 1000) {
			snprintf(slash, sizeof gen - (size_t)(slash - gen), "/../tests/helpers/gen_tubeman");
			snprintf(glb, sizeof glb, "%s/gen.glb", tmpdir);
			snprintf(cmd, sizeof cmd, "'%s' samples/cmu_12_01_walk.bvh '%s' --segments 7 --rings 3 >/dev/null 2>&1",
			         gen, glb);
			if (file_exists(gen) && system(cmd) == 0)
				pack_one("generated (gen_tubeman --segments 7 --rings 3)", glb, "", "gen.mlod");
			/* the walk's first frame alone */
			size_t bn = 0;
			char *bvh = (char *)read_all("samples/cmu_12_01_walk.bvh", &bn), one[600], *fr;
			snprintf(one, sizeof one, "%s/one.bvh", tmpdir);
			FILE *f = bvh && (fr = strstr(bvh, "Frames:")) ? fopen(one, "w") : NULL;
			if (f) {
				char *line = strstr(fr, "Frame Time:"), *end = line ? strchr(line, '\n') : NULL;
				char *first = end ? end + 1 : NULL, *first_end = first ? strchr(first, '\n') : NULL;
				if (first_end) {
					fwrite(bvh, 1, (size_t)(fr - bvh), f);
					fprintf(f, "Frames: 1\n");
					fwrite(line, 1, (size_t)(first_end + 1 - line), f);
				}
				fclose(f);
				snprintf(glb, sizeof glb, "%s/one.glb", tmpdir);
				snprintf(cmd, sizeof cmd, "'%s' '%s' '%s' --segments 7 --rings 3 >/dev/null 2>&1", gen, one, glb);
				char path[600];
				if (first_end && system(cmd) == 0 && run_pack(glb, "", "one.mlod", path, sizeof path) == 0 &&
				    (still.d = read_all(path, &still.n)) != NULL)
					still.what = "generated, one frame";
			}
			free(bvh);
		}
	}
	RUN(known_at_open);
	RUN(smaller_fails_the_level);
	RUN(hostile_value_refused);
	RUN(previous_minor_opens);
	for (int i = 0; i < npacks; i++)
		free(packs[i].d);
	free(still.d);
	rt_packer_cleanup();
	TEST_EXIT();
}
