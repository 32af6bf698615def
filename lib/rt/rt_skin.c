/*
 * rt_skin.c: the linear blend skinning kernels (mlod_rt.h).
 *
 * mlod_rt_skin_lbs blends, per vertex, the 4 palette matrices (16 floats
 * each, column-major) with fixed-length loops over restrict-qualified
 * data, which GCC and Clang vectorise at -O2 (4 lanes: one matrix column
 * per vector); the point and the normal are then one 4-lane multiply-add
 * chain each. mlod_rt_skin_lbs_scalar is the plain loop it is measured
 * against.
 */
#include <math.h>
#include <string.h>

#include "rt_internal.h"

void mlod_rt_skin_lbs(size_t n, const float *restrict positions, const float *restrict normals,
                      const uint16_t *restrict joints, const float *restrict weights,
                      const float *restrict palette, float *restrict out_pos, size_t pos_stride,
                      float *restrict out_nrm, size_t nrm_stride)
{
	for (size_t v = 0; v < n; v++) {
		const uint16_t *j = joints + 4 * v;
		const float *w = weights + 4 * v;
		const float *restrict m0 = palette + 16 * (size_t)j[0];
		const float *restrict m1 = palette + 16 * (size_t)j[1];
		const float *restrict m2 = palette + 16 * (size_t)j[2];
		const float *restrict m3 = palette + 16 * (size_t)j[3];
		const float w0 = w[0], w1 = w[1], w2 = w[2], w3 = w[3];
		float m[16];
		for (int c = 0; c < 16; c++)
			m[c] = w0 * m0[c] + w1 * m1[c] + w2 * m2[c] + w3 * m3[c];
		const float *p = positions + 3 * v;
		const float x = p[0], y = p[1], z = p[2];
		float o[4];
		for (int r = 0; r < 4; r++)
			o[r] = m[r] * x + m[4 + r] * y + m[8 + r] * z + m[12 + r];
		float *restrict op = (float *)((char *)out_pos + v * pos_stride);
		op[0] = o[0], op[1] = o[1], op[2] = o[2];
		if (normals) {
			const float *q = normals + 3 * v;
			const float nx = q[0], ny = q[1], nz = q[2];
			float t[4];
			for (int r = 0; r < 4; r++)
				t[r] = m[r] * nx + m[4 + r] * ny + m[8 + r] * nz;
			const float len2 = t[0] * t[0] + t[1] * t[1] + t[2] * t[2];
			const float il = len2 > 0.0f ? 1.0f / sqrtf(len2) : 0.0f;
			float *restrict on = (float *)((char *)out_nrm + v * nrm_stride);
			on[0] = t[0] * il, on[1] = t[1] * il, on[2] = t[2] * il;
		}
	}
}

#if defined(__GNUC__) && !defined(__clang__)
__attribute__((optimize("no-tree-vectorize")))
#endif
void mlod_rt_skin_lbs_scalar(size_t n, const float *positions, const float *normals, const uint16_t *joints,
                             const float *weights, const float *palette, float *out_pos, size_t pos_stride,
                             float *out_nrm, size_t nrm_stride)
{
	for (size_t v = 0; v < n; v++) {
		float m[12] = { 0 };
		for (int k = 0; k < 4; k++) {
			const float w = weights[4 * v + k];
			if (!(w > 0.0f))
				continue;
			const float *j = palette + 16 * (size_t)joints[4 * v + k];
			for (int c = 0; c < 4; c++)
				for (int r = 0; r < 3; r++)
					m[c * 3 + r] += w * j[c * 4 + r];
		}
		const float *p = positions + 3 * v;
		float *op = (float *)((char *)out_pos + v * pos_stride);
		for (int r = 0; r < 3; r++)
			op[r] = m[r] * p[0] + m[3 + r] * p[1] + m[6 + r] * p[2] + m[9 + r];
		if (normals) {
			const float *q = normals + 3 * v;
			float *on = (float *)((char *)out_nrm + v * nrm_stride), len2 = 0.0f;
			for (int r = 0; r < 3; r++) {
				on[r] = m[r] * q[0] + m[3 + r] * q[1] + m[6 + r] * q[2];
				len2 += on[r] * on[r];
			}
			const float il = len2 > 0.0f ? 1.0f / sqrtf(len2) : 0.0f;
			for (int r = 0; r < 3; r++)
				on[r] *= il;
		}
	}
}
