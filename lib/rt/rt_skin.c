/*
 * rt_skin.c: the linear blend skinning kernels (mlod_rt.h).
 *
 * mlod_rt_skin_lbs works in runs of 64 vertices. A run's vertices are
 * first bucketed by how many influences they use (up to the last non-zero
 * weight: a zero weight adds nothing, so skipping it changes no result;
 * one influence of weight exactly 1 is a bucket of its own, which skips
 * the multiplies by 1), then each bucket goes through a loop specialised
 * for its count, with no branch per influence. The loops blend the palette matrices
 * (16 floats each, column-major) 4 lanes at a time, one matrix column per
 * vector (two columns per 8-lane vector for two or more influences: one
 * AVX instruction in the AVX2 build), in the scalar loop's order of operations (so the results are
 * the scalar loop's, bit for bit, where the compiler does not contract
 * to fused multiply-adds); the point and the normal are then one 4-lane
 * multiply-add chain each. The run's normals are normalised after it, 4
 * at a time (SSE2: transposed, one square root and one division per 4
 * vertices, stored as rt_transform stores), 8 at a time where the CPU has
 * AVX (checked at run time; lane for lane the same operations). mlod_rt_skin does not bucket
 * every frame: rt_prepare_mesh (rt_prepare.c) keeps each skinned part's buckets
 * from rt_skin_order, and rt_skin_lbs_ordered is the same loop given them.
 * It is written with the GCC/Clang vector extension; SSE2 intrinsics (the
 * x86-64 baseline) only for the bucketing mask and the normalisation (inlined
 * into each build: called from the AVX2 one as a separate SSE function it
 * ran 3 times slower on the test machine, AMD EPYC), each
 * with a plain C fallback (forced with -DMLOD_RT_NO_SSE2). Other compilers
 * (or -DMLOD_RT_NO_VECTOR_EXT) get fixed-length restrict loops that the
 * auto-vectoriser handles. mlod_rt_skin_lbs_scalar is the plain loop they
 * are measured against (as bench/crowd does).
 */
#include <math.h>
#include <string.h>

#include "rt_internal.h"

/* GCC on x86-64 Linux: mlod_rt_skin_lbs is also built for AVX2 and picked
 * at load by the CPU (an ifunc). The source and so the operations are the
 * same: the VEX encoding only saves register copies (no FMA: -std=c11
 * does not contract, and AVX2 does not bring FMA), so the floats are the
 * same; 5% off the tubeman's far instances. -DMLOD_RT_NO_CLONES turns it
 * off. (rt_transform has its own 8-wide AVX loop, below.) */
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__) && \
	!defined(MLOD_RT_NO_CLONES) && !defined(MLOD_RT_NO_VECTOR_EXT)
#define RT_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define RT_CLONES
#endif

#if defined(__GNUC__) && !defined(MLOD_RT_NO_VECTOR_EXT)
/* GCC and Clang: 4-lane vectors (SSE, NEON), one matrix column per vector,
 * written with the compilers' vector extension; the same arithmetic, in
 * the same order, as the scalar loop. */
typedef float rt_v4 __attribute__((vector_size(16)));

#if defined(__SSE2__) && !defined(MLOD_RT_NO_SSE2)
#define RT_SSE2 1
#include <emmintrin.h>
#endif

#define RT_RUN RT_SKIN_RUN /* vertices per run */

static inline rt_v4 ld4(const float *p)
{
	rt_v4 v;
	memcpy(&v, p, sizeof v);
	return v;
}

/* 8-lane vectors for the blend (two matrix columns each), where the
 * compiler has __builtin_shufflevector to take their halves. */
#if defined(__clang__) || __GNUC__ >= 12
#define RT_V8 1
typedef float rt_v8 __attribute__((vector_size(32)));
#else
#define RT_V8 0
#endif


/* The influences of a vertex the kernel blends: up to the last non-zero
 * weight (at least 1); a zero weight adds nothing, so skipping it changes
 * no result. */
static const uint8_t rt_kcount[16] = { 1, 1, 2, 2, 3, 3, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4 };

/* A vertex's bucket: 0 for one influence of weight exactly 1 (its blend
 * is the matrix itself: 1 x is x for every float, so its loop skips the
 * four multiplies by the weight), else its count of influences, 1 to 4. */
static inline unsigned bucket_of(const float *w)
{
#if defined(RT_SSE2)
	const unsigned bits = (unsigned)_mm_movemask_ps(_mm_cmpneq_ps(_mm_loadu_ps(w), _mm_setzero_ps()));
#else
	const unsigned bits = (unsigned)(w[0] != 0.0f) | (unsigned)(w[1] != 0.0f) << 1 |
	                      (unsigned)(w[2] != 0.0f) << 2 | (unsigned)(w[3] != 0.0f) << 3;
#endif
	return bits == 1 && w[0] == 1.0f ? 0 : rt_kcount[bits];
}

