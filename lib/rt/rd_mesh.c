/*
 * rd_mesh.c: the pack reader's MESH levels: part records, the coarser
 * levels' vertex blocks, dequantisation, and Draco-coded levels.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#if MLOD_DRACO
#include "rt_draco.h"
#endif

#define MLOD_PACK_READER /* pack_internal.h: the reader's own part */
#include "pack_internal.h"

/* ------------------------------------------------------------------ */
/* MESH level k                                                        */
/* ------------------------------------------------------------------ */

/* Octahedral unit vector from two snorm16 values, normalised. */
static void oct_decode(int16_t qx, int16_t qy, float *out)
{
	float x = qx / 32767.0f, y = qy / 32767.0f;
	x = x < -1.0f ? -1.0f : x;
	y = y < -1.0f ? -1.0f : y;
	float z = 1.0f - fabsf(x) - fabsf(y);
	if (z < 0) {
		float ox = x;
		x = (1.0f - fabsf(y)) * (ox >= 0 ? 1.0f : -1.0f);
		y = (1.0f - fabsf(ox)) * (y >= 0 ? 1.0f : -1.0f);
	}
	float len = sqrtf(x * x + y * y + z * z); /* >= 1/sqrt(3): |x|+|y|+|z| = 1 */
	out[0] = x / len;
	out[1] = y / len;
	out[2] = z / len;
}

#define PART_KNOWN_FLAGS                                                                                        \
	(MLOD_PART_NORMALS | MLOD_PART_TANGENTS | MLOD_PART_COLORS | MLOD_PART_SKINNED | MLOD_PART_JOINTS16 |    \
	 MLOD_PART_INDEX16 | MLOD_PART_LOCAL | MLOD_PART_NEWBITS)

/* A part's vertex streams in a MESH chunk, in order, with their element
 * sizes (the targets' 'MTPQ' last, after 'IDX ' and 'MTSC'); the count. */
static int part_vstreams(const mlod_pack_part_rec *rc, uint32_t *tag, uint32_t *size)
{
	int n = 0;
	uint32_t f = rc->flags;
	tag[n] = MLOD_STREAM_POSQ, size[n++] = 8;
	if (f & MLOD_PART_NORMALS)
		tag[n] = MLOD_STREAM_NRMQ, size[n++] = 4;
	if (f & MLOD_PART_TANGENTS)
		tag[n] = MLOD_STREAM_TANQ, size[n++] = 8;
	for (uint32_t t = 0; t < rc->uv_sets && t < MLOD_PACK_MAX_UV; t++)
		tag[n] = MLOD_STREAM_UVQ0 + (t << 24), size[n++] = 4;
	if (f & MLOD_PART_COLORS)
		tag[n] = MLOD_STREAM_COLQ, size[n++] = 4;
	if (f & MLOD_PART_SKINNED) {
		int j16 = (f & MLOD_PART_JOINTS16) != 0;
		tag[n] = j16 ? MLOD_STREAM_JN16 : MLOD_STREAM_JNT8, size[n++] = j16 ? 8 : 4;
		tag[n] = MLOD_STREAM_WGT8, size[n++] = 4;
	}
	return n;
}

enum { VSTREAMS_MAX = 4 + MLOD_PACK_MAX_UV + 2 };

/* Checks a part record (as layout a's reader did). */
static mlod_result check_part_rec(const cx *x, uint32_t i, const mlod_pack_part_rec *rc, uint32_t J, uint32_t S,
                                  mlod_error *err)
{
	uint32_t f = rc->flags;
	if (f & ~PART_KNOWN_FLAGS)
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: part %u: unknown flags 0x%x", x->label, i, f & ~PART_KNOWN_FLAGS);
	if ((f & MLOD_PART_NEWBITS) && !(f & MLOD_PART_LOCAL))
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: part %u: NEWBITS without LOCAL", x->label, i);
	if ((f & MLOD_PART_JOINTS16) && !(f & MLOD_PART_SKINNED))
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: part %u: JOINTS16 without SKINNED", x->label, i);
	if (rc->index_count % 3 != 0)
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: part %u: index count %u is not a multiple of 3", x->label, i,
		                 rc->index_count);
	if (rc->uv_sets > MLOD_PACK_MAX_UV)
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: part %u: %u UV sets, more than %d", x->label, i, rc->uv_sets,
		                 MLOD_PACK_MAX_UV);
	if (rc->skin < -1 || rc->skin >= (int64_t)S)
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: part %u: skin %d is not -1 or below the skeleton's %u skins",
		                 x->label, i, rc->skin, S);
	if ((f & MLOD_PART_SKINNED) && rc->skin < 0)
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: part %u: skinned, but without a skin", x->label, i);
	if (rc->joint < -1 || rc->joint >= (int64_t)J)
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: part %u: joint %d is not -1 or below the skeleton's %u joints",
		                 x->label, i, rc->joint, J);
	if (rc->node < -1 || rc->mesh < -1 || rc->material < -1)
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: part %u: node %d, mesh %d, material %d: each must be -1 or an index",
		                 x->label, i, rc->node, rc->mesh, rc->material);
	if (!all_finite(rc->offset, 16))
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: part %u: its offset matrix is not finite", x->label, i);
	for (int a = 0; a < 3; a++)
		if (!isfinite(rc->pos_min[a]) || !(rc->pos_scale[a] >= 0) ||
		    !isfinite(rc->pos_min[a] + 65535.0f * rc->pos_scale[a]))
			return mlod_fail(err, MLOD_ERR_PARSE, "%s: part %u: position range %g + q * %g is not finite and increasing",
			                 x->label, i, (double)rc->pos_min[a], (double)rc->pos_scale[a]);
	for (uint32_t t = 0; t < rc->uv_sets; t++)
		for (int a = 0; a < 2; a++)
			if (!isfinite(rc->uv_min[t][a]) || !isfinite(rc->uv_scale[t][a]) ||
			    !isfinite(rc->uv_min[t][a] + 65535.0f * rc->uv_scale[t][a]))
				return mlod_fail(err, MLOD_ERR_PARSE, "%s: part %u: UV set %u range %g + q * %g is not finite", x->label,
				                 i, t, (double)rc->uv_min[t][a], (double)rc->uv_scale[t][a]);
	if (rc->vertex_count > rc->index_count)
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: part %u: %u vertices, more than its %u indices can use", x->label, i,
		                 rc->vertex_count, rc->index_count);
	return MLOD_OK;
}

