/*
 * bgm.h: the BindGraphMesh as the mesh layer's files share it (bgm.c
 * builds it, quadric.c gives its posed quadrics, collapse.c simplifies
 * it with the files collapse.h names, bgmlevel.c turns prefixes into primitives). Internal: not installed,
 * not for tools.
 *
 * Storage is append-only, so that every prefix of the collapse sequence
 * can be rebuilt: a collapse kills faces (death = its record number + 1)
 * and appends faces, wedges and one node; a face is live after prefix k
 * when birth <= k < death.
 */
#ifndef MLOD_BGM_H
#define MLOD_BGM_H

#include <limits.h>
#include <stddef.h>

#include "mesh/mlod_mesh.h"

#define BGM_ALIVE INT_MAX
#define BGM_RQUAD 11 /* doubles per node in mlod_bgm.rquad */

/* Node flags. */
enum {
	BGM_BORDER = 1,    /* on an edge with one face */
	BGM_LOCKED = 2,    /* never collapses: non-manifold or otherwise unsafe */
	BGM_ELIGIBLE = 4,  /* 4.2.2 allows it to disappear */
	BGM_DEAD = 8       /* collapsed into a newer node */
};

typedef struct bgm_face {
	int w[3];   /* corner wedges, in winding order */
	int n[3];   /* their nodes */
	int adj[3]; /* dual graph: the face across edge (n[e], n[(e + 1) % 3]), or -1 */
	int birth;  /* 0 for input faces, else the record number + 1 that made it */
	int death;  /* BGM_ALIVE, or the record number + 1 that removed it */
} bgm_face;

typedef struct bgm_node {
	double p[3];        /* bind position (mesh space for rigid meshes) */
	int flags;
	int inc_first;      /* incident live faces: inc[inc_first .. +inc_count] */
	int inc_count;
	int inc_cap;
} bgm_node;

/* Wedge attribute layout, in floats (offsets are -1 when absent). */
typedef struct bgm_layout {
	int normal;         /* 3 */
	int tangent;        /* 4 */
	int uv[MLOD_MAX_SETS];    /* 2 each */
	int color[MLOD_MAX_SETS]; /* 4 each */
	int target_normal;  /* 3 per target, target t at target_normal + 3 t */
	int target_tangent; /* 3 per target */
	int stride;
	int morph_stride;   /* node floats: 3 per target with positions, else 0 */
} bgm_layout;

struct mlod_bgm {
	/* The input. */
	const mlod_primitive *prim;
	int skinned;            /* weights come from the primitive */
	int rigid;              /* one joint with weight 1 (a rigid mesh under a joint) */
	int joint_count;        /* influence ids: skin joints, 1 when rigid, 0 when static */
	int *joint_map;         /* influence id -> skeleton joint */
	mlod_bgm_options opt;   /* with defaults filled in */
	double tau;
	double *eta;            /* per skeleton joint */
	int skeleton_joints;
	double diagonal;        /* of the nodes at pose 0 (bgm_quadrics_build; 0 without quadrics) */
	bgm_layout lay;

	/* Nodes, wedges, faces (append-only). */
	int node_count, node_cap;
	int node_aux_cap;       /* capacity of inf and morph */
	int quadric_cap;        /* rows of quadric and rquad (the nodes at bgm_quadrics_build) */
	bgm_node *nodes;
	mlod_influences *inf;   /* per node */
	float *morph;           /* per node, lay.morph_stride floats */
	int wedge_count, wedge_cap;
	int *wedge_node;
	int *wedge_source;      /* input vertex, or -1 for a new wedge */
	float *wedge_attr;      /* lay.stride floats per wedge */
	int face_count, face_cap;
	bgm_face *faces;
	int *inc;               /* the incidence pool */
	int inc_len, inc_cap;
	int live_triangles;

	/* The sequence. */
	int record_count, record_cap;
	mlod_vsplit *records;
	int *removed;
	int removed_len, removed_cap;

