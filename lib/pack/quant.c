/*
 * quant.c: the pack's quantisation (mlod_pack_write.h): octahedral
 * normals, u16 ranges, unorm8 weights summing to 255, switch distances.
 */
#include <math.h>

#include "pack/mlod_pack_write.h"

#include <meshoptimizer.h>
#include <stdlib.h>
#include <string.h>

static float sign_not_zero(float v)
{
	return v < 0.0f ? -1.0f : 1.0f;
}

static int16_t snorm16(float v)
{
	if (!(v > -1.0f))
		v = -1.0f; /* NaN too */
	if (v > 1.0f)
		v = 1.0f;
	return (int16_t)lrintf(v * 32767.0f);
}

void mlod_pack_oct_encode(const float n[3], int16_t out[2])
{
	mlod_pack_oct_encode_bits(n, 16, out);
}

/* The code of lattice point k (a multiple of step, the ends clamped to
 * +-32767). */
static int oct_code(long k, int step)
{
	long c = k * step;
	return (int)(c > 32767 ? 32767 : c < -32767 ? -32767 : c);
}

void mlod_pack_oct_encode_bits(const float n[3], int bits, int16_t out[2])
{
	bits = bits < MLOD_PACK_NORMAL_BITS_MIN ? MLOD_PACK_NORMAL_BITS_MIN : bits > 16 ? 16 : bits;
	int step = 1 << (16 - bits);
	long kmax = 1L << (bits - 1); /* k * step for |k| <= kmax, clamped: every code's lattice */
	float x = n[0], y = n[1], z = n[2];
	float l1 = fabsf(x) + fabsf(y) + fabsf(z);
	if (!(l1 > 0.0f)) {
		out[0] = 0;
		out[1] = 0;
		return;
	}
	x /= l1;
	y /= l1;
	z /= l1;
	if (z < 0.0f) {
		float ox = (1.0f - fabsf(y)) * sign_not_zero(x);
		float oy = (1.0f - fabsf(x)) * sign_not_zero(y);
		x = ox;
		y = oy;
	}
	/* The lattice code nearest in angle among the 9 around (x, y),
	 * measured in double (a float dot product cannot tell them apart). */
	long bx = lrint(snorm16(x) / (double)step), by = lrint(snorm16(y) / (double)step);
	int16_t best[2] = {(int16_t)oct_code(bx, step), (int16_t)oct_code(by, step)};
	double bestd = 1e300, len = sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
	for (int dx = -1; dx <= 1; dx++)
		for (int dy = -1; dy <= 1; dy++) {
			long kx = bx + dx, ky = by + dy;
			if (kx < -kmax || kx > kmax || ky < -kmax || ky > kmax)
				continue;
			int16_t c[2] = {(int16_t)oct_code(kx, step), (int16_t)oct_code(ky, step)};
			float d[3];
			mlod_pack_oct_decode(c, d);
			double e = 0.0;
			for (int a = 0; a < 3; a++)
				e += ((double)d[a] - n[a] / len) * ((double)d[a] - n[a] / len);
			if (e < bestd) {
				bestd = e;
				best[0] = c[0];
				best[1] = c[1];
			}
		}
	out[0] = best[0];
	out[1] = best[1];
}

double mlod_pack_oct_bound(int bits)
{
	/* half a lattice step per coordinate, stretched at most sqrt(18)
	 * times; 2e-6 rad for the f32 arithmetic */
	bits = bits < MLOD_PACK_NORMAL_BITS_MIN ? MLOD_PACK_NORMAL_BITS_MIN : bits > 16 ? 16 : bits;
	return 3.0 * sqrt(2.0) * ldexp(1.0, 15 - bits) / 32767.0 + 2e-6;
}

void mlod_pack_oct_decode(const int16_t in[2], float n[3])
{
	float x = in[0] / 32767.0f, y = in[1] / 32767.0f;
	float z = 1.0f - fabsf(x) - fabsf(y);
	float t = z < 0.0f ? -z : 0.0f;
	x += x >= 0.0f ? -t : t;
	y += y >= 0.0f ? -t : t;
	float l = sqrtf(x * x + y * y + z * z);
	n[0] = x / l;
	n[1] = y / l;
	n[2] = z / l;
}

float mlod_pack_range_scale(float min, float max)
{
	return mlod_pack_range_scale_bits(min, max, 16);
}

