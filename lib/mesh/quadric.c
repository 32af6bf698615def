/*
 * quadric.c: posed quadrics, the skin-aware cost of the mesh layer
 * (beyond Savoye & Meyer 2008, whose 4.2.3 orders collapses by triangle
 * compactness only).
 *
 * Garland & Heckbert's quadric error metric ("Surface simplification
 * using quadric error metrics", SIGGRAPH 1997), summed over poses: at
 * each pose p the input faces are skinned, and each node accumulates the
 * area-weighted plane quadrics Q_p of its faces (a new node v-bar sums
 * its parents'). A candidate v-bar with bind position x and influences w
 * costs sum_p q_p(M_p(w) x), where M_p(w) = sum_j w_j S_j,p blends the
 * skinning matrices: the error the collapse makes where the character is
 * actually seen, including what Power Skinning does to its weights. With
 * w fixed the cost is a quadric in x (sum_p M_p^T Q_p M_p), whose minimum
 * is the optimal placement.
 *
 * Pose 0 is the rest pose; the others come from mlod_bgm_options.poses
 * (clip frames and random poses). Every pose is posed into world space,
 * pose 0 included (a skinned mesh through the rest pose's skin matrices,
 * not the identity): the quadrics, the costs and the bounds are then in
 * the character's units whatever space the mesh is stored in (positions
 * scaled into integers by KHR_mesh_quantization, centimetres under an
 * armature scaled 0.01), and the levels do not depend on it.
 */
#include <limits.h>
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#ifdef __SSE2__
#include <emmintrin.h>
#endif

#include "bgm.h"

#define FEATURE_COS 0.5     /* creases sharper than 60 degrees are features */
#define FEATURE_WEIGHT 1.0  /* of a feature plane, times the squared edge length */

/* m's top 3x4, row-major. */
static void to_rows(const mlod_mat4 *m, float *out)
{
	for (int r = 0; r < 3; r++)
		for (int c = 0; c < 4; c++)
			out[4 * r + c] = m->m[c * 4 + r];
}

/* The plane of the face with corner a and fn: its bgm_face_normal and
 * that normal's length. */
static void plane_quadric(const double *a, const double *fn, double *q)
{
	double n[3] = {fn[0], fn[1], fn[2]};
	double len = fn[3];
	if (!(len > 0.0))
		return;
	double area = 0.5 * len;
	for (int i = 0; i < 3; i++)
		n[i] /= len;
	double d = -(n[0] * a[0] + n[1] * a[1] + n[2] * a[2]);
	/* q[k] += area * P[i] * P[j] over i <= j, P = (n, d), written out */
	double w0 = area * n[0], w1 = area * n[1], w2 = area * n[2], w3 = area * d;
	q[0] += w0 * n[0], q[1] += w0 * n[1], q[2] += w0 * n[2], q[3] += w0 * d;
	q[4] += w1 * n[1], q[5] += w1 * n[2], q[6] += w1 * d;
	q[7] += w2 * n[2], q[8] += w2 * d;
	q[9] += w3 * d;
}

