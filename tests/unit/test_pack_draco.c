/*
 * test_pack_draco.c: mlod-pack's codec draco (mlod(5): a MESH level of
 * codec 2 holds each part's level as a Draco mesh of its own) against the
 * meshopt pack of the same character and options.
 *
 * - Every decoded MESH level equals the meshopt pack's: the same part
 *   records (but the index form flags), the same counts, and the same
 *   triangles as a multiset, each corner's every attribute (positions,
 *   normals, tangents, UVs, colours, joints, weights, morph deltas) bit
 *   for bit; a triangle's corners may start anywhere (winding kept).
 * - The runtime (mlod_rt_open_memory) skins one frame of each mesh level
 *   of both packs to the same positions and normals, compared the same
 *   way (bit for bit).
 * - A Draco MESH chunk with bytes changed and its CRCs made valid again
 *   decodes or fails with a message; never a crash (run it under
 *   make config=sanitize for the out-of-bounds side).
 * - Built with MLOD_DRACO=0, the runtime refuses Draco chunks as
 *   MLOD_ERR_UNSUPPORTED, and the rest of the pack still decodes.
 */
#include "test.h"

#include "rt/mlod_rt.h"

#ifndef MLOD_DRACO
#define MLOD_DRACO 1
#endif

/* Writes a pack of path with codec (and entropy); NULL when it cannot. */
static void *make_pack(const char *path, mlod_pack_codec codec, int entropy, size_t *n)
{
	size_t size;
	void *data = test_read_file(path, &size), *pk = NULL;
	*n = 0;
	if (!data)
		return NULL;
	mlod_gltf *doc = NULL;
	mlod_character c;
	mlod_format fmt;
	if (mlod_load(data, size, "samples", &doc, &c, &fmt, &terr) != MLOD_OK) {
		free(data);
		return NULL;
	}
	mlod_pack_options opt;
	mlod_pack_options_default(&opt);
	opt.codec = codec;
	opt.entropy = entropy;
	if (mlod_pack_write(doc, &c, fmt, data, size, &opt, &pk, n, NULL, &terr) != MLOD_OK)
		pk = NULL;
	free(data);
	mlod_character_free(&c);
	mlod_gltf_free(doc);
	return pk;
}

#if MLOD_DRACO
/* A triangle corner's attributes as floats, a fixed record per part. */
static size_t corner_floats(const mlod_pack_part_rec *rc)
{
	return 3 + 3 + 4 + 2 * (size_t)rc->uv_sets + 4 + 4 + 4 + 3 * (size_t)rc->target_count;
}

static void corner(const mlod_pack_part *pt, uint32_t v, float *o)
{
	const mlod_pack_part_rec *rc = &pt->rec;
	memset(o, 0, corner_floats(rc) * sizeof *o);
	memcpy(o, pt->positions + 3 * (size_t)v, 12), o += 3;
	if (pt->normals)
		memcpy(o, pt->normals + 3 * (size_t)v, 12);
	o += 3;
	if (pt->tangents)
		memcpy(o, pt->tangents + 4 * (size_t)v, 16);
	o += 4;
	for (uint32_t s = 0; s < rc->uv_sets; s++, o += 2)
		memcpy(o, pt->uvs[s] + 2 * (size_t)v, 8);
	if (pt->colors)
		memcpy(o, pt->colors + 4 * (size_t)v, 16);
	o += 4;
	for (int k = 0; k < 4 && pt->joints; k++)
		o[k] = pt->joints[4 * (size_t)v + k];
	o += 4;
	if (pt->weights)
		memcpy(o, pt->weights + 4 * (size_t)v, 16);
	o += 4;
	for (uint32_t t = 0; t < rc->target_count; t++, o += 3)
		memcpy(o, pt->targets[t] + 3 * (size_t)v, 12);
}

static size_t sort_width; /* bytes of one triangle record, for qsort */
static int cmp_bytes(const void *a, const void *b)
{
	return memcmp(a, b, sort_width);
}

