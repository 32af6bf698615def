/*
 * lodgltf.c: mesh levels into glTF (mlod_mesh.h): MSFT_lod level nodes,
 * one document per level (--split), and levels following the skeleton
 * levels of mlod-skelgraph (their skins, their joints' stand-ins).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "meshlevels.h"

static mlod_result nomem(mlod_error *err)
{
	return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
}

/* The character skin whose glTF index is gltf, or -1. */
static int skin_of_gltf(const mlod_skeleton *s, int gltf)
{
	for (int i = 0; i < s->skin_count; i++)
		if (s->skins[i].gltf_index == gltf)
			return i;
	return -1;
}

/* The node standing for node in a skeleton level (node itself when it
 * was kept). */
static int stand_in_node(const mlod_mesh_skeleton *sk, int node)
{
	for (int i = 0; i < sk->remap_count; i++)
		if (sk->remap_from[i] == node)
			return sk->remap_to[i];
	return node;
}

/* The skeleton level mesh level k follows, or NULL. */
static const mlod_mesh_skeleton *skeleton_level(const mlod_mesh_levels *L, int k)
{
	if (L->skeleton_count <= 0)
		return NULL;
	return &L->skeleton[k < L->skeleton_count ? k : L->skeleton_count - 1];
}

/* Remaps the level mesh of a skinned instance to a skeleton level's skin:
 * every primitive must be one the level made (an unsimplified primitive
 * shares the input's accessors) and every weighted joint must have a
 * stand-in in that skin. *target is the skin's glTF index, or -1 when
 * that is not so (then nothing changed). */
static mlod_result remap_to_skeleton_level(const mlod_mesh_levels *L, const mlod_mesh_skeleton *sk, int skin,
                                           mlod_mesh *m, const unsigned char *owned, int *target, mlod_error *err)
{
	const mlod_skeleton *s = &L->c->skeleton;
	int to_gltf = skin < sk->skin_count ? sk->skins[skin] : -1, ts = to_gltf >= 0 ? skin_of_gltf(s, to_gltf) : -1;
	*target = -1;
	if (to_gltf < 0 || ts < 0)
		return MLOD_OK;
	const mlod_skin *from = &s->skins[skin], *to = &s->skins[ts];
	int *map = malloc(sizeof(int) * ((size_t)from->joint_count + 1));
	if (!map)
		return nomem(err);
	for (int j = 0; j < from->joint_count; j++) {
		int node = s->joints[from->joints[j]].node;
		int stand = node >= 0 ? stand_in_node(sk, node) : node;
		map[j] = -1;
		for (int t = 0; t < to->joint_count; t++)
			if (s->joints[to->joints[t]].node == stand)
				map[j] = t;
	}
	/* Check everything first, so a failure leaves the mesh as it was. */
	int ok = 1;
	for (int p = 0; ok && p < m->primitive_count; p++) {
		const mlod_primitive *q = &m->primitives[p];
		ok = owned[p] != 0;
		for (int set = 0; ok && set < q->weight_set_count; set++)
			for (long v = 0; ok && v < 4L * q->vertex_count; v++)
				ok = !(q->weights[set][v] > 0.0f) || (q->joints[set][v] < from->joint_count && map[q->joints[set][v]] >= 0);
	}
	mlod_result r = MLOD_OK;
	for (int p = 0; ok && r == MLOD_OK && p < m->primitive_count; p++)
		r = mlod_primitive_remap_joints(&m->primitives[p], map, from->joint_count, err); /* checked: cannot fail */
	free(map);
	if (ok && r == MLOD_OK)
		*target = to_gltf;
	return r;
}

mlod_result mlod_mesh_levels_follow(mlod_mesh_levels *L, const mlod_mesh_skeleton *skeleton, int count,
                                    mlod_error *err)
{
	const mlod_character *c = L->c;
	int fallback = 0;
	L->skeleton = skeleton;
	L->skeleton_count = count;
	for (int k = 0; k < L->count; k++) {
		mlod_mesh_level *lv = &L->levels[k];
		const mlod_mesh_skeleton *sk = skeleton_level(L, k);
		for (int i = 0; i < c->instance_count; i++) {
			const mlod_instance *in = &c->instances[i];
			lv->skins[i] = -1;
			if (in->skin < 0 || !mlod_mesh_has_levels_(L, i))
				continue;
			lv->skins[i] = c->skeleton.skins[in->skin].gltf_index;
			if (!sk)
				continue;
			int target;
			mlod_result r = remap_to_skeleton_level(L, sk, in->skin, &lv->meshes[i], lv->owned[i], &target, err);
			if (r != MLOD_OK)
				return r;
			if (target >= 0)
				lv->skins[i] = target;
			else
				fallback++;
		}
	}
	if (count > 0)
		mlod_mesh_note_(L, fallback ? "skeleton levels found: mesh level k uses skeleton level k's skins (some fell "
		                              "back to the full skin)"
		                            : "skeleton levels found: mesh level k uses skeleton level k's skins");
	return MLOD_OK;
}

