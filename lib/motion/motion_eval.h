/*
 * motion_eval.h: internal to lib/motion. Fast forms of the sampling,
 * forward kinematics and point error the motion layer measures with, each
 * giving bit for bit the result of the library function it stands for
 * (mlod_clip_sample, mlod_mat4_mul on an affine local matrix,
 * mlod_motion_point_error compared with a limit), so the levels and their
 * errors are the same as with the plain functions, only faster.
 *
 * - Sampling walks increasing times with a cursor per channel instead of
 *   a binary search, and keeps per segment what mlod_quat_slerp computes
 *   from the two keys alone (the normalised keys, their angle and its
 *   sine); per sample it then does the rest of mlod_quat_slerp's
 *   operations, in its order.
 * - A local matrix from mlod_mat4_from_trs has the last row (0, 0, 0, 1),
 *   so in parent * local the terms mlod_mat4_mul adds for it are exact
 *   zeros (or the parent's translation times 1): they are left out.
 * - sigma_max(A) <= |A|_F: a joint whose origin error plus radius times
 *   the Frobenius norm (with a margin far above rounding) is within the
 *   limit is within it; the others take cheaper bounds of sigma_max before
 *   sigma_max itself (eval_point_error_within, pointerror.c).
 * - eval_wrap_angle: mlod_wrap_angle without fmod where fmod's exact
 *   result is known.
 */
#ifndef MLOD_MOTION_EVAL_H
#define MLOD_MOTION_EVAL_H

/* The small hot helpers below are inlined where GCC would call them. */
#if defined(__GNUC__)
#define EVAL_INLINE static inline __attribute__((always_inline))
#else
#define EVAL_INLINE static inline
#endif

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "motion/mlod_motion.h"

/* The hottest loops (the key reduction's sample checks, the rounding's
 * per-channel tries) are compiled twice: as the rest of the library, and
 * for x86 CPUs with AVX2 (GCC's target attribute; EVAL_TARGET_AVX2 on
 * the second copy), chosen at run time (eval_avx2). The second copy
 * runs the same C on the same floats: the same IEEE operations in the
 * same order, only encoded with VEX (three-operand forms, broadcasts
 * from memory), so fewer instructions; no fused multiply-add (AVX2 does
 * not imply FMA, and -std=c11 does not contract). The same bytes either
 * way (test keys_avx2_same_as_generic). */
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
#define EVAL_HAVE_AVX2 1
#define EVAL_TARGET_AVX2 __attribute__((target("avx2")))
#else
#define EVAL_HAVE_AVX2 0
#define EVAL_TARGET_AVX2
#endif

/* For tests: nonzero makes eval_avx2 answer 0 (the generic copies run). */
extern int motion_eval_generic_only;

/* Should the AVX2 copies run? */
static inline int eval_avx2(void)
{
#if EVAL_HAVE_AVX2
	return !motion_eval_generic_only && __builtin_cpu_supports("avx2");
#else
	return 0;
#endif
}

/* Margin on the Frobenius bound: the computed sigma_max is the exact one
 * times (1 + 1e-9) plus rounding far below 1e-12 relative. */
#define EVAL_FROB_MARGIN (1.0 + 1e-6)

/* parent * local, local affine with last row (0, 0, 0, 1) as
 * mlod_mat4_from_trs makes it: rows 0 to 2 as mlod_mat4_mul computes
 * them (same products, same order of the sums, lane by lane when GCC's
 * vector extension computes a column at once); the last row (0, 0, 0, 1). */
#if defined(__GNUC__)
typedef float eval_v4 __attribute__((vector_size(16)));
typedef int32_t eval_v4i __attribute__((vector_size(16)));
#endif

