/*
 * unpack.c: a .mlod pack back to a glTF document (mlod-pack -x), read
 * through the one reader (rt/mlod_pack.h) and written through the glTF
 * shim (io/mlod_io.h).
 *
 * The document starts from the DOC chunk (the input without the levels'
 * data), its skins given back their inverse bind matrices and its joint
 * nodes their rest TRS from SKEL (mlod(5) DOC). Level 0 goes back where
 * it came from: each instance node gets a
 * mesh built from its level 0 parts (like the DOC mesh it named: name,
 * extras, primitives' material and extensions), and each clip's level 0
 * becomes an animation named after the clip. Coarser levels are added as
 * mlod-skelgraph, mlod-bgm and mlod-motion write them: a skin per skeleton
 * level and skin, an MSFT_lod level node per mesh level and instance
 * (with MSFT_screencoverage), and "<clip>@lod<k>" animations. A mesh
 * level keeps the weights the pack stores, on level 0's skin (a rigid
 * part's on a one-joint skin of its joint), not a skeleton level's as
 * mlod-bgm after mlod-skelgraph writes it: the runtime picks skeleton and
 * mesh levels apart, and a level on the full skin is what mlod-pack keeps
 * as it is, with its TOC error (issue 11). The DOC's emptied meshes go
 * (mlod_gltf_prune).
 *
 * The stage record (mlod-record(5), version 3) says which of these are
 * levels, with what the pack stores of them and nothing more: per
 * skeleton level its kept joints, remap (each removed skin joint's
 * palette joint, any other removed joint's nearest kept ancestor), skins
 * and TOC error; per mesh level its triangles, vertices and TOC error, on
 * the scene and on each level node; per motion level its source clip and
 * TOC error; on each full clip its level 0's TOC error (motion_level0).
 * mlod-pack then packs the glb again from these levels instead of making
 * new ones.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mlod_pack_write.h"
#include "measure/mlod_measure.h"
#include "record/mlod_record.h"

static mlod_result nomem(mlod_error *err)
{
	return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory unpacking");
}

/* The pack's full skeleton as an mlod_skeleton (names and arrays point
 * into k or into allocations freed by skeleton_free). */
static mlod_result build_skeleton(const mlod_pack_skeleton *k, mlod_skeleton *s, mlod_error *err)
{
	memset(s, 0, sizeof *s);
	if (!k)
		return MLOD_OK;
	s->joints = calloc((size_t)k->joint_count + 1, sizeof *s->joints);
	s->skins = calloc((size_t)k->skin_count + 1, sizeof *s->skins);
	if (!s->joints || !s->skins)
		return nomem(err);
	s->joint_count = (int)k->joint_count;
	for (uint32_t j = 0; j < k->joint_count; j++) {
		const mlod_pack_joint_rec *r = &k->joints[j];
		mlod_joint *o = &s->joints[j];
		o->name = (char *)k->joint_names[j];
		o->parent = r->parent;
		o->rest.t = (mlod_v3){r->t[0], r->t[1], r->t[2]};
		o->rest.r = (mlod_quat){r->r[0], r->r[1], r->r[2], r->r[3]};
		o->rest.s = (mlod_v3){r->s[0], r->s[1], r->s[2]};
		memcpy(o->base.m, r->base, sizeof o->base.m);
		o->node = r->node;
	}
	s->skin_count = (int)k->skin_count;
	for (uint32_t i = 0; i < k->skin_count; i++) {
		mlod_skin *o = &s->skins[i];
		uint32_t n = k->skins[i].joint_count;
		o->name = (char *)k->skin_names[i];
		o->joint_count = (int)n;
		o->joints = malloc(sizeof(int) * ((size_t)n + 1));
		o->inverse_bind = malloc(sizeof(mlod_mat4) * ((size_t)n + 1));
		if (!o->joints || !o->inverse_bind)
			return nomem(err);
		for (uint32_t j = 0; j < n; j++) {
			o->joints[j] = (int)k->skin_joints[i][j];
			memcpy(o->inverse_bind[j].m, k->inverse_bind[i] + 16 * (size_t)j, sizeof(mlod_mat4));
		}
		o->gltf_index = k->skins[i].gltf_index;
	}
	return MLOD_OK;
}

static void skeleton_free(mlod_skeleton *s)
{
	for (int i = 0; s->skins && i < s->skin_count; i++) {
		free(s->skins[i].joints);
		free(s->skins[i].inverse_bind);
	}
	free(s->skins);
	free(s->joints);
	memset(s, 0, sizeof *s);
}

/* One skeleton level's skins: per skin, the distinct stand-ins of its
 * joints in skin order (each with the bind of the first skin joint that
 * maps to it: the writer gives every skin joint of one stand-in the same
 * bind). No mesh level is written on them (the mesh levels keep the
 * pack's weights, on the full skin): they are the record's and a glTF
 * viewer's skeleton levels. */
typedef struct level_skins {
	int *gltf;      /* per skin: the glTF skin added, or -1 */
	int *stand;     /* per full joint: its stand-in at this level */
} level_skins;

static void level_skins_free(level_skins *l)
{
	free(l->gltf);
	free(l->stand);
	memset(l, 0, sizeof *l);
}

/* Level `level`'s stage record (mlod_record_write_skeleton): the pack's
 * kept joints and stand-ins as nodes, the level's skins and its TOC
 * error; threshold and joint_error are left out (the pack has neither). */