	/* Posed quadrics (quadric.c): pose_count poses, of which qpose_count
	 * are stored: a pose whose used skin matrices are bit for bit an
	 * earlier pose's has that pose's quadrics, for every node (qmap: pose
	 * -> stored pose, in order of first use; qpose: stored pose -> its
	 * pose). Per node qpose_count x 10 doubles, laid out as bgm_qat says
	 * (stored poses in pairs, side by side); a sum over poses takes each
	 * pose's stored pose's term, in pose order. Per pose and influence id
	 * a 3x4 skin matrix (row-major). */
	int pose_count;
	int qpose_count;
	int *qmap;
	/* Per node, its row of quadric and rquad. A collapse's new node takes
	 * its first parent's row: the parents are dead, and nothing reads a
	 * dead node's quadrics, so the rows never outnumber the nodes at
	 * bgm_quadrics_build (at 1M triangles 23% less peak memory than a
	 * row per node ever made: bench/RESULTS.md Run 118). */
	int *qslot;
	int qslot_cap;          /* capacity (nodes) of qslot */
	int released;           /* bgm_release_collapse_state ran: no more collapses */
	int *qpose;
	double *quadric;
	float *skin;
	double *rquad;          /* per node BGM_RQUAD doubles: its posed quadrics pulled back
	                         * into bind space with its influences (bgm_quadric_pullback;
	                         * NaN first until bgm_quadric_rest needs them), then the sum
	                         * over poses of their traces */
	double *skin2;          /* the skin matrices as doubles, two stored poses side by
	                         * side: per pair of stored poses (2i, 2i + 1) and influence
	                         * id, 12 entries of 2 doubles (2i, then 2i + 1);
	                         * qpose_count / 2 pairs, then for a last odd one a block
	                         * with it in both lanes; NULL when there is one pose or for
	                         * a mesh without influences */
	double *qsum;           /* the collapse's scratch: one plan's summed quadrics */
	double pose0[12];       /* pose 0's skin matrix, every influence's (3x4, row-major) */
	double pose0_cof[9];    /* its linear part's cofactors (row-major): n -> the posed n */
	int pose0_mapped;       /* pose0 is not the identity (0 without quadrics) */
	double skin_norm;       /* lowerbound.c: the largest Frobenius norm of a skin matrix's
	                         * linear part, 0 until worked out */

	/* Statistics. */
	int input_vertices, input_triangles, dropped, border_edges, nonmanifold_edges;
	int seam_nodes, locked_nodes, eligible_nodes;
	int caps, snaps, refused;
	double build_seconds, collapse_seconds;

	/* Collapse state (collapse.c): the queue of candidate collapses, a
	 * 4-ary heap of entries whose layout only collapse.c knows. */
	struct bgm_heap {
		int ready;                 /* every live face was queued */
		int count, cap;
		struct bgm_heap_entry *e;  /* released with free() by mlod_bgm_free */
		struct bgm_memo *memo;     /* queued operations' exact placement costs (collapse.h);
		                            * released with free() by mlod_bgm_free */
		int memo_count, memo_cap, memo_free;
		int dead;                  /* entries of faces that died since (about: a purge trigger) */
		int unordered;             /* a NaN key was queued: never purged (the order is then
		                            * not total, and the heap's shape matters) */
		int no_purge;              /* never purged (set by test_bgm, which checks that a purge
		                            * leaves the collapses as they were) */
		int purges;                /* how many times it was */
	} heap;
	int swept;              /* collapse.c: record_count when every live face was last queued */
	int border_phase;       /* collapse.c: border vertices may collapse (the compactness
	                         * cost without opt.allow_border: once nothing else could) */
	unsigned char *opstate; /* per face and op (collapse.h): refused when last looked at, queued */
	int opstate_cap;
	double *ftie;           /* per face (collapse.h): its compactness tie-break term, NaN until
	                         * worked out (a face's nodes never change) */
	double *fgeo;           /* per face (collapsecost.c): bgm_face_normal, its length (NaN until
	                         * worked out) and bgm_compactness, 5 doubles */
	double *fref;           /* per face (collapsecost.c): its reference normal and that normal's
	                         * length (NaN until worked out), 4 doubles: an input face's own,
	                         * a new face's that of the face it replaced */
	int ftie_cap;           /* of ftie, fgeo and fref */
	/* lowerbound.c: the weak queue keys' bounds by collapsed nodes (a pure
	 * function of them: an edge or triangle whose faces died and came
	 * back around a collapse is not worked out again); open addressing,
	 * released with free() by mlod_bgm_free. */
	struct bgm_lbmemo *lbmemo;
	int lbmemo_count, lbmemo_cap;
};

/* bgm.c */
int bgm_grow(void **p, int *cap, int need, size_t size);
int bgm_add_node(mlod_bgm *g);
int bgm_add_wedge(mlod_bgm *g, int node);
int bgm_add_face(mlod_bgm *g, const int *w, int birth);
int bgm_inc_add(mlod_bgm *g, int node, int face);
void bgm_inc_remove(mlod_bgm *g, int node, int face);
double bgm_seconds(void);
/* Frees what only the collapses use (the posed quadrics and skin
 * matrices, the queue and its memos, the per-face cost caches), keeping
 * the nodes, wedges, faces and the sequence that mlod_bgm_extract, the
 * prefixes and the budget read: for a chain that is final, whose
 * mlod_bgm_simplify is never called again (mlod_mesh_levels' parts, once
 * their collapses are over). On the 470k-triangle tubeman this is about
 * two thirds of the memory mlod-bgm holds at the end of the chain. */
void bgm_release_collapse_state(mlod_bgm *g);

/* Whether a triangles primitive has a triangle with three distinct
 * corners and a nonzero area: one without (indices all zero, or every
 * position the same point, say) has no surface to simplify or measure,
 * and mlod_bgm_build refuses it as unsupported. */