EVAL_INLINE mlod_mat4 eval_mul_affine(const mlod_mat4 *a, const mlod_mat4 *b)
{
	mlod_mat4 r;
#if defined(__GNUC__)
	eval_v4 a0, a1, a2, a3;
	memcpy(&a0, a->m, sizeof a0);
	memcpy(&a1, a->m + 4, sizeof a1);
	memcpy(&a2, a->m + 8, sizeof a2);
	memcpy(&a3, a->m + 12, sizeof a3);
	/* Column by column, written out (the loop was not unrolled). */
	eval_v4 s0 = a0 * b->m[0], s1 = a0 * b->m[4], s2 = a0 * b->m[8], s3 = a0 * b->m[12];
	s0 = s0 + a1 * b->m[1], s1 = s1 + a1 * b->m[5], s2 = s2 + a1 * b->m[9], s3 = s3 + a1 * b->m[13];
	s0 = s0 + a2 * b->m[2], s1 = s1 + a2 * b->m[6], s2 = s2 + a2 * b->m[10], s3 = s3 + a2 * b->m[14];
	s3 = s3 + a3;
	/* The last row (0, 0, 0, 1) set in the vectors (lane 3 cleared, then
	 * 1.0f's bits in the last), so the columns go out as they are
	 * instead of through scalar stores. */
	const eval_v4i keep = { -1, -1, -1, 0 }, one = { 0, 0, 0, 0x3f800000 };
	s0 = (eval_v4)((eval_v4i)s0 & keep);
	s1 = (eval_v4)((eval_v4i)s1 & keep);
	s2 = (eval_v4)((eval_v4i)s2 & keep);
	s3 = (eval_v4)(((eval_v4i)s3 & keep) | one);
	memcpy(r.m, &s0, sizeof s0);
	memcpy(r.m + 4, &s1, sizeof s1);
	memcpy(r.m + 8, &s2, sizeof s2);
	memcpy(r.m + 12, &s3, sizeof s3);
#else
	for (int c = 0; c < 4; c++) {
		const float b0 = b->m[c * 4], b1 = b->m[c * 4 + 1], b2 = b->m[c * 4 + 2];
		for (int row = 0; row < 3; row++) {
			float s = a->m[row] * b0;
			s += a->m[4 + row] * b1;
			s += a->m[8 + row] * b2;
			if (c == 3)
				s += a->m[12 + row];
			r.m[c * 4 + row] = s;
		}
	}
#endif
#if !defined(__GNUC__)
	r.m[3] = r.m[7] = r.m[11] = 0.0f;
	r.m[15] = 1.0f;
#endif
	return r;
}

/* eval_mul_affine with two columns in each 8-float vector: columns 0 and
 * 1, then 2 and 3, each lane the same products and sums in the same order
 * (column 2's lanes add -0.0f where column 3's add the translation: x +
 * -0 is x for every float x, a zero's sign included). Only for the AVX2
 * copies (wide: a constant there); elsewhere GCC would split the vectors
 * in two. 34 instructions against 53 (GCC 12, -O2 -mavx2). */
#if defined(__GNUC__) && !defined(__clang__) && EVAL_HAVE_AVX2
typedef float eval_v8 __attribute__((vector_size(32)));
typedef int32_t eval_v8i __attribute__((vector_size(32)));

EVAL_INLINE mlod_mat4 eval_mul_affine8(const mlod_mat4 *a, const mlod_mat4 *b)
{
	mlod_mat4 r;
	eval_v4 a0, a1, a2, a3;
	memcpy(&a0, a->m, sizeof a0);
	memcpy(&a1, a->m + 4, sizeof a1);
	memcpy(&a2, a->m + 8, sizeof a2);
	memcpy(&a3, a->m + 12, sizeof a3);
	const eval_v4 mz = { -0.0f, -0.0f, -0.0f, -0.0f };
	const eval_v8 A0 = __builtin_shufflevector(a0, a0, 0, 1, 2, 3, 0, 1, 2, 3);
	const eval_v8 A1 = __builtin_shufflevector(a1, a1, 0, 1, 2, 3, 0, 1, 2, 3);
	const eval_v8 A2 = __builtin_shufflevector(a2, a2, 0, 1, 2, 3, 0, 1, 2, 3);
	const eval_v8 A3 = __builtin_shufflevector(mz, a3, 0, 1, 2, 3, 4, 5, 6, 7);
	eval_v8 b01, b23;
	memcpy(&b01, b->m, sizeof b01);
	memcpy(&b23, b->m + 8, sizeof b23);
	/* Lanes 0-3 take column c's entry k, lanes 4-7 column c + 1's. */
	const eval_v8i k0 = { 0, 0, 0, 0, 4, 4, 4, 4 }, k1 = { 1, 1, 1, 1, 5, 5, 5, 5 }, k2 = { 2, 2, 2, 2, 6, 6, 6, 6 };
	eval_v8 s01 = A0 * __builtin_shuffle(b01, k0), s23 = A0 * __builtin_shuffle(b23, k0);
	s01 = s01 + A1 * __builtin_shuffle(b01, k1), s23 = s23 + A1 * __builtin_shuffle(b23, k1);
	s01 = s01 + A2 * __builtin_shuffle(b01, k2), s23 = s23 + A2 * __builtin_shuffle(b23, k2);
	s23 = s23 + A3;
	const eval_v8i keep = { -1, -1, -1, 0, -1, -1, -1, 0 }, one = { 0, 0, 0, 0, 0, 0, 0, 0x3f800000 };
	s01 = (eval_v8)((eval_v8i)s01 & keep);
	s23 = (eval_v8)(((eval_v8i)s23 & keep) | one);
	memcpy(r.m, &s01, sizeof s01);
	memcpy(r.m + 8, &s23, sizeof s23);
	return r;
}
#define EVAL_HAVE_MUL8 1
#else
#define EVAL_HAVE_MUL8 0
#endif