static mlod_result record_skel_level(const mlod_skeleton *s, const mlod_pack_skel_level *lv, const level_skins *ls,
                                     int level, float error, mlod_record_skel_level *o, mlod_error *err)
{
	int n = s->joint_count;
	memset(o, 0, sizeof *o);
	o->kept = malloc(sizeof(int) * ((size_t)n + 1));
	o->remap_from = malloc(sizeof(int) * ((size_t)n + 1));
	o->remap_to = malloc(sizeof(int) * ((size_t)n + 1));
	o->skins = malloc(sizeof(int) * ((size_t)s->skin_count + 1));
	int *stand = malloc(sizeof(int) * ((size_t)n + 1));
	if (!o->kept || !o->remap_from || !o->remap_to || !o->skins || !stand) {
		free(stand);
		return nomem(err);
	}
	unsigned char *kept = calloc((size_t)n + 1, 1);
	if (!kept) {
		free(stand);
		return nomem(err);
	}
	for (uint32_t i = 0; i < lv->kept_count; i++)
		if (lv->kept[i] < (uint32_t)n)
			kept[lv->kept[i]] = 1;
	memcpy(stand, ls->stand, sizeof(int) * (size_t)n);
	size_t base = 0; /* a removed skin joint's stand-in is its palette joint */
	for (int i = 0; i < s->skin_count; i++) {
		for (int q = 0; q < s->skins[i].joint_count; q++) {
			int j = s->skins[i].joints[q];
			if (j >= 0 && j < n && base + (size_t)q < lv->palette_size)
				stand[j] = (int)lv->palette_joint[base + (size_t)q];
		}
		base += (size_t)s->skins[i].joint_count;
	}
	o->level = level;
	o->missing_threshold = 1;
	o->missing_joint_error = 1;
	o->has_pack_error = 1;
	o->pack_error = error;
	for (int j = 0; j < n; j++) {
		int node = s->joints[j].node;
		if (node < 0)
			continue;
		if (kept[j])
			o->kept[o->kept_count++] = node;
		else if (stand[j] >= 0 && stand[j] < n && s->joints[stand[j]].node >= 0) {
			o->remap_from[o->remap_count] = node;
			o->remap_to[o->remap_count++] = s->joints[stand[j]].node;
		}
	}
	o->joints = (int)lv->kept_count;
	o->skin_count = s->skin_count;
	for (int i = 0; i < s->skin_count; i++)
		o->skins[i] = ls->gltf[i];
	free(stand);
	free(kept);
	return MLOD_OK;
}

static mlod_result add_level_skins(mlod_gltf *doc, const mlod_skeleton *s, const mlod_pack_skel_level *lv,
                                   int level, level_skins *out, mlod_error *err)
{
	memset(out, 0, sizeof *out);
	out->gltf = malloc(sizeof(int) * ((size_t)s->skin_count + 1));
	out->stand = malloc(sizeof(int) * ((size_t)s->joint_count + 1));
	if (!out->gltf || !out->stand)
		return nomem(err);
	/* Stand-ins: a joint's nearest kept ancestor (itself when kept). */
	unsigned char *kept = calloc((size_t)s->joint_count + 1, 1);
	if (!kept)
		return nomem(err);
	for (uint32_t i = 0; i < lv->kept_count; i++)
		kept[lv->kept[i]] = 1;
	for (int j = 0; j < s->joint_count; j++) { /* parents come before children */
		int a = j;
		while (a >= 0 && !kept[a])
			a = s->joints[a].parent;
		out->stand[j] = a >= 0 ? a : j;
	}
	free(kept);
	size_t base = 0;
	mlod_result r = MLOD_OK;
	for (int i = 0; r == MLOD_OK && i < s->skin_count; i++) {
		const mlod_skin *full = &s->skins[i];
		int n = full->joint_count, m = 0;
		int *joints = malloc(sizeof(int) * ((size_t)n + 1));
		mlod_mat4 *bind = malloc(sizeof(mlod_mat4) * ((size_t)n + 1));
		if (!joints || !bind) {
			free(joints);
			free(bind);
			return nomem(err);
		}
		for (int j = 0; j < n; j++) {
			int pj = (int)lv->palette_joint[base + (size_t)j], t = 0;
			while (t < m && joints[t] != pj)
				t++;
			if (t == m) {
				joints[m] = pj;
				memcpy(bind[m].m, lv->palette_bind + 16 * (base + (size_t)j), sizeof(mlod_mat4));
				m++;
			}
		}
		base += (size_t)n;
		char name[160];
		snprintf(name, sizeof name, "%s@lod%d", full->name ? full->name : "", level);
		mlod_skin skin = {0};
		skin.name = name;
		skin.joint_count = m;
		skin.joints = joints;
		skin.inverse_bind = bind;
		skin.gltf_index = -1;
		out->gltf[i] = -1;
		r = mlod_gltf_add_skin(doc, s, &skin, &out->gltf[i], err);
		free(joints);
		free(bind);
	}
	return r;
}

/* The primitive of a decoded part (pointing into it). */
static void part_primitive(const mlod_pack_part *q, mlod_primitive *p, mlod_morph_target *targets)
{
	memset(p, 0, sizeof *p);
	p->vertex_count = (int)q->rec.vertex_count;
	p->positions = q->positions;
	p->normals = q->normals;
	p->tangents = q->tangents;
	p->uv_set_count = (int)q->rec.uv_sets;
	for (uint32_t s = 0; s < q->rec.uv_sets; s++)
		p->uvs[s] = q->uvs[s];
	if (q->colors) {
		p->color_set_count = 1;
		p->colors[0] = q->colors;
	}
	if (q->joints && q->weights) {
		p->weight_set_count = 1;
		p->joints[0] = q->joints;
		p->weights[0] = q->weights;
	}
	p->index_count = (int)q->rec.index_count;
	p->indices = q->indices;
	p->mode = 4;
	p->material = q->rec.material;
	p->target_count = (int)q->rec.target_count;
	p->targets = targets;
	for (uint32_t t = 0; t < q->rec.target_count; t++) {
		memset(&targets[t], 0, sizeof targets[t]);
		targets[t].positions = q->targets[t];
	}
}

/* The parts of a mesh level that belong to node (in part order). */
static int node_parts(const mlod_pack_mesh *m, int node, int *out)
{
	int n = 0;
	for (uint32_t i = 0; i < m->part_count; i++)
		if (m->parts[i].rec.node == node)
			out[n++] = (int)i;
	return n;
}

/* A part without a triangle at a level (the writer drops the triangles
 * quantisation makes degenerate, mlod(5) MESH levels): glTF has no empty
 * primitive, so it goes out as one degenerate triangle on one vertex,
 * which mlod-pack drops again. The vertex is the part's first at the
 * nearest level that has one; a part with none at any level gets one
 * made up (at its grid's origin, normal +z, joint 0 of weight 1) in lone,
 * with *zeros its morph targets' zero deltas. */