/* Two levels' records of one part agree on everything but the counts and
 * the 16-bit index flag. */
static int same_part(const mlod_pack_part_rec *a, const mlod_pack_part_rec *b)
{
	mlod_pack_part_rec x = *a, y = *b;
	x.vertex_count = y.vertex_count = 0;
	x.index_count = y.index_count = 0;
	x.flags &= ~(MLOD_PART_INDEX16 | MLOD_PART_LOCAL | MLOD_PART_NEWBITS);
	y.flags &= ~(MLOD_PART_INDEX16 | MLOD_PART_LOCAL | MLOD_PART_NEWBITS);
	return memcmp(&x, &y, sizeof x) == 0;
}

/* The levels' blocks of one part: level l (0 the coarsest read) holds the
 * part's vertices first[l] .. first[l] + count[l] - 1, each attribute's
 * count[l] elements one after the other from base[l]. */
typedef struct mblock {
	uint8_t *base;
	uint64_t first;
	uint32_t count;
} mblock;

/* The chunk's bytes for a mesh decode: fetch gives it by TOC index. */
typedef struct mesh_src {
	const mlod_pack *p;
	const void *data; /* whole file or prefix */
	size_t size;
	mlod_pack_fetch_fn fetch;
	void *user;
	mlod_pack_reserve_fn reserve; /* or NULL (pack_internal.h) */
	void *reserve_user;
} mesh_src;

/* pk_cx_begin on a MESH chunk from m; prefix: the coarser levels' containers
 * (for MLOD_ENTROPY_ZSTD_PREFIX), or NULL. */
static mlod_result mesh_begin(const mesh_src *m, uint32_t index, const uint8_t *prefix, uint64_t prefix_size, cx *x,
                              mlod_error *err)
{
	mlod_result r = pk_cx_head(m->p, index, MLOD_CHUNK_MESH, x, err);
	if (r != MLOD_OK)
		return r;
	const void *bytes = NULL;
	if (!m->fetch) {
		const mlod_pack_chunk *c = x->c;
		if (c->offset > m->size || c->stored_size > m->size - c->offset)
			return mlod_fail(err, MLOD_ERR_PARSE, "%s: truncated: the chunk ends at byte %llu, the data has %zu",
			                 x->label, (unsigned long long)(c->offset + c->stored_size), m->size);
		bytes = (const uint8_t *)m->data + c->offset;
	} else {
		if ((r = m->fetch(m->user, index, &bytes, err)) != MLOD_OK)
			return r;
		if (!bytes && x->c->stored_size)
			return mlod_fail(err, MLOD_ERR_INVALID_ARG, "%s: the fetch gave no bytes", x->label);
	}
	x->base = bytes;
	x->prefix = prefix;
	x->prefix_size = prefix_size;
	return pk_cx_parse(x, err);
}

/* A part's MTSC stream s (its target count, checked): pt->targets and
 * *scales taken from the level's block, the scales copied and checked. */
static mlod_result morph_scales(cx *x, bump *bp, const stream *s, mlod_pack_part *pt, uint32_t i, float **scales,
                                mlod_error *err)
{
	const uint8_t *src;
	const uint32_t T = pt->rec.target_count;
	mlod_result r = pk_cx_load(x, s, &src, err);
	if (r != MLOD_OK)
		return r;
	pt->targets = bump_take(bp, (uint64_t)T * sizeof(float *));
	*scales = bump_take(bp, (uint64_t)T * 4);
	if (!pt->targets || !*scales)
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: internal block size mismatch", x->label);
	memcpy(*scales, src, (size_t)T * 4);
	for (uint32_t t = 0; t < T; t++)
		if (!((*scales)[t] >= 0) || !isfinite((*scales)[t] * 32768.0f))
			return mlod_fail(err, MLOD_ERR_PARSE, "%s: part %u: morph target %u: scale %g is not finite and >= 0",
			                 x->label, i, t, (double)(*scales)[t]);
	return MLOD_OK;
}

/* Dequantises a decoded part: gather holds its vertex attributes (as
 * part_vstreams lists them) one after the other, each vertex_count
 * elements, then its targets' 'MTPQ' elements the same way; scales the
 * targets' (pt->targets allocated). Takes the arrays from *bp. */