/* The triangles of a part as sorted records of 3 corners of w floats,
 * each starting at its smallest corner (winding kept), except that a
 * triangle with two corners at one position (the first 3 floats), which
 * has no area and so no winding, has its corners sorted: Draco's
 * edgebreaker may turn such a triangle around (the robot's coarse
 * levels, where quantisation puts two corners of a tiny triangle on one
 * point). */
static float *triangles(const float *corners, const uint32_t *idx, uint32_t ni, size_t w)
{
	float *t = malloc(sizeof *t * (ni ? ni : 1) * w);
	for (uint32_t f = 0; t && f < ni / 3; f++) {
		const float *c[3] = {corners + idx[3 * f] * w, corners + idx[3 * f + 1] * w, corners + idx[3 * f + 2] * w};
		int s = 0;
		for (int k = 1; k < 3; k++)
			if (memcmp(c[k], c[s], w * sizeof(float)) < 0)
				s = k;
		int flat = memcmp(c[0], c[1], 12) == 0 || memcmp(c[1], c[2], 12) == 0 || memcmp(c[2], c[0], 12) == 0;
		const float *o[3] = {c[s], c[(s + 1) % 3], c[(s + 2) % 3]};
		if (flat && memcmp(o[1], o[2], w * sizeof(float)) > 0) {
			const float *x = o[1];
			o[1] = o[2], o[2] = x;
		}
		for (int k = 0; k < 3; k++)
			memcpy(t + (3 * (size_t)f + k) * w, o[k], w * sizeof(float));
	}
	sort_width = 3 * w * sizeof(float);
	if (t)
		qsort(t, ni / 3, sort_width, cmp_bytes);
	return t;
}

/* Both parts' triangles as multisets of corners: 1 when equal. */
static int same_triangles(const mlod_pack_part *a, const mlod_pack_part *b)
{
	size_t w = corner_floats(&a->rec);
	uint32_t ni = a->rec.index_count;
	float *ca = malloc(sizeof *ca * w * ((size_t)a->rec.vertex_count + 1));
	float *cb = malloc(sizeof *cb * w * ((size_t)b->rec.vertex_count + 1));
	for (uint32_t v = 0; ca && v < a->rec.vertex_count; v++)
		corner(a, v, ca + v * w);
	for (uint32_t v = 0; cb && v < b->rec.vertex_count; v++)
		corner(b, v, cb + v * w);
	float *ta = ca ? triangles(ca, a->indices, ni, w) : NULL;
	float *tb = cb ? triangles(cb, b->indices, ni, w) : NULL;
	int same = ta && tb && memcmp(ta, tb, (size_t)ni * w * sizeof(float)) == 0;
	free(ca), free(cb), free(ta), free(tb);
	return same;
}
#endif