/* Skins the vertices v0 + list[0..m) of a run, each with K influences
 * (K 0: one of weight 1): positions stored, normals (when N) left
 * unnormalised in tn[i]. */
static inline __attribute__((always_inline)) void lbs_list(const int K, const int N, const uint8_t *restrict list,
                                                         size_t m, size_t v0, const float *restrict positions,
                                                         const float *restrict normals,
                                                         const uint16_t *restrict joints,
                                                         const float *restrict weights,
                                                         const float *restrict palette, float *restrict out_pos,
                                                         size_t pos_stride, rt_v4 *restrict tn)
{
	for (size_t t = 0; t < m; t++) {
		const size_t i = list[t], v = v0 + i;
		const uint16_t *j = joints + 4 * v;
		const float *w = weights + 4 * v;
		const float *a = palette + 16 * (size_t)j[0];
		rt_v4 c0, c1, c2, c3;
		if (K <= 1 || !RT_V8) {
			if (K == 0)
				c0 = ld4(a), c1 = ld4(a + 4), c2 = ld4(a + 8), c3 = ld4(a + 12);
			else
				c0 = w[0] * ld4(a), c1 = w[0] * ld4(a + 4), c2 = w[0] * ld4(a + 8), c3 = w[0] * ld4(a + 12);
		} else {
			/* Two columns per 8-lane vector (one AVX instruction each in
			 * the AVX2 build, two SSE ones otherwise): lane for lane the
			 * 4-lane blend's operations, so the same floats. */
#if RT_V8
			rt_v8 c01, c23, b01, b23;
			memcpy(&b01, a, sizeof b01), memcpy(&b23, a + 8, sizeof b23);
			c01 = w[0] * b01, c23 = w[0] * b23;
			for (int k = 1; k < K; k++) {
				const float *b = palette + 16 * (size_t)j[k];
				const float wk = w[k];
				memcpy(&b01, b, sizeof b01), memcpy(&b23, b + 8, sizeof b23);
				c01 += wk * b01, c23 += wk * b23;
			}
			c0 = __builtin_shufflevector(c01, c01, 0, 1, 2, 3), c1 = __builtin_shufflevector(c01, c01, 4, 5, 6, 7);
			c2 = __builtin_shufflevector(c23, c23, 0, 1, 2, 3), c3 = __builtin_shufflevector(c23, c23, 4, 5, 6, 7);
#endif
		}
		const float *p = positions + 3 * v;
		const rt_v4 o = c0 * p[0] + c1 * p[1] + c2 * p[2] + c3;
		float *restrict op = (float *)((char *)out_pos + v * pos_stride);
		op[0] = o[0], op[1] = o[1], op[2] = o[2];
		if (N) {
			const float *q = normals + 3 * v;
			tn[i] = c0 * q[0] + c1 * q[1] + c2 * q[2];
		}
	}
}

#if defined(RT_SSE2)
/* (a[i0], a[i1], b[i2], b[i3]) */
#define RT_SH(a, b, i0, i1, i2, i3) _mm_shuffle_ps(a, b, _MM_SHUFFLE(i3, i2, i1, i0))

/* X, Y, Z lanes stored as four xyz, stride bytes apart. */
static inline void store_xyz4(float *restrict out, size_t stride, __m128 x, __m128 y, __m128 z)
{
	const __m128 a = RT_SH(RT_SH(x, y, 0, 0, 0, 0), RT_SH(z, x, 0, 0, 1, 1), 0, 2, 0, 2);
	const __m128 b = RT_SH(RT_SH(y, z, 1, 1, 1, 1), RT_SH(x, y, 2, 2, 2, 2), 0, 2, 0, 2);
	const __m128 c = RT_SH(RT_SH(z, x, 2, 2, 3, 3), RT_SH(y, z, 3, 3, 3, 3), 0, 2, 0, 2);
	if (stride == 12) {
		_mm_storeu_ps(out, a), _mm_storeu_ps(out + 4, b), _mm_storeu_ps(out + 8, c);
		return;
	}
	float t[12];
	_mm_storeu_ps(t, a), _mm_storeu_ps(t + 4, b), _mm_storeu_ps(t + 8, c);
	for (int k = 0; k < 4; k++)
		memcpy((char *)out + (size_t)k * stride, t + 3 * k, 3 * sizeof(float));
}

#endif

#if defined(RT_SSE2) && defined(__x86_64__) && !defined(MLOD_RT_NO_AVX)
/* AVX helpers (each caller checks the CPU at run time): xyz of 8
 * vertices as X, Y, Z lanes and back, 4 per 128-bit half. */