/* eval_mul_affine, with wide (a constant in each copy) the AVX2 form. */
EVAL_INLINE mlod_mat4 eval_mul_affine_w(const mlod_mat4 *a, const mlod_mat4 *b, int wide)
{
#if EVAL_HAVE_MUL8
	if (wide)
		return eval_mul_affine8(a, b);
#endif
	(void)wide;
	return eval_mul_affine(a, b);
}

/* mlod_mat4_mul(a, b), the same floats: each entry summed from 0.0f in
 * its order (0 + a0 b0, + a1 b1, + a2 b2, + a3 b3; the first sum keeps
 * a -0 product's +0), a column's four rows at once where GCC's vector
 * extension is there. For a root's base times its local matrix. */
EVAL_INLINE mlod_mat4 eval_mul(const mlod_mat4 *a, const mlod_mat4 *b)
{
	mlod_mat4 r;
#if defined(__GNUC__)
	eval_v4 a0, a1, a2, a3;
	memcpy(&a0, a->m, sizeof a0);
	memcpy(&a1, a->m + 4, sizeof a1);
	memcpy(&a2, a->m + 8, sizeof a2);
	memcpy(&a3, a->m + 12, sizeof a3);
	const eval_v4 zero = { 0.0f, 0.0f, 0.0f, 0.0f };
	for (int c = 0; c < 4; c++) {
		eval_v4 s = zero + a0 * b->m[c * 4];
		s = s + a1 * b->m[c * 4 + 1];
		s = s + a2 * b->m[c * 4 + 2];
		s = s + a3 * b->m[c * 4 + 3];
		memcpy(r.m + c * 4, &s, sizeof s);
	}
#else
	r = mlod_mat4_mul(a, b);
#endif
	return r;
}

/* mlod_mat4_from_trs, the same operations, inline. */
EVAL_INLINE mlod_mat4 eval_from_trs(const mlod_trs *trs)
{
	double x = trs->r.x, y = trs->r.y, z = trs->r.z, w = trs->r.w;
	double n = x * x + y * y + z * z + w * w;
	double s = n > 0.0 ? 2.0 / n : 0.0;
	double r[3][3];
	r[0][0] = 1 - s * (y * y + z * z); r[0][1] = s * (x * y - w * z);     r[0][2] = s * (x * z + w * y);
	r[1][0] = s * (x * y + w * z);     r[1][1] = 1 - s * (x * x + z * z); r[1][2] = s * (y * z - w * x);
	r[2][0] = s * (x * z - w * y);     r[2][1] = s * (y * z + w * x);     r[2][2] = 1 - s * (x * x + y * y);
	const double sx = trs->s.x, sy = trs->s.y, sz = trs->s.z;
	mlod_mat4 m;
	/* Written out (GCC kept the loops): column c scaled by s[c]. */
	m.m[0] = (float)(r[0][0] * sx), m.m[1] = (float)(r[1][0] * sx), m.m[2] = (float)(r[2][0] * sx), m.m[3] = 0.0f;
	m.m[4] = (float)(r[0][1] * sy), m.m[5] = (float)(r[1][1] * sy), m.m[6] = (float)(r[2][1] * sy), m.m[7] = 0.0f;
	m.m[8] = (float)(r[0][2] * sz), m.m[9] = (float)(r[1][2] * sz), m.m[10] = (float)(r[2][2] * sz), m.m[11] = 0.0f;
	m.m[12] = trs->t.x;
	m.m[13] = trs->t.y;
	m.m[14] = trs->t.z;
	m.m[15] = 1.0f;
	return m;
}

