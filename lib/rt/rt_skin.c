/*
 * rt_skin.c: the linear blend skinning kernels (mlod_rt.h).
 *
 * mlod_rt_skin_lbs blends, per vertex, the palette matrices (16 floats
 * each, column-major) 4 lanes at a time, one matrix column per vector; the
 * point and the normal are then one 4-lane multiply-add chain each. With
 * GCC or Clang it is written with their vector extension and works in
 * runs of 32 vertices, each with a loop specialised for the run's largest
 * count of non-zero influences (1 to 4; a zero weight adds nothing, so the
 * results do not change), the normals normalised after the run. Other
 * compilers (or -DMLOD_RT_NO_VECTOR_EXT) get fixed-length restrict loops
 * that the auto-vectoriser handles. mlod_rt_skin_lbs_scalar is the plain
 * loop they are measured against.
 */
#include <math.h>
#include <string.h>

#include "rt_internal.h"

#if defined(__GNUC__) && !defined(MLOD_RT_NO_VECTOR_EXT)
/* GCC and Clang: 4-lane vectors (SSE, NEON), one matrix column per vector,
 * written with the compilers' vector extension; the same arithmetic as
 * the portable loop below. */
typedef float rt_v4 __attribute__((vector_size(16)));

static inline rt_v4 ld4(const float *p)
{
	rt_v4 v;
	memcpy(&v, p, sizeof v);
	return v;
}

/* The loop for K influences (the others are 0 in this run of vertices):
 * zero weights add nothing, so skipping them changes no result. */
static inline __attribute__((always_inline)) void lbs_k(const int K, size_t v0, size_t v1,
                                                      const float *restrict positions,
                                                      const float *restrict normals,
                                                      const uint16_t *restrict joints,
                                                      const float *restrict weights,
                                                      const float *restrict palette, float *restrict out_pos,
                                                      size_t pos_stride, float *restrict out_nrm,
                                                      size_t nrm_stride, float *restrict nx, float *restrict ny,
                                                      float *restrict nz)
{
	for (size_t v = v0; v < v1; v++) {
		const uint16_t *j = joints + 4 * v;
		const float *w = weights + 4 * v;
		rt_v4 c[4];
		const float *m0 = palette + 16 * (size_t)j[0];
		for (int k = 0; k < 4; k++)
			c[k] = w[0] * ld4(m0 + 4 * k);
		for (int i = 1; i < K; i++) {
			const float *m = palette + 16 * (size_t)j[i];
			const float wi = w[i];
			for (int k = 0; k < 4; k++)
				c[k] += wi * ld4(m + 4 * k);
		}
		const float *p = positions + 3 * v;
		const rt_v4 o = c[0] * p[0] + c[1] * p[1] + c[2] * p[2] + c[3];
		float *restrict op = (float *)((char *)out_pos + v * pos_stride);
		op[0] = o[0], op[1] = o[1], op[2] = o[2];
		if (normals) { /* unnormalised, in SoA for normalise_block */
			const float *q = normals + 3 * v;
			const rt_v4 t = c[0] * q[0] + c[1] * q[1] + c[2] * q[2];
			nx[v - v0] = t[0], ny[v - v0] = t[1], nz[v - v0] = t[2];
		}
	}
	(void)out_nrm, (void)nrm_stride;
}

/* Normalises m normals held as SoA and stores them, apart from the blend
 * loop so that the square roots and divisions of a run overlap. (GCC
 * vectorises this loop only with -fno-math-errno.) */
static void normalise_block(size_t m, const float *restrict nx, const float *restrict ny, const float *restrict nz,
                            float *restrict out, size_t stride)
{
	float il[32];
	for (size_t i = 0; i < m; i++) {
		const float l2 = nx[i] * nx[i] + ny[i] * ny[i] + nz[i] * nz[i];
		il[i] = l2 > 0.0f ? 1.0f / sqrtf(l2) : 0.0f;
	}
	for (size_t i = 0; i < m; i++) {
		float *restrict on = (float *)((char *)out + i * stride);
		on[0] = nx[i] * il[i], on[1] = ny[i] * il[i], on[2] = nz[i] * il[i];
	}
}

void mlod_rt_skin_lbs(size_t n, const float *restrict positions, const float *restrict normals,
                      const uint16_t *restrict joints, const float *restrict weights,
                      const float *restrict palette, float *restrict out_pos, size_t pos_stride,
                      float *restrict out_nrm, size_t nrm_stride)
{
	/* Runs of 32 vertices, each with the loop for its largest count of
	 * non-zero influences. */
	for (size_t v0 = 0; v0 < n; v0 += 32) {
		const size_t v1 = n - v0 < 32 ? n : v0 + 32;
		int used[4] = { 0, 0, 0, 0 };
		for (size_t v = v0; v < v1; v++)
			for (int k = 1; k < 4; k++)
				used[k] |= weights[4 * v + k] != 0.0f;
		const int K = used[3] ? 4 : used[2] ? 3 : used[1] ? 2 : 1;
		float nx[32], ny[32], nz[32];
		switch (K) {
		case 1: lbs_k(1, v0, v1, positions, normals, joints, weights, palette, out_pos, pos_stride, out_nrm, nrm_stride, nx, ny, nz); break;
		case 2: lbs_k(2, v0, v1, positions, normals, joints, weights, palette, out_pos, pos_stride, out_nrm, nrm_stride, nx, ny, nz); break;
		case 3: lbs_k(3, v0, v1, positions, normals, joints, weights, palette, out_pos, pos_stride, out_nrm, nrm_stride, nx, ny, nz); break;
		default: lbs_k(4, v0, v1, positions, normals, joints, weights, palette, out_pos, pos_stride, out_nrm, nrm_stride, nx, ny, nz); break;
		}
		if (normals)
			normalise_block(v1 - v0, nx, ny, nz, (float *)((char *)out_nrm + v0 * nrm_stride), nrm_stride);
	}
}
#else
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

#endif

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