#define RT_AVX 1
#include <immintrin.h>
#define RT_SH8(a, b, i0, i1, i2, i3) _mm256_shuffle_ps(a, b, _MM_SHUFFLE(i3, i2, i1, i0))

__attribute__((target("avx"))) static inline __m256 load2(const float *p, const float *q)
{
	return _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(p)), _mm_loadu_ps(q), 1);
}

__attribute__((target("avx"))) static inline void load_xyz8(const float *p, __m256 *x, __m256 *y, __m256 *z)
{
	const __m256 a = load2(p, p + 12), b = load2(p + 4, p + 16), c = load2(p + 8, p + 20);
	*x = RT_SH8(a, RT_SH8(b, c, 2, 0, 1, 0), 0, 3, 0, 2);
	*y = RT_SH8(RT_SH8(a, b, 1, 0, 0, 0), RT_SH8(b, c, 3, 0, 2, 0), 0, 2, 0, 2);
	*z = RT_SH8(RT_SH8(a, b, 2, 0, 1, 0), RT_SH8(c, c, 0, 0, 3, 0), 0, 2, 0, 2);
}

__attribute__((target("avx"))) static inline void store_xyz8(float *restrict out, size_t stride, __m256 x, __m256 y,
                                                           __m256 z)
{
	const __m256 a = RT_SH8(RT_SH8(x, y, 0, 0, 0, 0), RT_SH8(z, x, 0, 0, 1, 1), 0, 2, 0, 2);
	const __m256 b = RT_SH8(RT_SH8(y, z, 1, 1, 1, 1), RT_SH8(x, y, 2, 2, 2, 2), 0, 2, 0, 2);
	const __m256 c = RT_SH8(RT_SH8(z, x, 2, 2, 3, 3), RT_SH8(y, z, 3, 3, 3, 3), 0, 2, 0, 2);
	if (stride == 12) {
		_mm_storeu_ps(out, _mm256_castps256_ps128(a)), _mm_storeu_ps(out + 4, _mm256_castps256_ps128(b));
		_mm_storeu_ps(out + 8, _mm256_castps256_ps128(c)), _mm_storeu_ps(out + 12, _mm256_extractf128_ps(a, 1));
		_mm_storeu_ps(out + 16, _mm256_extractf128_ps(b, 1)), _mm_storeu_ps(out + 20, _mm256_extractf128_ps(c, 1));
		return;
	}
	float t[24];
	_mm_storeu_ps(t, _mm256_castps256_ps128(a)), _mm_storeu_ps(t + 4, _mm256_castps256_ps128(b));
	_mm_storeu_ps(t + 8, _mm256_castps256_ps128(c)), _mm_storeu_ps(t + 12, _mm256_extractf128_ps(a, 1));
	_mm_storeu_ps(t + 16, _mm256_extractf128_ps(b, 1)), _mm_storeu_ps(t + 20, _mm256_extractf128_ps(c, 1));
	for (int k = 0; k < 8; k++)
		memcpy((char *)out + (size_t)k * stride, t + 3 * k, 3 * sizeof(float));
}

/* Normalises tn[i0 .. i0 + 8) as normalise_run does 4 at a time, the low
 * 128-bit half carrying the first 4, the high half the next 4: lane for
 * lane the same operations, so the same floats. */
__attribute__((target("avx"))) static void normalise8(const rt_v4 *restrict tn, float *restrict on, size_t stride)
{
	__m256 x = load2((const float *)&tn[0], (const float *)&tn[4]);
	__m256 y = load2((const float *)&tn[1], (const float *)&tn[5]);
	__m256 z = load2((const float *)&tn[2], (const float *)&tn[6]);
	__m256 w = load2((const float *)&tn[3], (const float *)&tn[7]);
	/* _MM_TRANSPOSE4_PS within each half */
	const __m256 t0 = _mm256_unpacklo_ps(x, y), t1 = _mm256_unpacklo_ps(z, w);
	const __m256 t2 = _mm256_unpackhi_ps(x, y), t3 = _mm256_unpackhi_ps(z, w);
	x = _mm256_shuffle_ps(t0, t1, _MM_SHUFFLE(1, 0, 1, 0));
	y = _mm256_shuffle_ps(t0, t1, _MM_SHUFFLE(3, 2, 3, 2));
	z = _mm256_shuffle_ps(t2, t3, _MM_SHUFFLE(1, 0, 1, 0));
	const __m256 l2 = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(x, x), _mm256_mul_ps(y, y)), _mm256_mul_ps(z, z));
	const __m256 inv = _mm256_div_ps(_mm256_set1_ps(1.0f), _mm256_sqrt_ps(l2));
	const __m256 il = _mm256_and_ps(_mm256_cmp_ps(l2, _mm256_setzero_ps(), _CMP_GT_OQ), inv);
	store_xyz8(on, stride, _mm256_mul_ps(x, il), _mm256_mul_ps(y, il), _mm256_mul_ps(z, il));
}
#endif