static double dot3(const double *a, const double *b)
{
	return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

void bgm_face_normal(const double *a, const double *b, const double *c, double *n)
{
	double u[3], v[3];
	for (int i = 0; i < 3; i++)
		u[i] = b[i] - a[i], v[i] = c[i] - a[i];
	n[0] = u[1] * v[2] - u[2] * v[1];
	n[1] = u[2] * v[0] - u[0] * v[2];
	n[2] = u[0] * v[1] - u[1] * v[0];
}

/* The plane through edge (a, b) perpendicular to a face of normal n,
 * weighted by the squared edge length. */
static void edge_quadric(const double *a, const double *b, const double *n, double *q)
{
	double e[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, m[3];
	m[0] = e[1] * n[2] - e[2] * n[1];
	m[1] = e[2] * n[0] - e[0] * n[2];
	m[2] = e[0] * n[1] - e[1] * n[0];
	double len = sqrt(dot3(m, m)), l2 = dot3(e, e);
	if (!(len > 0.0))
		return;
	for (int i = 0; i < 3; i++)
		m[i] /= len;
	double d = -dot3(m, a), l = FEATURE_WEIGHT * l2;
	/* q[k] += FEATURE_WEIGHT * l2 * P[i] * P[j] over i <= j, P = (m, d), written out */
	double w0 = l * m[0], w1 = l * m[1], w2 = l * m[2], w3 = l * d;
	q[0] += w0 * m[0], q[1] += w0 * m[1], q[2] += w0 * m[2], q[3] += w0 * d;
	q[4] += w1 * m[1], q[5] += w1 * m[2], q[6] += w1 * d;
	q[7] += w2 * m[2], q[8] += w2 * d;
	q[9] += w3 * d;
}

/* The blended 3x4 matrix of pose p for influences inf. */
static inline void blend(const mlod_bgm *g, int p, const mlod_influences *inf, double *M)
{
	const float *S = g->skin + (size_t)p * (size_t)(g->joint_count > 0 ? g->joint_count : 1) * 12;
	if (g->joint_count == 0 || inf->count == 0) {
		for (int i = 0; i < 12; i++)
			M[i] = g->joint_count == 0 ? S[i] : (i % 5 == 0 ? 1.0 : 0.0);
		return;
	}
#ifdef __SSE2__
	/* Two entries at a time: each the same product and sum, in the same
	 * order, as the scalar loop below (SSE2 rounds as scalar code). */
	__m128d m0 = _mm_setzero_pd(), m1 = m0, m2 = m0, m3 = m0, m4 = m0, m5 = m0;
	for (int k = 0; k < inf->count; k++) {
		const float *s = S + 12 * (size_t)inf->joints[k];
		__m128d w = _mm_set1_pd((double)inf->weights[k]);
		__m128 a = _mm_loadu_ps(s), b = _mm_loadu_ps(s + 4), c = _mm_loadu_ps(s + 8);
		m0 = _mm_add_pd(m0, _mm_mul_pd(w, _mm_cvtps_pd(a)));
		m1 = _mm_add_pd(m1, _mm_mul_pd(w, _mm_cvtps_pd(_mm_movehl_ps(a, a))));
		m2 = _mm_add_pd(m2, _mm_mul_pd(w, _mm_cvtps_pd(b)));
		m3 = _mm_add_pd(m3, _mm_mul_pd(w, _mm_cvtps_pd(_mm_movehl_ps(b, b))));
		m4 = _mm_add_pd(m4, _mm_mul_pd(w, _mm_cvtps_pd(c)));
		m5 = _mm_add_pd(m5, _mm_mul_pd(w, _mm_cvtps_pd(_mm_movehl_ps(c, c))));
	}
	_mm_storeu_pd(M, m0);
	_mm_storeu_pd(M + 2, m1);
	_mm_storeu_pd(M + 4, m2);
	_mm_storeu_pd(M + 6, m3);
	_mm_storeu_pd(M + 8, m4);
	_mm_storeu_pd(M + 10, m5);
#else
	memset(M, 0, 12 * sizeof *M);
	for (int k = 0; k < inf->count; k++) {
		const float *s = S + 12 * (size_t)inf->joints[k];
		double w = inf->weights[k];
		for (int i = 0; i < 12; i++)
			M[i] += w * s[i];
	}
#endif
}

static inline void apply(const double *M, const double *x, double *y)
{
	for (int r = 0; r < 3; r++)
		y[r] = M[4 * r] * x[0] + M[4 * r + 1] * x[1] + M[4 * r + 2] * x[2] + M[4 * r + 3];
}

static inline double eval(const double *q, const double *x)
{
	return q[0] * x[0] * x[0] + 2 * q[1] * x[0] * x[1] + 2 * q[2] * x[0] * x[2] + 2 * q[3] * x[0] +
	       q[4] * x[1] * x[1] + 2 * q[5] * x[1] * x[2] + 2 * q[6] * x[1] + q[7] * x[2] * x[2] + 2 * q[8] * x[2] + q[9];
}

#ifdef __SSE2__
/* Two poses at a time (pair i: poses 2i and 2i + 1 in the low and high
 * lanes), each lane the same products and sums in the same order as the
 * one-pose functions above (SSE2 rounds as scalar code).
 * g->skin2 and the node quadrics (g->quadric, the collapse's g->qsum) come
 * from malloc, so their pairs (24 and 20 doubles) are 16-byte aligned:
 * aligned loads, which the products take as memory operands. */
_Static_assert(_Alignof(max_align_t) >= 16, "malloc's blocks must be 16-byte aligned for the two-pose loads");

/* blend for both poses of pair i; inf has influences (joint_count > 0). */
BGM_INLINE void blend2s(const double *S, const mlod_influences *inf, __m128d *M);

BGM_INLINE void blend2(const mlod_bgm *g, size_t i, const mlod_influences *inf, __m128d *M)
{
	blend2s(g->skin2 + i * (size_t)g->joint_count * 24, inf, M);
}

/* blend2 on the block S of two poses' skin matrices (24 doubles per
 * influence id). */
BGM_INLINE void blend2s(const double *S, const mlod_influences *inf, __m128d *M)
{
	/* Written out, so that the twelve sums stay in registers. */
	__m128d m0 = _mm_setzero_pd(), m1 = m0, m2 = m0, m3 = m0, m4 = m0, m5 = m0, m6 = m0, m7 = m0, m8 = m0,
	        m9 = m0, m10 = m0, m11 = m0;
	for (int k = 0; k < inf->count; k++) {
		const double *s = S + 24 * (size_t)inf->joints[k];
		__m128d w = _mm_set1_pd((double)inf->weights[k]);
		m0 = _mm_add_pd(m0, _mm_mul_pd(w, _mm_load_pd(s)));
		m1 = _mm_add_pd(m1, _mm_mul_pd(w, _mm_load_pd(s + 2)));
		m2 = _mm_add_pd(m2, _mm_mul_pd(w, _mm_load_pd(s + 4)));
		m3 = _mm_add_pd(m3, _mm_mul_pd(w, _mm_load_pd(s + 6)));
		m4 = _mm_add_pd(m4, _mm_mul_pd(w, _mm_load_pd(s + 8)));
		m5 = _mm_add_pd(m5, _mm_mul_pd(w, _mm_load_pd(s + 10)));
		m6 = _mm_add_pd(m6, _mm_mul_pd(w, _mm_load_pd(s + 12)));
		m7 = _mm_add_pd(m7, _mm_mul_pd(w, _mm_load_pd(s + 14)));
		m8 = _mm_add_pd(m8, _mm_mul_pd(w, _mm_load_pd(s + 16)));
		m9 = _mm_add_pd(m9, _mm_mul_pd(w, _mm_load_pd(s + 18)));
		m10 = _mm_add_pd(m10, _mm_mul_pd(w, _mm_load_pd(s + 20)));
		m11 = _mm_add_pd(m11, _mm_mul_pd(w, _mm_load_pd(s + 22)));
	}
	M[0] = m0, M[1] = m1, M[2] = m2, M[3] = m3, M[4] = m4, M[5] = m5;
	M[6] = m6, M[7] = m7, M[8] = m8, M[9] = m9, M[10] = m10, M[11] = m11;
}

/* Entry e of the node quadrics' pair u (poses 2i and 2i + 1 side by
 * side, bgm_qat: u = q + 20 i), loaded where it is used, so that the
 * products take it from memory (no copy of the pair). */
#define QP(u, e) _mm_load_pd((u) + 2 * (e))

/* eval for both poses (u: the pair's entries). */
BGM_INLINE __m128d eval2(const double *u, const __m128d *x)
{
	const __m128d two = _mm_set1_pd(2.0);
	__m128d v = _mm_mul_pd(_mm_mul_pd(QP(u, 0), x[0]), x[0]);
	v = _mm_add_pd(v, _mm_mul_pd(_mm_mul_pd(_mm_mul_pd(two, QP(u, 1)), x[0]), x[1]));
	v = _mm_add_pd(v, _mm_mul_pd(_mm_mul_pd(_mm_mul_pd(two, QP(u, 2)), x[0]), x[2]));
	v = _mm_add_pd(v, _mm_mul_pd(_mm_mul_pd(two, QP(u, 3)), x[0]));
	v = _mm_add_pd(v, _mm_mul_pd(_mm_mul_pd(QP(u, 4), x[1]), x[1]));
	v = _mm_add_pd(v, _mm_mul_pd(_mm_mul_pd(_mm_mul_pd(two, QP(u, 5)), x[1]), x[2]));
	v = _mm_add_pd(v, _mm_mul_pd(_mm_mul_pd(two, QP(u, 6)), x[1]));
	v = _mm_add_pd(v, _mm_mul_pd(_mm_mul_pd(QP(u, 7), x[2]), x[2]));
	v = _mm_add_pd(v, _mm_mul_pd(_mm_mul_pd(two, QP(u, 8)), x[2]));
	return _mm_add_pd(v, QP(u, 9));
}
#endif

/* Pose p's 10 entries (in order, from a) into node quadrics d (P poses),
 * where bgm_qat puts them. */
static inline void qput(double *d, int P, int p, const double *a)
{
	if (p < (P & ~1)) {
		d += 20 * (size_t)(p >> 1) + (size_t)(p & 1);
		for (int e = 0; e < 10; e++)
			d[2 * e] = a[e];
	} else {
		memcpy(d + 10 * (size_t)p, a, 10 * sizeof *d);
	}
}

#ifdef __SSE2__
/* Q[k] += q[k], k = 0..9, written out. */
#define ADD10(Q, q) \
	do { \
		(Q)[0] = _mm_add_pd((Q)[0], (q)[0]), (Q)[1] = _mm_add_pd((Q)[1], (q)[1]); \
		(Q)[2] = _mm_add_pd((Q)[2], (q)[2]), (Q)[3] = _mm_add_pd((Q)[3], (q)[3]); \
		(Q)[4] = _mm_add_pd((Q)[4], (q)[4]), (Q)[5] = _mm_add_pd((Q)[5], (q)[5]); \
		(Q)[6] = _mm_add_pd((Q)[6], (q)[6]), (Q)[7] = _mm_add_pd((Q)[7], (q)[7]); \
		(Q)[8] = _mm_add_pd((Q)[8], (q)[8]), (Q)[9] = _mm_add_pd((Q)[9], (q)[9]); \
	} while (0)

/* bgm_face_normal for both lanes. */
BGM_INLINE void normal2(const __m128d *a, const __m128d *b, const __m128d *c, __m128d *n)
{
	__m128d u0 = _mm_sub_pd(b[0], a[0]), u1 = _mm_sub_pd(b[1], a[1]), u2 = _mm_sub_pd(b[2], a[2]);
	__m128d v0 = _mm_sub_pd(c[0], a[0]), v1 = _mm_sub_pd(c[1], a[1]), v2 = _mm_sub_pd(c[2], a[2]);
	n[0] = _mm_sub_pd(_mm_mul_pd(u1, v2), _mm_mul_pd(u2, v1));
	n[1] = _mm_sub_pd(_mm_mul_pd(u2, v0), _mm_mul_pd(u0, v2));
	n[2] = _mm_sub_pd(_mm_mul_pd(u0, v1), _mm_mul_pd(u1, v0));
}

BGM_INLINE __m128d dot2(const __m128d *a, const __m128d *b)
{
	return _mm_add_pd(_mm_add_pd(_mm_mul_pd(a[0], b[0]), _mm_mul_pd(a[1], b[1])), _mm_mul_pd(a[2], b[2]));
}

/* q[k] = w_i P_j (P = (n, d), w = s P) in the lanes of keep, +0 in the
 * others: plane_quadric's and edge_quadric's terms. */
BGM_INLINE void terms2(__m128d s, const __m128d *n, __m128d d, __m128d keep, __m128d *q)
{
	__m128d w0 = _mm_mul_pd(s, n[0]), w1 = _mm_mul_pd(s, n[1]), w2 = _mm_mul_pd(s, n[2]), w3 = _mm_mul_pd(s, d);
	q[0] = _mm_and_pd(keep, _mm_mul_pd(w0, n[0])), q[1] = _mm_and_pd(keep, _mm_mul_pd(w0, n[1]));
	q[2] = _mm_and_pd(keep, _mm_mul_pd(w0, n[2])), q[3] = _mm_and_pd(keep, _mm_mul_pd(w0, d));
	q[4] = _mm_and_pd(keep, _mm_mul_pd(w1, n[1])), q[5] = _mm_and_pd(keep, _mm_mul_pd(w1, n[2]));
	q[6] = _mm_and_pd(keep, _mm_mul_pd(w1, d));
	q[7] = _mm_and_pd(keep, _mm_mul_pd(w2, n[2])), q[8] = _mm_and_pd(keep, _mm_mul_pd(w2, d));
	q[9] = _mm_and_pd(keep, _mm_mul_pd(w3, d));
}

/* edge_quadric for both lanes, added to q in the lanes of keep (where
 * the edge is a feature). */
BGM_INLINE void edge2(const __m128d *a, const __m128d *b, const __m128d *n, __m128d keep, __m128d *q)
{
	__m128d e[3] = {_mm_sub_pd(b[0], a[0]), _mm_sub_pd(b[1], a[1]), _mm_sub_pd(b[2], a[2])}, m[3];
	m[0] = _mm_sub_pd(_mm_mul_pd(e[1], n[2]), _mm_mul_pd(e[2], n[1]));
	m[1] = _mm_sub_pd(_mm_mul_pd(e[2], n[0]), _mm_mul_pd(e[0], n[2]));
	m[2] = _mm_sub_pd(_mm_mul_pd(e[0], n[1]), _mm_mul_pd(e[1], n[0]));
	__m128d len = _mm_sqrt_pd(dot2(m, m)), l2 = dot2(e, e);
	keep = _mm_and_pd(keep, _mm_cmpgt_pd(len, _mm_setzero_pd()));
	for (int i = 0; i < 3; i++)
		m[i] = _mm_div_pd(m[i], len);
	__m128d d = _mm_xor_pd(dot2(m, a), _mm_set1_pd(-0.0)), t[10];
	terms2(_mm_mul_pd(_mm_set1_pd(FEATURE_WEIGHT), l2), m, d, keep, t);
	ADD10(q, t);
}

/* The quadrics of stored poses da (low lane) and db = da + 1 (high lane;
 * db = da for a last one alone; da even) into g->quadric: the one-pose
 * loop of bgm_quadrics_build in two lanes, every lane the same products,
 * sums and tests in the same order (SSE2 rounds as scalar code; a
 * face's plane that one-pose code leaves out, a plane added as +0
 * instead of a -0, an edge that is no feature in a lane, add +0 there,
 * which leaves each sum as it was: a sum from +0 is never -0). Their
 * skin matrices are g->skin2's block da / 2. posed: 3 per node; fn: 4
 * per face; acc: 10 per node. */
static void quadrics_pair(mlod_bgm *g, int da, int db, __m128d *posed, __m128d *fn, __m128d *acc)
{
	int J = g->joint_count, D = g->qpose_count;
	const double *sk = g->skin2 + (size_t)(da / 2) * (size_t)J * 24;
	const __m128d zero = _mm_setzero_pd();
	for (int v = 0; v < g->node_count; v++) {
		const mlod_influences *inf = &g->inf[v];
		__m128d M[12];
		if (inf->count == 0) {
			for (int i = 0; i < 12; i++)
				M[i] = _mm_set1_pd(i % 5 == 0 ? 1.0 : 0.0);
		} else {
			blend2s(sk, inf, M);
		}
		const double *x = g->nodes[v].p;
		__m128d x0 = _mm_set1_pd(x[0]), x1 = _mm_set1_pd(x[1]), x2 = _mm_set1_pd(x[2]);
		for (int r = 0; r < 3; r++)
			posed[3 * v + r] = _mm_add_pd(
			        _mm_add_pd(_mm_add_pd(_mm_mul_pd(M[4 * r], x0), _mm_mul_pd(M[4 * r + 1], x1)), _mm_mul_pd(M[4 * r + 2], x2)),
			        M[4 * r + 3]);
	}
	/* Every face's normal and its length (the one-pose loop works each
	 * out once, when first needed: the same values). */
	for (int f = 0; f < g->face_count; f++) {
		const bgm_face *F = &g->faces[f];
		__m128d *n = fn + 4 * f;
		normal2(posed + 3 * F->n[0], posed + 3 * F->n[1], posed + 3 * F->n[2], n);
		n[3] = _mm_sqrt_pd(dot2(n, n));
	}
	memset(acc, 0, sizeof *acc * 10 * (size_t)g->node_count); /* +0 */
	const __m128d all = _mm_castsi128_pd(_mm_set1_epi32(-1)), half = _mm_set1_pd(0.5);
	const __m128d cosf = _mm_set1_pd(FEATURE_COS);
	for (int f = 0; f < g->face_count; f++) {
		const bgm_face *F = &g->faces[f];
		const __m128d *nf = fn + 4 * f, *a0 = posed + 3 * F->n[0];
		/* plane_quadric */
		__m128d q[10], len = nf[3];
		__m128d n[3] = {_mm_div_pd(nf[0], len), _mm_div_pd(nf[1], len), _mm_div_pd(nf[2], len)};
		__m128d d = _mm_xor_pd(dot2(n, a0), _mm_set1_pd(-0.0));
		terms2(_mm_mul_pd(half, len), n, d, _mm_cmpgt_pd(len, zero), q);
		ADD10(acc + (size_t)F->n[0] * 10, q);
		ADD10(acc + (size_t)F->n[1] * 10, q);
		ADD10(acc + (size_t)F->n[2] * 10, q);
		for (int e = 0; e < 3; e++) {
			int h = F->adj[e];
			if (h >= 0 && h < f)
				continue; /* each interior edge once */
			const __m128d *a = posed + 3 * F->n[e], *b = posed + 3 * F->n[(e + 1) % 3];
			const __m128d *o = posed + 3 * F->n[(e + 2) % 3];
			__m128d n1[3], keep = all;
			if (e == 0)
				n1[0] = nf[0], n1[1] = nf[1], n1[2] = nf[2];
			else
				normal2(a, b, o, n1);
			const __m128d *c = NULL;
			if (h >= 0) {
				c = fn + 4 * h;
				__m128d l1 = e == 0 ? nf[3] : _mm_sqrt_pd(dot2(n1, n1)), l2 = c[3];
				keep = _mm_and_pd(_mm_cmpgt_pd(l1, zero), _mm_cmpgt_pd(l2, zero));
				keep = _mm_andnot_pd(_mm_cmpgt_pd(dot2(n1, c), _mm_mul_pd(_mm_mul_pd(cosf, l1), l2)), keep);
				if (_mm_movemask_pd(keep) == 0)
					continue;
			}
			__m128d q2[10] = {zero, zero, zero, zero, zero, zero, zero, zero, zero, zero};
			edge2(a, b, n1, keep, q2);
			if (c)
				edge2(a, b, c, keep, q2);
			ADD10(acc + (size_t)F->n[e] * 10, q2);
			ADD10(acc + (size_t)F->n[(e + 1) % 3] * 10, q2);
		}
	}
	/* Out: a pair (2i, 2i + 1) as it lies (bgm_qat), else the low lane. */
	for (int v = 0; v < g->node_count; v++) {
		double *dst = g->quadric + (size_t)g->qslot[v] * (size_t)D * 10;
		const __m128d *A = acc + (size_t)v * 10;
		if (db == da + 1) {
			dst += 10 * (size_t)da;
			_mm_store_pd(dst, A[0]), _mm_store_pd(dst + 2, A[1]), _mm_store_pd(dst + 4, A[2]);
			_mm_store_pd(dst + 6, A[3]), _mm_store_pd(dst + 8, A[4]), _mm_store_pd(dst + 10, A[5]);
			_mm_store_pd(dst + 12, A[6]), _mm_store_pd(dst + 14, A[7]), _mm_store_pd(dst + 16, A[8]);
			_mm_store_pd(dst + 18, A[9]);
		} else {
			double lo[10];
			for (int k = 0; k < 10; k++)
				_mm_storel_pd(lo + k, A[k]);
			qput(dst, D, da, lo);
		}
	}
}
#endif

mlod_result bgm_quadrics_build(mlod_bgm *g, const mlod_character *c, const mlod_instance *in, mlod_error *err)
{
	const mlod_skeleton *s = &c->skeleton;
	const mlod_pose_set *ps = g->opt.poses;
	int extra = ps && ps->count > 0 && ps->joint_count == s->joint_count && g->joint_count > 0 ? ps->count : 0;
	int P = 1 + extra, J = g->joint_count > 0 ? g->joint_count : 1;
	mlod_result r = MLOD_OK;
	mlod_mat4 *mats = malloc(sizeof *mats * (size_t)J);
	mlod_mat4 *rest = malloc(sizeof *rest * ((size_t)s->joint_count + 1));
	mlod_trs *local = malloc(sizeof *local * ((size_t)s->joint_count + 1));
	double *posed = malloc(sizeof(double) * 3 * (size_t)g->node_count + 1);
	/* Per face, in the pose at hand: bgm_face_normal of its corners in
	 * order, and that normal's length (computed on first use, -1 before). */
	double *fn = malloc(sizeof(double) * 4 * (size_t)g->face_count + 1);
	/* One pose's quadrics, node after node: the faces add into this
	 * small array (not into g->quadric, where a node's poses sit
	 * together and one pose's nodes are P * 10 doubles apart, a cache
	 * miss for nearly every add on a large mesh), which is then copied
	 * out. Each node's sum is made in the same order from the same 0. */
	double *acc = malloc(sizeof(double) * 10 * (size_t)g->node_count + 1);
	g->skin = malloc(sizeof(float) * 12 * (size_t)J * (size_t)P);
	if (!mats || !rest || !local || !posed || !fn || !acc || !g->skin) {
		r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory building posed quadrics");
		goto done;
	}
	mlod_pose_rest(s, local);
	mlod_pose_world(s, local, rest);
	/* A skinned mesh's pose 0 is its bind shape, mapped for every
	 * influence through one matrix: the rest pose's skin matrix of the
	 * joint with the largest weight sum (ties: the first). That is the
	 * identity (within rounding) for a mesh stored in the character's
	 * space whose rest pose is its bind pose, a scale for one stored in
	 * other units (dequantisation folded into the inverse bind matrices,
	 * centimetres under an armature scaled 0.01), and a rigid motion as
	 * well where the rest pose is not the bind pose (the robot), which
	 * changes no distance. Its error is then in the units of the other
	 * poses' and weighs as one of them (with the identity, in the bind
	 * space's units, it weighed next to nothing on the robot, stored in
	 * 1/100 of its units, and outweighed every other pose on a
	 * gltfpack-quantised tubeman, 625 bind units to one of its own).
	 * One matrix for all keeps pose 0's term
	 * independent of the influences (bgm_lower_key's bound in lowerbound.c). */
	int dominant = -1;
	if (g->skinned) {
		double *sum = calloc((size_t)J, sizeof *sum);
		if (!sum) {
			r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory building posed quadrics");
			goto done;
		}
		for (int v = 0; v < g->node_count; v++)
			for (int k = 0; k < g->inf[v].count && k < MLOD_MAX_INFLUENCES; k++)
				if (g->inf[v].joints[k] < J)
					sum[g->inf[v].joints[k]] += g->inf[v].weights[k];
		dominant = 0; /* no weights at all: every node is locked */
		for (int k = 1; k < J; k++)
			if (sum[k] > sum[dominant])
				dominant = k;
		free(sum);
	}
	for (int p = 0; p < P; p++) {
		float *S = g->skin + (size_t)p * (size_t)J * 12;
		const mlod_mat4 *world = p == 0 ? rest : ps->world + (size_t)(p - 1) * (size_t)s->joint_count;
		if (g->skinned) {
			mlod_skin_matrices(&s->skins[in->skin], world, mats);
			for (int k = 0; k < J; k++)
				to_rows(&mats[p == 0 ? dominant : k], S + 12 * k);
		} else if (g->rigid) {
			mlod_mat4 m = mlod_mat4_mul(&world[in->joint], &in->offset);
			to_rows(&m, S);
		} else {
			to_rows(&in->offset, S);
		}
	}
	/* A skinned mesh's pose 0 matrix within rounding of the identity (its
	 * linear part's entries within 1e-6, its translation within 1e-6 of
	 * the bind box's diagonal: Ely's is within 1.2e-7) is the identity,
	 * so that a mesh stored in the character's space keeps the bind
	 * space's numbers exactly, without a matrix to apply. */
	if (g->skinned) {
		double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL}, d2 = 0.0;
		for (int v = 0; v < g->node_count; v++)
			for (int i = 0; i < 3; i++)
				lo[i] = fmin(lo[i], g->nodes[v].p[i]), hi[i] = fmax(hi[i], g->nodes[v].p[i]);
		for (int i = 0; i < 3 && g->node_count > 0; i++)
			d2 += (hi[i] - lo[i]) * (hi[i] - lo[i]);
		int near = 1;
		for (int e = 0; e < 12 && near; e++) {
			double x = g->skin[e];
			near = e % 4 == 3 ? fabs(x) <= 1e-6 * sqrt(d2) : fabs(x - (e % 5 == 0 ? 1.0 : 0.0)) <= 1e-6;
		}
		if (near) {
			mlod_mat4 id = mlod_mat4_identity();
			for (int k = 0; k < J; k++)
				to_rows(&id, g->skin + 12 * k);
		}
	}
	/* The diagonal of the nodes' box at pose 0, in the same units as the
	 * costs (the hybrid placement's cap). */
	{
		double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL}, M[12], y[3];
		for (int v = 0; v < g->node_count; v++) {
			blend(g, 0, &g->inf[v], M);
			apply(M, g->nodes[v].p, y);
			for (int i = 0; i < 3; i++)
				lo[i] = fmin(lo[i], y[i]), hi[i] = fmax(hi[i], y[i]);
		}
		g->diagonal = g->node_count > 0 ? sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
		                                       (hi[2] - lo[2]) * (hi[2] - lo[2]))
		                                 : 0.0;
	}
	/* The skin matrices the nodes use (all of them for a static mesh). */
	unsigned char *used = calloc((size_t)J, 1);
	g->qmap = malloc(sizeof(int) * (size_t)P);
	g->qpose = malloc(sizeof(int) * (size_t)P);
	if (!used || !g->qmap || !g->qpose) {
		free(used);
		r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory building posed quadrics");
		goto done;
	}
	if (g->joint_count == 0)
		used[0] = 1;
	for (int v = 0; v < g->node_count; v++)
		for (int k = 0; k < g->inf[v].count && k < MLOD_MAX_INFLUENCES; k++)
			if (g->inf[v].joints[k] < J)
				used[g->inf[v].joints[k]] = 1;
	/* A pose whose used skin matrices are bit for bit an earlier pose's
	 * (a rigid part or a joint the clip leaves still) has that pose's
	 * quadrics, every step being the same arithmetic on the same values,
	 * and so has every node the collapses make (their sums, their
	 * influences among the used ones): it is not stored, qmap sends it
	 * to the first such pose's quadrics, and the sums over poses take
	 * that pose's terms again. */
	int D = 0;
	for (int p = 0; p < P; p++) {
		int same = -1;
		for (int q = 0; q < p && same < 0; q++) {
			const float *a = g->skin + (size_t)p * (size_t)J * 12, *b = g->skin + (size_t)q * (size_t)J * 12;
			int eq = 1;
			for (int j = 0; j < J && eq; j++)
				eq = !used[j] || memcmp(a + 12 * (size_t)j, b + 12 * (size_t)j, 12 * sizeof *a) == 0;
			if (eq)
				same = q;
		}
		if (same >= 0) {
			g->qmap[p] = g->qmap[same];
		} else {
			g->qmap[p] = D;
			g->qpose[D++] = p;
		}
	}
	/* Pose 0's one matrix (every influence's), and its linear part's
	 * cofactors (a bind normal to a posed one), unless it is the
	 * identity. */
	{
		const float *S0 = g->skin;
		for (int e = 0; e < 12; e++) {
			g->pose0[e] = S0[e];
			if (g->pose0[e] != (e % 5 == 0 ? 1.0 : 0.0))
				g->pose0_mapped = 1;
		}
		const double *A = g->pose0;
		double *C = g->pose0_cof;
		C[0] = A[5] * A[10] - A[6] * A[9], C[1] = A[6] * A[8] - A[4] * A[10], C[2] = A[4] * A[9] - A[5] * A[8];
		C[3] = A[2] * A[9] - A[1] * A[10], C[4] = A[0] * A[10] - A[2] * A[8], C[5] = A[1] * A[8] - A[0] * A[9];
		C[6] = A[1] * A[6] - A[2] * A[5], C[7] = A[2] * A[4] - A[0] * A[6], C[8] = A[0] * A[5] - A[1] * A[4];
	}
	free(used);
	g->pose_count = P;
	g->qpose_count = D;
	/* One row per node; the nodes the collapses add reuse their parents'
	 * rows (qslot, bgm_apply), so the rows never grow. Every node's
	 * every stored pose is written below. */
	int qcap = g->node_count;
	g->quadric_cap = qcap;
	g->qslot = malloc(sizeof *g->qslot * (size_t)g->node_cap);
	if (!g->qslot) {
		r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory building posed quadrics");
		goto done;
	}
	g->qslot_cap = g->node_cap;
	for (int v = 0; v < g->node_count; v++)
		g->qslot[v] = v;
	g->quadric = malloc(sizeof *g->quadric * (size_t)qcap * (size_t)D * 10);
	g->rquad = malloc(sizeof *g->rquad * (size_t)qcap * BGM_RQUAD);
	if (!g->quadric || !g->rquad) {
		r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory building posed quadrics");
		goto done;
	}
	/* The stored poses' matrices as doubles, two side by side (the
	 * two-pose paths of bgm_quadric_error, bgm_quadric_pullback and
	 * lowerbound.c): block i holds stored poses 2i and 2i + 1, a last odd
	 * one a block of its own, itself in both lanes. */
	if (g->joint_count > 0 && P >= 2) {
		size_t pairs = (size_t)D / 2, blocks = ((size_t)D + 1) / 2;
		g->skin2 = malloc(sizeof(double) * 24 * (size_t)J * blocks);
		if (!g->skin2) {
			r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory building posed quadrics");
			goto done;
		}
		for (size_t i = 0; i < blocks; i++)
			for (int k = 0; k < J; k++) {
				const float *a = g->skin + ((size_t)g->qpose[2 * i] * (size_t)J + (size_t)k) * 12;
				const float *b = i < pairs ? g->skin + ((size_t)g->qpose[2 * i + 1] * (size_t)J + (size_t)k) * 12 : a;
				double *d = g->skin2 + (i * (size_t)J + (size_t)k) * 24;
				for (int e = 0; e < 12; e++)
					d[2 * e] = a[e], d[2 * e + 1] = b[e];
			}
	}
	int paired = 0;
