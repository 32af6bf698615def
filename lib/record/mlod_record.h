/*
 * mlod_record.h: the stage record, extras.mlod: what each stage of the
 * pipeline leaves in the glTF for the later ones (and for the pack). This
 * module owns its schema (mlod-record(5)), its version, and the one reader
 * and one writer of every part:
 *
 *   joint nodes     the labels and energy of mlod-label
 *   the scene       version; source, for a BVH's document (every stage);
 *                   skeleton_levels (mlod-skelgraph); mesh_levels, or
 *                   mesh_level in a --split file (mlod-bgm)
 *   skins           the skins standing for them at each skeleton level
 *   level nodes     the mesh level a node holds (mlod-bgm)
 *   animations      the motion level a "<clip>@lod<k>" animation holds
 *                   (mlod-motion), which the other stages do not take as
 *                   a clip (mlod_record_load)
 *
 * Writers merge: each sets its own keys of the scene record and keeps the
 * others (a later stage never drops an earlier stage's levels), and stamps
 * the version. Readers give typed structs and fail with MLOD_ERR_PARSE and
 * a message naming the object and key on a malformed record, and with
 * MLOD_ERR_UNSUPPORTED on a version newer than MLOD_RECORD_VERSION. A file
 * without a version is version 1 (what mlod wrote before it had one).
 *
 * JSON: the shim hands extras.mlod over as text; a small strict C reader
 * and writer in lib/record (json.c) turn it into these structs and back.
 * Numbers keep the digits they are written with.
 *
 * The glTF reader (lib/io) also writes and reads two keys of its own for a
 * BVH turned into glTF, documented in mlod-record(5) beside these:
 * extras.mlod.end_site on End Site nodes and extras.mlod_bvh.channels on
 * joint nodes.
 */
#ifndef MLOD_RECORD_H
#define MLOD_RECORD_H

#include "io/mlod_io.h"
#include "measure/mlod_measure.h"
#include "skeleton/mlod_skeleton.h"
#include "mesh/mlod_mesh.h"
#include "motion/mlod_motion.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The version this mlod writes and the newest it reads. Version 2:
 * joint_error.max_percent_height is of mlod_skeleton_height (version 1:
 * of the largest extent of the rest pose). Version 3: the measures a pack
 * does not store may be absent (the missing_* flags below: the reader
 * sets them, a writer leaves those keys out), each level may carry its
 * pack error (pack_error, scene units: what mlod-pack -x writes), and a
 * full clip may say it is a pack's motion level 0
 * (mlod_record_read_motion0). A record with every key reads as it did in
 * version 2. Version 4: the scene may say that the document was made from
 * a BVH file (source), whose lengths are in the file's own units; a
 * record without it reads as version 3's. */
#define MLOD_RECORD_VERSION 4

/* ------------------------------------------------------------------ */
/* Joint nodes: labels and energy (mlod-label)                         */
/* ------------------------------------------------------------------ */

/* Writes each joint's results (info, skeleton.joint_count entries) into
 * its node's extras.mlod, keeping other keys there, and stamps the
 * version on the scene. */
mlod_result mlod_record_write_joints(mlod_gltf *doc, const mlod_character *c, const mlod_joint_info *info,
                                     mlod_error *err);

/* Reads every joint's label and energy (and depth, children, neighbours,
 * weight) from its node. *found is 1 when every joint's node has a label
 * record, 0 when some have none (info is then left as it was); a record
 * that is there but malformed is MLOD_ERR_PARSE. */
mlod_result mlod_record_read_joints(const mlod_gltf *doc, const mlod_character *c, mlod_joint_info *info,
                                    int *found, mlod_error *err);

/* ------------------------------------------------------------------ */
/* The scene: skeleton and mesh levels                                 */
/* ------------------------------------------------------------------ */

/* One skeleton level (extras.mlod.skeleton_levels[k]). Joints are glTF
 * node indices. */