/* Normalises the run's m blended normals and stores them at out. */
static inline __attribute__((always_inline)) void normalise_run(size_t m, rt_v4 *restrict tn, float *restrict out,
                                                              size_t stride)
{
	for (size_t i = m; i % 4; i++)
		tn[i] = (rt_v4){ 0, 0, 0, 0 };
	size_t i0 = 0;
#if defined(RT_AVX)
	/* 8 at a time with AVX (256-bit square roots and divisions) */
	if (m >= 8 && __builtin_cpu_supports("avx"))
		for (; i0 + 8 <= m; i0 += 8)
			normalise8(tn + i0, (float *)((char *)out + i0 * stride), stride);
#endif
	for (; i0 < m; i0 += 4) {
#if defined(RT_SSE2)
		/* Four vertices at a time, transposed (x of the four in one
		 * vector): per lane (x x + y y) + z z, one square root and
		 * division, each component times 1 / sqrt, as the plain loop
		 * below; stored back as four xyz. */
		__m128 x = (__m128)tn[i0], y = (__m128)tn[i0 + 1], z = (__m128)tn[i0 + 2], w = (__m128)tn[i0 + 3];
		_MM_TRANSPOSE4_PS(x, y, z, w);
		const __m128 l2 = _mm_add_ps(_mm_add_ps(_mm_mul_ps(x, x), _mm_mul_ps(y, y)), _mm_mul_ps(z, z));
		const __m128 inv = _mm_div_ps(_mm_set1_ps(1.0f), _mm_sqrt_ps(l2));
		const __m128 il = _mm_and_ps(_mm_cmpgt_ps(l2, _mm_setzero_ps()), inv);
		x = _mm_mul_ps(x, il), y = _mm_mul_ps(y, il), z = _mm_mul_ps(z, il);
		float *restrict on = (float *)((char *)out + i0 * stride);
		if (m - i0 >= 4) {
			store_xyz4(on, stride, x, y, z);
		} else {
			float t[12];
			store_xyz4(t, 12, x, y, z);
			for (size_t k = 0; k < m - i0; k++)
				memcpy((char *)on + k * stride, t + 3 * k, 3 * sizeof(float));
		}
#else
		float il[4];
		for (int k = 0; k < 4; k++) {
			const rt_v4 t = tn[i0 + k];
			const float l2 = t[0] * t[0] + t[1] * t[1] + t[2] * t[2];
			il[k] = l2 > 0.0f ? 1.0f / sqrtf(l2) : 0.0f;
		}
		const size_t e = m - i0 < 4 ? m - i0 : 4;
		for (size_t k = 0; k < e; k++) {
			const rt_v4 r = tn[i0 + k] * il[k];
			float *restrict on = (float *)((char *)out + (i0 + k) * stride);
			on[0] = r[0], on[1] = r[1], on[2] = r[2];
		}
#endif
	}
}

/* Skins the vertices v0 .. v1 - 1 of a run whose vertices in bucket k
 * (bucket_of) are l[k][0..c[k]) (offsets within the run, increasing), and
 * normalises the run's normals (when N). */
static inline __attribute__((always_inline)) void lbs_sorted(const int N, size_t v0, size_t v1,
                                                           const uint8_t *const l[5], const size_t c[5],
                                                           const float *restrict positions,
                                                           const float *restrict normals,
                                                           const uint16_t *restrict joints,
                                                           const float *restrict weights,
                                                           const float *restrict palette, float *restrict out_pos,
                                                           size_t pos_stride, float *restrict out_nrm,
                                                           size_t nrm_stride)
{
	rt_v4 tn[RT_RUN];
	lbs_list(0, N, l[0], c[0], v0, positions, normals, joints, weights, palette, out_pos, pos_stride, tn);
	lbs_list(1, N, l[1], c[1], v0, positions, normals, joints, weights, palette, out_pos, pos_stride, tn);
	lbs_list(2, N, l[2], c[2], v0, positions, normals, joints, weights, palette, out_pos, pos_stride, tn);
	lbs_list(3, N, l[3], c[3], v0, positions, normals, joints, weights, palette, out_pos, pos_stride, tn);
	lbs_list(4, N, l[4], c[4], v0, positions, normals, joints, weights, palette, out_pos, pos_stride, tn);
	if (N)
		normalise_run(v1 - v0, tn, (float *)((char *)out_nrm + v0 * nrm_stride), nrm_stride);
}

