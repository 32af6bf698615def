/*
 * rt_math.c: the runtime's matrix helpers (rt_internal.h), used both when
 * a pack opens (rt_ctx.c: rest poses) and every frame (rt_eval.c).
 */
#include <string.h>

#include "rt_internal.h"

/* ---------------------------------------------------------------- */

/* a * b for affine a and b (bottom rows 0 0 0 1), as a 3x4 product: the
 * same sums in the same order as mlod_mat4_mul less its terms that
 * multiply by the bottom row's zeros, so the same floats (up to the sign
 * of a zero). */
void rt_mat_mul(const float *restrict a, const float *restrict b, float *out)
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

/* The local matrix of t as mlod_mat4_from_trs makes it: the rotation's
 * rows in double (its quat_to_rows), times the scale, rounded to float. */
static void trs_cols(const mlod_trs *t, float m[16])
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

void rt_mat_trs(const mlod_trs *t, float *out)
{
	trs_cols(t, out);
}

/* parent * trs(t): rt_mat_mul(parent, rt_mat_trs(t)) in one go. */
void rt_mat_mul_trs(const float *restrict parent, const mlod_trs *t, float *restrict out)
{
	float l[16];
	trs_cols(t, l);
	rt_mat_mul(parent, l, out);
}