typedef struct lone_vertex {
	float pos[3], nrm[3], tan[4], uv[MLOD_PACK_MAX_UV][2], col[4], w[4];
	uint16_t j[4];
	uint32_t idx[3];
} lone_vertex;

static mlod_result lone_primitive(const mlod_pack_mesh *meshes, int levels, int k, int part, mlod_primitive *p,
                                  mlod_morph_target *targets, lone_vertex *lone, float **zeros, mlod_error *err)
{
	const mlod_pack_part *q = &meshes[k].parts[part];
	for (int d = 1; d < levels; d++) /* the nearest level with vertices, finer first */
		for (int e = -1; e <= 1; e += 2) {
			int l = k + e * d;
			if (l >= 0 && l < levels && meshes[l].parts[part].rec.vertex_count > 0) {
				part_primitive(&meshes[l].parts[part], p, targets);
				p->vertex_count = 1;
				p->material = q->rec.material;
				p->index_count = 3;
				p->indices = lone->idx;
				return MLOD_OK;
			}
		}
	memset(lone, 0, sizeof *lone);
	part_primitive(q, p, targets);
	memcpy(lone->pos, q->rec.pos_min, sizeof lone->pos);
	lone->nrm[2] = 1.0f;
	lone->tan[0] = lone->tan[3] = 1.0f;
	for (uint32_t t = 0; t < q->rec.uv_sets; t++) {
		memcpy(lone->uv[t], q->rec.uv_min[t], sizeof lone->uv[t]);
		p->uvs[t] = lone->uv[t];
	}
	for (int c = 0; c < 4; c++)
		lone->col[c] = 1.0f;
	lone->w[0] = 1.0f;
	p->vertex_count = 1;
	p->positions = lone->pos;
	p->normals = q->rec.flags & MLOD_PART_NORMALS ? lone->nrm : NULL;
	p->tangents = q->rec.flags & MLOD_PART_TANGENTS ? lone->tan : NULL;
	p->color_set_count = q->rec.flags & MLOD_PART_COLORS ? 1 : 0;
	p->colors[0] = p->color_set_count ? lone->col : NULL;
	p->weight_set_count = q->rec.flags & MLOD_PART_SKINNED ? 1 : 0;
	p->joints[0] = p->weight_set_count ? lone->j : NULL;
	p->weights[0] = p->weight_set_count ? lone->w : NULL;
	p->index_count = 3;
	p->indices = lone->idx;
	if (q->rec.target_count > 0 && !(*zeros = calloc(3, sizeof **zeros)))
		return nomem(err);
	for (uint32_t t = 0; t < q->rec.target_count; t++)
		targets[t].positions = *zeros;
	return MLOD_OK;
}

/* Adds the mesh of node's parts at level k of meshes (levels of them;
 * like glTF mesh `like`), skinned parts with the joints and weights the
 * pack stores (on the full skin). rigid: the parts are a rigid part's
 * coarser level, given joint 0 of weight 1 (rigid_skin). */
static mlod_result add_parts_mesh(mlod_gltf *doc, const mlod_pack_mesh *meshes, int levels, int k, const int *parts,
                                  int count, int like, int rigid, int *out, mlod_error *err)
{
	const mlod_pack_mesh *m = &meshes[k];
	mlod_primitive *prims = calloc((size_t)count + 1, sizeof *prims);
	mlod_morph_target **targets = calloc((size_t)count + 1, sizeof *targets);
	uint16_t **js = calloc((size_t)count + 1, sizeof *js);
	float **ws = calloc((size_t)count + 1, sizeof *ws), **zeros = calloc((size_t)count + 1, sizeof *zeros);
	lone_vertex *lone = calloc((size_t)count + 1, sizeof *lone);
	mlod_result r = MLOD_OK;
	if (!prims || !targets || !js || !ws || !zeros || !lone)
		r = nomem(err);
	for (int i = 0; r == MLOD_OK && i < count; i++) {
		const mlod_pack_part *q = &m->parts[parts[i]];
		targets[i] = calloc((size_t)q->rec.target_count + 1, sizeof **targets);
		if (!targets[i]) {
			r = nomem(err);
			break;
		}
		part_primitive(q, &prims[i], targets[i]);
		if (q->rec.index_count == 0 &&
		    (r = lone_primitive(meshes, levels, k, parts[i], &prims[i], targets[i], &lone[i], &zeros[i], err)) !=
		        MLOD_OK)
			break;
		if (rigid && !prims[i].weight_set_count) {
			/* A rigid part's level follows its one-joint skin: joint 0, weight 1. */
			size_t nv = (size_t)prims[i].vertex_count;
			js[i] = calloc(4 * nv + 1, sizeof **js);
			ws[i] = calloc(4 * nv + 1, sizeof **ws);
			if (!js[i] || !ws[i]) {
				r = nomem(err);
				break;
			}
			for (size_t v = 0; v < nv; v++)
				ws[i][4 * v] = 1.0f;
			prims[i].weight_set_count = 1;
			prims[i].joints[0] = js[i];
			prims[i].weights[0] = ws[i];
		}
	}
	if (r == MLOD_OK) {
		mlod_mesh mesh = {0};
		mesh.primitive_count = count;
		mesh.primitives = prims;
		mesh.gltf_index = like;
		*out = -1;
		r = like >= 0 && like < mlod_gltf_count(doc, MLOD_GLTF_MESH) ? mlod_gltf_add_mesh_like(doc, like, &mesh, out, err)
		                                                               : mlod_gltf_add_mesh(doc, &mesh, out, err);
	}
	for (int i = 0; i < count; i++) {
		if (targets)
			free(targets[i]);
		if (js)
			free(js[i]);
		if (ws)
			free(ws[i]);
		if (zeros)
			free(zeros[i]);
	}
	free(targets);
	free(js);
	free(ws);
	free(zeros);
	free(lone);
	free(prims);
	return r;
}

/* A skin of one joint for a rigid part's coarser levels: world = W(joint)
 * * offset * p, the part's own joint and offset (the pack's). */