/* The run v0 .. v1 - 1 bucketed (bucket_of), in order: l[k] the offsets
 * within the run of the c[k] vertices in bucket k. */
static inline void bucket_run(const float *restrict weights, size_t v0, size_t v1, uint8_t l[5][RT_RUN],
                              size_t c[5])
{
	uint64_t packed = 0; /* the five counts, 12 bits each: no store in the chain */
	for (size_t v = v0; v < v1; v++) {
		const unsigned sh = 12 * bucket_of(weights + 4 * v);
		l[sh / 12][(packed >> sh) & 0xfff] = (uint8_t)(v - v0);
		packed += (uint64_t)1 << sh;
	}
	for (int k = 0; k < 5; k++)
		c[k] = packed >> (12 * k) & 0xfff;
}

static inline __attribute__((always_inline)) void lbs_run(const int N, size_t v0, size_t v1,
                                                        const float *restrict positions,
                                                        const float *restrict normals,
                                                        const uint16_t *restrict joints,
                                                        const float *restrict weights,
                                                        const float *restrict palette, float *restrict out_pos,
                                                        size_t pos_stride, float *restrict out_nrm,
                                                        size_t nrm_stride)
{
	uint8_t list[5][RT_RUN];
	size_t c[5];
	bucket_run(weights, v0, v1, list, c);
	const uint8_t *const l[5] = { list[0], list[1], list[2], list[3], list[4] };
	lbs_sorted(N, v0, v1, l, c, positions, normals, joints, weights, palette, out_pos, pos_stride, out_nrm,
	           nrm_stride);
}

RT_CLONES void mlod_rt_skin_lbs(size_t n, const float *restrict positions, const float *restrict normals,
                                const uint16_t *restrict joints, const float *restrict weights,
                                const float *restrict palette, float *restrict out_pos, size_t pos_stride,
                                float *restrict out_nrm, size_t nrm_stride)
{
	for (size_t v0 = 0; v0 < n; v0 += RT_RUN) {
		const size_t v1 = n - v0 < RT_RUN ? n : v0 + RT_RUN;
		if (normals)
			lbs_run(1, v0, v1, positions, normals, joints, weights, palette, out_pos, pos_stride, out_nrm, nrm_stride);
		else
			lbs_run(0, v0, v1, positions, normals, joints, weights, palette, out_pos, pos_stride, out_nrm, nrm_stride);
	}
}

void rt_skin_order(size_t n, const float *weights, uint8_t *order)
{
	for (size_t v0 = 0, r = 0; v0 < n; v0 += RT_RUN, r++) {
		const size_t v1 = n - v0 < RT_RUN ? n : v0 + RT_RUN;
		uint8_t l[5][RT_RUN];
		size_t c[5], o = v0;
		bucket_run(weights, v0, v1, l, c);
		for (int k = 0; k < 5; o += c[k], k++) {
			memcpy(order + o, l[k], c[k]);
			order[n + 5 * r + (size_t)k] = (uint8_t)c[k];
		}
	}
}

