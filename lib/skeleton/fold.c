/*
 * fold.c: applies a skeleton level to a character (paper 4.1.3, which does
 * not say what removal does to motion and skin; mlod-skelgraph(1), Levels,
 * documents this reading): motion folding, skin transfer and the joint remap.
 *
 * Motion folding. A kept joint c whose parent chain j1 (its parent), ...,
 * jk was removed gets the local transform
 *     L'_c(t) = L_jk(t) ... L_j1(t) L_c(t)
 * relative to its new parent, so its world transform, and every kept
 * joint's, is unchanged. Composed TRS with non-uniform scale can shear;
 * such samples are decomposed to the nearest TRS and counted.
 *
 * Skin transfer. A vertex's weight on a removed joint j moves to its
 * stand-in k (nearest kept ancestor); duplicates merge and the weights are
 * renormalised, so a vertex never has more influences than before. When k
 * was not in the skin, it joins it with the bind matrix that makes the
 * vertex follow k rigidly from j's bind pose: IBM_k = R(k->j) IBM_j, with
 * R(k->j) the rest transform from k down to j.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "skeleton/mlod_skeleton.h"

/* Duplicates n bytes, or returns NULL for a NULL or empty source. */
static void *dup_bytes(const void *src, size_t n, int *failed)
{
	if (!src || n == 0)
		return NULL;
	void *p = malloc(n);
	if (!p) {
		*failed = 1;
		return NULL;
	}
	memcpy(p, src, n);
	return p;
}

/* mlod_strdup, noting a failure in *failed. */
static char *copy_name(const char *s, int *failed)
{
	char *d = mlod_strdup(s);
	if (!d)
		*failed = 1;
	return d;
}

static void copy_primitive(const mlod_primitive *p, mlod_primitive *q, int *failed)
{
	size_t n = (size_t)p->vertex_count;
	*q = *p;
	q->positions = dup_bytes(p->positions, sizeof(float) * 3 * n, failed);
	q->normals = dup_bytes(p->normals, sizeof(float) * 3 * n, failed);
	q->tangents = dup_bytes(p->tangents, sizeof(float) * 4 * n, failed);
	for (int i = 0; i < MLOD_MAX_SETS; i++) {
		q->uvs[i] = dup_bytes(p->uvs[i], sizeof(float) * 2 * n, failed);
		q->colors[i] = dup_bytes(p->colors[i], sizeof(float) * 4 * n, failed);
		q->joints[i] = dup_bytes(p->joints[i], sizeof(uint16_t) * 4 * n, failed);
		q->weights[i] = dup_bytes(p->weights[i], sizeof(float) * 4 * n, failed);
	}
	q->indices = dup_bytes(p->indices, sizeof(uint32_t) * (size_t)p->index_count, failed);
	q->targets = NULL;
	if (p->target_count > 0) {
		q->targets = calloc((size_t)p->target_count, sizeof *q->targets);
		if (!q->targets) {
			*failed = 1;
			q->target_count = 0;
			return;
		}
		for (int t = 0; t < p->target_count; t++) {
			q->targets[t].positions = dup_bytes(p->targets[t].positions, sizeof(float) * 3 * n, failed);
			q->targets[t].normals = dup_bytes(p->targets[t].normals, sizeof(float) * 3 * n, failed);
			q->targets[t].tangents = dup_bytes(p->targets[t].tangents, sizeof(float) * 3 * n, failed);
		}
	}
}

/* World rest matrices of every joint of s; NULL when out of memory. */
static mlod_mat4 *rest_world(const mlod_skeleton *s)
{
	mlod_trs *local = malloc(sizeof *local * (size_t)s->joint_count);
	mlod_mat4 *world = malloc(sizeof *world * (size_t)s->joint_count);
	if (local && world) {
		mlod_pose_rest(s, local);
		mlod_pose_world(s, local, world);
	} else {
		free(world);
		world = NULL;
	}
	free(local);
	return world;
}

/* The product of the local transforms from just below `top` down to and
 * including `j` (top is an ancestor of j, or -1 for the whole chain). */
static mlod_mat4 chain_product(const mlod_skeleton *s, const mlod_trs *local, int top, int j)
{
	mlod_mat4 m = mlod_mat4_identity();
	for (int a = j; a != top; a = s->joints[a].parent) {
		mlod_mat4 l = mlod_mat4_from_trs(&local[a]);
		m = mlod_mat4_mul(&l, &m);
	}
	return m;
}

