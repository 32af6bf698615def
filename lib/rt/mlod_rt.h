/*
 * mlod_rt.h: the mlod runtime. Streams a .mlod pack (mlod(5)), picks
 * skeleton, mesh and motion levels per character by distance, samples the
 * motion, builds the pose and the skinning palette and linear-blend-skins
 * the mesh level into the caller's buffers. C11; depends only on the core
 * (mlod_core.h), the pack reader (mlod_pack.h), meshoptimizer's decoder and
 * libzstd's (the pack's entropy stage, mlod(5)).
 * It never prints or exits. See mlod_rt(3) and the pages it names.
 *
 * ------------------------------------------------------------------
 * Objects and ownership
 *
 *   mlod_rt_ctx      one opened character (a pack, or decoded views the
 *                    caller built): its levels, the resident-level cache
 *                    and a pool of instances. Created by mlod_rt_open_*,
 *                    released by mlod_rt_close (which releases everything
 *                    the context allocated, including its instances).
 *   instance         one character in the world, an id (uint32_t) from the
 *                    context's pool (sized at open: config.max_instances).
 *   mlod_rt_scratch  per-thread working memory for evaluation (local
 *                    transforms, world matrices, palette), sized at
 *                    creation for the context; released by
 *                    mlod_rt_scratch_destroy before mlod_rt_close.
 *
 * Pointers the runtime returns (world matrices, palettes, state) point into
 * the context or the scratch and stay valid until the next call that
 * writes there (the next mlod_rt_pose on that scratch, the next update).
 *
 * Allocation. Every allocation of the runtime goes through the
 * configuration's allocator (malloc/free when NULL), the pack reader's too
 * (the TOC, the decoded chunks and their decoding scratch: the runtime
 * hands it the allocator, mlod_pack_open_alloc). The exceptions are the
 * C library's FILE that mlod_rt_open_path opens with fopen, and Draco's
 * decoder: a Draco-coded mesh level (mlod-pack --codec draco) is decoded
 * by Draco's C++ code, which allocates with operator new (RobotExpressive:
 * 2,808 allocations, 1.08 MB in all, at open; 3,596, 4.49 MB, loading two
 * levels) and frees all of it before the call returns; the decoded level
 * is then copied into memory from the allocator. Memory is
 * allocated only by mlod_rt_open_*, mlod_rt_scratch_create and
 * mlod_rt_stream when it loads or tries to load a level (a level whose
 * reads keep failing is tried, and allocates, in every call that wants
 * it). mlod_rt_update, mlod_rt_request,
 * mlod_rt_pose, mlod_rt_palette, mlod_rt_skin, mlod_rt_skin_stale,
 * mlod_rt_bounds, the names and hierarchy calls, instance creation and
 * destruction (from the pool) allocate nothing.
 *
 * Threading. A context is not locked. Decoding happens only inside
 * mlod_rt_stream, on the caller's thread; nothing runs in the background.
 * mlod_rt_pose, mlod_rt_palette, mlod_rt_skin, mlod_rt_skin_stale and mlod_rt_bounds only read the context, so
 * several threads may evaluate different instances at once, each with its
 * own scratch, as long as no thread calls mlod_rt_update, mlod_rt_stream,
 * mlod_rt_request or creates, destroys or changes an instance meanwhile.
 *
 * Errors. Fallible calls return an mlod_result and fill *err (when not
 * NULL) with the code and a message (mlod_core.h). A corrupt chunk met by
 * mlod_rt_stream fails the levels that read it, and only those: its own
 * level and every level that needs it. With layout b2 (mlod(5)) a mesh
 * level reads the chunks of every coarser mesh level, so a corrupt mesh
 * chunk of level k fails mesh levels 0 .. k (those not resident: a
 * resident level decoded before stays usable); a nested motion level
 * reads the clip's coarser levels it builds on. (A level whose load fails for
 * another reason fails alone.) A failed level is marked failed
 * (mlod_rt_level_info.failed, each failed load counted in
 * mlod_rt_stats.failures) and never tried again, but for one that failed
 * for lack of memory (MLOD_ERR_NOMEM) or a read error (MLOD_ERR_IO): the
 * next mlod_rt_stream tries that one again when it is still wanted. For a
 * read source (mlod_rt_open_read, mlod_rt_open_path), bytes that fail
 * their chunk's CRC are read a second time; when they fail again though
 * that chunk matched its CRC when read before (the coarsest levels' at
 * open, any level's once loaded), the read is blamed: MLOD_ERR_IO, naming
 * the chunk, and tried again (a glitch, or a file rewritten under the
 * context), so that one bad read does not fail levels for good. An
 * instance wanting a failed level shows the finest resident
 * level coarser than it (Fallback below) and its want passes to the
 * finest coarser level not failed, which then loads (in the same
 * mlod_rt_stream call when it fails there) and is shown. The coarsest
 * level of each layer is decoded at open (a corrupt one fails the open),
 * stays resident and never fails, so there always is such a level.
 *
 * ------------------------------------------------------------------
 * Levels
 *
 * Three layers (mlod_rt_layer): skeleton, mesh, motion. Level 0 is the
 * finest; larger is coarser; the coarsest is count - 1. Motion levels are
 * per clip (one chunk per clip and level). Each level has the pack TOC's
 * measured error (scene units) and switch distance (mlod(5)). Skeleton
 * level 0 is the full skeleton (the SKELETON chunk).
 *
 * Static props. A pack of a static prop (no skin, no animation: any
 * glTF without them) has a skeleton of no joints. It opens like any
 * other: mlod_rt_joint_count and mlod_rt_palette_size are 0, mlod_rt_pose
 * poses no joint, mlod_rt_palette gives 0 matrices, mlod_rt_skin writes
 * its (static) parts by their offsets, and selection and streaming work on
 * its mesh levels as on any character's.
 *
 * Resident-level cache. Open decodes INFO, SKELETON and the coarsest level
 * of each layer (of each clip for motion); these stay resident until close.
 * Every other level is loaded when some instance wants it (or
 * mlod_rt_request asks for it) and decoded only inside
 * mlod_rt_stream(ctx, byte_budget). Resident bytes (the decoded levels plus
 * the runtime's per-level tables, counted from their arrays; a motion
 * level's as the block its reader allocated, sized exactly from its
 * channel records; the pack's zstd
 * decoder, the staging buffer and tables per chunk for a read source)
 * never exceed
 * the budget, not even while a level decodes: before a level's decoded
 * arrays are allocated, stream makes room for them: for a pack's level
 * its exact size (the reader reads the level's part, channel or
 * kept-joint and palette records first, and the room is what those
 * records decode to plus the runtime's tables; records claiming more
 * than the level's streams hold, or joints and bind matrices it lacks,
 * size nothing and fail the level, MLOD_ERR_PARSE; remembered, so a level that does not fit is not
 * decoded again until room appears); for views their size. The budget an
 * open needs: mlod_rt_open_memory_bytes and
 * mlod_rt_stats.open_bytes. Room is made by evicting resident levels that
 * no instance wanted in the current frame (below), least recently wanted
 * first; it
 * never evicts a level wanted in the current frame nor a coarsest level.
 * A level that cannot fit stays unloaded and is tried again when room
 * appears; meanwhile its wants pass to the finest coarser level of its
 * layer that neither failed nor cannot fit, which loads when absent (an
 * instance close by under a budget too small for mesh level 0 shows the
 * finest level the budget holds, not the coarsest) and, resident, is kept
 * from eviction. (The reader's own scratch while one chunk decodes, a
 * nested motion level's coarser levels decoded and freed inside its load,
 * and the instance pool, are not counted: the memory the allocator holds
 * between calls is the resident bytes plus what it held at open beyond
 * them, to a few hundred bytes either way, not exactly: a pack's mesh
 * level's block holds a 32-byte head and its arrays' 8-byte alignment
 * beyond its count (net 8 to 92 bytes a level on tubeman and
 * RobotExpressive; 272 for RobotExpressive's four finer levels), and a
 * level's count includes its descriptor, which the context holds from
 * open (32 bytes a motion level: RobotExpressive streaming its 14 clips
 * under a budget held up to 584 bytes less than it counted), measured
 * with counting allocator hooks, bench/RESULTS.md Runs 104 and 107;
 * tests/rt/test_rt_engine.c checks a crowd's frames hold at most 256
 * bytes beyond the count.)
 *
 * Frames. The wanted levels of a frame are those of every mlod_rt_update,
 * mlod_rt_update_positions and mlod_rt_request call since the last
 * mlod_rt_stream (or open): the first such call after a stream clears the
 * last frame's, the later ones add to them, so a frame may update its
 * instances in several batches (an instance in two batches counts
 * twice). mlod_rt_stream loads for them and keeps them until the next
 * frame starts.
 *
 * Fallback. An instance shows, per layer, the wanted level when resident,
 * else the finest resident level coarser than the wanted one (the coarsest
 * is always resident, so there always is one), and flags the layer in
 * mlod_rt_state.fallback. Why is the wanted level's mlod_rt_level_info
 * (the motion layer's for the instance's clip): failed (its load failed),
 * no_room (the last mlod_rt_stream found no room for it within the
 * budget), else it waits for an mlod_rt_stream with byte budget left.
 *
 * ------------------------------------------------------------------
 * Selection (mlod_rt_select)
 *
 * Every mode reduces to switch distances D_1 < ... per layer (D_0 = 0): the
 * level wanted at distance d without hysteresis is the largest l with
 * D_l <= d (the coarsest level fine enough).
 *
 * MLOD_RT_SELECT_ALPHA (the paper's): alpha = (d - d_near) / (d_far -
 * d_near) clamped to [0, 1]; per layer with L levels and interval
 * [t_s, t_e]: u = (alpha - t_s) / (t_e - t_s) clamped to [0, 1] (when
 * t_e <= t_s, u = 0 for alpha < t_s and 1 otherwise), and
 *     level = floor(u * (L - 1) + 0.5)     (rounded), clamped to [0, L - 1].
 * Hence D_l = d_near + (t_s + (l - 0.5) / (L - 1) * (t_e - t_s)) *
 * (d_far - d_near).
 *
 * MLOD_RT_SELECT_PIXELS: the coarsest level whose error e projects to at
 * most max_pixels pixels: e * lines / (2 d tan(fov_y / 2)) <= max_pixels,
 * so D_l = e_l * lines / (2 tan(fov_y / 2) * max_pixels). Motion levels
 * use their own clip's errors.
 *
 * MLOD_RT_SELECT_TOC: D_l is the TOC's switch distance (the pixel rule at
 * MLOD_PACK_FOV_Y, MLOD_PACK_LINES, MLOD_PACK_PIXELS, as baked).
 *
 * Any mode may be scaled: D_l is multiplied by distance_scale (1 when
 * <= 0). D_l values need not increase with l; the rule stays "the largest
 * l with D_l <= d".
 *
 * Hysteresis h >= 0 (relative). With c the level wanted at the last update:
 * switching finer happens at the threshold (go to the raw level l < c when
 * d < D_c); switching coarser needs the distance to pass the threshold
 * times (1 + h): the new level is the largest l > c with D_l * (1 + h) <=
 * d, or stays c. Inside [D_l, D_l (1 + h)) the level does not change,
 * whichever way the camera moves, so a character sitting at a switch
 * distance does not flicker.
 *
 * ------------------------------------------------------------------
 * Evaluation
 *
 * Sampling follows the bake side's mlod_clip_sample (lib/model/pose.c)
 * exactly: time clamped to [0, duration] (after wrapping into it when the
 * instance loops); outside the keys, or with one key, the end key's value;
 * STEP holds the key; LINEAR lerps translation and scale and slerps
 * rotation (mlod_quat_slerp: shortest arc); CUBICSPLINE is glTF's Hermite
 * with tangents scaled by the key interval; rotations are normalised after
 * sampling. Joints without a channel keep their rest TRS. The one
 * departure: slerp's weights come from one sine and one cosine instead of
 * three sines, which in double moves them by about 1e-13 of themselves, or,
 * for keys within 26 degrees, from power series in the squared angle (no
 * acos, sin or cos; at most 3e-14 of themselves), and a normalisation
 * multiplies by 1 / length instead of dividing by it (an ulp of a double),
 * all far below a float's resolution (the committed samples' poses are the
 * same floats). The levels the runtime decodes from a pack have their
 * rotation keys normalised once when they load (when that gives the same
 * samples), so that sampling need not normalise them every frame; views
 * are never changed. A motion level's load also lists the channels of
 * its animated joints (a channel of several keys) and makes the local
 * matrix of each joint whose channels all have one key (counted in its
 * resident bytes: mlod_rt_eval(3)), so a pose samples only the animated
 * joints' channels and any other joint costs one matrix product.
 *
 * Skeleton levels, folded at run time: a kept joint c whose parent chain
 * j1 (its parent) ... jk was removed gets the local transform
 * L'_c = L_jk ... L_j1 L_c relative to its nearest kept ancestor. The
 * runtime samples those removed ancestors' channels too and composes the
 * product on the way down from the kept ancestor (shared between kept
 * siblings), so every kept joint's world matrix equals the full skeleton's.
 * Removed joints with no kept descendant are neither sampled nor posed:
 * that is the skeleton level's saving. Roots get their base matrix:
 * W_root = base * L_root.
 *
 * Palette (per skin joint, all skins in order, as the pack's 'SKJT'):
 * level 0: W[skin joint] * IBM; level k: W[j] * B, with j the skin
 * joint's stand-in at that level (itself when kept) and B the bind matrix
 * the level gives it (the pack's palette references, mlod(5) SKELETON
 * levels: an inverse bind of 'IBMS' or one of its own). An entry with the
 * same joint and the same bind floats as an earlier one (skins sharing
 * joints; removed joints whose stand-in takes their weights) is copied
 * from it instead of multiplied again: the same floats.
 *
 * Skinning writes every part of the instance's mesh level, in part order,
 * vertices concatenated: skinned parts by linear blend skinning of 4
 * influences (positions by the blended matrix, normals by its 3x3 part,
 * renormalised); rigid parts (joint >= 0) by W[joint] * offset, or for a
 * joint the skeleton level removed, W[stand-in] * R * offset with R the
 * rest transform from the stand-in (nearest kept ancestor) to the joint, as
 * the bake side's fold does; static parts by offset. Before that, a part
 * with morph targets gets the instance's weights for it
 * (mlod_rt_instance_set_morph_weights; 0 by default): position = position
 * + sum of weight[t] * delta[t]. Normals are not morphed (the pack keeps
 * position deltas only).
 */