RT_CLONES void rt_skin_lbs_ordered(size_t n, const float *restrict positions, const float *restrict normals,
                                   const uint16_t *restrict joints, const float *restrict weights,
                                   const float *restrict palette, float *restrict out_pos, size_t pos_stride,
                                   float *restrict out_nrm, size_t nrm_stride, const uint8_t *restrict list,
                                   const uint8_t *restrict counts)
{
	for (size_t v0 = 0, r = 0; v0 < n; v0 += RT_RUN, r++) {
		const size_t v1 = n - v0 < RT_RUN ? n : v0 + RT_RUN;
		const uint8_t *cr = counts + 5 * r;
		const size_t c[5] = { cr[0], cr[1], cr[2], cr[3], cr[4] };
		const uint8_t *const l[5] = { list + v0, list + v0 + c[0], list + v0 + c[0] + c[1],
		                              list + v0 + c[0] + c[1] + c[2], list + v0 + c[0] + c[1] + c[2] + c[3] };
		if (normals)
			lbs_sorted(1, v0, v1, l, c, positions, normals, joints, weights, palette, out_pos, pos_stride,
			           out_nrm, nrm_stride);
		else
			lbs_sorted(0, v0, v1, l, c, positions, normals, joints, weights, palette, out_pos, pos_stride,
			           out_nrm, nrm_stride);
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


/* No buckets without the vector loops: the plain loop reads every weight. */
void rt_skin_order(size_t n, const float *weights, uint8_t *order)
{
	(void)weights;
	memset(order, 0, RT_SKIN_ORDER_BYTES(n));
}

void rt_skin_lbs_ordered(size_t n, const float *positions, const float *normals, const uint16_t *joints,
                         const float *weights, const float *palette, float *out_pos, size_t pos_stride,
                         float *out_nrm, size_t nrm_stride, const uint8_t *list, const uint8_t *counts)
{
	(void)list, (void)counts;
	mlod_rt_skin_lbs(n, positions, normals, joints, weights, palette, out_pos, pos_stride, out_nrm, nrm_stride);
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

/* ---------------------------------------------------------------- */
/* Rigid and static parts (rt_internal.h)                            */
/* ---------------------------------------------------------------- */

#if defined(__GNUC__) && !defined(MLOD_RT_NO_VECTOR_EXT)
/* One vertex at a time: one 4-lane multiply-add chain per point and per
 * normal (the tail of the 4-wide loop below for fewer than 4 vertices,
 * and its stand-in without SSE2). U: see rt_transform. */
static void transform_one_by_one(size_t n, const float *restrict pos, const float *restrict nrm, const float *M,
                                 const float *U, float *restrict out_pos, size_t ps, float *restrict out_nrm,
                                 size_t ns)
{
	const rt_v4 c0 = ld4(M), c1 = ld4(M + 4), c2 = ld4(M + 8), c3 = ld4(M + 12);
	for (size_t v = 0; v < n; v++) {
		const float *q = pos + 3 * v;
		const rt_v4 o = c0 * q[0] + c1 * q[1] + c2 * q[2] + c3;
		float *restrict op = (float *)((char *)out_pos + v * ps);
		op[0] = o[0], op[1] = o[1], op[2] = o[2];
	}
	if (!out_nrm)
		return;
	const float *N = U ? U : M;
	const rt_v4 u0 = ld4(N), u1 = ld4(N + 4), u2 = ld4(N + 8);
	for (size_t v = 0; v < n; v++) {
		float *restrict on = (float *)((char *)out_nrm + v * ns);
		if (!nrm) {
			on[0] = on[1] = on[2] = 0.0f;
			continue;
		}
		const float *nn = nrm + 3 * v;
		const rt_v4 t = u0 * nn[0] + u1 * nn[1] + u2 * nn[2];
		if (U) {
			on[0] = t[0], on[1] = t[1], on[2] = t[2];
			continue;
		}
		const float len2 = t[0] * t[0] + t[1] * t[1] + t[2] * t[2];
		const float il = len2 > 0.0f ? 1.0f / sqrtf(len2) : 0.0f;
		on[0] = t[0] * il, on[1] = t[1] * il, on[2] = t[2] * il;
	}
}

#if defined(RT_SSE2)
/* Four packed xyz (12 floats at p) as X, Y, Z lanes. */
static inline void load_xyz4(const float *p, __m128 *x, __m128 *y, __m128 *z)
{
	const __m128 a = _mm_loadu_ps(p), b = _mm_loadu_ps(p + 4), c = _mm_loadu_ps(p + 8);
	*x = RT_SH(a, RT_SH(b, c, 2, 0, 1, 0), 0, 3, 0, 2);
	*y = RT_SH(RT_SH(a, b, 1, 0, 0, 0), RT_SH(b, c, 3, 0, 2, 0), 0, 2, 0, 2);
	*z = RT_SH(RT_SH(a, b, 2, 0, 1, 0), RT_SH(c, c, 0, 0, 3, 0), 0, 2, 0, 2);
}

/* Four vertices at a time across the lanes (x of four points in one
 * vector): per lane the one-by-one loop's operations in its order, so the
 * same floats; the normals' 1 / sqrt four at a time (SSE2's square root
 * and division are IEEE's, as sqrtf and / are). n >= 4: when n is not a
 * multiple of 4 the last block is the last 4 vertices, overlapping the
 * one before (those vertices are computed and stored twice, the same
 * floats both times), so there is no one-by-one tail. */
static void transform4(size_t n, const float *restrict pos, const float *restrict nrm, const float *M,
                       const float *U, float *restrict out_pos, size_t ps, float *restrict out_nrm, size_t ns)
{
	__m128 m[16];
	for (int k = 0; k < 16; k++)
		m[k] = _mm_set1_ps(M[k]);
	for (size_t v0 = 0; v0 < n; v0 += 4) {
		const size_t v = n - v0 < 4 ? n - 4 : v0;
		__m128 x, y, z;
		load_xyz4(pos + 3 * v, &x, &y, &z);
		const __m128 ox = _mm_add_ps(
			_mm_add_ps(_mm_add_ps(_mm_mul_ps(m[0], x), _mm_mul_ps(m[4], y)), _mm_mul_ps(m[8], z)), m[12]);
		const __m128 oy = _mm_add_ps(
			_mm_add_ps(_mm_add_ps(_mm_mul_ps(m[1], x), _mm_mul_ps(m[5], y)), _mm_mul_ps(m[9], z)), m[13]);
		const __m128 oz = _mm_add_ps(
			_mm_add_ps(_mm_add_ps(_mm_mul_ps(m[2], x), _mm_mul_ps(m[6], y)), _mm_mul_ps(m[10], z)), m[14]);
		store_xyz4((float *)((char *)out_pos + v * ps), ps, ox, oy, oz);
	}
	if (out_nrm && nrm) {
		if (U)
			for (int k = 0; k < 11; k++)
				m[k] = _mm_set1_ps(U[k]);
		const __m128 zero = _mm_setzero_ps(), one = _mm_set1_ps(1.0f);
		for (size_t v0 = 0; v0 < n; v0 += 4) {
			const size_t v = n - v0 < 4 ? n - 4 : v0;
			__m128 x, y, z;
			load_xyz4(nrm + 3 * v, &x, &y, &z);
			const __m128 tx = _mm_add_ps(_mm_add_ps(_mm_mul_ps(m[0], x), _mm_mul_ps(m[4], y)), _mm_mul_ps(m[8], z));
			const __m128 ty = _mm_add_ps(_mm_add_ps(_mm_mul_ps(m[1], x), _mm_mul_ps(m[5], y)), _mm_mul_ps(m[9], z));
			const __m128 tz = _mm_add_ps(_mm_add_ps(_mm_mul_ps(m[2], x), _mm_mul_ps(m[6], y)), _mm_mul_ps(m[10], z));
			float *restrict on = (float *)((char *)out_nrm + v * ns);
			if (U) {
				store_xyz4(on, ns, tx, ty, tz);
				continue;
			}
			const __m128 l2 =
				_mm_add_ps(_mm_add_ps(_mm_mul_ps(tx, tx), _mm_mul_ps(ty, ty)), _mm_mul_ps(tz, tz));
			const __m128 il = _mm_and_ps(_mm_cmpgt_ps(l2, zero), _mm_div_ps(one, _mm_sqrt_ps(l2)));
			store_xyz4(on, ns, _mm_mul_ps(tx, il), _mm_mul_ps(ty, il), _mm_mul_ps(tz, il));
		}
	} else if (out_nrm) {
		for (size_t v = 0; v < n; v++) {
			float *restrict on = (float *)((char *)out_nrm + v * ns);
			on[0] = on[1] = on[2] = 0.0f;
		}
	}
}

#if defined(RT_AVX)
/* With AVX (checked at run time), 8 vertices at a time: the 4-wide loop's
 * shuffles work within each 128-bit half, so the low half carries
 * vertices 0-3 and the high half 4-7, and the arithmetic is the 4-wide
 * loop's, lane for lane (no FMA): the same floats. */
/* The 8 vertices from v: points by m (16 broadcast entries); normals by
 * m's first three columns, normalised (K 1) or as they are (K 0). */
__attribute__((target("avx"))) static inline __attribute__((always_inline)) void
pos8(size_t v, const float *restrict pos, const __m256 *m, float *restrict out_pos, size_t ps)
{
	__m256 x, y, z;
	load_xyz8(pos + 3 * v, &x, &y, &z);
	const __m256 ox = _mm256_add_ps(
		_mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(m[0], x), _mm256_mul_ps(m[4], y)), _mm256_mul_ps(m[8], z)), m[12]);
	const __m256 oy = _mm256_add_ps(
		_mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(m[1], x), _mm256_mul_ps(m[5], y)), _mm256_mul_ps(m[9], z)), m[13]);
	const __m256 oz = _mm256_add_ps(
		_mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(m[2], x), _mm256_mul_ps(m[6], y)), _mm256_mul_ps(m[10], z)), m[14]);
	store_xyz8((float *)((char *)out_pos + v * ps), ps, ox, oy, oz);
}

