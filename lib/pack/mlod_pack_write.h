/*
 * mlod_pack_write.h: the bake side of the .mlod pack (mlod(5), whose
 * layout rt/mlod_pack.h owns): gathers every level of every layer of a
 * loaded character and writes the pack bytes.
 *
 * Levels come from the stage record when the input has them (mlod-label,
 * mlod-skelgraph, mlod-bgm and mlod-motion ran before, or the input is a
 * glb of mlod_pack_unpack: then each level's error is the record's
 * pack_error, a layer whose record lists no level stays at level 0, each
 * clip that is a pack's motion level 0 keeps its keys and error, and the
 * record's pack name and bounds are the INFO's), and are computed with
 * each layer's defaults (or the options below) when it has not:
 *
 *   skeleton  the record's skeleton_levels (kept joints and remap, glTF
 *             nodes); else labels (the record's, or mlod_label_skeleton)
 *             and mlod_skel_levels_default within skel_max_error
 *   mesh      the MSFT_lod level nodes with a mesh level record; else
 *             mlod_mesh_levels_by_ratio (ratios) or _by_error (max_error),
 *             not following the skeleton levels: a mesh level's joints are
 *             the full skin's, and a skeleton level's palette (its joints and binds)
 *             does the transfer at run time
 *   motion    the "<clip>@lod<k>" animations with a motion level record;
 *             else per clip and bound the frames and the keys methods of
 *             lib/motion, the one with fewer bytes (mlod-motion's auto)
 *
 * Motion level 0, piped or not, is each full clip within
 * motion_level0_error (the same methods, a level of its own: the coarser
 * levels are made from the clip as read either way), or with
 * lossless_motion the clip as read.
 *
 * A piped document holds the level skins and level animations beside the
 * full ones: the writer packs the character's full skins (those no record
 * or level node names as a level's) and full clips (those without a motion
 * level record) only.
 *
 * Quantisation (the bounds tests/unit/test_pack_write.c checks): see the
 * mlod_pack_q* helpers below.
 *
 * The output is deterministic: the same input and options give the same
 * bytes. The DOC chunk holds the input document without what the other
 * chunks hold (mlod_gltf_strip_levels: geometry, joint channels, MSFT_lod;
 * then the packed skins' inverse bind matrices, the joint nodes' rest TRS
 * in one number style, the stages' records and a piped input's level
 * nodes, skins, meshes and animations: mlod(5) DOC), as glb; when it
 * cannot be stripped (an extension that may refer to accessors), the
 * document whole with every index as read, but for what goes without
 * moving one (mlod_gltf_keep_indices: the records, MSFT_lod, the levels
 * at the ends of the arrays), with a note (also in stats->doc_note); with
 * doc_whole, the input glb as read.
 */
#ifndef MLOD_PACK_WRITE_H
#define MLOD_PACK_WRITE_H

#include <stdio.h>

#include "rt/mlod_pack.h"
#include "io/mlod_io.h"
#include "mesh/mlod_mesh.h"
#include "motion/mlod_motion.h"
#include "skeleton/mlod_skeleton.h"

