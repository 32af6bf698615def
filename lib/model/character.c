/*
 * character.c: lifetime and invariants of the character model.
 *
 * mlod_character_free releases everything a reader allocated;
 * mlod_character_validate checks what the rest of the library relies on
 * (parents before children, every index in range, finite numbers,
 * increasing key times, non-negative weights) and names the first problem;
 * mlod_skeleton_height gives the scale of every "% of the height",
 * mlod_skeleton_extent the scale of numeric tolerances.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "model/mlod_model.h"

void mlod_primitive_free(mlod_primitive *p)
{
	if (!p)
		return;
	free(p->positions);
	free(p->normals);
	free(p->tangents);
	for (int i = 0; i < MLOD_MAX_SETS; i++) {
		free(p->uvs[i]);
		free(p->colors[i]);
		free(p->joints[i]);
		free(p->weights[i]);
	}
	free(p->indices);
	for (int t = 0; p->targets && t < p->target_count; t++) {
		free(p->targets[t].positions);
		free(p->targets[t].normals);
		free(p->targets[t].tangents);
	}
	free(p->targets);
	memset(p, 0, sizeof *p);
}

void mlod_character_free(mlod_character *c)
{
	if (!c)
		return;
	mlod_skeleton *s = &c->skeleton;
	for (int i = 0; s->joints && i < s->joint_count; i++)
		free(s->joints[i].name);
	free(s->joints);
	for (int i = 0; s->skins && i < s->skin_count; i++) {
		free(s->skins[i].name);
		free(s->skins[i].joints);
		free(s->skins[i].inverse_bind);
	}
	free(s->skins);
	for (int m = 0; c->meshes && m < c->mesh_count; m++) {
		for (int p = 0; c->meshes[m].primitives && p < c->meshes[m].primitive_count; p++)
			mlod_primitive_free(&c->meshes[m].primitives[p]);
		free(c->meshes[m].primitives);
		free(c->meshes[m].name);
	}
	free(c->meshes);
	free(c->instances);
	for (int k = 0; c->clips && k < c->clip_count; k++) {
		for (int ch = 0; c->clips[k].channels && ch < c->clips[k].channel_count; ch++) {
			free(c->clips[k].channels[ch].times);
			free(c->clips[k].channels[ch].values);
		}
		free(c->clips[k].channels);
		free(c->clips[k].name);
	}
	free(c->clips);
	free(c->notes);
	free(c->warnings);
	memset(c, 0, sizeof *c);
}

/* ---------------------------------------------------------------- */
/* Validation                                                        */
/* ---------------------------------------------------------------- */

/* Index of the first non-finite value among n floats, or -1. */
static long first_nonfinite(const float *v, long n)
{
	for (long i = 0; i < n; i++)
		if (!isfinite(v[i]))
			return i;
	return -1;
}

static int trs_finite(const mlod_trs *t)
{
	const float v[10] = { t->t.x, t->t.y, t->t.z, t->r.x, t->r.y, t->r.z, t->r.w, t->s.x, t->s.y, t->s.z };
	return first_nonfinite(v, 10) < 0;
}