__attribute__((target("avx"))) static inline __attribute__((always_inline)) void
nrm8(const int K, size_t v, const float *restrict nrm, const __m256 *m, float *restrict out_nrm, size_t ns)
{
	__m256 x, y, z;
	load_xyz8(nrm + 3 * v, &x, &y, &z);
	const __m256 tx =
		_mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(m[0], x), _mm256_mul_ps(m[4], y)), _mm256_mul_ps(m[8], z));
	const __m256 ty =
		_mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(m[1], x), _mm256_mul_ps(m[5], y)), _mm256_mul_ps(m[9], z));
	const __m256 tz =
		_mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(m[2], x), _mm256_mul_ps(m[6], y)), _mm256_mul_ps(m[10], z));
	float *restrict on = (float *)((char *)out_nrm + v * ns);
	if (!K) {
		store_xyz8(on, ns, tx, ty, tz);
		return;
	}
	const __m256 l2 =
		_mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(tx, tx), _mm256_mul_ps(ty, ty)), _mm256_mul_ps(tz, tz));
	const __m256 il = _mm256_and_ps(_mm256_cmp_ps(l2, _mm256_setzero_ps(), _CMP_GT_OQ),
	                                _mm256_div_ps(_mm256_set1_ps(1.0f), _mm256_sqrt_ps(l2)));
	store_xyz8(on, ns, _mm256_mul_ps(tx, il), _mm256_mul_ps(ty, il), _mm256_mul_ps(tz, il));
}

