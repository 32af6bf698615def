/*
 * packmesh.c: the MESH chunks, layout b2 (mlod(5) MESH levels): each
 * part's one quantised vertex buffer, the levels' index blocks into it, or
 * standalone Draco meshes (packwrite_internal.h).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pack/draco.h"
#include "pack/packwrite_internal.h"

/* ------------------------------------------------------------------ */
/* Layout b2 (mlod(5) MESH levels): per part one buffer of quantised     */
/* vertices on one grid, each vertex placed by the coarsest level that   */
/* has it; MESH level k carries its block of new vertices and its        */
/* indices into the buffer's prefix. The chunks are made coarsest first. */
/* ------------------------------------------------------------------ */

/* A part's vertex attribute in the interleaved working buffer. */
typedef struct mattr {
	uint32_t tag;
	uint16_t size;
	int off;
} mattr;

/* One part: a triangle primitive of an instance, at every level. jmap
 * maps a level primitive's joint indices to the full skin's (NULL: as
 * they are). */
struct mpart {
	mlod_pack_part_rec rec; /* the level-independent fields and the grid */
	const mlod_primitive *lv[MLOD_MESH_MAX_LEVELS + 1];
	const int *jmap[MLOD_MESH_MAX_LEVELS + 1];
	int jmap_count[MLOD_MESH_MAX_LEVELS + 1];
	float *tscale;          /* per morph target */
	mattr *attr;
	int nattr, ntargets, stride, skinned, wide;
	uint8_t *G;             /* the buffer, interleaved */
	uint32_t count;
	uint32_t *slot;         /* hash set of G's vertices: id + 1, 0 empty */
	size_t slot_cap;
	/* Coarse levels' own steps (part_coarse; mlod(5) QUANTISATION): per
	 * level and vertex, the finest level that has the vertex as level 0's
	 * steps quantise it (NULL: every vertex on level 0's steps); per
	 * level f >= 1, the position and UV shifts of a vertex whose finest
	 * level is f. */
	uint8_t *fin[MLOD_MESH_MAX_LEVELS + 1];
	int pos_shift[MLOD_MESH_MAX_LEVELS + 1];
	int uv_shift[MLOD_MESH_MAX_LEVELS + 1][MLOD_PACK_MAX_UV];
};

/* The attributes a level primitive has (the part's skin, -1 none). */
static uint32_t prim_signature(const mlod_primitive *p, int skin)
{
	int sets = p->uv_set_count < MLOD_PACK_MAX_UV ? p->uv_set_count : MLOD_PACK_MAX_UV;
	return (p->normals ? 1u : 0u) | (p->tangents ? 2u : 0u) | (p->color_set_count > 0 ? 4u : 0u) |
	       (skin >= 0 && p->weight_set_count > 0 ? 8u : 0u) | (uint32_t)sets << 4 | (uint32_t)p->target_count << 8;
}

/* The grid of every level of a part: the union of the levels' boxes,
 * level 0's steps (positions_bits and uv_bits of level 0's box); a union
 * wider than 65535 such steps takes the union's 16-bit steps. Morph
 * deltas: the largest |delta| of any level. bench/bench_layout makes the
 * same grid (mlod_pack_b2_grid). */
/* part_grid's axes of the positions (set -1) or of UV set `set`, at bits
 * of level 0's box: min and scale per axis. */
static void part_axes(const struct mpart *m, int M, int set, int bits, float *min, float *scale)
{
	const int n = set < 0 ? 3 : 2;
	float mn[3], mx[3], mn0[3], mx0[3];
	for (int k = 0; k < M; k++) {
		const mlod_primitive *p = m->lv[k];
		const float *d = set < 0 ? p->positions : p->uvs[set];
		for (int v = 0; v < p->vertex_count; v++)
			for (int a = 0; a < n; a++) {
				float f = d[n * v + a];
				int first = k == 0 && v == 0;
				if (first || f < mn[a])
					mn[a] = f;
				if (first || f > mx[a])
					mx[a] = f;
				if (k == 0)
					mn0[a] = first || f < mn0[a] ? f : mn0[a], mx0[a] = first || f > mx0[a] ? f : mx0[a];
			}
	}
	for (int a = 0; a < n; a++) {
		float s0 = mlod_pack_range_scale_bits(mn0[a], mx0[a], bits);
		float s16 = mlod_pack_range_scale_bits(mn[a], mx[a], 16);
		min[a] = mn[a];
		scale[a] = s0 > s16 ? s0 : s16;
	}
}

static void part_grid(struct ctx *x, struct mpart *m, int M)
{
	part_axes(m, M, -1, x->opt->position_bits, m->rec.pos_min, m->rec.pos_scale);
	for (int s = 0; s < (int)m->rec.uv_sets; s++)
		part_axes(m, M, s, x->opt->uv_bits, m->rec.uv_min[s], m->rec.uv_scale[s]);
	for (int t = 0; t < m->ntargets; t++) {
		float mt = 0.0f;
		for (int k = 0; k < M; k++) {
			const float *d = m->lv[k]->targets[t].positions;
			for (int i = 0; d && i < 3 * m->lv[k]->vertex_count; i++)
				mt = fabsf(d[i]) > mt ? fabsf(d[i]) : mt;
		}
		m->tscale[t] = mt > 0.0f ? (float)(mt / (ldexp(1.0, x->opt->position_bits - 1) - 1.0)) : 0.0f;
	}
}