/* Marks in use the channels of joint j; returns 1 when there is one. */
static int mark_channels(const mlod_clip *clip, int j, unsigned char *use, int *step_only)
{
	int animated = 0;
	for (int i = 0; i < clip->channel_count; i++) {
		const mlod_channel *ch = &clip->channels[i];
		if (ch->joint != j)
			continue;
		use[i] = 1;
		animated = 1;
		if (ch->interp != MLOD_INTERP_STEP)
			*step_only = 0;
	}
	return animated;
}

/* Allocates channel storage; returns 0 or -1. */
static int channel_init(mlod_channel *ch, int joint, mlod_path path, mlod_interp interp, int keys)
{
	int comps = path == MLOD_PATH_ROTATION ? 4 : 3;
	ch->joint = joint;
	ch->path = path;
	ch->interp = interp;
	ch->key_count = keys;
	ch->times = malloc(sizeof(float) * (size_t)keys);
	ch->values = malloc(sizeof(float) * (size_t)comps * (size_t)keys);
	return ch->times && ch->values ? 0 : -1;
}

struct folder {
	const mlod_character *c;
	const mlod_skel_level *level;
	const int *newidx;      /* old joint -> new joint, or -1 */
	mlod_fold_stats stats;
	mlod_error *err;
};

/* Writes the folded channels of kept joint j (new index nj) of clip into
 * out, appending at *used. */
static mlod_result fold_clip_joint(struct folder *f, const mlod_clip *clip, int j, mlod_clip *out)
{
	const mlod_skeleton *s = &f->c->skeleton;
	int top = f->level->parent[j];
	int nj = f->newidx[j];
	float *times = NULL;
	int count = 0, step_only = 1, animated = 0;
	mlod_result r = MLOD_OK;

	/* The keys of j and its removed ancestors, or the frames of a sampled clip. */
	unsigned char *use = calloc((size_t)clip->channel_count + 1, 1);
	if (!use)
		goto nomem;
	for (int a = j; a != top; a = s->joints[a].parent)
		animated |= mark_channels(clip, a, use, &step_only);
	if (!animated) {
		free(use);
		return MLOD_OK; /* the folded rest transform covers it */
	}
	count = mlod_clip_key_times(clip, use, 1, &times, NULL);
	if (count < 0) {
		free(use);
		goto nomem;
	}

	mlod_trs *pose = malloc(sizeof *pose * (size_t)s->joint_count);
	mlod_channel tc = {0}, rc = {0}, sc = {0};
	mlod_interp interp = step_only ? MLOD_INTERP_STEP : MLOD_INTERP_LINEAR;
	if (!pose || channel_init(&tc, nj, MLOD_PATH_TRANSLATION, interp, count) ||
	    channel_init(&rc, nj, MLOD_PATH_ROTATION, interp, count) ||
	    channel_init(&sc, nj, MLOD_PATH_SCALE, interp, count)) {
		free(use);
		free(pose);
		free(tc.times), free(tc.values), free(rc.times), free(rc.values), free(sc.times), free(sc.values);
		goto nomem;
	}
	int scaled = 0;
	mlod_quat prev = mlod_quat_identity();
	for (int i = 0; i < count; i++) {
		/* The chain's joints only: mlod_clip_sample over the channels in use, in order. */
		for (int a = j; a != top; a = s->joints[a].parent)
			pose[a] = s->joints[a].rest;
		for (int c = 0; c < clip->channel_count; c++)
			if (use[c])
				mlod_channel_sample(&clip->channels[c], clip->duration, times[i], &pose[clip->channels[c].joint]);
		mlod_mat4 m = chain_product(s, pose, top, j);
		mlod_trs trs;
		if (mlod_mat4_to_trs(&m, &trs, 1e-4f) != 0)
			f->stats.shear_samples++;
		if (i > 0 && trs.r.x * prev.x + trs.r.y * prev.y + trs.r.z * prev.z + trs.r.w * prev.w < 0.0f)
			trs.r = (mlod_quat){-trs.r.x, -trs.r.y, -trs.r.z, -trs.r.w};
		prev = trs.r;
		tc.times[i] = rc.times[i] = sc.times[i] = times[i];
		memcpy(&tc.values[3 * i], &trs.t, sizeof(float) * 3);
		memcpy(&rc.values[4 * i], &trs.r, sizeof(float) * 4);
		memcpy(&sc.values[3 * i], &trs.s, sizeof(float) * 3);
		if (fabsf(trs.s.x - 1.0f) > 1e-6f || fabsf(trs.s.y - 1.0f) > 1e-6f || fabsf(trs.s.z - 1.0f) > 1e-6f)
			scaled = 1;
	}
	free(pose);
	free(use);
	out->channels[out->channel_count++] = tc;
	out->channels[out->channel_count++] = rc;
	if (scaled) {
		out->channels[out->channel_count++] = sc;
	} else {
		free(sc.times);
		free(sc.values);
	}
	free(times);
	return r;
nomem:
	free(times);
	return mlod_fail(f->err, MLOD_ERR_NOMEM, "out of memory folding clip %s", MLOD_QUOTED(clip->name));
}

