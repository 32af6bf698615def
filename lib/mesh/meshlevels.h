/* meshlevels.h: what meshlevels.c shares with lodgltf.c (internal to lib/mesh). */
#ifndef MLOD_MESH_LEVELS_H
#define MLOD_MESH_LEVELS_H

#include "mesh/mlod_mesh.h"

/* Appends a note to L->notes. */
void mlod_mesh_note_(mlod_mesh_levels *L, const char *text);

/* Does instance i get levels (a node, and a primitive with a BGM)? */
int mlod_mesh_has_levels_(const mlod_mesh_levels *L, int i);

#endif
