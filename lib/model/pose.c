/*
 * pose.c: clip sampling, forward kinematics and linear blend skinning.
 *
 * Sampling follows glTF 2.0 (Appendix C): STEP holds a key, LINEAR
 * interpolates (rotations by spherical interpolation along the shorter
 * arc, as the spec requires; frames removed by motion LoD leave keys far
 * apart, where nlerp would drift from what viewers play), CUBICSPLINE is
 * the Hermite spline with tangents scaled by the key interval. Skinning
 * is linear blend skinning over all weight sets: each vertex is moved by
 * the weighted sum of its joints' skin matrices (normalised by the weight
 * sum), normals by that matrix's 3x3 part and renormalised.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "model/mlod_model.h"

void mlod_pose_rest(const mlod_skeleton *s, mlod_trs *local)
{
	for (int i = 0; i < s->joint_count; i++)
		local[i] = s->joints[i].rest;
}

/* ---------------------------------------------------------------- */
/* Sampling                                                          */
/* ---------------------------------------------------------------- */

/* The key k with times[k] <= t < times[k + 1], for times[0] <= t < times[n - 1]. */
static int find_key(const float *times, int n, float t)
{
	int lo = 0, hi = n - 1;
	while (hi - lo > 1) {
		int mid = lo + (hi - lo) / 2;
		if (times[mid] <= t)
			lo = mid;
		else
			hi = mid;
	}
	return lo;
}

/* Samples one channel at t into out (comps floats). */
static void sample_channel(const mlod_channel *ch, float t, int comps, float *out)
{
	const int n = ch->key_count;
	/* CUBICSPLINE keys are (in-tangent, value, out-tangent) triples. */
	const int cubic = ch->interp == MLOD_INTERP_CUBICSPLINE;
	const int stride = cubic ? 3 * comps : comps, value = cubic ? comps : 0;
	const float *v = ch->values;
	int k;
	if (n == 1 || !(t > ch->times[0]))
		k = 0;
	else if (t >= ch->times[n - 1])
		k = n - 1;
	else
		k = -1;
	if (k >= 0) { /* outside the keys, or a constant */
		memcpy(out, v + k * stride + value, (size_t)comps * sizeof *out);
		return;
	}
	k = find_key(ch->times, n, t);
	const float t0 = ch->times[k], t1 = ch->times[k + 1], dt = t1 - t0;
	const float u = (t - t0) / dt;
	const float *a = v + k * stride, *b = v + (k + 1) * stride;
	switch (ch->interp) {
	case MLOD_INTERP_STEP:
		memcpy(out, a, (size_t)comps * sizeof *out);
		break;
	case MLOD_INTERP_LINEAR:
		if (comps == 4) {
			mlod_quat qa = { a[0], a[1], a[2], a[3] }, qb = { b[0], b[1], b[2], b[3] };
			mlod_quat q = mlod_quat_slerp(qa, qb, u);
			out[0] = q.x, out[1] = q.y, out[2] = q.z, out[3] = q.w;
		} else {
			for (int c = 0; c < comps; c++)
				out[c] = a[c] + (b[c] - a[c]) * u;
		}
		break;
	case MLOD_INTERP_CUBICSPLINE: {
		/* p = h00 v_k + h10 dt b_k + h01 v_k+1 + h11 dt a_k+1 (glTF Appendix C) */
		const float u2 = u * u, u3 = u2 * u;
		const float h00 = 2 * u3 - 3 * u2 + 1, h10 = u3 - 2 * u2 + u;
		const float h01 = -2 * u3 + 3 * u2, h11 = u3 - u2;
		for (int c = 0; c < comps; c++)
			out[c] = h00 * a[comps + c] + h10 * dt * a[2 * comps + c] + h01 * b[comps + c] + h11 * dt * b[c];
		break;
	}
	}
}

void mlod_channel_sample(const mlod_channel *ch, float duration, float t, mlod_trs *l)
{
	if (!(t > 0.0f))
		t = 0.0f; /* also NaN */
	if (t > duration)
		t = duration;
	float v[4];
	if (ch->key_count < 1)
		return;
	switch (ch->path) {
	case MLOD_PATH_TRANSLATION:
		sample_channel(ch, t, 3, v);
		l->t.x = v[0], l->t.y = v[1], l->t.z = v[2];
		break;
	case MLOD_PATH_SCALE:
		sample_channel(ch, t, 3, v);
		l->s.x = v[0], l->s.y = v[1], l->s.z = v[2];
		break;
	case MLOD_PATH_ROTATION: {
		sample_channel(ch, t, 4, v);
		mlod_quat q = { v[0], v[1], v[2], v[3] };
		l->r = mlod_quat_normalize(q);
		break;
	}
	}
}

void mlod_clip_sample(const mlod_clip *clip, float t, mlod_trs *local)
{
	for (int i = 0; i < clip->channel_count; i++)
		mlod_channel_sample(&clip->channels[i], clip->duration, t, &local[clip->channels[i].joint]);
}

