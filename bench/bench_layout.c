/*
 * bench_layout: mesh level layouts of the pack, measured side by side
 * (issue 11: "measure at least two layouts and document the choice").
 *
 *   bench_layout [-c] FILE.glb ...
 *
 * The mesh levels are computed as mlod-pack computes them with its
 * defaults (mlod-bgm's ratios 0.5 0.25 0.1). Each part (a triangle
 * primitive of an instance) is quantised as the writer does (mlod(5)
 * QUANTISATION: positions at 14 bits of a box, octahedral normals at 8
 * bits, UVs at 12 bits of a range, tangents, colours, joints u8/u16 and
 * weights u8, morph target deltas) and its streams coded with meshopt
 * 0.18, each padded to 4 bytes as stored. Two layouts:
 *
 *   (a) what the pack stored up to format 1.x: each level of each part its
 *       own vertex and index streams, quantised to that level's own box,
 *       in the best of the writer's ten orders (mlod_pack_vertex_order).
 *   (b) per part one vertex buffer: the coarsest level's vertices, then
 *       each finer level's vertices that are not bit-identical (all
 *       quantised attributes) to one already in the buffer, appended in
 *       level order; one index buffer per level into that prefix. All
 *       levels of a part share one grid, the writer's: the union of the
 *       levels' boxes at level 0's steps, or at the union's 16-bit steps
 *       where it is wider than 65535 of them (positions, UVs; morph
 *       deltas: the largest |delta| of any level).
 *       Within a level's appended block the vertices follow one of the
 *       writer's ten orders applied to that level's triangles, chosen
 *       level by level, coarsest first: the one that codes the block and
 *       the level's indices to the fewest bytes. Coded two ways: b1 the
 *       whole buffer as one meshopt vertex stream per attribute (a reader
 *       must have every level before it can decode any), b2 each level's
 *       appended block as its own streams (streamable coarse to fine, as
 *       the pack's chunks are). b2 is what the pack stores since format
 *       2.0 (mlod(5) MESH levels), with each level's indices in the
 *       writer's form (format 3.0: the level's own numbering and its map
 *       where that codes smaller, mlod_pack_index_cost): checked against
 *       the MESH chunks mlod_pack_write makes of the same input (their
 *       streams but 'PART', same padding), the two must agree (the
 *       writer with coarse_share 0: (b) puts every vertex on level 0's
 *       steps, where the pack rounds a vertex only coarse levels have to
 *       coarser ones, mlod(5) QUANTISATION).
 *
 * Per input: stream bytes of (a), of (a) quantised on (b)'s grid (what
 * the grid alone changes), b1 and b2; unique vertices of (b)
 * against the sum of the levels' vertices; the decode of the whole mesh
 * (every level) through meshopt, best of 51 runs in thread CPU time, as
 * microseconds and as MB/s of decoded (quantised) bytes; and per level
 * the vertices a runtime skinning the level's whole prefix in (b) skins
 * beyond those the level uses, as a % of the level's vertices in (a);
 * and the other way for a runtime that wants (a)'s buffers: expanding
 * (b) to per-level buffers at load (gather the vertices each level's
 * indices use from the decoded prefix, rewrite the indices), best of 51
 * in thread CPU time, on top of the decode. With -c, also (c) estimated:
 * the coarsest level plus the recorded vertex splits (layout_c says how).
 */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <meshoptimizer.h>

#include "bench.h"
#include "mlod.h"
#include "rt/mlod_pack.h"

#define RUNS 51
#define MAXL (MLOD_MESH_MAX_LEVELS + 1)
#define MAXA (8 + MLOD_PACK_MAX_UV)

static void *xmalloc(size_t n)
{
	void *p = malloc(n ? n : 1);
	if (!p) {
		fprintf(stderr, "bench_layout: out of memory\n");
		exit(1);
	}
	return p;
}