static void levels_equal(const char *path)
{
	size_t nm, nd;
	void *pm = make_pack(path, MLOD_CODEC_MESHOPT, MLOD_ENTROPY_ZSTD, &nm);
	void *pd = make_pack(path, MLOD_CODEC_DRACO, MLOD_ENTROPY_ZSTD, &nd);
	CHECK_MSG(pm && pd, "%s: cannot pack: %s", path, terr.message);
	mlod_pack km, kd;
	CHECK_OK(mlod_pack_open(pm, nm, &km, &terr));
	CHECK_OK(mlod_pack_open(pd, nd, &kd, &terr));
	mlod_pack_skeleton sk = {0};
	CHECK_OK(mlod_pack_decode_skeleton(&km, pm, nm, &sk, &terr));
	uint32_t levels = 0, parts = 0, tris = 0;
	for (uint32_t l = 0;; l++) {
		int cm = mlod_pack_find(&km, MLOD_CHUNK_MESH, l, 0), cd = mlod_pack_find(&kd, MLOD_CHUNK_MESH, l, 0);
		CHECK_MSG((cm < 0) == (cd < 0), "MESH level %u in one pack only", l);
		if (cm < 0)
			break;
		CHECK(kd.chunks[cd].codec == MLOD_CODEC_DRACO && kd.chunks[cd].entropy != MLOD_ENTROPY_ZSTD_PREFIX);
#if MLOD_DRACO
		mlod_pack_mesh a = {0}, b = {0};
		CHECK_OK(mlod_pack_decode_mesh(&km, (uint32_t)cm, pm, nm, &sk, &a, &terr));
		CHECK_OK(mlod_pack_decode_mesh(&kd, (uint32_t)cd, pd, nd, &sk, &b, &terr));
		CHECK(a.part_count == b.part_count);
		for (uint32_t i = 0; i < a.part_count; i++) {
			mlod_pack_part_rec ra = a.parts[i].rec, rb = b.parts[i].rec;
			ra.flags &= ~(MLOD_PART_INDEX16 | MLOD_PART_LOCAL | MLOD_PART_NEWBITS);
			CHECK_MSG(memcmp(&ra, &rb, sizeof ra) == 0, "level %u part %u: records differ", l, i);
			CHECK_MSG(same_triangles(&a.parts[i], &b.parts[i]), "%s: level %u part %u: the triangles differ", path,
			          l, i);
			parts++;
			tris += ra.index_count / 3;
		}
		mlod_pack_mesh_free(&a);
		mlod_pack_mesh_free(&b);
#else
		mlod_pack_mesh b = {0};
		CHECK(mlod_pack_decode_mesh(&kd, (uint32_t)cd, pd, nd, &sk, &b, &terr) == MLOD_ERR_UNSUPPORTED);
		CHECK_MSG(strstr(terr.message, "Draco") != NULL, "message: %s", terr.message);
		CHECK(b.parts == NULL);
#endif
		levels++;
	}
	CHECK(levels >= 2);
#if MLOD_DRACO
	CHECK_OK(mlod_pack_check(&kd, pd, nd, &terr));
#else
	CHECK(mlod_pack_check(&kd, pd, nd, &terr) == MLOD_ERR_UNSUPPORTED);
#endif
#if MLOD_DRACO
	printf("# %s: %u MESH levels, %u parts, %u triangles equal; pack %zu bytes (draco) vs %zu (meshopt)\n", path,
	       levels, parts, tris, nd, nm);
#else
	printf("# %s: %u Draco MESH levels refused as unsupported (MLOD_DRACO=0)\n", path, levels);
	(void)parts, (void)tris;
#endif
	mlod_pack_skeleton_free(&sk);
	mlod_pack_close(&km);
	mlod_pack_close(&kd);
	mlod_free(pm);
	mlod_free(pd);
}

TEST(draco_levels_equal_tubeman) { levels_equal("samples/tubeman.glb"); }
TEST(draco_levels_equal_robot) { levels_equal("samples/RobotExpressive.glb"); }
TEST(draco_levels_equal_ely)
{
	NEED_SHARED();
	char why[256], path[1200];
	snprintf(path, sizeof path, "%s/Ely.glb", test_shared_dir(why, sizeof why));
	levels_equal(path);
}