#ifndef MLOD_RT_H
#define MLOD_RT_H

#include <stddef.h>
#include <stdint.h>

#include "mlod_core.h"
#include "mlod_pack.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct mlod_rt_ctx mlod_rt_ctx;
typedef struct mlod_rt_scratch mlod_rt_scratch;

/* The runtime's layers, from 0. Not the pack's MLOD_LAYER_* of a TOC entry
 * (mlod_pack.h), which count from 1 (MLOD_LAYER_MESH is 2, MLOD_RT_MESH 1):
 * a caller reading the TOC with mlod_pack(3) compares with those. */
typedef enum mlod_rt_layer {
	MLOD_RT_SKELETON = 0,
	MLOD_RT_MESH = 1,
	MLOD_RT_MOTION = 2,
	MLOD_RT_LAYERS = 3
} mlod_rt_layer;

/* ------------------------------------------------------------------ */
/* Opening (mlod_rt_open(3))                                           */
/* ------------------------------------------------------------------ */

/* User allocator: malloc(user, size) returns NULL on failure; free(user,
 * NULL) must be harmless. Both or neither (one alone: MLOD_ERR_INVALID_ARG
 * from every open). */
typedef struct mlod_rt_allocator {
	void *(*malloc)(void *user, size_t size);
	void (*free)(void *user, void *p);
	void *user;
} mlod_rt_allocator; /* the same callbacks as mlod_pack_alloc */

