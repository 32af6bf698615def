/*
 * packchar.c: the character as packed: the view of the input (its full
 * skins and clips), its rest measures (bounds, height, diagonal), the
 * notes and warnings, and the attributes the pack does not store
 * (packwrite_internal.h).
 */
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pack/packwrite_internal.h"

/* ------------------------------------------------------------------ */
/* The character as packed                                             */
/* ------------------------------------------------------------------ */

void pack_note_n(struct ctx *x, const char *text, size_t tlen)
{
	char *n = x->st->notes;
	size_t len = strlen(n);
	if (len + tlen + 3 < sizeof x->st->notes && tlen <= INT_MAX)
		snprintf(n + len, sizeof x->st->notes - len, "%s%.*s", len ? "; " : "", (int)tlen, text);
}

void pack_note(struct ctx *x, const char *text)
{
	pack_note_n(x, text, strlen(text));
}

/* A note that is also a warning (mlod_pack_stats.warnings). */
void pack_warn(struct ctx *x, const char *text)
{
	pack_note(x, text);
	char *w = x->st->warnings;
	size_t len = strlen(w);
	if (len + strlen(text) + 2 < sizeof x->st->warnings)
		snprintf(w + len, sizeof x->st->warnings - len, "%s%s", len ? "\n" : "", text);
}

int pack_joint_of_node(const mlod_skeleton *s, int node)
{
	for (int j = 0; j < s->joint_count; j++)
		if (s->joints[j].node == node)
			return j;
	return -1;
}

int pack_skin_of_gltf(const mlod_skeleton *s, int g)
{
	for (int i = 0; g >= 0 && i < s->skin_count; i++)
		if (s->skins[i].gltf_index == g)
			return i;
	return -1;
}

int pack_mesh_of_gltf(const mlod_character *c, int g)
{
	for (int i = 0; g >= 0 && i < c->mesh_count; i++)
		if (c->meshes[i].gltf_index == g)
			return i;
	return -1;
}

/* The level nodes of instance node `node`, by mesh level (1-based) into
 * nodes[]; returns the largest level found. errors (may be NULL) gets the
 * largest error_percent.max of each level's nodes, pack_errors the largest
 * pack_error (-1 where none has one), and *no_error 1 when a node has
 * neither. */
mlod_result pack_level_nodes(struct ctx *x, int node, int *nodes, int *max_level, double *errors,
                             double *pack_errors, int *no_error)
{
	int ids[64], count = 0;
	*max_level = 0;
	if (node < 0 || !x->doc)
		return MLOD_OK;
	mlod_result r = mlod_gltf_node_lod(x->doc, node, ids, 64, &count, x->err);
	for (int i = 0; r == MLOD_OK && i < count && i < 64; i++) {
		mlod_record_mesh_node mn;
		int found = 0;
		if ((r = mlod_record_read_mesh_node(x->doc, ids[i], &mn, &found, x->err)) != MLOD_OK || !found)
			continue;
		if (mn.level >= 1 && mn.level <= MLOD_MESH_MAX_LEVELS) {
			nodes[mn.level - 1] = ids[i];
			if (errors && mn.error.max > errors[mn.level - 1])
				errors[mn.level - 1] = mn.error.max;
			if (pack_errors && mn.has_pack_error && mn.pack_error > pack_errors[mn.level - 1])
				pack_errors[mn.level - 1] = mn.pack_error;
			if (no_error && mn.missing_error && !mn.has_pack_error)
				*no_error = 1;
			*max_level = mn.level > *max_level ? mn.level : *max_level;
		}
	}
	return r;
}

/* Builds the view: skins that are not a level's, clips that are not a
 * motion level. */