typedef struct mlod_record_skel_level {
	int level;               /* 1 for the finest */
	double threshold;        /* energy threshold */
	int joints;              /* joints kept */
	int kept_count;
	int *kept;               /* the kept joints' nodes */
	int remap_count;
	int *remap_from;         /* a removed joint's node ... */
	int *remap_to;           /* ... and its stand-in's node */
	int skin_count;
	int *skins;              /* the level's glTF skin for each skin of the character, in order */
	mlod_deviation joint_error;   /* removed joints following their stand-ins: scene units (scale 0) */
	int has_vertex_error;
	mlod_deviation vertex_error;  /* skinned-vertex error, % of the bounding diagonal (scale 0) */
	int missing_threshold;   /* no threshold (version 3; 0 above) */
	int missing_joint_error; /* no joint_error (version 3; zeros above) */
	int has_pack_error;
	double pack_error;       /* the level's pack error (TOC), scene units */
} mlod_record_skel_level;

/* One mesh level (extras.mlod.mesh_levels[k], or mesh_level of a --split
 * file). */
typedef struct mlod_record_mesh_level {
	int level;               /* 1 for the finest */
	double ratio;            /* requested, or found under a --max-error */
	int triangles, vertices; /* of the whole character at this level */
	mlod_deviation error;    /* posed error, % of the bounding diagonal (scale 0) */
	double coverage;         /* screen coverage from which the level shows
	                          * (MSFT_screencoverage; filled by the reader
	                          * from error.max: 0 when error_percent is missing) */
	int missing_ratio;       /* no ratio (version 3; 0 above) */
	int missing_error;       /* no error_percent (version 3; zeros above) */
	int has_pack_error;
	double pack_error;       /* the level's pack error (TOC), scene units */
} mlod_record_mesh_level;

/* The skins standing for one skin of the character (extras.mlod of the
 * skin). */
typedef struct mlod_record_skin {
	int skin;                /* the glTF skin */
	int level_count;
	int *levels;             /* its stand-in skin at each skeleton level */
} mlod_record_skin;

/* Everything the scene and skins record. */
typedef struct mlod_record {
	int version;             /* as read; 1 when the file has none */
	int has_skel_levels;     /* skeleton_levels is there (maybe empty: mlod-pack -x
	                          * of a pack with skeleton level 0 alone) */
	int has_mesh_levels;     /* mesh_levels is there (maybe empty) */
	int skel_level_count;
	mlod_record_skel_level *skel_levels;
	int skin_count;          /* skins with a record */
	mlod_record_skin *skins;
	int mesh_level_count;
	mlod_record_mesh_level *mesh_levels;
	int has_mesh_level;      /* a --split file: the one level it holds */
	mlod_record_mesh_level mesh_level;
	/* extras.mlod.pack (version 3, mlod-pack -x): the INFO fields of the
	 * pack the file was unpacked from that its data does not give back
	 * exactly, for packing it again. */
	int has_pack;
	char *pack_name;         /* the character's name */
	double pack_bounds_min[3], pack_bounds_max[3]; /* the rest pose's bounds (INFO) */
	/* extras.mlod.source (version 4): MLOD_FORMAT_BVH when the document
	 * was made from a BVH file, else MLOD_FORMAT_UNKNOWN. */
	mlod_format source;
} mlod_record;

/* Reads the scene's and the skins' records (all empty when there are
 * none). Release with mlod_record_free. */
mlod_result mlod_record_read(const mlod_gltf *doc, mlod_record *out, mlod_error *err);
void mlod_record_free(mlod_record *r);

/* The typed levels of skeleton levels as measured: kept joints and remap
 * as nodes of full's document; skins[k * full->skeleton.skin_count + s]
 * is level k's glTF skin for skin s (as mlod_gltf_add_skel_levels gives
 * them). Release each with mlod_record_skel_level_free. */
mlod_result mlod_record_skel_levels_make(const mlod_character *full, const mlod_skel_level_record *levels, int count,
                                         const int *skins, mlod_record_skel_level *out, mlod_error *err);
void mlod_record_skel_level_free(mlod_record_skel_level *l);

/* Writes extras.mlod.skeleton_levels of the scene (replacing earlier
 * skeleton levels, keeping every other key) and each full skin's list of
 * stand-ins (full_skins: the glTF skin of each of the character's
 * skin_count skins, -1 for none). */