/* A skin of one joint for a rigid instance: world = W_joint * offset * p.
 * With a skeleton level, the joint's stand-in carries it with the rest
 * transform between them. */
static mlod_result rigid_skin(const mlod_mesh_levels *L, mlod_gltf *doc, const mlod_instance *in, int stand_joint,
                              int *index, mlod_error *err)
{
	const mlod_skeleton *s = &L->c->skeleton;
	mlod_mat4 ibm = in->offset;
	if (stand_joint != in->joint) {
		mlod_trs *local = malloc(sizeof *local * (size_t)s->joint_count);
		mlod_mat4 *world = malloc(sizeof *world * (size_t)s->joint_count), inv;
		if (!local || !world) {
			free(local);
			free(world);
			return nomem(err);
		}
		mlod_pose_rest(s, local);
		mlod_pose_world(s, local, world);
		if (mlod_mat4_invert(&world[stand_joint], &inv) == 0) {
			mlod_mat4 rel = mlod_mat4_mul(&inv, &world[in->joint]);
			ibm = mlod_mat4_mul(&rel, &in->offset);
		} else {
			stand_joint = in->joint;
		}
		free(local);
		free(world);
	}
	int joints[1] = {stand_joint};
	mlod_skin skin = {0};
	skin.name = "mlod rigid part";
	skin.joint_count = 1;
	skin.joints = joints;
	skin.inverse_bind = &ibm;
	skin.gltf_index = -1;
	*index = -1;
	return mlod_gltf_add_skin(doc, s, &skin, index, err);
}

/* The joint standing for j in a skeleton level (j itself without one). */
static int stand_in_joint(const mlod_mesh_levels *L, const mlod_mesh_skeleton *sk, int j)
{
	const mlod_skeleton *s = &L->c->skeleton;
	if (!sk || s->joints[j].node < 0)
		return j;
	int node = stand_in_node(sk, s->joints[j].node);
	for (int t = 0; t < s->joint_count; t++)
		if (s->joints[t].node == node)
			return t;
	return j;
}

static int has_targets(const mlod_mesh *m)
{
	for (int p = 0; p < m->primitive_count; p++)
		if (m->primitives[p].target_count > 0)
			return 1;
	return 0;
}

/* Adds level mesh m of instance i like its glTF mesh (name, morph weights,
 * extras). */
static mlod_result add_level_mesh(const mlod_mesh_levels *L, mlod_gltf *doc, int i, const mlod_mesh *m, int *mesh,
                                  mlod_error *err)
{
	int like = L->c->meshes[L->c->instances[i].mesh].gltf_index;
	*mesh = -1;
	return like >= 0 && like < mlod_gltf_count(doc, MLOD_GLTF_MESH) ? mlod_gltf_add_mesh_like(doc, like, m, mesh, err)
	                                                                 : mlod_gltf_add_mesh(doc, m, mesh, err);
}

void mlod_mesh_lod_free(mlod_mesh_lod *lod)
{
	free(lod->node);
	free(lod->level);
	free(lod->skeleton_level);
	memset(lod, 0, sizeof *lod);
}