#ifdef __SSE2__
	/* Two stored poses at a time (quadrics_pair), a last one alone. */
	if (g->joint_count > 0 && P >= 2) {
		__m128d *posed2 = malloc(sizeof(__m128d) * 3 * (size_t)g->node_count + 16);
		__m128d *fn2 = malloc(sizeof(__m128d) * 4 * (size_t)g->face_count + 16);
		__m128d *acc2 = malloc(sizeof(__m128d) * 10 * (size_t)g->node_count + 16);
		if (posed2 && fn2 && acc2) {
			for (int d = 0; d < D; d += 2)
				quadrics_pair(g, d, d + 1 < D ? d + 1 : d, posed2, fn2, acc2);
			paired = 1;
		}
		free(posed2);
		free(fn2);
		free(acc2);
		if (!paired) {
			r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory building posed quadrics");
			goto done;
		}
	}
#endif
	for (int d = 0; d < D && !paired; d++) {
		int p = g->qpose[d];
		double M[12];
		for (int v = 0; v < g->node_count; v++) {
			blend(g, p, &g->inf[v], M);
			apply(M, g->nodes[v].p, posed + 3 * v);
		}
		for (int f = 0; f < g->face_count; f++)
			fn[4 * f + 3] = -1.0;
		memset(acc, 0, sizeof(double) * 10 * (size_t)g->node_count);
		for (int f = 0; f < g->face_count; f++) {
			const bgm_face *F = &g->faces[f];
			double q[10] = {0};
			/* Its own normal: worked out once per pose (a neighbour may have),
			 * for its plane and its first edge. */
			double *nf = fn + 4 * f;
			if (nf[3] < 0.0) {
				bgm_face_normal(posed + 3 * F->n[0], posed + 3 * F->n[1], posed + 3 * F->n[2], nf);
				nf[3] = sqrt(dot3(nf, nf));
			}
			plane_quadric(posed + 3 * F->n[0], nf, q);
			for (int i = 0; i < 3; i++) {
				double *Q = acc + (size_t)F->n[i] * 10;
#ifdef __SSE2__
				/* two entries at a time, each the same sum */
				for (int k = 0; k < 10; k += 2)
					_mm_storeu_pd(Q + k, _mm_add_pd(_mm_loadu_pd(Q + k), _mm_loadu_pd(q + k)));
#else
				for (int k = 0; k < 10; k++)
					Q[k] += q[k];
#endif
			}
			/* Feature edges (borders, creases sharper than FEATURE_COS):
			 * a plane through the edge, perpendicular to the face, keeps
			 * collapses from sliding along the surface and cutting the
			 * feature short (the tip of a thin blade, a rim). */
			for (int e = 0; e < 3; e++) {
				int h = F->adj[e];
				if (h >= 0 && h < f)
					continue; /* each interior edge once */
				const double *a = posed + 3 * F->n[e], *b = posed + 3 * F->n[(e + 1) % 3];
				const double *o = posed + 3 * F->n[(e + 2) % 3];
				double n1[3];
				const double *n2 = NULL;
				if (e == 0) /* (a, b, o) is the face's own order */
					memcpy(n1, nf, sizeof n1);
				else
					bgm_face_normal(a, b, o, n1);
				if (h >= 0) {
					double *c = fn + 4 * h;
					if (c[3] < 0.0) {
						const bgm_face *H = &g->faces[h];
						bgm_face_normal(posed + 3 * H->n[0], posed + 3 * H->n[1], posed + 3 * H->n[2], c);
						c[3] = sqrt(dot3(c, c));
					}
					n2 = c;
					double l1 = e == 0 ? nf[3] : sqrt(dot3(n1, n1)), l2 = c[3];
					if (!(l1 > 0.0) || !(l2 > 0.0) || dot3(n1, n2) > FEATURE_COS * l1 * l2)
						continue;
				}
				double q2[10] = {0};
				edge_quadric(a, b, n1, q2);
				if (h >= 0)
					edge_quadric(a, b, n2, q2);
				int ends[2] = {F->n[e], F->n[(e + 1) % 3]};
				for (int i = 0; i < 2; i++) {
					double *Q = acc + (size_t)ends[i] * 10;
#ifdef __SSE2__
					/* two entries at a time, each the same sum */
					for (int k = 0; k < 10; k += 2)
						_mm_storeu_pd(Q + k, _mm_add_pd(_mm_loadu_pd(Q + k), _mm_loadu_pd(q2 + k)));
#else
					for (int k = 0; k < 10; k++)
						Q[k] += q2[k];
#endif
				}
			}
		}
		for (int v = 0; v < g->node_count; v++)
			qput(g->quadric + (size_t)g->qslot[v] * (size_t)D * 10, D, d, acc + (size_t)v * 10);
	}
	for (int v = 0; v < g->node_count; v++)
		bgm_quadric_rest_reset(g, v);
