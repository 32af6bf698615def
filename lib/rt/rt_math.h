/*
 * rt_math.h: the runtime's affine matrix helpers (4x4 column-major, bottom
 * row 0 0 0 1), used both when a pack opens (rt_open.c: rest poses) and
 * every frame (rt_eval.c), inline: a pose makes a few per joint.
 * Included by rt_internal.h.
 */
#ifndef MLOD_RT_MATH_H
#define MLOD_RT_MATH_H

#include <string.h>

#include "mlod_core.h"

/* a * b for affine a and b (bottom rows 0 0 0 1), as a 3x4 product: the
 * same sums in the same order as mlod_mat4_mul less its terms that
 * multiply by the bottom row's zeros, so the same floats (up to the sign
 * of a zero). out may be a or b. */
#if defined(__GNUC__) && !defined(MLOD_RT_NO_VECTOR_EXT)
/* GCC and Clang: a column per 4-lane vector (SSE, NEON). */
typedef float rt_m4 __attribute__((vector_size(16)));

static inline rt_m4 rt_m4_load(const float *p)
{
	rt_m4 v;
	memcpy(&v, p, sizeof v);
	return v;
}

/* An affine matrix's columns stored at out, its bottom row set in the
 * vectors, not stored over them: a matrix read back a column per load
 * (the next joint's parent) then comes from one store each (no
 * store-to-load forwarding stall). */
static inline void rt_m4_store_affine(float *out, rt_m4 r0, rt_m4 r1, rt_m4 r2, rt_m4 r3)
{
	r0[3] = r1[3] = r2[3] = 0.0f, r3[3] = 1.0f;
	memcpy(out, &r0, sizeof r0);
	memcpy(out + 4, &r1, sizeof r1);
	memcpy(out + 8, &r2, sizeof r2);
	memcpy(out + 12, &r3, sizeof r3);
}

static inline void rt_mat_mul(const float *a, const float *b, float *out)
{
	const rt_m4 a0 = rt_m4_load(a), a1 = rt_m4_load(a + 4), a2 = rt_m4_load(a + 8), a3 = rt_m4_load(a + 12);
	const rt_m4 b0 = rt_m4_load(b), b1 = rt_m4_load(b + 4), b2 = rt_m4_load(b + 8), b3 = rt_m4_load(b + 12);
	rt_m4 r0 = a0 * b0[0] + a1 * b0[1] + a2 * b0[2];
	rt_m4 r1 = a0 * b1[0] + a1 * b1[1] + a2 * b1[2];
	rt_m4 r2 = a0 * b2[0] + a1 * b2[1] + a2 * b2[2];
	rt_m4 r3 = a0 * b3[0] + a1 * b3[1] + a2 * b3[2] + a3;
	rt_m4_store_affine(out, r0, r1, r2, r3);
}
#else
static inline void rt_mat_mul(const float *a, const float *b, float *out)
{
	float r[16];
	for (int c = 0; c < 3; c++)
		for (int row = 0; row < 3; row++)
			r[c * 4 + row] = a[row] * b[c * 4] + a[4 + row] * b[c * 4 + 1] + a[8 + row] * b[c * 4 + 2];
	for (int row = 0; row < 3; row++)
		r[12 + row] = a[row] * b[12] + a[4 + row] * b[13] + a[8 + row] * b[14] + a[12 + row];
	r[3] = r[7] = r[11] = 0.0f;
	r[15] = 1.0f;
	memcpy(out, r, sizeof r);
}
#endif

/* The local matrix of t as mlod_mat4_from_trs makes it: the rotation's
 * rows in double (its quat_to_rows), times the scale, rounded to float. */
static inline void rt_trs_cols(const mlod_trs *t, float m[16])
{
	const double x = t->r.x, y = t->r.y, z = t->r.z, w = t->r.w;
	const double n = x * x + y * y + z * z + w * w;
	const double s = n > 0.0 ? 2.0 / n : 0.0;
	const double sx = t->s.x, sy = t->s.y, sz = t->s.z;
	m[0] = (float)((1 - s * (y * y + z * z)) * sx);
	m[1] = (float)(s * (x * y + w * z) * sx);
	m[2] = (float)(s * (x * z - w * y) * sx);
	m[4] = (float)(s * (x * y - w * z) * sy);
	m[5] = (float)((1 - s * (x * x + z * z)) * sy);
	m[6] = (float)(s * (y * z + w * x) * sy);
	m[8] = (float)(s * (x * z + w * y) * sz);
	m[9] = (float)(s * (y * z - w * x) * sz);
	m[10] = (float)((1 - s * (x * x + y * y)) * sz);
	m[12] = t->t.x, m[13] = t->t.y, m[14] = t->t.z;
	m[3] = m[7] = m[11] = 0.0f;
	m[15] = 1.0f;
}