/* Level k's vertices quantised on the part's grid into V (interleaved). */
static void part_quantise(struct ctx *x, const struct mpart *m, int k, uint8_t *V)
{
	const mlod_primitive *p = m->lv[k];
	const mlod_pack_part_rec *rec = &m->rec;
	int nv = p->vertex_count;
	memset(V, 0, (size_t)nv * (size_t)m->stride);
	for (int v = 0; v < nv; v++) {
		uint8_t *o = V + (size_t)v * (size_t)m->stride;
		int a = 0;
		uint16_t q[4] = {0, 0, 0, 0};
		int f = m->fin[k] ? m->fin[k][v] : 0; /* the vertex's finest level: its steps */
		for (int c = 0; c < 3; c++)
			q[c] = f ? mlod_pack_qu16_shift(p->positions[3 * v + c], rec->pos_min[c], rec->pos_scale[c],
			                                m->pos_shift[f])
			         : mlod_pack_qu16(p->positions[3 * v + c], rec->pos_min[c], rec->pos_scale[c]);
		memcpy(o + m->attr[a++].off, q, 8);
		if (p->normals) {
			int16_t s[2];
			mlod_pack_oct_encode_bits(p->normals + 3 * v, x->opt->normal_bits, s);
			memcpy(o + m->attr[a++].off, s, 4);
		}
		if (p->tangents) {
			int16_t s[4] = {0, 0, 0, 0};
			mlod_pack_oct_encode_bits(p->tangents + 4 * v, x->opt->normal_bits, s);
			s[2] = p->tangents[4 * v + 3] < 0.0f ? -32767 : 32767;
			memcpy(o + m->attr[a++].off, s, 8);
		}
		for (uint32_t s = 0; s < rec->uv_sets; s++) {
			uint16_t u[2];
			for (int c = 0; c < 2; c++)
				u[c] = f ? mlod_pack_qu16_shift(p->uvs[s][2 * v + c], rec->uv_min[s][c], rec->uv_scale[s][c],
				                                m->uv_shift[f][s])
				         : mlod_pack_qu16(p->uvs[s][2 * v + c], rec->uv_min[s][c], rec->uv_scale[s][c]);
			memcpy(o + m->attr[a++].off, u, 4);
		}
		if (p->color_set_count > 0) {
			uint8_t *u8 = o + m->attr[a++].off;
			for (int c = 0; c < 4; c++) {
				float f = p->colors[0][4 * v + c];
				f = f > 0.0f ? (f < 1.0f ? f : 1.0f) : 0.0f;
				u8[c] = (uint8_t)lrintf(f * 255.0f);
			}
		}
		if (m->skinned) {
			int joints = x->v.skeleton.skins[rec->skin].joint_count;
			int bj[4];
			float bw[4];
			mlod_pack_top4(p, (uint32_t)v, m->jmap[k], m->jmap_count[k], bj, bw);
			uint8_t w8[4], j8[4];
			uint16_t j16[4];
			mlod_pack_weights8(bw, w8);
			if (w8[0] + w8[1] + w8[2] + w8[3] == 0) { /* no weight: the skin's root (note_unweighted) */
				w8[0] = 255;
				bj[0] = mlod_skin_root(&x->v.skeleton, rec->skin);
			}
			for (int t = 0; t < 4; t++) {
				int jt = w8[t] ? bj[t] : 0;
				if (jt < 0 || jt >= joints)
					jt = 0;
				j16[t] = (uint16_t)jt, j8[t] = (uint8_t)jt;
			}
			if (m->wide)
				memcpy(o + m->attr[a++].off, j16, 8);
			else
				memcpy(o + m->attr[a++].off, j8, 4);
			memcpy(o + m->attr[a++].off, w8, 4);
		}
		for (int t = 0; t < m->ntargets; t++) {
			const float *d = p->targets[t].positions;
			int16_t s[4] = {0, 0, 0, 0};
			for (int c = 0; c < 3; c++) {
				float f = d && m->tscale[t] > 0.0f ? d[3 * v + c] / m->tscale[t] : 0.0f;
				f = f > 32767.0f ? 32767.0f : f < -32767.0f ? -32767.0f : f;
				s[c] = (int16_t)lrintf(f);
			}
			memcpy(o + m->attr[a++].off, s, 8);
		}
	}
}

static uint64_t vhash(const uint8_t *p, int n)
{
	uint64_t h = 1469598103934665603ull;
	for (int i = 0; i < n; i++)
		h = (h ^ p[i]) * 1099511628211ull;
	return h;
}

static int dbl_asc(const void *a, const void *b)
{
	double p = *(const double *)a, q = *(const double *)b;
	return p < q ? -1 : p > q;
}

/* The part's skinning scale at the rest pose: the largest singular value
 * bound (mlod_mat4_sigma_bound) of its skin's matrices (joint world times
 * inverse bind), or of its rigid matrix (joint world times offset, or
 * offset). */
static double part_sigma(const struct ctx *x, const struct mpart *m)
{
	const mlod_pack_part_rec *rec = &m->rec;
	const mlod_character *c = &x->v;
	if (m->skinned) {
		const mlod_skin *sk = &c->skeleton.skins[rec->skin];
		double s = 0.0;
		for (int j = 0; j < sk->joint_count; j++) {
			mlod_mat4 J = mlod_mat4_mul(&x->world[sk->joints[j]], &sk->inverse_bind[j]);
			double g = mlod_mat4_sigma_bound(&J);
			s = g > s ? g : s;
		}
		return s;
	}
	const mlod_instance *in = &c->instances[rec->instance];
	mlod_mat4 R = in->joint >= 0 ? mlod_mat4_mul(&x->world[in->joint], &in->offset) : in->offset;
	return mlod_mat4_sigma_bound(&R);
}

/* The q-th quantile (0 to 1, the lower of two) of n values, sorted in
 * place; 0 when n is 0. */
static double quantile(double *v, size_t n, double q)
{
	if (n == 0)
		return 0.0;
	qsort(v, n, sizeof *v, dbl_asc);
	size_t i = (size_t)(q * (double)(n - 1));
	return v[i];
}

/* The texture's density in UV units per mesh unit: the
 * MLOD_PACK_COARSE_UV_QUANTILE quantile over the primitive's edges of UV
 * length over length (those with both above 0). */
static double coarse_density(const mlod_primitive *p, int set, double *work)
{
	uint32_t ni = p->index_count > 0 ? (uint32_t)p->index_count : (uint32_t)p->vertex_count;
	size_t n = 0;
	for (uint32_t t = 0; t + 3 <= ni; t += 3)
		for (int e = 0; e < 3; e++) {
			uint32_t a = p->index_count > 0 ? p->indices[t + e] : t + e;
			uint32_t b = p->index_count > 0 ? p->indices[t + (e + 1) % 3] : t + (e + 1) % 3;
			double d = 0.0, u = 0.0;
			for (int c = 0; c < 3; c++) {
				double w = (double)p->positions[3 * a + c] - p->positions[3 * b + c];
				d += w * w;
			}
			for (int c = 0; c < 2; c++) {
				double w = (double)p->uvs[set][2 * a + c] - p->uvs[set][2 * b + c];
				u += w * w;
			}
			if (d > 0.0 && u > 0.0)
				work[n++] = sqrt(u / d);
		}
	return quantile(work, n, MLOD_PACK_COARSE_UV_QUANTILE);
}

/* The largest shift (0 to 15) whose steps, scale * 2^shift per axis of
 * n, stay within bound as a half-step vector, with every code of the
 * range [0, qmax] still rounding within 0 .. 65535. */