done:
	free(mats);
	free(rest);
	free(local);
	free(posed);
	free(fn);
	free(acc);
	return r;
}

#ifdef __SSE2__
/* Stored poses' terms kept for the sums over poses when some poses are
 * stored once for several (qmap): beyond this many stored poses each
 * pose's pair is worked out again. */
#define TERMS_MAX 128

/* The two stored poses' error terms (block i: stored poses 2i and
 * 2i + 1, u their entries, bgm_qat), each clamped at 0. */
BGM_INLINE __m128d err_pair(const mlod_bgm *g, const double *u, const mlod_influences *inf, size_t i, __m128d x0,
                               __m128d x1, __m128d x2)
{
	__m128d Mv[12], yv[3];
	blend2(g, i, inf, Mv);
#define ROW(r) _mm_add_pd(_mm_add_pd(_mm_add_pd(_mm_mul_pd(Mv[4 * r], x0), _mm_mul_pd(Mv[4 * r + 1], x1)), \
                                    _mm_mul_pd(Mv[4 * r + 2], x2)), \
                         Mv[4 * r + 3])
	yv[0] = ROW(0), yv[1] = ROW(1), yv[2] = ROW(2);
#undef ROW
	__m128d ev = eval2(u, yv);
	/* v > 0 ? v : 0 in the lanes */
	return _mm_and_pd(_mm_cmpgt_pd(ev, _mm_setzero_pd()), ev);
}
#endif