static mlod_result part_dequant(const char *label, bump *bp, mlod_pack_part *pt, uint32_t i, const uint8_t *gather,
                                const float *scales, const mlod_pack_skeleton *skel, mlod_error *err)
{
	bump b = *bp;
	struct {
		const char *label;
	} x = {label};
	mlod_result r = MLOD_OK;
	const mlod_pack_part_rec *rc = &pt->rec;
	uint32_t V = rc->vertex_count, T = rc->target_count;
	uint32_t size[VSTREAMS_MAX], tag[VSTREAMS_MAX];
	int nvs = part_vstreams(rc, tag, size);
	const uint8_t *g[VSTREAMS_MAX] = {0};
	(void)tag;
	{
		size_t off = 0;
		for (int c = 0; c < nvs; c++)
			g[c] = gather + off, off += (size_t)V * size[c];
	}
	/* Dequantise. */
	int a = 0;
	const uint8_t *q = g[a++];
	TAKE(pt->positions, (uint64_t)V * 12);
	for (uint32_t v = 0; v < V; v++)
		for (int c = 0; c < 3; c++)
			pt->positions[3 * v + c] = rc->pos_min[c] + rd16(q + 8 * (size_t)v + 2 * c) * rc->pos_scale[c];
	if (rc->flags & MLOD_PART_NORMALS) {
		q = g[a++];
		TAKE(pt->normals, (uint64_t)V * 12);
		for (uint32_t v = 0; v < V; v++)
			oct_decode(rdi16(q + 4 * (size_t)v), rdi16(q + 4 * (size_t)v + 2), pt->normals + 3 * (size_t)v);
	}
	if (rc->flags & MLOD_PART_TANGENTS) {
		q = g[a++];
		TAKE(pt->tangents, (uint64_t)V * 16);
		for (uint32_t v = 0; v < V; v++) {
			const uint8_t *e = q + 8 * (size_t)v;
			int16_t w = rdi16(e + 4);
			if (w != 32767 && w != -32767)
				FAIL("%s: part %u: vertex %u: tangent handedness %d is not -32767 or 32767", x.label, i, v, w);
			oct_decode(rdi16(e), rdi16(e + 2), pt->tangents + 4 * (size_t)v);
			pt->tangents[4 * (size_t)v + 3] = w > 0 ? 1.0f : -1.0f;
		}
	}
	for (uint32_t t = 0; t < rc->uv_sets; t++) {
		q = g[a++];
		TAKE(pt->uvs[t], (uint64_t)V * 8);
		for (uint32_t v = 0; v < V; v++)
			for (int c = 0; c < 2; c++)
				pt->uvs[t][2 * (size_t)v + c] =
				        rc->uv_min[t][c] + rd16(q + 4 * (size_t)v + 2 * c) * rc->uv_scale[t][c];
	}
	if (rc->flags & MLOD_PART_COLORS) {
		q = g[a++];
		TAKE(pt->colors, (uint64_t)V * 16);
		for (size_t k = 0; k < (size_t)V * 4; k++)
			pt->colors[k] = q[k] / 255.0f;
	}
	if (rc->flags & MLOD_PART_SKINNED) {
		int j16 = (rc->flags & MLOD_PART_JOINTS16) != 0;
		uint32_t skin_joints = skel->skins[rc->skin].joint_count;
		q = g[a++];
		TAKE(pt->joints, (uint64_t)V * 8);
		for (size_t k = 0; k < (size_t)V * 4; k++) {
			uint16_t jv = j16 ? rd16(q + 2 * k) : q[k];
			if (jv >= skin_joints)
				FAIL("%s: part %u: vertex %zu: joint %u is not below skin %d's %u joints", x.label, i, k / 4,
				     jv, rc->skin, skin_joints);
			pt->joints[k] = jv;
		}
		q = g[a++];
		TAKE(pt->weights, (uint64_t)V * 16);
		for (uint32_t v = 0; v < V; v++) {
			const uint8_t *e = q + 4 * (size_t)v;
			unsigned sum = (unsigned)e[0] + e[1] + e[2] + e[3];
			if (sum != 255)
				FAIL("%s: part %u: vertex %u: weights sum to %u, not 255", x.label, i, v, sum);
			for (int c = 0; c < 4; c++)
				pt->weights[4 * (size_t)v + c] = e[c] / 255.0f;
		}
	}
	q = gather;
	for (int c = 0; c < nvs; c++)
		q += (size_t)V * size[c];
	for (uint32_t t = 0; t < T; t++) {
		TAKE(pt->targets[t], (uint64_t)V * 12);
		const uint8_t *e = q + (size_t)t * V * 8;
		for (uint32_t v = 0; v < V; v++)
			for (int c = 0; c < 3; c++)
				pt->targets[t][3 * (size_t)v + c] = rdi16(e + 8 * (size_t)v + 2 * c) * scales[t];
	}
fail:
	*bp = b;
	return r;
}

/* The bytes a decoded mesh level's part takes (its mlod_pack_part arrays,
 * each rounded to 8), from its record alone. */
static uint64_t decoded_part_bytes(const mlod_pack_part_rec *rc)
{
	const uint64_t V = rc->vertex_count, T = rc->target_count;
	const uint32_t f = rc->flags;
	uint64_t total = round8(V * 12);
	total += (f & MLOD_PART_NORMALS) ? round8(V * 12) : 0;
	total += (f & MLOD_PART_TANGENTS) ? round8(V * 16) : 0;
	total += (uint64_t)rc->uv_sets * round8(V * 8);
	total += (f & MLOD_PART_COLORS) ? round8(V * 16) : 0;
	total += (f & MLOD_PART_SKINNED) ? round8(V * 8) + round8(V * 16) : 0;
	total += round8((uint64_t)rc->index_count * 4);
	if (T)
		total += round8(T * sizeof(float *)) + round8(T * 4) + T * round8(V * 12);
	return total;
}

#if MLOD_DRACO
/* A part's attribute in a Draco mesh (mlod(5), codec draco): the stream's
 * element as components of 1 or 2 bytes; 'POSQ' and 'MTPQ' drop their
 * fourth (zero) component. */
static void draco_comp(uint32_t tag, uint32_t elsize, int *components, int *bytes)
{
	if (elsize == 8) {
		*bytes = 2;
		*components = tag == MLOD_STREAM_POSQ || tag == MLOD_STREAM_MTPQ ? 3 : 4;
	} else if (tag == MLOD_STREAM_COLQ || tag == MLOD_STREAM_JNT8 || tag == MLOD_STREAM_WGT8) {
		*bytes = 1, *components = 4;
	} else {
		*bytes = 2, *components = 2;
	}
}

/* A MESH level of codec draco: stands alone (no coarser chunk is read).
 * 'PART', then per part 'DRCO' (its level as one Draco mesh) and, with
 * morph targets, 'MTSC'. */