int bgm_has_triangle(const mlod_primitive *p);
/* Do the m directed edges from[i] -> to[i] (node ids) form one cycle, or
 * with path_ok one path? A link of more than 256 edges or with a
 * negative id is refused (0). */
int bgm_link_ok(const int *from, const int *to, int m, int path_ok);
double bgm_compactness(const double *a, const double *b, const double *c);
int bgm_node_eligible(const mlod_bgm *g, const mlod_influences *inf);
/* Whether two influence lists are the same: the same joints with the
 * same weights, in the same order (welding in bgm.c, the collapse's
 * placements). */
static inline int bgm_same_influences(const mlod_influences *x, const mlod_influences *y)
{
	if (x->count != y->count)
		return 0;
	for (int i = 0; i < x->count; i++)
		if (x->joints[i] != y->joints[i] || x->weights[i] != y->weights[i])
			return 0;
	return 1;
}

/* The two-pose helpers of quadric.c and the collapse files: inlined where
 * they are used (called from more than one place, gcc would otherwise
 * call them, their vectors passed through memory). */
#if defined(__GNUC__)
#define BGM_INLINE static inline __attribute__((always_inline))
#else
#define BGM_INLINE static inline
#endif

/* quadric.c */
/* Where entry e (0-9) of stored pose p is among a node's P x 10 posed
 * quadric doubles (P = qpose_count): stored poses 2i and 2i + 1 side by
 * side, entry e of pair i at 20 i + 2 e (2i) and 20 i + 2 e + 1
 * (2i + 1), so that the two-pose sums load a pair's entries straight; a
 * last odd one's 10 entries after the pairs, in order. */
static inline size_t bgm_qat(int P, int p, int e)
{
	return p < (P & ~1) ? 20 * (size_t)(p >> 1) + 2 * (size_t)e + (size_t)(p & 1) : 10 * (size_t)p + (size_t)e;
}
/* Pose p's 10 entries of the node quadrics q (P poses), in order. */
static inline void bgm_quadric_get(const double *q, int P, int p, double *out)
{
	for (int e = 0; e < 10; e++)
		out[e] = q[bgm_qat(P, p, e)];
}
/* n = (b - a) x (c - a): the face's normal times twice its area. */
void bgm_face_normal(const double *a, const double *b, const double *c, double *n);
mlod_result bgm_quadrics_build(mlod_bgm *g, const mlod_character *c, const mlod_instance *in, mlod_error *err);
/* The error of a node at bind position p with influences inf against
 * the quadrics q (qpose_count x 10, as bgm_qat lays them out): sum over poses; HUGE_VAL as soon as
 * the partial sum reaches stop (HUGE_VAL: never). */
double bgm_quadric_error(const mlod_bgm *g, const double *q, const mlod_influences *inf, const double *p,
                         double stop);
/* bgm_quadric_error, and when it stops, the partial sum that reached stop
 * in *reached (not NULL): the terms are +0 or above and summed in one
 * order, so any stop at or below it stops that sum too. */
double bgm_quadric_error_reach(const mlod_bgm *g, const double *q, const mlod_influences *inf, const double *p,
                               double stop, double *reached);
/* h (10 doubles) = sum over poses of M_p^T Q_p M_p, M_p the pose's skin
 * matrix blended for inf: the posed quadrics q pulled back into bind
 * space (DeCoro & Rusinkiewicz 2005), exact for a node that keeps inf. */
void bgm_quadric_pullback(const mlod_bgm *g, const double *q, const mlod_influences *inf, double *h);
/* Node v's rquad, its pulled-back quadric computed on first use. */
const double *bgm_quadric_rest(mlod_bgm *g, int v);
/* Sets node v's trace sum and marks its pulled-back quadric for
 * computing (a new node, its quadrics summed). */
void bgm_quadric_rest_reset(mlod_bgm *g, int v);
/* A packed quadric's value at x, clamped at 0 (inline: the queue's keys
 * and plan() call it for every candidate). */
static inline double bgm_quadric_eval(const double *q, const double *x)
{
	double v = q[0] * x[0] * x[0] + 2 * q[1] * x[0] * x[1] + 2 * q[2] * x[0] * x[2] + 2 * q[3] * x[0] +
	           q[4] * x[1] * x[1] + 2 * q[5] * x[1] * x[2] + 2 * q[6] * x[1] + q[7] * x[2] * x[2] + 2 * q[8] * x[2] + q[9];
	return v > 0.0 ? v : 0.0;
}
/* The minimiser of the packed quadric h (directions it leaves free stay
 * at x0); returns 0 and fills out, or -1. */
int bgm_quadric_solve(const double *h, const double *x0, double *out);
/* The bind position minimising that error with inf fixed (directions the
 * quadric leaves free stay at x0); returns 0 and fills out, or -1. */
int bgm_quadric_optimum(const mlod_bgm *g, const double *q, const mlod_influences *inf, const double *x0,
                        double *out);

#endif