/* An upper bound of mlod_motion_point_error(w, w0, radius) from float
 * arithmetic: each difference of two floats is their exact difference
 * within a relative 2^-24, the sums of squares and square roots add a few
 * more such roundings, and underflowed squares lose less than 1e-18 in
 * the roots: the factor 1 + 1e-5 and that absolute term cover them (and
 * sigma_max <= Frobenius norm). Lane 3 of each column (the last row) only
 * adds. Inf or NaN when the matrices hold them. */
static inline double eval_error_bound(const mlod_mat4 *w, const mlod_mat4 *w0, double radius)
{
#if defined(__GNUC__)
	/* Written out: GCC kept the loop over the columns, and the differences
	 * on the stack. */
	eval_v4 x0, x1, x2, x3, y0, y1, y2, y3;
	memcpy(&x0, w->m, sizeof x0);
	memcpy(&x1, w->m + 4, sizeof x1);
	memcpy(&x2, w->m + 8, sizeof x2);
	memcpy(&x3, w->m + 12, sizeof x3);
	memcpy(&y0, w0->m, sizeof y0);
	memcpy(&y1, w0->m + 4, sizeof y1);
	memcpy(&y2, w0->m + 8, sizeof y2);
	memcpy(&y3, w0->m + 12, sizeof y3);
	eval_v4 d0 = x0 - y0, d1 = x1 - y1, d2 = x2 - y2, d3 = x3 - y3;
	eval_v4 f = d0 * d0 + d1 * d1 + d2 * d2, t = d3 * d3;
#if defined(__clang__)
	float frob = (f[0] + f[1]) + (f[2] + f[3]), dp2 = (t[0] + t[1]) + (t[2] + t[3]);
#else
	/* The same sums, both at once: (f0 + f1, f2 + f3, t0 + t1, t2 + t3),
	 * then each pair's sum in lanes 0 and 2. */
	const eval_v4i even = { 0, 2, 4, 6 }, odd = { 1, 3, 5, 7 }, swap = { 1, 0, 3, 2 };
	eval_v4 p = __builtin_shuffle(f, t, even) + __builtin_shuffle(f, t, odd);
	p = p + __builtin_shuffle(p, swap);
#if defined(__SSE__)
	/* Both roots in one instruction (the same IEEE square roots, without
	 * sqrtf's errno test: the sums are never negative). */
	p = __builtin_ia32_sqrtps(p);
	return ((double)p[2] + radius * (double)p[0]) * (1.0 + 1e-5) + 1e-18 * (1.0 + radius);
#endif
	float frob = p[0], dp2 = p[2];
#endif
#else
	float frob = 0.0f, dp2 = 0.0f;
	for (int i = 0; i < 16; i++) {
		float x = w->m[i] - w0->m[i];
		if (i < 12)
			frob += x * x;
		else
			dp2 += x * x;
	}
#endif
	return ((double)sqrtf(dp2) + radius * (double)sqrtf(frob)) * (1.0 + 1e-5) + 1e-18 * (1.0 + radius);
}

/* eval_error_bound, with wide (a constant in each copy) two columns in
 * each 8-float vector in the AVX2 copies: the same differences and
 * squares lane by lane, and the sum d0 d0 + d1 d1 + d2 d2 in its order
 * (the low half of columns 0-1 plus their high half, plus column 2), then
 * eval_error_bound's own sums and roots. */