static mlod_result rigid_skin(mlod_gltf *doc, const mlod_skeleton *s, int joint, const float *offset, int *index,
                              mlod_error *err)
{
	mlod_mat4 ibm;
	memcpy(ibm.m, offset, sizeof ibm.m);
	int joints[1] = {joint};
	mlod_skin skin = {0};
	skin.name = "mlod rigid part";
	skin.joint_count = 1;
	skin.joints = joints;
	skin.inverse_bind = &ibm;
	skin.gltf_index = -1;
	*index = -1;
	return mlod_gltf_add_skin(doc, s, &skin, index, err);
}

/* A decoded motion level as a clip (pointing into it). */
static mlod_result add_clip(mlod_gltf *doc, const mlod_skeleton *s, const mlod_pack_motion *mo, const char *name,
                            int *index, mlod_error *err)
{
	mlod_clip clip = {0};
	clip.name = (char *)name;
	clip.duration = mo->duration;
	clip.channel_count = (int)mo->channel_count;
	clip.channels = calloc((size_t)mo->channel_count + 1, sizeof *clip.channels);
	clip.gltf_index = -1;
	if (!clip.channels)
		return nomem(err);
	for (uint32_t i = 0; i < mo->channel_count; i++) {
		const mlod_pack_channel *c = &mo->channels[i];
		mlod_channel *o = &clip.channels[i];
		o->joint = (int)c->rec.joint;
		o->path = (mlod_path)c->rec.path;
		o->interp = (mlod_interp)c->rec.interp;
		o->key_count = (int)c->rec.key_count;
		o->times = (float *)c->times;
		o->values = c->values;
		/* Rotations on the int16 lattice go back as normalised shorts. */
		if (o->path == MLOD_PATH_ROTATION && o->interp != MLOD_INTERP_CUBICSPLINE) {
			int lattice = 1;
			for (size_t v = 0; lattice && v < 4 * (size_t)o->key_count; v++) {
				float q = o->values[v] * 32767.0f;
				lattice = q == rintf(q) && fabsf(q) <= 32767.0f;
			}
			o->short_values = lattice;
		}
	}
	*index = -1;
	mlod_result r = mlod_gltf_add_animation(doc, s, &clip, index, err);
	free(clip.channels);
	return r;
}

/* Per animation of the DOC as read, whether it holds joint channels (a
 * clip of the document's character with channels): the DOC holds the
 * input whole (mlod(5) DOC), as a stripped DOC keeps no joint channel.
 * *out is NULL when the document gives no character. */
static mlod_result whole_animations(const mlod_gltf *doc, unsigned char **out, mlod_error *err)
{
	int n = mlod_gltf_count(doc, MLOD_GLTF_ANIMATION);
	mlod_character c;
	mlod_error ignored = {0};
	*out = NULL;
	if (n == 0)
		return MLOD_OK;
	memset(&c, 0, sizeof c);
	if (mlod_gltf_to_character(doc, &c, &ignored) != MLOD_OK) {
		mlod_character_free(&c);
		return MLOD_OK; /* a stripped DOC's emptied meshes */
	}
	unsigned char *w = calloc((size_t)n + 1, 1);
	if (!w) {
		mlod_character_free(&c);
		return nomem(err);
	}
	for (int i = 0; i < c.clip_count; i++)
		if (c.clips[i].channel_count > 0 && c.clips[i].gltf_index >= 0 && c.clips[i].gltf_index < n)
			w[c.clips[i].gltf_index] = 1;
	mlod_character_free(&c);
	*out = w;
	return MLOD_OK;
}

/* Whether a mesh of the DOC has a triangle list without attributes (its
 * geometry stripped: a MESH part holds it). */
static mlod_result mesh_stripped(const mlod_gltf *doc, int mesh, int *stripped, mlod_error *err)
{
	*stripped = 0;
	for (int p = 0; !*stripped; p++) {
		char **names = NULL;
		int count = 0, mode = 4;
		mlod_error e = {0};
		mlod_result r = mlod_gltf_primitive_attributes(doc, mesh, p, &mode, &names, &count, &e);
		if (r == MLOD_ERR_NOMEM)
			return mlod_fail(err, r, "%s", e.message);
		if (r != MLOD_OK) /* past the mesh's last primitive */
			break;
		mlod_free(names);
		*stripped = mode == 4 && count == 0;
	}
	return MLOD_OK;
}

/* Every DOC node whose mesh lost its geometry to the MESH chunks must be
 * an instance node of MESH level 0's parts, which give it back: another
 * would keep a primitive without attributes (not glTF). */
static mlod_result check_doc_meshes(const mlod_gltf *doc, const mlod_pack_mesh *level0, mlod_error *err)
{
	int nodes = mlod_gltf_count(doc, MLOD_GLTF_NODE);
	for (int n = 0; n < nodes; n++) {
		int mesh = -1, skin = -1, stripped = 0, part = 0;
		mlod_error ignored = {0};
		if (mlod_gltf_node_refs(doc, n, &mesh, &skin, &ignored) != MLOD_OK || mesh < 0)
			continue;
		for (uint32_t i = 0; level0 && i < level0->part_count && !part; i++)
			part = level0->parts[i].rec.node == n;
		if (part)
			continue;
		mlod_result r = mesh_stripped(doc, mesh, &stripped, err);
		if (r != MLOD_OK)
			return r;
		if (stripped)
			return mlod_fail(err, MLOD_ERR_PARSE, "DOC: node %d has mesh %d, whose triangles no MESH part of "
			                 "that node holds", n, mesh);
	}
	return MLOD_OK;
}

/* Reads the DOC's glb (mlod_gltf_read_doc: buffers emptied by stripping,
 * as older packs hold them, are dropped). */
static mlod_result read_doc(const void *glb, size_t size, mlod_gltf **doc, mlod_error *err)
{
	mlod_error derr = {0};
	mlod_result r = mlod_gltf_read_doc(glb, size, doc, &derr);
	if (r != MLOD_OK)
		return mlod_fail(err, r == MLOD_ERR_NOMEM ? r : MLOD_ERR_PARSE, "DOC: %s", derr.message);
	return MLOD_OK;
}

/* SKELETON's glTF indices are the DOC's (which keeps node and skin
 * indices): a joint's node and a skin's glTF skin must be there. */