static int coarse_shift(const float *scale, const uint32_t *qmax, int n, double bound)
{
	int best = 0;
	for (int sh = 1; sh <= 15; sh++) {
		double h = 0.0;
		int fits = 1;
		for (int a = 0; a < n; a++) {
			double st = ldexp((double)scale[a], sh);
			h += st * st;
			fits &= qmax[a] + ldexp(1.0, sh - 1) + 1.0 <= 65535.0;
		}
		if (!fits || !(sqrt(h) / 2.0 <= bound))
			break;
		best = sh;
	}
	return best;
}

/* Per vertex of every level, the finest level that has it on level 0's
 * steps (the same quantised attributes), and per level f >= 1 the
 * position and UV shifts of the vertices whose finest level is f: within
 * the writer's share of the smallest TOC error of the levels f and
 * coarser, as mlod(5) QUANTISATION states. Nothing (every vertex on level
 * 0's steps) with a share of 0 or one level. 0, or -1
 * out of memory. */
static int part_coarse(struct ctx *x, struct mpart *m, int M)
{
	double share = x->opt->coarse_share;
	if (!(share > 0.0) || M < 2)
		return 0;
	size_t total = 0, most = 0;
	for (int k = 0; k < M; k++) {
		size_t nv = (size_t)m->lv[k]->vertex_count, ni = m->lv[k]->index_count > 0 ? (size_t)m->lv[k]->index_count : nv;
		total += nv;
		most = 3 * ni > most ? 3 * ni : most;
	}
	size_t cap = 16;
	while (cap < 2 * total + 2)
		cap *= 2;
	uint8_t *K = malloc(total * (size_t)m->stride + 1);
	uint32_t *slot = calloc(cap, sizeof *slot);
	uint8_t *lev = malloc(total + 1);
	double *work = malloc(sizeof *work * (most + 1));
	int ok = K && slot && lev && work;
	uint32_t count = 0;
	/* Level 0's steps: the finest level of each distinct key. */
	for (int k = 0; ok && k < M; k++) {
		const mlod_primitive *p = m->lv[k];
		uint8_t *V = malloc((size_t)p->vertex_count * (size_t)m->stride + 1);
		uint8_t *fk = malloc((size_t)p->vertex_count + 1);
		if (!V || !fk) {
			free(V), free(fk);
			ok = 0;
			break;
		}
		part_quantise(x, m, k, V); /* level 0's steps: fin[k] is still NULL */
		m->fin[k] = fk;
		for (int v = 0; v < p->vertex_count; v++) {
			const uint8_t *key = V + (size_t)v * (size_t)m->stride;
			size_t i = vhash(key, m->stride) & (cap - 1);
			while (slot[i] && memcmp(K + (size_t)(slot[i] - 1) * (size_t)m->stride, key, (size_t)m->stride) != 0)
				i = (i + 1) & (cap - 1);
			if (!slot[i]) {
				memcpy(K + (size_t)count * (size_t)m->stride, key, (size_t)m->stride);
				lev[count] = (uint8_t)k;
				slot[i] = ++count;
			}
			m->fin[k][v] = lev[slot[i] - 1];
		}
		free(V);
	}
	/* Each level's bounds (mesh units, UV units), then the
	 * smallest of them over it and the coarser levels. */
	double sigma = ok ? part_sigma(x, m) : 0.0;
	double bpos[MLOD_MESH_MAX_LEVELS + 1], buv[MLOD_MESH_MAX_LEVELS + 1][MLOD_PACK_MAX_UV];
	double rho[MLOD_PACK_MAX_UV] = {0};
	for (uint32_t s = 0; ok && s < m->rec.uv_sets; s++)
		rho[s] = coarse_density(m->lv[0], (int)s, work);
	for (int k = M - 1; ok && k >= 1; k--) {
		double e = share * (double)x->mesh_error[k - 1];
		if (!(e > 0.0) || !(sigma > 0.0) || !isfinite(e / sigma))
			e = 0.0;
		bpos[k] = sigma > 0.0 ? e / sigma : 0.0;
		for (uint32_t s = 0; s < m->rec.uv_sets; s++)
			buv[k][s] = e * rho[s] / (sigma > 0.0 ? sigma : 1.0);
		if (k < M - 1) {
			bpos[k] = fmin(bpos[k], bpos[k + 1]);
			for (uint32_t s = 0; s < m->rec.uv_sets; s++)
				buv[k][s] = fmin(buv[k][s], buv[k + 1][s]);
		}
	}
	for (int k = 1; ok && k < M; k++) {
		uint32_t qmax[3];
		for (int a = 0; a < 3; a++) {
			float hi = m->rec.pos_min[a];
			for (int j = 0; j < M; j++)
				for (int v = 0; v < m->lv[j]->vertex_count; v++)
					hi = fmaxf(hi, m->lv[j]->positions[3 * v + a]);
			qmax[a] = mlod_pack_qu16(hi, m->rec.pos_min[a], m->rec.pos_scale[a]);
		}
		m->pos_shift[k] = coarse_shift(m->rec.pos_scale, qmax, 3, bpos[k]);
		for (uint32_t s = 0; s < m->rec.uv_sets; s++) {
			uint32_t umax[2];
			for (int a = 0; a < 2; a++) {
				float hi = m->rec.uv_min[s][a];
				for (int j = 0; j < M; j++)
					for (int v = 0; v < m->lv[j]->vertex_count; v++)
						hi = fmaxf(hi, m->lv[j]->uvs[s][2 * v + a]);
				umax[a] = mlod_pack_qu16(hi, m->rec.uv_min[s][a], m->rec.uv_scale[s][a]);
			}
			m->uv_shift[k][s] = coarse_shift(m->rec.uv_scale[s], umax, 2, buv[k][s]);
		}
	}
	free(K), free(slot), free(lev), free(work);
	return ok ? 0 : -1;
}

/* The id of vertex key in the part's buffer, appending it when new. */
static uint32_t part_vertex(struct mpart *m, const uint8_t *key)
{
	size_t i = vhash(key, m->stride) & (m->slot_cap - 1);
	while (m->slot[i]) {
		uint32_t id = m->slot[i] - 1;
		if (memcmp(m->G + (size_t)id * (size_t)m->stride, key, (size_t)m->stride) == 0)
			return id;
		i = (i + 1) & (m->slot_cap - 1);
	}
	memcpy(m->G + (size_t)m->count * (size_t)m->stride, key, (size_t)m->stride);
	m->slot[i] = ++m->count;
	return m->count - 1;
}

