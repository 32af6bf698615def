/*
 * collapse.h: internal to the collapse files of lib/mesh (bgm.h has the
 * BindGraphMesh they work on). The collapse sequence (mlod_bgm_simplify)
 * is made by these files, each calling only those below it:
 *
 *   collapse.c       the queue, a 4-ary heap of operations, and its loop:
 *                    operations queued, popped, planned, applied or put
 *                    back
 *   collapseapply.c  a planned collapse applied: the patch re-meshed
 *                    around v-bar, its wedges, the record
 *   lowerbound.c     lower bounds of an operation's posed cost, the keys
 *                    the queue waits on before planning it
 *   collapseplan.c   an operation worked out: its patch, the validity
 *                    checks and the cheapest valid placement
 *   collapsecost.c   what the plan and the bounds share: per-face
 *                    geometry, summed quadrics, Power Skinning by role
 *
 * Helpers that the plan and the bounds both call in their inner loops
 * are static inline here (the build is -O2 without LTO).
 */
#ifndef MLOD_COLLAPSE_H
#define MLOD_COLLAPSE_H

#include <math.h>

#include "bgm.h"

#define MAX_PATCH 128       /* faces around a, b and c */
#define MAX_WEDGES 64       /* distinct wedges of a, b and c in the patch */
#define MAX_CANDIDATES 8
#define TIE_WEIGHT 1e-5     /* compactness tie-break of the posed cost */
#define BORDER_PENALTY 50.0 /* posed cost factor of a collapse along a border (measured:
                             * bench/RESULTS.md, the mesh layer's floor) */

/* An operation on a face: collapse the triangle, or one of its edges. */
#define OP_TRIANGLE 3       /* ops 0..2: the edge (n[op], n[(op + 1) % 3]) */
#define BLOCKED(op) (1u << (op))       /* opstate: refused when last planned */
#define QUEUED(op) (16u << (op))       /* opstate: has an entry in the heap */
#define ALL_BLOCKED 15u
/* opstate of a dead face: its queue entries are dropped when popped
 * (read here rather than the face's death, a cache miss in a large
 * mesh). No live face has every bit: an op is never both blocked and
 * queued. */
#define DEAD 255u

/* What the exact posed cost of an operation's placements came to. It
 * depends only on the collapsed vertices (quadrics, positions and
 * influences, fixed while the face lives), not on the patch, so an
 * operation back in the queue keeps it for its next bound or plan.
 * Placements by role: 0 the optimum, 1 + i vertex i, 4 the barycenter,
 * 5 + i vertex i kept whole (hybrid placement: its own influences). */
#define MEMO_ROLES 8
#define MEMO_WSUM (1u << MEMO_ROLES)
#define MEMO_SKINNED 5        /* roles 0-4: placements Power Skinning weighs */
typedef struct bgm_memo {
	double opt[3];
	int opt_state;              /* 0 not worked out, 1 found, 2 none */
	unsigned known;             /* bit r: e[r] holds role r's full sum; MEMO_WSUM: wsum */
	unsigned stopped;           /* bit r: role r's sum stopped early, its partial sum then in ge[r] */
	double e[MEMO_ROLES];
	double ge[MEMO_ROLES];
	double wsum;
	int next_free;
	unsigned skinned;           /* bit r: w[r] and capped[r] are role r's Power Skinning */
	unsigned char capped[MEMO_SKINNED];
	mlod_influences w[MEMO_SKINNED];
} bgm_memo;

/* Everything a collapse needs, worked out by bgm_plan_op() and applied by
 * bgm_apply(). */
typedef struct bgm_plan {
	int t, op;                  /* face t, OP_TRIANGLE or the edge */
	int k;                      /* 3 (a, b, c) or 2 (the edge a, b) */
	int v[3];                   /* a, b, c (v[2] = -1 for an edge) */
	int nf, faces[MAX_PATCH];   /* the patch */
	int nr, removed[MAX_PATCH]; /* faces with two or more of a, b, c */
	int nk, kept[MAX_PATCH];    /* the others, re-meshed around v-bar */
	int corner[MAX_PATCH];      /* the corner of kept[i] that becomes v-bar */
	double onormal[MAX_PATCH][4]; /* kept[i]'s normal, then its length */
	double rnormal[MAX_PATCH][4]; /* kept[i]'s reference normal (face_ref), then its length */
	unsigned char oflip[MAX_PATCH]; /* kept[i] is not degenerate: it may not flip */
	int nw, wedges[MAX_WEDGES], group[MAX_WEDGES], ngroups;
	int src[MAX_PATCH];         /* vertex placement: the wedge of v[snap] kept[i]'s corner copies */
	/* The chosen placement. */
	double pos[3];
	int snap;                   /* 0..2: v-bar at v[snap]; -1: free */
	int whole;                  /* v-bar is v[snap] kept whole (wedges src[], its influences) */
	int hard[3];                /* a, b, c have hard normal edges */
	double lambda[3];           /* attribute and morph weights of a, b, c */
	mlod_influences inf;
	int capped;
	double cost;
} bgm_plan;

/* collapsecost.c: what the plan and the queue's bounds both price a
 * collapse with. */
/* Grows the per-face arrays (opstate, ftie, fgeo, fref) to face_cap;
 * -1 when out of memory. */