mlod_result mlod_record_write_skeleton(mlod_gltf *doc, const mlod_record_skel_level *levels, int count,
                                       const int *full_skins, int skin_count, mlod_error *err);

/* Writes extras.mlod.mesh_levels of the scene (count 0: an empty list,
 * the character has level 0 alone), keeping every other key. */
mlod_result mlod_record_write_mesh_levels(mlod_gltf *doc, const mlod_record_mesh_level *levels, int count,
                                          mlod_error *err);

/* Writes extras.mlod.pack of the scene: the name and bounds of the pack
 * a file was unpacked from. */
mlod_result mlod_record_write_pack(mlod_gltf *doc, const char *name, const float bounds_min[3],
                                   const float bounds_max[3], mlod_error *err);

/* Writes extras.mlod.mesh_level of the scene: the one level a --split
 * file holds. */
mlod_result mlod_record_write_mesh_split(mlod_gltf *doc, const mlod_record_mesh_level *level, mlod_error *err);

/* What mesh level k's skinned instances need from the skeleton levels
 * (mlod_mesh_skeleton, for mlod_mesh_levels_follow): the record's
 * skeleton level k. */
void mlod_record_mesh_skeleton(const mlod_record_skel_level *l, mlod_mesh_skeleton *out);

/* ------------------------------------------------------------------ */
/* Level nodes (mlod-bgm)                                              */
/* ------------------------------------------------------------------ */

typedef struct mlod_record_mesh_node {
	int level;               /* the mesh level the node holds */
	double ratio;
	mlod_deviation error;    /* % of the bounding diagonal (scale 0) */
	int skeleton_level;      /* its skin is a skeleton level's */
	int missing_ratio;       /* no ratio (version 3) */
	int missing_error;       /* no error_percent (version 3) */
	int has_pack_error;
	double pack_error;       /* the level's pack error (TOC), scene units */
} mlod_record_mesh_node;

/* Writes one level node's record (merging with its other keys). */
mlod_result mlod_record_write_mesh_node(mlod_gltf *doc, int node, const mlod_record_mesh_node *n, mlod_error *err);
/* Writes the record of every level node of lod (mlod_mesh_levels_write). */
mlod_result mlod_record_write_mesh_nodes(mlod_gltf *doc, const mlod_mesh_levels *levels, const mlod_mesh_lod *lod,
                                         mlod_error *err);
/* Reads a node's mesh level record; *found is 0 when it has none. */
mlod_result mlod_record_read_mesh_node(const mlod_gltf *doc, int node, mlod_record_mesh_node *out, int *found,
                                       mlod_error *err);

/* ------------------------------------------------------------------ */
/* Motion levels: "<clip>@lod<k>" animations (mlod-motion)             */
/* ------------------------------------------------------------------ */

/* What was done to a level's morph target weights channels. */
typedef struct mlod_record_morph_weights {
	int channels;
	long keys, source_keys, bytes;
	double bound;            /* scene units */
	double error;            /* the largest vertex displacement bound of the reduced tracks */
	int copied;              /* tracks kept as they are */
} mlod_record_morph_weights;

/* Up to version 2 every key but bound, grid, subdivide,
 * vertex_error_percent_diagonal and morph_weights is required; version 3
 * lets method with threshold, keys with source_keys and bytes,
 * joint_error and point_error be missing (a pack stores none of them). */
typedef struct mlod_record_motion_level {
	int level;               /* 1 for the finest */
	int source_animation;    /* the glTF animation it reduces */
	mlod_motion_method method;
	double threshold;
	int has_bound;
	double bound;            /* scene units */
	long keys, source_keys, bytes;   /* joint channels and morph weights together */
	mlod_deviation joint_error;      /* scene units (scale 0) */
	double joint_error_max_percent_height;
	double point_error, grid;
	int subdivide;
	int has_vertex_error;
	double vertex_error_percent_diagonal;
	int has_morph_weights;
	mlod_record_morph_weights morph_weights;
	int missing_method;      /* no method and threshold (version 3) */
	int missing_keys;        /* no keys, source_keys and bytes (version 3) */
	int missing_joint_error; /* no joint_error (version 3) */
	int missing_point_error; /* no point_error (version 3) */
	int has_pack_error;
	double pack_error;       /* the level's pack error (TOC), scene units */
} mlod_record_motion_level;

