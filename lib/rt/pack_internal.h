/*
 * pack_internal.h: what the runtime (lib/rt) uses of the pack reader
 * beyond mlod_pack.h.
 */
#ifndef MLOD_PACK_INTERNAL_H
#define MLOD_PACK_INTERNAL_H

#include "mlod_pack.h"

/* Called by mlod_pack_decode_mesh_reserve once the level's part records
 * are read and checked (after the coarser levels' blocks are decoded into
 * the reader's scratch), before the decoded level's one block is
 * allocated: the records (vertex and index counts, flags, UV sets, target
 * counts) give the decoded level's arrays exactly. A result other than
 * MLOD_OK stops the decode with that result, before that allocation. */
typedef mlod_result (*mlod_pack_reserve_fn)(void *user, const mlod_pack_part_rec *parts, uint32_t part_count,
                                            mlod_error *err);

/* mlod_pack_decode_mesh (fetch NULL: the chunks from data, size) or
 * mlod_pack_decode_mesh_fetch (fetch not NULL), calling reserve (may be
 * NULL) as above; Draco-coded levels too. */
mlod_result mlod_pack_decode_mesh_reserve(const mlod_pack *p, uint32_t chunk, const void *data, size_t size,
                                          mlod_pack_fetch_fn fetch, void *fetch_user, mlod_pack_reserve_fn reserve,
                                          void *reserve_user, const mlod_pack_skeleton *skel, mlod_pack_mesh *out,
                                          mlod_error *err);

/* INFO's counts against what the chunks hold (MLOD_ERR_PARSE naming
 * INFO): its joint and skin counts against SKELETON's, its instance count
 * against a decoded MESH level's parts (every level has the same parts).
 * mlod_pack_check runs them; the runtime's open too. */
mlod_result mlod_pack_info_check_skeleton(const mlod_pack_info *info, const mlod_pack_skeleton *skel,
                                          mlod_error *err);
mlod_result mlod_pack_info_check_mesh(const mlod_pack_info *info, const mlod_pack_mesh *mesh, unsigned level,
                                      mlod_error *err);

/* The bytes allocated for a decoded level's block (mlod_pack_motion.block
 * and the others: one allocation each), 0 for NULL. */
size_t mlod_pack_block_size(const void *block);

#endif
