/*
 * skelgltf.c: records skeleton levels in a glTF document.
 *
 * For each level:
 * - every skin becomes a real glTF skin over the kept joints' nodes (plus
 *   any stand-in it needs), with the level's inverse bind matrices;
 * - every skinned mesh gets a copy whose JOINTS_n/WEIGHTS_n hold the
 *   transferred weights (the other attributes share the original
 *   accessors), placed on a node outside the scene that uses the level's
 *   skin; the original node lists these nodes in MSFT_lod, with
 *   MSFT_screencoverage from the measured errors;
 * - extras.mlod of the scene lists the levels (threshold, kept joints,
 *   remap table as node indices, errors), and extras.mlod of each skin the
 *   skins that stand for it.
 * Played with the original animations, a level node deforms exactly like
 * the level: folding keeps every kept joint's world transform.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "skeleton/mlod_skeleton.h"

/* A growing string for JSON. */
struct text {
	char *s;
	size_t len, cap;
	int failed;
};

static void put(struct text *t, const char *fmt, ...)
{
	va_list ap;
	if (t->failed)
		return;
	for (;;) {
		va_start(ap, fmt);
		int n = vsnprintf(t->s ? t->s + t->len : NULL, t->s ? t->cap - t->len : 0, fmt, ap);
		va_end(ap);
		if (n < 0) {
			t->failed = 1;
			return;
		}
		if (t->s && t->len + (size_t)n < t->cap) {
			t->len += (size_t)n;
			return;
		}
		size_t cap = (t->cap + (size_t)n + 1) * 2;
		char *s = realloc(t->s, cap);
		if (!s) {
			t->failed = 1;
			return;
		}
		t->s = s;
		t->cap = cap;
	}
}

double mlod_error_coverage(double error_percent, double screen_pixels, double pixel_budget)
{
	if (error_percent <= 0.0)
		return 0.0;
	double c = 100.0 * pixel_budget / (error_percent * screen_pixels);
	return c > 1.0 ? 1.0 : c;
}

/* The error that decides when a level may be shown, in percent of the
 * character's size. */
static double level_error(const mlod_skel_level_record *r)
{
	if (r->vertex.scale > 0.0)
		return r->vertex.max;
	return r->size > 0.0 ? 100.0 * r->joint.max / r->size : 0.0;
}