/* Writes the record of glTF animation `animation`, a motion level. */
mlod_result mlod_record_write_motion(mlod_gltf *doc, int animation, const mlod_record_motion_level *level,
                                     mlod_error *err);
/* Reads it; *found is 0 when the animation has no motion level record. */
mlod_result mlod_record_read_motion(const mlod_gltf *doc, int animation, mlod_record_motion_level *out, int *found,
                                    mlod_error *err);
/* The number of animations whose record says they are motion levels
 * (mlod-motion's <clip>@lod<k>, or mlod-pack -x's). */
mlod_result mlod_record_motion_level_count(const mlod_gltf *doc, int *count, mlod_error *err);

/* A full clip that is a pack's motion level 0 (mlod-pack -x writes it):
 * extras.mlod.motion_level0 of its animation, an object whose pack_error
 * is the level's joint position error against the clip the pack was made
 * from (scene units). The packer keeps such a clip's keys as they are and
 * takes that error. */
mlod_result mlod_record_write_motion0(mlod_gltf *doc, int animation, double pack_error, mlod_error *err);
/* Reads it; *found is 0 when the animation has none. */
mlod_result mlod_record_read_motion0(const mlod_gltf *doc, int animation, double *pack_error, int *found,
                                     mlod_error *err);

/* "frames" or "keys". */
const char *mlod_record_method_name(mlod_motion_method m);

/* ------------------------------------------------------------------ */
/* The input: its source and the clips the stages take                 */
/* ------------------------------------------------------------------ */

/* Writes extras.mlod.source of the scene (version 4): "bvh", for a
 * document made from a BVH file (the only source recorded; another is
 * MLOD_ERR_INVALID_ARG). mlod_record_load writes it on a BVH's document,
 * and the stages keep it, so that a glb of a BVH says so to the next. */
mlod_result mlod_record_write_source(mlod_gltf *doc, mlod_format source, mlod_error *err);

/* Is the character a BVH's: the input is BVH (format), or a document
 * whose record (r, may be NULL) says it was made from one? Its lengths
 * are then in the file's own units, and every default that assumes
 * glTF's metres takes the BVH rule instead: the point distance is
 * mlod_motion_point_distance(s, !mlod_record_from_bvh(r, format)). */
int mlod_record_from_bvh(const mlod_record *r, mlod_format format);

/* What mlod_record_load tells of its input. */
typedef struct mlod_record_input {
	mlod_format format;      /* the file's format */
	int from_bvh;            /* mlod_record_from_bvh: a BVH, or a document made from one */
	int level_clips;         /* motion level animations left out of the clips
	                          * (MLOD_RECORD_INPUT_CLIPS) */
} mlod_record_input;

/* mlod_record_load leaves the motion levels (animations whose record
 * has motion_level: mlod-motion's "<clip>@lod<k>", mlod-pack -x's) out
 * of the character's clips, which then hold the input's clips alone:
 * what every stage but the motion stage and the pack takes, so that the
 * stages give the same levels in any order. The animations stay in the
 * document, unchanged. */
#define MLOD_RECORD_INPUT_CLIPS 1

/* mlod_load through the record: loads glb, glTF or BVH bytes into a
 * document (doc may be NULL) and a character, then writes the source of
 * a BVH's document (mlod_record_write_source) or reads a document's
 * (refusing a record newer than this mlod, MLOD_ERR_UNSUPPORTED, or a
 * malformed source, MLOD_ERR_PARSE), and with MLOD_RECORD_INPUT_CLIPS in
 * flags leaves the motion levels out of the clips. in may be NULL. On
 * failure nothing is allocated. */
mlod_result mlod_record_load(const void *data, size_t size, const char *base_dir, int flags, mlod_gltf **doc,
                             mlod_character *c, mlod_record_input *in, mlod_error *err);

#ifdef __cplusplus
}
#endif

#endif /* MLOD_RECORD_H */