/* Appends level V's vertices not yet in the buffer that its triangles in
 * use, in order o of the triangles (mlod_pack_vertex_order); the level's
 * indices into the buffer, or NULL when out of memory. With cls (each vertex of V: its
 * buffer id as the hash set gave it, or for a vertex the buffer lacked,
 * count + the first of its bit-identical copies in V), the same without
 * the hash set, which it leaves as it was (for trying orders). */
static uint32_t *part_append(struct mpart *m, const uint8_t *V, const uint32_t *in, uint32_t ni, uint32_t nv,
                             const float *positions, int o, mlod_pack_order_memo *memo, const uint32_t *cls)
{
	uint32_t *remap = malloc(sizeof *remap * ((size_t)nv + 1));
	uint32_t *inv = malloc(sizeof *inv * ((size_t)nv + 1));
	uint32_t *out = malloc(sizeof *out * ((size_t)ni + 1));
	uint32_t *gid = malloc(sizeof *gid * ((size_t)nv + 1));
	uint32_t *idx = malloc(sizeof *idx * ((size_t)ni + 1));
	uint8_t *used = calloc((size_t)nv + 1, 1);
	if (!remap || !inv || !out || !gid || !idx || !used ||
	    mlod_pack_vertex_order_memo(o, in, ni, nv, positions, memo, remap, out) != 0) {
		free(remap), free(inv), free(out), free(gid), free(idx), free(used);
		return NULL;
	}
	for (uint32_t v = 0; v < nv; v++)
		inv[remap[v]] = v;
	for (uint32_t t = 0; t < ni; t++) /* a vertex only dropped triangles used: not stored */
		used[in[t]] = 1;
	if (cls) { /* remap becomes each new class's id: UINT32_MAX until placed */
		uint32_t count0 = m->count;
		for (uint32_t v = 0; v < nv; v++)
			remap[v] = UINT32_MAX;
		for (uint32_t j = 0; j < nv; j++) {
			uint32_t c = cls[inv[j]];
			if (!used[inv[j]])
				continue;
			if (c < count0) {
				gid[j] = c;
				continue;
			}
			if (remap[c - count0] == UINT32_MAX) {
				memcpy(m->G + (size_t)m->count * (size_t)m->stride, V + (size_t)inv[j] * (size_t)m->stride,
				       (size_t)m->stride);
				remap[c - count0] = m->count++;
			}
			gid[j] = remap[c - count0];
		}
	} else {
		for (uint32_t j = 0; j < nv; j++)
			if (used[inv[j]])
				gid[j] = part_vertex(m, V + (size_t)inv[j] * (size_t)m->stride);
	}
	for (uint32_t t = 0; t < ni; t++)
		idx[t] = gid[out[t]];
	free(remap), free(inv), free(out), free(gid), free(used);
	return idx;
}

/* The level's own numbering of its indices idx (ni of them, into a prefix
 * of count vertices): its vertices in first-use order into map (the prefix
 * vertex of each; *nused of them) and the renumbered indices into local.
 * seen is count zeroed u32s, left zeroed. */
static void local_form(const uint32_t *idx, uint32_t ni, uint32_t *seen, uint32_t *map, uint32_t *nused,
                       uint32_t *local)
{
	uint32_t n = 0;
	for (uint32_t t = 0; t < ni; t++) {
		if (!seen[idx[t]])
			map[n] = idx[t], seen[idx[t]] = ++n;
		local[t] = seen[idx[t]] - 1;
	}
	for (uint32_t v = 0; v < n; v++)
		seen[map[v]] = 0;
	*nused = n;
}

/* The level's own numbering in the stored form (MLOD_PART_LOCAL): from
 * local_form's map (nused vertices), the words of 'INEW' (bit v set:
 * vertex v is the next of the level's block, which starts at count0) and
 * the prefix vertices of the others ('IMAP', *nold of them). Without
 * split, or when the block's vertices are not in the order the level
 * first uses them, no bit is set and 'IMAP' lists every vertex; returns
 * whether bits were set. */
static int local_split(const uint32_t *map, uint32_t nused, uint32_t count0, int split, uint32_t *words, uint32_t *old,
                       uint32_t *nold)
{
	uint32_t nn = 0, no = 0;
	memset(words, 0, sizeof *words * (((size_t)nused + 31) / 32));
	if (!split)
		count0 = UINT32_MAX;
	for (uint32_t v = 0; v < nused; v++) {
		if (map[v] < count0) {
			old[no++] = map[v];
			continue;
		}
		if (map[v] != count0 + nn) { /* out of order: list them all */
			memset(words, 0, sizeof *words * (((size_t)nused + 31) / 32));
			memcpy(old, map, sizeof *old * nused);
			*nold = nused;
			return 0;
		}
		nn++;
		words[v / 32] |= 1u << (v % 32);
	}
	*nold = no;
	return split;
}

/* Adds an index stream of n u32s as u16 when wide is 0. */
static void add_index_stream(chunkb *cb, uint32_t tag, const uint32_t *v, uint32_t n, int wide, int index)
{
	if (wide) {
		pack_cb_add(cb, tag, n, 4, v, index);
		return;
	}
	uint16_t *i16 = malloc(sizeof *i16 * ((size_t)n + 1));
	if (!i16) {
		cb->fail = 1;
		return;
	}
	for (uint32_t i = 0; i < n; i++)
		i16[i] = (uint16_t)v[i];
	pack_cb_add(cb, tag, n, 2, i16, index);
	free(i16);
}

/* Adds the streams of the part's block (vertices first .. count - 1 of
 * the buffer) and of its level's indices, in the chunk's stream order:
 * with local, 'INEW' (nwords words; none when words is NULL), 'IMAP'
 * (old, nold of them) and 'IDX ' in the level's own numbering (idx then
 * holds those). */
static void part_block_streams(chunkb *cb, const struct mpart *m, uint32_t first, const uint32_t *idx, uint32_t ni,
                               int local, const uint32_t *words, uint32_t nwords, const uint32_t *old, uint32_t nold)
{
	uint32_t n = m->count - first;
	uint8_t *s = malloc((size_t)n * 8 + 8);
	if (!s) {
		cb->fail = 1;
		return;
	}
	int plain = m->nattr - m->ntargets, wide = m->count > 65536;
	for (int a = 0; a <= m->nattr; a++) {
		if (a == plain) { /* the indices, then the targets' scales */
			if (local) {
				if (words)
					pack_cb_add(cb, MLOD_STREAM_INEW, nwords, 4, words, 0);
				add_index_stream(cb, MLOD_STREAM_IMAP, old, nold, wide, 2);
			}
			add_index_stream(cb, MLOD_STREAM_IDX, idx, ni, wide, 1);
			if (m->ntargets)
				pack_cb_add(cb, MLOD_STREAM_MTSC, (uint32_t)m->ntargets, 4, m->tscale, 0);
		}
		if (a == m->nattr)
			break;
		const mattr *at = &m->attr[a];
		for (uint32_t v = 0; v < n; v++)
			memcpy(s + (size_t)v * at->size, m->G + (size_t)(first + v) * (size_t)m->stride + at->off, at->size);
		pack_cb_add(cb, at->tag, n, at->size, s, 0);
	}
	free(s);
}