mlod_result mlod_gltf_add_skel_levels(mlod_gltf *doc, const mlod_character *full,
                                      const mlod_skel_level_record *levels, int count, mlod_error *err)
{
	const mlod_skeleton *s = &full->skeleton;
	int skins = s->skin_count, meshes = full->mesh_count;
	mlod_result r = MLOD_OK;
	struct text scene = {0};
	struct text *skin_text = calloc((size_t)skins + 1, sizeof *skin_text);
	int *skin_index = malloc(sizeof(int) * ((size_t)skins * (size_t)count + 1));
	int *mesh_index = malloc(sizeof(int) * ((size_t)meshes * (size_t)count + 1));
	int *lod_nodes = malloc(sizeof(int) * ((size_t)count + 1));
	float *coverage = malloc(sizeof(float) * ((size_t)count + 2));
	if (!skin_text || !skin_index || !mesh_index || !lod_nodes || !coverage) {
		r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory writing skeleton levels");
		goto done;
	}

	/* Skins and reskinned meshes of every level. */
	for (int k = 0; k < count; k++) {
		const mlod_character *lc = levels[k].character;
		for (int sk = 0; sk < skins; sk++) {
			r = mlod_gltf_add_skin(doc, &lc->skeleton, &lc->skeleton.skins[sk], &skin_index[k * skins + sk], err);
			if (r != MLOD_OK)
				goto done;
		}
		for (int m = 0; m < meshes; m++) {
			mesh_index[k * meshes + m] = -1;
			int skinned = 0;
			for (int i = 0; i < full->instance_count; i++)
				skinned |= full->instances[i].mesh == m && full->instances[i].skin >= 0;
			if (!skinned || full->meshes[m].gltf_index < 0)
				continue;
			r = mlod_gltf_add_mesh_reskinned(doc, full->meshes[m].gltf_index, &lc->meshes[m],
			                                 &mesh_index[k * meshes + m], err);
			if (r != MLOD_OK)
				goto done;
		}
	}

	/* Level nodes, outside the scene, listed in MSFT_lod of each skinned
	 * instance node. */
	for (int i = 0; i < full->instance_count; i++) {
		const mlod_instance *in = &full->instances[i];
		if (in->skin < 0 || in->node < 0 || mesh_index[in->mesh] < 0) /* level 1's mesh */
			continue;
		for (int k = 0; k < count; k++) {
			char name[64];
			snprintf(name, sizeof name, "mlod skeleton level %d of node %d", k + 1, in->node);
			r = mlod_gltf_add_node(doc, name, MLOD_GLTF_DETACHED, mesh_index[k * meshes + in->mesh],
			                       skin_index[k * skins + in->skin], NULL, &lod_nodes[k], err);
			if (r != MLOD_OK)
				goto done;
		}
		/* Coverage: the full mesh while level 1's error would exceed a pixel
		 * at 1080 lines, and so on down; the last level to the end. */
		for (int k = 0; k < count; k++)
			coverage[k] = (float)mlod_error_coverage(level_error(&levels[k]), 1080.0, 1.0);
		coverage[count] = 0.0f;
		for (int k = 1; k <= count; k++)
			if (coverage[k] > coverage[k - 1])
				coverage[k] = coverage[k - 1];
		if (count > 0 && (r = mlod_gltf_set_lod(doc, in->node, lod_nodes, count, coverage, err)) != MLOD_OK)
			goto done;
	}

	/* extras.mlod of the scene: the levels; of each skin: its stand-ins. */
	put(&scene, "{\"skeleton_levels\":[");
	for (int k = 0; k < count; k++) {
		const mlod_skel_level_record *rec = &levels[k];
		const mlod_skel_level *l = rec->level;
		put(&scene, "%s{\"level\":%d,\"threshold\":%.9g,\"joints\":%d,\"kept\":[", k ? "," : "", k + 1,
		    l->threshold, l->kept_count);
		for (int j = 0, first = 1; j < s->joint_count; j++) {
			if (!l->kept[j])
				continue;
			put(&scene, first ? "%d" : ",%d", s->joints[j].node);
			first = 0;
		}
		put(&scene, "],\"remap\":{");
		for (int j = 0, first = 1; j < s->joint_count; j++) {
			if (l->kept[j] || s->joints[j].node < 0)
				continue;
			put(&scene, first ? "\"%d\":%d" : ",\"%d\":%d", s->joints[j].node, s->joints[l->remap[j]].node);
			first = 0;
		}
		put(&scene, "},\"skins\":[");
		for (int sk = 0; sk < skins; sk++)
			put(&scene, sk ? ",%d" : "%d", skin_index[k * skins + sk]);
		put(&scene, "],\"joint_error\":{\"max\":%.9g,\"mean\":%.9g}", rec->joint.max, rec->joint.mean);
		if (rec->vertex.scale > 0.0)
			put(&scene, ",\"vertex_error_percent\":{\"max\":%.9g,\"mean\":%.9g}", rec->vertex.max,
			    rec->vertex.mean);
		put(&scene, "}");
	}
	put(&scene, "]}");
	for (int sk = 0; sk < skins; sk++) {
		put(&skin_text[sk], "{\"skeleton_levels\":[");
		for (int k = 0; k < count; k++)
			put(&skin_text[sk], k ? ",%d" : "%d", skin_index[k * skins + sk]);
		put(&skin_text[sk], "]}");
	}
	if (scene.failed) {
		r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory writing skeleton levels");
		goto done;
	}
	r = mlod_gltf_set_extra(doc, MLOD_GLTF_SCENE, -1, "mlod", scene.s, err);
	for (int sk = 0; r == MLOD_OK && sk < skins; sk++) {
		if (skin_text[sk].failed)
			r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory writing skeleton levels");
		else if (s->skins[sk].gltf_index >= 0)
			r = mlod_gltf_set_extra(doc, MLOD_GLTF_SKIN, s->skins[sk].gltf_index, "mlod", skin_text[sk].s, err);
	}
done:
	for (int sk = 0; skin_text && sk < skins; sk++)
		free(skin_text[sk].s);
	free(skin_text);
	free(scene.s);
	free(skin_index);
	free(mesh_index);
	free(lod_nodes);
	free(coverage);
	return r;
}