mlod_result mlod_mesh_levels_write(mlod_mesh_levels *L, mlod_gltf *doc, mlod_mesh_lod *out, mlod_error *err)
{
	const mlod_character *c = L->c;
	int morph_channels = 0, untransformable = 0;
	float coverage[MLOD_MESH_MAX_LEVELS + 1];
	double errors[MLOD_MESH_MAX_LEVELS];
	mlod_result r = MLOD_OK;
	memset(out, 0, sizeof *out);
	size_t cap = (size_t)c->instance_count * (size_t)L->count + 1;
	out->node = malloc(sizeof(int) * cap);
	out->level = malloc(sizeof(int) * cap);
	out->skeleton_level = malloc(cap);
	if (!out->node || !out->level || !out->skeleton_level) {
		mlod_mesh_lod_free(out);
		return nomem(err);
	}
	for (int k = 0; k < L->count; k++)
		errors[k] = L->levels[k].error.max;
	mlod_lod_coverage(errors, L->count, coverage);

	for (int i = 0; r == MLOD_OK && L->count > 0 && i < c->instance_count; i++) {
		const mlod_instance *in = &c->instances[i];
		if (!mlod_mesh_has_levels_(L, i))
			continue;
		/* A static level node stands where the node stands: same local transform. */
		mlod_trs local, *trs = NULL;
		if (in->skin < 0 && in->joint < 0) {
			mlod_error ignored = {0};
			if (mlod_gltf_get_node_trs(doc, in->node, &local, &ignored) != MLOD_OK) {
				untransformable++;
				continue;
			}
			trs = &local;
		}
		int lod_nodes[MLOD_MESH_MAX_LEVELS], rigid_joint = -1, rigid_index = -1;
		for (int k = 0; r == MLOD_OK && k < L->count; k++) {
			mlod_mesh_level *lv = &L->levels[k];
			const mlod_mesh_skeleton *sk = skeleton_level(L, k);
			int skin = lv->skins[i], node = -1, mesh = -1;
			if (in->skin < 0 && in->joint >= 0) { /* rigid: skinned to its joint's stand-in */
				int joint = stand_in_joint(L, sk, in->joint);
				if (joint != rigid_joint) {
					rigid_joint = joint;
					if ((r = rigid_skin(L, doc, in, joint, &rigid_index, err)) != MLOD_OK)
						break;
				}
				skin = rigid_index;
			}
			if ((r = add_level_mesh(L, doc, i, &lv->meshes[i], &mesh, err)) != MLOD_OK)
				break;
			char name[96];
			snprintf(name, sizeof name, "mlod mesh level %d of node %d", k + 1, in->node);
			if ((r = mlod_gltf_add_node(doc, name, MLOD_GLTF_DETACHED, mesh, skin, trs, &node, err)) != MLOD_OK)
				break;
			if (has_targets(&lv->meshes[i])) {
				int added = 0;
				if ((r = mlod_gltf_copy_morph_animation(doc, in->node, node, &added, err)) != MLOD_OK)
					break;
				morph_channels += added;
			}
			out->node[out->count] = node;
			out->level[out->count] = k;
			out->skeleton_level[out->count++] = sk && skin >= 0;
			lod_nodes[k] = node;
		}
		/* A node that has MSFT_lod levels of its own (not a stage's: an
		 * input with mesh levels passes through, and mlod-skelgraph's
		 * skeleton levels are followed, L->skeleton_count) gets mlod's
		 * instead; its own level nodes stay in the document, outside the
		 * list. */
		int own[8], own_count = 0;
		mlod_error ignored = {0};
		if (r == MLOD_OK && L->skeleton_count == 0 &&
		    mlod_gltf_node_lod(doc, in->node, own, 8, &own_count, &ignored) == MLOD_OK &&
		    own_count > 0) {
			char list[80] = "", text[200];
			mlod_int_list(list, sizeof list, own, own_count, 8);
			snprintf(text, sizeof text, "node %d: its own MSFT_lod levels (node%s %s) are replaced by mlod's: those "
			         "nodes stay outside the level list", in->node, own_count > 1 ? "s" : "", list);
			mlod_mesh_note_(L, text);
		}
		if (r == MLOD_OK)
			r = mlod_gltf_set_lod(doc, in->node, lod_nodes, L->count, coverage, err);
	}
	char text[128];
	if (morph_channels) {
		snprintf(text, sizeof text, "%d morph weight channel(s) copied to the level nodes", morph_channels);
		mlod_mesh_note_(L, text);
	}
	if (untransformable) {
		snprintf(text, sizeof text, "%d static mesh node(s) with a sheared matrix: no MSFT_lod", untransformable);
		mlod_mesh_note_(L, text);
	}
	if (r != MLOD_OK)
		mlod_mesh_lod_free(out);
	return r;
}

mlod_result mlod_mesh_levels_split(mlod_mesh_levels *L, const mlod_gltf *input, int k, mlod_gltf **out,
                                   int *unpruned, mlod_error *err)
{
	const mlod_character *c = L->c;
	mlod_mesh_level *lv = &L->levels[k];
	mlod_gltf *doc = NULL;
	*out = NULL;
	mlod_result r = mlod_gltf_copy(input, &doc, err);
	for (int i = 0; r == MLOD_OK && i < c->instance_count; i++) {
		const mlod_instance *in = &c->instances[i];
		if (!mlod_mesh_has_levels_(L, i))
			continue;
		/* A rigid part stays under its joint: without the weights its level was given. */
		mlod_mesh m = lv->meshes[i];
		mlod_primitive *prims = malloc(sizeof *prims * ((size_t)m.primitive_count + 1));
		if (!prims) {
			r = nomem(err);
			break;
		}
		for (int p = 0; p < m.primitive_count; p++) {
			prims[p] = m.primitives[p];
			if (in->skin < 0 && lv->owned[i][p])
				prims[p].weight_set_count = 0;
		}
		m.primitives = prims;
		int mesh = -1;
		r = add_level_mesh(L, doc, i, &m, &mesh, err);
		free(prims);
		/* A level file holds one level: the node's earlier levels (the
		 * skeleton levels' nodes, say) go. */
		if (r == MLOD_OK)
			r = mlod_gltf_clear_lod(doc, in->node, err);
		if (r == MLOD_OK)
			r = mlod_gltf_set_node_mesh(doc, in->node, mesh, lv->skins[i], err);
	}
	if (r == MLOD_OK) {
		mlod_error perr = {0};
		mlod_result p = mlod_gltf_prune(doc, &perr);
		if (p == MLOD_ERR_UNSUPPORTED && !*unpruned) {
			*unpruned = 1;
			mlod_mesh_note_(L, "the split glb keep the full meshes too: an extension may refer to them");
		}
		else if (p != MLOD_OK)
			r = mlod_fail(err, p, "%s", perr.message);
	}
	if (r != MLOD_OK) {
		mlod_gltf_free(doc);
		return r;
	}
	*out = doc;
	return MLOD_OK;
}