void pack_mesh_parts_free(struct ctx *x)
{
	for (int i = 0; i < x->mp_count; i++) {
		struct mpart *m = &x->mp[i];
		free(m->tscale), free(m->attr), free(m->G), free(m->slot);
		for (int k = 0; k <= MLOD_MESH_MAX_LEVELS; k++)
			free(m->fin[k]);
	}
	free(x->mp);
	x->mp = NULL;
	x->mp_count = 0;
	for (int i = 0; i < x->lmap_count; i++)
		free(x->lmaps[i]);
	free(x->lmaps);
	x->lmaps = NULL;
	x->lmap_count = 0;
}

/* Maps the joints of a level skin (input skin `lsk`) to the full skin
 * `fsk`: the same joint, else the first joint of the full skin that the
 * level joint stands in for (its nearest ancestor in the level skin). */
int *pack_level_joint_map(const mlod_skeleton *s, const mlod_skin *lsk, const mlod_skin *fsk)
{
	int *map = malloc(sizeof(int) * ((size_t)lsk->joint_count + 1));
	if (!map)
		return NULL;
	for (int q = 0; q < lsk->joint_count; q++) {
		int j = lsk->joints[q], at = -1;
		for (int t = 0; t < fsk->joint_count && at < 0; t++)
			if (fsk->joints[t] == j)
				at = t;
		for (int t = 0; t < fsk->joint_count && at < 0; t++) {
			int a = fsk->joints[t];
			int in_level = 0;
			for (int u = 0; u < lsk->joint_count; u++)
				in_level |= lsk->joints[u] == a;
			if (in_level)
				continue;
			while (a >= 0 && a != j) {
				int p = s->joints[a].parent, in = 0;
				for (int u = 0; p >= 0 && u < lsk->joint_count; u++)
					in |= lsk->joints[u] == p;
				a = p;
				if (in && p != j)
					a = -1; /* a nearer level joint stands in for it */
			}
			if (a == j)
				at = t;
		}
		map[q] = at >= 0 ? at : 0;
	}
	return map;
}

/* The parts (level 0's triangle primitives of every instance) with their
 * level primitives, attributes, grids and buffers. Every level of a part
 * must have triangles and the attributes level 0 has. */
static mlod_result mesh_parts(struct ctx *x, int M)
{
	const mlod_character *c = &x->v;
	mlod_result r = MLOD_OK;
	int cap = 0;
	x->lmap_count = c->instance_count * M;
	x->lmaps = calloc((size_t)x->lmap_count + 1, sizeof *x->lmaps);
	if (!x->lmaps)
		return mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
	for (int i = 0; i < c->instance_count; i++) {
		const mlod_instance *in = &c->instances[i];
		const mlod_mesh *m = &c->meshes[in->mesh];
		const mlod_mesh *lm[MLOD_MESH_MAX_LEVELS + 1];
		int lmap_count[MLOD_MESH_MAX_LEVELS + 1] = {0};
		for (int k = 0; k < M; k++) {
			lm[k] = m;
			if (k > 0 && x->level_mesh[k - 1]) {
				lm[k] = &x->level_mesh[k - 1][i];
			} else if (k > 0 && x->level_node[k - 1] && x->level_node[k - 1][i] >= 0) {
				int gm = -1, gs = -1;
				if ((r = mlod_gltf_node_refs(x->doc, x->level_node[k - 1][i], &gm, &gs, x->err)) != MLOD_OK)
					return r;
				int mi = pack_mesh_of_gltf(x->in, gm);
				if (mi < 0)
					return mlod_fail(x->err, MLOD_ERR_PARSE, "mesh level %d of node %d: its mesh %d was not read", k,
					                 in->node, gm);
				lm[k] = &x->in->meshes[mi];
				int ls = pack_skin_of_gltf(&x->in->skeleton, gs);
				if (in->skin >= 0 && ls >= 0 && x->view_skin[ls] != in->skin) {
					int **mp = &x->lmaps[k * c->instance_count + i];
					*mp = pack_level_joint_map(&c->skeleton, &x->in->skeleton.skins[ls], &c->skeleton.skins[in->skin]);
					if (!*mp)
						return mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
					lmap_count[k] = x->in->skeleton.skins[ls].joint_count;
				}
			}
		}
		for (int p = 0; p < m->primitive_count; p++) {
			const mlod_primitive *p0 = &m->primitives[p];
			if (p0->mode != 4 || p0->vertex_count <= 0)
				continue;
			if (x->mp_count == cap) {
				cap = cap ? 2 * cap : 16;
				struct mpart *q = realloc(x->mp, sizeof *q * (size_t)cap);
				if (!q)
					return mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
				x->mp = q;
			}
			struct mpart *pt = &x->mp[x->mp_count++];
			memset(pt, 0, sizeof *pt);
			size_t total = 0;
			for (int k = 0; k < M; k++) {
				const mlod_primitive *pr = p < lm[k]->primitive_count ? &lm[k]->primitives[p] : NULL;
				if (!pr || pr->mode != 4 || pr->vertex_count <= 0)
					return mlod_fail(x->err, MLOD_ERR_UNSUPPORTED,
					                 "mesh level %d of node %d: primitive %d has no triangles (every level of a "
					                 "part needs some)",
					                 k, in->node, p);
				if (prim_signature(pr, in->skin) != prim_signature(p0, in->skin))
					return mlod_fail(x->err, MLOD_ERR_UNSUPPORTED,
					                 "mesh level %d of node %d: primitive %d has other attributes than level 0 "
					                 "(normals, tangents, UV sets, colours, weights or morph targets); the "
					                 "pack stores a part's levels with one set",
					                 k, in->node, p);
				pt->lv[k] = pr;
				pt->jmap[k] = x->lmaps[k * c->instance_count + i];
				pt->jmap_count[k] = lmap_count[k];
				total += (size_t)pr->vertex_count;
			}
			mlod_pack_part_rec *rec = &pt->rec;
			rec->instance = (uint32_t)i;
			rec->node = in->node;
			rec->mesh = m->gltf_index;
			rec->primitive = (uint32_t)p;
			rec->skin = in->skin;
			rec->joint = in->joint;
			rec->material = p0->material;
			memcpy(rec->offset, in->offset.m, sizeof rec->offset);
			rec->uv_sets = (uint32_t)(p0->uv_set_count < MLOD_PACK_MAX_UV ? p0->uv_set_count : MLOD_PACK_MAX_UV);
			rec->target_count = (uint32_t)p0->target_count;
			pt->skinned = in->skin >= 0 && p0->weight_set_count > 0;
			pt->wide = pt->skinned && c->skeleton.skins[in->skin].joint_count > 256;
			pt->ntargets = p0->target_count;
			rec->flags = (p0->normals ? MLOD_PART_NORMALS : 0) | (p0->tangents ? MLOD_PART_TANGENTS : 0) |
			             (p0->color_set_count > 0 ? MLOD_PART_COLORS : 0) | (pt->skinned ? MLOD_PART_SKINNED : 0) |
			             (pt->wide ? MLOD_PART_JOINTS16 : 0);
			pt->attr = malloc(sizeof *pt->attr * (size_t)(8 + MLOD_PACK_MAX_UV + pt->ntargets));
			pt->tscale = malloc(sizeof(float) * ((size_t)pt->ntargets + 1));
			if (!pt->attr || !pt->tscale)
				return mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
#define ATTR(t, s) (pt->attr[pt->nattr++] = (mattr){(t), (s), pt->stride}, pt->stride += (s))
			ATTR(MLOD_STREAM_POSQ, 8);
			if (p0->normals)
				ATTR(MLOD_STREAM_NRMQ, 4);
			if (p0->tangents)
				ATTR(MLOD_STREAM_TANQ, 8);
			for (uint32_t s = 0; s < rec->uv_sets; s++)
				ATTR(MLOD_STREAM_UVQ0 + (s << 24), 4);
			if (p0->color_set_count > 0)
				ATTR(MLOD_STREAM_COLQ, 4);
			if (pt->skinned) {
				if (pt->wide)
					ATTR(MLOD_STREAM_JN16, 8);
				else
					ATTR(MLOD_STREAM_JNT8, 4);
				ATTR(MLOD_STREAM_WGT8, 4);
			}
			for (int t = 0; t < pt->ntargets; t++)
				ATTR(MLOD_STREAM_MTPQ, 8);
#undef ATTR
			part_grid(x, pt, M);
			if (part_coarse(x, pt, M) != 0)
				return mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
			pt->slot_cap = 16;
			while (pt->slot_cap < 2 * total + 2)
				pt->slot_cap *= 2;
			pt->G = malloc(total * (size_t)pt->stride + 1);
			pt->slot = calloc(pt->slot_cap, sizeof *pt->slot);
			if (!pt->G || !pt->slot)
				return mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
		}
	}
	return MLOD_OK;
}