static mlod_result fold_clip(struct folder *f, const mlod_clip *clip, mlod_clip *out)
{
	const mlod_skeleton *s = &f->c->skeleton;
	const mlod_skel_level *l = f->level;
	int failed = 0;
	*out = *clip;
	out->channels = NULL;
	out->channel_count = 0;
	out->name = copy_name(clip->name, &failed);
	/* At most 3 channels per kept joint besides the copied ones. */
	out->channels = calloc((size_t)clip->channel_count + 3 * (size_t)l->kept_count + 1, sizeof(mlod_channel));
	if (failed || !out->channels)
		return mlod_fail(f->err, MLOD_ERR_NOMEM, "out of memory folding clip %s", MLOD_QUOTED(clip->name));
	for (int j = 0; j < s->joint_count; j++) {
		if (!l->kept[j])
			continue;
		int folded = s->joints[j].parent >= 0 && !l->kept[s->joints[j].parent];
		if (folded) {
			mlod_result r = fold_clip_joint(f, clip, j, out);
			if (r != MLOD_OK)
				return r;
			continue;
		}
		for (int i = 0; i < clip->channel_count; i++) {
			const mlod_channel *ch = &clip->channels[i];
			if (ch->joint != j)
				continue;
			int comps = (ch->path == MLOD_PATH_ROTATION ? 4 : 3) * (ch->interp == MLOD_INTERP_CUBICSPLINE ? 3 : 1);
			mlod_channel *o = &out->channels[out->channel_count++];
			*o = *ch;
			o->joint = f->newidx[j];
			o->times = dup_bytes(ch->times, sizeof(float) * (size_t)ch->key_count, &failed);
			o->values = dup_bytes(ch->values, sizeof(float) * (size_t)comps * (size_t)ch->key_count, &failed);
			if (failed)
				return mlod_fail(f->err, MLOD_ERR_NOMEM, "out of memory folding clip %s", MLOD_QUOTED(clip->name));
		}
	}
	return MLOD_OK;
}

/* The skin of the level for skin `sk`: its joints mapped to stand-ins and
 * deduplicated; map[k] gives the new local index of old local index k. */
static mlod_result reduce_skin(struct folder *f, const mlod_skin *sk, const mlod_mat4 *world,
                               mlod_skin *out, int *map)
{
	const mlod_skeleton *s = &f->c->skeleton;
	int failed = 0;
	memset(out, 0, sizeof *out);
	out->name = copy_name(sk->name, &failed);
	out->gltf_index = sk->gltf_index;
	out->joints = malloc(sizeof(int) * (size_t)(sk->joint_count ? sk->joint_count : 1));
	out->inverse_bind = malloc(sizeof(mlod_mat4) * (size_t)(sk->joint_count ? sk->joint_count : 1));
	if (failed || !out->joints || !out->inverse_bind)
		return mlod_fail(f->err, MLOD_ERR_NOMEM, "out of memory reducing skin %s", MLOD_QUOTED(sk->name));
	/* Kept joints of the skin first, in their order, with their own bind. */
	for (int k = 0; k < sk->joint_count; k++) {
		int j = sk->joints[k];
		map[k] = -1;
		if (f->level->kept[j]) {
			map[k] = out->joint_count;
			out->joints[out->joint_count] = j;
			out->inverse_bind[out->joint_count++] = sk->inverse_bind[k];
		}
	}
	/* Then each removed joint goes to its stand-in, added when missing. */
	for (int k = 0; k < sk->joint_count; k++) {
		if (map[k] >= 0)
			continue;
		int j = sk->joints[k], stand = f->level->remap[j];
		for (int q = 0; q < out->joint_count; q++)
			if (out->joints[q] == stand)
				map[k] = q;
		if (map[k] >= 0)
			continue;
		/* R(k->j) = inverse(world_k) * world_j in the rest pose. */
		mlod_mat4 inv, rel;
		if (mlod_mat4_invert(&world[stand], &inv) != 0)
			return mlod_fail(f->err, MLOD_ERR_PARSE, "joint %s has a singular rest transform",
			                 MLOD_QUOTED(s->joints[stand].name));
		rel = mlod_mat4_mul(&inv, &world[j]);
		map[k] = out->joint_count;
		out->joints[out->joint_count] = stand;
		out->inverse_bind[out->joint_count++] = mlod_mat4_mul(&rel, &sk->inverse_bind[k]);
	}
	for (int q = 0; q < out->joint_count; q++)
		out->joints[q] = f->newidx[out->joints[q]];
	return MLOD_OK;
}