static mlod_result validate_skeleton(const mlod_skeleton *s, mlod_error *err)
{
	if (s->joint_count < 0 || (s->joint_count > 0 && !s->joints))
		return mlod_fail(err, MLOD_ERR_PARSE, "skeleton: bad joint list (%d joints)", s->joint_count);
	for (int i = 0; i < s->joint_count; i++) {
		const mlod_joint *j = &s->joints[i];
		const char *name = j->name ? j->name : "";
		if (!j->name)
			return mlod_fail(err, MLOD_ERR_PARSE, "joint %d: no name", i);
		if (j->parent < -1 || j->parent >= s->joint_count)
			return mlod_fail(err, MLOD_ERR_PARSE, "joint %d \"%s\": parent %d out of range", i, name, j->parent);
		if (j->parent >= i)
			return mlod_fail(err, MLOD_ERR_PARSE, "joint %d \"%s\": parent %d comes after it", i, name, j->parent);
		if (!trs_finite(&j->rest))
			return mlod_fail(err, MLOD_ERR_PARSE, "joint %d \"%s\": rest transform is not finite", i, name);
		if (first_nonfinite(j->base.m, 16) >= 0)
			return mlod_fail(err, MLOD_ERR_PARSE, "joint %d \"%s\": base transform is not finite", i, name);
		if (j->channel_count != 0 && j->channel_count != 3 && j->channel_count != 6)
			return mlod_fail(err, MLOD_ERR_PARSE, "joint %d \"%s\": %d BVH channels (0, 3 or 6 expected)", i, name, j->channel_count);
		for (int k = 0; k < j->channel_count; k++)
			if (j->channels[k] > MLOD_BVH_ZROT)
				return mlod_fail(err, MLOD_ERR_PARSE, "joint %d \"%s\": bad BVH channel code %d", i, name, j->channels[k]);
		if ((int)j->euler < 0 || (int)j->euler > MLOD_EULER_ZYX)
			return mlod_fail(err, MLOD_ERR_PARSE, "joint %d \"%s\": bad Euler order %d", i, name, (int)j->euler);
		const float es[3] = { j->end_site.x, j->end_site.y, j->end_site.z };
		if (j->has_end_site && first_nonfinite(es, 3) >= 0)
			return mlod_fail(err, MLOD_ERR_PARSE, "joint %d \"%s\": End Site offset is not finite", i, name);
	}
	if (s->skin_count < 0 || (s->skin_count > 0 && !s->skins))
		return mlod_fail(err, MLOD_ERR_PARSE, "skeleton: bad skin list (%d skins)", s->skin_count);
	for (int k = 0; k < s->skin_count; k++) {
		const mlod_skin *sk = &s->skins[k];
		if (sk->joint_count < 0 || (sk->joint_count > 0 && (!sk->joints || !sk->inverse_bind)))
			return mlod_fail(err, MLOD_ERR_PARSE, "skin %d: bad joint list (%d joints)", k, sk->joint_count);
		for (int i = 0; i < sk->joint_count; i++) {
			if (sk->joints[i] < 0 || sk->joints[i] >= s->joint_count)
				return mlod_fail(err, MLOD_ERR_PARSE, "skin %d: joint %d is %d, out of range (%d joints)",
				                 k, i, sk->joints[i], s->joint_count);
			if (first_nonfinite(sk->inverse_bind[i].m, 16) >= 0)
				return mlod_fail(err, MLOD_ERR_PARSE, "skin %d: inverse bind matrix %d is not finite", k, i);
		}
	}
	return MLOD_OK;
}

static mlod_result validate_primitive(const mlod_primitive *p, int m, int pi, mlod_error *err)
{
	long n = p->vertex_count;
	if (n < 0 || (n > 0 && !p->positions))
		return mlod_fail(err, MLOD_ERR_PARSE, "mesh %d primitive %d: bad vertex data (%ld vertices)", m, pi, n);
	long bad = first_nonfinite(p->positions, 3 * n);
	if (bad >= 0)
		return mlod_fail(err, MLOD_ERR_PARSE, "mesh %d primitive %d: position of vertex %ld is not finite", m, pi, bad / 3);
	if (p->uv_set_count < 0 || p->uv_set_count > MLOD_MAX_SETS || p->color_set_count < 0 ||
	    p->color_set_count > MLOD_MAX_SETS || p->weight_set_count < 0 || p->weight_set_count > MLOD_MAX_SETS)
		return mlod_fail(err, MLOD_ERR_PARSE, "mesh %d primitive %d: bad attribute set count", m, pi);
	for (int s = 0; s < p->weight_set_count; s++) {
		if (n > 0 && (!p->joints[s] || !p->weights[s]))
			return mlod_fail(err, MLOD_ERR_PARSE, "mesh %d primitive %d: weight set %d has no data", m, pi, s);
		for (long i = 0; i < 4 * n; i++)
			if (!(p->weights[s][i] >= 0.0f) || !isfinite(p->weights[s][i]))
				return mlod_fail(err, MLOD_ERR_PARSE, "mesh %d primitive %d: vertex %ld has weight %g in set %d",
				                 m, pi, i / 4, (double)p->weights[s][i], s);
	}
	if (p->index_count < 0 || (p->index_count > 0 && !p->indices))
		return mlod_fail(err, MLOD_ERR_PARSE, "mesh %d primitive %d: bad index list (%d indices)", m, pi, p->index_count);
	for (int i = 0; i < p->index_count; i++)
		if (p->indices[i] >= (uint32_t)n)
			return mlod_fail(err, MLOD_ERR_PARSE, "mesh %d primitive %d: index %d is %u, out of range (%ld vertices)",
			                 m, pi, i, p->indices[i], n);
	if (p->target_count < 0 || (p->target_count > 0 && !p->targets))
		return mlod_fail(err, MLOD_ERR_PARSE, "mesh %d primitive %d: bad morph target list", m, pi);
	return MLOD_OK;
}