#if MLOD_DRACO
/* The runtime: one frame of every mesh level, skinned from both packs. */
static void rt_skin_equal(const char *path)
{
	size_t n[2];
	void *pk[2] = {make_pack(path, MLOD_CODEC_MESHOPT, MLOD_ENTROPY_ZSTD, &n[0]),
	               make_pack(path, MLOD_CODEC_DRACO, MLOD_ENTROPY_ZSTD, &n[1])};
	CHECK_MSG(pk[0] && pk[1], "%s: cannot pack: %s", path, terr.message);
	mlod_rt_ctx *ctx[2] = {NULL, NULL};
	mlod_rt_scratch *sc[2];
	float *out[2][2];
	for (int k = 0; k < 2; k++) {
		CHECK_OK(mlod_rt_open_memory(pk[k], n[k], NULL, &ctx[k], &terr));
		/* sized at open for every level (INFO's max_vertex_count) */
		uint32_t nv = mlod_rt_max_vertex_count(ctx[k]);
		out[k][0] = malloc((size_t)nv * 12 + 12), out[k][1] = malloc((size_t)nv * 12 + 12);
		for (uint32_t l = 0; l < mlod_rt_level_count(ctx[k], MLOD_RT_MESH); l++)
			CHECK_OK(mlod_rt_request(ctx[k], MLOD_RT_MESH, l, 0, &terr));
		CHECK_OK(mlod_rt_stream(ctx[k], SIZE_MAX, NULL, &terr));
		sc[k] = mlod_rt_scratch_create(ctx[k]);
		CHECK(sc[k] != NULL);
	}
	uint32_t L = mlod_rt_level_count(ctx[0], MLOD_RT_MESH), compared = 0;
	CHECK(L == mlod_rt_level_count(ctx[1], MLOD_RT_MESH) && L >= 2);
	mlod_rt_select sel;
	mlod_rt_select_default(&sel);
	for (uint32_t l = 0; l < L; l++) {
		sel.force_level = (int)l;
		float *tri[2] = {NULL, NULL};
		size_t ntri = 0;
		for (int k = 0; k < 2; k++) {
			uint32_t id, nv = 0;
			float d = 1;
			CHECK_OK(mlod_rt_instance_create(ctx[k], 0, 0.37f, 0, &id, &terr));
			CHECK_OK(mlod_rt_update(ctx[k], &sel, &id, &d, 1, 0.0f, &terr));
			CHECK_OK(mlod_rt_skin(ctx[k], sc[k], id, out[k][0], 12, out[k][1], 12,
			                      mlod_rt_max_vertex_count(ctx[k]), &nv, &terr));
			CHECK(nv == mlod_rt_mesh_vertex_count(ctx[k], l));
			/* every triangle corner's skinned position and normal */
			uint32_t P = mlod_rt_mesh_part_count(ctx[k], l), ni = 0;
			for (uint32_t p = 0; p < P; p++) {
				mlod_rt_part_info info;
				CHECK_OK(mlod_rt_mesh_part(ctx[k], l, p, &info, &terr));
				ni += info.index_count;
			}
			float *c = malloc(sizeof *c * 6 * ((size_t)nv + 1));
			uint32_t *idx = malloc(sizeof *idx * ((size_t)ni + 1));
			CHECK(c && idx);
			for (uint32_t v = 0; v < nv; v++)
				memcpy(c + 6 * (size_t)v, out[k][0] + 3 * (size_t)v, 12),
				        memcpy(c + 6 * (size_t)v + 3, out[k][1] + 3 * (size_t)v, 12);
			for (uint32_t p = 0, o = 0; p < P; p++) {
				mlod_rt_part_info info;
				CHECK_OK(mlod_rt_mesh_part(ctx[k], l, p, &info, &terr));
				for (uint32_t q = 0; q < info.index_count; q++)
					idx[o++] = info.first_vertex + info.indices[q];
			}
			tri[k] = triangles(c, idx, ni, 6);
			ntri = ni / 3;
			free(c), free(idx);
			mlod_rt_instance_destroy(ctx[k], id);
		}
		CHECK_MSG(tri[0] && tri[1] && memcmp(tri[0], tri[1], ntri * 18 * sizeof(float)) == 0,
		          "%s: mesh level %u: the skinned triangles differ", path, l);
		compared += (uint32_t)ntri;
		free(tri[0]), free(tri[1]);
	}
	printf("# %s: %u MESH levels, %u skinned triangles equal bit for bit\n", path, L, compared);
	for (int k = 0; k < 2; k++) {
		free(out[k][0]), free(out[k][1]);
		mlod_rt_scratch_destroy(ctx[k], sc[k]);
		mlod_rt_close(ctx[k]);
		mlod_free(pk[k]);
	}
}

