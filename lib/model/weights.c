/*
 * weights.c: the one rule for skin weights glTF does not allow
 * (mlod_model.h): a vertex whose weights are all 0 goes on the skin's
 * root joint, and weights that do not sum to 1 are scaled to. The glTF
 * reader applies it to every skinned primitive, so that every level a
 * tool writes and every measure agrees with the pack, whose weights sum
 * to 255 and so cannot say "no weight".
 */
#include <math.h>

#include "model/mlod_model.h"

int mlod_skin_root(const mlod_skeleton *s, int skin)
{
	if (!s || skin < 0 || skin >= s->skin_count)
		return -1;
	const mlod_skin *sk = &s->skins[skin];
	int best = -1, best_depth = -1;
	for (int q = 0; q < sk->joint_count; q++) {
		int depth = 0, j = sk->joints[q];
		while (j >= 0 && j < s->joint_count && depth <= s->joint_count)
			j = s->joints[j].parent, depth++;
		if (best_depth < 0 || depth < best_depth)
			best = q, best_depth = depth;
	}
	return best;
}

/* The sum of vertex v's weights as the Khronos validator adds them: in
 * float, the first influence of every set, then the second, and so on;
 * *nonzero gets the count of positive weights. -1 when a weight is
 * negative or not finite (mlod_character_validate refuses those). */
static float vertex_sum(const mlod_primitive *p, int v, int *nonzero)
{
	float sum = 0.0f;
	*nonzero = 0;
	for (int i = 0; i < 4; i++)
		for (int s = 0; s < p->weight_set_count; s++) {
			float w = p->weights[s][4 * (size_t)v + (size_t)i];
			if (!(w >= 0.0f) || !isfinite(w))
				return -1.0f;
			if (w > 0.0f)
				sum += w, (*nonzero)++;
		}
	return sum;
}

/* Whether the validator takes the sum: within 2e-7 of 1 per non-zero
 * weight (its ACCESSOR_WEIGHTS_NON_NORMALIZED tolerance). */
static int sum_ok(float sum, int nonzero)
{
	return fabsf(sum - 1.0f) <= 2e-7f * (float)nonzero;
}

void mlod_primitive_fix_weights(mlod_primitive *p, int root, mlod_weight_fix *fix)
{
	fix->unweighted = fix->rescaled = 0;
	fix->first_unweighted = fix->first_rescaled = -1;
	fix->first_sum = 0.0f;
	if (!p || p->weight_set_count <= 0 || p->weight_set_count > MLOD_MAX_SETS)
		return;
	for (int s = 0; s < p->weight_set_count; s++)
		if (!p->joints[s] || !p->weights[s]) /* mlod_character_validate refuses it */
			return;
	for (int v = 0; v < p->vertex_count; v++) {
		int nonzero;
		float sum = vertex_sum(p, v, &nonzero);
		if (sum < 0.0f || (nonzero > 0 && sum_ok(sum, nonzero)))
			continue;
		if (nonzero == 0) {
			if (fix->unweighted++ == 0)
				fix->first_unweighted = v;
			if (root < 0)
				continue;
			for (int s = 0; s < p->weight_set_count; s++)
				for (int i = 0; i < 4; i++)
					p->joints[s][4 * (size_t)v + (size_t)i] = 0;
			p->joints[0][4 * (size_t)v] = (uint16_t)root;
			p->weights[0][4 * (size_t)v] = 1.0f;
			continue;
		}
		if (fix->rescaled++ == 0)
			fix->first_rescaled = v, fix->first_sum = sum;
		/* Scaled in double, then the float rounding that is left (a few
		 * ulps) goes on the largest weight, which it changes least. */
		double total = 0.0;
		for (int s = 0; s < p->weight_set_count; s++)
			for (int i = 0; i < 4; i++)
				total += p->weights[s][4 * (size_t)v + (size_t)i];
		float *largest = NULL;
		for (int s = 0; s < p->weight_set_count; s++)
			for (int i = 0; i < 4; i++) {
				float *w = &p->weights[s][4 * (size_t)v + (size_t)i];
				*w = (float)(*w / total);
				if (!largest || *w > *largest)
					largest = w;
			}
		sum = vertex_sum(p, v, &nonzero);
		if (!sum_ok(sum, nonzero))
			*largest += 1.0f - sum;
	}
}