typedef struct mlod_rt_config {
	size_t budget_bytes;      /* resident bytes allowed; 0: no limit */
	uint32_t max_instances;   /* the instance pool's size (0: 1024) */
	const mlod_rt_allocator *allocator; /* NULL: malloc and free; copied */
} mlod_rt_config;

/* Reads size bytes at offset of the pack into dst; returns 0 on success,
 * anything else for an error. Called only inside mlod_rt_open_read and
 * mlod_rt_stream, on the caller's thread. */
typedef int (*mlod_rt_read_fn)(void *user, uint64_t offset, size_t size, void *dst);

/* Opens a pack held in memory. The memory is borrowed: it must stay valid
 * and unchanged until mlod_rt_close. config may be NULL (defaults).
 * Errors: MLOD_ERR_INVALID_ARG, MLOD_ERR_PARSE / MLOD_ERR_UNSUPPORTED from
 * the reader (malformed or newer pack, a corrupt coarse chunk),
 * MLOD_ERR_LIMIT when the coarse levels alone exceed the budget (the
 * budget they need: mlod_rt_open_memory_bytes, below), MLOD_ERR_NOMEM. */
mlod_result mlod_rt_open_memory(const void *data, size_t size, const mlod_rt_config *config, mlod_rt_ctx **out,
                                mlod_error *err);
/* Opens a pack file; the file stays open until mlod_rt_close and is read
 * only by open and mlod_rt_stream. Adds MLOD_ERR_IO. */
mlod_result mlod_rt_open_path(const char *path, const mlod_rt_config *config, mlod_rt_ctx **out, mlod_error *err);
/* Opens a pack of file_size bytes read through read(user, ...). user must
 * stay valid until mlod_rt_close. Adds MLOD_ERR_IO when read fails. */
mlod_result mlod_rt_open_read(mlod_rt_read_fn read, void *user, uint64_t file_size, const mlod_rt_config *config,
                              mlod_rt_ctx **out, mlod_error *err);

/* The budget an open needs: *bytes is the least budget_bytes with which
 * the same open (the same source kind: a _path or _read open also holds
 * the staging buffer, memory does not) succeeds, the resident bytes it
 * pins (INFO, SKELETON, the coarsest level of each layer and clip, their
 * tables, the zstd decoder); mlod_rt_stats.open_bytes of the context
 * that open makes. Costs an open: it opens the pack with no budget
 * through config's allocator (config's budget_bytes is ignored; NULL:
 * defaults) and closes it, so *bytes is exact, not a bound from the TOC
 * (whose sizes are claims until the chunks decode). A caller adds the
 * room it wants for finer levels (mlod_rt_level_info.bytes once loaded).
 * Errors: the open's, never MLOD_ERR_LIMIT for the budget; *bytes is 0
 * on failure. */