static mlod_result decode_mesh_draco(const mesh_src *m, uint32_t chunk, const mlod_pack_skeleton *skel,
                                     mlod_pack_mesh *out, mlod_error *err)
{
	const mlod_pack *p = m->p;
	const mlod_pack_alloc *al = &p->alloc;
	cx x;
	memset(&x, 0, sizeof x);
	bump b = {0};
	stream s, sp;
	const uint8_t *src;
	mlod_pack_part_rec *recs = NULL;
	uint8_t *gather = NULL;
	uint32_t J = skel ? skel->joint_count : 0, S = skel ? skel->skin_count : 0;
	mlod_result r = mesh_begin(m, chunk, NULL, 0, &x, err);
	if (r != MLOD_OK) {
		pk_cx_done(&x);
		return r;
	}
	TRY(pk_cx_expect(&x, &sp, MLOD_STREAM_PART, sizeof(mlod_pack_part_rec), UINT64_MAX, "", "", err));
	if (sp.codec != MLOD_SCODEC_RAW)
		FAIL("%s: 'PART' is not stored raw in a Draco chunk", x.label);
	uint64_t P = sp.count; /* raw: its bytes are inside the chunk */
	TRY(pk_cx_load(&x, &sp, &src, err));
	if (!(recs = pk_calloc(al, P + 1, sizeof *recs)))
		FAIL_NOMEM("%s: out of memory for %llu parts", x.label, (unsigned long long)P);
	for (uint64_t i = 0; i < P; i++)
		memcpy(&recs[i], src + i * sizeof *recs, sizeof *recs);
	/* The records bound every allocation before Draco decodes anything. */
	uint64_t total = round8(P * sizeof(mlod_pack_part)), big = 8;
	for (uint32_t i = 0; i < P; i++) {
		const mlod_pack_part_rec *rc = &recs[i];
		TRY(check_part_rec(&x, i, rc, J, S, err));
		if (rc->flags & (MLOD_PART_INDEX16 | MLOD_PART_LOCAL | MLOD_PART_NEWBITS))
			FAIL("%s: part %u: flags 0x%x: INDEX16, LOCAL and NEWBITS are not for a Draco chunk", x.label, i,
			     rc->flags);
		if ((rc->vertex_count == 0) != (rc->index_count == 0))
			FAIL("%s: part %u: %u vertices and %u indices: a Draco part has triangles or neither", x.label, i,
			     rc->vertex_count, rc->index_count);
		uint64_t V = rc->vertex_count, T = rc->target_count;
		uint32_t tag[VSTREAMS_MAX], size[VSTREAMS_MAX];
		int nv = part_vstreams(rc, tag, size);
		uint64_t stride = 8 * T;
		for (int a = 0; a < nv; a++)
			stride += size[a];
		total += decoded_part_bytes(rc);
		big = V * stride > big ? V * stride : big;
		if (total > PACK_MAX_BLOCK || big > PACK_MAX_BLOCK)
			FAIL("%s: decoded, its parts need more than the reader's limit", x.label);
	}
	if (total > (uint64_t)PACK_DRACO_MAX_EXPAND * x.size)
		FAIL("%s: its part records say %llu decoded bytes, more than %d times its %llu-byte container (Draco "
		     "levels expand no more)",
		     x.label, (unsigned long long)total, PACK_DRACO_MAX_EXPAND, (unsigned long long)x.size);
	if (m->reserve)
		TRY(m->reserve(m->reserve_user, recs, (uint32_t)P, err));
	TRY(pk_bump_alloc(&b, &x, total, err));
	if (!(gather = pk_malloc(al, 1, (size_t)big)))
		FAIL_NOMEM("%s: out of memory", x.label);
	mlod_pack_part *parts = bump_take(&b, P * sizeof *parts);
	if (!parts)
		FAIL("%s: internal block size mismatch", x.label);
	for (uint32_t i = 0; i < P; i++) {
		mlod_pack_part *pt = &parts[i];
		pt->rec = recs[i];
		const mlod_pack_part_rec *rc = &pt->rec;
		uint32_t V = rc->vertex_count, T = rc->target_count, tag[VSTREAMS_MAX], size[VSTREAMS_MAX];
		int nv = part_vstreams(rc, tag, size);
		char what[32];
		snprintf(what, sizeof what, "part %u", i);
		TRY(pk_cx_expect(&x, &s, MLOD_STREAM_DRCO, 1, UINT64_MAX, what, "", err));
		if (s.codec != MLOD_SCODEC_RAW)
			FAIL("%s: part %u: 'DRCO' is not stored raw", x.label, i);
		stream dr = s;
		mlod_rt_draco_attr at[VSTREAMS_MAX + 256];
		if (T > 256)
			FAIL("%s: part %u: %u morph targets, more than a Draco part's 256", x.label, i, T);
		size_t off = 0;
		for (int a = 0; a < nv + (int)T; a++) {
			uint32_t es = a < nv ? size[a] : 8, tg = a < nv ? tag[a] : MLOD_STREAM_MTPQ;
			draco_comp(tg, es, &at[a].components, &at[a].elsize);
			at[a].dst = gather + off;
			at[a].stride = es;
			off += (size_t)V * es;
		}
		memset(gather, 0, off); /* the dropped fourth components */
		TAKE(pt->indices, (uint64_t)rc->index_count * 4);
		char msg[160];
		if (V == 0 && dr.stored != 0) /* a part without triangles (mlod(5)) */
			FAIL("%s: part %u: no vertices, but a %llu-byte 'DRCO'", x.label, i, (unsigned long long)dr.stored);
		if (V > 0 && mlod_rt_draco_decode(dr.src, dr.stored, V, rc->index_count, at, nv + (int)T, pt->indices, msg,
		                                  sizeof msg) != 0)
			FAIL("%s: part %u: %s", x.label, i, msg);
		float *scales = NULL;
		if (T) {
			TRY(pk_cx_expect(&x, &s, MLOD_STREAM_MTSC, 4, T, what, "target count", err));
			TRY(morph_scales(&x, &b, &s, pt, i, &scales, err));
		}
		TRY(part_dequant(x.label, &b, pt, i, gather, scales, skel, err));
	}
	TRY(pk_cx_end(&x, err));
	out->part_count = (uint32_t)P;
	out->parts = parts;
	out->block = b.base;
	b.base = NULL;
	r = MLOD_OK;
fail:
	pk_cx_done(&x);
	pk_free(al, b.base);
	pk_free(al, recs);
	pk_free(al, gather);
	return r;
}
#endif