/* A level's index forms (mlod(5) MESH levels): its indices as they are,
 * or in its own numbering (MLOD_PART_LOCAL); the working arrays as
 * local_form and local_split take them. */
typedef struct iforms {
	uint32_t *seen, *map, *lidx, *words, *old;
	uint32_t nused, nold;
	int split; /* the local form has 'INEW' */
} iforms;

/* The coded bytes of a level's indices idx (into a prefix of count
 * vertices, the level's block from count0) in the smaller of the forms,
 * with 16 for each stream beyond 'IDX ' (*stored: without them); *local
 * 1 when that is the level's own numbering (f then holds it). */
static size_t index_bytes(const uint32_t *idx, uint32_t ni, uint32_t count0, uint32_t count, iforms *f, int *local,
                          size_t *stored)
{
	int wide = count > 65536;
	chunkb t = {0};
	add_index_stream(&t, MLOD_STREAM_IDX, idx, ni, wide, 1);
	size_t g = t.fail ? 0 : pack_stream_coded_bytes(&t.s[0]), best[2] = {g, g};
	local_form(idx, ni, f->seen, f->map, &f->nused, f->lidx);
	add_index_stream(&t, MLOD_STREAM_IDX, f->lidx, ni, wide, 1);
	size_t li = t.fail ? 0 : pack_stream_coded_bytes(&t.s[1]);
	for (int split = 1; split >= 0 && !t.fail; split--) { /* with the bits, then without */
		if (!local_split(f->map, f->nused, count0, split, f->words, f->old, &f->nold) && split)
			continue;
		if (split)
			pack_cb_add(&t, MLOD_STREAM_INEW, (f->nused + 31) / 32, 4, f->words, 0);
		add_index_stream(&t, MLOD_STREAM_IMAP, f->old, f->nold, wide, 2);
		/* the streams beyond 'IDX ': their 16-byte headers count */
		best[split] = t.fail ? g : 16 * (size_t)(1 + split) + li + pack_stream_coded_bytes(&t.s[t.n - 1]) +
		                                   (split ? pack_stream_coded_bytes(&t.s[t.n - 2]) : 0);
	}
	pack_cb_free(&t);
	int split = best[1] < best[0];
	size_t l = best[split];
	*local = l < g;
	f->split = *local && split;
	if (*local) /* f holds the form chosen */
		local_split(f->map, f->nused, count0, split, f->words, f->old, &f->nold);
	*stored = *local ? l - 16 * (size_t)(1 + split) : g;
	return l < g ? l : g;
}

size_t mlod_pack_index_cost(const uint32_t *idx, uint32_t ni, uint32_t count0, uint32_t count, size_t *stored)
{
	iforms f = {0};
	size_t cost = 0;
	int local;
	*stored = 0;
	f.seen = calloc((size_t)count + 1, sizeof *f.seen);
	f.map = malloc(sizeof *f.map * ((size_t)ni + 1));
	f.lidx = malloc(sizeof *f.lidx * ((size_t)ni + 1));
	f.words = malloc(sizeof *f.words * ((size_t)ni / 32 + 2));
	f.old = malloc(sizeof *f.old * ((size_t)ni + 1));
	if (f.seen && f.map && f.lidx && f.words && f.old)
		cost = index_bytes(idx, ni, count0, count, &f, &local, stored);
	free(f.seen), free(f.map), free(f.lidx), free(f.words), free(f.old);
	return cost;
}

/* Draco's speed option (0 smallest .. 10 fastest), for encoding and decoding. */
#ifndef MLOD_PACK_DRACO_SPEED
#define MLOD_PACK_DRACO_SPEED 0
#endif