mlod_result mlod_rt_open_memory_bytes(const void *data, size_t size, const mlod_rt_config *config, size_t *bytes,
                                      mlod_error *err);
mlod_result mlod_rt_open_path_bytes(const char *path, const mlod_rt_config *config, size_t *bytes, mlod_error *err);
mlod_result mlod_rt_open_read_bytes(mlod_rt_read_fn read, void *user, uint64_t file_size,
                                    const mlod_rt_config *config, size_t *bytes, mlod_error *err);

/* Decoded views built by the caller (tests, or a host that decodes
 * itself). Everything is borrowed and must outlive the context. The levels
 * still go through the cache: only the coarsest of each layer is resident
 * after open; the others "load" in mlod_rt_stream (no decoding), costing
 * bytes (given, or counted from the arrays when 0). The runtime checks
 * every index in them when it loads a level (MLOD_ERR_PARSE). */
typedef struct mlod_rt_view_level {
	const void *data;  /* mlod_pack_skel_level, mlod_pack_mesh or mlod_pack_motion */
	float error;       /* scene units */
	float distance;    /* switch distance (MLOD_RT_SELECT_TOC) */
	size_t bytes;      /* decoded size to count; 0: counted from the arrays */
} mlod_rt_view_level;

typedef struct mlod_rt_views {
	const mlod_pack_skeleton *skeleton;  /* required */
	uint32_t skel_levels;                /* counting level 0 (>= 1) */
	const mlod_rt_view_level *skel;      /* skel_levels; [0].data is ignored (the full skeleton) */
	uint32_t mesh_levels;                /* 0: no mesh */
	const mlod_rt_view_level *mesh;
	uint32_t clip_count, motion_levels;  /* 0: no motion */
	const mlod_rt_view_level *motion;    /* clip_count * motion_levels, [clip * motion_levels + level] */
} mlod_rt_views;

mlod_result mlod_rt_open_views(const mlod_rt_views *views, const mlod_rt_config *config, mlod_rt_ctx **out,
                               mlod_error *err);

/* Releases the context, its instances, its resident levels and, for
 * mlod_rt_open_path, closes the file. NULL is harmless. */
void mlod_rt_close(mlod_rt_ctx *ctx);

/* ------------------------------------------------------------------ */
/* Levels and streaming (mlod_rt_stream(3))                            */
/* ------------------------------------------------------------------ */

typedef struct mlod_rt_level_info {
	float error;          /* scene units */
	float distance;       /* the TOC's switch distance */
	uint32_t stored_size; /* bytes in the pack (0 for views) */
	size_t bytes;         /* resident bytes, 0 when not resident; 0 for skeleton level 0,
	                         the context's own skeleton (mlod_rt_open(3)) */
	int resident;         /* 1 when resident */
	int failed;           /* 1 when loading it failed (NOMEM, IO: until the next
	                         mlod_rt_stream tries it again) */
	uint32_t users;       /* instances showing it at the last update */
	int no_room;          /* 1 when the last mlod_rt_stream wanted it but found no
	                         room for it within budget_bytes, even after evicting
	                         every level the frame does not want (the room a
	                         level decodes to, exactly): it stays
	                         unloaded and its wants passed to a coarser level
	                         (Resident-level cache, above); 0 once that call
	                         loaded it or did not reach it */
} mlod_rt_level_info;

/* budget_bytes: the configured budget, 0 for no limit (configured 0).
 * open_bytes: the resident bytes open pinned (the coarsest levels and the
 * rest open holds resident until close): the least budget_bytes that
 * opens this pack from this kind of source (mlod_rt_open_memory_bytes);
 * budget_bytes - open_bytes is the room finer levels stream into. */
typedef struct mlod_rt_stats {
	size_t resident_bytes, budget_bytes, peak_resident_bytes;
	uint32_t resident_levels, pending_levels; /* pending: wanted, not resident, not failed */
	uint64_t loads, evictions, failures; /* failures: failed loads */
	size_t open_bytes;                   /* last: the members before keep their offsets */
} mlod_rt_stats;

/* Levels of a layer, counting level 0 (motion: per clip). */
uint32_t mlod_rt_level_count(const mlod_rt_ctx *ctx, mlod_rt_layer layer);
uint32_t mlod_rt_clip_count(const mlod_rt_ctx *ctx);
uint32_t mlod_rt_joint_count(const mlod_rt_ctx *ctx);
/* Palette entries: the skin joints of every skin. */
uint32_t mlod_rt_palette_size(const mlod_rt_ctx *ctx);
/* The clip's duration in seconds (its coarsest level's). */
float mlod_rt_clip_duration(const mlod_rt_ctx *ctx, uint32_t clip);
/* item is the clip for the motion layer, else ignored. MLOD_ERR_INVALID_ARG
 * out of range. */
mlod_result mlod_rt_level_info_get(const mlod_rt_ctx *ctx, mlod_rt_layer layer, uint32_t level, uint32_t item,
                                   mlod_rt_level_info *out, mlod_error *err);
/* Vertices the mesh level writes (all parts) when resident, else 0; and
 * the largest count of any mesh level: the vertices the caller's skinning
 * buffers need for every level, known from open on, before any streaming,
 * for a pack of format 8.1 or later (INFO's max_vertex_count, mlod(5))
 * and for views (their largest level). Open refuses a pack whose value
 * is more than its MESH chunks can hold (a level's vertices are among its
 * indices, 2 raw bytes each at least, and among the 'POSQ' elements of it
 * and the coarser levels, 8 raw bytes each: at most half its chunk's TOC
 * raw size and an eighth of the raw sizes of it and the coarser MESH
 * chunks, so that positions and normals (24 bytes a vertex) sized from
 * it take at most 3 times the MESH chunks' raw bytes; a Draco level at
 * most 1024 / 12 vertices per byte of its container), and a level of more
 * vertices than it fails its load (MLOD_ERR_PARSE naming the level,
 * before it is allocated), so mlod_rt_skin never wants more. The raw
 * sizes are the TOC's claims, checked only as each chunk decodes (a zstd
 * frame has no fixed expansion limit): a hostile pack can claim raw sizes
 * it does not hold and a count up to 2^31 - 1 with them (its levels then
 * fail their loads), so a caller that opens untrusted packs caps the
 * buffers it sizes from this at a limit of its own. For an older pack
 * (format 8.0 and before, which leave it 0) it is the largest count of
 * any mesh level resident so far, and grows as finer levels load. */
