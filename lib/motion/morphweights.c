/*
 * morphweights.c: morph target weight channels of a motion level.
 *
 * Beyond the paper, whose motion layer (4.3) reduces joint motion only.
 * A weights channel animates every target of a node's mesh with one key
 * list, so keys go per channel. A weight error dw on target t moves each
 * vertex v by dw * delta_t(v) (through the mesh's placement), so
 *
 *     sum over targets of |dw_t| * reach_t,
 *
 * reach_t the largest |delta_t(v)| as placed in the rest pose (rigidly, or
 * through each vertex's skinning matrices), bounds how far any vertex
 * moves: an error in scene units, like the joint error of the level it
 * goes with. Keys go greedily: from a kept key, the segment reaches as far
 * as the error stays within the bound at every key time and the times
 * between (the same samples as the joints, mlod_motion_sample_times).
 * The first and last keys stay, except that a track that comes down to
 * two equal keys (a constant) keeps one.
 */
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "motion/mlod_motion.h"

/* How far offset d moves once placed by m (its 3x3 part). */
static double moved(const mlod_mat4 *m, const float *d)
{
	mlod_v3 v = mlod_mat4_vector(m, (mlod_v3){ d[0], d[1], d[2] });
	return mlod_v3_length(v);
}

mlod_result mlod_morph_target_reach(const mlod_character *c, int node, int targets, double *out, mlod_error *err)
{
	if (!c || !out || targets <= 0)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_morph_target_reach: NULL argument or no targets");
	const mlod_instance *in = NULL;
	for (int i = 0; i < c->instance_count && !in; i++)
		if (c->instances[i].node == node)
			in = &c->instances[i];
	if (!in || in->mesh < 0 || in->mesh >= c->mesh_count)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "node %d places no mesh of the character", node);
	const mlod_mesh *mesh = &c->meshes[in->mesh];
	const mlod_skeleton *s = &c->skeleton;
	int J = s->joint_count > 0 ? s->joint_count : 1;
	const mlod_skin *skin = in->skin >= 0 && in->skin < s->skin_count ? &s->skins[in->skin] : NULL;
	mlod_trs *local = malloc(sizeof *local * (size_t)J);
	mlod_mat4 *world = malloc(sizeof *world * (size_t)J);
	mlod_mat4 *mats = malloc(sizeof *mats * (size_t)(skin && skin->joint_count > 0 ? skin->joint_count : 1));
	if (!local || !world || !mats) {
		free(local), free(world), free(mats);
		return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
	}
	mlod_result r = MLOD_OK;
	for (int t = 0; t < targets; t++)
		out[t] = 0.0;
	if (s->joint_count > 0) {
		mlod_pose_rest(s, local);
		mlod_pose_world(s, local, world);
	}
	mlod_mat4 rigid = in->offset;
	if (!skin && in->joint >= 0 && in->joint < s->joint_count)
		rigid = mlod_mat4_mul(&world[in->joint], &in->offset);
	if (skin)
		mlod_skin_matrices(skin, world, mats);
	for (int p = 0; p < mesh->primitive_count && r == MLOD_OK; p++) {
		const mlod_primitive *pr = &mesh->primitives[p];
		if (pr->target_count != targets) {
			r = mlod_fail(err, MLOD_ERR_INVALID_ARG, "node %d: its mesh has %d morph targets, the channel %d", node,
			              pr->target_count, targets);
			break;
		}
		for (int v = 0; v < pr->vertex_count; v++) {
			mlod_mat4 m = rigid;
			if (skin && pr->weight_set_count > 0) {
				/* The blend of the vertex's skinning matrices, as skinning does. */
				memset(&m, 0, sizeof m);
				for (int set = 0; set < pr->weight_set_count; set++)
					for (int k = 0; k < 4; k++) {
						float w = pr->weights[set][4 * v + k];
						int j = pr->joints[set][4 * v + k];
						if (w <= 0.0f || j >= skin->joint_count)
							continue;
						for (int e = 0; e < 16; e++)
							m.m[e] += w * mats[j].m[e];
					}
			}
			for (int t = 0; t < targets; t++) {
				const float *d = pr->targets[t].positions;
				if (!d)
					continue;
				double e = moved(&m, d + 3 * v);
				if (e > out[t])
					out[t] = e;
			}
		}
	}
	free(local), free(world), free(mats);
	return r;
}

/* The value of target c of a LINEAR or STEP track at time t between its
 * keys a < b (a <= t <= b), as players interpolate. */
static float track_value(const mlod_weight_track *tr, int a, int b, int c, float t)
{
	const float *va = tr->values + (size_t)a * (size_t)tr->targets;
	if (tr->interp == MLOD_INTERP_STEP || !(t > tr->times[a]))
		return va[c];
	if (!(t < tr->times[b]))
		return tr->values[(size_t)b * (size_t)tr->targets + (size_t)c];
	const float *vb = tr->values + (size_t)b * (size_t)tr->targets;
	const float u = (t - tr->times[a]) / (tr->times[b] - tr->times[a]);
	return va[c] + (vb[c] - va[c]) * u;
}