EVAL_INLINE double eval_error_bound_w(const mlod_mat4 *w, const mlod_mat4 *w0, double radius, int wide)
{
#if EVAL_HAVE_MUL8 && defined(__SSE__)
	if (wide) {
		eval_v8 x01, x23, y01, y23;
		memcpy(&x01, w->m, sizeof x01);
		memcpy(&x23, w->m + 8, sizeof x23);
		memcpy(&y01, w0->m, sizeof y01);
		memcpy(&y23, w0->m + 8, sizeof y23);
		eval_v8 d01 = x01 - y01, d23 = x23 - y23;
		eval_v8 q01 = d01 * d01, q23 = d23 * d23;
		eval_v4 f = __builtin_shufflevector(q01, q01, 0, 1, 2, 3) + __builtin_shufflevector(q01, q01, 4, 5, 6, 7);
		f = f + __builtin_shufflevector(q23, q23, 0, 1, 2, 3);
		eval_v4 t = __builtin_shufflevector(q23, q23, 4, 5, 6, 7);
		const eval_v4i even = { 0, 2, 4, 6 }, odd = { 1, 3, 5, 7 }, swap = { 1, 0, 3, 2 };
		eval_v4 p = __builtin_shuffle(f, t, even) + __builtin_shuffle(f, t, odd);
		p = p + __builtin_shuffle(p, swap);
		p = __builtin_ia32_sqrtps(p);
		return ((double)p[2] + radius * (double)p[0]) * (1.0 + 1e-5) + 1e-18 * (1.0 + radius);
	}
#endif
	(void)wide;
	return eval_error_bound(w, w0, radius);
}

/* mlod_motion_point_error(w, w0, radius) <= limit, exactly that answer,
 * its largest singular value computed only when cheaper bounds of it
 * cannot tell (pointerror.c). */
int eval_point_error_within(const mlod_mat4 *w, const mlod_mat4 *w0, double radius, double limit);
#if EVAL_HAVE_AVX2
/* mlod_motion_point_within compiled for AVX2 (pointerror.c). */
int motion_point_within_avx2(const mlod_mat4 *w, const mlod_mat4 *w0, double radius, double budget);
#endif

/* Is mlod_motion_point_error(w, w0, radius) <= limit? Exactly that
 * answer; the exact error is computed only when the bounds cannot tell. */
EVAL_INLINE int eval_within_w(const mlod_mat4 *w, const mlod_mat4 *w0, double radius, double limit, int wide)
{
	if (eval_error_bound_w(w, w0, radius, wide) <= limit)
		return 1;
	double dx = (double)w->m[12] - w0->m[12], dy = (double)w->m[13] - w0->m[13], dz = (double)w->m[14] - w0->m[14];
	double dp = sqrt(dx * dx + dy * dy + dz * dz), frob = 0.0;
	for (int c = 0; c < 3; c++)
		for (int r = 0; r < 3; r++) {
			double a = (double)w->m[c * 4 + r] - w0->m[c * 4 + r];
			frob += a * a;
		}
	if (dp + radius * (sqrt(frob) * EVAL_FROB_MARGIN) <= limit)
		return 1;
	return eval_point_error_within(w, w0, radius, limit);
}

EVAL_INLINE int eval_within(const mlod_mat4 *w, const mlod_mat4 *w0, double radius, double limit)
{
	return eval_within_w(w, w0, radius, limit, 0);
}

/* The worst of a running maximum and an error from eval_error_over (-1:
 * within it); a NaN is the worst and stays so. */
EVAL_INLINE double eval_worst(double worst, double e)
{
	if (worst != worst || e != e)
		return worst != worst ? worst : e;
	return e > worst ? e : worst;
}

/* mlod_motion_point_error(w, w0, radius), or -1 when a bound shows that
 * it is at most limit. */
EVAL_INLINE double eval_error_over(const mlod_mat4 *w, const mlod_mat4 *w0, double radius, double limit)
{
	if (eval_error_bound(w, w0, radius) <= limit)
		return -1.0;
	double dx = (double)w->m[12] - w0->m[12], dy = (double)w->m[13] - w0->m[13], dz = (double)w->m[14] - w0->m[14];
	double dp = sqrt(dx * dx + dy * dy + dz * dz), frob = 0.0;
	for (int c = 0; c < 3; c++)
		for (int r = 0; r < 3; r++) {
			double a = (double)w->m[c * 4 + r] - w0->m[c * 4 + r];
			frob += a * a;
		}
	if (dp + radius * (sqrt(frob) * EVAL_FROB_MARGIN) <= limit || eval_point_error_within(w, w0, radius, limit))
		return -1.0; /* the callers keep the largest error: one within the limit changes nothing */
	return mlod_motion_point_error(w, w0, radius);
}