uint32_t mlod_rt_mesh_vertex_count(const mlod_rt_ctx *ctx, uint32_t level);
uint32_t mlod_rt_max_vertex_count(const mlod_rt_ctx *ctx);
/* All 0 for a NULL ctx; nothing for a NULL out. */
void mlod_rt_stats_get(const mlod_rt_ctx *ctx, mlod_rt_stats *out);

/* A part of a resident mesh level, for drawing what mlod_rt_skin wrote:
 * its vertices are first_vertex .. first_vertex + vertex_count - 1 of the
 * skinned output, its triangles index_count indices local to the part
 * (add first_vertex), pointing into the resident level: valid until that
 * level is evicted (mlod_rt_stream) or the context closes. A part that
 * quantisation left without a triangle at a level has vertex_count and
 * index_count 0 there (mlod(5) MESH levels): nothing to draw. */
typedef struct mlod_rt_part_info {
	uint32_t first_vertex, vertex_count;
	uint32_t index_count;
	const uint32_t *indices;
	int32_t material;     /* the input's glTF material, or -1 */
	int32_t skin, joint;  /* skinned, rigid (joint >= 0) or static */
	uint32_t instance;    /* the character's mesh instance the part belongs to */
	int32_t node;         /* its glTF node, or -1 */
	uint32_t target_count; /* morph targets (mlod_rt_morph_target_count) */
	/* The level's decoded arrays of this part, in the bind pose, valid
	 * while the level stays resident: positions, normals, tangents, UV
	 * sets, colours, joints (its skin's joints: palette entry
	 * palette_first + joint) and weights (mlod_pack.h), so that a caller
	 * draws it (UVs, tangents, colours) or skins it on the GPU with
	 * mlod_rt_palette's matrices without decoding the chunk again. */
	const mlod_pack_part *attributes;
	uint32_t palette_first; /* a skinned part: the palette entry of its skin's joint 0 */
} mlod_rt_part_info;

/* Parts of a mesh level when resident, else 0. */
uint32_t mlod_rt_mesh_part_count(const mlod_rt_ctx *ctx, uint32_t level);
/* MLOD_ERR_INVALID_ARG for a level not resident or a part out of range. */
mlod_result mlod_rt_mesh_part(const mlod_rt_ctx *ctx, uint32_t level, uint32_t part, mlod_rt_part_info *out,
                              mlod_error *err);

/* Asks for a level as if an instance wanted it in the current frame
 * (Frames, above). No decoding here. */
mlod_result mlod_rt_request(mlod_rt_ctx *ctx, mlod_rt_layer layer, uint32_t level, uint32_t item, mlod_error *err);

/* Loads wanted levels, decoding on the caller's thread, most wanted first
 * (ties: coarser first), until the stored bytes of the levels loaded in
 * this call reach byte_budget (each level's own chunk: a mesh level also
 * reads the chunks of every coarser mesh level, and a nested motion level
 * those it builds on, which byte_budget does not count, so the bytes read
 * can be larger; tubeman's mesh level 0 stores 12,339 bytes and reads
 * 50,459; a first level larger than byte_budget is
 * still loaded alone, so that every level can load; 0 loads nothing;
 * views have no stored size and count 1 byte each; a level whose load
 * fails or that does not fit counts nothing),
 * evicting as described above. Then re-resolves the instances (fallback
 * levels change to the better resident ones, and away from evicted ones).
 * *loaded (may be NULL) gets the number of levels loaded. Returns MLOD_OK,
 * or the error of a level that failed to load (the call still went on
 * with the others; the context stays usable). */
mlod_result mlod_rt_stream(mlod_rt_ctx *ctx, size_t byte_budget, uint32_t *loaded, mlod_error *err);

/* ------------------------------------------------------------------ */
/* Names, hierarchy and bounds (mlod_rt_info(3))                       */
/* ------------------------------------------------------------------ */

/* The character as the pack's INFO gives it. Views have no INFO: name
 * "", every number 0. */
typedef struct mlod_rt_character {
	const char *name;          /* valid until mlod_rt_close */
	float bounds_min[3];       /* the rest pose of mesh level 0 (of the skeleton without
	                            * a mesh), scene units */
	float bounds_max[3];
	float height;              /* the skeleton height (mlod(5)) */
	float diagonal;            /* of the bounds */
} mlod_rt_character;

/* MLOD_ERR_INVALID_ARG for a NULL argument. */
mlod_result mlod_rt_character_get(const mlod_rt_ctx *ctx, mlod_rt_character *out, mlod_error *err);

/* A clip's name (INFO 'NAME'), valid until mlod_rt_close; "" for views;
 * NULL for a clip out of range. mlod_rt_clip_find sets *clip to the first
 * clip of that name (byte for byte): MLOD_ERR_INVALID_ARG with a message
 * naming it when there is none. No allocation; both read only what open
 * decoded. */
const char *mlod_rt_clip_name(const mlod_rt_ctx *ctx, uint32_t clip);
mlod_result mlod_rt_clip_find(const mlod_rt_ctx *ctx, const char *name, uint32_t *clip, mlod_error *err);

/* The full skeleton (level 0: the SKELETON chunk, mlod_rt_joint_count
 * joints, parents before children): a joint's name (valid until
 * mlod_rt_close; "" when views give none; NULL out of range), its parent
 * (-1 for a root, and for a joint out of range), and the first joint of a
 * name (MLOD_ERR_INVALID_ARG naming it when none). The world matrices of
 * mlod_rt_pose are indexed by these joints. */
const char *mlod_rt_joint_name(const mlod_rt_ctx *ctx, uint32_t joint);
int32_t mlod_rt_joint_parent(const mlod_rt_ctx *ctx, uint32_t joint);
mlod_result mlod_rt_joint_find(const mlod_rt_ctx *ctx, const char *name, uint32_t *joint, mlod_error *err);