static double cpu_now(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ------------------------------------------------------------------ */
/* Quantisation, as lib/pack/packmesh.c's part_quantise               */
/* ------------------------------------------------------------------ */

/* The interleaved quantised vertex: attribute a at off[a], size[a] bytes. */
typedef struct layout {
	int n, stride;
	int off[MAXA], size[MAXA];
	int targets;         /* morph targets: the last `targets` attributes */
} layout;

typedef struct grid {
	float pmin[3], pscale[3];
	float umin[MLOD_PACK_MAX_UV][2], uscale[MLOD_PACK_MAX_UV][2];
	float *tscale;       /* per morph target */
} grid;

static int uv_sets(const mlod_primitive *p)
{
	return p->uv_set_count < MLOD_PACK_MAX_UV ? p->uv_set_count : MLOD_PACK_MAX_UV;
}

static int skinned(const mlod_primitive *p, int skin) { return skin >= 0 && p->weight_set_count > 0; }

static void add_attr(layout *L, int size)
{
	L->off[L->n] = L->stride, L->size[L->n++] = size, L->stride += size;
}

static layout make_layout(const mlod_primitive *p, int skin, int wide)
{
	layout L = {0};
	add_attr(&L, 8);
	if (p->normals)
		add_attr(&L, 4);
	if (p->tangents)
		add_attr(&L, 8);
	for (int s = 0; s < uv_sets(p); s++)
		add_attr(&L, 4);
	if (p->color_set_count > 0)
		add_attr(&L, 4);
	if (skinned(p, skin))
		add_attr(&L, wide ? 8 : 4), add_attr(&L, 4);
	for (int t = 0; t < p->target_count && L.n < MAXA; t++)
		add_attr(&L, 8), L.targets++;
	return L;
}

/* Widens g by p's ranges (first: starts from them). */
static void grid_grow(grid *g, float (*pmx)[3], float (*umx)[2], const mlod_primitive *p, int first)
{
	int nv = p->vertex_count;
	for (int v = 0; v < nv; v++)
		for (int a = 0; a < 3; a++) {
			float f = p->positions[3 * v + a];
			if ((first && v == 0) || f < g->pmin[a])
				g->pmin[a] = f;
			if ((first && v == 0) || f > (*pmx)[a])
				(*pmx)[a] = f;
		}
	for (int s = 0; s < uv_sets(p); s++)
		for (int v = 0; v < nv; v++)
			for (int a = 0; a < 2; a++) {
				float f = p->uvs[s][2 * v + a];
				if ((first && v == 0) || f < g->umin[s][a])
					g->umin[s][a] = f;
				if ((first && v == 0) || f > umx[s][a])
					umx[s][a] = f;
			}
	for (int t = 0; t < p->target_count; t++) {
		float m = 0.0f;
		const float *d = p->targets[t].positions;
		for (int i = 0; d && i < 3 * nv; i++)
			m = fabsf(d[i]) > m ? fabsf(d[i]) : m;
		float sc = m > 0.0f ? (float)(m / (ldexp(1.0, MLOD_PACK_POSITION_BITS_DEFAULT - 1) - 1.0)) : 0.0f;
		if (first || sc > g->tscale[t])
			g->tscale[t] = sc;
	}
}

/* The grid of the given levels (one: that level's own, as the writer). */
static void make_grid(grid *g, const mlod_primitive *const *lv, int n)
{
	float pmx[3] = {0, 0, 0}, umx[MLOD_PACK_MAX_UV][2] = {{0}};
	for (int k = 0; k < n; k++)
		grid_grow(g, &pmx, umx, lv[k], k == 0);
	for (int a = 0; a < 3; a++)
		g->pscale[a] = mlod_pack_range_scale_bits(g->pmin[a], pmx[a], MLOD_PACK_POSITION_BITS_DEFAULT);
	for (int s = 0; s < uv_sets(lv[0]); s++)
		for (int a = 0; a < 2; a++)
			g->uscale[s][a] = mlod_pack_range_scale_bits(g->umin[s][a], umx[s][a], MLOD_PACK_UV_BITS_DEFAULT);
}

/* p's vertices quantised on g into V (nv * L->stride bytes). */
static void quantise(const mlod_primitive *p, const layout *L, const grid *g, int skin, int wide, uint8_t *V)
{
	int nv = p->vertex_count;
	memset(V, 0, (size_t)nv * (size_t)L->stride);
	for (int v = 0; v < nv; v++) {
		uint8_t *o = V + (size_t)v * (size_t)L->stride;
		int a = 0;
		uint16_t q[4] = {0, 0, 0, 0};
		for (int c = 0; c < 3; c++)
			q[c] = mlod_pack_qu16(p->positions[3 * v + c], g->pmin[c], g->pscale[c]);
		memcpy(o + L->off[a++], q, 8);
		if (p->normals) {
			int16_t s[2];
			mlod_pack_oct_encode_bits(p->normals + 3 * v, MLOD_PACK_NORMAL_BITS_DEFAULT, s);
			memcpy(o + L->off[a++], s, 4);
		}
		if (p->tangents) {
			int16_t s[4] = {0, 0, 0, 0};
			mlod_pack_oct_encode_bits(p->tangents + 4 * v, MLOD_PACK_NORMAL_BITS_DEFAULT, s);
			s[2] = p->tangents[4 * v + 3] < 0.0f ? -32767 : 32767;
			memcpy(o + L->off[a++], s, 8);
		}
		for (int s = 0; s < uv_sets(p); s++) {
			uint16_t u[2];
			for (int c = 0; c < 2; c++)
				u[c] = mlod_pack_qu16(p->uvs[s][2 * v + c], g->umin[s][c], g->uscale[s][c]);
			memcpy(o + L->off[a++], u, 4);
		}
		if (p->color_set_count > 0) {
			uint8_t *u8 = o + L->off[a++];
			for (int c = 0; c < 4; c++) {
				float f = p->colors[0][4 * v + c];
				f = f > 0.0f ? (f < 1.0f ? f : 1.0f) : 0.0f;
				u8[c] = (uint8_t)lrintf(f * 255.0f);
			}
		}
		if (skinned(p, skin)) {
			int bj[4];
			float bw[4];
			mlod_pack_top4(p, (uint32_t)v, NULL, 0, bj, bw);
			uint8_t w8[4];
			mlod_pack_weights8(bw, w8);
			uint16_t j16[4];
			uint8_t j8[4];
			for (int t = 0; t < 4; t++) {
				int jt = w8[t] ? bj[t] : 0;
				if (jt < 0 || jt >= skin)
					jt = 0;
				j16[t] = (uint16_t)jt, j8[t] = (uint8_t)jt;
			}
			if (wide)
				memcpy(o + L->off[a++], j16, 8);
			else
				memcpy(o + L->off[a++], j8, 4);
			memcpy(o + L->off[a++], w8, 4);
		}
		for (int t = 0; t < L->targets; t++) {
			const float *d = p->targets[t].positions;
			int16_t s[4] = {0, 0, 0, 0};
			for (int c = 0; c < 3; c++) {
				float f = d && g->tscale[t] > 0.0f ? d[3 * v + c] / g->tscale[t] : 0.0f;
				f = f > 32767.0f ? 32767.0f : f < -32767.0f ? -32767.0f : f;
				s[c] = (int16_t)lrintf(f);
			}
			memcpy(o + L->off[a++], s, 8);
		}
	}
}

/* ------------------------------------------------------------------ */
/* Coded streams                                                       */
/* ------------------------------------------------------------------ */

typedef struct blob {
	unsigned char *enc;  /* NULL: stored raw */
	size_t bytes;        /* stored */
	uint32_t count;
	uint16_t size;
	int index;
	void *raw;           /* the input, to check the decode */
} blob;

typedef struct blobs {
	blob *b;
	int n, cap;
} blobs;

static size_t pad4(size_t n) { return (n + 3) & ~(size_t)3; }

/* Codes one stream as cb_finish does; keeps it in out when out is not NULL. */
static size_t code(const void *data, uint32_t count, uint16_t size, int index, blobs *out)
{
	size_t bytes = (size_t)count * size, stored = bytes;
	unsigned char *enc = NULL;
	if (count == 0)
		return 0;
	if (index) {
		unsigned int *idx = xmalloc(sizeof *idx * count), maxv = 0;
		for (uint32_t k = 0; k < count; k++) {
			if (size == 2) {
				uint16_t v;
				memcpy(&v, (const uint8_t *)data + 2 * k, 2);
				idx[k] = v;
			} else {
				memcpy(&idx[k], (const uint8_t *)data + 4 * k, 4);
			}
			maxv = idx[k] > maxv ? idx[k] : maxv;
		}
		size_t bound = meshopt_encodeIndexBufferBound(count, (size_t)maxv + 1);
		enc = xmalloc(bound);
		stored = meshopt_encodeIndexBuffer(enc, bound, idx, count);
		free(idx);
	} else {
		size_t bound = meshopt_encodeVertexBufferBound(count, size);
		enc = xmalloc(bound);
		size_t e = meshopt_encodeVertexBuffer(enc, bound, data, count, size);
		if (e > 0 && e < bytes)
			stored = e;
		else
			free(enc), enc = NULL;
	}
	if (out) {
		if (out->n == out->cap) {
			out->cap = out->cap ? 2 * out->cap : 64;
			blob *q = realloc(out->b, sizeof *q * (size_t)out->cap);
			if (!q)
				exit(1);
			out->b = q;
		}
		void *raw = xmalloc(bytes);
		memcpy(raw, data, bytes);
		out->b[out->n++] = (blob){enc, stored, count, size, index, raw};
	} else {
		free(enc);
	}
	return pad4(stored);
}

/* Attribute streams of V's vertices first .. first + count - 1. */
static size_t code_vertices(const uint8_t *V, uint32_t first, uint32_t count, const layout *L, blobs *out)
{
	size_t total = 0;
	uint8_t *s = xmalloc((size_t)count * 8 + 8);
	for (int a = 0; a < L->n; a++) {
		for (uint32_t v = 0; v < count; v++)
			memcpy(s + (size_t)v * (size_t)L->size[a], V + (size_t)(first + v) * (size_t)L->stride + L->off[a],
			       (size_t)L->size[a]);
		total += code(s, count, (uint16_t)L->size[a], 0, out);
	}
	free(s);
	return total;
}

static size_t code_indices(const uint32_t *idx, uint32_t ni, uint32_t nv, blobs *out)
{
	if (nv > 65536)
		return code(idx, ni, 4, 1, out);
	uint16_t *i16 = xmalloc(sizeof *i16 * ((size_t)ni + 1));
	for (uint32_t i = 0; i < ni; i++)
		i16[i] = (uint16_t)idx[i];
	size_t b = code(i16, ni, 2, 1, out);
	free(i16);
	return b;
}

/* Decodes every blob once; returns the seconds (thread CPU time), checks
 * the result on the first run. */
static double decode_all(const blobs *B, void *scratch, int check)
{
	double t0 = cpu_now();
	for (int i = 0; i < B->n; i++) {
		const blob *b = &B->b[i];
		if (!b->enc)
			memcpy(scratch, b->raw, (size_t)b->count * b->size);
		else if ((b->index ? meshopt_decodeIndexBuffer(scratch, b->count, b->size, b->enc, b->bytes)
		                   : meshopt_decodeVertexBuffer(scratch, b->count, b->size, b->enc, b->bytes)) != 0) {
			fprintf(stderr, "bench_layout: decode failed\n");
			exit(1);
		}
		if (check && !b->index && memcmp(scratch, b->raw, (size_t)b->count * b->size) != 0) {
			fprintf(stderr, "bench_layout: round trip differs\n");
			exit(1);
		}
	}
	return cpu_now() - t0;
}

static void time_decode(const blobs *B, double *us, double *mbs)
{
	size_t raw = 0, big = 0;
	for (int i = 0; i < B->n; i++) {
		size_t n = (size_t)B->b[i].count * B->b[i].size;
		raw += n, big = n > big ? n : big;
	}
	void *scratch = xmalloc(big);
	double best = decode_all(B, scratch, 1);
	for (int r = 1; r < RUNS; r++) {
		double t = decode_all(B, scratch, 0);
		best = t < best ? t : best;
	}
	free(scratch);
	*us = best * 1e6;
	*mbs = (double)raw / best / 1e6;
}

static void blobs_free(blobs *B)
{
	for (int i = 0; i < B->n; i++)
		free(B->b[i].enc), free(B->b[i].raw);
	free(B->b);
	memset(B, 0, sizeof *B);
}

/* ------------------------------------------------------------------ */
/* The layouts                                                         */
/* ------------------------------------------------------------------ */

/* One part of (b), to time its expansion to (a) at load: per level, the
 * vertices its indices use gathered from the prefix in first-use order
 * and its indices rewritten to them. */
typedef struct job {
	uint8_t *G;                        /* the buffer, interleaved */
	int stride, n;
	uint32_t count, prefix[MAXL], ni[MAXL];
	uint32_t *idx[MAXL];
} job;

typedef struct totals {
	int levels;
	size_t a, ag, b1, b2;              /* stream bytes (ag: (a) on (b)'s grid) */
	long verts_a, unique_b;            /* sum of level vertices; (b)'s buffer */
	long nv[MAXL], prefix[MAXL], used[MAXL]; /* per level */
	size_t la[MAXL], lb2[MAXL];        /* per level: (a)'s bytes, (b2)'s (its block and indices) */
	size_t ia, ib1;                    /* of them, index streams ((b1)'s, in the prefix's numbering) */
	int union_wider;                   /* parts whose union box is wider than level 0's */
	double widest;                     /* the largest union / level 0 extent over axes and parts */
	unsigned maxcode;                  /* (b)'s largest position code */
	int parts;
	blobs A, B1, B2;                   /* the best orders' streams, for the decode */
	/* (c) estimate: parts done, parts whose rebuilt sequence missed the
	 * pack's coarsest level; coarsest bytes ((a)'s), vertices appended by
	 * the splits, their coded bytes, the records' bits, the splits */
	int c_parts, c_missed;
	size_t c_base, c_vbytes, c_bits;
	long c_verts, c_splits, c_base_verts;
	job *jobs;                         /* (b2)'s order, per part */
	int njobs;
} totals;

static uint32_t *level_indices(const mlod_primitive *p, uint32_t *ni)
{
	uint32_t n = p->index_count > 0 ? (uint32_t)p->index_count : (uint32_t)p->vertex_count;
	n -= n % 3;
	uint32_t *in = xmalloc(sizeof *in * ((size_t)n + 1));
	for (uint32_t i = 0; i < n; i++)
		in[i] = p->index_count > 0 ? p->indices[i] : i;
	*ni = n;
	return in;
}

/* (a): one level of one part, the best of the writer's orders. */
static void layout_a(const mlod_primitive *p, int level, int skin, int wide, const grid *shared, totals *T)
{
	layout L = make_layout(p, skin, wide);
	grid g = {0};
	g.tscale = xmalloc(sizeof(float) * ((size_t)p->target_count + 1));
	make_grid(&g, &p, 1);
	if (shared) { /* (a) on (b)'s grid */
		memcpy(g.tscale, shared->tscale, sizeof(float) * (size_t)p->target_count);
		float *keep = g.tscale;
		g = *shared;
		g.tscale = keep;
	}
	uint32_t nv = (uint32_t)p->vertex_count, ni;
	uint8_t *V = xmalloc((size_t)nv * (size_t)L.stride), *W = xmalloc((size_t)nv * (size_t)L.stride);
	quantise(p, &L, &g, skin, wide, V);
	uint32_t *in = level_indices(p, &ni), *out = xmalloc(sizeof *out * ((size_t)ni + 1));
	uint32_t *remap = xmalloc(sizeof *remap * ((size_t)nv + 1));
	size_t best = 0;
	int best_o = 0;
	for (int pass = 0; pass < 2; pass++)
		for (int o = pass ? best_o : 0; o < (pass ? best_o + 1 : MLOD_PACK_ORDERS); o++) {
			if (mlod_pack_vertex_order(o, in, ni, nv, p->positions, remap, out) != 0)
				exit(1);
			for (uint32_t v = 0; v < nv; v++)
				memcpy(W + (size_t)remap[v] * (size_t)L.stride, V + (size_t)v * (size_t)L.stride, (size_t)L.stride);
			blobs *keep = pass && !shared ? &T->A : NULL;
			size_t ib = code_indices(out, ni, nv, keep), b = code_vertices(W, 0, nv, &L, keep) + ib;
			if (pass && !shared)
				T->ia += ib;
			if (L.targets)
				b += code(g.tscale, (uint32_t)L.targets, 4, 0, keep); /* 'MTSC' */
			if (!pass && (o == 0 || b < best))
				best = b, best_o = o;
		}
	if (shared)
		T->ag += best;
	else
		T->a += best, T->la[level] += best;
	free(V), free(W), free(in), free(out), free(remap), free(g.tscale);
}

/* A hash set of vertices (their quantised bytes) to ids in G. */
typedef struct vset {
	uint32_t *slot; /* id + 1, 0 empty */
	size_t cap;
} vset;

static uint64_t hash_bytes(const uint8_t *p, int n)
{
	uint64_t h = 1469598103934665603ull;
	for (int i = 0; i < n; i++)
		h = (h ^ p[i]) * 1099511628211ull;
	return h;
}

/* The id of vertex key (stride bytes) in G (count *n), appending it when new. */
static uint32_t vset_get(vset *s, uint8_t *G, uint32_t *n, const uint8_t *key, int stride)
{
	size_t i = hash_bytes(key, stride) & (s->cap - 1);
	while (s->slot[i]) {
		uint32_t id = s->slot[i] - 1;
		if (memcmp(G + (size_t)id * (size_t)stride, key, (size_t)stride) == 0)
			return id;
		i = (i + 1) & (s->cap - 1);
	}
	memcpy(G + (size_t)*n * (size_t)stride, key, (size_t)stride);
	s->slot[i] = ++*n;
	return *n - 1;
}

/* Appends level V's vertices not yet in G (ids by set) in order o of the
 * level's triangles; returns its indices into G, *used the distinct
 * vertices of G it has. */
static uint32_t *append_level(vset *set, uint8_t *G, uint32_t *count, const uint8_t *V, const uint32_t *in,
                              uint32_t ni, uint32_t nv, const float *positions, int o, int stride, uint32_t *used)
{
	uint32_t *remap = xmalloc(sizeof *remap * ((size_t)nv + 1));
	uint32_t *inv = xmalloc(sizeof *inv * ((size_t)nv + 1));
	uint32_t *out = xmalloc(sizeof *out * ((size_t)ni + 1));
	uint32_t *gid = xmalloc(sizeof *gid * ((size_t)nv + 1));
	uint32_t *idx = xmalloc(sizeof *idx * ((size_t)ni + 1));
	if (mlod_pack_vertex_order(o, in, ni, nv, positions, remap, out) != 0)
		exit(1);
	for (uint32_t v = 0; v < nv; v++)
		inv[remap[v]] = v;
	for (uint32_t j = 0; j < nv; j++) /* by new local index */
		gid[j] = vset_get(set, G, count, V + (size_t)inv[j] * (size_t)stride, stride);
	for (uint32_t t = 0; t < ni; t++)
		idx[t] = gid[out[t]];
	unsigned char *seen = calloc((size_t)*count + 1, 1);
	if (!seen)
		exit(1);
	*used = 0;
	for (uint32_t j = 0; j < nv; j++)
		if (!seen[gid[j]])
			seen[gid[j]] = 1, ++*used;
	free(seen), free(remap), free(inv), free(out), free(gid);
	return idx;
}

/* (b)'s grid for every level of a part, the writer's (lib/pack/packmesh.c
 * part_grid): level 0's steps from the corner of the union of the levels'
 * boxes, or the union's 16-bit steps where the union is wider than 65535
 * of level 0's; morph deltas: the largest |delta| of any level. */
static grid shared_grid(const mlod_primitive *const *lv, int n, totals *T)
{
	grid g = {0}, g0 = {0};
	g.tscale = xmalloc(sizeof(float) * ((size_t)lv[0]->target_count + 1));
	g0.tscale = xmalloc(sizeof(float) * ((size_t)lv[0]->target_count + 1));
	make_grid(&g, lv, n);
	make_grid(&g0, lv, 1);
	float pmx[3] = {0, 0, 0}, umx[MLOD_PACK_MAX_UV][2] = {{0}};
	for (int k = 0; k < n; k++) /* the union's upper corner */
		for (int v = 0; v < lv[k]->vertex_count; v++) {
			int first = k == 0 && v == 0;
			for (int a = 0; a < 3; a++)
				if (first || lv[k]->positions[3 * v + a] > pmx[a])
					pmx[a] = lv[k]->positions[3 * v + a];
			for (int s = 0; s < uv_sets(lv[0]); s++)
				for (int a = 0; a < 2; a++)
					if (first || lv[k]->uvs[s][2 * v + a] > umx[s][a])
						umx[s][a] = lv[k]->uvs[s][2 * v + a];
		}
	/* Level 0's steps from the union's corner: every level at the finest
	 * level's precision; a union wider than level 0's box takes codes
	 * past 2^bits - 1, which the u16 holds. */
	int wider = memcmp(g.pmin, g0.pmin, sizeof g.pmin) != 0;
	for (int a = 0; a < 3; a++) {
		wider |= g.pscale[a] != g0.pscale[a];
		if (g0.pscale[a] > 0.0f && g.pscale[a] / g0.pscale[a] > T->widest)
			T->widest = g.pscale[a] / g0.pscale[a];
		float s16 = mlod_pack_range_scale_bits(g.pmin[a], pmx[a], 16);
		g.pscale[a] = g0.pscale[a] > s16 ? g0.pscale[a] : s16;
	}
	T->union_wider += wider;
	for (int s = 0; s < uv_sets(lv[0]); s++)
		for (int a = 0; a < 2; a++) {
			float s16 = mlod_pack_range_scale_bits(g.umin[s][a], umx[s][a], 16);
			g.uscale[s][a] = g0.uscale[s][a] > s16 ? g0.uscale[s][a] : s16;
		}
	free(g0.tscale);
	return g;
}

/* (b): every level of one part (lv[0] finest .. lv[n-1] coarsest). */
static void layout_b(const mlod_primitive *const *lv, int n, int skin, int wide, totals *T)
{
	layout L = make_layout(lv[0], skin, wide);
	for (int k = 1; k < n; k++) {
		layout Lk = make_layout(lv[k], skin, wide);
		if (Lk.stride != L.stride) {
			fprintf(stderr, "bench_layout: a level has other attributes than level 0\n");
			exit(1);
		}
	}
	grid g = shared_grid(lv, n, T);
	size_t total_nv = 0;
	uint8_t *V[MAXL];
	uint32_t *in[MAXL], ni[MAXL], nv[MAXL];
	for (int k = 0; k < n; k++) {
		nv[k] = (uint32_t)lv[k]->vertex_count;
		total_nv += nv[k];
		V[k] = xmalloc((size_t)nv[k] * (size_t)L.stride);
		quantise(lv[k], &L, &g, skin, wide, V[k]);
		in[k] = level_indices(lv[k], &ni[k]);
		for (uint32_t v = 0; v < nv[k]; v++)
			for (int a = 0; a < 3; a++) {
				uint16_t q;
				memcpy(&q, V[k] + (size_t)v * (size_t)L.stride + 2 * a, 2);
				T->maxcode = q > T->maxcode ? q : T->maxcode;
			}
	}
	uint8_t *G = xmalloc(total_nv * (size_t)L.stride);
	vset set = {0};
	set.cap = 16;
	while (set.cap < 2 * total_nv + 2)
		set.cap *= 2;
	set.slot = xmalloc(sizeof *set.slot * set.cap);
	uint32_t *saved = xmalloc(sizeof *saved * set.cap);
	memset(set.slot, 0, sizeof *set.slot * set.cap);
	uint32_t *idx[MAXL], prefix[MAXL], used[MAXL], count = 0;
	size_t tsc = L.targets ? code(g.tscale, (uint32_t)L.targets, 4, 0, NULL) : 0;
	/* Coarsest first; each level's block in the order (of the writer's
	 * ten, on that level's triangles) that codes its block and indices
	 * to the fewest bytes. */
	for (int k = n - 1; k >= 0; k--) {
		uint32_t count0 = count;
		memcpy(saved, set.slot, sizeof *saved * set.cap);
		size_t best = 0;
		int bo = 0;
		for (int t = 0; t <= MLOD_PACK_ORDERS; t++) {
			int o = t < MLOD_PACK_ORDERS ? t : bo;
			memcpy(set.slot, saved, sizeof *saved * set.cap);
			count = count0;
			uint32_t u;
			uint32_t *ix = append_level(&set, G, &count, V[k], in[k], ni[k], nv[k], lv[k]->positions, o, L.stride, &u);
			if (t == MLOD_PACK_ORDERS) {
				idx[k] = ix, used[k] = u, prefix[k] = count;
				break;
			}
			size_t st; /* the level's indices in the writer's form (format 3.0) */
			size_t b = code_vertices(G, count0, count - count0, &L, NULL) + mlod_pack_index_cost(ix, ni[k], count0, count, &st);
			if (t == 0 || b < best)
				best = b, bo = o;
			free(ix);
		}
	}
	/* b1: the buffer whole, the indices in its numbering; b2: per level
	 * block, the indices in the writer's form (the prefix's numbering or,
	 * format 3.0, the level's own with its map: mlod_pack_index_cost);
	 * the decode times take the prefix's numbering for both. */
	size_t b1 = code_vertices(G, 0, count, &L, &T->B1) + tsc, b2 = 0;
	for (int k = n - 1; k >= 0; k--) {
		uint32_t first = k == n - 1 ? 0 : prefix[k + 1];
		size_t vb = code_vertices(G, first, prefix[k] - first, &L, &T->B2) + tsc, ib2;
		code_indices(idx[k], ni[k], prefix[k], &T->B2);
		mlod_pack_index_cost(idx[k], ni[k], first, prefix[k], &ib2);
		size_t ib = code_indices(idx[k], ni[k], prefix[k], &T->B1);
		b1 += ib, b2 += vb + ib2;
		T->ib1 += ib, T->lb2[k] += vb + ib2;
		T->prefix[k] += prefix[k], T->used[k] += used[k];
	}
	T->b1 += b1, T->b2 += b2, T->unique_b += count;
	job *q = realloc(T->jobs, sizeof *q * ((size_t)T->njobs + 1));
	if (!q)
		exit(1);
	T->jobs = q;
	job *J = &T->jobs[T->njobs++];
	J->G = G, J->stride = L.stride, J->n = n, J->count = count;
	for (int k = 0; k < n; k++)
		J->prefix[k] = prefix[k], J->ni[k] = ni[k], J->idx[k] = idx[k];
	for (int k = 0; k < n; k++)
		free(V[k]), free(in[k]);
	free(set.slot), free(saved), free(g.tscale);
}

/* (c), estimated: rebuilds the part's BGM as mlod_mesh_levels does (same
 * options, poses and joint weights), takes the prefix that gives the
 * pack's coarsest level (checked: same vertex and index counts), and
 * replays its splits coarse to fine. Vertices: every vertex of every
 * intermediate mesh (mlod_bgm_extract at each prefix) not bit-identical on
 * (b)'s grid to one already sent, appended in split order and coded with
 * meshopt's vertex codec like (b)'s blocks. Records, bit-packed, no entropy
 * coding: the split node (ceil log2 of the part's vertex total), the
 * counts of faces brought back and taken away (8 bits), 3 vertex
 * references per face brought back (ceil log2 of the vertex total) and an
 * id per face taken away (ceil log2 of the faces ever made). */
static void layout_c(const mlod_mesh_levels *ML, int instance, int primitive, const mlod_primitive *const *lv, int n,
                     int skin, int wide, size_t coarse_bytes, totals *T)
{
	const mlod_character *c = ML->c;
	const mlod_primitive *p0 = lv[0], *pc = lv[n - 1];
	int triangles = (p0->index_count > 0 ? p0->index_count : p0->vertex_count) / 3;
	if (n < 2 || triangles < 4 || c->instances[instance].node < 0)
		return;
	mlod_bgm *g = NULL;
	mlod_error err = {0};
	if (mlod_bgm_build(c, instance, primitive, &ML->opt, &g, &err) != MLOD_OK ||
	    mlod_bgm_simplify(g, (int)ceil(0.1 * triangles), 0, &err) != MLOD_OK ||
	    (ML->budget == MLOD_BUDGET_CHARACTER && mlod_bgm_simplify(g, 0, 0, &err) != MLOD_OK)) {
		mlod_bgm_free(g);
		T->c_missed++;
		return;
	}
	int P = mlod_bgm_prefix_for(g, pc->index_count / 3);
	mlod_primitive e;
	if (mlod_bgm_extract(g, P, c->instances[instance].skin < 0, &e, &err) != MLOD_OK) {
		mlod_bgm_free(g);
		T->c_missed++;
		return;
	}
	int same = e.vertex_count == pc->vertex_count && e.index_count == pc->index_count;
	mlod_primitive_free(&e);
	if (!same) {
		mlod_bgm_free(g);
		T->c_missed++;
		return;
	}
	grid gr = shared_grid(lv, n, &(totals){0});
	layout L = make_layout(p0, skin, wide);
	size_t cap = 1024;
	uint8_t *C = xmalloc(cap * (size_t)L.stride);
	vset set = {0};
	set.cap = 1 << 20;
	set.slot = calloc(set.cap, sizeof *set.slot);
	uint32_t count = 0, base = 0;
	for (int k = P; k >= 0; k--) {
		if (mlod_bgm_extract(g, k, c->instances[instance].skin < 0, &e, &err) != MLOD_OK)
			exit(1);
		uint8_t *V = xmalloc((size_t)e.vertex_count * (size_t)L.stride + 1);
		quantise(&e, &L, &gr, skin, wide, V);
		if (count + (size_t)e.vertex_count > cap) {
			while (count + (size_t)e.vertex_count > cap)
				cap *= 2;
			uint8_t *q = realloc(C, cap * (size_t)L.stride);
			if (!q)
				exit(1);
			C = q;
		}
		for (int v = 0; v < e.vertex_count; v++)
			vset_get(&set, C, &count, V + (size_t)v * (size_t)L.stride, L.stride);
		if (2 * (size_t)count >= set.cap) {
			fprintf(stderr, "bench_layout: (c): a part with more than %zu vertices\n", set.cap / 2);
			exit(1);
		}
		if (k == P)
			base = count;
		free(V);
		mlod_primitive_free(&e);
	}
	int nrec;
	const mlod_vsplit *seq = mlod_bgm_sequence(g, &nrec);
	long faces = triangles;
	for (int r = 0; r < P; r++)
		faces += seq[r].added_count;
	int vbits = 1, fbits = 1;
	while ((1ul << vbits) < count)
		vbits++;
	while ((1l << fbits) < faces)
		fbits++;
	size_t bits = 0;
	for (int r = 0; r < P; r++)
		bits += (size_t)vbits + 8 + 3 * (size_t)vbits * (size_t)seq[r].removed_count + (size_t)fbits * (size_t)seq[r].added_count;
	T->c_parts++;
	T->c_base += coarse_bytes;
	T->c_base_verts += base;
	T->c_verts += count - base;
	T->c_vbytes += code_vertices(C, base, count - base, &L, NULL);
	T->c_bits += bits;
	T->c_splits += P;
	free(C), free(set.slot), free(gr.tscale);
	mlod_bgm_free(g);
}

/* The stream bytes of the MESH chunks mlod_pack_write makes (but 'PART'),
 * padded as stored: what (b2), the pack's layout since format 2.0, must
 * come to. */
static size_t packed_mesh_bytes(const char *path, int *levels)
{
	FILE *f = fopen(path, "rb");
	if (!f)
		return 0;
	fseek(f, 0, SEEK_END);
	long size = ftell(f);
	fseek(f, 0, SEEK_SET);
	void *data = xmalloc((size_t)size + 1);
	size_t got = fread(data, 1, (size_t)size, f);
	fclose(f);
	mlod_gltf *doc = NULL;
	mlod_character c = {0};
	mlod_error err = {0};
	if (mlod_load(data, got, ".", &doc, &c, NULL, &err) != MLOD_OK) {
		fprintf(stderr, "bench_layout: %s: %s\n", path, err.message);
		exit(1);
	}
	mlod_pack_options opt;
	mlod_pack_options_default(&opt);
	opt.entropy = MLOD_ENTROPY_NONE; /* the streams as the codec stores them, read in place below */
	opt.coarse_share = 0.0;          /* every vertex on level 0's steps, as (b) quantises them */
	void *pack = NULL;
	size_t pack_size = 0;
	if (mlod_pack_write(doc, &c, mlod_detect_format(data, got), data, got, &opt, &pack, &pack_size, NULL, &err) !=
	    MLOD_OK) {
		fprintf(stderr, "bench_layout: %s: %s\n", path, err.message);
		exit(1);
	}
	mlod_pack p;
	if (mlod_pack_open(pack, pack_size, &p, &err) != MLOD_OK) {
		fprintf(stderr, "bench_layout: %s: %s\n", path, err.message);
		exit(1);
	}
	size_t total = 0;
	*levels = 0;
	for (uint32_t i = 0; i < p.chunk_count; i++) {
		const mlod_pack_chunk *ch = &p.chunks[i];
		if (ch->type != MLOD_CHUNK_MESH)
			continue;
		(*levels)++;
		const uint8_t *b = (const uint8_t *)pack + ch->offset;
		uint32_t ns = (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24;
		for (uint32_t s = 0; s < ns; s++) {
			const uint8_t *h = b + 4 + 16 * (size_t)s;
			uint32_t tag, stored;
			memcpy(&tag, h, 4), memcpy(&stored, h + 12, 4);
			if (tag != MLOD_STREAM_PART)
				total += pad4(stored);
		}
	}
	mlod_pack_close(&p);
	mlod_free(pack);
	mlod_gltf_free(doc);
	mlod_character_free(&c);
	free(data);
	return total;
}

/* Expands every level of every part once; returns thread CPU seconds. */
static double expand_all(const totals *T, uint32_t *map, uint8_t *out, uint32_t *oidx, long *gathered)
{
	double t0 = cpu_now();
	long g = 0;
	for (int j = 0; j < T->njobs; j++) {
		const job *J = &T->jobs[j];
		for (int k = 0; k < J->n; k++) {
			memset(map, 0xff, sizeof *map * J->prefix[k]);
			uint32_t m = 0;
			for (uint32_t t = 0; t < J->ni[k]; t++) {
				uint32_t v = J->idx[k][t];
				if (map[v] == UINT32_MAX) {
					memcpy(out + (size_t)m * (size_t)J->stride, J->G + (size_t)v * (size_t)J->stride,
					       (size_t)J->stride);
					map[v] = m++;
				}
				oidx[t] = map[v];
			}
			g += m;
		}
	}
	*gathered = g;
	return cpu_now() - t0;
}

static double time_expand(const totals *T, long *gathered)
{
	size_t big = 1, bigi = 1, bigv = 1;
	for (int j = 0; j < T->njobs; j++) {
		const job *J = &T->jobs[j];
		big = (size_t)J->count > big ? J->count : big;
		bigv = (size_t)J->count * (size_t)J->stride > bigv ? (size_t)J->count * (size_t)J->stride : bigv;
		for (int k = 0; k < J->n; k++)
			bigi = J->ni[k] > bigi ? J->ni[k] : bigi;
	}
	uint32_t *map = xmalloc(sizeof *map * big), *oidx = xmalloc(sizeof *oidx * bigi);
	uint8_t *out = xmalloc(bigv);
	double best = expand_all(T, map, out, oidx, gathered);
	for (int r = 1; r < RUNS; r++) {
		double t = expand_all(T, map, out, oidx, gathered);
		best = t < best ? t : best;
	}
	free(map), free(oidx), free(out);
	return best * 1e6;
}

static void pct(char *out, size_t n, double part, double whole)
{
	snprintf(out, n, "%.1f%%", whole > 0 ? 100.0 * part / whole : 0.0);
}

int main(int argc, char **argv)
{
	if (argc < 2) {
		fprintf(stderr, "usage: bench_layout [-c] FILE.glb ...\n");
		return 1;
	}
	int with_c = strcmp(argv[1], "-c") == 0, first = 1 + with_c;
	static const double ratios_default[] = {MLOD_MESH_RATIOS_DEFAULT};
	int nr = (int)(sizeof ratios_default / sizeof *ratios_default);
	printf("| input | levels | parts | (a) per level | (a) on (b)'s grid | (b1) one buffer | (b2) per-level blocks | (b2) / (a) |"
	       " level vertices | (b) unique | decode (a) | decode (b1) | decode (b2) | expand (b) to (a) |\n");
	printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
	char extra[64][512];
	int ne = 0;
	char ctab[64][512];
	int nc = 0;
	for (int i = first; i < argc; i++) {
		mlod_character c = {0};
		if (bench_load("bench_layout", argv[i], &c, NULL))
			return 2;
		if (mlod_mesh_triangle_primitives(&c) == 0) { /* the pack has no mesh levels either */
			mlod_character_free(&c);
			continue;
		}
		mlod_pack_options opt;
		mlod_pack_options_default(&opt);
		mlod_bgm_options bo = opt.bgm;
		mlod_mesh_budget budget = opt.budget;
		mlod_mesh_resolve(&bo, &budget);
		mlod_mesh_levels ML;
		mlod_error err = {0};
		if (mlod_mesh_levels_init(&ML, &c, &bo, budget, ratios_default[nr - 1], &err) != MLOD_OK ||
		    mlod_mesh_levels_by_ratio(&ML, ratios_default, nr, &err) != MLOD_OK) {
			fprintf(stderr, "bench_layout: %s: %s\n", argv[i], err.message);
			return 2;
		}
		totals T = {0};
		T.levels = ML.count + 1;
		for (int k = 0; k < c.instance_count; k++) {
			const mlod_instance *in = &c.instances[k];
			const mlod_mesh *m = &c.meshes[in->mesh];
			int skin = in->skin >= 0 ? c.skeleton.skins[in->skin].joint_count : -1, wide = skin > 256;
			for (int q = 0; q < m->primitive_count; q++) {
				const mlod_primitive *lv[MAXL];
				int n = 0;
				for (int l = 0; l <= ML.count; l++) {
					const mlod_mesh *lm = l == 0 ? m : &ML.levels[l - 1].meshes[k];
					if (q >= lm->primitive_count || m->primitives[q].mode != 4 || lm->primitives[q].mode != 4 ||
					    lm->primitives[q].vertex_count <= 0)
						continue;
					lv[n++] = &lm->primitives[q];
				}
				grid sg = {0};
				if (n > 0)
					sg = shared_grid(lv, n, &(totals){0});
				size_t coarse_before = n > 0 ? T.la[n - 1] : 0;
				for (int l = 0; l < n; l++) {
					layout_a(lv[l], l, skin, wide, NULL, &T);
					layout_a(lv[l], l, skin, wide, &sg, &T);
					T.nv[l] += lv[l]->vertex_count;
					T.verts_a += lv[l]->vertex_count;
				}
				if (n > 0)
					layout_b(lv, n, skin, wide, &T), T.parts++;
				if (n > 0 && with_c)
					layout_c(&ML, k, q, lv, n, skin, wide, T.la[n - 1] - coarse_before, &T);
				free(sg.tscale);
			}
		}
		int packed_levels = 0;
		size_t packed = packed_mesh_bytes(argv[i], &packed_levels);
		double ua, ma, u1, m1, u2, m2;
		time_decode(&T.A, &ua, &ma);
		time_decode(&T.B1, &u1, &m1);
		time_decode(&T.B2, &u2, &m2);
		long gathered = 0;
		double ux = time_expand(&T, &gathered);
		const char *name = strrchr(argv[i], '/') ? strrchr(argv[i], '/') + 1 : argv[i];
		char r[32];
		pct(r, sizeof r, (double)T.b2, (double)T.a);
		printf("| %s | %d | %d | %zu | %zu | %zu | %zu | %s | %ld | %ld (%.1f%%) | %.0f us, %.0f MB/s | %.0f us, %.0f MB/s |"
		       " %.0f us, %.0f MB/s | %.0f us (%ld vertices) |\n",
		       name, T.levels, T.parts, T.a, T.ag, T.b1, T.b2, r, T.verts_a, T.unique_b,
		       100.0 * (double)T.unique_b / (double)T.verts_a, ua, ma, u1, m1, u2, m2, ux, gathered);
		if (packed != T.b2 || packed_levels != T.levels) {
			fprintf(stderr, "bench_layout: %s: (b2) computed %zu bytes over %d levels, the pack's MESH streams %zu over %d\n",
			        name, T.b2, T.levels, packed, packed_levels);
			return 3;
		}
		/* per level: (b)'s prefix against what the level uses */
		int at = 0;
		at += snprintf(extra[ne] + at, sizeof extra[ne] - (size_t)at, "| %s |", name);
		for (int l = 0; l < T.levels && at < (int)sizeof extra[ne]; l++) {
			char e[32];
			pct(e, sizeof e, (double)(T.prefix[l] - T.used[l]), (double)T.nv[l]);
			at += snprintf(extra[ne] + at, sizeof extra[ne] - (size_t)at, " %ld / %ld / %ld: +%s; %zu / %zu B |",
			               T.nv[l], T.prefix[l], T.used[l], e, T.la[l], T.lb2[l]);
		}
		if (T.union_wider)
			at += snprintf(extra[ne] + at, sizeof extra[ne] - (size_t)at,
			               " %d of %d parts wider than level 0's box (extent at most %.3fx); largest code %u |",
			               T.union_wider, T.parts, T.widest, T.maxcode);
		else
			at += snprintf(extra[ne] + at, sizeof extra[ne] - (size_t)at, " none |");
		if (at < (int)sizeof extra[ne])
			snprintf(extra[ne] + at, sizeof extra[ne] - (size_t)at, " %zu / %zu |", T.ia, T.ib1);
		if (ne < 63)
			ne++;
		if (with_c && nc < 64) {
			size_t cb = T.c_base + T.c_vbytes + (T.c_bits + 7) / 8;
			snprintf(ctab[nc++], sizeof ctab[0],
			         "| %s | %d (%d missed) | %ld | %zu | %ld + %ld | %zu | %zu | %zu | %.1f%% |", name, T.c_parts,
			         T.c_missed, T.c_splits, T.c_base, T.c_base_verts, T.c_verts, T.c_vbytes, (T.c_bits + 7) / 8, cb,
			         100.0 * (double)cb / (double)T.a);
		}
		blobs_free(&T.A), blobs_free(&T.B1), blobs_free(&T.B2);
		for (int j = 0; j < T.njobs; j++) {
			free(T.jobs[j].G);
			for (int k = 0; k < T.jobs[j].n; k++)
				free(T.jobs[j].idx[k]);
		}
		free(T.jobs);
		mlod_mesh_levels_free(&ML);
		mlod_character_free(&c);
	}
	printf("\nPer level (0 finest), vertices (a) / prefix (b) / used of the prefix: + the prefix's vertices the level\n"
	       "does not use, which a runtime skinning the whole prefix skins beyond (a), as a %% of the level's (a) vertices;\n"
	       "then the level's bytes in (a) / in (b2) (its appended block and its indices).\n\n");
	printf("| input | level 0 | level 1 | level 2 | level 3 | (b)'s shared grid | index bytes (a) / (b) |\n"
	       "|---|---|---|---|---|---|---|\n");
	for (int e = 0; e < ne; e++)
		printf("%s\n", extra[e]);
	if (with_c) {
		printf("\n(c) estimated (-c): the coarsest level as (a) stores it, then the recorded splits replayed coarse to fine\n"
		       "(parts with a BGM; 'missed': rebuilt sequence did not give the pack's coarsest level, left out).\n\n");
		printf("| input | parts | splits | coarsest (a) bytes | vertices coarsest + appended | appended, meshopt |"
		       " records, bit-packed | (c) total | (c) / (a) |\n|---|---|---|---|---|---|---|---|---|\n");
		for (int e = 0; e < nc; e++)
			printf("%s\n", ctab[e]);
	}
	return 0;
}