/* The largest error over samples lo..hi (sample i in interval i / sub) of
 * the segment from key a to key b against the track's own keys. */
static double segment_error(const mlod_weight_track *tr, const double *reach, const float *st, int sub, int a, int b,
                            int lo, int hi)
{
	double worst = 0.0;
	for (int i = lo; i <= hi; i++) {
		int k = i / sub;
		int k1 = k + 1 < tr->key_count ? k + 1 : k;
		double e = 0.0;
		for (int c = 0; c < tr->targets; c++)
			e += fabs((double)track_value(tr, a, b, c, st[i]) - track_value(tr, k, k1, c, st[i])) * reach[c];
		if (!(e <= worst))
			worst = e;
	}
	return worst;
}

mlod_result mlod_weight_track_reduce(const mlod_weight_track *in, const double *reach, double bound, int subdivide,
                                     mlod_weight_track *out, double *error, mlod_error *err)
{
	if (!in || !reach || !out || !error)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_weight_track_reduce: NULL argument");
	memset(out, 0, sizeof *out);
	*error = 0.0;
	if (in->interp == MLOD_INTERP_CUBICSPLINE)
		return mlod_fail(err, MLOD_ERR_UNSUPPORTED, "node %d: CUBICSPLINE weights are not reduced", in->node);
	if (in->key_count <= 0 || in->targets <= 0 || !in->times || !in->values || !(bound >= 0.0) || subdivide < 1 ||
	    subdivide > MLOD_MAX_SUBDIVIDE)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_weight_track_reduce: no keys, or a bad bound or subdivide");
	if ((double)(in->key_count - 1) * subdivide + 1.0 > (double)INT_MAX / 16)
		return mlod_fail(err, MLOD_ERR_UNSUPPORTED, "node %d: %d keys at %d samples each are too many", in->node,
		                 in->key_count, subdivide);
	int n = in->key_count, sub = subdivide, S = (n - 1) * sub + 1;
	float *st = malloc(sizeof(float) * (size_t)S);
	unsigned char *keep = calloc((size_t)n, 1);
	if (!st || !keep) {
		free(st), free(keep);
		return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
	}
	mlod_motion_sample_times(in->times, n, sub, st);
	keep[0] = keep[n - 1] = 1;
	for (int a = 0; a < n - 1;) {
		/* The farthest b whose segment stays within the bound: gallop,
		 * then bisect (a segment of one interval is the track itself). */
		int b = a + 1, fail = -1;
		for (int step = 1; b < n - 1; step *= 2) {
			int t = b + step < n - 1 ? b + step : n - 1;
			if (segment_error(in, reach, st, sub, a, t, a * sub, t * sub) <= bound) {
				b = t;
			} else {
				fail = t;
				break;
			}
		}
		while (fail > b + 1) {
			int mid = b + (fail - b) / 2;
			if (segment_error(in, reach, st, sub, a, mid, a * sub, mid * sub) <= bound)
				b = mid;
			else
				fail = mid;
		}
		keep[b] = 1;
		double e = segment_error(in, reach, st, sub, a, b, a * sub, b * sub);
		if (!(e <= *error))
			*error = e;
		a = b;
	}
	int kept = 0;
	for (int k = 0; k < n; k++)
		kept += keep[k];
	/* Two equal ends are a constant: one key. */
	if (kept == 2 && n > 1 &&
	    memcmp(in->values, in->values + (size_t)(n - 1) * (size_t)in->targets, sizeof(float) * (size_t)in->targets) == 0) {
		keep[n - 1] = 0;
		kept = 1;
	}
	*out = *in;
	out->key_count = kept;
	out->times = malloc(sizeof(float) * (size_t)kept);
	out->values = malloc(sizeof(float) * (size_t)kept * (size_t)in->targets);
	if (!out->times || !out->values) {
		free(out->times), free(out->values);
		memset(out, 0, sizeof *out);
		free(st), free(keep);
		return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
	}
	for (int k = 0, i = 0; k < n; k++)
		if (keep[k]) {
			out->times[i] = in->times[k];
			memcpy(out->values + (size_t)i * (size_t)in->targets, in->values + (size_t)k * (size_t)in->targets,
			       sizeof(float) * (size_t)in->targets);
			i++;
		}
	free(st), free(keep);
	return MLOD_OK;
}

long mlod_weight_tracks_keys(const mlod_weight_track *tracks, int count)
{
	long n = 0;
	for (int i = 0; tracks && i < count; i++)
		n += tracks[i].key_count;
	return n;
}

long mlod_weight_tracks_bytes(const mlod_weight_track *tracks, int count)
{
	long bytes = 0;
	for (int i = 0; tracks && i < count; i++) {
		const mlod_weight_track *t = &tracks[i];
		bytes += (long)t->key_count * t->targets * (t->interp == MLOD_INTERP_CUBICSPLINE ? 3 : 1) * 4;
		int shared = 0;
		for (int k = 0; k < i && !shared; k++)
			shared = tracks[k].key_count == t->key_count &&
			         memcmp(tracks[k].times, t->times, sizeof(float) * (size_t)t->key_count) == 0;
		if (!shared)
			bytes += (long)t->key_count * 4;
	}
	return bytes;
}