/* A joint at a skeleton level (Skeleton levels, above). kept: the level
 * keeps it; posed: mlod_rt_pose at that level computes its world matrix
 * (kept, or a removed ancestor of a kept joint); stand_in: the joint whose
 * world matrix it follows there (itself when kept, else its nearest kept
 * ancestor; every root is kept); parent: its parent at the level (its
 * nearest kept proper ancestor, -1 for a root); rest_from_stand_in: 16
 * floats, column-major, the rest transform from the stand-in to the joint
 * (the identity when kept), so that W[stand_in] * rest_from_stand_in
 * places something attached to a removed joint as mlod_rt_skin places a
 * rigid part on it. Valid while the level stays resident. Level 0 keeps
 * every joint. MLOD_ERR_INVALID_ARG for a level or joint out of range and
 * a skeleton level >= 1 not resident (its table is built when it
 * loads; the coarsest always is). */
typedef struct mlod_rt_joint_level {
	int kept, posed;
	uint32_t stand_in;
	int32_t parent;
	const float *rest_from_stand_in;
} mlod_rt_joint_level;

mlod_result mlod_rt_joint_level_get(const mlod_rt_ctx *ctx, uint32_t level, uint32_t joint, mlod_rt_joint_level *out,
                                    mlod_error *err);

/* ------------------------------------------------------------------ */
/* Instances and selection (mlod_rt_instance(3))                       */
/* ------------------------------------------------------------------ */

#define MLOD_RT_LOOP 0x1u  /* instance flag: time wraps over the clip's duration */

/* What an instance shows: per layer (mlod_rt_layer) the wanted level and
 * the resident level shown; fallback has bit (1 << layer) set when they
 * differ. */
typedef struct mlod_rt_state {
	uint32_t clip;
	uint32_t flags;           /* MLOD_RT_LOOP */
	float time;               /* seconds: as set plus each update's dt, always finite; a
	                           * looping instance's wrapped into [0, duration) by
	                           * mlod_rt_update, another's saturating at +-FLT_MAX
	                           * (sampling clamps it to [0, duration]) */
	float distance;           /* at the last update */
	float alpha;              /* the paper's alpha at the last update (alpha mode) */
	uint16_t wanted[MLOD_RT_LAYERS];
	uint16_t level[MLOD_RT_LAYERS];
	uint32_t fallback;
	int alive;
} mlod_rt_state;

/* Takes an instance from the pool, showing clip (ignored without clips)
 * from time, at the coarsest levels until the first update.
 * MLOD_ERR_LIMIT when the pool is full, MLOD_ERR_INVALID_ARG for a clip out
 * of range or a time that is not finite. */
mlod_result mlod_rt_instance_create(mlod_rt_ctx *ctx, uint32_t clip, float time, uint32_t flags, uint32_t *id,
                                    mlod_error *err);
/* Returns the instance to the pool; an id not alive is ignored. An id is
 * a handle (the slot's index and its generation), not an index: once its
 * instance is destroyed, it names nothing, even after the pool gives the
 * slot to a new instance, until the slot's generation wraps after
 * 2^(32 - bits) destroys, bits being the fewest (at least 1) that hold
 * max_instances - 1 (2^22 for the default pool of 1024). */
void mlod_rt_instance_destroy(mlod_rt_ctx *ctx, uint32_t id);
/* Shows clip from time on a live instance (the levels stay as they are
 * until the next update); MLOD_ERR_INVALID_ARG, nothing changed, for an id
 * not alive, a clip out of range or a time that is not finite. */
mlod_result mlod_rt_instance_set(mlod_rt_ctx *ctx, uint32_t id, uint32_t clip, float time, uint32_t flags,
                                 mlod_error *err);
/* The instance's state, or NULL for an id not alive. */
const mlod_rt_state *mlod_rt_instance_state(const mlod_rt_ctx *ctx, uint32_t id);

/* Morph targets. A pack's mesh levels have the same parts, in the same
 * order (mlod_rt_mesh_part's index); mlod_rt_morph_target_count gives a
 * part's morph targets as the coarsest level has them (views: the most
 * any level has), 0 for a part out of range. glTF gives one weight vector per mesh: set it on each part of
 * that mesh instance (mlod_rt_part_info.instance or .node).
 * mlod_rt_instance_set_morph_weights sets the instance's weights of one
 * part: count (at most the part's targets) weights, the others 0; they
 * stay until set again or the instance is destroyed (a new instance has
 * all weights 0: no morph). mlod_rt_skin applies them to every mesh level
 * (up to the targets that level's part has). MLOD_ERR_INVALID_ARG for an
 * id not alive, a part out of range (whatever count), too many weights or a
 * weight not finite. No allocation;
 * like mlod_rt_update, not while other threads evaluate the context. */
uint32_t mlod_rt_morph_target_count(const mlod_rt_ctx *ctx, uint32_t part);
mlod_result mlod_rt_instance_set_morph_weights(mlod_rt_ctx *ctx, uint32_t id, uint32_t part, const float *weights,
                                               uint32_t count, mlod_error *err);

typedef enum mlod_rt_select_mode {
	MLOD_RT_SELECT_ALPHA = 0,
	MLOD_RT_SELECT_PIXELS = 1,
	MLOD_RT_SELECT_TOC = 2
} mlod_rt_select_mode;

/* Selection parameters (see "Selection" above). mlod_rt_select_default
 * fills: ALPHA mode, d_near 2, d_far 200 (scene units), every layer's
 * interval [0, 1], fov_y 60 degrees (in radians), 1080 lines, 1 pixel,
 * hysteresis 0.1, distance_scale 1, force_level -1. */
typedef struct mlod_rt_select {
	mlod_rt_select_mode mode;
	float d_near, d_far;
	float t_start[MLOD_RT_LAYERS], t_end[MLOD_RT_LAYERS];
	float fov_y;        /* radians */
	float lines;        /* screen height in pixels */
	float max_pixels;
	float hysteresis;   /* h >= 0 */
	float distance_scale;
	int force_level;    /* >= 0: every layer wants this level (clamped), no selection */
} mlod_rt_select;

void mlod_rt_select_default(mlod_rt_select *sel);

/* One frame for n instances: each instance's time advances by dt, its
 * levels are selected at distances[i] (scene units, >= 0), and wanted
 * levels are recorded for mlod_rt_stream (for a failed level, the finest
 * coarser one not failed: see Errors); shown levels are resolved.
 * Ids not alive are skipped. No allocation. MLOD_ERR_INVALID_ARG for a
 * NULL ctx or sel (there is no default selection: mlod_rt_select_default
 * fills one), or NULL ids or distances with n > 0 (with n 0 they may be
 * NULL: the call then only starts the frame); with a message naming the
 * index i, when distances[i] is NaN, negative or
 * infinite (for every i < n, alive or not), when dt is not finite
 * (dt may be negative: time runs back), and for a selection whose mode is
 * not one of the three, a float member not finite, a negative
 * hysteresis or distance_scale, d_near < 0 or d_near > d_far, fov_y not
 * strictly between 0 and pi, or lines or max_pixels <= 0 (the message
 * names the member); everything is checked first, so such a call changes
 * nothing (no instance, no wanted level). The wants add to those of the
 * frame's earlier calls (Frames). */
