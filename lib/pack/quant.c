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
	/* The rounded code nearest in angle among the 9 around (x, y),
	 * measured in double (a float dot product cannot tell them apart). */
	int16_t bx = snorm16(x), by = snorm16(y), best[2] = {bx, by};
	double bestd = 1e300, len = sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
	for (int dx = -1; dx <= 1; dx++)
		for (int dy = -1; dy <= 1; dy++) {
			int cx = bx + dx, cy = by + dy;
			if (cx < -32767 || cx > 32767 || cy < -32767 || cy > 32767)
				continue;
			int16_t c[2] = {(int16_t)cx, (int16_t)cy};
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
	return max > min ? (float)(((double)max - (double)min) / 65535.0) : 0.0f;
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

int mlod_pack_vertex_order(int order, const uint32_t *indices, uint32_t ni, uint32_t nv, uint32_t *remap,
                           uint32_t *out)
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
	meshopt_optimizeVertexCache(cache, indices, ni, nv);
	if (order == 1) {
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
	meshopt_remapIndexBuffer(out, cache, ni, remap);
	free(cache);
	return 0;
}