static inline void rt_mat_trs(const mlod_trs *t, float *out)
{
	rt_trs_cols(t, out);
}

/* parent * L for the affine L whose 3x3 part is l[0], l[stride], ...,
 * l[8 stride] (column-major: rt_trs_cols' m[0], m[1], m[2], m[4], ...,
 * m[10]) and translation tr: rt_mat_mul(parent, L)'s operations, so the
 * same floats. */
static inline void rt_mat_mul_rs(const float *restrict parent, const float *l, size_t stride, const float *tr,
                                 float *restrict out)
{
#if defined(__GNUC__) && !defined(MLOD_RT_NO_VECTOR_EXT)
	const rt_m4 a0 = rt_m4_load(parent), a1 = rt_m4_load(parent + 4), a2 = rt_m4_load(parent + 8),
	            a3 = rt_m4_load(parent + 12);
	rt_m4 r0 = a0 * l[0] + a1 * l[stride] + a2 * l[2 * stride];
	rt_m4 r1 = a0 * l[3 * stride] + a1 * l[4 * stride] + a2 * l[5 * stride];
	rt_m4 r2 = a0 * l[6 * stride] + a1 * l[7 * stride] + a2 * l[8 * stride];
	rt_m4 r3 = a0 * tr[0] + a1 * tr[1] + a2 * tr[2] + a3;
	rt_m4_store_affine(out, r0, r1, r2, r3);
#else
	float b[16];
	for (int c = 0; c < 3; c++)
		for (int row = 0; row < 3; row++)
			b[4 * c + row] = l[(size_t)(3 * c + row) * stride];
	b[12] = tr[0], b[13] = tr[1], b[14] = tr[2];
	b[3] = b[7] = b[11] = 0.0f;
	b[15] = 1.0f;
	rt_mat_mul(parent, b, out);
#endif
}

/* parent * trs(t): rt_mat_mul(parent, rt_mat_trs(t)) in one go. */
#if defined(__GNUC__) && !defined(MLOD_RT_NO_VECTOR_EXT)
/* rt_trs_cols' entries kept in registers and multiplied in as rt_mat_mul
 * does (the same operations, so the same floats), without storing the
 * local matrix a float at a time and reading it back a column per load
 * (a store-to-load forwarding stall per column). */
static inline void rt_mat_mul_trs(const float *restrict parent, const mlod_trs *t, float *restrict out)
{
	const double x = t->r.x, y = t->r.y, z = t->r.z, w = t->r.w;
	const double n = x * x + y * y + z * z + w * w;
	const double s = n > 0.0 ? 2.0 / n : 0.0;
	const double sx = t->s.x, sy = t->s.y, sz = t->s.z;
	const float m0 = (float)((1 - s * (y * y + z * z)) * sx);
	const float m1 = (float)(s * (x * y + w * z) * sx);
	const float m2 = (float)(s * (x * z - w * y) * sx);
	const float m4 = (float)(s * (x * y - w * z) * sy);
	const float m5 = (float)((1 - s * (x * x + z * z)) * sy);
	const float m6 = (float)(s * (y * z + w * x) * sy);
	const float m8 = (float)(s * (x * z + w * y) * sz);
	const float m9 = (float)(s * (y * z - w * x) * sz);
	const float m10 = (float)((1 - s * (x * x + y * y)) * sz);
	const rt_m4 a0 = rt_m4_load(parent), a1 = rt_m4_load(parent + 4), a2 = rt_m4_load(parent + 8),
	            a3 = rt_m4_load(parent + 12);
	rt_m4 r0 = a0 * m0 + a1 * m1 + a2 * m2;
	rt_m4 r1 = a0 * m4 + a1 * m5 + a2 * m6;
	rt_m4 r2 = a0 * m8 + a1 * m9 + a2 * m10;
	rt_m4 r3 = a0 * t->t.x + a1 * t->t.y + a2 * t->t.z + a3;
	rt_m4_store_affine(out, r0, r1, r2, r3);
}
#else
static inline void rt_mat_mul_trs(const float *restrict parent, const mlod_trs *t, float *restrict out)
{
	float l[16];
	rt_trs_cols(t, l);
	rt_mat_mul(parent, l, out);
}
#endif

#endif