mlod_result pack_make_view(struct ctx *x)
{
	const mlod_character *c = x->in;
	const mlod_skeleton *s = &c->skeleton;
	mlod_result r;
	unsigned char *level_skin = calloc((size_t)s->skin_count + 1, 1);
	x->view_skin = malloc(sizeof(int) * ((size_t)s->skin_count + 1));
	if (!level_skin || !x->view_skin) {
		free(level_skin);
		return mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
	}
	for (int i = 0; i < x->rec.skin_count; i++)
		for (int k = 0; k < x->rec.skins[i].level_count; k++) {
			int sk = pack_skin_of_gltf(s, x->rec.skins[i].levels[k]);
			if (sk >= 0)
				level_skin[sk] = 1;
		}
	for (int k = 0; k < x->rec.skel_level_count; k++)
		for (int i = 0; i < x->rec.skel_levels[k].skin_count; i++) {
			int sk = pack_skin_of_gltf(s, x->rec.skel_levels[k].skins[i]);
			if (sk >= 0)
				level_skin[sk] = 1;
		}
	for (int i = 0; i < c->instance_count; i++) {
		int nodes[MLOD_MESH_MAX_LEVELS], max = 0;
		if ((r = pack_level_nodes(x, c->instances[i].node, nodes, &max, NULL, NULL, NULL)) != MLOD_OK) {
			free(level_skin);
			return r;
		}
		for (int k = 0; k < max; k++) {
			int mesh = -1, skin = -1;
			mlod_error ignored;
			if (mlod_gltf_node_refs(x->doc, nodes[k], &mesh, &skin, &ignored) == MLOD_OK && skin >= 0) {
				int sk = pack_skin_of_gltf(s, skin);
				if (sk >= 0 && sk != c->instances[i].skin)
					level_skin[sk] = 1;
			}
		}
	}
	x->v = *c;
	x->v.notes = NULL;
	x->v.skeleton.skins = malloc(sizeof(mlod_skin) * ((size_t)s->skin_count + 1));
	x->v.instances = malloc(sizeof(mlod_instance) * ((size_t)c->instance_count + 1));
	x->v.clips = malloc(sizeof(mlod_clip) * ((size_t)c->clip_count + 1));
	if (!x->v.skeleton.skins || !x->v.instances || !x->v.clips) {
		free(level_skin);
		return mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
	}
	x->v.skeleton.skin_count = 0;
	for (int i = 0; i < s->skin_count; i++) {
		x->view_skin[i] = level_skin[i] ? -1 : x->v.skeleton.skin_count;
		if (!level_skin[i])
			x->v.skeleton.skins[x->v.skeleton.skin_count++] = s->skins[i];
	}
	free(level_skin);
	for (int i = 0; i < c->instance_count; i++) {
		x->v.instances[i] = c->instances[i];
		if (c->instances[i].skin >= 0)
			x->v.instances[i].skin = x->view_skin[c->instances[i].skin];
	}
	x->v.clip_count = 0;
	for (int i = 0; i < c->clip_count; i++) {
		int found = 0;
		mlod_record_motion_level ml;
		if (x->doc && c->clips[i].gltf_index >= 0 &&
		    (r = mlod_record_read_motion(x->doc, c->clips[i].gltf_index, &ml, &found, x->err)) != MLOD_OK)
			return r;
		if (!found)
			x->v.clips[x->v.clip_count++] = c->clips[i];
	}
	if (x->v.skeleton.skin_count < s->skin_count || x->v.clip_count < c->clip_count) {
		char text[160];
		snprintf(text, sizeof text, "the input's level skins (%d) and level animations (%d) are packed as levels",
		         s->skin_count - x->v.skeleton.skin_count, c->clip_count - x->v.clip_count);
		pack_note(x, text);
	}
	return MLOD_OK;
}