/* mlod_wrap_angle(a), the same double: for x = a + pi in (0, 2 pi),
 * fmod(x, 2 pi) is x itself (fmod is exact, and returns x for 0 <= x < y),
 * so the call is left out; and so for x in [2 pi, 4 pi), where fmod's
 * exact result is x - 2 pi (a difference of two doubles within a factor
 * two of each other, exact: Sterbenz), and for x in (-2 pi, 0], where it
 * is x (then x <= 0 takes 2 pi, as mlod_wrap_angle does). */
static inline double eval_wrap_angle(double a)
{
	const double y = 2.0 * MLOD_PI;
	double x = a + MLOD_PI;
	if (x > 0.0 && x < y)
		return x - MLOD_PI;
	if (x >= y && x < 2.0 * y) {
		x -= y;
		if (x <= 0.0)
			x += y;
		return x - MLOD_PI;
	}
	if (x > -y && x <= 0.0)
		return (x + y) - MLOD_PI;
	return mlod_wrap_angle(a);
}

/* Per channel: the segment a cursor is in and what slerp needs of it. */
typedef struct eval_seg {
	int k;               /* first key of the segment, -1: none yet */
	int ready;           /* rotation data below filled for k */
	int near;            /* |dot| > 0.9995: slerp blends linearly */
	mlod_quat a, b;      /* the keys, normalised */
	double sign, theta, s;
} eval_seg;

#if defined(__GNUC__)
typedef double eval_v2d __attribute__((vector_size(16)));
#endif

/* (float)(x / n) ... for the four components: two lanes at a time where
 * GCC's vector extension is there (each lane the same IEEE division). */
static inline mlod_quat eval_div4(double x, double y, double z, double w, double n)
{
#if defined(__GNUC__)
	eval_v2d a = { x, y }, b = { z, w }, d = { n, n };
	a = a / d;
	b = b / d;
	mlod_quat r = { (float)a[0], (float)a[1], (float)b[0], (float)b[1] };
#else
	mlod_quat r = { (float)(x / n), (float)(y / n), (float)(z / n), (float)(w / n) };
#endif
	return r;
}

/* mlod_quat_normalize, the same operations, inline. */
static inline mlod_quat eval_normalize(mlod_quat q)
{
	double n = sqrt((double)q.x * q.x + (double)q.y * q.y + (double)q.z * q.z + (double)q.w * q.w);
	if (!(n > 0.0) || !isfinite(n))
		return mlod_quat_identity();
	return eval_div4(q.x, q.y, q.z, q.w, n);
}

static inline mlod_quat eval_blend(mlod_quat a, double wa, mlod_quat b, double wb)
{
	double x = wa * a.x + wb * b.x, y = wa * a.y + wb * b.y;
	double z = wa * a.z + wb * b.z, w = wa * a.w + wb * b.w;
	double n = sqrt(x * x + y * y + z * z + w * w);
	if (!(n > 0.0))
		return mlod_quat_identity();
	return eval_div4(x, y, z, w, n);
}

/* mlod_quat_slerp(ka, kb, u) with the segment's keys ka, kb (float[4]). */
EVAL_INLINE mlod_quat eval_slerp(eval_seg *sg, const float *ka, const float *kb, float u)
{
	if (!sg->ready) {
		sg->a = eval_normalize((mlod_quat){ ka[0], ka[1], ka[2], ka[3] });
		sg->b = eval_normalize((mlod_quat){ kb[0], kb[1], kb[2], kb[3] });
		double d = (double)sg->a.x * sg->b.x + (double)sg->a.y * sg->b.y + (double)sg->a.z * sg->b.z +
		           (double)sg->a.w * sg->b.w;
		sg->sign = d < 0.0 ? -1.0 : 1.0;
		d = fabs(d);
		sg->near = d > 0.9995;
		if (!sg->near) {
			sg->theta = acos(d);
			sg->s = sin(sg->theta);
		}
		sg->ready = 1;
	}
	if (sg->near)
		return eval_blend(sg->a, 1.0 - u, sg->b, sg->sign * u);
	return eval_blend(sg->a, sin((1.0 - u) * sg->theta) / sg->s, sg->b, sg->sign * sin(u * sg->theta) / sg->s);
}

/* The key k with times[k] <= t < times[k + 1] (times[0] < t < times[n - 1]),
 * from the cursor's segment forward (or by bisection when t went back). */