/* bgm_quadric_error_reach's early return: the partial sum that reached
 * stop into *reached (when not NULL). */
static inline double stopped(double e, double *reached)
{
	if (reached)
		*reached = e;
	return HUGE_VAL;
}

double bgm_quadric_error_reach(const mlod_bgm *g, const double *q, const mlod_influences *inf, const double *x, double stop,
                               double *reached)
{
	double M[12], y[3], e = 0.0;
	int P = g->pose_count, D = g->qpose_count;
#ifdef __SSE2__
	if (g->skin2 && inf->count > 0) {
		/* Two stored poses at a time; the sum and its stop test pose by
		 * pose. A last odd stored pose the same way, in both lanes (its
		 * own g->skin2 block, its entries doubled in last), the low lane
		 * taken. */
		const __m128d x0 = _mm_set1_pd(x[0]), x1 = _mm_set1_pd(x[1]), x2 = _mm_set1_pd(x[2]);
		int pairs = D / 2, n = (D + 1) / 2;
		_Alignas(16) double last[20];
		if (D & 1)
			for (int k = 0; k < 10; k++)
				last[2 * k] = last[2 * k + 1] = q[20 * (size_t)pairs + (size_t)k];
		if (D == P) {
			/* every pose stored, in order */
			for (int i = 0; i < n; i++) {
				double v[2];
				_mm_storeu_pd(v, err_pair(g, i < pairs ? q + 20 * (size_t)i : last, inf, (size_t)i, x0, x1, x2));
				e += v[0];
				if (e >= stop)
					return stopped(e, reached);
				if (i == pairs)
					break;
				e += v[1];
				if (e >= stop)
					return stopped(e, reached);
			}
			return e;
		}
		/* Pose p's term is its stored pose's: worked out when first
		 * needed (a stored pose comes first at its own pose, in order). */
		double t[TERMS_MAX];
		int done = 0;
		for (int p = 0; p < P; p++) {
			int d = g->qmap[p], i = d / 2;
			double v;
			if (2 * n <= TERMS_MAX) {
				for (; done <= i; done++)
					_mm_storeu_pd(t + 2 * done, err_pair(g, done < pairs ? q + 20 * (size_t)done : last, inf, (size_t)done,
					                                     x0, x1, x2));
				v = t[d];
			} else {
				double w[2];
				_mm_storeu_pd(w, err_pair(g, i < pairs ? q + 20 * (size_t)i : last, inf, (size_t)i, x0, x1, x2));
				v = w[d & 1];
			}
			e += v;
			if (e >= stop)
				return stopped(e, reached);
		}
		return e;
	}
#endif
	for (int p = 0; p < P; p++) {
		double a[10];
		bgm_quadric_get(q, D, g->qmap[p], a);
		blend(g, p, inf, M);
		apply(M, x, y);
		double v = eval(a, y);
		e += v > 0.0 ? v : 0.0;
		if (e >= stop)
			return stopped(e, reached);
	}
	return e;
}