/* Rest world matrices, bounds, height and diagonal. */
mlod_result pack_measure(struct ctx *x)
{
	const mlod_skeleton *s = &x->v.skeleton;
	x->world = malloc(sizeof(mlod_mat4) * ((size_t)s->joint_count + 1));
	mlod_trs *local = malloc(sizeof(mlod_trs) * ((size_t)s->joint_count + 1));
	if (!x->world || !local) {
		free(local);
		return mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
	}
	mlod_pose_rest(s, local);
	mlod_pose_world(s, local, x->world);
	free(local);
	int any = 0;
	for (int a = 0; a < 3; a++) {
		x->bmin[a] = 0.0f;
		x->bmax[a] = 0.0f;
	}
	mlod_posed posed = {0};
	if (x->v.instance_count > 0) {
		mlod_result r = mlod_pose_character(&x->v, x->world, &posed, x->err);
		if (r != MLOD_OK) {
			mlod_posed_free(&posed);
			return r;
		}
	}
	for (int i = 0; i < posed.vertex_count; i++)
		for (int a = 0; a < 3; a++) {
			float p = posed.positions[3 * i + a];
			if (!any || p < x->bmin[a])
				x->bmin[a] = p;
			if (!any || p > x->bmax[a])
				x->bmax[a] = p;
			any |= a == 2;
		}
	mlod_posed_free(&posed);
	if (!any)
		for (int j = 0; j < s->joint_count; j++) {
			float p[3] = {x->world[j].m[12], x->world[j].m[13], x->world[j].m[14]};
			for (int a = 0; a < 3; a++) {
				if (!any || p[a] < x->bmin[a])
					x->bmin[a] = p[a];
				if (!any || p[a] > x->bmax[a])
					x->bmax[a] = p[a];
			}
			any = 1;
		}
	/* An input unpacked from a pack (extras.mlod.pack): that pack's bounds,
	 * which its level 0 posed again after quantisation gives back only to
	 * within the quantisation steps (and its diagonal is the one its
	 * errors in percent were of). */
	if (x->rec.has_pack)
		for (int a = 0; a < 3; a++) {
			x->bmin[a] = (float)x->rec.pack_bounds_min[a];
			x->bmax[a] = (float)x->rec.pack_bounds_max[a];
		}
	float d[3] = {x->bmax[0] - x->bmin[0], x->bmax[1] - x->bmin[1], x->bmax[2] - x->bmin[2]};
	x->diag = sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
	x->height = s->joint_count > 0 ? mlod_skeleton_height(s) : 0.0f;
	return MLOD_OK;
}

/* ------------------------------------------------------------------ */
/* Attributes the pack does not store                                  */
/* ------------------------------------------------------------------ */

/* An attribute name a part stores (mlod(5) MESH levels): POSITION,
 * NORMAL, TANGENT, TEXCOORD_0 to TEXCOORD_3 (MLOD_PACK_MAX_UV), COLOR_0,
 * JOINTS_n and WEIGHTS_n (the influences). */
static int known_attribute(const char *name)
{
	static const char *const sets[] = {"TEXCOORD_", "COLOR_", "JOINTS_", "WEIGHTS_"};
	static const long most[] = {MLOD_PACK_MAX_UV, 1, LONG_MAX, LONG_MAX};
	if (!strcmp(name, "POSITION") || !strcmp(name, "NORMAL") || !strcmp(name, "TANGENT"))
		return 1;
	for (size_t i = 0; i < sizeof sets / sizeof *sets; i++) {
		size_t n = strlen(sets[i]);
		if (!strncmp(name, sets[i], n) && name[n] >= '0' && name[n] <= '9') {
			char *d;
			long k = strtol(name + n, &d, 10);
			return *d == '\0' && k < most[i];
		}
	}
	return 0;
}

/* Notes each attribute of a triangle list that the pack does not store
 * (_ID, any other custom or unknown name, a fifth UV set, a second
 * colour set), from the document's primitives (lib/io lists them; the
 * DOC chunk drops them with the rest of level 0), then morph target
 * normal and tangent deltas and influences past a vertex's 4 largest,
 * from the character's parts. Points, lines, strips
 * and fans stay whole in the DOC chunk: no note. */
