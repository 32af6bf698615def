/*
 * mlod_skeleton.h: the skeleton layer (paper 4.1): joint labels and energy, the
 * Multiresolution Skeletal Graph, nested skeleton levels with folded motion
 * and transferred weights, their glTF output, and the level policy of
 * mlod-skelgraph (default levels within an error bound, levels by threshold
 * or joint fraction). The stage record they leave is lib/record's.
 */
#ifndef MLOD_SKELETON_H
#define MLOD_SKELETON_H

#include "model/mlod_model.h"
#include "io/mlod_io.h"
#include "measure/mlod_measure.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ------------------------------------------------------------------ */
/* Skeleton labeling and joint energy (paper 4.1.1, 4.1.2)             */
/* ------------------------------------------------------------------ */

typedef enum mlod_label {
	MLOD_LABEL_ROOT,         /* zeta */
	MLOD_LABEL_END_EFFECTOR, /* chi */
	MLOD_LABEL_MAJOR,        /* psi */
	MLOD_LABEL_EXTREME,      /* mu */
	MLOD_LABEL_MINOR         /* kappa: the only removable joints */
} mlod_label;

const char *mlod_label_name(mlod_label l);   /* "root", "end-effector", ... */
const char *mlod_label_symbol(mlod_label l); /* UTF-8 Greek letter */
/* Parses a label name; returns 0 on success, -1 otherwise. */
int mlod_label_parse(const char *s, mlod_label *out);

/* The defaults: the paper's hub factor, and a half turn per Euler axis. */
#define MLOD_LABEL_HUB_FACTOR_DEFAULT 1.9
#define MLOD_LABEL_MAX_ANGLE_DEFAULT 180.0 /* degrees */

typedef struct mlod_label_options {
	double hub_factor;   /* 0 means MLOD_LABEL_HUB_FACTOR_DEFAULT */
	double max_angle;    /* radians: rotation range per Euler axis for energy normalisation; 0 means
	                      * MLOD_LABEL_MAX_ANGLE_DEFAULT degrees */
} mlod_label_options;

typedef struct mlod_joint_info {
	int depth;           /* edges to the joint's root */
	int children;
	int neighbors;       /* children + 1 if the joint has a parent */
	mlod_label label;
	double weight;       /* (h - depth) / h, h = tree height (max depth + 1) */
	double energy;       /* max over clips of the joint energy */
} mlod_joint_info;

/* Labels every joint and computes its energy from the character's clips
 * (0 when there are none). info holds skeleton.joint_count entries. */
mlod_result mlod_label_skeleton(const mlod_character *c, const mlod_label_options *opt,
                                mlod_joint_info *info, mlod_error *err);


/* ------------------------------------------------------------------ */
/* Multiresolution Skeletal Graph and skeleton levels (paper 4.1.3)    */
/* ------------------------------------------------------------------ */

/* An edge of the transitive closure of a kinematic sub-chain: from an
 * ancestor a to a descendant b, weighted by the bone length along the
 * chain between them. */
typedef struct mlod_skelgraph_edge {
	int a, b;
	float length;
} mlod_skelgraph_edge;

/* The graph: each kinematic sub-chain is a connected set of joints whose
 * interior joints are minor and whose ends are non-minor; chains meet only
 * at non-minor joints. A chain may branch where a minor joint has several
 * children. */
typedef struct mlod_skelgraph {
	int joint_count;
	int *joint_parent;            /* joint_count: the skeleton's parents */
	int chain_count;
	int *chain_start;             /* chain_count + 1 offsets into chain_joints */
	int *chain_joints;            /* each chain's joints, its top joint first, parents before children */
	int edge_count;
	mlod_skelgraph_edge *edges;   /* the closure of every chain, sorted by (length, a, b) */
} mlod_skelgraph;

/* Builds the graph from the skeleton and its labels. A skeleton whose
 * closure would exceed a few million edges is MLOD_ERR_LIMIT. */
mlod_result mlod_skelgraph_build(const mlod_skeleton *s, const mlod_joint_info *info,
                                 mlod_skelgraph *out, mlod_error *err);
void mlod_skelgraph_free(mlod_skelgraph *g);

/* One skeleton level. */
typedef struct mlod_skel_level {
	double threshold;        /* minor joints with energy below it are removed */
	int joint_count;         /* of the full skeleton */
	int kept_count;
	unsigned char *kept;     /* joint_count flags */
	int *parent;             /* joint_count: a kept joint's parent in the level (-1 for a root or a removed joint) */
	int *remap;              /* joint_count: the kept joint that stands in for each joint (itself when kept) */
} mlod_skel_level;