/* Rewrites a primitive's joint indices through map, merging duplicates and
 * renormalising. */
static void transfer_weights(struct folder *f, mlod_primitive *p, const int *map, int map_count)
{
	int sets = p->weight_set_count;
	int slots = 4 * sets;
	int joint[4 * MLOD_MAX_SETS];
	float weight[4 * MLOD_MAX_SETS];
	for (int v = 0; v < p->vertex_count; v++) {
		int n = 0, merged = 0;
		float total = 0.0f;
		for (int s = 0; s < sets; s++) {
			for (int i = 0; i < 4; i++) {
				float w = p->weights[s][4 * v + i];
				int old = p->joints[s][4 * v + i];
				if (w <= 0.0f || old >= map_count)
					continue;
				int nj = map[old], k = 0;
				while (k < n && joint[k] != nj)
					k++;
				if (k == n) {
					joint[n] = nj;
					weight[n++] = w;
				} else {
					weight[k] += w;
					merged = 1;
				}
				total += w;
			}
		}
		f->stats.weight_merges += merged;
		for (int k = 0; k < slots; k++) {
			int s = k / 4, i = k % 4;
			p->joints[s][4 * v + i] = (uint16_t)(k < n ? joint[k] : 0);
			p->weights[s][4 * v + i] = k < n && total > 0.0f ? weight[k] / total : 0.0f;
		}
	}
}