/* ---------------------------------------------------------------- */
/* Forward kinematics                                                */
/* ---------------------------------------------------------------- */

void mlod_pose_world(const mlod_skeleton *s, const mlod_trs *local, mlod_mat4 *world)
{
	for (int i = 0; i < s->joint_count; i++) {
		const mlod_joint *j = &s->joints[i];
		mlod_mat4 l = mlod_mat4_from_trs(&local[i]);
		/* parents come first, so world[parent] is ready */
		world[i] = mlod_mat4_mul(j->parent < 0 ? &j->base : &world[j->parent], &l);
	}
}

void mlod_skin_matrices(const mlod_skin *skin, const mlod_mat4 *world, mlod_mat4 *out)
{
	for (int k = 0; k < skin->joint_count; k++)
		out[k] = mlod_mat4_mul(&world[skin->joints[k]], &skin->inverse_bind[k]);
}

/* ---------------------------------------------------------------- */
/* Skinning                                                          */
/* ---------------------------------------------------------------- */

/* The blended skin matrix of vertex v (column-major, 16 floats: the
 * fourth row is blended too, and unused, so that each column is four
 * floats the compiler can treat as one vector) and the sum of its
 * weights. Every entry gets the same operations in the same order
 * whichever of the callers below runs it, so mlod_skin_vertex and
 * mlod_skin_primitive give the same bits. */
static inline float skin_blend(const mlod_primitive *p, int v, const mlod_mat4 *skin_mats, float m[16])
{
	float wsum = 0.0f;
	for (int e = 0; e < 16; e++)
		m[e] = 0.0f;
	for (int s = 0; s < p->weight_set_count; s++) {
		const float *ws = p->weights[s] + 4 * v;
		const uint16_t *js = p->joints[s] + 4 * v;
		for (int k = 0; k < 4; k++) {
			float w = ws[k];
			if (!(w > 0.0f))
				continue;
			const float *j = skin_mats[js[k]].m;
			/* column by column: one vector operation each */
			for (int e = 0; e < 4; e++)
				m[e] += w * j[e];
			for (int e = 4; e < 8; e++)
				m[e] += w * j[e];
			for (int e = 8; e < 12; e++)
				m[e] += w * j[e];
			for (int e = 12; e < 16; e++)
				m[e] += w * j[e];
			wsum += w;
		}
	}
	return wsum;
}

/* The skinned position of a vertex at pos with blended matrix m and
 * weight sum wsum > 0. */
static inline void skin_point(const float m[16], const float *pos, float wsum, float *op)
{
	const float inv = 1.0f / wsum;
	float o[4]; /* the fourth row too: four lanes */
	for (int r = 0; r < 4; r++)
		o[r] = (m[r] * pos[0] + m[4 + r] * pos[1] + m[8 + r] * pos[2] + m[12 + r]) * inv;
	memcpy(op, o, 3 * sizeof *op);
}

void mlod_skin_vertex(const mlod_primitive *p, int v, const mlod_mat4 *skin_mats, float out[3])
{
	float m[16];
	float wsum = skin_blend(p, v, skin_mats, m);
	if (!(wsum > 0.0f))
		memcpy(out, p->positions + 3 * v, 3 * sizeof *out);
	else
		skin_point(m, p->positions + 3 * v, wsum, out);
}

void mlod_skin_primitive(const mlod_primitive *p, const mlod_mat4 *skin_mats,
                         float *out_positions, float *out_normals)
{
	const int do_normals = out_normals && p->normals;
	for (int v = 0; v < p->vertex_count; v++) {
		const float *pos = p->positions + 3 * v;
		float m[16];
		float wsum = skin_blend(p, v, skin_mats, m);
		float *op = out_positions + 3 * v;
		if (!(wsum > 0.0f)) { /* unweighted: stays at bind */
			memcpy(op, pos, 3 * sizeof *op);
			if (do_normals)
				memcpy(out_normals + 3 * v, p->normals + 3 * v, 3 * sizeof *out_normals);
			continue;
		}
		skin_point(m, pos, wsum, op);
		if (do_normals) {
			const float *n = p->normals + 3 * v;
			float *on = out_normals + 3 * v, len2 = 0.0f;
			for (int r = 0; r < 3; r++) {
				on[r] = m[r] * n[0] + m[4 + r] * n[1] + m[8 + r] * n[2];
				len2 += on[r] * on[r];
			}
			if (len2 > 0.0f) {
				const float il = 1.0f / sqrtf(len2);
				for (int r = 0; r < 3; r++)
					on[r] *= il;
			}
		}
	}
}

/* ---------------------------------------------------------------- */
/* Posing the whole character                                        */
/* ---------------------------------------------------------------- */

static long primitive_triangles(const mlod_primitive *p)
{
	if (p->mode != 4 || p->vertex_count <= 0)
		return 0;
	return (p->index_count > 0 ? p->index_count : p->vertex_count) / 3;
}

