/*
 * powerskin.c: the Power Skinning Algorithm (Savoye & Meyer 2008, 4.2.4),
 * the multiple weight update rule that gives the vertex v-bar of a
 * collapse its joint influences.
 *
 * For the k collapsed vertices v_i: d_i = |v-bar - v_i| (the distances),
 * D = sum d_i (the power distance), dinv_i = D - d_i (the inverse
 * distances), Dinv = sum dinv_i = (k - 1) D, and the power weights
 * W_i = dinv_i / Dinv = (D - d_i) / ((k - 1) D), which sum to 1. When
 * D = 0 (every vertex at v-bar) each gets 1/k. v-bar's weight on joint j
 * is sum_i W_i w(j, v_i); these sum to 1 when each v_i's do.
 *
 * glTF carries 4 influences per weight set, and the mesh layer gives
 * v-bar one set: when more than 4 joints remain, the 4 largest stay and
 * are renormalised, and the caller counts the event.
 */
#include <math.h>
#include <string.h>

#include "mesh/mlod_mesh.h"

void mlod_power_weights(const mlod_v3 *v, int k, mlod_v3 vbar, double *W)
{
	if (k <= 0)
		return;
	if (k == 1) {
		W[0] = 1.0;
		return;
	}
	double D = 0.0;
	for (int i = 0; i < k; i++) {
		double dx = (double)vbar.x - v[i].x, dy = (double)vbar.y - v[i].y, dz = (double)vbar.z - v[i].z;
		W[i] = sqrt(dx * dx + dy * dy + dz * dz); /* d_i for now */
		D += W[i];
	}
	if (!(D > 0.0) || !isfinite(D)) {
		for (int i = 0; i < k; i++)
			W[i] = 1.0 / k;
		return;
	}
	for (int i = 0; i < k; i++)
		W[i] = (D - W[i]) / ((k - 1) * D);
}

/* Sorts influences by weight, largest first; equal weights by joint. */
static void sort_influences(mlod_influences *x)
{
	for (int i = 1; i < x->count; i++) {
		uint16_t j = x->joints[i];
		float w = x->weights[i];
		int k = i;
		while (k > 0 && (x->weights[k - 1] < w || (x->weights[k - 1] == w && x->joints[k - 1] > j))) {
			x->joints[k] = x->joints[k - 1];
			x->weights[k] = x->weights[k - 1];
			k--;
		}
		x->joints[k] = j;
		x->weights[k] = w;
	}
}

int mlod_power_skin(const mlod_v3 *v, const mlod_influences *in, int k, mlod_v3 vbar, mlod_influences *out)
{
	double W[MLOD_MAX_INFLUENCES];
	uint16_t joint[3 * MLOD_MAX_INFLUENCES];
	double weight[3 * MLOD_MAX_INFLUENCES];
	int n = 0, capped = 0;
	if (k > MLOD_MAX_INFLUENCES)
		k = MLOD_MAX_INFLUENCES;
	memset(out, 0, sizeof *out);
	if (k <= 0)
		return 0;
	mlod_power_weights(v, k, vbar, W);
	/* The accumulator: sum_i W_i w(j, v_i) per joint. */
	for (int i = 0; i < k; i++)
		for (int a = 0; a < in[i].count && a < MLOD_MAX_INFLUENCES; a++) {
			if (!(in[i].weights[a] > 0.0f))
				continue;
			int s = 0;
			while (s < n && joint[s] != in[i].joints[a])
				s++;
			if (s == n) {
				if (n == (int)(sizeof joint / sizeof *joint))
					continue;
				joint[n] = in[i].joints[a];
				weight[n++] = 0.0;
			}
			weight[s] += W[i] * in[i].weights[a];
		}
	/* Largest first, equal weights by joint. */
	for (int i = 1; i < n; i++) {
		uint16_t j = joint[i];
		double w = weight[i];
		int s = i;
		while (s > 0 && (weight[s - 1] < w || (weight[s - 1] == w && joint[s - 1] > j))) {
			joint[s] = joint[s - 1];
			weight[s] = weight[s - 1];
			s--;
		}
		joint[s] = j;
		weight[s] = w;
	}
	while (n > 0 && !(weight[n - 1] > 0.0))
		n--;
	if (n > 4) {
		n = 4;
		capped = 1;
	}
	double sum = 0.0;
	for (int i = 0; i < n; i++)
		sum += weight[i];
	if (!(sum > 0.0))
		return capped;
	out->count = n;
	for (int i = 0; i < n; i++) {
		out->joints[i] = joint[i];
		out->weights[i] = (float)(weight[i] / sum);
	}
	/* Float rounding: put the remainder on the largest weight so the sum
	 * is 1 as closely as floats allow. */
	double fs = 0.0;
	for (int i = 1; i < n; i++)
		fs += out->weights[i];
	out->weights[0] = (float)(1.0 - fs);
	sort_influences(out);
	return capped;
}