/* Extracts the level at threshold: disables the minor joints whose energy
 * is below it, then takes the minimum spanning tree of the enabled joints
 * over the closure edges, oriented from the roots. Levels extracted at
 * increasing thresholds are nested. */
mlod_result mlod_skelgraph_extract(const mlod_skelgraph *g, const mlod_joint_info *info,
                                   double threshold, mlod_skel_level *out, mlod_error *err);
void mlod_skel_level_free(mlod_skel_level *l);

/* The paper's decimation order: the minor joints sorted by energy, lowest
 * first; equal energies (joints that never move relative to their parent)
 * go deepest first, then by index. Writes the minor joints to order
 * (joint_count entries suffice) and returns how many there are. */
int mlod_skel_removal_order(const mlod_skeleton *s, const mlod_joint_info *info, int *order);

/* Extracts the level that removes the first `removed` joints of order, as
 * mlod_skelgraph_extract does for a threshold. Levels with increasing
 * counts are nested. out->threshold is the energy of the last removed
 * joint (0 when none). */
mlod_result mlod_skelgraph_extract_first(const mlod_skelgraph *g, const mlod_joint_info *info,
                                         const int *order, int removed, mlod_skel_level *out,
                                         mlod_error *err);

/* A level as measured, for mlod_gltf_add_skel_levels. */
typedef struct mlod_skel_level_record {
	const mlod_skel_level *level;
	const mlod_character *character; /* the level applied to the full character */
	mlod_deviation vertex;           /* skinned-vertex error, % of diagonal; scale 0 without meshes */
	mlod_deviation joint;            /* joint position error, scene units */
	double height;                   /* mlod_skeleton_height, for the joint error */
} mlod_skel_level_record;

typedef struct mlod_fold_stats {
	int shear_samples;       /* composed transforms that had shear TRS cannot express */
	int weight_merges;       /* vertices whose influences were merged */
} mlod_fold_stats;

/* Applies a level to a character, giving a standalone character whose
 * skeleton holds only the kept joints (in the same relative order):
 * - motion folding: a kept joint whose parent was removed gets the local
 *   transform L'_c = L_j ... L_c composed over its removed ancestors, at
 *   the union of their key times (or every frame of a sampled clip), so
 *   every kept joint's world transform is unchanged there;
 * - skin transfer: each vertex's weight on a removed joint moves to its
 *   stand-in; duplicates merge and the weights are renormalised;
 * - skins list the kept joints they used plus any stand-in they need, with
 *   inverse bind matrices from the full skeleton;
 * - rigid instances on a removed joint follow its stand-in.
 * out->joints[k].node keeps the original node index. stats may be NULL. */
mlod_result mlod_skel_level_apply(const mlod_character *c, const mlod_skel_level *l,
                                  mlod_character *out, mlod_fold_stats *stats, mlod_error *err);

/* Adds levels (coarser in order) to the document that full was read
 * from: per level a glTF skin for each skin, over the kept joints; a copy
 * of each skinned mesh with the transferred weights, on a node outside the
 * scene listed in the original node's MSFT_lod (coverage from the
 * errors). skins (count * skin_count entries, may be NULL) receives level
 * k's glTF skin for skin s at k * skin_count + s: what the stage record
 * (mlod_record_write_skeleton) lists. With lod 0 no MSFT_lod is set or
 * changed: the level nodes stay detached, for a document whose MSFT_lod
 * already lists mesh levels (mlod-bgm ran first), which the skeleton
 * levels must not replace. */
mlod_result mlod_gltf_add_skel_levels(mlod_gltf *doc, const mlod_character *full,
                                      const mlod_skel_level_record *levels, int count, int *skins, int lod,
                                      mlod_error *err);

/* ------------------------------------------------------------------ */
/* The skeleton level policy (skellevels.c)                                */
/* ------------------------------------------------------------------ */

/* The defaults of mlod-skelgraph: levels removing these fractions of the
 * joints (the paper's figure), within MLOD_SKEL_MAX_ERROR_DEFAULT percent
 * of the skeleton height; errors measured at up to MLOD_SKEL_SAMPLES times
 * per clip. */
#define MLOD_SKEL_REMOVED_DEFAULT 0.13, 0.26, 0.39
#define MLOD_SKEL_MAX_ERROR_DEFAULT 2.0
#define MLOD_SKEL_SAMPLES 120
#define MLOD_SKEL_MAX_LEVELS 32

/* a's skinned positions kept between calls of mlod_skel_vertex_deviation
 * for levels of the same character a (same max_samples), up to
 * MLOD_SKEL_CACHE_BYTES; past that, positions are skinned again. Not
 * shared between threads. */