static mlod_result check_skel_indices(const mlod_pack_skeleton *k, const mlod_gltf *doc, mlod_error *err)
{
	int nodes = mlod_gltf_count(doc, MLOD_GLTF_NODE), skins = mlod_gltf_count(doc, MLOD_GLTF_SKIN);
	for (uint32_t j = 0; j < k->joint_count; j++)
		if (k->joints[j].node >= nodes)
			return mlod_fail(err, MLOD_ERR_PARSE, "SKELETON: joint %u: node %d is not one of the DOC chunk's %d "
			                 "nodes", j, (int)k->joints[j].node, nodes);
	for (uint32_t i = 0; i < k->skin_count; i++)
		if (k->skins[i].gltf_index >= skins)
			return mlod_fail(err, MLOD_ERR_PARSE, "SKELETON: skin %u: glTF skin %d is not one of the DOC chunk's "
			                 "%d skins", i, (int)k->skins[i].gltf_index, skins);
	return MLOD_OK;
}

mlod_result mlod_pack_check_doc(const mlod_pack *p, const void *data, size_t size, mlod_error *err)
{
	mlod_pack_doc_bytes glb;
	mlod_pack_skeleton skel;
	mlod_gltf *doc = NULL;
	memset(&skel, 0, sizeof skel);
	mlod_result r = mlod_pack_decode_doc(p, data, size, &glb, err);
	if (r != MLOD_OK)
		return r;
	r = read_doc(glb.glb, glb.size, &doc, err);
	mlod_pack_doc_free(&glb);
	if (r == MLOD_OK && mlod_pack_find(p, MLOD_CHUNK_SKELETON, 0, 0) >= 0 &&
	    (r = mlod_pack_decode_skeleton(p, data, size, &skel, err)) == MLOD_OK)
		r = check_skel_indices(&skel, doc, err);
	mlod_pack_skeleton_free(&skel);
	mlod_gltf_free(doc);
	return r;
}

mlod_result mlod_pack_inspect(const void *data, size_t size, mlod_pack *p, mlod_pack_info *info, mlod_error *err)
{
	memset(info, 0, sizeof *info);
	mlod_result r = mlod_pack_open(data, size, p, err);
	if (r != MLOD_OK)
		return r;
	if ((r = mlod_pack_check(p, data, size, err)) == MLOD_OK && (r = mlod_pack_check_doc(p, data, size, err)) == MLOD_OK) {
		if (p->file_size != size)
			r = mlod_fail(err, MLOD_ERR_PARSE, "the header says %llu bytes, the file has %zu",
			              (unsigned long long)p->file_size, size);
		else
			r = mlod_pack_decode_info(p, data, size, info, err);
	}
	if (r != MLOD_OK)
		mlod_pack_close(p);
	return r;
}