double bgm_quadric_error(const mlod_bgm *g, const double *q, const mlod_influences *inf, const double *x, double stop)
{
	return bgm_quadric_error_reach(g, q, inf, x, stop, NULL);
}

void bgm_quadric_rest_reset(mlod_bgm *g, int v)
{
	int P = g->pose_count, D = g->qpose_count;
	const double *q = g->quadric + (size_t)g->qslot[v] * (size_t)D * 10;
	double *r = g->rquad + (size_t)g->qslot[v] * BGM_RQUAD, t = 0.0;
	for (int p = 0; p < P; p++) {
		int d = g->qmap[p];
		t += q[bgm_qat(D, d, 0)] + q[bgm_qat(D, d, 4)] + q[bgm_qat(D, d, 7)];
	}
	r[0] = NAN; /* not computed yet: bgm_quadric_rest */
	r[10] = t;
}

const double *bgm_quadric_rest(mlod_bgm *g, int v)
{
	double *r = g->rquad + (size_t)g->qslot[v] * BGM_RQUAD;
	/* NaN marks it unknown: a computed r[0] may round below 0 (a
	 * direction the planes leave free), which must not recompute it at
	 * every use. */
	if (isnan(r[0]))
		bgm_quadric_pullback(g, g->quadric + (size_t)g->qslot[v] * (size_t)g->qpose_count * 10, &g->inf[v], r);
	return r;
}