/* Joint indices that carry weight must name a joint of the skin. Zero-weight
 * influences are ignored by skinning, so their index does not matter. */
static mlod_result validate_skinning(const mlod_primitive *p, const mlod_skin *skin, int inst, int m, int pi,
                                     mlod_error *err)
{
	for (int s = 0; s < p->weight_set_count; s++)
		for (long i = 0; i < 4L * p->vertex_count; i++)
			if (p->weights[s][i] > 0.0f && p->joints[s][i] >= skin->joint_count)
				return mlod_fail(err, MLOD_ERR_PARSE,
				                 "instance %d (mesh %d primitive %d): vertex %ld uses joint %u of a skin with %d joints",
				                 inst, m, pi, i / 4, p->joints[s][i], skin->joint_count);
	return MLOD_OK;
}

static mlod_result validate_clip(const mlod_clip *c, int k, int joint_count, mlod_error *err)
{
	const char *name = c->name ? c->name : "";
	if (!isfinite(c->duration) || c->duration < 0.0f || !isfinite(c->frame_time) || c->frame_time < 0.0f ||
	    c->frame_count < 0)
		return mlod_fail(err, MLOD_ERR_PARSE, "clip %d \"%s\": bad duration or frame time", k, name);
	if (c->channel_count < 0 || (c->channel_count > 0 && !c->channels))
		return mlod_fail(err, MLOD_ERR_PARSE, "clip %d \"%s\": bad channel list", k, name);
	for (int i = 0; i < c->channel_count; i++) {
		const mlod_channel *ch = &c->channels[i];
		if (ch->joint < 0 || ch->joint >= joint_count)
			return mlod_fail(err, MLOD_ERR_PARSE, "clip %d \"%s\" channel %d: joint %d out of range", k, name, i, ch->joint);
		if ((int)ch->path < 0 || ch->path > MLOD_PATH_SCALE || (int)ch->interp < 0 || ch->interp > MLOD_INTERP_CUBICSPLINE)
			return mlod_fail(err, MLOD_ERR_PARSE, "clip %d \"%s\" channel %d: bad path or interpolation", k, name, i);
		if (ch->key_count < 1 || !ch->times || !ch->values)
			return mlod_fail(err, MLOD_ERR_PARSE, "clip %d \"%s\" channel %d: no keys", k, name, i);
		long comps = (ch->path == MLOD_PATH_ROTATION ? 4 : 3) * (ch->interp == MLOD_INTERP_CUBICSPLINE ? 3 : 1);
		for (int t = 0; t < ch->key_count; t++) {
			if (!isfinite(ch->times[t]))
				return mlod_fail(err, MLOD_ERR_PARSE, "clip %d \"%s\" channel %d: key %d time is not finite", k, name, i, t);
			if (t > 0 && !(ch->times[t] > ch->times[t - 1]))
				return mlod_fail(err, MLOD_ERR_PARSE, "clip %d \"%s\" channel %d: key %d time %g does not follow %g",
				                 k, name, i, t, (double)ch->times[t], (double)ch->times[t - 1]);
		}
		long bad = first_nonfinite(ch->values, comps * ch->key_count);
		if (bad >= 0)
			return mlod_fail(err, MLOD_ERR_PARSE, "clip %d \"%s\" channel %d: key %ld value is not finite", k, name, i, bad / comps);
	}
	return MLOD_OK;
}

