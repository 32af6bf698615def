/*
 * mlod_skeleton.h: the skeleton layer (paper 4.1): joint labels and energy, the
 * Multiresolution Skeletal Graph, nested skeleton levels with folded motion
 * and transferred weights, and their glTF output.
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

typedef struct mlod_label_options {
	double hub_factor;   /* 0 means 1.9, the paper's value */
	double max_angle;    /* rotation range per Euler axis for energy normalisation; 0 means pi */
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
	double size;                     /* the skeleton height, for the joint error */
} mlod_skel_level_record;

/* The largest screen coverage (fraction of the screen height covered by
 * the character) at which an error of error_percent of the character's
 * size stays within pixel_budget pixels on a screen screen_pixels high;
 * at most 1, and 0 for no error. */
double mlod_error_coverage(double error_percent, double screen_pixels, double pixel_budget);

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

/* Records levels (coarser in order) in the document that full was read
 * from: per level a glTF skin for each skin, over the kept joints; a copy
 * of each skinned mesh with the transferred weights, on a node outside the
 * scene listed in the original node's MSFT_lod (coverage from the
 * errors); and extras.mlod on the scene (the levels: threshold, kept
 * nodes, remap as node -> stand-in node, skins, errors) and on each skin
 * (the skins of its levels). */
mlod_result mlod_gltf_add_skel_levels(mlod_gltf *doc, const mlod_character *full,
                                      const mlod_skel_level_record *levels, int count, mlod_error *err);


#ifdef __cplusplus
}
#endif

#endif /* MLOD_SKELETON_H */