static mlod_result decode_mesh(const mesh_src *m, uint32_t chunk, const mlod_pack_skeleton *skel, mlod_pack_mesh *out,
                               mlod_error *err)
{
	if (!out)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_pack_decode_mesh: out is NULL");
	memset(out, 0, sizeof *out);
	const mlod_pack *p = m->p;
	if (!p || (!m->fetch && !m->data && m->size))
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "pack decode: the pack or the data is NULL");
	cx x;
	mlod_result r = pk_cx_head(p, chunk, MLOD_CHUNK_MESH, &x, err);
	if (r != MLOD_OK)
		return r;
#if MLOD_DRACO
	if (p->chunks[chunk].codec == MLOD_CODEC_DRACO)
		return decode_mesh_draco(m, chunk, skel, out, err);
#endif
	/* The chunks to read: every MESH level from the coarsest down to this
	 * one (their blocks make the prefix this level's indices refer to). */
	unsigned K = p->chunks[chunk].level, top = K;
	for (uint32_t i = 0; i < p->chunk_count; i++)
		if (p->chunks[i].type == MLOD_CHUNK_MESH && p->chunks[i].level > top)
			top = p->chunks[i].level;
	uint32_t nlev = top - K + 1;
	const mlod_pack_alloc *al = &p->alloc;
	bump b = {0};
	stream s;
	const uint8_t *src;
	uint32_t J = skel ? skel->joint_count : 0, S = skel ? skel->skin_count : 0;
	uint64_t P = 0;
	mlod_pack_part_rec *recs0 = NULL; /* the coarsest level's records */
	mblock *blk = NULL;               /* nlev * P */
	uint8_t *blocks = NULL, *temp = NULL; /* the levels' blocks; meshopt's output of the other streams */
	uint64_t blocks_used = 0, sumraw = 0, maxraw = 0, temp_cap = 0;
	uint32_t *map = NULL, *used = NULL;
	uint8_t *work = NULL, *gather = NULL;
	int lev_open = 0;
	memset(&x, 0, sizeof x);
	/* The chunks' raw sizes bound what their blocks and streams decode to
	 * (pk_cx_parse checks them): two allocations for every level. */
	for (uint32_t l = 0; l < nlev; l++) {
		int ci = mlod_pack_find(p, MLOD_CHUNK_MESH, top - l, 0);
		/* An unknown codec or entropy stage: its raw size means nothing
		 * (pk_cx_head says which; called only then, for its message). */
		if (ci >= 0 && (p->chunks[ci].codec > MLOD_CODEC_DRACO || p->chunks[ci].entropy > MLOD_ENTROPY_ZSTD_PREFIX) &&
		    (r = pk_cx_head(p, (uint32_t)ci, MLOD_CHUNK_MESH, &x, err)) != MLOD_OK)
			return r;
		uint64_t raw = ci >= 0 ? p->chunks[ci].raw_size : 0;
		sumraw += raw;
		maxraw = raw > maxraw ? raw : maxraw;
	}
	if (sumraw > PACK_MAX_BLOCK)
		return mlod_fail(err, MLOD_ERR_NOMEM, "MESH level %u: decoding it and the coarser levels needs %llu bytes, more "
		                 "than the reader's limit", K, (unsigned long long)sumraw);
	/* The prefix of the finest prefix-coded level read (format 6.0): the
	 * containers of the levels above it, coarsest first, kept as they are
	 * read; each container's size is its TOC coded size, or its stored
	 * size without an entropy stage (pk_cx_parse checks both). */
	unsigned pmin = 0; /* that level + 1; 0: no level read is prefix-coded */
	uint64_t pcap = 0, pused = 0;
	uint8_t *pbuf = NULL;
	for (uint32_t l = 0; l < nlev; l++) {
		int ci = mlod_pack_find(p, MLOD_CHUNK_MESH, top - l, 0);
		if (ci >= 0 && p->chunks[ci].entropy == MLOD_ENTROPY_ZSTD_PREFIX)
			pmin = top - l + 1;
	}
	for (unsigned L = top; pmin && L >= pmin; L--) {
		int ci = mlod_pack_find(p, MLOD_CHUNK_MESH, L, 0);
		if (ci >= 0)
			pcap += p->chunks[ci].entropy ? p->chunks[ci].coded_size : p->chunks[ci].stored_size;
		if (L == 0)
			break;
	}
	if (pcap > MLOD_PACK_MAX_PREFIX)
		return mlod_fail(err, MLOD_ERR_PARSE, "MESH level %u: its prefix (MESH levels %u to %u's containers) is %llu "
		                 "bytes, more than the format's %llu", pmin - 1, top, pmin, (unsigned long long)pcap,
		                 (unsigned long long)MLOD_PACK_MAX_PREFIX);
	if (pmin && !(pbuf = pk_malloc(al, 1, (size_t)pcap + 1)))
		return mlod_fail(err, MLOD_ERR_NOMEM, "MESH level %u: out of memory for its %llu-byte prefix", pmin - 1,
		                 (unsigned long long)pcap);
	blocks = pk_malloc(al, 1, (size_t)sumraw + 8);
	if (!blocks) {
		pk_free(al, pbuf);
		return mlod_fail(err, MLOD_ERR_NOMEM, "MESH level %u: out of memory", K);
	}
	for (uint32_t l = 0; l < nlev; l++) {
		unsigned L = top - l;
		int ci = mlod_pack_find(p, MLOD_CHUNK_MESH, L, 0);
		if (ci < 0) {
			r = mlod_fail(err, MLOD_ERR_PARSE, "MESH level %u: MESH level %u is missing (a level needs every coarser "
			              "one)", K, L);
			goto fail;
		}
		if (p->chunks[ci].codec == MLOD_CODEC_DRACO)
			FAIL("MESH level %u: builds on MESH level %u, which is Draco-coded (a Draco level stands alone; layout "
			     "b2 levels cannot use its vertices)", K, L);
		TRY(mesh_begin(m, (uint32_t)ci, pbuf, pused, &x, err));
		lev_open = 1;
		if (pmin && L >= pmin) {
			if (x.size > pcap - pused)
				FAIL("%s: its container of %llu bytes does not fit the prefix's %llu", x.label,
				     (unsigned long long)x.size, (unsigned long long)(pcap - pused));
			memcpy(pbuf + pused, x.base, (size_t)x.size);
			pused += x.size;
		}
		stream sp;
		TRY(pk_cx_expect(&x, &sp, MLOD_STREAM_PART, sizeof(mlod_pack_part_rec), l ? P : UINT64_MAX, "",
		                 "the parts of the coarsest level", err));
		if (l == 0) {
			P = sp.count;
			if (P * (2 * sizeof *recs0 + nlev * sizeof *blk + sizeof(mlod_pack_part)) > PACK_MAX_BLOCK) {
				r = mlod_fail(err, MLOD_ERR_NOMEM, "%s: %llu parts: decoding them needs more than the reader's limit",
				              x.label, (unsigned long long)P);
				goto fail;
			}
			recs0 = pk_calloc(al, P + 1, sizeof *recs0);
			blk = pk_calloc(al, (uint64_t)nlev * P + 1, sizeof *blk);
			if (!recs0 || !blk) {
				r = mlod_fail(err, MLOD_ERR_NOMEM, "%s: out of memory for %llu parts", x.label, (unsigned long long)P);
				goto fail;
			}
		}
		/* Size this level's blocks from the stream headers. */
		uint64_t bytes = 0;
		/* meshopt's output of the streams not decoded into a block: 'PART'
		 * (read above), 'IDX ' and 'MTSC' */
		uint64_t need = sp.codec != MLOD_SCODEC_RAW ? (uint64_t)sp.count * sp.elsize : 0;
		{
			stream t;
			while (cx_next(&x, &t))
				if (t.tag != MLOD_STREAM_IDX && t.tag != MLOD_STREAM_INEW && t.tag != MLOD_STREAM_IMAP &&
				    t.tag != MLOD_STREAM_MTSC && t.tag != MLOD_STREAM_PART)
					bytes += round8((uint64_t)t.count * t.elsize);
				else if (t.codec != MLOD_SCODEC_RAW && (uint64_t)t.count * t.elsize > need)
					need = (uint64_t)t.count * t.elsize;
			cx_rewind(&x);
			TRY(pk_cx_expect(&x, &sp, MLOD_STREAM_PART, sizeof(mlod_pack_part_rec), P, "", "", err));
		}
		if (bytes > sumraw - blocks_used || need > maxraw)
			FAIL("%s: internal block size mismatch", x.label);
		if (need > temp_cap) {
			pk_free(al, temp);
			temp_cap = 0;
			if (!(temp = pk_malloc(al, 1, (size_t)need + 8)))
				FAIL_NOMEM("%s: out of memory for %llu bytes of scratch", x.label, (unsigned long long)need);
			temp_cap = need;
		}
		x.temp = temp, x.aux = 0; /* the decode's scratch, shared by the levels (pk_cx_done frees none) */
		uint8_t *at = blocks + blocks_used;
		blocks_used += bytes;
		TRY(pk_cx_load(&x, &sp, &src, err));
		mlod_pack_part_rec *recs = pk_calloc(al, P + 1, sizeof *recs);
		if (!recs) {
			r = mlod_fail(err, MLOD_ERR_NOMEM, "%s: out of memory", x.label);
			goto fail;
		}
		for (uint64_t i = 0; i < P; i++)
			memcpy(&recs[i], src + i * sizeof(mlod_pack_part_rec), sizeof(mlod_pack_part_rec));
		for (uint32_t i = 0; i < P && r == MLOD_OK; i++) {
			r = check_part_rec(&x, i, &recs[i], J, S, err);
			if (r == MLOD_OK && l == 0)
				recs0[i] = recs[i];
			else if (r == MLOD_OK && !same_part(&recs[i], &recs0[i]))
				r = mlod_fail(err, MLOD_ERR_PARSE,
				              "%s: part %u: its record differs from MESH level %u's (a part's levels share its "
				              "node, skin, attributes and grid)",
				              x.label, i, top);
		}
		if (r != MLOD_OK) {
			pk_free(al, recs);
			goto fail;
		}
		for (uint32_t i = 0; i < P && r == MLOD_OK; i++) {
			const mlod_pack_part_rec *rc = &recs[i];
			mblock *mb = &blk[(uint64_t)l * P + i];
			char what[32];
			snprintf(what, sizeof what, "part %u", i);
			uint32_t tag[VSTREAMS_MAX], size[VSTREAMS_MAX];
			int nv = part_vstreams(rc, tag, size);
			mb->first = l ? blk[(uint64_t)(l - 1) * P + i].first + blk[(uint64_t)(l - 1) * P + i].count : 0;
			mb->base = at;
			uint64_t off = 0;
			for (int a = 0; a < nv && r == MLOD_OK; a++) {
				r = pk_cx_expect(&x, &s, tag[a], size[a], a ? mb->count : UINT64_MAX, what, "the block's vertex count",
				                 err);
				if (r == MLOD_OK && a == 0)
					mb->count = s.count;
				if (r == MLOD_OK)
					r = pk_cx_load_into(&x, &s, mb->base + off, err);
				off += (uint64_t)s.count * size[a];
			}
			if (r != MLOD_OK)
				break;
			int i16 = (rc->flags & MLOD_PART_INDEX16) != 0;
			if (rc->flags & MLOD_PART_LOCAL) {
				if (rc->flags & MLOD_PART_NEWBITS)
					r = pk_cx_expect(&x, &s, MLOD_STREAM_INEW, 4, ((uint64_t)rc->vertex_count + 31) / 32, what,
					                 "a bit per vertex", err);
				if (r == MLOD_OK) /* its count: checked against 'INEW' when decoded */
					r = pk_cx_expect(&x, &s, MLOD_STREAM_IMAP, i16 ? 2 : 4, UINT64_MAX, what, "", err);
			}
			if (r == MLOD_OK)
				r = pk_cx_expect(&x, &s, MLOD_STREAM_IDX, i16 ? 2 : 4, rc->index_count, what, "index count", err);
			if (r == MLOD_OK && rc->target_count > 0)
				r = pk_cx_expect(&x, &s, MLOD_STREAM_MTSC, 4, rc->target_count, what, "target count", err);
			for (uint32_t t = 0; t < rc->target_count && r == MLOD_OK; t++) {
				char twhat[64];
				snprintf(twhat, sizeof twhat, "part %u target %u", i, t);
				r = pk_cx_expect(&x, &s, MLOD_STREAM_MTPQ, 8, mb->count, twhat, "the block's vertex count", err);
				if (r == MLOD_OK)
					r = pk_cx_load_into(&x, &s, mb->base + off, err);
				off += (uint64_t)s.count * 8;
			}
			at += round8(off);
			if (r != MLOD_OK || l + 1 < nlev)
				continue;
			/* This level: gather the vertices its indices use. */
			uint64_t prefix = mb->first + mb->count;
			if (rc->vertex_count > prefix) {
				r = mlod_fail(err, MLOD_ERR_PARSE, "%s: part %u: %u vertices, more than its prefix of %llu (MESH levels %u to %u)",
				              x.label, i, rc->vertex_count, (unsigned long long)prefix, top, K);
				break;
			}
		}
		if (r != MLOD_OK) {
			pk_free(al, recs);
			goto fail;
		}
		if (l + 1 < nlev) {
			TRY(pk_cx_end(&x, err));
			x.temp = NULL;
			pk_cx_done(&x);
			lev_open = 0;
			pk_free(al, recs);
			continue;
		}
		/* The finest level read is the one asked for: its output. */
		uint64_t total = round8(P * sizeof(mlod_pack_part)), big_prefix = 1, big_v = 1;
		for (uint32_t i = 0; i < P; i++) {
			const mlod_pack_part_rec *rc = &recs[i];
			uint64_t V = rc->vertex_count, T = rc->target_count;
			total += decoded_part_bytes(rc);
			const mblock *mb = &blk[(uint64_t)l * P + i];
			uint64_t stride = 0;
			uint32_t tag[VSTREAMS_MAX], size[VSTREAMS_MAX];
			int nv = part_vstreams(rc, tag, size);
			for (int a = 0; a < nv; a++)
				stride += size[a];
			stride += 8 * T;
			big_prefix = mb->first + mb->count > big_prefix ? mb->first + mb->count : big_prefix;
			big_v = V * stride > big_v ? V * stride : big_v;
			if (total > PACK_MAX_BLOCK || big_v > PACK_MAX_BLOCK)
				break;
		}
		if (big_prefix > PACK_MAX_BLOCK / 8 || big_v > PACK_MAX_BLOCK) {
			pk_free(al, recs);
			FAIL("%s: its parts' prefixes (%llu vertices) are larger than the reader's limit", x.label,
			     (unsigned long long)big_prefix);
		}
		if (m->reserve && (r = m->reserve(m->reserve_user, recs, (uint32_t)P, err)) != MLOD_OK) {
			pk_free(al, recs);
			goto fail;
		}
		r = pk_bump_alloc(&b, &x, total, err);
		work = pk_malloc(al, 1, (size_t)(8 * big_prefix + big_v + 8));
		if (work) {
			map = (uint32_t *)work;
			used = map + big_prefix;
			gather = (uint8_t *)(used + big_prefix);
		}
		if (r == MLOD_OK && !work)
			r = mlod_fail(err, MLOD_ERR_NOMEM, "%s: out of memory", x.label);
		if (r != MLOD_OK) {
			pk_free(al, recs);
			goto fail;
		}
		mlod_pack_part *parts = bump_take(&b, P * sizeof *parts);
		if (!parts) {
			pk_free(al, recs);
			FAIL("%s: internal block size mismatch", x.label);
		}
		for (uint64_t i = 0; i < P; i++)
			parts[i].rec = recs[i];
		pk_free(al, recs);
		/* Walk the chunk again for the indices and the targets' scales. */
		cx_rewind(&x);
		TRY(pk_cx_expect(&x, &sp, MLOD_STREAM_PART, sizeof(mlod_pack_part_rec), P, "", "", err));
		for (uint32_t i = 0; i < P; i++) {
			mlod_pack_part *pt = &parts[i];
			const mlod_pack_part_rec *rc = &pt->rec;
			uint32_t tag[VSTREAMS_MAX], size[VSTREAMS_MAX];
			int nvs = part_vstreams(rc, tag, size);
			for (int a = 0; a < nvs; a++)
				cx_next(&x, &s);
			int i16 = (rc->flags & MLOD_PART_INDEX16) != 0, local = (rc->flags & MLOD_PART_LOCAL) != 0;
			const mblock *mb = &blk[(uint64_t)l * P + i];
			uint64_t prefix = mb->first + mb->count;
			uint32_t V = rc->vertex_count, nused = 0;
			if (local) { /* the prefix vertex of each of the level's: 'INEW', 'IMAP' */
				uint32_t nnew = 0, nold = 0, w = 0;
				int bits = (rc->flags & MLOD_PART_NEWBITS) != 0;
				if (bits) {
					cx_next(&x, &s);
					TRY(pk_cx_load(&x, &s, &src, err));
				}
				for (uint32_t v = 0; v < V; v++) {
					if (bits)
						memcpy(&w, src + 4 * (size_t)(v / 32), 4);
					if (!(w >> (v % 32) & 1u)) {
						used[v] = UINT32_MAX, nold++;
						continue;
					}
					if (nnew == mb->count)
						FAIL("%s: part %u: 'INEW' marks more than its block's %u vertices new", x.label, i,
						     mb->count);
					used[v] = (uint32_t)mb->first + nnew++;
				}
				cx_next(&x, &s);
				if (s.count != nold)
					FAIL("%s: part %u: stream %u 'IMAP' has %u elements, expected %u (the vertices 'INEW' leaves)",
					     x.label, i, s.index, s.count, nold);
				TRY(pk_cx_load(&x, &s, &src, err));
				for (uint32_t v = 0, o = 0; v < V; v++) {
					if (used[v] != UINT32_MAX)
						continue;
					const uint32_t iv = index_at(src, i16, o);
					if (iv >= prefix)
						FAIL("%s: part %u: vertex %u maps to %u, past its prefix of %llu vertices (MESH levels %u "
						     "to %u)",
						     x.label, i, v, iv, (unsigned long long)prefix, top, K);
					used[v] = iv, o++;
				}
				nused = V;
			}
			cx_next(&x, &s); /* 'IDX ', checked above */
			TRY(pk_cx_load(&x, &s, &src, err));
			for (uint64_t v = 0; v < prefix && !local; v++)
				map[v] = UINT32_MAX;
			TAKE(pt->indices, (uint64_t)rc->index_count * 4);
			for (uint32_t k = 0; k < rc->index_count && local; k++) {
				const uint32_t iv = index_at(src, i16, k);
				if (iv >= V)
					FAIL("%s: part %u: index %u refers past its %u vertices (at position %u)", x.label, i, iv, V, k);
				pt->indices[k] = iv;
			}
			for (uint32_t k = 0; k < rc->index_count && !local; k++) {
				const uint32_t iv = index_at(src, i16, k);
				if (iv >= prefix)
					FAIL("%s: part %u: index %u refers past its prefix of %llu vertices (MESH levels %u to %u; at "
					     "position %u)",
					     x.label, i, iv, (unsigned long long)prefix, top, K, k);
				if (map[iv] == UINT32_MAX) {
					if (nused == V)
						FAIL("%s: part %u: its indices use more than its %u vertices", x.label, i, V);
					used[nused] = iv;
					map[iv] = nused++;
				}
				pt->indices[k] = map[iv];
			}
			if (nused != V)
				FAIL("%s: part %u: its indices use %u vertices, its record says %u", x.label, i, nused, V);
			float *scales = NULL;
			uint32_t T = rc->target_count;
			if (T) {
				cx_next(&x, &s); /* 'MTSC', checked above */
				TRY(morph_scales(&x, &b, &s, pt, i, &scales, err));
				for (uint32_t t = 0; t < T; t++)
					cx_next(&x, &s);
			}
			/* Gather: each attribute of the level's vertices, one after
			 * the other, from the levels' blocks (coarsest first; map[v]
			 * becomes vertex v's block). */
			for (uint32_t v = 0; v < V; v++) {
				uint32_t lo = 0, hi = nlev - 1;
				while (lo < hi) {
					uint32_t mid = lo + (hi - lo + 1) / 2;
					if (blk[(uint64_t)mid * P + i].first <= used[v])
						lo = mid;
					else
						hi = mid - 1;
				}
				map[v] = lo;
			}
			uint64_t aoff = 0, before = 0;
			for (int a = 0; a < nvs + (int)T; a++) {
				uint32_t es = a < nvs ? size[a] : 8;
				uint8_t *dst = gather + aoff;
				const uint8_t *from[64];
				uint64_t first[64];
				for (uint32_t q = 0; q < nlev && q < 64; q++) { /* attribute a of each level's block */
					const mblock *bb = &blk[(uint64_t)q * P + i];
					from[q] = bb->base + before * bb->count, first[q] = bb->first;
				}
				for (uint32_t v = 0; v < V; v++) {
					const uint8_t *sv;
					if (map[v] < 64) {
						sv = from[map[v]] + (used[v] - first[map[v]]) * es;
					} else {
						const mblock *bb = &blk[(uint64_t)map[v] * P + i];
						sv = bb->base + before * bb->count + (used[v] - bb->first) * es;
					}
					if (es == 4)
						memcpy(dst + (size_t)v * 4, sv, 4);
					else
						memcpy(dst + (size_t)v * 8, sv, 8);
				}
				aoff += (uint64_t)V * es;
				before += es;
			}
			TRY(part_dequant(x.label, &b, pt, i, gather, scales, skel, err));
		}
		TRY(pk_cx_end(&x, err));
		x.temp = NULL;
		pk_cx_done(&x);
		lev_open = 0;
		out->part_count = (uint32_t)P;
		out->parts = parts;
		out->block = b.base;
		b.base = NULL;
	}
	r = MLOD_OK;