/* Grows out's buffers to hold the given counts (never shrinks them). */
static mlod_result posed_reserve(mlod_posed *out, long vertices, long triangles, mlod_error *err)
{
	if (vertices > out->vertex_count) {
		float *p = realloc(out->positions, (size_t)vertices * 3 * sizeof *p);
		if (!p)
			return mlod_fail(err, MLOD_ERR_NOMEM, "posing: cannot allocate %ld vertices", vertices);
		out->positions = p;
	}
	if (triangles > out->triangle_count) {
		uint32_t *ix = realloc(out->indices, (size_t)triangles * 3 * sizeof *ix);
		if (!ix)
			return mlod_fail(err, MLOD_ERR_NOMEM, "posing: cannot allocate %ld triangles", triangles);
		out->indices = ix;
	}
	return MLOD_OK;
}

/* Places one primitive's vertices (skinned or rigid) at out + 3 * base and
 * its triangles at tri, indexed from base. */
static void pose_primitive(const mlod_primitive *p, const mlod_mat4 *skin_mats, const mlod_mat4 *rigid,
                           float *positions, uint32_t base, uint32_t *tri)
{
	if (skin_mats) {
		mlod_skin_primitive(p, skin_mats, positions, NULL);
	} else {
		for (int v = 0; v < p->vertex_count; v++) {
			mlod_v3 q = { p->positions[3 * v], p->positions[3 * v + 1], p->positions[3 * v + 2] };
			q = mlod_mat4_point(rigid, q);
			positions[3 * v] = q.x, positions[3 * v + 1] = q.y, positions[3 * v + 2] = q.z;
		}
	}
	long n = 3 * primitive_triangles(p);
	if (p->index_count > 0 && base == 0)
		memcpy(tri, p->indices, (size_t)n * sizeof *tri);
	else if (p->index_count > 0)
		for (long i = 0; i < n; i++)
			tri[i] = base + p->indices[i];
	else
		for (long i = 0; i < n; i++)
			tri[i] = base + (uint32_t)i;
}

mlod_result mlod_pose_character(const mlod_character *c, const mlod_mat4 *world,
                                mlod_posed *out, mlod_error *err)
{
	if (!c || !out || (!world && c->skeleton.joint_count > 0))
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "posing: NULL argument");
	const mlod_skeleton *s = &c->skeleton;
	long vertices = 0, triangles = 0;
	int max_skin = 0;
	for (int i = 0; i < c->instance_count; i++) {
		const mlod_instance *in = &c->instances[i];
		if (in->mesh < 0 || in->mesh >= c->mesh_count || in->skin < -1 || in->skin >= s->skin_count ||
		    in->joint < -1 || in->joint >= s->joint_count)
			return mlod_fail(err, MLOD_ERR_INVALID_ARG, "posing: instance %d refers outside the character", i);
		if (in->skin >= 0 && s->skins[in->skin].joint_count > max_skin)
			max_skin = s->skins[in->skin].joint_count;
		const mlod_mesh *m = &c->meshes[in->mesh];
		for (int p = 0; p < m->primitive_count; p++) {
			long t = primitive_triangles(&m->primitives[p]);
			if (t > 0) {
				vertices += m->primitives[p].vertex_count;
				triangles += t;
			}
		}
		if (vertices > INT32_MAX / 3 || triangles > INT32_MAX / 3)
			return mlod_fail(err, MLOD_ERR_NOMEM, "posing: more than %d vertices or triangles", INT32_MAX / 3);
	}
	mlod_result r = posed_reserve(out, vertices, triangles, err);
	if (r)
		return r;
	mlod_mat4 *skin_mats = NULL;
	if (max_skin > 0 && !(skin_mats = malloc((size_t)max_skin * sizeof *skin_mats)))
		return mlod_fail(err, MLOD_ERR_NOMEM, "posing: cannot allocate %d skin matrices", max_skin);

	long v = 0, t = 0;
	for (int i = 0; i < c->instance_count; i++) {
		const mlod_instance *in = &c->instances[i];
		const mlod_mesh *m = &c->meshes[in->mesh];
		mlod_mat4 rigid = in->offset;
		if (in->skin >= 0)
			mlod_skin_matrices(&s->skins[in->skin], world, skin_mats);
		else if (in->joint >= 0)
			rigid = mlod_mat4_mul(&world[in->joint], &in->offset);
		for (int p = 0; p < m->primitive_count; p++) {
			const mlod_primitive *prim = &m->primitives[p];
			if (primitive_triangles(prim) == 0)
				continue;
			pose_primitive(prim, in->skin >= 0 ? skin_mats : NULL, &rigid, out->positions + 3 * v,
			               (uint32_t)v, out->indices + 3 * t);
			v += prim->vertex_count;
			t += primitive_triangles(prim);
		}
	}
	free(skin_mats);
	out->vertex_count = (int)vertices;
	out->triangle_count = (int)triangles;
	return MLOD_OK;
}

void mlod_posed_free(mlod_posed *p)
{
	if (!p)
		return;
	free(p->positions);
	free(p->indices);
	memset(p, 0, sizeof *p);
}