static inline int eval_find(const float *times, int n, int k, float t)
{
	if (k < 0 || k >= n - 1 || times[k] > t) {
		int lo = 0, hi = n - 1;
		while (hi - lo > 1) {
			int mid = lo + (hi - lo) / 2;
			if (times[mid] <= t)
				lo = mid;
			else
				hi = mid;
		}
		return lo;
	}
	while (times[k + 1] <= t)
		k++;
	return k;
}

/* One channel (LINEAR or STEP) at t (already clamped as mlod_clip_sample
 * clamps it) into out, comps floats, as mlod_clip_sample's sampling;
 * rotations come out as the slerp (not yet normalised). */
EVAL_INLINE void eval_channel(const mlod_channel *ch, eval_seg *sg, float t, float *out)
{
	const int n = ch->key_count, comps = ch->path == MLOD_PATH_ROTATION ? 4 : 3;
	const float *v = ch->values;
	if (n == 1 || !(t > ch->times[0])) {
		memcpy(out, v, (size_t)comps * sizeof *out);
		return;
	}
	if (t >= ch->times[n - 1]) {
		memcpy(out, v + (size_t)(n - 1) * (size_t)comps, (size_t)comps * sizeof *out);
		return;
	}
	int k = eval_find(ch->times, n, sg->k, t);
	if (k != sg->k) {
		sg->k = k;
		sg->ready = 0;
	}
	const float *a = v + (size_t)k * (size_t)comps, *b = a + comps;
	if (ch->interp == MLOD_INTERP_STEP) {
		memcpy(out, a, (size_t)comps * sizeof *out);
		return;
	}
	const float t0 = ch->times[k], t1 = ch->times[k + 1], dt = t1 - t0;
	const float u = (t - t0) / dt;
	if (comps == 4) {
		mlod_quat q = eval_slerp(sg, a, b, u);
		out[0] = q.x, out[1] = q.y, out[2] = q.z, out[3] = q.w;
	} else {
		for (int c = 0; c < 3; c++)
			out[c] = a[c] + (b[c] - a[c]) * u;
	}
}

/* Can eval_sample sample this clip (LINEAR and STEP channels only)? */
static inline int eval_clip_ok(const mlod_clip *clip)
{
	for (int i = 0; i < clip->channel_count; i++)
		if (clip->channels[i].interp == MLOD_INTERP_CUBICSPLINE)
			return 0;
	return 1;
}

/* mlod_clip_sample(clip, t, local) for a clip eval_clip_ok accepts, with
 * one eval_seg per channel (k = -1 at first). */
EVAL_INLINE void eval_sample(const mlod_clip *clip, eval_seg *segs, float t, mlod_trs *local)
{
	if (!(t > 0.0f))
		t = 0.0f;
	if (t > clip->duration)
		t = clip->duration;
	for (int i = 0; i < clip->channel_count; i++) {
		const mlod_channel *ch = &clip->channels[i];
		mlod_trs *l = &local[ch->joint];
		float v[4];
		if (ch->key_count < 1)
			continue;
		eval_channel(ch, &segs[i], t, v);
		switch (ch->path) {
		case MLOD_PATH_TRANSLATION: l->t.x = v[0], l->t.y = v[1], l->t.z = v[2]; break;
		case MLOD_PATH_SCALE: l->s.x = v[0], l->s.y = v[1], l->s.z = v[2]; break;
		case MLOD_PATH_ROTATION: l->r = eval_normalize((mlod_quat){ v[0], v[1], v[2], v[3] }); break;
		}
	}
}

/* mlod_pose_world with eval_mul_affine. */
static inline void eval_pose_world(const mlod_skeleton *s, const mlod_trs *local, mlod_mat4 *world)
{
	for (int i = 0; i < s->joint_count; i++) {
		const mlod_joint *j = &s->joints[i];
		mlod_mat4 l = eval_from_trs(&local[i]);
		world[i] = j->parent < 0 ? eval_mul(&j->base, &l) : eval_mul_affine(&world[j->parent], &l);
	}
}

/* A buffer kept across calls (not its contents), so that the large
 * per-call arrays of the key reduction and the rounding are not mapped
 * and faulted in again at every call. */