int bgm_face_arrays_grow(mlod_bgm *g);
/* Face h's bgm_face_normal (0-2), its length (3) and its compactness (4). */
const double *bgm_face_geo(mlod_bgm *g, int h);
/* The collapsed vertices' posed quadrics summed per pose into Q. */
void bgm_sum_quadrics(const mlod_bgm *g, const bgm_plan *pl, double *Q);
/* mlod_power_skin of the collapsed vertices at x for placement role, as
 * mm remembers it (mm may be NULL); returns whether it capped. */
int bgm_skin_role(bgm_memo *mm, int role, const mlod_v3 *V, const mlod_influences *in3, int K, const double *x,
                  mlod_influences *w);

/* collapseplan.c: works out operation op on face t (its triangle
 * collapse, or the collapse of one of its edges); 1 when it is valid (pl
 * holds the cheapest valid placement), else 0. With exact, the posed
 * cost of each placement with its own weights, through mm (may be NULL). */
int bgm_plan_op(mlod_bgm *g, int t, int op, int exact, bgm_plan *pl, bgm_memo *mm);

/* lowerbound.c: lower bounds of bgm_plan_op's cost, from the quadrics
 * alone: a queue key (*weak: a bind-pose bound, bgm_exact_bound comes
 * next), and the least exact cost over every placement. */
double bgm_lower_key(mlod_bgm *g, int f, int op, int *weak);
double bgm_exact_bound(mlod_bgm *g, int f, int op, bgm_memo *mm);

/* collapseapply.c: applies a planned collapse; 0, or -1 when out of
 * memory. */
int bgm_apply(mlod_bgm *g, bgm_plan *pl);

/* The index of wedge w among the patch's wedges (pl->wedges), or -1. */
static inline int bgm_wedge_slot(const bgm_plan *pl, int w)
{
	for (int i = 0; i < pl->nw; i++)
		if (pl->wedges[i] == w)
			return i;
	return -1;
}

/* Whether float k of a wedge's attributes is a normal's (its own or a
 * morph target's). */
static inline int bgm_is_normal_float(const bgm_layout *L, int k, int targets)
{
	return (L->normal >= 0 && k >= L->normal && k < L->normal + 3) ||
	       (L->target_normal >= 0 && k >= L->target_normal && k < L->target_normal + 3 * targets);
}

/* Face h's area times its lack of compactness (sqrt(area_sq) from its
 * normal: area_sq's arithmetic). */
BGM_INLINE double bgm_face_tie(mlod_bgm *g, int h)
{
	double *t = &g->ftie[h];
	if (isnan(*t)) {
		const double *o = bgm_face_geo(g, h);
		if (g->pose0_mapped) {
			/* its area at pose 0, in the units of the posed cost */
			const double *C = g->pose0_cof;
			double n[3];
			for (int i = 0; i < 3; i++)
				n[i] = C[3 * i] * o[0] + C[3 * i + 1] * o[1] + C[3 * i + 2] * o[2];
			*t = sqrt(0.25 * (n[0] * n[0] + n[1] * n[1] + n[2] * n[2])) * (1.0 - o[4]);
		} else {
			*t = sqrt(0.25 * (o[0] * o[0] + o[1] * o[1] + o[2] * o[2])) * (1.0 - o[4]);
		}
	}
	return *t;
}

/* The tie-break term of a collapse: the collapsed triangle's area times
 * its lack of compactness, or for an edge the mean over its faces. */
BGM_INLINE double bgm_collapse_tie(mlod_bgm *g, int f, int op, int K)
{
	if (K == 3)
		return bgm_face_tie(g, f);
	const bgm_face *F = &g->faces[f];
	int faces[2] = {f, F->adj[op]}, nr = faces[1] >= 0 ? 2 : 1;
	double tie = 0.0;
	for (int j = 0; j < nr; j++)
		tie += bgm_face_tie(g, faces[j]) / nr;
	return tie;
}

/* Whether a placement stays near the collapsed vertices P[0..K-1]: at
 * most their longest edge from the barycenter (K == 2: the one edge). */
BGM_INLINE int bgm_near_collapsed(const double *const P[3], int K, const double bary[3], const double opt[3])
{
	double lmax = 0.0, d = 0.0;
	for (int e = 0; e < (K == 3 ? 3 : 1); e++) {
		double l = 0.0;
		for (int i = 0; i < 3; i++)
			l += (P[e][i] - P[(e + 1) % K][i]) * (P[e][i] - P[(e + 1) % K][i]);
		lmax = fmax(lmax, l);
	}
	for (int i = 0; i < 3; i++)
		d += (opt[i] - bary[i]) * (opt[i] - bary[i]);
	return d <= lmax;
}

/* Whether collapses may move and remove border vertices: with the posed
 * cost or mlod_bgm_options.allow_border from the start, else (the
 * compactness cost, which cannot rank them) once nothing else collapses
 * (mlod_bgm_simplify's border phase). */
static inline int bgm_borders_ok(const mlod_bgm *g)
{
	return g->opt.allow_border || g->border_phase || g->opt.cost == MLOD_COST_POSED;
}

/* What a collapse along a border costs, times its posed cost:
 * BORDER_PENALTY unless mlod_bgm_options.allow_border ranks it like any
 * other. */
static inline double bgm_border_factor(const mlod_bgm *g)
{
	return g->opt.allow_border ? 1.0 : BORDER_PENALTY;
}

/* The optimal placement's candidates are tried (MLOD_PLACE_HYBRID too). */
static inline int bgm_optimal_like(const mlod_bgm *g)
{
	return g->opt.placement == MLOD_PLACE_OPTIMAL || g->opt.placement == MLOD_PLACE_HYBRID;
}

#endif