#ifdef __SSE2__
/* The two stored poses' pullback terms h[0..9] (block i, u their
 * entries): [M; 0 0 0 1]^T Q [M; 0 0 0 1] in the order of the one-pose
 * loop of bgm_quadric_pullback. */
BGM_INLINE void pull_pair(const mlod_bgm *g, const double *u, const mlod_influences *inf, size_t i, __m128d *h)
{
	__m128d M[12];
	blend2(g, i, inf, M);
#define a(e) QP(u, e)
#define MUL(x, y) _mm_mul_pd(x, y)
#define ADD(x, y) _mm_add_pd(x, y)
#define DOT3(a0, m0, a1, m1, a2, m2) ADD(ADD(MUL(a0, m0), MUL(a1, m1)), MUL(a2, m2))
	__m128d t00 = DOT3(a(0), M[0], a(1), M[4], a(2), M[8]);
	__m128d t01 = DOT3(a(0), M[1], a(1), M[5], a(2), M[9]);
	__m128d t02 = DOT3(a(0), M[2], a(1), M[6], a(2), M[10]);
	__m128d t10 = DOT3(a(1), M[0], a(4), M[4], a(5), M[8]);
	__m128d t11 = DOT3(a(1), M[1], a(4), M[5], a(5), M[9]);
	__m128d t12 = DOT3(a(1), M[2], a(4), M[6], a(5), M[10]);
	__m128d t20 = DOT3(a(2), M[0], a(5), M[4], a(7), M[8]);
	__m128d t21 = DOT3(a(2), M[1], a(5), M[5], a(7), M[9]);
	__m128d t22 = DOT3(a(2), M[2], a(5), M[6], a(7), M[10]);
	__m128d t03 = ADD(DOT3(a(0), M[3], a(1), M[7], a(2), M[11]), a(3));
	__m128d t13 = ADD(DOT3(a(1), M[3], a(4), M[7], a(5), M[11]), a(6));
	__m128d t23 = ADD(DOT3(a(2), M[3], a(5), M[7], a(7), M[11]), a(8));
	__m128d t33 = ADD(DOT3(a(3), M[3], a(6), M[7], a(8), M[11]), a(9));
	h[0] = DOT3(M[0], t00, M[4], t10, M[8], t20);
	h[1] = DOT3(M[0], t01, M[4], t11, M[8], t21);
	h[2] = DOT3(M[0], t02, M[4], t12, M[8], t22);
	h[3] = DOT3(M[0], t03, M[4], t13, M[8], t23);
	h[4] = DOT3(M[1], t01, M[5], t11, M[9], t21);
	h[5] = DOT3(M[1], t02, M[5], t12, M[9], t22);
	h[6] = DOT3(M[1], t03, M[5], t13, M[9], t23);
	h[7] = DOT3(M[2], t02, M[6], t12, M[10], t22);
	h[8] = DOT3(M[2], t03, M[6], t13, M[10], t23);
	h[9] = ADD(DOT3(M[3], t03, M[7], t13, M[11], t23), t33);
#undef a
#undef DOT3
#undef ADD
#undef MUL
}
#endif

/* h (10 doubles, packed as a quadric) = sum over poses of
 * [M_p; 0 0 0 1]^T Q_p [M_p; 0 0 0 1], M_p blended for inf: the posed
 * quadrics q pulled back into bind space. */
