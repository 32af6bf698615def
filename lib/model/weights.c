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

/* Merges the influences of vertex v that name one joint twice or more
 * with non-zero weights (the validator's ACCESSOR_JOINTS_INDEX_DUPLICATE)
 * into the first of them, in the order vertex_sum reads them: its weight
 * takes theirs, and each later one becomes joint 0 at weight 0. Changes
 * no pose: skinning sums the influences of a joint however many slots
 * hold them. Returns whether it merged any. A negative or non-finite
 * weight is left for mlod_character_validate. */
static int merge_repeats(mlod_primitive *p, int v)
{
	const int n = 4 * p->weight_set_count;
	int merged = 0;
	for (int a = 0; a < n; a++) {
		float *wa = &p->weights[a % p->weight_set_count][4 * (size_t)v + (size_t)(a / p->weight_set_count)];
		if (!(*wa > 0.0f) || !isfinite(*wa))
			continue;
		uint16_t ja = p->joints[a % p->weight_set_count][4 * (size_t)v + (size_t)(a / p->weight_set_count)];
		for (int b = a + 1; b < n; b++) {
			const size_t at = 4 * (size_t)v + (size_t)(b / p->weight_set_count);
			float *wb = &p->weights[b % p->weight_set_count][at];
			uint16_t *jb = &p->joints[b % p->weight_set_count][at];
			if (*jb != ja || !(*wb > 0.0f) || !isfinite(*wb))
				continue;
			*wa += *wb;
			*wb = 0.0f, *jb = 0;
			merged = 1;
		}
	}
	return merged;
}

/* Whether the validator takes the sum: within 2e-7 of 1 per non-zero
 * weight (its ACCESSOR_WEIGHTS_NON_NORMALIZED tolerance). */
static int sum_ok(float sum, int nonzero)
{
	return fabsf(sum - 1.0f) <= 2e-7f * (float)nonzero;
}

void mlod_primitive_fix_weights(mlod_primitive *p, int root, mlod_weight_fix *fix)
{
	fix->unweighted = fix->rescaled = fix->merged = 0;
	fix->first_unweighted = fix->first_rescaled = fix->first_merged = -1;
	fix->first_sum = 0.0f;
	if (!p || p->weight_set_count <= 0 || p->weight_set_count > MLOD_MAX_SETS)
		return;
	for (int s = 0; s < p->weight_set_count; s++)
		if (!p->joints[s] || !p->weights[s]) /* mlod_character_validate refuses it */
			return;
	for (int v = 0; v < p->vertex_count; v++) {
		if (merge_repeats(p, v) && fix->merged++ == 0)
			fix->first_merged = v;
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