mlod_result mlod_pack_unpack(const void *data, size_t size, mlod_gltf **out, mlod_error *err)
{
	mlod_pack p;
	mlod_pack_info info;
	mlod_pack_skeleton skel;
	mlod_pack_mesh *meshes = NULL;
	mlod_skeleton s;
	level_skins *ls = NULL;
	mlod_gltf *doc = NULL;
	int *parts = NULL, *nodes = NULL, *mesh_map = NULL, *lod_nodes = NULL;
	unsigned char *used = NULL, *whole = NULL;
	mlod_record_skel_level *skel_rec = NULL; /* the stage record's skeleton levels */
	mlod_record_mesh_level *mesh_rec = NULL;  /* and mesh levels */
	uint32_t mesh_levels = 0, skel_levels = 0;
	int have_skel = 0, node_count = 0;
	/* The chunk whose data the document is being built from: a glTF call
	 * that refuses it as an argument (MLOD_ERR_INVALID_ARG) means a
	 * corrupt pack, MLOD_ERR_PARSE with the chunk named (at done). */
	char where[64] = "";
	memset(&info, 0, sizeof info);
	memset(&skel, 0, sizeof skel);
	memset(&s, 0, sizeof s);
	*out = NULL;

	mlod_result r = mlod_pack_open(data, size, &p, err);
	if (r != MLOD_OK)
		return r;
	/* Every chunk and INFO's counts checked first, as --info checks them
	 * (the chunks are decoded again below: -x is not a hot path). */
	if ((r = mlod_pack_check(&p, data, size, err)) != MLOD_OK)
		goto done;
	if ((r = mlod_pack_decode_info(&p, data, size, &info, err)) != MLOD_OK)
		goto done;
	if (mlod_pack_find(&p, MLOD_CHUNK_SKELETON, 0, 0) >= 0) {
		if ((r = mlod_pack_decode_skeleton(&p, data, size, &skel, err)) != MLOD_OK)
			goto done;
		have_skel = 1;
	}
	mlod_pack_doc_bytes glb;
	if ((r = mlod_pack_decode_doc(&p, data, size, &glb, err)) != MLOD_OK)
		goto done;
	r = read_doc(glb.glb, glb.size, &doc, err);
	mlod_pack_doc_free(&glb);
	if (r != MLOD_OK)
		goto done;
	if ((r = whole_animations(doc, &whole, err)) != MLOD_OK)
		goto done;
	if ((r = build_skeleton(have_skel ? &skel : NULL, &s, err)) != MLOD_OK)
		goto done;
	node_count = mlod_gltf_count(doc, MLOD_GLTF_NODE);
	if (have_skel && (r = check_skel_indices(&skel, doc, err)) != MLOD_OK)
		goto done;
	snprintf(where, sizeof where, "SKELETON");
	/* The joints' nodes get back their rest TRS from SKEL, and the DOC's
	 * skins the inverse bind matrices SKEL holds (the writer drops both
	 * from the DOC unless they are the defaults). */
	char *mark = NULL;
	mlod_error merr = {0};
	int trs_mode = -1; /* the writer's asset extras.mlod.doc_trs; none: no TRS dropped */
	if (mlod_gltf_get_extra(doc, MLOD_GLTF_ASSET, 0, "mlod", &mark, &merr) == MLOD_OK && mark) {
		for (int m = 0; m < 3; m++) {
			char want[32];
			snprintf(want, sizeof want, "{\"doc_trs\":%d}", m);
			if (strcmp(mark, want) == 0)
				trs_mode = m;
		}
		if (trs_mode >= 0 && (r = mlod_gltf_remove_extra(doc, MLOD_GLTF_ASSET, 0, "mlod", NULL, err)) != MLOD_OK) {
			mlod_free(mark);
			goto done;
		}
	}
	mlod_free(mark);
	for (int j = 0; trs_mode >= 0 && j < s.joint_count; j++) {
		mlod_error serr = {0};
		if (s.joints[j].node >= 0 && s.joints[j].node < node_count &&
		    mlod_gltf_fill_node_trs(doc, s.joints[j].node, &s.joints[j].rest, trs_mode, &serr) != MLOD_OK) {
			r = mlod_fail(err, MLOD_ERR_PARSE, "SKEL joint %d: %s", j, serr.message);
			goto done;
		}
	}
	for (int i = 0; i < s.skin_count; i++) {
		const mlod_skin *sk = &s.skins[i];
		mlod_mat4 id = mlod_mat4_identity();
		int identity = 1;
		for (int j = 0; identity && j < sk->joint_count; j++)
			identity = memcmp(&sk->inverse_bind[j], &id, sizeof id) == 0;
		if (identity || sk->gltf_index < 0 || sk->gltf_index >= mlod_gltf_count(doc, MLOD_GLTF_SKIN) ||
		    mlod_gltf_skin_has_inverse_binds(doc, sk->gltf_index)) /* a DOC holding the input whole */
			continue;
		mlod_error serr = {0};
		if (mlod_gltf_set_inverse_binds(doc, sk->gltf_index, sk->inverse_bind, sk->joint_count, &serr) != MLOD_OK) {
			r = mlod_fail(err, MLOD_ERR_PARSE, "SKEL skin %d: %s", i, serr.message);
			goto done;
		}
	}

	/* Skeleton levels: their skins. */
	skel_levels = have_skel ? info.rec.skeleton_levels : 0;
	ls = calloc((size_t)skel_levels + 1, sizeof *ls);
	skel_rec = calloc((size_t)skel_levels + 1, sizeof *skel_rec);
	if (!ls || !skel_rec) {
		r = nomem(err);
		goto done;
	}
	for (uint32_t k = 1; k < skel_levels; k++) {
		int c = mlod_pack_find(&p, MLOD_CHUNK_SKELETON, k, 0);
		mlod_pack_skel_level lv;
		memset(&lv, 0, sizeof lv);
		if (c < 0) {
			r = mlod_fail(err, MLOD_ERR_PARSE, "SKEL level %u: missing", k);
			goto done;
		}
		if ((r = mlod_pack_decode_skel_level(&p, (uint32_t)c, data, size, &skel, &lv, err)) != MLOD_OK)
			goto done;
		snprintf(where, sizeof where, "SKELETON level %u", k);
		r = add_level_skins(doc, &s, &lv, (int)k, &ls[k], err);
		if (r == MLOD_OK)
			r = record_skel_level(&s, &lv, &ls[k], (int)k, p.chunks[c].error, &skel_rec[k - 1], err);
		mlod_pack_skel_level_free(&lv);
		if (r != MLOD_OK)
			goto done;
	}

	/* Mesh levels. */
	mesh_levels = info.rec.mesh_levels;
	meshes = calloc((size_t)mesh_levels + 1, sizeof *meshes);
	if (!meshes) {
		r = nomem(err);
		goto done;
	}
	for (uint32_t k = 0; k < mesh_levels; k++) {
		int c = mlod_pack_find(&p, MLOD_CHUNK_MESH, k, 0);
		if (c < 0) {
			r = mlod_fail(err, MLOD_ERR_PARSE, "MESH level %u: missing", k);
			goto done;
		}
		if ((r = mlod_pack_decode_mesh(&p, (uint32_t)c, data, size, have_skel ? &skel : NULL, &meshes[k], err)) !=
		    MLOD_OK)
			goto done;
	}
	if ((r = check_doc_meshes(doc, mesh_levels > 0 ? &meshes[0] : NULL, err)) != MLOD_OK)
		goto done;
	/* The record's mesh levels: what the pack stores of each. */
	mesh_rec = calloc((size_t)mesh_levels + 1, sizeof *mesh_rec);
	if (!mesh_rec) {
		r = nomem(err);
		goto done;
	}
	for (uint32_t k = 1; k < mesh_levels; k++) {
		mlod_record_mesh_level *m = &mesh_rec[k - 1];
		long tris = 0, verts = 0;
		for (uint32_t i = 0; i < meshes[k].part_count; i++) {
			tris += (long)meshes[k].parts[i].rec.index_count / 3;
			verts += (long)meshes[k].parts[i].rec.vertex_count;
		}
		m->level = (int)k;
		m->missing_ratio = 1;
		m->missing_error = 1;
		m->triangles = (int)tris;
		m->vertices = (int)verts;
		m->has_pack_error = 1;
		m->pack_error = p.chunks[mlod_pack_find(&p, MLOD_CHUNK_MESH, k, 0)].error;
	}
	if (mesh_levels > 0) {
		uint32_t n = meshes[0].part_count, most = 0;
		for (uint32_t k = 0; k < mesh_levels; k++) /* node_parts' room at any level */
			most = meshes[k].part_count > most ? meshes[k].part_count : most;
		parts = malloc(sizeof(int) * ((size_t)most + 1));
		nodes = malloc(sizeof(int) * ((size_t)n + 1));
		mesh_map = malloc(sizeof(int) * ((size_t)mlod_gltf_count(doc, MLOD_GLTF_MESH) + 1));
		lod_nodes = malloc(sizeof(int) * ((size_t)mesh_levels + 1));
		if (!parts || !nodes || !mesh_map || !lod_nodes) {
			r = nomem(err);
			goto done;
		}
		for (int i = 0; i < mlod_gltf_count(doc, MLOD_GLTF_MESH); i++)
			mesh_map[i] = -1;
		/* The instance nodes, in part order. */
		int nn = 0;
		for (uint32_t i = 0; i < n; i++) {
			int node = meshes[0].parts[i].rec.node, seen = 0;
			for (int j = 0; j < nn; j++)
				seen |= nodes[j] == node;
			if (!seen)
				nodes[nn++] = node;
		}
		double errors[MLOD_MESH_MAX_LEVELS + 64];
		float coverage[MLOD_MESH_MAX_LEVELS + 65];
		int lods = (int)mesh_levels - 1;
		if (lods > MLOD_MESH_MAX_LEVELS + 63)
			lods = MLOD_MESH_MAX_LEVELS + 63;
		for (int k = 1; k <= lods; k++) {
			int c = mlod_pack_find(&p, MLOD_CHUNK_MESH, (unsigned)k, 0);
			float e = p.chunks[c].error;
			errors[k - 1] = info.rec.diagonal > 0.0f ? 100.0 * e / info.rec.diagonal : 0.0;
		}
		if (lods > 0)
			mlod_lod_coverage(errors, lods, coverage);
		for (int j = 0; j < nn; j++) {
			int node = nodes[j];
			if (node < 0 || node >= node_count)
				continue; /* an instance the DOC has no node for */
			int count = node_parts(&meshes[0], node, parts);
			const mlod_pack_part_rec *q0 = &meshes[0].parts[parts[0]].rec;
			int like = q0->mesh, old_mesh = -1, old_skin = -1, mesh = -1;
			snprintf(where, sizeof where, "MESH level 0");
			if ((r = mlod_gltf_node_refs(doc, node, &old_mesh, &old_skin, err)) != MLOD_OK)
				goto done;
			/* Level 0: the node's own mesh again; a DOC that holds the
			 * input whole has it as read (which an extension mlod does
			 * not know may refer to): it stays. */
			int kept = 0;
			if (like >= 0 && like < mlod_gltf_count(doc, MLOD_GLTF_MESH) && like == old_mesh &&
			    (r = mesh_stripped(doc, like, &kept, err)) != MLOD_OK)
				goto done;
			kept = like >= 0 && like == old_mesh && !kept;
			if (kept) {
				mesh = like;
			} else if (like >= 0 && like < mlod_gltf_count(doc, MLOD_GLTF_MESH) && mesh_map[like] >= 0) {
				mesh = mesh_map[like];
			} else {
				if ((r = add_parts_mesh(doc, meshes, (int)mesh_levels, 0, parts, count, like, 0, &mesh, err)) != MLOD_OK)
					goto done;
				/* the DOC mesh's points, lines, strips and fans, kept whole */
				if (like >= 0 && like < mlod_gltf_count(doc, MLOD_GLTF_MESH) &&
				    (r = mlod_gltf_append_other_primitives(doc, like, mesh, NULL, err)) != MLOD_OK)
					goto done;
				if (like >= 0 && like < mlod_gltf_count(doc, MLOD_GLTF_MESH))
					mesh_map[like] = mesh;
			}
			int skin0 = old_skin;
			if (q0->skin >= 0 && q0->skin < s.skin_count && s.skins[q0->skin].gltf_index >= 0)
				skin0 = s.skins[q0->skin].gltf_index;
			if ((r = mlod_gltf_set_node_mesh(doc, node, mesh, skin0, err)) != MLOD_OK)
				goto done;
			/* Coarser levels: detached level nodes. */
			mlod_trs trs, *tp = NULL;
			if (q0->skin < 0 && q0->joint < 0) {
				mlod_error ignored = {0};
				if (mlod_gltf_get_node_trs(doc, node, &trs, &ignored) != MLOD_OK)
					continue; /* a sheared matrix: no MSFT_lod (as mlod-bgm) */
				tp = &trs;
			}
			int rigid_index = -1;
			for (int k = 1; k <= lods; k++) {
				int ck = node_parts(&meshes[k], node, parts);
				if (ck != count) {
					r = mlod_fail(err, MLOD_ERR_PARSE, "MESH level %d: node %d has %d parts, level 0 %d", k, node, ck,
					              count);
					goto done;
				}
				int skin = skin0, lmesh = -1, lnode = -1;
				snprintf(where, sizeof where, "MESH level %d", k);
				/* Every level on the weights the pack stores: a skinned
				 * part's on the full skin (level 0's), a rigid part's on
				 * a one-joint skin of its own joint, so that the level
				 * poses as the runtime poses it at skeleton level 0 and
				 * mlod-pack keeps it as it is. */
				if (q0->skin < 0 && q0->joint >= 0 && q0->joint < s.joint_count) {
					if (rigid_index < 0 &&
					    (r = rigid_skin(doc, &s, q0->joint, q0->offset, &rigid_index, err)) != MLOD_OK)
						goto done;
					skin = rigid_index;
				}
				if ((r = add_parts_mesh(doc, meshes, (int)mesh_levels, k, parts, count, like, q0->skin < 0 && q0->joint >= 0,
				                          &lmesh, err)) != MLOD_OK)
					goto done;
				char name[96];
				snprintf(name, sizeof name, "mlod mesh level %d of node %d", k, node);
				if ((r = mlod_gltf_add_node(doc, name, MLOD_GLTF_DETACHED, lmesh, skin, tp, &lnode, err)) != MLOD_OK)
					goto done;
				mlod_record_mesh_node rn;
				memset(&rn, 0, sizeof rn);
				rn.level = k;
				rn.missing_ratio = 1;
				rn.missing_error = 1;
				rn.has_pack_error = 1;
				rn.pack_error = mesh_rec[k - 1].pack_error;
				if ((r = mlod_record_write_mesh_node(doc, lnode, &rn, err)) != MLOD_OK)
					goto done;
				if (meshes[k].parts[parts[0]].rec.target_count > 0 &&
				    (r = mlod_gltf_copy_morph_animation(doc, node, lnode, NULL, err)) != MLOD_OK)
					goto done;
				lod_nodes[k - 1] = lnode;
			}
			if (lods > 0 && (r = mlod_gltf_set_lod(doc, node, lod_nodes, lods, coverage, err)) != MLOD_OK)
				goto done;
		}
	}

	/* Motion: level 0 as the clip, coarser levels as <clip>@lod<k>. A
	 * clip whose animation the DOC kept (for its other channels: morph
	 * weights, nodes that are not joints) goes back into it. */
	int doc_anims = mlod_gltf_count(doc, MLOD_GLTF_ANIMATION);
	used = calloc((size_t)doc_anims + 1, 1);
	if (!used) {
		r = nomem(err);
		goto done;
	}
	for (uint32_t c = 0; have_skel && c < info.rec.clip_count; c++) {
		int anim0 = -1; /* the clip's level-0 animation */
		for (uint32_t k = 0; k < info.rec.motion_levels; k++) {
			int ch = mlod_pack_find(&p, MLOD_CHUNK_MOTION, k, c);
			if (ch < 0) {
				r = mlod_fail(err, MLOD_ERR_PARSE, "ANIM level %u of clip %u: missing", k, c);
				goto done;
			}
			mlod_pack_motion mo;
			memset(&mo, 0, sizeof mo);
			if ((r = mlod_pack_decode_motion(&p, (uint32_t)ch, data, size, &skel, &mo, err)) != MLOD_OK)
				goto done;
			char name[512];
			if (k == 0)
				snprintf(name, sizeof name, "%s", info.clip_names[c]);
			else if (info.clip_names[c][0])
				snprintf(name, sizeof name, "%s@lod%u", info.clip_names[c], k);
			else /* an unnamed clip's levels: animation_<its index>, as mlod-motion names them */
				snprintf(name, sizeof name, "animation_%d@lod%u", anim0, k);
			if (mo.channel_count == 0) {
				/* A clip that animates no joint (a camera's, a morph
				 * weights clip): its levels hold nothing to add, and its
				 * channels stay in the document's animation. */
				mlod_pack_motion_free(&mo);
				continue;
			}
			int anim = -1, into = -1;
			snprintf(where, sizeof where, "MOTION level %u of clip %u", k, c);
			for (int a = 0; k == 0 && a < doc_anims; a++) {
				a = mlod_gltf_find_animation(doc, name, a);
				if (a < 0 || a >= doc_anims)
					break;
				if (!used[a]) {
					into = a;
					used[a] = 1;
					break;
				}
			}
			if (into >= 0 && whole && whole[into]) {
				/* The DOC holds the input whole, this clip's joint
				 * channels too: they stay as the clip (the input's keys,
				 * within level 0's error of them), as the document's
				 * channels cannot be taken out; merged, the level-0
				 * channels would animate every joint twice. */
				anim = into;
			} else {
				r = add_clip(doc, &s, &mo, name, &anim, err);
				if (r == MLOD_OK && into >= 0) {
					r = mlod_gltf_merge_animation(doc, into, err);
					anim = into;
				}
			}
			mlod_pack_motion_free(&mo);
			/* Its record: level 0's error on the clip, a coarser level's
			 * source clip and error on it. */
			if (r == MLOD_OK && k == 0) {
				anim0 = anim;
				r = mlod_record_write_motion0(doc, anim, p.chunks[ch].error, err);
			} else if (r == MLOD_OK) {
				mlod_record_motion_level ml;
				memset(&ml, 0, sizeof ml);
				ml.level = (int)k;
				ml.source_animation = anim0;
				ml.missing_method = ml.missing_keys = ml.missing_joint_error = ml.missing_point_error = 1;
				ml.has_pack_error = 1;
				ml.pack_error = p.chunks[ch].error;
				r = mlod_record_write_motion(doc, anim, &ml, err);
			}
			if (r != MLOD_OK)
				goto done;
		}
	}

	/* The scene's record: skeleton and mesh levels (every writer above
	 * stamped the version). */
	snprintf(where, sizeof where, "SKELETON");
	if (have_skel) { /* an empty list when the pack has level 0 alone */
		int *full = malloc(sizeof(int) * ((size_t)s.skin_count + 1));
		if (!full) {
			r = nomem(err);
			goto done;
		}
		for (int i = 0; i < s.skin_count; i++)
			full[i] = s.skins[i].gltf_index >= 0 && s.skins[i].gltf_index < mlod_gltf_count(doc, MLOD_GLTF_SKIN)
			              ? s.skins[i].gltf_index
			              : -1;
		r = mlod_record_write_skeleton(doc, skel_rec, skel_levels > 0 ? (int)skel_levels - 1 : 0, full, s.skin_count,
		                               err);
		free(full);
		if (r != MLOD_OK)
			goto done;
	}
	snprintf(where, sizeof where, "MESH");
	if (mesh_levels > 0 && (r = mlod_record_write_mesh_levels(doc, mesh_rec, (int)mesh_levels - 1, err)) != MLOD_OK)
		goto done;
	{
		snprintf(where, sizeof where, "INFO");
		/* the record's writer puts a byte of the name that is not UTF-8 as U+FFFD */
		if ((r = mlod_record_write_pack(doc, info.name, info.rec.bounds_min, info.rec.bounds_max, err)) != MLOD_OK)
			goto done;
	}

	/* The DOC's emptied meshes go. */
	{
		mlod_error perr = {0};
		mlod_result pr = mlod_gltf_prune(doc, &perr);
		if (pr != MLOD_OK && pr != MLOD_ERR_UNSUPPORTED) {
			r = mlod_fail(err, pr, "%s", perr.message);
			goto done;
		}
	}
	*out = doc;
	doc = NULL;
done:
	if (r == MLOD_ERR_INVALID_ARG && where[0] && err) {
		char message[sizeof err->message];
		snprintf(message, sizeof message, "%s", err->message);
		r = mlod_fail(err, MLOD_ERR_PARSE, "%s: %s", where, message);
	}
	for (uint32_t k = 0; meshes && k < mesh_levels; k++)
		mlod_pack_mesh_free(&meshes[k]);
	free(meshes);
	for (uint32_t k = 0; ls && k <= skel_levels; k++)
		level_skins_free(&ls[k]);
	free(ls);
	for (uint32_t k = 0; skel_rec && k < skel_levels; k++)
		mlod_record_skel_level_free(&skel_rec[k]);
	free(skel_rec);
	free(mesh_rec);
	free(parts);
	free(nodes);
	free(mesh_map);
	free(lod_nodes);
	free(used);
	free(whole);
	skeleton_free(&s);
	mlod_gltf_free(doc);
	mlod_pack_skeleton_free(&skel);
	mlod_pack_info_free(&info);
	mlod_pack_close(&p);
	return r;
}