mlod_result mlod_rt_update(mlod_rt_ctx *ctx, const mlod_rt_select *sel, const uint32_t *ids,
                           const float *distances, size_t n, float dt, mlod_error *err);
/* The same with the distance from camera[3] to positions[3 * i]
 * (MLOD_ERR_INVALID_ARG naming i when it is not finite). */
mlod_result mlod_rt_update_positions(mlod_rt_ctx *ctx, const mlod_rt_select *sel, const float camera[3],
                                     const uint32_t *ids, const float *positions, size_t n, float dt,
                                     mlod_error *err);
/* The level wanted at distance d by sel, for a layer, with the previous
 * wanted level prev (or -1 for none: no hysteresis), the motion layer for
 * clip item. The rule mlod_rt_update applies. */
uint32_t mlod_rt_select_level(const mlod_rt_ctx *ctx, const mlod_rt_select *sel, mlod_rt_layer layer,
                              uint32_t item, float d, int prev);

/* ------------------------------------------------------------------ */
/* Evaluation (mlod_rt_eval(3))                                        */
/* ------------------------------------------------------------------ */

/* Working memory for one thread (sized for the context). NULL when out of
 * memory. Destroy before closing the context. */
mlod_rt_scratch *mlod_rt_scratch_create(mlod_rt_ctx *ctx);
void mlod_rt_scratch_destroy(mlod_rt_ctx *ctx, mlod_rt_scratch *s);

/* Samples the instance's motion level at its time and poses its skeleton
 * level: *world (may be NULL) points to joint_count column-major 4x4
 * matrices in the scratch, valid at the level's posed joints (the kept
 * joints and their removed ancestors; *joints and *joint_count (may be NULL)
 * list the kept ones). Without clips the rest pose. */
mlod_result mlod_rt_pose(const mlod_rt_ctx *ctx, mlod_rt_scratch *s, uint32_t id, const float **world,
                         const uint32_t **joints, uint32_t *joint_count, mlod_error *err);
/* The skinning palette of the pose last computed in s (mlod_rt_pose):
 * palette_size column-major 4x4 matrices (see "Palette"), for GPU
 * skinning (0 matrices for a static prop). After mlod_rt_skin (which
 * poses only what its mesh level reads, nothing without a mesh) it poses
 * that instance again in full first. */
mlod_result mlod_rt_palette(const mlod_rt_ctx *ctx, mlod_rt_scratch *s, const float **palette, uint32_t *count,
                            mlod_error *err);
/* Poses the instance (as mlod_rt_pose, but only the joints that its mesh
 * level's palette entries and rigid parts follow, with their ancestors:
 * the same floats) and skins its mesh level into the caller's buffers:
 * 3 floats per vertex at positions + i * pos_stride bytes and, when
 * normals is not NULL, at normals + i * nrm_stride (strides >= 12 and
 * multiples of 4); parts without normals get (0, 0, 0). capacity is
 * the vertices the buffers hold: MLOD_ERR_LIMIT when the level needs more
 * (mlod_rt_mesh_vertex_count). *vertex_count (may be NULL) gets the
 * vertices written. MLOD_ERR_INVALID_ARG for an id not alive, also on a
 * pack without a mesh (skeleton and motion only), where a live instance
 * gets MLOD_OK and 0 vertices. */
mlod_result mlod_rt_skin(const mlod_rt_ctx *ctx, mlod_rt_scratch *s, uint32_t id, float *positions,
                         size_t pos_stride, float *normals, size_t nrm_stride, uint32_t capacity,
                         uint32_t *vertex_count, mlod_error *err);

/* A box (min, max: scene units, the space mlod_rt_skin writes in) that
 * holds every vertex mlod_rt_skin would write for the instance now, at
 * its current levels, time and morph weights: for culling before
 * skinning. It poses the instance as mlod_rt_skin does (only the joints
 * its mesh level reads, into s: mlod_rt_palette after it poses in full)
 * and makes the palette entries the level reads. When the mesh level
 * loads, the runtime bounds, per palette entry, the bind-pose positions
 * of the level's vertices weighted to it (weight > 0): their box and a
 * ball about its centre, and their box in the joint's space (through the
 * entry's inverse bind matrix B: a box along the bone); per rigid or
 * static part, the box and ball of its positions. Per entry the box of
 * its points' images is then the intersection of the image of the
 * bind-pose box and ball under the entry's matrix P and of the joint-space
 * box under P B^-1 (the joint's world matrix at skeleton level 0); per
 * rigid or static part, of its box and ball under the matrix mlod_rt_skin
 * gives it. The result is their union: a skinned vertex is a convex
 * combination of its influences' images (weights summing to 1, as a
 * pack's do). Morph weights widen every box and ball by the largest over
 * the parts of sum |weight| x that target's longest delta. Each box is
 * widened by 1e-5 of the magnitudes the kernels sum there, for their
 * rounding. Measured at mesh level 0 (mlod_rt_info(3)): the box's volume
 * is 1.37 times the skinned vertices' box's at the median on tubeman,
 * 1.21 on RobotExpressive, 1.001 on Ely; a call costs 35,700, 44,200 and
 * 17,500 instructions against mlod_rt_skin's 254,400, 180,300 and
 * 298,200. mlod_rt_skin right after it, with the same scratch and
 * instance and nothing changed between (the instance's time, clip and
 * levels, the resident levels), takes its pose and palette entries as
 * they are instead of making them again. Without a mesh, or for a level
 * without vertices, the empty box: min FLT_MAX, max -FLT_MAX. When a
 * bound comes to NaN (a pose or palette that is not finite, which only a
 * hostile pack gives), all of space: min -infinity, max +infinity, which
 * no cull drops. MLOD_ERR_INVALID_ARG as mlod_rt_skin (min and max are
 * then the empty box). No allocation. */