/* Codec draco (mlod(5)): level k of a part as one Draco mesh of its own
 * (layout a: the nused vertices map[] of the part's buffer, in that
 * numbering, and the triangles lidx), every attribute the stream's
 * quantised integers (lossless), coded by edgebreaker; the sequential
 * coder where edgebreaker does not give back exactly nused vertices and
 * ni / 3 triangles (it splits non-manifold vertices and drops degenerate
 * triangles), which the reader requires. Adds 'DRCO', then 'MTSC' with
 * morph targets. 0 on failure (x->draco_fail and the message set, or out
 * of memory: cb->fail). */
static int draco_level(struct ctx *x, chunkb *cb, const struct mpart *m, const uint32_t *map, uint32_t nused,
                       const uint32_t *lidx, uint32_t ni)
{
	mlod_draco_attr at[8 + MLOD_PACK_MAX_UV + 256];
	int na = m->nattr, ok = 0;
	if (nused == 0 && ni == 0 && m->ntargets <= 256) { /* no triangle left: an empty 'DRCO' */
		pack_cb_add(cb, MLOD_STREAM_DRCO, 0, 1, NULL, 0);
		if (m->ntargets)
			pack_cb_add(cb, MLOD_STREAM_MTSC, (uint32_t)m->ntargets, 4, m->tscale, 0);
		return !cb->fail;
	}
	if (nused == 0 || ni == 0 || na > (int)(sizeof at / sizeof at[0])) {
		x->draco_fail = mlod_fail(x->err, MLOD_ERR_UNSUPPORTED,
		                          "codec draco: a part of %u vertices, %u indices and %d attributes (Draco parts "
		                          "need triangles and at most 256 morph targets)",
		                          nused, ni, m->ntargets);
		return 0;
	}
	memset(at, 0, sizeof at);
	for (int a = 0; a < na; a++) {
		const mattr *ma = &m->attr[a];
		int bytes = 2, comps;
		if (ma->size == 8)
			comps = ma->tag == MLOD_STREAM_POSQ || ma->tag == MLOD_STREAM_MTPQ ? 3 : 4;
		else if (ma->tag == MLOD_STREAM_COLQ || ma->tag == MLOD_STREAM_JNT8 || ma->tag == MLOD_STREAM_WGT8)
			bytes = 1, comps = 4;
		else
			comps = 2;
		at[a].kind = ma->tag == MLOD_STREAM_POSQ ? MLOD_DRACO_POSITION : MLOD_DRACO_GENERIC;
		at[a].type = bytes == 1 ? MLOD_DRACO_U8 : MLOD_DRACO_U16;
		at[a].components = comps;
		uint8_t *d = malloc((size_t)nused * (size_t)(comps * bytes) + 1);
		if (!d)
			goto done;
		for (uint32_t v = 0; v < nused; v++)
			memcpy(d + (size_t)v * (size_t)(comps * bytes), m->G + (size_t)map[v] * (size_t)m->stride + ma->off,
			       (size_t)(comps * bytes));
		at[a].data = d;
	}
	for (int sequential = 0; sequential < 2 && !ok; sequential++) {
		void *enc = NULL;
		size_t size = 0;
		mlod_error e2;
		mlod_result r = mlod_draco_encode((int)nused, at, na, lidx, (int)ni, sequential, MLOD_PACK_DRACO_SPEED, &enc,
		                                  &size, &e2);
		if (r == MLOD_ERR_NOMEM)
			goto done;
		if (r != MLOD_OK)
			continue;
		/* What the reader checks: exactly these counts back. */
		mlod_draco_attr back[8 + MLOD_PACK_MAX_UV + 256];
		memcpy(back, at, sizeof(mlod_draco_attr) * (size_t)na);
		int bv = 0, bi = 0;
		uint32_t *bix = NULL;
		r = mlod_draco_decode(enc, size, back, na, &bv, &bix, &bi, &e2);
		if (r == MLOD_OK) {
			for (int a = 0; a < na; a++)
				mlod_free(back[a].data);
			mlod_free(bix);
		}
		if (r == MLOD_OK && bv == (int)nused && bi == (int)ni) {
			pack_cb_add(cb, MLOD_STREAM_DRCO, (uint32_t)size, 1, enc, 0);
			if (m->ntargets)
				pack_cb_add(cb, MLOD_STREAM_MTSC, (uint32_t)m->ntargets, 4, m->tscale, 0);
			ok = 1;
		}
		mlod_free(enc);
		if (r == MLOD_ERR_NOMEM)
			goto done;
	}
	if (!ok)
		x->draco_fail = mlod_fail(x->err, MLOD_ERR_UNSUPPORTED,
		                          "codec draco: a part of %u vertices and %u triangles does not come back from Draco "
		                          "with those counts, by edgebreaker or the sequential coder",
		                          nused, ni / 3);
done:
	for (int a = 0; a < na; a++)
		free(at[a].data);
	if (!ok && !x->draco_fail)
		cb->fail = 1;
	return ok;
}

/* Level k of one part: appends its new vertices (in the order of the
 * writer's that codes the block and the indices to the fewest bytes; the
 * input order with codec none) and adds their streams, with the indices
 * in the level's own numbering when that codes smaller (MLOD_PART_LOCAL);
 * rec is the part's record at this level. */