mlod_result pack_note_unstored_attributes(struct ctx *x, const mlod_gltf *doc)
{
	for (int mesh = 0; doc && mesh < mlod_gltf_count(doc, MLOD_GLTF_MESH); mesh++)
		for (int p = 0;; p++) {
			char **names = NULL;
			int count = 0, mode = 4;
			mlod_error e = {0};
			mlod_result r = mlod_gltf_primitive_attributes(doc, mesh, p, &mode, &names, &count, &e);
			if (r == MLOD_ERR_NOMEM)
				return mlod_fail(x->err, r, "%s", e.message);
			if (r != MLOD_OK) /* past the mesh's last primitive */
				break;
			for (int k = 0; mode == 4 && k < count; k++)
				if (!known_attribute(names[k])) {
					char text[256];
					snprintf(text, sizeof text, "mesh %d primitive %d: attribute %s is not stored in the pack", mesh,
					         p, MLOD_QUOTED(names[k]));
					pack_warn(x, text);
				}
			mlod_free(names);
		}
	/* What the character's own parts carry that a MESH part does not:
	 * morph target normal and tangent deltas, influences past the 4
	 * largest of a vertex. */
	const mlod_character *c = x->in;
	for (int m = 0; m < c->mesh_count; m++) {
		int shown = 0;
		for (int i = 0; i < c->instance_count && !shown; i++)
			shown = c->instances[i].mesh == m;
		for (int p = 0; shown && p < c->meshes[m].primitive_count; p++) {
			const mlod_primitive *pr = &c->meshes[m].primitives[p];
			int nt = 0, past = 0;
			for (int t = 0; t < pr->target_count; t++)
				nt |= (pr->targets[t].normals ? 1 : 0) | (pr->targets[t].tangents ? 2 : 0);
			for (int v = 0; pr->weight_set_count > 1 && v < pr->vertex_count && !past; v++) {
				int distinct = 0; /* joints with weight, each counted once */
				for (int s = 0; s < pr->weight_set_count; s++)
					for (int i = 0; i < 4; i++) {
						const size_t a = 4 * (size_t)v + (size_t)i;
						int seen = !(pr->weights[s][a] > 0.0f);
						for (int s2 = 0; s2 <= s && !seen; s2++)
							for (int i2 = 0; i2 < (s2 == s ? i : 4) && !seen; i2++) {
								const size_t b = 4 * (size_t)v + (size_t)i2;
								seen = pr->weights[s2][b] > 0.0f && pr->joints[s2][b] == pr->joints[s][a];
							}
						distinct += !seen;
					}
				past = distinct > 4;
			}
			char text[256];
			if (nt) {
				snprintf(text, sizeof text, "mesh %d primitive %d: morph target %s deltas are not stored in the pack "
				         "(position deltas only)", c->meshes[m].gltf_index, p,
				         nt == 3 ? "normal and tangent" : nt == 1 ? "normal" : "tangent");
				pack_warn(x, text);
			}
			if (past) {
				snprintf(text, sizeof text, "mesh %d primitive %d: influences past the 4 largest of a vertex are "
				         "dropped (the 4 kept are scaled to sum to 1)", c->meshes[m].gltf_index, p);
				pack_warn(x, text);
			}
		}
	}
	return MLOD_OK;
}

/* Notes the skinned vertices whose weights are all 0 (glTF wants them to
 * sum to 1; the validator flags them): a pack's weights sum to 255, so
 * each goes on the skin's root joint (mlod_skin_root), which the vertex
 * then follows, the rule of mlod_primitive_fix_weights. The glTF reader
 * leaves none (it applies that rule, with its own warning, in the same
 * words): this is for a character built otherwise. */
void pack_note_unweighted(struct ctx *x)
{
	const mlod_character *c = x->in;
	for (int m = 0; m < c->mesh_count; m++) {
		int skin = -1;
		for (int i = 0; i < c->instance_count && skin < 0; i++)
			if (c->instances[i].mesh == m)
				skin = c->instances[i].skin;
		if (skin < 0 || skin >= c->skeleton.skin_count)
			continue;
		const mlod_mesh *mesh = &c->meshes[m];
		for (int p = 0; p < mesh->primitive_count; p++) {
			const mlod_primitive *pr = &mesh->primitives[p];
			int count = 0, first = -1;
			for (int v = 0; pr->weight_set_count > 0 && v < pr->vertex_count; v++) {
				int any = 0;
				for (int set = 0; set < pr->weight_set_count && !any; set++)
					for (int i = 0; i < 4; i++)
						any |= pr->weights[set][4 * (size_t)v + (size_t)i] > 0.0f;
				if (!any && count++ == 0)
					first = v;
			}
			if (count == 0)
				continue;
			const mlod_skin *sk = &c->skeleton.skins[skin];
			int root = sk->joint_count > 0 ? sk->joints[mlod_skin_root(&c->skeleton, skin)] : -1;
			const char *name = root >= 0 && c->skeleton.joints[root].name ? c->skeleton.joints[root].name : "";
			char text[256];
			int g = mesh->gltf_index >= 0 ? mesh->gltf_index : m;
			if (count == 1)
				snprintf(text, sizeof text, "mesh %d primitive %d: vertex %d has no weight: it follows the skin's "
				         "root joint %s", g, p, first, MLOD_QUOTED(name));
			else
				snprintf(text, sizeof text, "mesh %d primitive %d: %d vertices have no weight (vertex %d the first): "
				         "they follow the skin's root joint %s", g, p, count, first, MLOD_QUOTED(name));
			pack_warn(x, text);
		}
	}
}