typedef struct mlod_skel_pose_cache mlod_skel_pose_cache;
#define MLOD_SKEL_CACHE_BYTES ((size_t)128 << 20)
mlod_skel_pose_cache *mlod_skel_pose_cache_new(void); /* NULL when out of memory */
void mlod_skel_pose_cache_free(mlod_skel_pose_cache *cache);

/* mlod_vertex_deviation(a, b, ...), the same numbers bit for bit, for a
 * level b of a (mlod_skel_level_apply): only the vertices whose skin
 * matrices or weights differ in b at a time are skinned, in both, a's
 * from cache when it has them (cache may be NULL) (skeldev.c). Other
 * pairs of characters go to mlod_vertex_deviation. */
mlod_result mlod_skel_vertex_deviation(const mlod_character *a, const mlod_character *b, int max_samples,
                                       mlod_skel_pose_cache *cache, mlod_deviation *out, mlod_error *err);

/* A level made and measured. */
typedef struct mlod_skel_built {
	mlod_skel_level skel;
	mlod_character c;        /* the level as a standalone character */
	mlod_fold_stats stats;
	int has_mesh_error;
	mlod_deviation vertex;   /* skinned-vertex error, % of the bounding diagonal */
	mlod_deviation joint;    /* joint position error, scene units */
	double bound_error;      /* what a bound is compared with: the vertex error with meshes, else the
	                          * joint error, in % of the skeleton height */
} mlod_skel_built;

/* The levels of one character, finest first. */
typedef struct mlod_skel_levels {
	const mlod_character *c;
	const mlod_joint_info *info;
	mlod_skelgraph graph;
	int *order;              /* the removal order of the minor joints */
	int minor_count;
	double height;           /* mlod_skeleton_height */
	int has_mesh;
	mlod_skel_pose_cache *cache; /* the full character's posed vertices, for measuring levels (or NULL) */
	int count;
	mlod_skel_built levels[MLOD_SKEL_MAX_LEVELS];
} mlod_skel_levels;

/* Builds the graph and the removal order (c and info must outlive L). */
mlod_result mlod_skel_levels_init(mlod_skel_levels *L, const mlod_character *c, const mlod_joint_info *info,
                                  mlod_error *err);
void mlod_skel_levels_free(mlod_skel_levels *L);

/* Makes and measures one level: at an energy threshold (threshold >= 0),
 * else removing the first `removed` joints of the order. It fills L's
 * cache: one thread at a time per L. */
mlod_result mlod_skel_levels_make(const mlod_skel_levels *L, double threshold, int removed, mlod_skel_built *out,
                                  mlod_error *err);
void mlod_skel_built_free(mlod_skel_built *b);

/* Adds levels at energy thresholds, or keeping fractions of the joints. */
mlod_result mlod_skel_levels_thresholds(mlod_skel_levels *L, const double *thresholds, int n, mlod_error *err);
mlod_result mlod_skel_levels_fractions(mlod_skel_levels *L, const double *kept, int n, mlod_error *err);

/* The default chain: MLOD_SKEL_REMOVED_DEFAULT of the joints removed,
 * each only while bound_error stays within max_error; past it, the
 * largest removal within it (mlod_level_search_run) ends the chain. */
mlod_result mlod_skel_levels_default(mlod_skel_levels *L, double max_error, mlod_error *err);

/* The levels as records for mlod_gltf_add_skel_levels (L->count). */
void mlod_skel_levels_records(const mlod_skel_levels *L, mlod_skel_level_record *out);


/* ------------------------------------------------------------------ */
/* BVH output (skelbvh.c)                                              */
/* ------------------------------------------------------------------ */

/* BVH has no scale channel. mlod_bvh_write puts every joint of a clip
 * where the character does, scales or not, but an End Site is a fixed
 * OFFSET in its joint's frame (its place in the rest pose): where a scale
 * changes during the clip (a glTF scale channel), or a non-uniform scale
 * lies above a joint that turns, the End Sites below do not follow. *max
 * gets how far the End Sites of a BVH of clip `clip` of c are from where
 * c places them, the largest over the clip's key times (scene units; 0
 * for clip < 0, the rest pose), *joint the joint whose End Site it is
 * (-1: none), and note (when not NULL) what to tell the user when that is
 * more than float rounding (1e-5 of the skeleton's extent), else "". */
#define MLOD_SKEL_BVH_NOTE_SIZE 512
mlod_result mlod_skel_bvh_end_sites(const mlod_character *c, int clip, double *max, int *joint, char *note,
                                    size_t note_size, mlod_error *err);

#ifdef __cplusplus
}
#endif

#endif /* MLOD_SKELETON_H */