TEST(draco_rt_skin_equal_tubeman) { rt_skin_equal("samples/tubeman.glb"); }
TEST(draco_rt_skin_equal_robot) { rt_skin_equal("samples/RobotExpressive.glb"); }

static void put32(uint8_t *p, uint32_t v)
{
	for (int k = 0; k < 4; k++)
		p[k] = (uint8_t)(v >> (8 * k));
}
static uint32_t get32(const uint8_t *p)
{
	return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

/* Chunk c's CRC in the TOC, the TOC's and the header's made valid again
 * after its stored bytes were changed in pk (a copy of k's pack). */
static void restamp(uint8_t *pk, const mlod_pack *k, uint32_t c)
{
	const mlod_pack_chunk *ch = &k->chunks[c];
	put32(pk + 32 + 48 * (size_t)c + 32, mlod_pack_crc32(0, pk + ch->offset, ch->stored_size));
	put32(pk + 24, mlod_pack_crc32(0, pk + 32, 48 * (size_t)k->chunk_count));
	put32(pk + 28, mlod_pack_crc32(0, pk, 28));
}

/* Bytes of the Draco streams changed (no entropy stage, so the stored
 * bytes are the container), every CRC made valid again. */
TEST(draco_corrupt_chunk_is_an_error)
{
	size_t n;
	uint8_t *pk = make_pack("samples/tubeman.glb", MLOD_CODEC_DRACO, MLOD_ENTROPY_NONE, &n);
	CHECK_MSG(pk, "cannot pack: %s", terr.message);
	mlod_pack k;
	CHECK_OK(mlod_pack_open(pk, n, &k, &terr));
	mlod_pack_skeleton sk = {0};
	CHECK_OK(mlod_pack_decode_skeleton(&k, pk, n, &sk, &terr));
	uint8_t *bad = malloc(n);
	CHECK(bad != NULL);
	uint32_t seed = 12345, tries = 0, failed = 0, ok = 0;
	for (uint32_t c = 0; c < k.chunk_count; c++) {
		const mlod_pack_chunk *ch = &k.chunks[c];
		if (ch->type != MLOD_CHUNK_MESH)
			continue;
		CHECK(ch->codec == MLOD_CODEC_DRACO && ch->entropy == MLOD_ENTROPY_NONE);
		const uint8_t *base = pk + ch->offset;
		uint32_t ns = get32(base);
		uint64_t cur = 4 + 16 * (uint64_t)ns;
		for (uint32_t s = 0; s < ns; s++) {
			const uint8_t *h = base + 4 + 16 * s;
			uint32_t stored = get32(h + 12);
			if (get32(h) == MLOD_STREAM_DRCO) {
				for (int t = 0; t < 120; t++) {
					memcpy(bad, pk, n);
					int nflip = 1 + t % 4;
					for (int f = 0; f < nflip; f++) {
						seed = seed * 1664525u + 1013904223u;
						uint32_t at = (seed >> 8) % stored;
						/* the first bytes hold the header and counts: hit them often */
						if (t % 3 == 0)
							at %= stored < 40 ? stored : 40;
						bad[ch->offset + cur + at] ^= (uint8_t)(1u + (seed >> 24) % 255u);
					}
					if (t % 10 == 9) /* a truncated Draco stream: its tail zeroed */
						memset(bad + ch->offset + cur + stored / 2, 0, stored - stored / 2);
					restamp(bad, &k, c);
					mlod_pack kb;
					CHECK_OK(mlod_pack_open(bad, n, &kb, &terr));
					mlod_pack_mesh m = {0};
					mlod_result r = mlod_pack_decode_mesh(&kb, c, bad, n, &sk, &m, &terr);
					tries++;
					if (r == MLOD_OK) {
						ok++;
						mlod_pack_mesh_free(&m);
					} else {
						CHECK_MSG(r == MLOD_ERR_PARSE || r == MLOD_ERR_NOMEM, "result %d: %s", r, terr.message);
						CHECK_MSG(strstr(terr.message, "MESH level") != NULL, "message: %s", terr.message);
						CHECK(m.parts == NULL && m.block == NULL);
						failed++;
					}
					mlod_pack_close(&kb);
				}
			}
			cur += (stored + 3) & ~3u;
		}
	}
	printf("# %u corrupted Draco chunks: %u refused with a message, %u decoded (values changed)\n", tries, failed, ok);
	CHECK(tries > 0 && failed > tries / 2);
	free(bad);
	mlod_pack_skeleton_free(&sk);
	mlod_pack_close(&k);
	mlod_free(pk);
}

/* A Draco chunk's part record claiming millions of vertices, CRCs valid:
 * the reader sizes its arrays from the records before Draco decodes, so it
 * must refuse the claim against the container (PACK_DRACO_MAX_EXPAND)
 * instead of allocating it (make fuzz found a 7 KB pack asking 683 MB). */
TEST(draco_part_counts_bounded)
{
	size_t n;
	uint8_t *pk = make_pack("samples/tubeman.glb", MLOD_CODEC_DRACO, MLOD_ENTROPY_NONE, &n);
	CHECK_MSG(pk, "cannot pack: %s", terr.message);
	mlod_pack k;
	CHECK_OK(mlod_pack_open(pk, n, &k, &terr));
	mlod_pack_skeleton sk = {0};
	CHECK_OK(mlod_pack_decode_skeleton(&k, pk, n, &sk, &terr));
	uint8_t *bad = malloc(n);
	CHECK(bad != NULL);
	uint32_t refused = 0;
	for (uint32_t c = 0; c < k.chunk_count; c++) {
		const mlod_pack_chunk *ch = &k.chunks[c];
		if (ch->type != MLOD_CHUNK_MESH)
			continue;
		const uint8_t *base = pk + ch->offset;
		uint32_t ns = get32(base);
		uint64_t cur = 4 + 16 * (uint64_t)ns;
		CHECK(ns > 0 && get32(base + 4) == MLOD_STREAM_PART);
		memcpy(bad, pk, n);
		/* the first part: 4 million vertices, 4 million triangles */
		uint8_t *rec = bad + ch->offset + cur;
		put32(rec + offsetof(mlod_pack_part_rec, vertex_count), 4000000u);
		put32(rec + offsetof(mlod_pack_part_rec, index_count), 12000000u);
		restamp(bad, &k, c);
		mlod_pack kb;
		CHECK_OK(mlod_pack_open(bad, n, &kb, &terr));
		mlod_pack_mesh m = {0};
		mlod_result r = mlod_pack_decode_mesh(&kb, c, bad, n, &sk, &m, &terr);
		CHECK_MSG(r == MLOD_ERR_PARSE, "level %u: result %d: %s", ch->level, r, terr.message);
		CHECK_MSG(strstr(terr.message, "MESH level") && strstr(terr.message, "times its"), "message: %s",
		          terr.message);
		CHECK(m.parts == NULL && m.block == NULL);
		mlod_pack_close(&kb);
		refused++;
	}
	CHECK(refused == 5);
	free(bad);
	mlod_pack_skeleton_free(&sk);
	mlod_pack_close(&k);
	mlod_free(pk);
}
#endif

int main(void)
{
	RUN(draco_levels_equal_tubeman);
	RUN(draco_levels_equal_robot);
	RUN(draco_levels_equal_ely);
#if MLOD_DRACO
	RUN(draco_rt_skin_equal_tubeman);
	RUN(draco_rt_skin_equal_robot);
	RUN(draco_corrupt_chunk_is_an_error);
	RUN(draco_part_counts_bounded);
#endif
	TEST_EXIT();
}