/* n >= 8: blocks of 8 and, when n is not a multiple of 8, the last 8
 * vertices (overlapping the block before: those are computed and stored
 * twice, the same floats both times). */
__attribute__((target("avx"))) static void transform8(size_t n, const float *restrict pos,
                                                    const float *restrict nrm, const float *M, const float *U,
                                                    float *restrict out_pos, size_t ps, float *restrict out_nrm,
                                                    size_t ns)
{
	__m256 m[16];
	for (int k = 0; k < 16; k++)
		m[k] = _mm256_set1_ps(M[k]);
	const size_t n8 = n & ~(size_t)7;
	for (size_t v = 0; v < n8; v += 8)
		pos8(v, pos, m, out_pos, ps);
	if (n8 < n)
		pos8(n - 8, pos, m, out_pos, ps);
	if (!out_nrm)
		return;
	if (!nrm) {
		for (size_t v = 0; v < n; v++) {
			float *restrict on = (float *)((char *)out_nrm + v * ns);
			on[0] = on[1] = on[2] = 0.0f;
		}
		return;
	}
	if (U) {
		for (int k = 0; k < 11; k++)
			m[k] = _mm256_set1_ps(U[k]);
		for (size_t v = 0; v < n8; v += 8)
			nrm8(0, v, nrm, m, out_nrm, ns);
		if (n8 < n)
			nrm8(0, n - 8, nrm, m, out_nrm, ns);
	} else {
		for (size_t v = 0; v < n8; v += 8)
			nrm8(1, v, nrm, m, out_nrm, ns);
		if (n8 < n)
			nrm8(1, n - 8, nrm, m, out_nrm, ns);
	}
}
#endif

void rt_transform(size_t n, const float *restrict pos, const float *restrict nrm, const float *M, const float *U,
                  float *restrict out_pos, size_t ps, float *restrict out_nrm, size_t ns)
{
#if defined(RT_AVX)
	if (n >= 8 && __builtin_cpu_supports("avx")) {
		transform8(n, pos, nrm, M, U, out_pos, ps, out_nrm, ns);
		return;
	}
#endif
	if (n >= 4)
		transform4(n, pos, nrm, M, U, out_pos, ps, out_nrm, ns);
	else
		transform_one_by_one(n, pos, nrm, M, U, out_pos, ps, out_nrm, ns);
}
#undef RT_SH
#else
void rt_transform(size_t n, const float *restrict pos, const float *restrict nrm, const float *M, const float *U,
                  float *restrict out_pos, size_t ps, float *restrict out_nrm, size_t ns)
{
	transform_one_by_one(n, pos, nrm, M, U, out_pos, ps, out_nrm, ns);
}
#endif
#else
void rt_transform(size_t n, const float *pos, const float *nrm, const float *M, const float *U, float *out_pos,
                  size_t ps, float *out_nrm, size_t ns)
{
	for (size_t v = 0; v < n; v++) {
		const float *q = pos + 3 * v;
		float *o = (float *)((char *)out_pos + v * ps);
		for (int r = 0; r < 3; r++)
			o[r] = M[r] * q[0] + M[4 + r] * q[1] + M[8 + r] * q[2] + M[12 + r];
		if (out_nrm) {
			float *on = (float *)((char *)out_nrm + v * ns);
			if (!nrm) {
				on[0] = on[1] = on[2] = 0.0f;
				continue;
			}
			const float *nn = nrm + 3 * v, *N = U ? U : M;
			float len2 = 0.0f;
			for (int r = 0; r < 3; r++) {
				on[r] = N[r] * nn[0] + N[4 + r] * nn[1] + N[8 + r] * nn[2];
				len2 += on[r] * on[r];
			}
			if (U)
				continue;
			const float il = len2 > 0.0f ? 1.0f / sqrtf(len2) : 0.0f;
			for (int r = 0; r < 3; r++)
				on[r] *= il;
		}
	}
}
#endif
