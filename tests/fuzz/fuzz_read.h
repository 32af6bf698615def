/*
 * fuzz_read.h: what the fuzz targets of the bake side's input (fuzz_io.c,
 * fuzz_record.c) do with a loaded document: read back every record a later
 * stage reads, with the stage's own calls, and free it all.
 *
 *   mlod-skelgraph, mlod-pack   mlod_record_read_joints (joint nodes)
 *   mlod-bgm, mlod-pack         mlod_record_read (scene and skins)
 *   mlod-pack                   mlod_record_read_mesh_node (every node),
 *                               mlod_record_read_motion and _motion0 (every
 *                               animation)
 *   mlod-motion                 mlod_gltf_weight_tracks (every animation)
 *   mlod-bgm (lodgltf.c)        mlod_gltf_get_node_trs (every node)
 */
#ifndef MLOD_FUZZ_READ_H
#define MLOD_FUZZ_READ_H

#include <stdlib.h>

#include "io/mlod_io.h"
#include "record/mlod_record.h"
#include "skeleton/mlod_skeleton.h"

static void read_records(const mlod_gltf *doc, const mlod_character *c)
{
	mlod_error e;
	mlod_joint_info *info = calloc((size_t)c->skeleton.joint_count + 1, sizeof *info);
	if (info) {
		int found = 0;
		mlod_record_read_joints(doc, c, info, &found, &e);
		free(info);
	}
	mlod_record rec;
	if (mlod_record_read(doc, &rec, &e) == MLOD_OK) {
		for (int k = 0; k < rec.skel_level_count; k++) {
			mlod_mesh_skeleton ms;
			mlod_record_mesh_skeleton(&rec.skel_levels[k], &ms);
		}
		mlod_record_free(&rec);
	}
	int nodes = mlod_gltf_count(doc, MLOD_GLTF_NODE);
	for (int n = 0; n < nodes; n++) {
		mlod_record_mesh_node mn;
		int found = 0;
		mlod_record_read_mesh_node(doc, n, &mn, &found, &e);
		mlod_trs trs;
		mlod_gltf_get_node_trs(doc, n, &trs, &e);
	}
	int anims = mlod_gltf_count(doc, MLOD_GLTF_ANIMATION);
	for (int a = 0; a < anims; a++) {
		mlod_record_motion_level ml;
		int found = 0;
		mlod_record_read_motion(doc, a, &ml, &found, &e);
		double pack_error = 0.0;
		mlod_record_read_motion0(doc, a, &pack_error, &found, &e);
		mlod_weight_track *tracks = NULL;
		int count = 0;
		if (mlod_gltf_weight_tracks(doc, a, &tracks, &count, &e) == MLOD_OK)
			mlod_weight_tracks_free(tracks, count);
	}
}

#endif