#ifdef __cplusplus
extern "C" {
#endif

#define MLOD_PACK_MAX_MOTION_LEVELS 32
/* mlod-motion's default bounds: 0.2%, 1% and 3% of the skeleton height. */
#define MLOD_PACK_MOTION_BOUNDS_DEFAULT 0.2, 1.0, 3.0
/* Motion level 0's default bound, % of the skeleton height: a quarter of
 * the finest default level's, below gltfpack -cc's own error on every
 * sample clip (bench_motion pointerr; mlod-pack(1)). */
#define MLOD_PACK_MOTION_LEVEL0_DEFAULT 0.05
/* The rounds in which mlod_pack_write makes a clip's levels again while
 * one measures above its bound as the reader returns its keys (each round
 * that level's bound less 1.05 times the excess, twice that each round, at
 * least a quarter of the bound before); after them a level 0 still above
 * its bound is the clip as read (mlod-pack(1)). */
#define MLOD_PACK_HOLD_ROUNDS 8

/* Zero-initialised options are not the defaults: start from
 * mlod_pack_options_default. */
typedef struct mlod_pack_options {
	mlod_pack_codec codec;       /* NONE, MESHOPT or DRACO (MESH chunks as Draco
	                              * meshes, the other chunks MESHOPT; mlod(5)) */
	int entropy;                 /* MLOD_ENTROPY_ZSTD (the default) or _NONE: each
	                              * chunk but INFO through zstd -19 after its codec,
	                              * kept where it stores fewer bytes (mlod(5)) */
	const char *name;            /* the character's name in INFO; NULL: the
	                              * name in the input's record (extras.mlod.pack,
	                              * mlod-pack -x), else default_name, else "" */
	const char *default_name;
	/* skeleton, when computed */
	double skel_max_error;       /* % of the skeleton height (MLOD_SKEL_MAX_ERROR_DEFAULT) */
	mlod_label_options label;
	/* mesh, when computed */
	int ratio_count;             /* levels at these ratios (decreasing) ... */
	double ratios[MLOD_MESH_MAX_LEVELS];
	double mesh_max_error;       /* ... or, when >= 0, down to this % of the diagonal */
	mlod_bgm_options bgm;
	mlod_mesh_budget budget;
	/* motion, when computed */
	int motion_bound_count;      /* one level per bound on the joint position error */
	double motion_bounds[MLOD_PACK_MAX_MOTION_LEVELS];
	unsigned char motion_percent[MLOD_PACK_MAX_MOTION_LEVELS]; /* bound in % of the height, else scene units */
	double point_distance;       /* 0: 0.1 for glTF, height / 18 for BVH or a glb made from one
	                              * (mlod_record_from_bvh; as mlod-motion) */
	/* motion level 0 (computed or piped alike): the input clip within this
	 * point error bound (keys reduced, values rounded), or as read */
	double motion_level0_error;  /* > 0 and below the smallest of motion_bounds (else mlod_pack_write
	                              * is MLOD_ERR_INVALID_ARG: level 0 is the finest); 0: as read */
	unsigned char motion_level0_percent; /* in % of the height, else scene units */
	int lossless_motion;         /* level 0 as read whatever motion_level0_error says */
	/* each layer can be left at level 0 alone */
	int no_skeleton_levels, no_mesh_levels, no_motion_levels;
	int doc_whole;               /* DOC: the input glb whole, not stripped */
	/* mesh quantisation (mlod(5) QUANTISATION; MLOD_PACK_*_BITS_MIN to 16) */
	int position_bits;           /* positions: 2^bits - 1 steps of the part's box per axis;
	                              * morph deltas: 2^(bits-1) - 1 steps of their largest |value| */
	int normal_bits;             /* normals, tangents: octahedral codes on a 2^bits lattice */
	int uv_bits;                 /* UVs: 2^bits - 1 steps of the part's UV box per axis */
	double coarse_share;         /* a vertex only coarse levels have: rounded within this share
	                              * of their TOC error (MLOD_PACK_COARSE_SHARE; 0: level 0's
	                              * steps for every vertex, the writer before this rule) */
} mlod_pack_options;

void mlod_pack_options_default(mlod_pack_options *opt);

/* What one layer got. */
typedef struct mlod_pack_layer_stats {
	int levels;                  /* counting level 0 (0: the layer is empty) */
	int from_input;              /* the levels were the input's (1) or computed (0) */
	uint64_t stored, raw;        /* bytes of its chunks */
	double seconds;              /* computing its levels and encoding them */
	float errors[MLOD_PACK_MAX_MOTION_LEVELS + MLOD_MESH_MAX_LEVELS]; /* per level, scene units (largest over clips) */
} mlod_pack_layer_stats;

typedef struct mlod_pack_stats {
	mlod_pack_layer_stats skeleton, mesh, motion;
	uint64_t info_bytes, doc_bytes, total;
	int doc_stripped;            /* DOC holds the stripped document (else the input whole) */
	uint32_t chunks, first_drawable;
	int joints, skins, parts, clips;
	float height, diagonal;
	char notes[1024];            /* the reader's notes on the input, then what was done or skipped, "; "-separated */
	char warnings[1024];         /* of those, the ones a user must hear of (what the pack does not keep or keeps
	                                changed: an attribute not stored, an unweighted vertex moved, a motion bound
	                                missed), one per line, names quoted; the tool prints them on stderr */
	char doc_note[MLOD_ERROR_MESSAGE_SIZE + 64]; /* why DOC holds the input whole ("" when stripped), also in notes */
} mlod_pack_stats;

/* Packs the character c read from doc (mlod_load of input, input_size
 * bytes, in format). *out (release with mlod_free) gets the pack. stats
 * may be NULL. Errors: MLOD_ERR_UNSUPPORTED for a part the draco codec
 * cannot hold (no triangles, more than 256 morph targets, or counts Draco
 * does not give back), MLOD_ERR_PARSE for a malformed record, what the
 * layers return. */
mlod_result mlod_pack_write(const mlod_gltf *doc, const mlod_character *c, mlod_format format, const void *input,
                            size_t input_size, const mlod_pack_options *opt, void **out, size_t *out_size,
                            mlod_pack_stats *stats, mlod_error *err);

/* ------------------------------------------------------------------ */
/* Quantisation, as the writer does it (the reader undoes it)          */
/* ------------------------------------------------------------------ */

/* Unit vector to octahedral snorm16 (x, y), and back (normalised). The
 * angle between n and its round trip is below MLOD_PACK_OCT_BOUND. */
#define MLOD_PACK_OCT_BOUND 1e-4 /* radians (4.3e-5 measured over 200000 random normals) */
void mlod_pack_oct_encode(const float n[3], int16_t out[2]);

/* The same at `bits` (MLOD_PACK_NORMAL_BITS_MIN to 16; 16 is
 * mlod_pack_oct_encode): the code nearest in angle among the multiples of
 * step = 2^(16 - bits), each coordinate clamped to +-32767, so the reader's
 * snorm16 decode is unchanged and the low 16 - bits bits of most codes are
 * zero (meshopt's byte codec then stores them in almost nothing). The
 * angle is within mlod_pack_oct_bound(bits) = 3 sqrt(2) (step / 2) / 32767
 * (+ 2e-6 for f32): each coordinate within half a step, the map from the
 * octahedron to the sphere stretching that at most sqrt(18) times. */
#define MLOD_PACK_NORMAL_BITS_MIN 6
void mlod_pack_oct_encode_bits(const float n[3], int bits, int16_t out[2]);
double mlod_pack_oct_bound(int bits);

/* Defaults and lower limits of the mesh bits (the options above). */
#define MLOD_PACK_POSITION_BITS_MIN 8
#define MLOD_PACK_UV_BITS_MIN 8
#define MLOD_PACK_POSITION_BITS_DEFAULT 14
#define MLOD_PACK_NORMAL_BITS_DEFAULT 8
#define MLOD_PACK_UV_BITS_DEFAULT 12

/* 'ROTQ' rotations (mlod(5) QUANTISATION): a key on the lattice of
 * normalised shorts whose largest component is the one the reader
 * rebuilds from the other three (every key of lib/motion's levels) comes
 * back exactly, up to the sign. Any other key: the normalised input's
 * three smaller components within half a step h = 1/65534, the largest
 * (rebuilt, then on the lattice) within 4 h (3 h from the others' rounding,
 * as the largest is at least 1/2, plus h), so each component within
 * MLOD_PACK_ROTQ_BOUND, the 4-vector within sqrt(19) h and the rotation
 * angle at most 2 asin(sqrt(19) h) (MLOD_PACK_ROTQ_ANGLE). */
#define MLOD_PACK_ROTQ_BOUND (2.0 / 32767.0)
/* Key times as 'TICK': each decoded time is the time given, or within
 * MLOD_PACK_TICK_TOLERANCE * max(|t|, step) of it (about 8 f32 ulps:
 * 4.8 microseconds at t = 5 s); the writer prefers a step that is exact. */
#define MLOD_PACK_TICK_TOLERANCE (1.0 / 1048576.0)
#define MLOD_PACK_ROTQ_ANGLE 1.3304e-4 /* radians, 2 asin(sqrt(19) / 65534) rounded up; 0.0076 degrees */
/* Format 4.0: the rotation keys of every motion level may go on a coarser
 * lattice per joint (steps of 2^shift lattice units, shift 0 to
 * MLOD_PACK_ROTQ_SHIFT_MAX), each key then within 2 asin(sqrt(19) h 2^shift)
 * rad (mlod_pack_rotq_angle). The writer picks the shifts from the clip's
 * posed joints so that the shifts' part of every joint's point error
 * (mlod_motion_point_error, the angle times the joint's distance to each
 * rotated ancestor plus its point distance) stays within
 * MLOD_PACK_ROTQ_SHARE times the level's TOC error on top of what shift 0
 * gives (MLOD_PACK_ROTQ_ANGLE's share), with the joints' non-cubic
 * translations rounded to power-of-two grids within the same sums; one
 * set per clip (from the smallest TOC error of its levels), kept where the
 * clip's MOTION chunks get smaller. */
#define MLOD_PACK_ROTQ_SHARE 0.25
double mlod_pack_rotq_angle(int shift);
void mlod_pack_oct_decode(const int16_t in[2], float n[3]);

/* A value within [min, min + 65535 * scale] to u16: q = round((v - min) /
 * scale) (0 when scale is 0); |min + q * scale - v| <= scale / 2. The
 * scale for a range: (max - min) / 65535. */
uint16_t mlod_pack_qu16(float v, float min, float scale);
float mlod_pack_range_scale(float min, float max);
/* The scale at `bits` (1 to 16): (max - min) / (2^bits - 1), so q is
 * within [0, 2^bits - 1] and |min + q * scale - v| <= scale / 2. */
float mlod_pack_range_scale_bits(float min, float max, int bits);
/* The same on a coarser grid of the same steps: q the multiple of 2^shift
 * nearest (v - min) / scale (shift 0 to 15; clamped to 0 .. 65535), so
 * |min + q * scale - v| <= 2^shift scale / 2 where that stays in range. */
uint16_t mlod_pack_qu16_shift(float v, float min, float scale, int shift);

/* Coarse levels' steps (mlod(5) QUANTISATION). A part's vertex that no
 * finer level has with the same quantised attributes on level 0's steps,
 * whose finest level is f >= 1, has its position and UVs rounded to a
 * coarser multiple of the same grid (the reader's decode unchanged),
 * within share times e, the smallest TOC error of levels f and coarser
 * (e <= each of theirs): positions: the half-step vector (mesh units)
 * times sigma, the largest singular value bound of the part's rest
 * skinning matrices, within share e; UVs: the half-step vector within
 * share e rho / sigma, rho the MLOD_PACK_COARSE_UV_QUANTILE quantile over
 * level 0's edges of UV length over length (a UV error that moves the
 * texture on the surface by at most share e, one share of a pixel at the
 * level's switch distance, where the texture is at least that dense).
 * Each a minimum over f and the coarser levels' own bounds. Normals keep
 * level 0's bits (fewer bits measured no smaller: mlod(5)). */
#define MLOD_PACK_COARSE_SHARE 0.25
#define MLOD_PACK_COARSE_UV_QUANTILE 0.1

/* Up to 4 weights (>= 0, any sum > 0) to unorm8 summing exactly to 255
 * by largest-remainder rounding: each differs from 255 w / sum by less
 * than 1. A zero sum gives all zeros. */
void mlod_pack_weights8(const float w[4], uint8_t out[4]);

/* The 4 largest influences of vertex v over every weight set of p (a
 * joint met twice merged; ties: the lower slot), each joint mapped
 * through jmap when it is given (one past jmap_count becomes 0); unused
 * slots hold joint 0 and weight 0. */
void mlod_pack_top4(const mlod_primitive *p, uint32_t v, const int *jmap, int jmap_count, int joints[4],
                    float weights[4]);

/* The orders a part may be stored in (the writer keeps whichever codes
 * to the fewest bytes, input order on a tie and with codec none):
 *   0 as input;
 *   1 the triangles reordered for the vertex cache
 *     (meshopt_optimizeVertexCache), vertices as input;
 *   2 as 1, then the vertices in the order those triangles first use them
 *     (meshopt_optimizeVertexFetchRemap), vertices no triangle uses after
 *     them in input order;
 *   3 as 2 with the triangles in strip order
 *     (meshopt_optimizeVertexCacheStrip);
 *   4 as 1 with the triangles for a FIFO cache of MLOD_PACK_INDEX_FIFO
 *     vertices, the size of the vertex FIFO of meshopt's index codec
 *     (meshopt_optimizeVertexCacheFifo);
 *   5 as 4, then the vertices in first-use order as in 2;
 *   6 as 1, then the vertices in spatial order (meshopt_spatialSortRemap
 *     of positions, 3 floats per vertex): near vertices, notably the
 *     copies of a position along a seam or crease, stand next to each
 *     other; as 1 when positions is NULL;
 *   7 as 4, then the vertices in spatial order as in 6 (as 4 when
 *     positions is NULL);
 *   8 as 2, then each vertex whose position is bit-identical to an
 *     earlier one's moved to follow the first of them (as 2 when
 *     positions is NULL);
 *   9 as 5, then the copies of a position together as in 8.
 * remap[old] = new (nv entries), out[ni] the triangles in new vertex
 * indices. ni is a multiple of 3 and every index below nv, else the order
 * is left as it is (identity remap, out = indices). 0, or -1 when out of
 * memory. */
#define MLOD_PACK_ORDERS 10
#define MLOD_PACK_INDEX_FIFO 16
int mlod_pack_vertex_order(int order, const uint32_t *indices, uint32_t ni, uint32_t nv, const float *positions,
                           uint32_t *remap, uint32_t *out);

/* The same, keeping the triangle orders in memo between calls on the
 * same indices (meshopt_optimizeVertexCache's, which orders 1 2 6 8
 * share, the FIFO one of 4 5 7 9, the strip one of 3), so that each is
 * made once;
 * zero it before the first call, release it with
 * mlod_pack_order_memo_free. The results equal mlod_pack_vertex_order's. */
typedef struct mlod_pack_order_memo {
	uint32_t *tri[3]; /* the cache, FIFO and strip triangle orders, ni each, or NULL */
} mlod_pack_order_memo;
int mlod_pack_vertex_order_memo(int order, const uint32_t *indices, uint32_t ni, uint32_t nv, const float *positions,
                                mlod_pack_order_memo *memo, uint32_t *remap, uint32_t *out);
void mlod_pack_order_memo_free(mlod_pack_order_memo *memo);

/* A level's indices idx (ni, into a prefix of count vertices whose last
 * count - count0 are the level's block) in the form the writer stores
 * (mlod(5) MESH levels: the prefix's numbering, or the level's own with
 * 'IMAP' and, when the block is in first-use order, 'INEW'): returns the
 * cost the writer compares (the streams' meshopt-coded bytes, each padded
 * to 4, and 16 per stream beyond 'IDX '); *stored the same without the
 * headers. 0 (and *stored 0) when out of memory. */
size_t mlod_pack_index_cost(const uint32_t *idx, uint32_t ni, uint32_t count0, uint32_t count, size_t *stored);

/* The switch distance of an error (scene units) at MLOD_PACK_FOV_Y,
 * MLOD_PACK_LINES and MLOD_PACK_PIXELS: error * lines / (2 tan(fov / 2)
 * pixels). */
float mlod_pack_switch_distance(float error);

/* Unpacks a pack (read through rt/mlod_pack.h) to a glTF document
 * (lib/pack/unpack.c): the DOC chunk with level 0 back in its nodes'
 * meshes and clips, MSFT_lod level nodes for the coarser mesh levels,
 * a skin per skeleton level and skin, "<clip>@lod<k>" animations,
 * and the stage record (mlod-record(5) version 3) of what the pack stores
 * of those levels, so that mlod_pack_write packs it again from them.
 * MLOD_ERR_PARSE (the reader's message, naming the chunk) for a corrupt
 * pack. Release *out with mlod_gltf_free. */
mlod_result mlod_pack_unpack(const void *pack, size_t size, mlod_gltf **out, mlod_error *err);

/* What mlod_pack_unpack checks beyond mlod_pack_check (p opened on data):
 * the DOC chunk's glb read through the same glTF reader, and SKELETON's
 * glTF node and skin indices against the DOC's. MLOD_ERR_PARSE naming
 * the chunk ("DOC: ...", "SKELETON: ...") for a corrupt pack. */
mlod_result mlod_pack_check_doc(const mlod_pack *p, const void *data, size_t size, mlod_error *err);

/* Opens a whole pack and checks everything mlod_pack_unpack would
 * (mlod_pack_check, mlod_pack_check_doc, the header's size against size),
 * then decodes its INFO chunk into *info: what mlod-pack --info prints.
 * On success release with mlod_pack_info_free and mlod_pack_close; on
 * failure nothing is left to release. */
mlod_result mlod_pack_inspect(const void *data, size_t size, mlod_pack *p, mlod_pack_info *info, mlod_error *err);

/* A pack's TOC summed per layer (mlod_pack_layer, 0 to 3: none,
 * skeleton, mesh, motion; an unknown layer counts as none), and over
 * all: the bytes stored in chunks, their raw bytes, and the rest of the
 * file (header, TOC, padding). What mlod-pack --info prints (packinfo.c). */
typedef struct mlod_pack_totals {
	uint64_t stored[4], raw[4];
	uint32_t chunks[4];
	uint64_t all_stored, all_raw, overhead;
} mlod_pack_totals;
void mlod_pack_totals_sum(const mlod_pack *p, mlod_pack_totals *t);

/* A chunk's codec as --info names it: "meshopt", or "meshopt+zstd" with
 * an entropy stage; written to buf (n bytes), which it returns. */
const char *mlod_pack_codec_label(const mlod_pack_chunk *c, char *buf, size_t n);

/* The codec (meshopt, none, draco) and entropy stage (zstd, none) of
 * mlod-pack's --codec and --entropy into opt: 0, or -1 (opt unchanged)
 * for another name. */
int mlod_pack_codec_parse(const char *name, mlod_pack_options *opt);
int mlod_pack_entropy_parse(const char *name, mlod_pack_options *opt);

/* The text forms of mlod-pack's --info and --report (packinfo.c): the
 * table, or JSON laid out one member a line (mlod-pack(1)). Names are
 * escaped by mlod_name_put. Both write to f, which the caller flushes and
 * checks. */
typedef enum mlod_pack_text { MLOD_PACK_TEXT_TABLE, MLOD_PACK_TEXT_JSON } mlod_pack_text;

/* --info: the pack data (size bytes), opened and checked as
 * mlod_pack_inspect does, its header, INFO and every chunk's TOC entry,
 * and the layers' totals; as JSON also its rest bounds and every joint's
 * name and parent (SKELETON decoded). label names the pack in the output.
 * Errors: mlod_pack_inspect's (nothing written), the SKELETON chunk's
 * (MLOD_ERR_PARSE, the JSON written up to the skeleton). */
mlod_result mlod_pack_print_info(FILE *f, const char *label, const void *data, size_t size, mlod_pack_text form,
                                 mlod_error *err);

/* --report: what mlod_pack_write packed (st) of input, with codec the
 * codec's name as the report gives it ("meshopt+zstd"). */
void mlod_pack_print_stats(FILE *f, const char *input, const mlod_pack_stats *st, const char *codec,
                           mlod_pack_text form);

#ifdef __cplusplus
}
#endif

#endif /* MLOD_PACK_WRITE_H */