mlod_result mlod_skel_level_apply(const mlod_character *c, const mlod_skel_level *l,
                                  mlod_character *out, mlod_fold_stats *stats, mlod_error *err)
{
	const mlod_skeleton *s = &c->skeleton;
	struct folder f = {c, l, NULL, {0, 0}, err};
	int failed = 0, n = s->joint_count;
	mlod_result r = MLOD_OK;
	memset(out, 0, sizeof *out);
	if (l->joint_count != n)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "the level has %d joints, the skeleton %d", l->joint_count, n);

	int *newidx = malloc(sizeof(int) * (size_t)n);
	int *map = NULL;
	mlod_trs *local = malloc(sizeof *local * (size_t)n);
	mlod_mat4 *world = rest_world(s);
	if (!newidx || !local || !world)
		goto nomem;
	f.newidx = newidx;
	mlod_pose_rest(s, local);

	/* Skeleton: kept joints, renumbered, with folded rest transforms. */
	out->skeleton.joints = calloc((size_t)l->kept_count + 1, sizeof(mlod_joint));
	if (!out->skeleton.joints)
		goto nomem;
	for (int j = 0; j < n; j++) {
		newidx[j] = -1;
		if (!l->kept[j])
			continue;
		mlod_joint *nj = &out->skeleton.joints[out->skeleton.joint_count];
		*nj = s->joints[j];
		nj->name = copy_name(s->joints[j].name, &failed);
		newidx[j] = out->skeleton.joint_count++;
		nj->parent = l->parent[j] >= 0 ? newidx[l->parent[j]] : -1;
		if (s->joints[j].parent >= 0 && !l->kept[s->joints[j].parent]) {
			mlod_mat4 m = chain_product(s, local, l->parent[j], j);
			if (mlod_mat4_to_trs(&m, &nj->rest, 1e-4f) != 0)
				f.stats.shear_samples++;
			/* A folded joint moves with its removed ancestors: in BVH
			 * terms it needs position channels. */
			if (nj->channel_count == 3) {
				unsigned char ch[6] = {MLOD_BVH_XPOS, MLOD_BVH_YPOS, MLOD_BVH_ZPOS};
				memcpy(ch + 3, s->joints[j].channels, 3);
				memcpy(nj->channels, ch, 6);
				nj->channel_count = 6;
			}
		}
	}
	if (failed)
		goto nomem;

	/* Skins, and the old-to-new local joint maps used to transfer weights. */
	out->skeleton.skins = calloc((size_t)s->skin_count + 1, sizeof(mlod_skin));
	int max_skin = 1;
	for (int k = 0; k < s->skin_count; k++)
		if (s->skins[k].joint_count > max_skin)
			max_skin = s->skins[k].joint_count;
	map = malloc(sizeof(int) * (size_t)max_skin * (size_t)(s->skin_count + 1));
	if (!out->skeleton.skins || !map)
		goto nomem;
	for (int k = 0; k < s->skin_count; k++) {
		out->skeleton.skin_count++;
		r = reduce_skin(&f, &s->skins[k], world, &out->skeleton.skins[k], map + (size_t)k * (size_t)max_skin);
		if (r != MLOD_OK)
			goto fail;
	}

	/* Meshes: copies with transferred weights, each through the skin of
	 * the instances that use it. */
	out->meshes = calloc((size_t)c->mesh_count + 1, sizeof(mlod_mesh));
	if (!out->meshes)
		goto nomem;
	for (int m = 0; m < c->mesh_count; m++) {
		const mlod_mesh *src = &c->meshes[m];
		mlod_mesh *dst = &out->meshes[out->mesh_count++];
		int skin = -1;
		for (int i = 0; i < c->instance_count; i++) {
			const mlod_instance *in = &c->instances[i];
			if (in->mesh != m || in->skin < 0)
				continue;
			if (skin >= 0 && skin != in->skin) {
				r = mlod_fail(err, MLOD_ERR_UNSUPPORTED,
				              "mesh %d %s is skinned by two different skins (%d and %d)", m,
				              MLOD_QUOTED(src->name), skin, in->skin);
				goto fail;
			}
			skin = in->skin;
		}
		*dst = *src;
		dst->name = copy_name(src->name, &failed);
		dst->primitives = calloc((size_t)src->primitive_count + 1, sizeof(mlod_primitive));
		if (failed || !dst->primitives) {
			dst->primitive_count = 0;
			goto nomem;
		}
		for (int p = 0; p < src->primitive_count; p++) {
			copy_primitive(&src->primitives[p], &dst->primitives[p], &failed);
			if (failed)
				goto nomem;
			if (skin >= 0)
				transfer_weights(&f, &dst->primitives[p], map + (size_t)skin * (size_t)max_skin,
				                 s->skins[skin].joint_count);
		}
	}

	/* Instances: rigid ones on a removed joint follow its stand-in. */
	out->instances = calloc((size_t)c->instance_count + 1, sizeof(mlod_instance));
	if (!out->instances)
		goto nomem;
	for (int i = 0; i < c->instance_count; i++) {
		mlod_instance in = c->instances[i];
		if (in.joint >= 0) {
			int stand = l->remap[in.joint];
			if (stand != in.joint) {
				mlod_mat4 inv, rel;
				if (mlod_mat4_invert(&world[stand], &inv) != 0) {
					r = mlod_fail(err, MLOD_ERR_PARSE, "joint %s has a singular rest transform",
					              MLOD_QUOTED(s->joints[stand].name));
					goto fail;
				}
				rel = mlod_mat4_mul(&inv, &world[in.joint]);
				in.offset = mlod_mat4_mul(&rel, &in.offset);
			}
			in.joint = newidx[stand];
		}
		out->instances[out->instance_count++] = in;
	}

	/* Clips, folded. */
	out->clips = calloc((size_t)c->clip_count + 1, sizeof(mlod_clip));
	if (!out->clips)
		goto nomem;
	for (int k = 0; k < c->clip_count; k++) {
		out->clip_count++;
		r = fold_clip(&f, &c->clips[k], &out->clips[k]);
		if (r != MLOD_OK)
			goto fail;
	}
	if (c->notes) {
		out->notes = copy_name(c->notes, &failed);
		if (failed)
			goto nomem;
	}
	if (c->warnings) {
		out->warnings = copy_name(c->warnings, &failed);
		if (failed)
			goto nomem;
	}
	if (stats)
		*stats = f.stats;
	free(newidx);
	free(map);
	free(local);
	free(world);
	return MLOD_OK;

nomem:
	r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory applying a skeleton level");
fail:
	free(newidx);
	free(map);
	free(local);
	free(world);
	mlod_character_free(out);
	return r;
}