static int part_level(struct ctx *x, chunkb *cb, struct mpart *m, int k, mlod_pack_part_rec *rec)
{
	const mlod_primitive *p = m->lv[k];
	uint32_t nv = (uint32_t)p->vertex_count;
	uint32_t ni = p->index_count > 0 ? (uint32_t)p->index_count : nv;
	ni -= ni % 3;
	uint8_t *V = malloc((size_t)nv * (size_t)m->stride + 1);
	uint32_t *in = malloc(sizeof *in * ((size_t)ni + 1));
	uint32_t *saved = malloc(sizeof *saved * m->slot_cap);
	iforms f = {0};
	mlod_pack_order_memo memo = {{NULL, NULL, NULL}}; /* the triangle orders the vertex orders share */
	f.seen = calloc((size_t)m->count + nv + 1, sizeof *f.seen);
	f.map = malloc(sizeof *f.map * ((size_t)ni + 1));
	f.lidx = malloc(sizeof *f.lidx * ((size_t)ni + 1));
	f.words = malloc(sizeof *f.words * ((size_t)ni / 32 + 2));
	f.old = malloc(sizeof *f.old * ((size_t)ni + 1));
	uint32_t *idx = NULL, *cls = NULL;
	int ok = 0, local = 0;
	if (!V || !in || !saved || !f.seen || !f.map || !f.lidx || !f.words || !f.old)
		goto done;
	part_quantise(x, m, k, V);
	uint32_t count0 = m->count;
	int best = 0;
	/* Each vertex's class once (part_append's cls), the hash set then as
	 * it was: the orders tried need no hashing. */
	memcpy(saved, m->slot, sizeof *saved * m->slot_cap);
	if (!(cls = malloc(sizeof *cls * ((size_t)nv + 1))))
		goto done;
	for (uint32_t v = 0; v < nv; v++)
		cls[v] = part_vertex(m, V + (size_t)v * (size_t)m->stride);
	memcpy(m->slot, saved, sizeof *saved * m->slot_cap);
	m->count = count0;
	/* The triangles quantisation leaves: one whose corners are two or
	 * three times one vertex of the buffer (bit-identical quantised
	 * attributes) is dropped, as is one repeating an index of its own
	 * (the input's: counted apart); a part may keep none at a level. */
	uint32_t kept = 0, repeated = 0;
	for (uint32_t t = 0; t + 3 <= ni; t += 3) {
		uint32_t a = p->index_count > 0 ? p->indices[t] : t, b = p->index_count > 0 ? p->indices[t + 1] : t + 1,
		         c = p->index_count > 0 ? p->indices[t + 2] : t + 2;
		if (a == b || b == c || a == c) {
			repeated++;
			continue;
		}
		if (cls[a] == cls[b] || cls[b] == cls[c] || cls[a] == cls[c])
			continue;
		in[kept++] = a, in[kept++] = b, in[kept++] = c;
	}
	x->repeated[k] += repeated;
	x->degenerate[k] += (ni - kept) / 3 - repeated;
	x->emptied[k] += ni > 0 && kept == 0;
	ni = kept;
	if (x->opt->codec == MLOD_CODEC_MESHOPT && !x->draco) {
		size_t best_bytes = 0;
		for (int o = 0; o < MLOD_PACK_ORDERS; o++) {
			uint32_t *ix = part_append(m, V, in, ni, nv, p->positions, o, &memo, cls);
			if (!ix)
				goto done;
			int from = cb->n, loc;
			size_t st;
			part_block_streams(cb, m, count0, ix, 0, 0, NULL, 0, NULL, 0); /* the vertex streams (no indices) */
			size_t b = cb->fail ? 0
			                    : pack_cb_coded_bytes(cb, from) + index_bytes(ix, ni, count0, m->count, &f, &loc, &st);
			while (cb->n > from)
				free(cb->s[--cb->n].data);
			free(ix);
			if (o == 0 || b < best_bytes)
				best = o, best_bytes = b;
			m->count = count0;
		}
	}
	if (!(idx = part_append(m, V, in, ni, nv, p->positions, best, &memo, NULL)))
		goto done;
	/* The vertices the level uses: what a reader gathers from the prefix. */
	size_t st;
	if (x->draco) {
		local_form(idx, ni, f.seen, f.map, &f.nused, f.lidx);
		if (!draco_level(x, cb, m, f.map, f.nused, f.lidx, ni))
			goto done;
		*rec = m->rec;
		rec->vertex_count = f.nused;
		rec->index_count = ni;
		ok = 1;
		goto done;
	}
	if (x->opt->codec == MLOD_CODEC_MESHOPT)
		index_bytes(idx, ni, count0, m->count, &f, &local, &st);
	else
		local_form(idx, ni, f.seen, f.map, &f.nused, f.lidx);
	part_block_streams(cb, m, count0, local ? f.lidx : idx, ni, local, f.split ? f.words : NULL, (f.nused + 31) / 32,
	                   f.old, f.nold);
	*rec = m->rec;
	rec->vertex_count = f.nused;
	rec->index_count = ni;
	if (m->count <= 65536)
		rec->flags |= MLOD_PART_INDEX16;
	if (local)
		rec->flags |= MLOD_PART_LOCAL | (f.split ? MLOD_PART_NEWBITS : 0);
	ok = 1;
done:
	free(V), free(in), free(saved), free(idx), free(f.seen), free(f.map), free(f.lidx), free(f.words), free(f.old);
	mlod_pack_order_memo_free(&memo);
	free(cls);
	return ok;
}

mlod_result pack_mesh_chunk(struct ctx *x, int k, chunks *out, int *part_count)
{
	chunkb cb = {0};
	mlod_result r = MLOD_OK;
	if (!x->mp_ready) { /* the coarsest level comes first */
		if ((r = mesh_parts(x, k + 1)) != MLOD_OK)
			return r;
		x->mp_ready = 1;
	}
	int np = x->mp_count;
	mlod_pack_part_rec *recs = malloc(sizeof *recs * ((size_t)np + 1));
	if (!recs)
		return mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
	/* PART first: its records are complete once the streams are made. */
	pack_cb_add(&cb, MLOD_STREAM_PART, 0, sizeof(mlod_pack_part_rec), NULL, 0);
	for (int i = 0; i < np && !cb.fail; i++)
		if (!part_level(x, &cb, &x->mp[i], k, &recs[i]))
			cb.fail = 1;
	if (!cb.fail) {
		/* the level's vertices as a reader decodes them: its records' */
		uint64_t nv = 0;
		for (int i = 0; i < np; i++)
			nv += recs[i].vertex_count;
		if (nv > x->max_vertices)
			x->max_vertices = nv;
		free(cb.s[0].data);
		cb.s[0].data = (uint8_t *)recs;
		cb.s[0].count = (uint32_t)np;
		recs = NULL;
	}
	free(recs);
	*part_count = np;
	if (!cb.fail && x->repeated[k]) { /* the input's own, which draw nothing */
		char text[128];
		snprintf(text, sizeof text, "mesh level %d: %u triangles that repeat a vertex (no area) not stored", k,
		         x->repeated[k]);
		pack_note(x, text);
	}
	if (!cb.fail && x->degenerate[k]) {
		char text[160], parts[64] = "";
		if (x->emptied[k])
			snprintf(parts, sizeof parts, " (parts left without a triangle: %d)", x->emptied[k]);
		snprintf(text, sizeof text, "mesh level %d: %u triangles quantisation made degenerate dropped%s", k,
		         x->degenerate[k], parts);
		pack_note(x, text);
	}
	if (x->draco && x->draco_fail) {
		pack_cb_free(&cb);
		return x->draco_fail;
	}
	return pack_cb_finish(&cb, x->draco ? MLOD_CODEC_DRACO : x->opt->codec, out, MLOD_CHUNK_MESH, MLOD_LAYER_MESH, k, 0,
	                      k > 0 ? x->mesh_error[k - 1] : 0.0f,
	                      x->err);
}
