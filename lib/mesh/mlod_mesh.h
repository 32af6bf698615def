/*
 * mlod_mesh.h: the mesh layer (paper 4.2): the BindGraphMesh, triangle and edge
 * collapses, Power Skinning, progressive levels, and the level policy of
 * mlod-bgm: levels by ratio or down to an error bound, following the
 * skeleton levels, written under MSFT_lod or one document per level. The
 * stage record they leave is lib/record's.
 */
#ifndef MLOD_MESH_H
#define MLOD_MESH_H

#include "model/mlod_model.h"
#include "io/mlod_io.h"
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

/* Where v-bar goes. Next to a texture seam it always snaps to a seam
 * vertex (a border vertex when a border is involved), so that textures
 * neither tear nor smear; a collapse moving a border vertex puts v-bar on
 * a border vertex or the midpoint of a border edge. */
typedef enum mlod_placement {
	MLOD_PLACE_DEFAULT = 0, /* OPTIMAL with the posed cost (measured), BARYCENTER with compactness (the paper) */
	MLOD_PLACE_BARYCENTER,  /* the paper: the triangle's barycenter */
	MLOD_PLACE_OPTIMAL,     /* beyond the paper: the minimum of the posed quadric (or the barycenter when lower) */
	MLOD_PLACE_VERTEX,      /* one of the collapsed vertices, kept whole (attributes and influences as it has
	                         * them, no Power Skinning): coarse levels reuse level-0 vertices */
	MLOD_PLACE_HYBRID       /* per collapse, VERTEX's cheapest whole vertex when its posed cost is at most
	                         * OPTIMAL's or within hybrid_error, else OPTIMAL's candidates; the nodes'
	                         * influences are read as VERTEX reads them (as stored, not merged or
	                         * normalised), so the free placements' blends can differ from OPTIMAL's on
	                         * inputs with two weight sets or unnormalised weights (posed cost only:
	                         * with compactness it resolves to OPTIMAL) */
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
	double hybrid_error;         /* MLOD_PLACE_HYBRID: a whole vertex is also kept when its posed cost
	                              * (a mean squared distance over the patch and the poses) is at most
	                              * the square of this percentage of the diagonal; 0 means
	                              * MLOD_MESH_HYBRID_ERROR */
	int allow_border;            /* collapses along a border rank at their plain posed cost
	                              * (default: 50 times it), and with the compactness cost border
	                              * collapses start at once (default: once nothing else does) */
	int fast_cost;               /* posed cost: every pose's quadrics pulled back into bind
	                              * space with each vertex's own influences (DeCoro &
	                              * Rusinkiewicz 2005), not skinned with each placement's:
	                              * faster, at some posed error (bench/RESULTS.md) */
	const mlod_pose_set *poses;  /* the posed cost's poses; NULL: the bind pose only */
	const double *eta;           /* per joint (mlod_joint_weight_average); NULL: computed */
	int threads;                 /* mlod_mesh_levels: primitives and measured poses on this many
	                              * threads (0 or 1: the caller's); the same levels at any count */
	double influence_budget;     /* mlod_mesh_levels_by_ratio: each level's skinned vertices drop
	                              * influences while they move at most this fraction of the level's
	                              * mean posed error at every training pose; 0: the default
	                              * MLOD_MESH_INFLUENCE_BUDGET; negative: off */
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
/* Replaces the DEFAULT cost, placement, collapse and eligibility with what
 * they stand for (the cost first: posed; then optimal, edge, all; with the
 * compactness cost barycenter, triangle, bend): the one place these
 * defaults are set, for mlod_bgm_build and mlod_mesh_resolve. */
void mlod_bgm_options_resolve(mlod_bgm_options *opt);
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
	int snaps;             /* collapses that snapped v-bar to a texture seam's vertex, keeping
	                        * its wedges (a border vertex with the seam on a border) */
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


/* ------------------------------------------------------------------ */
/* Mesh levels: the policy (meshlevels.c) and their glTF output (lodgltf.c) */
/* ------------------------------------------------------------------ */

/* The defaults of mlod-bgm: levels keeping these fractions of the
 * triangles; under a --max-error, levels halving the triangles down to
 * MLOD_MESH_MIN_RATIO, the last found by MLOD_MESH_BISECTIONS halvings.
 * The posed cost trains on clip frames and MLOD_MESH_RANDOM_POSES random
 * poses (seed MLOD_MESH_TRAIN_SEED, joints turned up to
 * MLOD_MESH_RANDOM_ANGLE radians); the error is measured on the rest pose,
 * clip frames and as many other random poses (seed
 * MLOD_MESH_MEASURE_SEED). */
#define MLOD_MESH_RATIOS_DEFAULT 0.5, 0.25, 0.1, 0.03
/* Influence pruning of the levels (mlod_bgm_options.influence_budget): a
 * level's skinned vertex loses its smallest influences (the weight spread
 * over the others, or given to one of them, whichever moves it least)
 * while it moves at most this fraction of the level's mean posed error, at
 * every training pose; the level is then measured again, and when its
 * Hausdorff error rose, pruned anew under half and a quarter of that,
 * else left as it was. 0: off by default (measured, bench/RESULTS.md: 2
 * skins 3-17% fewer instructions far away at about a quarter more bake
 * time, the levels measured again). */
#define MLOD_MESH_INFLUENCE_BUDGET 0.0
/* MLOD_PLACE_HYBRID's default hybrid_error, in percent of the diagonal
 * (bench/RESULTS.md, the hybrid placement's sweep). */
#define MLOD_MESH_HYBRID_ERROR 0.1
#define MLOD_MESH_MAX_LEVELS 16
#define MLOD_MESH_MIN_RATIO (1.0 / 256)
#define MLOD_MESH_BISECTIONS 6
#define MLOD_MESH_RANDOM_POSES 8
/* Past this many clips, the training and measuring poses come from this
 * many of them, evenly spaced (2 frames each): a pose holds a posed copy of
 * the mesh (about 64 bytes per triangle). */
#define MLOD_MESH_MAX_POSE_CLIPS 16
#define MLOD_MESH_RANDOM_ANGLE 0.69813170f /* 40 degrees */
#define MLOD_MESH_TRAIN_SEED 1
#define MLOD_MESH_MEASURE_SEED 2008

/* Whose triangles a level's ratio counts. */
typedef enum mlod_mesh_budget {
	MLOD_BUDGET_DEFAULT = 0, /* CHARACTER with the posed cost (measured), PRIMITIVE with compactness */
	MLOD_BUDGET_CHARACTER,   /* all simplified primitives together, cheapest collapses first (posed cost only) */
	MLOD_BUDGET_PRIMITIVE    /* each primitive keeps the ratio */
} mlod_mesh_budget;

/* Names as the tools spell them ("posed", "edge", "character", ...). */
const char *mlod_mesh_cost_name(mlod_mesh_cost c);
const char *mlod_mesh_op_name(mlod_collapse_op op);
const char *mlod_mesh_budget_name(mlod_mesh_budget b);
const char *mlod_mesh_placement_name(mlod_placement p);
/* Parses a placement name: barycenter, optimal, vertex, hybrid or
 * hybrid=PCT (hybrid_error PCT, above 0 and at most 100); sets *p and,
 * for hybrid, *error (0: the default). Returns 0, or -1 for anything
 * else. */
int mlod_mesh_placement_parse(const char *s, mlod_placement *p, double *error);
const char *mlod_mesh_eligibility_name(mlod_eligibility e);

/* Replaces the DEFAULT values with what they stand for
 * (mlod_bgm_options_resolve, then the budget, tau, the hybrid share and
 * the influence budget), as the BGM and the levels use them. */
void mlod_mesh_resolve(mlod_bgm_options *opt, mlod_mesh_budget *budget);

/* The triangle primitives (mode 4) of the character's instances. */
int mlod_mesh_triangle_primitives(const mlod_character *c);
/* Whether a mesh has a triangle list with a triangle of three distinct
 * corners and a nonzero area: one the mesh layer simplifies (the others
 * are left as they are). */
int mlod_mesh_has_surface(const mlod_mesh *m);

/* One level of the whole character. */
typedef struct mlod_mesh_level {
	double ratio;            /* requested, or found under a bound */
	mlod_mesh *meshes;       /* one per instance */
	unsigned char **owned;   /* per instance and primitive: extracted (else the input's) */
	int *skins;              /* per instance: the glTF skin of its skinned level mesh (mlod_mesh_levels_follow) */
	mlod_character view;     /* the character with these meshes */
	int triangles, vertices, caps, collapses;
	double collapse_seconds;
	mlod_deviation error;    /* posed error, % of the bounding diagonal */
} mlod_mesh_level;

/* What a mesh level follows of skeleton level k (from the stage record:
 * mlod_record_mesh_skeleton). */
typedef struct mlod_mesh_skeleton {
	int skin_count;
	const int *skins;        /* the glTF skin standing for each skin of the character, -1: none */
	int remap_count;
	const int *remap_from;   /* a removed joint's node ... */
	const int *remap_to;     /* ... and its stand-in's node */
} mlod_mesh_skeleton;

typedef struct mlod_mesh_part mlod_mesh_part;

/* The levels of one character, finest first. */
typedef struct mlod_mesh_levels {
	const mlod_character *c;
	mlod_bgm_options opt;    /* resolved (mlod_mesh_resolve) */
	mlod_mesh_budget budget;
	mlod_pose_set train, measure;
	double *eta;
	mlod_mesh_part **parts;  /* per instance, per primitive */
	int simplified;          /* primitives with a BGM */
	int statics;             /* of them, on no joint and no skin */
	int triangles, vertices; /* of the input */
	int degenerate;          /* input triangles with two corners at one position, in no level */
	double build_seconds;
	double measure_seconds;  /* measuring the levels' posed error (wall clock, all levels) */
	int chain_pending;       /* the one primitive's collapses wait for the levels' call */
	double chain_ratio;      /* init's min_ratio, for them */
	int count;
	mlod_mesh_level levels[MLOD_MESH_MAX_LEVELS];
	const mlod_mesh_skeleton *skeleton; /* followed skeleton levels (mlod_mesh_levels_follow) */
	int skeleton_count;
	char notes[2048];        /* what was done, "; "-separated, for reports */
} mlod_mesh_levels;

/* Builds the BGM of every triangle primitive of c (which must outlive L)
 * and records its collapses down to min_ratio of its triangles (0, or the
 * character budget: as far as they go). With opt->threads >= 2 and one
 * primitive to simplify, its collapses are left to
 * mlod_mesh_levels_by_ratio or _by_error (the same sequence): by_ratio
 * then measures each level on the other threads while the collapses go on
 * to the next. Once a primitive's collapses are over, what only they use
 * (its posed quadrics, queue and cost caches) is freed; and once
 * by_ratio or by_error has measured the levels, so is the full character
 * posed at every measuring pose (a later call poses it again). */
mlod_result mlod_mesh_levels_init(mlod_mesh_levels *L, const mlod_character *c, const mlod_bgm_options *opt,
                                  mlod_mesh_budget budget, double min_ratio, mlod_error *err);
void mlod_mesh_levels_free(mlod_mesh_levels *L);

/* Levels at these ratios (decreasing); a ratio that removes nothing more
 * is dropped with a note. */
mlod_result mlod_mesh_levels_by_ratio(mlod_mesh_levels *L, const double *ratios, int n, mlod_error *err);

/* Levels halving the triangles while the posed error stays within bound
 * (% of the diagonal); past it, the coarsest ratio within it
 * (mlod_level_search_run) ends the chain. */
mlod_result mlod_mesh_levels_by_error(mlod_mesh_levels *L, double bound, mlod_error *err);

/* Sums of the BGMs' figures (nodes, seams, borders, ...). */
void mlod_mesh_levels_totals(const mlod_mesh_levels *L, mlod_bgm_info *sum);

/* Mesh level k follows skeleton level min(k, count - 1): the level meshes
 * of skinned instances are remapped to its skin where every weighted
 * joint has a stand-in there, and rigid parts follow their joint's
 * stand-in. skeleton must outlive L. */
mlod_result mlod_mesh_levels_follow(mlod_mesh_levels *L, const mlod_mesh_skeleton *skeleton, int count,
                                    mlod_error *err);

/* The level nodes mlod_mesh_levels_write added. */
typedef struct mlod_mesh_lod {
	int count;
	int *node;               /* glTF node */
	int *level;              /* its mesh level, 0 for the finest */
	unsigned char *skeleton_level; /* its skin is a skeleton level's */
} mlod_mesh_lod;
void mlod_mesh_lod_free(mlod_mesh_lod *lod);

/* Writes the levels into doc, the document c was read from: each
 * simplified mesh node lists one node per level in MSFT_lod (coverage
 * from the errors: mlod_lod_coverage); level nodes use the node's skin or
 * the followed skeleton level's; rigid meshes become meshes skinned to
 * their joint with weight 1; static meshes keep the node's transform;
 * level nodes that keep morph targets get copies of the node's weight
 * animation channels. */
mlod_result mlod_mesh_levels_write(mlod_mesh_levels *L, mlod_gltf *doc, mlod_mesh_lod *out, mlod_error *err);

/* Level k on its own: a copy of input with each simplified node's mesh
 * replaced by the level's (skinned ones on the followed skeleton level's
 * skin, rigid and static ones where they hang), without the nodes'
 * MSFT_lod, the unused meshes pruned. *unpruned (0 at first, passed to
 * every call) is set, and a note added, when an extension kept the full
 * meshes. */
mlod_result mlod_mesh_levels_split(mlod_mesh_levels *L, const mlod_gltf *input, int k, mlod_gltf **out,
                                   int *unpruned, mlod_error *err);



#ifdef __cplusplus
}
#endif

#endif /* MLOD_MESH_H */