float mlod_pack_range_scale_bits(float min, float max, int bits)
{
	bits = bits < 1 ? 1 : bits > 16 ? 16 : bits;
	return max > min ? (float)(((double)max - (double)min) / (ldexp(1.0, bits) - 1.0)) : 0.0f;
}

uint16_t mlod_pack_qu16(float v, float min, float scale)
{
	if (!(scale > 0.0f))
		return 0;
	double q = floor(((double)v - (double)min) / (double)scale + 0.5);
	if (!(q > 0.0))
		return 0;
	if (q > 65535.0)
		return 65535;
	return (uint16_t)q;
}

uint16_t mlod_pack_qu16_shift(float v, float min, float scale, int shift)
{
	if (shift <= 0)
		return mlod_pack_qu16(v, min, scale);
	shift = shift > 15 ? 15 : shift;
	if (!(scale > 0.0f))
		return 0;
	double step = ldexp(1.0, shift);
	double q = floor(((double)v - (double)min) / (double)scale / step + 0.5) * step;
	if (!(q > 0.0))
		return 0;
	const double top = floor(65535.0 / step) * step; /* the largest multiple of step in range */
	return (uint16_t)(q > top ? top : q);
}

void mlod_pack_weights8(const float w[4], uint8_t out[4])
{
	double sum = 0.0, rem[4];
	int total = 0;
	for (int i = 0; i < 4; i++)
		sum += w[i] > 0.0f ? w[i] : 0.0f;
	if (!(sum > 0.0)) {
		for (int i = 0; i < 4; i++)
			out[i] = 0;
		return;
	}
	for (int i = 0; i < 4; i++) {
		double x = (w[i] > 0.0f ? w[i] : 0.0f) * 255.0 / sum;
		double f = floor(x);
		out[i] = (uint8_t)f;
		rem[i] = x - f;
		total += (int)f;
	}
	/* Largest remainders first; ties to the lower slot. */
	while (total < 255) {
		int best = 0;
		for (int i = 1; i < 4; i++)
			if (rem[i] > rem[best])
				best = i;
		out[best]++;
		rem[best] = -1.0;
		total++;
	}
}

float mlod_pack_switch_distance(float error)
{
	const double pi = 3.14159265358979323846;
	if (!(error > 0.0f))
		return 0.0f;
	return (float)((double)error * MLOD_PACK_LINES / (2.0 * tan(MLOD_PACK_FOV_Y * pi / 360.0) * MLOD_PACK_PIXELS));
}

/* Rewrites the first-use order remap (old -> new) so that the vertices
 * with bit-identical positions follow the first of them to come, in
 * first-use order among themselves. 0, or -1 when out of memory. */
static int group_copies(const float *positions, uint32_t nv, uint32_t *remap)
{
	size_t cap = 16;
	while (cap < 2 * (size_t)nv + 2)
		cap *= 2;
	uint32_t *ord = malloc(sizeof *ord * ((size_t)nv + 1)), *rep = malloc(sizeof *rep * ((size_t)nv + 1));
	uint32_t *next = malloc(sizeof *next * ((size_t)nv + 1)), *tail = malloc(sizeof *tail * ((size_t)nv + 1));
	uint32_t *slot = calloc(cap, sizeof *slot);
	int ok = ord && rep && next && tail && slot;
	for (uint32_t v = 0; ok && v < nv; v++)
		ord[remap[v]] = v;
	for (uint32_t i = 0; ok && i < nv; i++) {
		uint32_t v = ord[i];
		uint64_t h = 1469598103934665603ull;
		const unsigned char *b = (const unsigned char *)(positions + 3 * (size_t)v);
		for (int k = 0; k < 12; k++)
			h = (h ^ b[k]) * 1099511628211ull;
		size_t s = (size_t)h & (cap - 1);
		while (slot[s] && memcmp(positions + 3 * (size_t)(slot[s] - 1), positions + 3 * (size_t)v, 12) != 0)
			s = (s + 1) & (cap - 1);
		next[v] = UINT32_MAX;
		if (!slot[s]) {
			slot[s] = v + 1;
			rep[v] = v, tail[v] = v;
		} else {
			uint32_t r = slot[s] - 1;
			rep[v] = r, next[tail[r]] = v, tail[r] = v;
		}
	}
	uint32_t at = 0;
	for (uint32_t i = 0; ok && i < nv; i++)
		if (rep[ord[i]] == ord[i])
			for (uint32_t v = ord[i]; v != UINT32_MAX; v = next[v])
				remap[v] = at++;
	free(ord), free(rep), free(next), free(tail), free(slot);
	return ok ? 0 : -1;
}