void bgm_quadric_pullback(const mlod_bgm *g, const double *q, const mlod_influences *inf, double *h)
{
	/* H's upper triangle, packed as a quadric: every entry a sum over
	 * poses from 0, each term in the order of the matrix products
	 * T = Q [M; 0 0 0 1] and [M; 0 0 0 1]^T T (the last row's zeros left
	 * out), written out entry by entry. */
	double H[10] = {0};
	int P = g->pose_count, D = g->qpose_count;
#ifdef __SSE2__
	if (g->skin2 && inf->count > 0) {
		/* Two stored poses at a time, the terms added to H pose by pose.
		 * A last odd stored pose the same way, in both lanes (its own
		 * g->skin2 block, its entries doubled in last), the low lane
		 * taken. Two entries of H to a register (Hv[j] = H[2j],
		 * H[2j + 1]), the terms regrouped to match. */
		int pairs = D / 2, n = (D + 1) / 2;
		_Alignas(16) double last[20];
		if (D & 1)
			for (int k = 0; k < 10; k++)
				last[2 * k] = last[2 * k + 1] = q[20 * (size_t)pairs + (size_t)k];
		__m128d Hv[5];
		for (int j = 0; j < 5; j++)
			Hv[j] = _mm_setzero_pd();
		if (D == P) {
			/* every pose stored, in order: H[e] += pose 2i's term, then
			 * += pose 2i + 1's (unpacklo: both entries' pose 2i terms) */
			for (int i = 0; i < n; i++) {
				__m128d t[10];
				pull_pair(g, i < pairs ? q + 20 * (size_t)i : last, inf, (size_t)i, t);
#define ACC(j) Hv[j] = _mm_add_pd(_mm_add_pd(Hv[j], _mm_unpacklo_pd(t[2 * j], t[2 * j + 1])), \
                                  _mm_unpackhi_pd(t[2 * j], t[2 * j + 1]))
#define ACC1(j) Hv[j] = _mm_add_pd(Hv[j], _mm_unpacklo_pd(t[2 * j], t[2 * j + 1]))
				if (i < pairs) {
					ACC(0), ACC(1), ACC(2), ACC(3), ACC(4);
				} else {
					ACC1(0), ACC1(1), ACC1(2), ACC1(3), ACC1(4);
				}
#undef ACC1
#undef ACC
			}
		} else if (n <= TERMS_MAX / 2) {
			/* Pose p's terms are its stored pose's, each stored pair's
			 * worked out when first needed (a stored pose comes first at
			 * its own pose, in order) and kept; poses in order, two at a
			 * time where two poses in a row are a stored pair. */
			__m128d hb[TERMS_MAX / 2][10];
			int done = 0;
			for (int p = 0; p < P;) {
				int d = g->qmap[p], i = d / 2;
				for (; done <= i; done++)
					pull_pair(g, done < pairs ? q + 20 * (size_t)done : last, inf, (size_t)done, hb[done]);
				const __m128d *t = hb[i];
#define ACC(j) Hv[j] = _mm_add_pd(_mm_add_pd(Hv[j], _mm_unpacklo_pd(t[2 * j], t[2 * j + 1])), \
                                  _mm_unpackhi_pd(t[2 * j], t[2 * j + 1]))
#define ACCL(j) Hv[j] = _mm_add_pd(Hv[j], _mm_unpacklo_pd(t[2 * j], t[2 * j + 1]))
#define ACCH(j) Hv[j] = _mm_add_pd(Hv[j], _mm_unpackhi_pd(t[2 * j], t[2 * j + 1]))
				if ((d & 1) == 0 && i < pairs && p + 1 < P && g->qmap[p + 1] == d + 1) {
					ACC(0), ACC(1), ACC(2), ACC(3), ACC(4);
					p += 2;
				} else {
					if (d & 1)
						ACCH(0), ACCH(1), ACCH(2), ACCH(3), ACCH(4);
					else
						ACCL(0), ACCL(1), ACCL(2), ACCL(3), ACCL(4);
					p++;
				}
#undef ACCH
#undef ACCL
#undef ACC
			}
		} else {
			for (int p = 0; p < P; p++) {
				int d = g->qmap[p], i = d / 2;
				__m128d t[10];
				double ht[10][2];
				pull_pair(g, i < pairs ? q + 20 * (size_t)i : last, inf, (size_t)i, t);
				for (int k = 0; k < 10; k++)
					_mm_storeu_pd(ht[k], t[k]);
				for (int j = 0; j < 5; j++)
					Hv[j] = _mm_add_pd(Hv[j], _mm_set_pd(ht[2 * j + 1][d & 1], ht[2 * j][d & 1]));
			}
		}
		for (int j = 0; j < 5; j++)
			_mm_storeu_pd(H + 2 * j, Hv[j]);
		memcpy(h, H, sizeof H);
		return;
	}
#endif
	for (int p = 0; p < P; p++) {
		double M[12], a[10];
		bgm_quadric_get(q, D, g->qmap[p], a);
		blend(g, p, inf, M);
		double t00 = a[0] * M[0] + a[1] * M[4] + a[2] * M[8];
		double t01 = a[0] * M[1] + a[1] * M[5] + a[2] * M[9];
		double t02 = a[0] * M[2] + a[1] * M[6] + a[2] * M[10];
		double t10 = a[1] * M[0] + a[4] * M[4] + a[5] * M[8];
		double t11 = a[1] * M[1] + a[4] * M[5] + a[5] * M[9];
		double t12 = a[1] * M[2] + a[4] * M[6] + a[5] * M[10];
		double t20 = a[2] * M[0] + a[5] * M[4] + a[7] * M[8];
		double t21 = a[2] * M[1] + a[5] * M[5] + a[7] * M[9];
		double t22 = a[2] * M[2] + a[5] * M[6] + a[7] * M[10];
		double t03 = a[0] * M[3] + a[1] * M[7] + a[2] * M[11] + a[3];
		double t13 = a[1] * M[3] + a[4] * M[7] + a[5] * M[11] + a[6];
		double t23 = a[2] * M[3] + a[5] * M[7] + a[7] * M[11] + a[8];
		double t33 = a[3] * M[3] + a[6] * M[7] + a[8] * M[11] + a[9];
		H[0] += M[0] * t00 + M[4] * t10 + M[8] * t20;
		H[1] += M[0] * t01 + M[4] * t11 + M[8] * t21;
		H[2] += M[0] * t02 + M[4] * t12 + M[8] * t22;
		H[3] += M[0] * t03 + M[4] * t13 + M[8] * t23;
		H[4] += M[1] * t01 + M[5] * t11 + M[9] * t21;
		H[5] += M[1] * t02 + M[5] * t12 + M[9] * t22;
		H[6] += M[1] * t03 + M[5] * t13 + M[9] * t23;
		H[7] += M[2] * t02 + M[6] * t12 + M[10] * t22;
		H[8] += M[2] * t03 + M[6] * t13 + M[10] * t23;
		H[9] += M[3] * t03 + M[7] * t13 + M[11] * t23 + t33;
	}
	memcpy(h, H, sizeof H);
}

int bgm_quadric_solve(const double *h, const double *x0, double *out)
{
	/* Solve (H[0..2][0..2] + mu I) x = -H[0..2][3] + mu x0 by Cramer's
	 * rule: the small mu pins the directions the quadric leaves free
	 * (flat regions, creases) at x0 instead of leaving them singular. */
	double tr = h[0] + h[4] + h[7];
	if (!(tr > 0.0) || !isfinite(tr))
		return -1;
	double mu = 1e-5 * tr;
	double a = h[0] + mu, b = h[1], c = h[2], d = h[4] + mu, e = h[5], f = h[7] + mu;
	double det = a * (d * f - e * e) - b * (b * f - c * e) + c * (b * e - c * d);
	if (!(fabs(det) > 0.0))
		return -1;
	double r0 = -h[3] + mu * x0[0], r1 = -h[6] + mu * x0[1], r2 = -h[8] + mu * x0[2];
	out[0] = (r0 * (d * f - e * e) - b * (r1 * f - e * r2) + c * (r1 * e - d * r2)) / det;
	out[1] = (a * (r1 * f - e * r2) - r0 * (b * f - c * e) + c * (b * r2 - r1 * c)) / det;
	out[2] = (a * (d * r2 - r1 * e) - b * (b * r2 - r1 * c) + r0 * (b * e - c * d)) / det;
	return isfinite(out[0]) && isfinite(out[1]) && isfinite(out[2]) ? 0 : -1;
}

int bgm_quadric_optimum(const mlod_bgm *g, const double *q, const mlod_influences *inf, const double *x0, double *out)
{
	double h[10];
	bgm_quadric_pullback(g, q, inf, h);
	return bgm_quadric_solve(h, x0, out);
}