typedef struct eval_scratch {
	void *p;
	size_t size;
} eval_scratch;

/* mlod_motion_create, its setup (the clip as read at every sample) on up
 * to threads threads: the same motion at any count. */
mlod_result motion_create_on(const mlod_character *c, int clip, const mlod_motion_options *opt, int threads,
                             mlod_motion **out, mlod_error *err);

/* At least size bytes, or NULL when out of memory. */
static inline void *eval_scratch_get(eval_scratch *sc, size_t size)
{
	if (sc->size < size || !sc->p) {
		free(sc->p);
		sc->p = malloc(size > 0 ? size : 1);
		sc->size = sc->p ? size : 0;
	}
	return sc->p;
}

/* The next n bytes of a scratch buffer, 64-byte aligned (*at moves on);
 * eval_carve_size(n) is what it takes at most. */
#define eval_carve_size(n) ((size_t)(n) + 64u)
static inline void *eval_carve(char **at, size_t n)
{
	uintptr_t a = ((uintptr_t)*at + 63u) & ~(uintptr_t)63u;
	*at = (char *)a + n;
	return (void *)a;
}

/* The key reduction's end state kept for the next run on the same clip
 * (keyreduce_run): the current local transforms, their matrices and the
 * world matrices at every sample, and the keys they were made from. A
 * run that starts from those keys (the next level, which builds on this
 * one's keys) takes them instead of computing them again, once it has
 * checked that they are what its setup would compute. All zero: empty. */
typedef struct keyreduce_state {
	mlod_trs *lc;
	mlod_mat4 *lm, *wc;
	size_t fj;                /* their length */
	unsigned char *kept;      /* the keys (channels * frames) of lc */
	size_t nkept;
	int valid;
	int reused;               /* the last run took them instead of its setup */
	const mlod_skeleton *s;   /* what they were made from */
	const mlod_clip *common;
	const mlod_mat4 *w0;
	int per;
} keyreduce_state;

static inline void keyreduce_state_free(keyreduce_state *st)
{
	free(st->lc);
	free(st->lm);
	free(st->wc);
	free(st->kept);
	memset(st, 0, sizeof *st);
}

/* mlod_keyreduce, with the clip as read at the samples given (w0, samples
 * * joints world matrices as mlod_pose_world makes them; NULL: computed),
 * and *max_error (if not NULL) the largest point error of the result as
 * levelerror.c's motion_level_max_error measures its level clip, or -1 when not
 * measured (a NaN, or samples past the clip's duration); its large arrays
 * in *scratch (NULL: its own, freed on return), but for the current
 * local transforms and matrices, which go to *state when it is given
 * (see keyreduce_state); on up to threads threads (the same result at any
 * count). */
mlod_result keyreduce_run(const mlod_skeleton *s, const mlod_clip *original, const mlod_clip *common, double bound,
                          double point_distance, int subdivide, unsigned char *kept, const mlod_mat4 *w0,
                          double *max_error, eval_scratch *scratch, keyreduce_state *state, int threads,
                          mlod_error *err);

/* Tasks 0..n-1 of a sequence on up to lanes threads (tasks.c): run(ctx,
 * lane, t) runs task t with lane's own buffers (lane < lanes; one task at
 * a time per lane); task t starts once every earlier task u with
 * conflict(ctx, u, t) has finished, so the result is that of the tasks in
 * order when tasks that do not conflict touch disjoint data. conflict is
 * called under a lock and should be cheap. MLOD_ERR_NOMEM when it could
 * not start (nothing run). */
typedef int (*motion_conflict_fn)(void *ctx, int u, int t);
/* Is joint a joint b, one of its ancestors or one of its descendants?
 * (Two channels of joints that are not touch disjoint world matrices.) */
static inline int eval_joints_related(const mlod_skeleton *s, int a, int b)
{
	for (int x = b; x >= 0; x = s->joints[x].parent)
		if (x == a)
			return 1;
	for (int x = a; x >= 0; x = s->joints[x].parent)
		if (x == b)
			return 1;
	return 0;
}
typedef void (*motion_task_fn)(void *ctx, int lane, int t);
mlod_result motion_run_tasks(int n, int lanes, motion_conflict_fn conflict, motion_task_fn run, void *ctx);

#endif /* MLOD_MOTION_EVAL_H */
