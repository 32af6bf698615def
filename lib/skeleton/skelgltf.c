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
 *   MSFT_screencoverage from the measured errors (unless the caller keeps
 *   an MSFT_lod of mesh levels: then they stay detached, listed by the
 *   stage record's skins only);
 * - the caller gets each level's skins, for the stage record
 *   (lib/record: extras.mlod of the scene and of each skin).
 * Played with the original animations, a level node deforms exactly like
 * the level: folding keeps every kept joint's world transform.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "skeleton/mlod_skeleton.h"

/* The error that decides when a level may be shown, in percent of the
 * skeleton height (mlod_skeleton_height). */
static double level_error(const mlod_skel_level_record *r)
{
	if (r->vertex.scale > 0.0)
		return r->vertex.max;
	return r->height > 0.0 ? 100.0 * r->joint.max / r->height : 0.0;
}

mlod_result mlod_gltf_add_skel_levels(mlod_gltf *doc, const mlod_character *full,
                                      const mlod_skel_level_record *levels, int count, int *skins_out, int lod,
                                      mlod_error *err)
{
	const mlod_skeleton *s = &full->skeleton;
	int skins = s->skin_count, meshes = full->mesh_count;
	mlod_result r = MLOD_OK;
	int *skin_index = malloc(sizeof(int) * ((size_t)skins * (size_t)count + 1));
	int *mesh_index = malloc(sizeof(int) * ((size_t)meshes * (size_t)count + 1));
	int *lod_nodes = malloc(sizeof(int) * ((size_t)count + 1));
	float *coverage = malloc(sizeof(float) * ((size_t)count + 2));
	double *errors = malloc(sizeof(double) * ((size_t)count + 1));
	if (!errors || !skin_index || !mesh_index || !lod_nodes || !coverage) {
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
		/* level 1's mesh (none without levels: mesh_index holds nothing) */
		if (count <= 0 || in->skin < 0 || in->node < 0 || mesh_index[in->mesh] < 0)
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
			errors[k] = level_error(&levels[k]);
		mlod_lod_coverage(errors, count, coverage);
		if (lod && count > 0 && (r = mlod_gltf_set_lod(doc, in->node, lod_nodes, count, coverage, err)) != MLOD_OK)
			goto done;
	}

	if (skins_out)
		memcpy(skins_out, skin_index, sizeof(int) * (size_t)skins * (size_t)count);
done:
	free(errors);
	free(skin_index);
	free(mesh_index);
	free(lod_nodes);
	free(coverage);
	return r;
}
