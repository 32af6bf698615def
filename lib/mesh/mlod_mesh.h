/*
 * mlod_mesh.h: the mesh layer (paper 4.2): the BindGraphMesh, triangle and edge
 * collapses, Power Skinning, progressive levels.
 */
#ifndef MLOD_MESH_H
#define MLOD_MESH_H

#include "model/mlod_model.h"
#include "measure/mlod_measure.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ------------------------------------------------------------------ */
/* Mesh layer: BindGraphMesh, triangle collapse, Power Skinning (4.2)  */
/* ------------------------------------------------------------------ */

/* The mesh layer simplifies each triangle primitive of a character on its
 * own. A BindGraphMesh (BGM) holds one primitive welded by position (the
 * topology) with one attribute "wedge" per seam side (each glTF vertex),
 * its dual graph (face adjacency) and each node's joint influences. Rigid
 * meshes hanging under a joint are skinned to it with weight 1. Triangle
 * (the paper) or edge collapses into a new vertex v-bar are recorded in
 * order, so that every prefix of the sequence is a valid mesh: a level is
 * a prefix. */

/* Up to this many joint influences per vertex (every weight set). */
#define MLOD_MAX_INFLUENCES (4 * MLOD_MAX_SETS)

/* A vertex's joint influences: joints are skin-local indices (or the one
 * joint of a rigid mesh, index 0), weights are positive. */
typedef struct mlod_influences {
	int count;
	uint16_t joints[MLOD_MAX_INFLUENCES];
	float weights[MLOD_MAX_INFLUENCES];
} mlod_influences;

/* Power Skinning (4.2.4), the weights of k collapsed vertices v[0..k-1]
 * for the new vertex vbar: with d_i = |vbar - v_i| and D = sum d_i,
 * W[i] = (D - d_i) / ((k - 1) D); 1/k each when D = 0 (or k = 1). The W
 * sum to 1. */
void mlod_power_weights(const mlod_v3 *v, int k, mlod_v3 vbar, double *W);

/* The influences of vbar: w(j) = sum_i W[i] w(j, v_i), with W from
 * mlod_power_weights. When more than 4 remain, the largest 4 are kept
 * (ties: lower joint first); out is then renormalised to sum 1, sorted
 * by weight, largest first. Returns 1 when influences were dropped (a
 * "cap event"), else 0. */
int mlod_power_skin(const mlod_v3 *v, const mlod_influences *in, int k, mlod_v3 vbar, mlod_influences *out);

/* Which vertices may disappear (4.2.2). eta(j) is the average of the
 * non-zero weights joint j has on vertices. */
typedef enum mlod_eligibility {
	MLOD_ELIGIBLE_DEFAULT = 0, /* the measured default: BEND with the compactness cost, ALL with the posed cost */
	MLOD_ELIGIBLE_LITERAL,     /* the paper: v only when w(j, v) < tau * eta(j) for every joint j */
	MLOD_ELIGIBLE_BEND,        /* protects bends: v only when its largest weight w(j, v) >= tau * eta(j) */
	MLOD_ELIGIBLE_ALL          /* every vertex */
} mlod_eligibility;

/* eta for every joint of the character (joint_count values, 0 for a joint
 * without weight): skinned instances count each vertex's weights, rigid
 * instances weight 1 on their joint. */
mlod_result mlod_joint_weight_average(const mlod_character *c, double *eta, mlod_error *err);

/* 1 when a vertex with influences inf may disappear. joint_map turns the
 * influence joints into skeleton joints (eta's index); tau 0 means 1. */
int mlod_vertex_eligible(mlod_eligibility rule, double tau, const mlod_influences *inf, const int *joint_map,
                         const double *eta);

/* What orders the collapses. */
typedef enum mlod_mesh_cost {
	MLOD_COST_DEFAULT = 0,  /* the measured default: MLOD_COST_POSED */
	MLOD_COST_COMPACTNESS,  /* the paper (4.2.3): lowest 4 sqrt(3) a / (l1^2 + l2^2 + l3^2) first */
	MLOD_COST_POSED         /* beyond the paper: quadric error summed over poses, compactness as tie-break */
} mlod_mesh_cost;

/* Where v-bar goes. Next to a seam or an allowed border it always snaps
 * to a seam (border) vertex, so that textures neither tear nor smear. */
typedef enum mlod_placement {
	MLOD_PLACE_DEFAULT = 0, /* OPTIMAL with the posed cost (measured), BARYCENTER with compactness (the paper) */
	MLOD_PLACE_BARYCENTER,  /* the paper: the triangle's barycenter */
	MLOD_PLACE_OPTIMAL      /* beyond the paper: the minimum of the posed quadric (or the barycenter when lower) */
} mlod_placement;

/* Which collapses run. */
typedef enum mlod_collapse_op {
	MLOD_OP_DEFAULT = 0,    /* the measured default: EDGE with the posed cost, TRIANGLE with compactness */
	MLOD_OP_TRIANGLE,       /* the paper (4.2.3): triangle collapses only */
	MLOD_OP_EDGE,           /* beyond the paper: edge collapses only (the posed cost only: compactness
	                         * does not rank an edge) */
	MLOD_OP_MIXED           /* triangle and edge collapses in one queue, cheapest first (posed cost only) */
} mlod_collapse_op;

/* Zero-initialised options are the defaults. */
typedef struct mlod_bgm_options {
	mlod_mesh_cost cost;
	mlod_placement placement;
	mlod_collapse_op op;
	mlod_eligibility eligibility;
	double tau;                  /* 0 means 1 */
	int allow_border;            /* let collapses move and remove border vertices */
	const mlod_pose_set *poses;  /* the posed cost's poses; NULL: the bind pose only */
	const double *eta;           /* per joint (mlod_joint_weight_average); NULL: computed */
} mlod_bgm_options;