fail:
	if (lev_open) {
		x.temp = NULL;
		pk_cx_done(&x);
	}
	pk_free(al, b.base);
	pk_free(al, blocks);
	pk_free(al, pbuf);
	pk_free(al, temp);
	pk_free(al, recs0);
	pk_free(al, blk);
	pk_free(al, work);
	return r;
}

mlod_result mlod_pack_decode_mesh(const mlod_pack *p, uint32_t chunk, const void *data, size_t size,
                                  const mlod_pack_skeleton *skel, mlod_pack_mesh *out, mlod_error *err)
{
	mesh_src m = {p, data, size, NULL, NULL, NULL, NULL};
	return decode_mesh(&m, chunk, skel, out, err);
}

mlod_result mlod_pack_decode_mesh_reserve(const mlod_pack *p, uint32_t chunk, const void *data, size_t size,
                                          mlod_pack_fetch_fn fetch, void *fetch_user, mlod_pack_reserve_fn reserve,
                                          void *reserve_user, const mlod_pack_skeleton *skel, mlod_pack_mesh *out,
                                          mlod_error *err)
{
	mesh_src m = {p, fetch ? NULL : data, fetch ? 0 : size, fetch, fetch_user, reserve, reserve_user};
	return decode_mesh(&m, chunk, skel, out, err);
}

mlod_result mlod_pack_decode_mesh_fetch(const mlod_pack *p, uint32_t chunk, mlod_pack_fetch_fn fetch, void *user,
                                        const mlod_pack_skeleton *skel, mlod_pack_mesh *out, mlod_error *err)
{
	if (!fetch) {
		if (out)
			memset(out, 0, sizeof *out);
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_pack_decode_mesh_fetch: fetch is NULL");
	}
	mesh_src m = {p, NULL, 0, fetch, user, NULL, NULL};
	return decode_mesh(&m, chunk, skel, out, err);
}

void mlod_pack_mesh_free(mlod_pack_mesh *x)
{
	if (x)
		pk_block_release(x->block, x, sizeof *x);
}
