/*
 * eligible.c: eligible vertices, skeletal-controlled mesh simplification
 * (Savoye & Meyer 2008, 4.2.2).
 *
 * eta(j), the blend weight average of joint j, is the mean of the
 * non-zero weights j has on the character's vertices. The paper's rule
 * (MLOD_ELIGIBLE_LITERAL): v may disappear if and only if w(j, v) <
 * tau * eta(j) for every joint j. Read literally it protects the vertices
 * one joint dominates (the middle of a bone segment) and frees the ones
 * whose weight is split (the bends), the opposite of the stated intent
 * ("preserve high-detail regions around joints"; mlod-bgm(1), Eligible
 * vertices).
 * MLOD_ELIGIBLE_BEND protects the bends instead: v may disappear only when
 * its largest weight w(j, v) reaches tau * eta(j) for that joint, i.e.
 * when one joint dominates it at least as much as that joint usually
 * dominates its vertices. Vertices without influences (static meshes)
 * are eligible under every rule. bench/mesh.sh measures both rules on
 * posed error; the default follows the measurement.
 */
#include <stdlib.h>
#include <string.h>

#include "mesh/mlod_mesh.h"

mlod_result mlod_joint_weight_average(const mlod_character *c, double *eta, mlod_error *err)
{
	if (!c || !eta)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_joint_weight_average: NULL argument");
	int n = c->skeleton.joint_count;
	long *count = calloc((size_t)n + 1, sizeof *count);
	if (!count)
		return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory averaging weights");
	for (int j = 0; j < n; j++)
		eta[j] = 0.0;
	for (int i = 0; i < c->instance_count; i++) {
		const mlod_instance *in = &c->instances[i];
		if (in->mesh < 0 || in->mesh >= c->mesh_count)
			continue;
		const mlod_mesh *m = &c->meshes[in->mesh];
		for (int p = 0; p < m->primitive_count; p++) {
			const mlod_primitive *pr = &m->primitives[p];
			if (in->skin >= 0 && in->skin < c->skeleton.skin_count) {
				const mlod_skin *skin = &c->skeleton.skins[in->skin];
				for (int s = 0; s < pr->weight_set_count && s < MLOD_MAX_SETS; s++) {
					if (!pr->weights[s] || !pr->joints[s])
						continue;
					for (long v = 0; v < 4L * pr->vertex_count; v++) {
						float w = pr->weights[s][v];
						int j = pr->joints[s][v];
						if (!(w > 0.0f) || j >= skin->joint_count)
							continue;
						j = skin->joints[j];
						if (j < 0 || j >= n)
							continue;
						eta[j] += w;
						count[j]++;
					}
				}
			} else if (in->joint >= 0 && in->joint < n) {
				eta[in->joint] += pr->vertex_count;
				count[in->joint] += pr->vertex_count;
			}
		}
	}
	for (int j = 0; j < n; j++)
		eta[j] = count[j] > 0 ? eta[j] / (double)count[j] : 0.0;
	free(count);
	return MLOD_OK;
}

int mlod_vertex_eligible(mlod_eligibility rule, double tau, const mlod_influences *inf, const int *joint_map,
                         const double *eta)
{
	if (tau <= 0.0)
		tau = 1.0;
	if (rule == MLOD_ELIGIBLE_ALL || inf->count <= 0)
		return 1;
	if (rule == MLOD_ELIGIBLE_LITERAL) {
		for (int i = 0; i < inf->count; i++)
			if (inf->weights[i] > 0.0f && !((double)inf->weights[i] < tau * eta[joint_map[inf->joints[i]]]))
				return 0;
		return 1;
	}
	/* MLOD_ELIGIBLE_BEND (and the default). */
	int best = -1;
	for (int i = 0; i < inf->count; i++)
		if (inf->weights[i] > 0.0f && (best < 0 || inf->weights[i] > inf->weights[best]))
			best = i;
	if (best < 0)
		return 1;
	return (double)inf->weights[best] >= tau * eta[joint_map[inf->joints[best]]];
}