typedef struct mlod_bgm mlod_bgm;

/* Builds the BGM of primitive `primitive` of the mesh of instance
 * `instance`: welds by position (and equal influences and morph target
 * offsets, so that nothing tears when posed or morphed), builds the dual
 * graph, marks borders, seams, locked nodes (non-manifold edges or fans,
 * inconsistent winding, duplicate faces, skinned vertices without weight)
 * and eligible ones, and the posed quadrics. Degenerate triangles (two
 * corners on one node) are dropped. A primitive that is not triangles is
 * MLOD_ERR_UNSUPPORTED. */
mlod_result mlod_bgm_build(const mlod_character *c, int instance, int primitive, const mlod_bgm_options *opt,
                           mlod_bgm **out, mlod_error *err);
void mlod_bgm_free(mlod_bgm *g);

typedef struct mlod_bgm_info {
	int vertices;          /* glTF vertices (wedges) of the input */
	int nodes;             /* welded positions */
	int triangles;         /* input triangles, degenerate ones dropped */
	int dropped;           /* degenerate input triangles dropped */
	int border_edges;
	int nonmanifold_edges; /* edges with more than two faces */
	int seam_nodes;        /* nodes with more than one wedge */
	int locked_nodes;
	int eligible_nodes;
	int collapses;         /* recorded so far */
	int live_triangles;    /* after all of them */
	int caps;              /* collapses whose v-bar had more than 4 influences */
	int snaps;             /* collapses that snapped v-bar to a seam or border vertex */
	int refused;           /* candidate collapses refused as invalid */
	double build_seconds;
	double collapse_seconds;
} mlod_bgm_info;

void mlod_bgm_get_info(const mlod_bgm *g, mlod_bgm_info *out);

/* Collapses triangles, cheapest first, until at most target triangles are
 * left (0: as far as validity allows) or max_collapses more (0: no
 * limit); every collapse is appended to the sequence. May be called again
 * to go further. */
mlod_result mlod_bgm_simplify(mlod_bgm *g, int target, int max_collapses, mlod_error *err);

/* One recorded triangle collapse, a vertex-split record: undoing it
 * removes faces added_first .. added_first + added_count - 1 and brings
 * back the faces it removed. */
typedef struct mlod_vsplit {
	int parents[3];     /* the collapsed nodes (parents[2] is -1 for an edge) */
	int parent_count;   /* 3: a triangle collapse; 2: an edge collapse */
	int node;           /* v-bar */
	int snapped;        /* v-bar is at parents[snapped], or -1 */
	int removed_first;  /* into mlod_bgm_removed_faces */
	int removed_count;
	int added_first;    /* face ids */
	int added_count;
	int triangles;      /* live triangles after it */
	int capped;         /* v-bar's influences were capped to 4 */
	double cost;
	double seconds;     /* collapse time spent on this BGM up to and including it */
} mlod_vsplit;

/* The sequence so far (valid until the next mlod_bgm_simplify), and the
 * faces each record removed. */
const mlod_vsplit *mlod_bgm_sequence(const mlod_bgm *g, int *count);
const int *mlod_bgm_removed_faces(const mlod_bgm *g);

/* The shortest prefix of the sequence that leaves at most target
 * triangles, or the whole sequence when none does. */
int mlod_bgm_prefix_for(const mlod_bgm *g, int target);

/* A budget shared by several primitives (beyond the paper): the prefixes
 * of n simplified BGMs (NULL entries are skipped, prefix 0) that bring
 * their live triangles down to at most target in all, taking over every
 * sequence the next collapse of lowest cost first. Meaningful with the
 * posed cost, whose costs are errors in one unit across primitives.
 * Returns the triangles left (more than target when the sequences end). */
long mlod_bgm_share_budget(mlod_bgm *const *bgms, int n, long target, int *prefix);

/* The mesh after the first `prefix` collapses as a primitive (release it
 * with mlod_primitive_free): original vertices keep their attributes;
 * new ones get interpolated attributes (per wedge), morph target offsets,
 * and at most 4 influences in set 0. A rigid mesh gets one weight set with
 * joint 0 weight 1 when rigid_as_skinned is set, none otherwise. Unused
 * vertices are dropped. */
mlod_result mlod_bgm_extract(const mlod_bgm *g, int prefix, int rigid_as_skinned, mlod_primitive *out,
                             mlod_error *err);

/* Triangles live after the first `prefix` collapses (0: the input). */
int mlod_bgm_triangles(const mlod_bgm *g, int prefix);

/* Checks the live mesh's internal consistency (dual graph symmetric,
 * incidence lists, manifold fans at every node that was not locked);
 * MLOD_ERR_PARSE names the first problem. For tests. */
mlod_result mlod_bgm_check(const mlod_bgm *g, mlod_error *err);

/* Maps a primitive's joint indices through map (map_count entries; old
 * joint -> new joint), merging influences that land on the same joint
 * (weights add up, so sums are unchanged) and writing them back into the
 * same weight sets, largest first. Returns MLOD_ERR_INVALID_ARG when a
 * weighted joint is outside map (the vertices before it are already
 * remapped: check first when that matters). */
mlod_result mlod_primitive_remap_joints(mlod_primitive *p, const int *map, int map_count, mlod_error *err);



#ifdef __cplusplus
}
#endif

#endif /* MLOD_MESH_H */
