/* meshlevels.h: what meshlevels.c, meshnote.c, influence.c and lodgltf.c
 * share (internal to lib/mesh). */
#ifndef MLOD_MESH_LEVELS_H
#define MLOD_MESH_LEVELS_H

#include "mesh/mlod_mesh.h"

/* Appends a note to L->notes (meshnote.c). */
void mlod_mesh_note_(mlod_mesh_levels *L, const char *text);

/* Does instance i get levels (a node, and a primitive with a BGM)? */
int mlod_mesh_has_levels_(const mlod_mesh_levels *L, int i);

/* Instance i's primitive p's BGM (NULL when it has none): for tests
 * that read a part's whole collapse sequence. */
mlod_bgm *mlod_mesh_part_bgm_(const mlod_mesh_levels *L, int i, int p);
/* Influence pruning (influence.c) of levels [first, L->count), each
 * measured before, and measured again after when anything changed
 * (mlod_bgm_options.influence_budget, resolved: > 0 on). */
mlod_result mlod_mesh_prune_influences_(mlod_mesh_levels *L, int first, mlod_error *err);

#endif