mlod_result mlod_character_validate(const mlod_character *c, mlod_error *err)
{
	if (!c)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "no character");
	mlod_result r = validate_skeleton(&c->skeleton, err);
	if (r)
		return r;
	if (c->mesh_count < 0 || (c->mesh_count > 0 && !c->meshes))
		return mlod_fail(err, MLOD_ERR_PARSE, "bad mesh list (%d meshes)", c->mesh_count);
	for (int m = 0; m < c->mesh_count; m++) {
		const mlod_mesh *mesh = &c->meshes[m];
		if (mesh->primitive_count < 0 || (mesh->primitive_count > 0 && !mesh->primitives))
			return mlod_fail(err, MLOD_ERR_PARSE, "mesh %d: bad primitive list", m);
		for (int p = 0; p < mesh->primitive_count; p++)
			if ((r = validate_primitive(&mesh->primitives[p], m, p, err)))
				return r;
	}
	if (c->instance_count < 0 || (c->instance_count > 0 && !c->instances))
		return mlod_fail(err, MLOD_ERR_PARSE, "bad instance list (%d instances)", c->instance_count);
	for (int i = 0; i < c->instance_count; i++) {
		const mlod_instance *in = &c->instances[i];
		if (in->mesh < 0 || in->mesh >= c->mesh_count)
			return mlod_fail(err, MLOD_ERR_PARSE, "instance %d: mesh %d out of range (%d meshes)", i, in->mesh, c->mesh_count);
		if (in->skin < -1 || in->skin >= c->skeleton.skin_count)
			return mlod_fail(err, MLOD_ERR_PARSE, "instance %d: skin %d out of range (%d skins)", i, in->skin,
			                 c->skeleton.skin_count);
		if (in->joint < -1 || in->joint >= c->skeleton.joint_count)
			return mlod_fail(err, MLOD_ERR_PARSE, "instance %d: joint %d out of range (%d joints)", i, in->joint,
			                 c->skeleton.joint_count);
		if (first_nonfinite(in->offset.m, 16) >= 0)
			return mlod_fail(err, MLOD_ERR_PARSE, "instance %d: offset is not finite", i);
		if (in->skin < 0)
			continue;
		const mlod_mesh *mesh = &c->meshes[in->mesh];
		for (int p = 0; p < mesh->primitive_count; p++)
			if ((r = validate_skinning(&mesh->primitives[p], &c->skeleton.skins[in->skin], i, in->mesh, p, err)))
				return r;
	}
	if (c->clip_count < 0 || (c->clip_count > 0 && !c->clips))
		return mlod_fail(err, MLOD_ERR_PARSE, "bad clip list (%d clips)", c->clip_count);
	for (int k = 0; k < c->clip_count; k++)
		if ((r = validate_clip(&c->clips[k], k, c->skeleton.joint_count, err)))
			return r;
	return MLOD_OK;
}

char *mlod_strdup(const char *s)
{
	size_t n = strlen(s ? s : "") + 1;
	char *d = malloc(n);
	if (d)
		memcpy(d, s ? s : "", n);
	return d;
}

/* ---------------------------------------------------------------- */
/* Height                                                            */
/* ---------------------------------------------------------------- */

/* The box of the rest-pose joint origins in world space: each origin
 * carried up through its ancestors' rest transforms and its root's base.
 * Returns 0 without joints. */
static int rest_box(const mlod_skeleton *s, float lo[3], float hi[3])
{
	if (!s || s->joint_count <= 0)
		return 0;
	for (int a = 0; a < 3; a++)
		lo[a] = INFINITY, hi[a] = -INFINITY;
	for (int i = 0; i < s->joint_count; i++) {
		mlod_v3 p = { 0, 0, 0 };
		int j = i, root = i;
		for (; j >= 0; j = s->joints[j].parent) {
			mlod_mat4 l = mlod_mat4_from_trs(&s->joints[j].rest);
			p = mlod_mat4_point(&l, p);
			root = j;
		}
		p = mlod_mat4_point(&s->joints[root].base, p);
		const float v[3] = { p.x, p.y, p.z };
		for (int a = 0; a < 3; a++) {
			lo[a] = fminf(lo[a], v[a]);
			hi[a] = fmaxf(hi[a], v[a]);
		}
	}
	return 1;
}

float mlod_skeleton_extent(const mlod_skeleton *s)
{
	float lo[3], hi[3];
	if (!rest_box(s, lo, hi))
		return 0.0f;
	float size = fmaxf(hi[0] - lo[0], fmaxf(hi[1] - lo[1], hi[2] - lo[2]));
	return size > 0.0f && isfinite(size) ? size : 1.0f; /* a single point: unit scale */
}

float mlod_skeleton_height(const mlod_skeleton *s)
{
	float lo[3], hi[3];
	if (!rest_box(s, lo, hi))
		return 0.0f;
	float extent = mlod_skeleton_extent(s), up = hi[1] - lo[1];
	/* Lying down, modelled Z-up, a snake, one joint: the largest extent. */
	return up >= MLOD_HEIGHT_MIN_UP * extent && isfinite(up) ? up : extent;
}