void mlod_pack_order_memo_free(mlod_pack_order_memo *memo)
{
	free(memo->tri[0]), free(memo->tri[1]), free(memo->tri[2]);
	memo->tri[0] = memo->tri[1] = memo->tri[2] = NULL;
}

int mlod_pack_vertex_order(int order, const uint32_t *indices, uint32_t ni, uint32_t nv, const float *positions,
                           uint32_t *remap, uint32_t *out)
{
	return mlod_pack_vertex_order_memo(order, indices, ni, nv, positions, NULL, remap, out);
}

int mlod_pack_vertex_order_memo(int order, const uint32_t *indices, uint32_t ni, uint32_t nv, const float *positions,
                                mlod_pack_order_memo *memo, uint32_t *remap, uint32_t *out)
{
	int ok = ni % 3 == 0 && order > 0;
	for (uint32_t i = 0; ok && i < ni; i++)
		ok = indices[i] < nv;
	if (!ok || nv == 0) {
		for (uint32_t v = 0; v < nv; v++)
			remap[v] = v;
		if (ni)
			memmove(out, indices, sizeof *out * ni);
		return 0;
	}
	unsigned int *cache = malloc(sizeof *cache * ((size_t)ni + 1));
	if (!cache)
		return -1;
	int kind = order == 3 ? 2 : order == 4 || order == 5 || order == 7 || order == 9 ? 1 : 0;
	if (memo && memo->tri[kind])
		memcpy(cache, memo->tri[kind], sizeof *cache * ni);
	else if (kind == 2)
		meshopt_optimizeVertexCacheStrip(cache, indices, ni, nv);
	else if (kind == 1)
		meshopt_optimizeVertexCacheFifo(cache, indices, ni, nv, MLOD_PACK_INDEX_FIFO);
	else
		meshopt_optimizeVertexCache(cache, indices, ni, nv);
	if (memo && !memo->tri[kind] && (memo->tri[kind] = malloc(sizeof *cache * ((size_t)ni + 1))))
		memcpy(memo->tri[kind], cache, sizeof *cache * ni);
	if ((order == 6 || order == 7) && positions) {
		meshopt_spatialSortRemap(remap, positions, nv, 3 * sizeof(float));
		meshopt_remapIndexBuffer(out, cache, ni, remap);
		free(cache);
		return 0;
	}
	if (order == 1 || order == 4 || order == 6 || order == 7) {
		for (uint32_t v = 0; v < nv; v++)
			remap[v] = v;
		memcpy(out, cache, sizeof *out * ni);
		free(cache);
		return 0;
	}
	size_t used = meshopt_optimizeVertexFetchRemap(remap, cache, ni, nv);
	for (uint32_t v = 0; v < nv; v++)
		if (remap[v] == ~0u)
			remap[v] = (uint32_t)used++;
	if ((order == 8 || order == 9) && positions && group_copies(positions, nv, remap) != 0) {
		free(cache);
		return -1;
	}
	meshopt_remapIndexBuffer(out, cache, ni, remap);
	free(cache);
	return 0;
}

void mlod_pack_top4(const mlod_primitive *p, uint32_t v, const int *jmap, int jmap_count, int joints[4],
                    float weights[4])
{
	for (int t = 0; t < 4; t++)
		joints[t] = 0, weights[t] = 0.0f;
	for (int s = 0; s < p->weight_set_count; s++)
		for (int i = 0; i < 4; i++) {
			float w = p->weights[s][4 * (size_t)v + i];
			int jt = p->joints[s][4 * (size_t)v + i];
			if (!(w > 0.0f))
				continue;
			if (jmap)
				jt = jt < jmap_count ? jmap[jt] : 0;
			int at = -1; /* a joint met twice */
			for (int t = 0; t < 4; t++)
				if (weights[t] > 0.0f && joints[t] == jt)
					at = t;
			if (at >= 0) {
				weights[at] += w;
				continue;
			}
			int low = 0;
			for (int t = 1; t < 4; t++)
				if (weights[t] < weights[low])
					low = t;
			if (w > weights[low])
				weights[low] = w, joints[low] = jt;
		}
}