mlod_result mlod_rt_bounds(const mlod_rt_ctx *ctx, mlod_rt_scratch *s, uint32_t id, float min[3], float max[3],
                           mlod_error *err);

/* Skinning only when the vertices shown went stale. A CPU-skinning
 * caller that keeps each instance's skinned vertices in buffers of its own
 * (the ones it draws) poses every instance every frame and skins one again
 * only when the vertices it kept are provably more than max_stale_pixels
 * off where mlod_rt_skin would put them now. The caller keeps, per
 * instance, a record of mlod_rt_stale_size(ctx) bytes (4-byte aligned, its
 * own memory: the runtime allocates nothing for it; record_size its
 * size), all zero for "never skinned" (zero it again whenever its buffers
 * no longer hold that instance's last skin): 32 bytes, then 48 per joint of the full skeleton
 * (the 3x4 affine part of each world matrix the kept skin used), then 4 per
 * morph weight (mlod_rt_morph_target_count summed over the parts). The
 * record names the context that wrote it (a count of the opens in the
 * process): a record written through another context, of another pack or
 * another open of the same one, holds no skin for this one (it skins), so
 * a record means nothing outside the process that wrote it.
 * mlod_rt_skin_stale poses the instance as mlod_rt_skin does (only what
 * its mesh level reads) and makes the palette entries; then, when the
 * record holds a skin of the same instance id, at the same skeleton and
 * mesh levels shown, the same clip and the same morph weights (bit for
 * bit), it bounds how far any vertex moved since: a skinned vertex is a
 * convex combination of its palette entries' images, so with P0 an entry's
 * matrix then (made again from the kept world matrix by the same product:
 * the same floats) and P1 now, L0 and L1 their 3x3 linear parts, c, r and h
 * the centre, radius and half extents of the bind-pose ball and box of the
 * vertices weighted to the entry (mlod_rt_bounds' tables), grown by g for
 * the morph weights as there, every vertex moved at most
 *     max_e |P1 c_e - P0 c_e| + min(||L1 - L0||_F (r_e + g),
 *                                   | (sum_j |(L1 - L0)_ij| (h_j + g))_i |)
 * (the Frobenius norm bounds the spectral norm), the same for each rigid
 * part's matrix and ball, plus the rounding of both skins (1e-5 of the
 * magnitudes the kernels sum, each matrix, as mlod_rt_bounds allows); an
 * entry whose matrix did not change adds 0 (the kernels then write the
 * same floats). That is exact, whatever the clip does between. At the
 * instance's distance d at the last update (mlod_rt_update), a move D is
 * D lines / (2 d tan(fov_y / 2)) pixels (sel's fov_y and lines; nothing
 * else of sel is read). When that is at most max_stale_pixels, nothing is
 * written (*skinned 0, *stale_pixels the bound in pixels, *vertex_count
 * the level's vertices, which the buffers still hold); at d 0 only a pose
 * that did not move at all keeps (every bound 0: *stale_pixels 0).
 * Otherwise (a bound over it, or NaN, which only a hostile pack gives; d 0
 * with a pose that moved; the record empty or of another context,
 * instance, level, clip or weights) it skins into the buffers as mlod_rt_skin (*skinned 1, *stale_pixels 0)
 * and keeps this skin's world matrices and weights in the record. The
 * motion level may change without a skin: the bound is on the matrices.
 * Without a mesh it is mlod_rt_skin. Errors and arguments as
 * mlod_rt_skin, and MLOD_ERR_INVALID_ARG for a NULL sel or record, fov_y
 * not in (0, pi), lines not > 0, max_stale_pixels negative or not finite,
 * or record_size below mlod_rt_stale_size(ctx) (nothing written then);
 * after a skin that fails the record is marked empty. No allocation (the check keeps the changes of up to 16 palette
 * sources on the stack, about 2.6 KB). The errors add: a mesh level selected within p
 * pixels of level 0 (MLOD_RT_SELECT_PIXELS) shown with a stale pose within
 * q pixels of now is within p + q pixels of level 0 now (0.5 + 0.5 keeps
 * the pixel rule's 1 pixel). Like mlod_rt_skin it only reads the context;
 * a record is one instance's, used by one thread at a time. Measured:
 * mlod_rt_eval(3), bench/RESULTS.md Run 112. */
size_t mlod_rt_stale_size(const mlod_rt_ctx *ctx);
mlod_result mlod_rt_skin_stale(const mlod_rt_ctx *ctx, mlod_rt_scratch *s, uint32_t id, const mlod_rt_select *sel,
                               float max_stale_pixels, void *record, size_t record_size, float *positions,
                               size_t pos_stride, float *normals, size_t nrm_stride, uint32_t capacity,
                               uint32_t *vertex_count, int *skinned, float *stale_pixels, mlod_error *err);

/* The skinning kernels, for callers with their own data and for the
 * benchmark: n vertices, positions and normals 3 floats each (normals may
 * be NULL, then out_nrm is not written), joints 4 palette indices each
 * (the caller guarantees them in range), weights 4 each (summing to 1:
 * no renormalisation), palette 16 floats per matrix (column-major 4x4, as
 * mlod_rt_palette gives); output 3 floats per vertex with byte strides.
 * The first is the runtime's loop (vertices bucketed by their count of
 * influences up to the last non-zero weight, one loop per count, 4-lane
 * blends; see rt_skin.c), the second a plain scalar loop (per-influence
 * accumulation skipping zero weights, vectorisation disabled where the
 * compiler allows it), kept as the benchmark's reference. Same results to
 * rounding (bit for bit on x86-64 with GCC). Neither allocates; the first
 * uses about 1.3 KB of stack. Only the 3 floats of each output vertex are
 * written, so positions and normals may be interleaved in one buffer. */
void mlod_rt_skin_lbs(size_t n, const float *positions, const float *normals, const uint16_t *joints,
                      const float *weights, const float *palette, float *out_pos, size_t pos_stride,
                      float *out_nrm, size_t nrm_stride);
void mlod_rt_skin_lbs_scalar(size_t n, const float *positions, const float *normals, const uint16_t *joints,
                             const float *weights, const float *palette, float *out_pos, size_t pos_stride,
                             float *out_nrm, size_t nrm_stride);

#ifdef __cplusplus
}
#endif

#endif /* MLOD_RT_H */
