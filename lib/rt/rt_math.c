/*
 * rt_math.c: the runtime's two matrix helpers (rt_internal.h), used both
 * when a pack opens (rt_ctx.c: rest poses) and every frame (rt_eval.c).
 */
#include <string.h>

#include "rt_internal.h"

/* ---------------------------------------------------------------- */

/* a * b for affine a and b; the same sums in the same order as
 * mlod_mat4_mul, so the same floats. */
void rt_mat_mul(const float *a, const float *b, float *out)
{
	float r[16];
	for (int c = 0; c < 4; c++) {
		for (int row = 0; row < 3; row++)
			r[c * 4 + row] = a[row] * b[c * 4] + a[4 + row] * b[c * 4 + 1] + a[8 + row] * b[c * 4 + 2] +
			                 a[12 + row] * b[c * 4 + 3];
		r[c * 4 + 3] = c == 3 ? 1.0f : 0.0f;
	}
	memcpy(out, r, sizeof r);
}

void rt_mat_trs(const mlod_trs *t, float *out)
{
	mlod_mat4 m = mlod_mat4_from_trs(t);
	memcpy(out, m.m, sizeof m.m);
}

