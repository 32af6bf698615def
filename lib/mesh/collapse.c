/*
 * collapse.c: triangle decimation on the BindGraphMesh (Savoye & Meyer
 * 2008, 4.2.3), recorded as a progressive sequence.
 *
 * A triangle collapse contracts t = (a, b, c) into one new vertex v-bar:
 * t and the faces sharing an edge with it go (up to four), and the rest
 * of the mesh patch (the faces sharing a vertex with t) is re-meshed
 * around v-bar. Candidates wait in a priority queue: by compactness
 * 4 sqrt(3) area / (l1^2 + l2^2 + l3^2), lowest first (the paper), or by
 * the posed quadric error of quadric.c (beyond the paper, compactness
 * breaking ties); the faces a collapse creates join the queue.
 *
 * Beyond the paper, with the posed cost, the same machinery collapses an
 * edge (a, b) into v-bar: its two faces go and the rest of the patch is
 * re-meshed. A triangle collapse always merges three vertices into one
 * point, which costs something on any curved surface; an edge collapse
 * along a flat or straight direction costs nothing. Measured (bench/
 * RESULTS.md), edges alone give the lowest posed error, so they are the
 * posed cost's default; MLOD_OP_MIXED queues both, by cost per removed
 * face.
 *
 * The paper does not check validity; a collapse is refused when
 * - a collapsed vertex is locked or not eligible (4.2.2);
 * - two collapsed vertices are on a border but not joined by a border
 *   edge of t (the collapse would pinch the border), three are, or the
 *   border edge bounds a hole of three edges (it would close);
 * - the re-meshed patch would not be one fan around v-bar (the link
 *   condition generalised to a triangle: this also refuses duplicate
 *   faces and the closing of tunnels);
 * - a re-meshed face would be degenerate, turn in the bind pose by more
 *   than ~78 degrees from its current normal, or face more than 90
 *   degrees away from its reference (the normal of the input face it
 *   descends from: each re-meshed face stands for the face it replaces,
 *   so turns cannot add up over collapses to an inside-out face) or from
 *   the sum of its corners' NORMAL attribute (v-bar's as apply() makes
 *   it): what a renderer culls and shades;
 * - the attribute wedges of the patch cannot be carried over: at a
 *   texture seam (wedges differing in more than normals), v-bar snaps
 *   onto a seam (or, with a border, border) vertex s, and every wedge
 *   group (wedges joined through the removed faces) must hold exactly one
 *   wedge of s and at most one of each other vertex. Elsewhere v-bar gets
 *   one wedge interpolated inside t (along the edge), the corners of a
 *   vertex with hard normal edges keeping their own normals: every wedge
 *   of a flat-shaded vertex collapses the same way. So seams neither tear
 *   nor smear.
 * Open borders stay where they are: a collapse moving a border vertex
 * puts v-bar on a border vertex, or for an edge along the border also at
 * its midpoint, and the border planes of quadric.c price it. With the
 * posed cost a collapse along the border (two border vertices: the
 * border's shape changes) ranks with the rest at BORDER_PENALTY times its
 * cost (1 with mlod_bgm_options.allow_border); one whose only border
 * vertex stays put costs what it costs. The compactness cost, which
 * cannot price them, lets border collapses in only once nothing else
 * collapses. When the queue empties, every live face is queued once
 * more, so that the sequence ends where no valid collapse is left.
 * v-bar goes to t's barycenter (the paper) or to the posed quadric's
 * optimum (or the barycenter, or for an edge either end, when that is
 * cheaper), or with MLOD_PLACE_VERTEX to the cheapest of the collapsed
 * vertices that keeps every wedge group whole, snapped (its wedges and
 * influences copied as they are, so coarse levels reuse its vertices);
 * MLOD_PLACE_HYBRID weighs both per collapse: the cheapest whole vertex
 * when its posed cost is at most the cheapest other placement's, or at
 * most the square of hybrid_error percent of the diagonal (the cost being
 * a mean squared distance over the patch and the poses), else that other
 * placement (the collapse costing what the chosen placement costs);
 * otherwise Power Skinning
 * (powerskin.c) gives its weights, the same barycentric weights as its
 * attributes give its morph target offsets.
 *
 * Each collapse appends one vertex-split record (the faces it removed
 * and the faces it added), so any prefix of the sequence is a valid mesh
 * and can be rebuilt, undone or redone.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#ifdef __SSE2__
#include <emmintrin.h>
#endif

#include "bgm.h"

#define MAX_PATCH 128       /* faces around a, b and c */
#define MAX_WEDGES 64       /* distinct wedges of a, b and c in the patch */
#define MAX_CANDIDATES 8
#define FLIP_COS 0.2        /* a re-meshed face may turn by less than ~78 degrees */
#define REF_COS 0.0         /* and face less than 90 degrees away from its reference (78:
                             * the robot's 10% level 5.54% -> 10.19% Hausdorff, bench/RESULTS.md) */
#define DEGENERATE 1e-3     /* compactness under which a new face counts as degenerate */
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

/* A queued operation, as the heap hands it back. */
typedef struct heap_entry {
	double key;
	int face;
	int op;
	int weak;   /* key is lower_key's bind-pose bound: exact_bound comes next */
	int memo;   /* into heap.memo, or -1 */
} heap_entry;

/* As the heap stores it: 16 bytes, four children to a 64-byte line
 * (tag: op in bits 0-1, weak in bit 2, memo + 1 above). */
struct bgm_heap_entry {
	double key;
	int face;
	unsigned tag;
};

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
} memo;

/* mlod_power_skin of the collapsed vertices (V, in3) at x, placement
 * role's position (the same for the operation while its face lives), as
 * mm remembers it (when mm is not NULL). */
static int skin_role(memo *mm, int role, const mlod_v3 *V, const mlod_influences *in3, int K, const double *x,
                     mlod_influences *w)
{
	if (mm && role < MEMO_SKINNED && (mm->skinned >> role & 1u)) {
		*w = mm->w[role];
		return mm->capped[role];
	}
	int capped = mlod_power_skin(V, in3, K, (mlod_v3){(float)x[0], (float)x[1], (float)x[2]}, w);
	if (mm && role < MEMO_SKINNED) {
		mm->w[role] = *w;
		mm->capped[role] = (unsigned char)capped;
		mm->skinned |= 1u << role;
	}
	return capped;
}

/* A slot holding m; returns its index, or -1 when out of memory. */
static int memo_add(struct bgm_heap *h, const memo *m)
{
	int i = h->memo_free;
	if (i >= 0) {
		h->memo_free = h->memo[i].next_free;
	} else {
		if (bgm_grow((void **)&h->memo, &h->memo_cap, h->memo_count + 1, sizeof *h->memo))
			return -1;
		i = h->memo_count++;
	}
	h->memo[i] = *m;
	h->memo[i].next_free = -1;
	return i;
}

static void memo_release(struct bgm_heap *h, int i)
{
	if (i < 0)
		return;
	h->memo[i].next_free = h->memo_free;
	h->memo_free = i;
}

/* The queue's order: key, then face, then op (a total order, so the
 * operations come out in the same order whatever the heap's shape). */
static int entry_less(const struct bgm_heap_entry *a, const struct bgm_heap_entry *b)
{
	return a->key < b->key ||
	       (a->key == b->key && (a->face < b->face || (a->face == b->face && (a->tag & 3u) < (b->tag & 3u))));
}

/* A 4-ary heap: half the levels of a binary one, its entries' cache
 * misses being what a large mesh's collapses wait on. */
static int heap_push(struct bgm_heap *h, double key, int face, int op, int weak, int memo_slot)
{
	if (bgm_grow((void **)&h->e, &h->cap, h->count + 1, sizeof *h->e))
		return -1;
	int i = h->count++;
	struct bgm_heap_entry x = {key, face, (unsigned)op | (weak ? 4u : 0u) | (unsigned)(memo_slot + 1) << 3};
	if (isnan(key))
		h->unordered = 1;
	while (i > 0) {
		int p = (i - 1) / 4;
		if (!entry_less(&x, &h->e[p]))
			break;
		h->e[i] = h->e[p];
		i = p;
	}
	h->e[i] = x;
	return 0;
}

/* Puts x at slot i of the 4-ary heap or below it, moving the least
 * child up while it is less than x. */
static void sift_down(struct bgm_heap *h, int i, struct bgm_heap_entry x)
{
	const int n = h->count;
	for (;;) {
		int c = 4 * i + 1, m = c;
		if (c >= n)
			break;
		int end = c + 4 < n ? c + 4 : n;
		for (int j = c + 1; j < end; j++)
			if (entry_less(&h->e[j], &h->e[m]))
				m = j;
		if (!entry_less(&h->e[m], &x))
			break;
		h->e[i] = h->e[m];
		i = m;
	}
	h->e[i] = x;
}

static heap_entry heap_pop(struct bgm_heap *h)
{
	struct bgm_heap_entry t = h->e[0], x = h->e[--h->count];
	if (h->count > 0)
		sift_down(h, 0, x);
	heap_entry top = {t.key, t.face, (int)(t.tag & 3u), (int)(t.tag >> 2 & 1u), (int)(t.tag >> 3) - 1};
	return top;
}

/* Drops the entries of dead faces (what heap_pop's callers would drop
 * when they come up) and rebuilds the heap from the rest. Entries are
 * one per face and op and entry_less orders them totally (no NaN key
 * was queued), so the live entries come out in the same order as
 * before; a dead entry popped costs a walk down the heap, this one pass
 * over it. */
static void heap_purge(struct bgm_heap *h, const unsigned char *opstate, unsigned char dead)
{
	int n = 0;
	for (int i = 0; i < h->count; i++) {
		if (opstate[h->e[i].face] == dead) {
			memo_release(h, (int)(h->e[i].tag >> 3) - 1);
			continue;
		}
		h->e[n++] = h->e[i];
	}
	h->count = n;
	h->dead = 0;
	h->purges++;
	for (int s = n > 1 ? (n - 2) / 4 : -1; s >= 0; s--)
		sift_down(h, s, h->e[s]);
}

/* Everything a collapse needs, worked out by plan() and applied by
 * apply(). */
struct plan {
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
};

static int find(int *parent, int i)
{
	while (parent[i] != i)
		i = parent[i] = parent[parent[i]];
	return i;
}

/* Which of the collapsed vertices node n is (0 .. k-1), or -1. */
static int owner_of(const struct plan *pl, int n)
{
	/* v[2] is -1 for an edge (plan() sets it), never a node */
	return n == pl->v[0] ? 0 : n == pl->v[1] ? 1 : n == pl->v[2] ? 2 : -1;
}

static int wedge_slot(const struct plan *pl, int w)
{
	for (int i = 0; i < pl->nw; i++)
		if (pl->wedges[i] == w)
			return i;
	return -1;
}

static int is_normal_float(const bgm_layout *L, int k, int targets)
{
	return (L->normal >= 0 && k >= L->normal && k < L->normal + 3) ||
	       (L->target_normal >= 0 && k >= L->target_normal && k < L->target_normal + 3 * targets);
}

/* What differs between the wedges of node v: *texture when anything but
 * the normals does (a UV, colour or tangent seam), *hard when the normals
 * do (a hard edge, as on faceted meshes). */
static void node_seams(const mlod_bgm *g, int v, int *texture, int *hard)
{
	const bgm_node *n = &g->nodes[v];
	const bgm_layout *L = &g->lay;
	int first = -1, T = g->prim->target_count;
	*texture = *hard = 0;
	for (int i = 0; i < n->inc_count; i++) {
		const bgm_face *f = &g->faces[g->inc[n->inc_first + i]];
		int w = f->w[f->n[0] == v ? 0 : f->n[1] == v ? 1 : 2];
		if (first < 0) {
			first = w;
			continue;
		}
		if (w == first)
			continue;
		const float *a = g->wedge_attr + (size_t)first * (size_t)L->stride, *b = g->wedge_attr + (size_t)w * (size_t)L->stride;
		for (int k = 0; k < L->stride; k++)
			if (a[k] != b[k]) {
				if (is_normal_float(L, k, T))
					*hard = 1;
				else
					*texture = 1;
			}
	}
}

/* The barycentric coordinates of x projected onto triangle (a, b, c),
 * clamped into it. */
static void barycentric(const double *a, const double *b, const double *c, const double *x, double *l)
{
	double v0[3], v1[3], v2[3];
	for (int i = 0; i < 3; i++)
		v0[i] = b[i] - a[i], v1[i] = c[i] - a[i], v2[i] = x[i] - a[i];
	double d00 = v0[0] * v0[0] + v0[1] * v0[1] + v0[2] * v0[2];
	double d01 = v0[0] * v1[0] + v0[1] * v1[1] + v0[2] * v1[2];
	double d11 = v1[0] * v1[0] + v1[1] * v1[1] + v1[2] * v1[2];
	double d20 = v2[0] * v0[0] + v2[1] * v0[1] + v2[2] * v0[2];
	double d21 = v2[0] * v1[0] + v2[1] * v1[1] + v2[2] * v1[2];
	double den = d00 * d11 - d01 * d01;
	if (!(fabs(den) > 0.0)) {
		l[0] = l[1] = l[2] = 1.0 / 3.0;
		return;
	}
	double v = (d11 * d20 - d01 * d21) / den, w = (d00 * d21 - d01 * d20) / den;
	l[0] = 1.0 - v - w, l[1] = v, l[2] = w;
	double sum = 0.0;
	for (int i = 0; i < 3; i++) {
		l[i] = l[i] > 0.0 ? l[i] : 0.0;
		sum += l[i];
	}
	for (int i = 0; i < 3; i++)
		l[i] = sum > 0.0 ? l[i] / sum : 1.0 / 3.0;
}

/* The NORMAL attribute apply() gives v-bar's corner of kept[j] (unit,
 * or 0 without normals): a copy of a wedge of the kept vertex or the
 * snap vertex, else interpolate_wedge's, the corner's own normal at a
 * hard edge. */
static void vbar_normal(const mlod_bgm *g, const struct plan *pl, int j, double *n, double *interp)
{
	const bgm_layout *L = &g->lay;
	n[0] = n[1] = n[2] = 0.0;
	if (L->normal < 0 || L->stride == 0)
		return;
	int S = L->stride, w = g->faces[pl->kept[j]].w[pl->corner[j]], from = -1;
	if (pl->whole) {
		from = pl->src[j];
	} else if (pl->snap >= 0) {
		int k = pl->group[wedge_slot(pl, w)];
		for (int i = 0; i < pl->nw; i++)
			if (pl->group[i] == k && g->wedge_node[pl->wedges[i]] == pl->v[pl->snap])
				from = pl->wedges[i];
	} else {
		int x = g->wedge_node[w], o = x == pl->v[0] ? 0 : x == pl->v[1] ? 1 : 2;
		if (pl->hard[o])
			from = w;
	}
	if (from >= 0) {
		const float *a = g->wedge_attr + (size_t)from * (size_t)S + L->normal;
		n[0] = a[0], n[1] = a[1], n[2] = a[2];
		return;
	}
	if (!isnan(interp[0])) { /* the same for every corner: worked out once */
		memcpy(n, interp, 3 * sizeof *n);
		return;
	}
	const bgm_face *TF = &g->faces[pl->t];
	int tw[3] = {TF->w[0], TF->w[1], TF->w[2]};
	if (pl->k == 2)
		tw[0] = TF->w[pl->op], tw[1] = TF->w[(pl->op + 1) % 3], tw[2] = tw[0];
	const double *l = pl->lambda;
	float f[3];
	for (int i = 0; i < 3; i++)
		f[i] = (float)(l[0] * g->wedge_attr[(size_t)tw[0] * (size_t)S + (size_t)(L->normal + i)] +
		               l[1] * g->wedge_attr[(size_t)tw[1] * (size_t)S + (size_t)(L->normal + i)] +
		               l[2] * g->wedge_attr[(size_t)tw[2] * (size_t)S + (size_t)(L->normal + i)]);
	double len = sqrt((double)f[0] * f[0] + (double)f[1] * f[1] + (double)f[2] * f[2]);
	int m = l[0] >= l[1] && l[0] >= l[2] ? 0 : l[1] >= l[2] ? 1 : 2;
	for (int i = 0; i < 3; i++)
		n[i] = len > 1e-6 ? f[i] / len : g->wedge_attr[(size_t)tw[m] * (size_t)S + (size_t)(L->normal + i)];
	memcpy(interp, n, 3 * sizeof *n);
}

/* The chosen placement's re-meshed faces against the NORMAL attribute
 * of their corners, v-bar's as apply() will make it: a face facing more
 * than 90 degrees away from their sum is inside out where it is shaded.
 * (Checking the two other corners for every placement in geometry_ok as
 * well refused more: Ely's 10% level 1.31% -> 2.47% Hausdorff.) */
static int normals_ok(const mlod_bgm *g, const struct plan *pl)
{
	const bgm_layout *L = &g->lay;
	if (L->normal < 0 || L->stride == 0)
		return 1;
	double interp[3] = {NAN, NAN, NAN};
	for (int j = 0; j < pl->nk; j++) {
		const bgm_face *f = &g->faces[pl->kept[j]];
		const double *q[3];
		for (int k = 0; k < 3; k++)
			q[k] = g->nodes[f->n[k]].p;
		q[pl->corner[j]] = pl->pos;
		double nn[3], s[3];
		bgm_face_normal(q[0], q[1], q[2], nn);
		vbar_normal(g, pl, j, s, interp);
		for (int k = 1; k < 3; k++) {
			const float *x = g->wedge_attr + (size_t)f->w[(pl->corner[j] + k) % 3] * (size_t)L->stride + L->normal;
			s[0] += x[0], s[1] += x[1], s[2] += x[2];
		}
		if (!(s[0] * nn[0] + s[1] * nn[1] + s[2] * nn[2] > 0.0))
			return 0;
	}
	return 1;
}

/* Checks the re-meshed faces for flips and degeneracy with v-bar at x.
 * Each face's normal is bgm_face_normal's and its compactness
 * bgm_compactness's (the same arithmetic on the same edge vectors, made
 * once here), the compactness (a division) only for a face that does not
 * flip: all three tests must pass. */
static int geometry_ok(const mlod_bgm *g, const struct plan *pl, const double *x)
{
	for (int i = 0; i < pl->nk; i++) {
		const bgm_face *f = &g->faces[pl->kept[i]];
		const double *q[3];
		for (int k = 0; k < 3; k++)
			q[k] = g->nodes[f->n[k]].p;
		q[pl->corner[i]] = x;
		const double *no = pl->onormal[i];
		double u[3], v[3], w[3], nn[3];
		u[0] = q[1][0] - q[0][0], u[1] = q[1][1] - q[0][1], u[2] = q[1][2] - q[0][2];
		v[0] = q[2][0] - q[0][0], v[1] = q[2][1] - q[0][1], v[2] = q[2][2] - q[0][2];
		w[0] = q[2][0] - q[1][0], w[1] = q[2][1] - q[1][1], w[2] = q[2][2] - q[1][2];
		nn[0] = u[1] * v[2] - u[2] * v[1];
		nn[1] = u[2] * v[0] - u[0] * v[2];
		nn[2] = u[0] * v[1] - u[1] * v[0];
		double lo = no[3];
		double ln = sqrt(nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2]);
		if (!(ln > 0.0))
			return 0;
		if (lo > 0.0 && pl->oflip[i] &&
		    !(no[0] * nn[0] + no[1] * nn[1] + no[2] * nn[2] > FLIP_COS * lo * ln))
			return 0;
		/* Turns add up over collapses: the reference too (the input
		 * face this one stands for). */
		const double *rn = pl->rnormal[i];
		if (rn[3] > 0.0 && !(rn[0] * nn[0] + rn[1] * nn[1] + rn[2] * nn[2] > REF_COS * rn[3] * ln))
			return 0;
		double area = 0.5 * ln;
		double l2 = u[0] * u[0] + u[1] * u[1] + u[2] * u[2] + v[0] * v[0] + v[1] * v[1] + v[2] * v[2] + w[0] * w[0] +
		            w[1] * w[1] + w[2] * w[2];
		double cn = l2 > 0.0 ? 4.0 * sqrt(3.0) * area / l2 : 0.0;
		if (cn < DEGENERATE)
			return 0;
	}
	return 1;
}

/* The weights of x projected onto segment (a, b), clamped into it. */
static void segment_weights(const double *a, const double *b, const double *x, double *l)
{
	double d = 0.0, len2 = 0.0;
	for (int i = 0; i < 3; i++) {
		d += (x[i] - a[i]) * (b[i] - a[i]);
		len2 += (b[i] - a[i]) * (b[i] - a[i]);
	}
	double s = len2 > 0.0 ? d / len2 : 0.5;
	s = s < 0.0 ? 0.0 : s > 1.0 ? 1.0 : s;
	l[0] = 1.0 - s, l[1] = s, l[2] = 0.0;
}

/* The collapsed vertices' posed quadrics summed per pose, as plan()
 * sums them. */
static void sum_quadrics(const mlod_bgm *g, const struct plan *pl, double *Q)
{
	/* Each sum from 0 in the vertices' order (the same bits whatever
	 * loop makes it). */
	size_t n = 10 * (size_t)g->qpose_count;
	const double *a = g->quadric + (size_t)pl->v[0] * n, *b = pl->k > 1 ? g->quadric + (size_t)pl->v[1] * n : NULL;
#ifdef __SSE2__
	/* Two entries at a time (n is even): each lane the sum below. */
	if (pl->k == 2 || pl->k == 3) {
		const __m128d zero = _mm_setzero_pd();
		if (pl->k == 3) {
			const double *c = g->quadric + (size_t)pl->v[2] * n;
			for (size_t k = 0; k < n; k += 2)
				_mm_storeu_pd(Q + k, _mm_add_pd(_mm_add_pd(_mm_add_pd(zero, _mm_load_pd(a + k)), _mm_load_pd(b + k)),
				                                _mm_load_pd(c + k)));
		} else {
			for (size_t k = 0; k < n; k += 2)
				_mm_storeu_pd(Q + k, _mm_add_pd(_mm_add_pd(zero, _mm_load_pd(a + k)), _mm_load_pd(b + k)));
		}
		return;
	}
#endif
	if (pl->k == 3) {
		const double *c = g->quadric + (size_t)pl->v[2] * n;
		for (size_t k = 0; k < n; k++) {
			double s = 0.0;
			s += a[k];
			s += b[k];
			s += c[k];
			Q[k] = s;
		}
	} else if (pl->k == 2) {
		for (size_t k = 0; k < n; k++) {
			double s = 0.0;
			s += a[k];
			s += b[k];
			Q[k] = s;
		}
	} else {
		for (size_t k = 0; k < n; k++) {
			double s = 0.0;
			for (int j = 0; j < pl->k; j++)
				s += g->quadric[(size_t)pl->v[j] * n + k];
			Q[k] = s;
		}
	}
}

/* Face h's bgm_face_normal (0-2), its length (3) and its compactness
 * (4), worked out once (its nodes, in its order, never change): the
 * same arithmetic every time. */
static const double *face_geo(mlod_bgm *g, int h)
{
	double *o = g->fgeo + 5 * (size_t)h;
	if (isnan(o[3])) {
		const bgm_face *F = &g->faces[h];
		const double *a = g->nodes[F->n[0]].p, *b = g->nodes[F->n[1]].p, *c = g->nodes[F->n[2]].p;
		bgm_face_normal(a, b, c, o);
		o[3] = sqrt(o[0] * o[0] + o[1] * o[1] + o[2] * o[2]);
		o[4] = bgm_compactness(a, b, c);
	}
	return o;
}

/* Face h's reference normal (0-2) and its length (3): an input face's
 * own bgm_face_normal; a face a collapse made has the reference of the
 * face it replaced (the same face with its v-bar corner moved), so each
 * face keeps the orientation of the input face it descends from. */
static const double *face_ref(mlod_bgm *g, int h)
{
	double *r = g->fref + 4 * (size_t)h;
	if (isnan(r[3]))
		memcpy(r, face_geo(g, h), 4 * sizeof *r); /* only input faces: apply sets the others' */
	return r;
}

/* Face h's area times its lack of compactness (sqrt(area_sq) from its
 * normal: area_sq's arithmetic). */
BGM_INLINE double face_tie(mlod_bgm *g, int h)
{
	double *t = &g->ftie[h];
	if (isnan(*t)) {
		const double *o = face_geo(g, h);
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
BGM_INLINE double collapse_tie(mlod_bgm *g, int f, int op, int K)
{
	if (K == 3)
		return face_tie(g, f);
	const bgm_face *F = &g->faces[f];
	int faces[2] = {f, F->adj[op]}, nr = faces[1] >= 0 ? 2 : 1;
	double tie = 0.0;
	for (int j = 0; j < nr; j++)
		tie += face_tie(g, faces[j]) / nr;
	return tie;
}

/* Whether a placement stays near the collapsed vertices P[0..K-1]: at
 * most their longest edge from the barycenter (K == 2: the one edge). */
BGM_INLINE int near_collapsed(const double *const P[3], int K, const double bary[3], const double opt[3])
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

/* The other end of each border edge at node v but the one to w: 1 when
 * some is also a border neighbour of w, so that collapsing the border
 * edge (v, w) would close a hole of three edges. */
static int closes_hole(const mlod_bgm *g, int v, int w)
{
	const bgm_node *n = &g->nodes[v], *m = &g->nodes[w];
	for (int i = 0; i < n->inc_count; i++) {
		const bgm_face *F = &g->faces[g->inc[n->inc_first + i]];
		for (int e = 0; e < 3; e++) {
			if (F->adj[e] >= 0 || (F->n[e] != v && F->n[(e + 1) % 3] != v))
				continue;
			int x = F->n[e] == v ? F->n[(e + 1) % 3] : F->n[e];
			if (x == w)
				continue;
			for (int j = 0; j < m->inc_count; j++) {
				const bgm_face *H = &g->faces[g->inc[m->inc_first + j]];
				for (int k = 0; k < 3; k++)
					if (H->adj[k] < 0 && ((H->n[k] == w && H->n[(k + 1) % 3] == x) ||
					                      (H->n[k] == x && H->n[(k + 1) % 3] == w)))
						return 1;
			}
		}
	}
	return 0;
}

/* Whether collapses may move and remove border vertices: with the posed
 * cost or mlod_bgm_options.allow_border from the start, else (the
 * compactness cost, which cannot rank them) once nothing else collapses
 * (mlod_bgm_simplify's border phase). */
static int borders_ok(const mlod_bgm *g)
{
	return g->opt.allow_border || g->border_phase || g->opt.cost == MLOD_COST_POSED;
}

/* What a collapse along a border costs, times its posed cost:
 * BORDER_PENALTY unless mlod_bgm_options.allow_border ranks it like any
 * other. */
static double border_factor(const mlod_bgm *g)
{
	return g->opt.allow_border ? 1.0 : BORDER_PENALTY;
}

/* Whether v-bar can be collapsed vertex s with its wedges as they are:
 * every wedge group holds exactly one wedge of s and at most one of each
 * other collapsed vertex. */
static int keeps_groups(const int (*per)[3], int ngroups, int K, int s)
{
	for (int k = 0; k < ngroups; k++)
		for (int o = 0; o < K; o++)
			if ((o == s && per[k][o] != 1) || per[k][o] > 1)
				return 0;
	return 1;
}

static int same_influences(const mlod_influences *x, const mlod_influences *y);

/* The optimal placement's candidates are tried (MLOD_PLACE_HYBRID too). */
static int optimal_like(const mlod_bgm *g)
{
	return g->opt.placement == MLOD_PLACE_OPTIMAL || g->opt.placement == MLOD_PLACE_HYBRID;
}

/* Vertex placement: which wedge of v[snap] each kept face's corner takes,
 * copied whole. Its own corners keep theirs; another vertex's corner the
 * one wedge of v[snap] in its wedge group (a texture seam: plan() made
 * sure there is exactly one), else (normals differ only: hard edges) the
 * wedge of v[snap] whose normal is nearest its own, the first of equals. */
static void vertex_wedges(const mlod_bgm *g, struct plan *pl, const int *owner)
{
	const bgm_layout *L = &g->lay;
	int S = L->stride, s = pl->snap;
	for (int j = 0; j < pl->nk; j++) {
		int w = g->faces[pl->kept[j]].w[pl->corner[j]], slot = wedge_slot(pl, w);
		if (owner[slot] == s) {
			pl->src[j] = w;
			continue;
		}
		int in_group = -1, count = 0, nearest = -1;
		double best = -HUGE_VAL;
		for (int i = 0; i < pl->nw; i++) {
			if (owner[i] != s)
				continue;
			if (pl->group[i] == pl->group[slot])
				in_group = pl->wedges[i], count++;
			double d = 0.0;
			if (S > 0 && L->normal >= 0) {
				const float *a = g->wedge_attr + (size_t)pl->wedges[i] * (size_t)S + L->normal;
				const float *b = g->wedge_attr + (size_t)w * (size_t)S + L->normal;
				d = (double)a[0] * b[0] + (double)a[1] * b[1] + (double)a[2] * b[2];
			}
			if (nearest < 0 || d > best)
				nearest = pl->wedges[i], best = d;
		}
		pl->src[j] = count == 1 ? in_group : nearest;
	}
}

/* Works out operation op on face t (its triangle collapse, or the
 * collapse of one of its edges); returns 1 when it is valid (pl holds
 * the cheapest valid placement), else 0. */
/* Where plan() stops summing a candidate of family fam: once it cannot
 * beat the best of its family (a whole vertex: nor be kept, costing more
 * than both the free best and the cap), with a margin far above
 * rounding, so that the choice is the one the full sum makes. */
BGM_INLINE double plan_stop(const mlod_bgm *g, const struct plan *pl, int fam, const int *bestf, const double *costf,
                            double cap, double tie, double wsum)
{
	double stop = HUGE_VAL, add = TIE_WEIGHT * tie, limit = HUGE_VAL;
	if (bestf[fam] >= 0)
		limit = costf[fam];
	if (fam == 1 && bestf[0] >= 0)
		limit = fmin(limit, fmax(costf[0], cap));
	if (limit < HUGE_VAL && wsum > 0.0) {
		double lim = limit * (g->opt.op == MLOD_OP_MIXED ? pl->nr : 1) - add;
		if (lim > 1e-6 * add)
			stop = lim * wsum * (1.0 + 1e-9);
	}
	return stop;
}

static int plan(mlod_bgm *g, int t, int op, int exact, struct plan *pl, memo *mm)
{
	const bgm_face *T = &g->faces[t];
	int allow_border = borders_ok(g);
	if (T->death != BGM_ALIVE)
		return 0;
	pl->t = t;
	pl->op = op;
	pl->k = op == OP_TRIANGLE ? 3 : 2;
	pl->v[2] = -1;
	for (int i = 0; i < pl->k; i++) {
		int v = pl->v[i] = T->n[op == OP_TRIANGLE ? i : (op + i) % 3];
		int fl = g->nodes[v].flags;
		if ((fl & (BGM_LOCKED | BGM_DEAD)) || !(fl & BGM_ELIGIBLE) || (!allow_border && (fl & BGM_BORDER)))
			return 0;
	}
	int K = pl->k, vertex = g->opt.placement == MLOD_PLACE_VERTEX;
	int hybrid = g->opt.placement == MLOD_PLACE_HYBRID && g->opt.cost == MLOD_COST_POSED;

	/* The patch. */
	pl->nf = pl->nr = pl->nk = 0;
	for (int i = 0; i < K; i++) {
		const bgm_node *n = &g->nodes[pl->v[i]];
		for (int k = 0; k < n->inc_count; k++) {
			int f = g->inc[n->inc_first + k], seen = 0;
			for (int j = 0; j < pl->nf && !seen; j++)
				seen = pl->faces[j] == f;
			if (seen)
				continue;
			if (pl->nf == MAX_PATCH)
				return 0;
			pl->faces[pl->nf++] = f;
		}
	}
	int from[MAX_PATCH], to[MAX_PATCH], all3 = 0;
	for (int j = 0; j < pl->nf; j++) {
		const bgm_face *f = &g->faces[pl->faces[j]];
		int in = 0, corner = -1;
		for (int k = 0; k < 3; k++)
			if (owner_of(pl, f->n[k]) >= 0)
				in++, corner = k;
		if (in == 3)
			all3++;
		if (in >= 2) {
			pl->removed[pl->nr++] = pl->faces[j];
			continue;
		}
		pl->corner[pl->nk] = corner;
		from[pl->nk] = f->n[(corner + 1) % 3];
		to[pl->nk] = f->n[(corner + 2) % 3];
		pl->kept[pl->nk++] = pl->faces[j];
	}
	if ((K == 3 && all3 != 1) || pl->nk == 0)
		return 0;
	/* Each collapsed edge has at most two faces (t and one across). */
	for (int e = 0; e < (K == 3 ? 3 : 1); e++) {
		int x = pl->v[e], y = pl->v[(e + 1) % K], count = 0;
		for (int j = 0; j < pl->nr; j++) {
			const bgm_face *f = &g->faces[pl->removed[j]];
			int hx = f->n[0] == x || f->n[1] == x || f->n[2] == x;
			int hy = f->n[0] == y || f->n[1] == y || f->n[2] == y;
			count += hx && hy;
		}
		if (count > 2)
			return 0;
	}
	int border = 0, nb = 0, onb[3] = {0, 0, 0}, tex[3] = {0, 0, 0}, anytex = 0, special[3] = {0, 0, 0};
	for (int i = 0; i < K; i++) {
		onb[i] = (g->nodes[pl->v[i]].flags & BGM_BORDER) != 0;
		node_seams(g, pl->v[i], &tex[i], &pl->hard[i]);
		border |= onb[i];
		nb += onb[i];
		anytex |= tex[i];
	}
	/* A texture seam among the collapsed vertices: v-bar snaps onto a
	 * seam (or border) vertex keeping every wedge group whole. Without
	 * one, a border only restricts where v-bar goes (below). */
	for (int i = 0; i < K && anytex; i++)
		special[i] = onb[i] || tex[i];
	/* The link condition: the re-meshed faces form one fan around v-bar. */
	if (!bgm_link_ok(from, to, pl->nk, border))
		return 0;

	/* Wedge groups: wedges of the collapsed vertices joined through
	 * removed faces. */
	int parent[MAX_WEDGES], owner[MAX_WEDGES];
	pl->nw = 0;
	for (int j = 0; j < pl->nf; j++) {
		const bgm_face *f = &g->faces[pl->faces[j]];
		for (int k = 0; k < 3; k++) {
			int o = owner_of(pl, f->n[k]);
			if (o < 0 || wedge_slot(pl, f->w[k]) >= 0)
				continue;
			if (pl->nw == MAX_WEDGES)
				return 0;
			owner[pl->nw] = o;
			parent[pl->nw] = pl->nw;
			pl->wedges[pl->nw++] = f->w[k];
		}
	}
	for (int j = 0; j < pl->nr; j++) {
		const bgm_face *f = &g->faces[pl->removed[j]];
		int first = -1;
		for (int k = 0; k < 3; k++) {
			int s = wedge_slot(pl, f->w[k]);
			if (s < 0)
				continue;
			if (first < 0)
				first = s;
			else
				parent[find(parent, s)] = find(parent, first);
		}
	}
	pl->ngroups = 0;
	int root_group[MAX_WEDGES];
	for (int i = 0; i < pl->nw; i++)
		root_group[i] = -1;
	for (int i = 0; i < pl->nw; i++) {
		int r = find(parent, i);
		if (root_group[r] < 0)
			root_group[r] = pl->ngroups++;
		pl->group[i] = root_group[r];
	}
	/* Per group, how many wedges each collapsed vertex has there. */
	int per[MAX_WEDGES][3];
	memset(per, 0, sizeof per[0] * (size_t)pl->ngroups); /* the groups' rows */
	for (int i = 0; i < pl->nw; i++)
		per[pl->group[i]][owner[i]]++;

	/* Candidate placements. */
	double cand[MAX_CANDIDATES][3];
	int cand_snap[MAX_CANDIDATES], cand_role[MAX_CANDIDATES], cand_at[MAX_CANDIDATES], nc = 0;
	int cand_whole[MAX_CANDIDATES];
	const double *P[3] = {g->nodes[pl->v[0]].p, g->nodes[pl->v[1]].p, K == 3 ? g->nodes[pl->v[2]].p : NULL};
	double bary[3];
	for (int i = 0; i < 3; i++) {
		bary[i] = 0.0;
		for (int j = 0; j < K; j++)
			bary[i] += P[j][i] / K;
	}
	mlod_v3 V[3];
	mlod_influences in3[3];
	for (int j = 0; j < K; j++) {
		V[j] = (mlod_v3){(float)P[j][0], (float)P[j][1], (float)P[j][2]};
		in3[j] = g->inf[pl->v[j]];
	}
	if (special[0] || special[1] || special[2]) {
		/* Snap onto a seam (or border) vertex that keeps every wedge group
		 * whole. Border vertices must stay on the border. */
		for (int s = 0; s < K; s++) {
			if (!special[s] || (border && !(g->nodes[pl->v[s]].flags & BGM_BORDER)))
				continue;
			if (!keeps_groups((const int (*)[3])per, pl->ngroups, K, s))
				continue;
			memcpy(cand[nc], P[s], sizeof cand[nc]);
			cand_role[nc] = 1 + s;
			cand_at[nc] = s;
			cand_whole[nc] = vertex;
			cand_snap[nc++] = s;
		}
		if (nc == 0)
			return 0;
	} else if (border) {
		/* The border stays where it is: v-bar goes to a border vertex,
		 * or for an edge along the border also to its midpoint. */
		int along = -1;
		if (nb >= 2) {
			/* Two border vertices must share a border edge of t (else the
			 * collapse would pinch two stretches of border together); three
			 * never collapse. */
			for (int e = 0; e < 3 && nb == 2; e++) {
				int x = owner_of(pl, T->n[e]), y = owner_of(pl, T->n[(e + 1) % 3]);
				if (x >= 0 && y >= 0 && onb[x] && onb[y] && T->adj[e] < 0)
					along = e;
			}
			if (along < 0 || closes_hole(g, T->n[along], T->n[(along + 1) % 3]))
				return 0;
		}
		for (int s = 0; s < K; s++) {
			if (!onb[s])
				continue;
			memcpy(cand[nc], P[s], sizeof cand[nc]);
			cand_role[nc] = 1 + s;
			cand_at[nc] = s;
			cand_whole[nc] = vertex;
			cand_snap[nc++] = vertex ? s : -1;
		}
		if (K == 2 && nb == 2 && !vertex) {
			memcpy(cand[nc], bary, sizeof cand[nc]);
			cand_role[nc] = 4;
			cand_at[nc] = -1;
			cand_whole[nc] = 0;
			cand_snap[nc++] = -1;
		}
	}
	/* The summed posed quadrics of the collapsed vertices, and their area
	 * (the normaliser of the posed cost). */
	double *Q = g->qsum, wsum = 0.0, R[10] = {0};
	int fast = !exact && g->rquad, q_ready = 0;
	if (g->pose_count > 0 && fast) {
		for (int j = 0; j < K; j++) {
			const double *r = bgm_quadric_rest(g, pl->v[j]);
			for (int k = 0; k < 10; k++)
				R[k] += r[k];
			wsum += r[10];
		}
	} else if (g->pose_count > 0 && mm && (mm->known & MEMO_WSUM)) {
		wsum = mm->wsum; /* Q is summed when needed */
	} else if (g->pose_count > 0) {
		sum_quadrics(g, pl, Q);
		q_ready = 1;
		for (int p = 0; p < g->pose_count; p++)
			wsum += Q[bgm_qat(g->qpose_count, g->qmap[p], 0)] + Q[bgm_qat(g->qpose_count, g->qmap[p], 4)] +
			        Q[bgm_qat(g->qpose_count, g->qmap[p], 7)];
		if (mm) {
			mm->wsum = wsum;
			mm->known |= MEMO_WSUM;
		}
	}
	if (!(special[0] || special[1] || special[2]) && !border && vertex) {
		/* Vertex placement: v-bar is one of the collapsed vertices, its
		 * wedges copied whole (vertex_wedges). */
		for (int s = 0; s < K; s++) {
			memcpy(cand[nc], P[s], sizeof cand[nc]);
			cand_role[nc] = 1 + s;
			cand_at[nc] = s;
			cand_whole[nc] = 1;
			cand_snap[nc++] = s;
		}
	} else if (!(special[0] || special[1] || special[2]) && !border) {
		if (optimal_like(g) && g->pose_count > 0) {
			mlod_influences w;
			double opt[3];
			int found;
			if (fast) {
				found = bgm_quadric_solve(R, bary, opt) == 0;
			} else if (mm && mm->opt_state) {
				found = mm->opt_state == 1;
				memcpy(opt, mm->opt, sizeof opt);
			} else {
				if (!q_ready)
					sum_quadrics(g, pl, Q), q_ready = 1;
				skin_role(mm, 4, V, in3, K, bary, &w);
				found = bgm_quadric_optimum(g, Q, &w, bary, opt) == 0;
				if (mm) {
					mm->opt_state = found ? 1 : 2;
					memcpy(mm->opt, opt, sizeof opt);
				}
			}
			{
				if (found) {
					if (near_collapsed(P, K, bary, opt)) {
						memcpy(cand[nc], opt, sizeof cand[nc]);
						cand_role[nc] = 0;
						cand_at[nc] = -1;
						cand_whole[nc] = 0;
						cand_snap[nc++] = -1;
					}
				}
			}
			/* An edge may also go to either end (a half-edge collapse),
			 * with that end's attributes. */
			for (int s = 0; s < K && K == 2; s++) {
				memcpy(cand[nc], P[s], sizeof cand[nc]);
				cand_role[nc] = 1 + s;
				cand_at[nc] = s;
				cand_whole[nc] = 0;
				cand_snap[nc++] = -1;
			}
		}
		memcpy(cand[nc], bary, sizeof cand[nc]);
		cand_role[nc] = 4;
		cand_at[nc] = -1;
		cand_whole[nc] = 0;
		cand_snap[nc++] = -1;
	}
	if (hybrid) {
		/* Each collapsed vertex the placements above may go to (all of
		 * them away from seams and borders), kept whole too: last, so
		 * that the others' least cost is known when they are tried. */
		int n0 = nc, any = !(special[0] || special[1] || special[2]) && !border;
		for (int s = 0; s < K; s++) {
			int offered = any;
			for (int i = 0; i < n0; i++)
				offered |= cand_at[i] == s;
			if (!offered)
				continue;
			memcpy(cand[nc], P[s], sizeof cand[nc]);
			cand_role[nc] = 5 + s;
			cand_at[nc] = s;
			cand_whole[nc] = 1;
			cand_snap[nc++] = s;
		}
	}

	/* The kept faces as they are, for geometry_ok: their normals and
	 * their references. */
	for (int i = 0; i < pl->nk; i++) {
		const double *o = face_geo(g, pl->kept[i]);
		memcpy(pl->onormal[i], o, 4 * sizeof *o);
		pl->oflip[i] = o[3] > 0.0 && o[4] >= DEGENERATE;
		memcpy(pl->rnormal[i], face_ref(g, pl->kept[i]), 4 * sizeof *o);
	}
	/* The cheapest valid candidate; with the compactness cost (the same
	 * for every placement), the one nearest the barycenter. The
	 * compactness tie-break of the posed cost is t's own for a triangle,
	 * the mean over the removed faces for an edge. The hybrid placement
	 * keeps two: the cheapest free placement (family 0) and the cheapest
	 * whole vertex (family 1), tried last. */
	int bestf[2] = {-1, -1}, capf[2] = {0, 0};
	unsigned same_end = 0;
	int geo_at[3] = {-1, -1, -1};
	double end_e[3] = {0.0, 0.0, 0.0};
	double costf[2] = {0.0, 0.0}, df[2] = {0.0, 0.0}, tie = 0.0;
	/* Hybrid: a whole vertex within this cost is kept (the squared share
	 * of the diagonal: the cost is a mean squared distance). */
	double cap = hybrid ? g->opt.hybrid_error / 100.0 * g->diagonal : 0.0;
	cap *= cap;
	mlod_influences inff[2];
	if (K == 3) {
		tie = face_tie(g, t);
	} else {
		for (int j = 0; j < pl->nr; j++)
			tie += face_tie(g, pl->removed[j]) / pl->nr;
	}
	/* The fast posed cost does not depend on the influences: rank the
	 * candidates by it, and the first valid one is the choice (the one
	 * the loop below would make, ties going to the earlier). */
	int order[MAX_CANDIDATES];
	double ckey[MAX_CANDIDATES];
	int ranked = fast && g->opt.cost == MLOD_COST_POSED && !hybrid;
	for (int k = 0; k < nc; k++) {
		order[k] = k;
		if (!ranked)
			continue;
		double e = g->pose_count > 0 ? bgm_quadric_eval(R, cand[k]) : 0.0;
		ckey[k] = (wsum > 0.0 ? e / wsum : 0.0) + TIE_WEIGHT * tie;
		if (g->opt.op == MLOD_OP_MIXED)
			ckey[k] /= pl->nr;
		for (int i = k; i > 0 && ckey[order[i]] < ckey[order[i - 1]]; i--) {
			int x = order[i];
			order[i] = order[i - 1];
			order[i - 1] = x;
		}
	}
	/* With the exact posed cost (not hybrid), once a candidate is taken,
	 * or when its error is memoised, a candidate's geometry is checked
	 * only if it is cheaper than the best so far: its sum stops early
	 * when it is not, and geometry_ok is spared. Before any is taken the
	 * check comes first (a failure spares the sum). The choice is the
	 * same in either order: a candidate is taken when valid, skinned and
	 * cheaper than the best before it. bench_mesh profile: tubeman -3.1%
	 * instructions, RobotExpressive -2.0%, Ely -2.5% (checking late for
	 * every candidate: the robot +0.7%, its geometry failing more). */
	int late_geo = g->opt.cost == MLOD_COST_POSED && !ranked && !hybrid && g->pose_count > 0;
	for (int kk = 0; kk < nc; kk++) {
		int k = order[kk], fam = hybrid && cand_whole[k];
		int late = late_geo && (bestf[0] >= 0 || (mm && (mm->known >> cand_role[k] & 1u)));
		/* A sum that stopped before (exact_bound's, or an earlier plan's)
		 * at a partial sum the stop here does not exceed stops here too
		 * (bgm_quadric_error_reach): not planned again. */
		if (late_geo && mm && bestf[0] >= 0 && (mm->stopped >> cand_role[k] & 1u) && !(mm->known >> cand_role[k] & 1u) &&
		    mm->ge[cand_role[k]] >= plan_stop(g, pl, 0, bestf, costf, cap, tie, wsum))
			continue;
		if (ranked && bestf[0] >= 0)
			break;
		int at = cand_at[k];
		if (fam == 1 && (same_end >> at & 1u) && bestf[0] >= 0) {
			/* Its cost is known (the free end's): skip it when it cannot
			 * be kept. */
			double c = (wsum > 0.0 ? end_e[at] / wsum : 0.0) + TIE_WEIGHT * tie;
			if (g->opt.op == MLOD_OP_MIXED)
				c /= pl->nr;
			if (c > costf[0] && c > cap)
				continue;
		}
		if (!late) {
			/* A whole vertex is where a free end was: the same answer. */
			int ok = fam == 1 && geo_at[at] >= 0 ? geo_at[at] : geometry_ok(g, pl, cand[k]);
			if (hybrid && at >= 0 && !cand_whole[k])
				geo_at[at] = ok;
			if (!ok)
				continue;
		}
		mlod_influences w;
		int capped = 0;
		if (cand_whole[k])
			w = in3[cand_at[k]]; /* the vertex's own influences, not blended */
		else
			capped = skin_role(mm, cand_role[k], V, in3, K, cand[k], &w);
		if (g->joint_count > 0 && w.count == 0)
			continue;
		double cost, d = 0.0;
		for (int i = 0; i < 3; i++)
			d += (cand[k][i] - bary[i]) * (cand[k][i] - bary[i]);
		if (g->opt.cost == MLOD_COST_POSED) {
			/* Area-normalised (a mean squared distance), so small
			 * features count as much as large ones. */
			double e = 0.0;
			if (ranked) {
				cost = ckey[k];
				goto take;
			} else if (g->pose_count > 0) {
				double stop = plan_stop(g, pl, fam, bestf, costf, cap, tie, wsum);
				int role = cand_role[k];
				if (role >= 5 && (same_end >> (role - 5) & 1u)) {
					e = end_e[role - 5];
				} else if (mm && (mm->known >> role & 1u)) {
					e = mm->e[role];
				} else {
					if (!q_ready)
						sum_quadrics(g, pl, Q), q_ready = 1;
					double reached;
					e = bgm_quadric_error_reach(g, Q, &w, cand[k], stop, &reached);
					if (e == HUGE_VAL) {
						if (mm && role < MEMO_ROLES) {
							mm->ge[role] = reached;
							mm->stopped |= 1u << role;
						}
						continue;
					}
					if (mm) {
						mm->e[role] = e;
						mm->known |= 1u << role;
					}
				}
				/* A free end skinned with the vertex's own influences (as
				 * Power Skinning at a vertex mostly gives) costs what
				 * that vertex kept whole costs. */
				if (hybrid && role >= 1 && role <= 3 && same_influences(&w, &in3[role - 1])) {
					end_e[role - 1] = e;
					same_end |= 1u << (role - 1);
				}
			}
			cost = (wsum > 0.0 ? e / wsum : 0.0) + TIE_WEIGHT * tie;
			if (g->opt.op == MLOD_OP_MIXED) /* per removed face: triangles and edges compete */
				cost /= pl->nr;
			if (bestf[fam] >= 0 && !(cost < costf[fam]))
				continue;
			if (late && !geometry_ok(g, pl, cand[k]))
				continue;
		} else {
			cost = bgm_compactness(P[0], P[1], P[2]);
			if (bestf[fam] >= 0 && !(d < df[fam]))
				continue;
		}
	take:
		bestf[fam] = k;
		costf[fam] = cost;
		df[fam] = d;
		inff[fam] = w;
		capf[fam] = capped;
	}
	/* Hybrid: the whole vertex when it costs no more than the free
	 * placement, or no more than the cap. */
	int fam = bestf[1] >= 0 && (bestf[0] < 0 || costf[1] <= costf[0] || costf[1] <= cap);
	int best = bestf[fam];
	if (best < 0)
		return 0;
	pl->cost = costf[fam];
	pl->inf = inff[fam];
	pl->capped = capf[fam];
	if (nb >= 2 && g->opt.cost == MLOD_COST_POSED)
		pl->cost *= border_factor(g); /* the border moves (a lone border vertex stays put) */
	memcpy(pl->pos, cand[best], sizeof pl->pos);
	pl->snap = cand_snap[best];
	pl->whole = cand_whole[best];
	if (pl->whole)
		vertex_wedges(g, pl, owner);
	if (cand_at[best] >= 0) {
		pl->lambda[0] = pl->lambda[1] = pl->lambda[2] = 0.0;
		pl->lambda[cand_at[best]] = 1.0;
	} else if (K == 3) {
		barycentric(P[0], P[1], P[2], pl->pos, pl->lambda);
	} else {
		segment_weights(P[0], P[1], pl->pos, pl->lambda);
	}
	return normals_ok(g, pl);
}

/* Interpolates wedge attributes: out = sum_i l[i] * attr(w[i]), with unit
 * normals and tangents. */
static void interpolate_wedge(mlod_bgm *g, int out, const int *w, const double *l)
{
	const bgm_layout *L = &g->lay;
	int S = L->stride;
	if (S == 0)
		return;
	float *o = g->wedge_attr + (size_t)out * (size_t)S;
	const float *x[3];
	for (int i = 0; i < 3; i++)
		x[i] = g->wedge_attr + (size_t)w[i] * (size_t)S;
	for (int k = 0; k < S; k++)
		o[k] = (float)(l[0] * x[0][k] + l[1] * x[1][k] + l[2] * x[2][k]);
	if (L->normal >= 0) {
		float *n = o + L->normal;
		double len = sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
		int m = l[0] >= l[1] && l[0] >= l[2] ? 0 : l[1] >= l[2] ? 1 : 2;
		if (len > 1e-6)
			for (int i = 0; i < 3; i++)
				n[i] = (float)(n[i] / len);
		else
			memcpy(n, x[m] + L->normal, 3 * sizeof(float));
	}
	if (L->tangent >= 0) {
		float *tg = o + L->tangent;
		double len = sqrt((double)tg[0] * tg[0] + (double)tg[1] * tg[1] + (double)tg[2] * tg[2]);
		int m = l[0] >= l[1] && l[0] >= l[2] ? 0 : l[1] >= l[2] ? 1 : 2;
		if (len > 1e-6)
			for (int i = 0; i < 3; i++)
				tg[i] = (float)(tg[i] / len);
		else
			memcpy(tg, x[m] + L->tangent, 3 * sizeof(float));
		tg[3] = x[m][L->tangent + 3] < 0.0f ? -1.0f : 1.0f;
	}
}

static int grow_face_arrays(mlod_bgm *g)
{
	if (g->opstate_cap < g->face_cap) {
		unsigned char *b = realloc(g->opstate, (size_t)g->face_cap);
		if (!b)
			return -1;
		for (int f = g->opstate_cap; f < g->face_cap; f++)
			b[f] = f < g->face_count && g->faces[f].death != BGM_ALIVE ? DEAD : 0;
		g->opstate = b;
		g->opstate_cap = g->face_cap;
	}
	if (g->ftie_cap < g->face_cap) {
		double *t = realloc(g->ftie, sizeof *t * (size_t)g->face_cap);
		if (!t)
			return -1;
		g->ftie = t;
		double *o = realloc(g->fgeo, sizeof *o * 5 * (size_t)g->face_cap);
		if (!o)
			return -1;
		g->fgeo = o;
		double *rf = realloc(g->fref, sizeof *rf * 4 * (size_t)g->face_cap);
		if (!rf)
			return -1;
		g->fref = rf;
		for (int f = g->ftie_cap; f < g->face_cap; f++)
			t[f] = o[5 * (size_t)f + 3] = rf[4 * (size_t)f + 3] = NAN;
		g->ftie_cap = g->face_cap;
	}
	return 0;
}

/* 1 when the queue takes lower bounds of the posed cost (lower_key) and
 * plans an operation only when it is popped. */
static int lazy_keys(const mlod_bgm *g)
{
	return g->opt.cost == MLOD_COST_POSED && g->rquad && g->pose_count > 0 && g->opt.op != MLOD_OP_MIXED;
}

static int same_influences(const mlod_influences *x, const mlod_influences *y)
{
	if (x->count != y->count)
		return 0;
	for (int i = 0; i < x->count; i++)
		if (x->joints[i] != y->joints[i] || x->weights[i] != y->weights[i])
			return 0;
	return 1;
}

/* fmax without the library call (the same value: NaN gives the other
 * argument; the arguments here are never zeros of both signs). */
static inline double max_d(double a, double b)
{
	return a != a ? b : b != b ? a : a > b ? a : b;
}

/* posed_min_bound's term for pose p (not added when not above 0 or not
 * finite; -1 when the pose gives none). */
static inline double pose_min_bound(const mlod_bgm *g, const uint16_t *joint, int nj, const double *const qv[3], int k,
                                    size_t p, const double *bary, double rl, double inv)
{
	int J = g->joint_count;
	const float *S = g->skin + p * (size_t)J * 12;
	double z[3 * MLOD_MAX_INFLUENCES][3], c[3] = {0, 0, 0};
	for (int j = 0; j < nj; j++) {
		const float *m = S + 12 * (size_t)joint[j];
		for (int i = 0; i < 3; i++) {
			z[j][i] = (double)m[4 * i] * bary[0] + (double)m[4 * i + 1] * bary[1] + (double)m[4 * i + 2] * bary[2] +
			          (double)m[4 * i + 3];
			c[i] += z[j][i];
		}
	}
	for (int i = 0; i < 3; i++)
		c[i] *= inv;
	double spread = 0.0, far = 0.0;
	for (int j = 0; j < nj; j++) {
		double d = 0.0, a = 0.0;
		for (int i = 0; i < 3; i++) {
			d += (z[j][i] - c[i]) * (z[j][i] - c[i]);
			a += z[j][i] * z[j][i];
		}
		spread = max_d(spread, d);
		far = max_d(far, a);
	}
	double R = (sqrt(spread) + rl) * (1.0 + 1e-6) + 1e-6 * (sqrt(far) + rl);
	double q[10], q0[10], q1[10], q2[10];
	int D = g->qpose_count, sp = g->qmap[p]; /* pose p's stored pose */
	bgm_quadric_get(qv[0], D, sp, q0);
	if (k == 1) {
		memcpy(q, q0, sizeof q);
	} else if (k == 2) {
		bgm_quadric_get(qv[1], D, sp, q1);
		for (int e = 0; e < 10; e++)
			q[e] = q0[e] + q1[e];
	} else {
		bgm_quadric_get(qv[1], D, sp, q1);
		bgm_quadric_get(qv[2], D, sp, q2);
		for (int e = 0; e < 10; e++)
			q[e] = q0[e] + q1[e] + q2[e];
	}
	double tr = q[0] + q[4] + q[7];
	if (!(tr > 0.0) || !isfinite(tr))
		return -1.0;
	double mu = 1e-5 * tr, y[3];
	double a = q[0] + mu, b = q[1], cc = q[2], d = q[4] + mu, e = q[5], f = q[7] + mu;
	double det = a * (d * f - e * e) - b * (b * f - cc * e) + cc * (b * e - cc * d);
	if (!(fabs(det) > 0.0))
		return -1.0;
	double r0 = -q[3] + mu * c[0], r1 = -q[6] + mu * c[1], r2 = -q[8] + mu * c[2];
	y[0] = (r0 * (d * f - e * e) - b * (r1 * f - e * r2) + cc * (r1 * e - d * r2)) / det;
	y[1] = (a * (r1 * f - e * r2) - r0 * (b * f - cc * e) + cc * (b * r2 - r1 * cc)) / det;
	y[2] = (a * (d * r2 - r1 * e) - b * (b * r2 - r1 * cc) + r0 * (b * e - cc * d)) / det;
	/* bgm_quadric_eval(q, y), written out here (the same sum) */
	double val = q[0] * y[0] * y[0] + 2 * q[1] * y[0] * y[1] + 2 * q[2] * y[0] * y[2] + 2 * q[3] * y[0] +
	             q[4] * y[1] * y[1] + 2 * q[5] * y[1] * y[2] + 2 * q[6] * y[1] + q[7] * y[2] * y[2] + 2 * q[8] * y[2] + q[9];
	double dy = 0.0;
	val = val > 0.0 ? val : 0.0;
	for (int i = 0; i < 3; i++)
		dy += (y[i] - c[i]) * (y[i] - c[i]);
	val += mu * dy - mu * R * R;
	/* Rounding: the terms of the quadric's value at a point within R of
	 * c, far above the errors of the sums here and in plan(). */
	double ym = max_d(max_d(fabs(c[0]), fabs(c[1])), fabs(c[2])) + R;
	double mag = fabs(q[9]) + 2.0 * (fabs(q[3]) + fabs(q[6]) + fabs(q[8])) * ym +
	             (fabs(q[0]) + fabs(q[4]) + fabs(q[7]) + 2.0 * (fabs(q[1]) + fabs(q[2]) + fabs(q[5]))) * ym * ym;
	val -= 1e-12 * mag;
	return val;
}

#ifdef __SSE2__
/* max_d lane by lane. */
static inline __m128d max_pd2(__m128d a, __m128d b)
{
	__m128d an = _mm_cmpunord_pd(a, a), bn = _mm_cmpunord_pd(b, b), gt = _mm_cmpgt_pd(a, b);
	__m128d take_a = _mm_andnot_pd(an, _mm_or_pd(bn, gt));
	return _mm_or_pd(_mm_and_pd(take_a, a), _mm_andnot_pd(take_a, b));
}

static inline __m128d abs_pd2(__m128d x)
{
	return _mm_andnot_pd(_mm_set1_pd(-0.0), x);
}

/* pose_min_bound for poses p and p + 1 (lanes 0 and 1), every step
 * done whatever the tests: val, tr and det per pose, for the caller to
 * test as pose_min_bound does. */
BGM_INLINE __m128d pose_min_bound2(const mlod_bgm *g, const uint16_t *joint, int nj, const double *const qv[3],
                                      int k, size_t i2, const double *bary, double rl, double inv)
{
	int J = g->joint_count;
	/* g->skin2: the skin matrices as doubles, poses p and p + 1 side by side
	 * (block i2 = p / 2); qv: the k vertices' quadrics of that pair */
	const double *S = g->skin2 + i2 * (size_t)J * 24;
	const __m128d bx = _mm_set1_pd(bary[0]), by = _mm_set1_pd(bary[1]), bz = _mm_set1_pd(bary[2]);
	const __m128d zero = _mm_setzero_pd();
	/* Three rows and sums in registers; |z_j|^2 and its running maximum as
	 * the joints come (it needs no c). A square is +0 or above, or NaN, so
	 * the sums of three squares are the ones from 0 (0 + x x = x x). */
	__m128d z[3 * MLOD_MAX_INFLUENCES][3], c0 = zero, c1 = zero, c2 = zero, far = zero;
	for (int j = 0; j < nj; j++) {
		const double *m = S + 24 * (size_t)joint[j];
#define ROW(i) _mm_add_pd(_mm_add_pd(_mm_add_pd(_mm_mul_pd(_mm_load_pd(m + 8 * (i)), bx), \
                                                _mm_mul_pd(_mm_load_pd(m + 8 * (i) + 2), by)), \
                                     _mm_mul_pd(_mm_load_pd(m + 8 * (i) + 4), bz)), \
                          _mm_load_pd(m + 8 * (i) + 6))
		__m128d z0 = ROW(0), z1 = ROW(1), z2 = ROW(2);
#undef ROW
		z[j][0] = z0, z[j][1] = z1, z[j][2] = z2;
		c0 = _mm_add_pd(c0, z0), c1 = _mm_add_pd(c1, z1), c2 = _mm_add_pd(c2, z2);
		__m128d a = _mm_add_pd(_mm_add_pd(_mm_mul_pd(z0, z0), _mm_mul_pd(z1, z1)), _mm_mul_pd(z2, z2));
		/* max_d(far, a): a is +0 or above, or NaN (then far, never NaN,
		 * stays, as maxpd gives its second operand) */
		far = _mm_max_pd(a, far);
	}
	const __m128d vinv = _mm_set1_pd(inv);
	c0 = _mm_mul_pd(c0, vinv), c1 = _mm_mul_pd(c1, vinv), c2 = _mm_mul_pd(c2, vinv);
	__m128d c[3] = {c0, c1, c2};
	__m128d spread = zero;
	for (int j = 0; j < nj; j++) {
		__m128d x0 = _mm_sub_pd(z[j][0], c0), x1 = _mm_sub_pd(z[j][1], c1), x2 = _mm_sub_pd(z[j][2], c2);
		__m128d d = _mm_add_pd(_mm_add_pd(_mm_mul_pd(x0, x0), _mm_mul_pd(x1, x1)), _mm_mul_pd(x2, x2));
		/* max_d(spread, d), as far above */
		spread = _mm_max_pd(d, spread);
	}
	const __m128d vrl = _mm_set1_pd(rl);
	__m128d R = _mm_add_pd(_mm_mul_pd(_mm_add_pd(_mm_sqrt_pd(spread), vrl), _mm_set1_pd(1.0 + 1e-6)),
	                       _mm_mul_pd(_mm_set1_pd(1e-6), _mm_add_pd(_mm_sqrt_pd(far), vrl)));
	__m128d q[10];
	/* poses p and p + 1 side by side (bgm_qat): entry e at 2 e */
	const double *a0 = qv[0];
	if (k == 1) {
		for (int e = 0; e < 10; e++)
			q[e] = _mm_load_pd(a0 + 2 * e);
	} else if (k == 2) {
		const double *a1 = qv[1];
#define Q2(e) q[e] = _mm_add_pd(_mm_load_pd(a0 + 2 * (e)), _mm_load_pd(a1 + 2 * (e)))
		Q2(0), Q2(1), Q2(2), Q2(3), Q2(4), Q2(5), Q2(6), Q2(7), Q2(8), Q2(9);
#undef Q2
	} else {
		const double *a1 = qv[1], *a2 = qv[2];
#define Q3(e) q[e] = _mm_add_pd(_mm_add_pd(_mm_load_pd(a0 + 2 * (e)), _mm_load_pd(a1 + 2 * (e))), _mm_load_pd(a2 + 2 * (e)))
		Q3(0), Q3(1), Q3(2), Q3(3), Q3(4), Q3(5), Q3(6), Q3(7), Q3(8), Q3(9);
#undef Q3
	}
	__m128d tr = _mm_add_pd(_mm_add_pd(q[0], q[4]), q[7]);
	__m128d mu = _mm_mul_pd(_mm_set1_pd(1e-5), tr);
	__m128d a = _mm_add_pd(q[0], mu), b = q[1], cc = q[2], d = _mm_add_pd(q[4], mu), e = q[5], f = _mm_add_pd(q[7], mu);
	__m128d A1 = _mm_sub_pd(_mm_mul_pd(d, f), _mm_mul_pd(e, e));
	__m128d B1 = _mm_sub_pd(_mm_mul_pd(b, f), _mm_mul_pd(cc, e));
	__m128d C1 = _mm_sub_pd(_mm_mul_pd(b, e), _mm_mul_pd(cc, d));
	__m128d det = _mm_add_pd(_mm_sub_pd(_mm_mul_pd(a, A1), _mm_mul_pd(b, B1)), _mm_mul_pd(cc, C1));
	const __m128d neg = _mm_set1_pd(-0.0);
	__m128d r0 = _mm_add_pd(_mm_xor_pd(q[3], neg), _mm_mul_pd(mu, c[0]));
	__m128d r1 = _mm_add_pd(_mm_xor_pd(q[6], neg), _mm_mul_pd(mu, c[1]));
	__m128d r2 = _mm_add_pd(_mm_xor_pd(q[8], neg), _mm_mul_pd(mu, c[2]));
	__m128d F1 = _mm_sub_pd(_mm_mul_pd(r1, f), _mm_mul_pd(e, r2));  /* r1 f - e r2 */
	__m128d y[3];
	y[0] = _mm_div_pd(_mm_add_pd(_mm_sub_pd(_mm_mul_pd(r0, A1), _mm_mul_pd(b, F1)),
	                             _mm_mul_pd(cc, _mm_sub_pd(_mm_mul_pd(r1, e), _mm_mul_pd(d, r2)))),
	                  det);
	y[1] = _mm_div_pd(_mm_add_pd(_mm_sub_pd(_mm_mul_pd(a, F1), _mm_mul_pd(r0, B1)),
	                             _mm_mul_pd(cc, _mm_sub_pd(_mm_mul_pd(b, r2), _mm_mul_pd(r1, cc)))),
	                  det);
	y[2] = _mm_div_pd(_mm_add_pd(_mm_sub_pd(_mm_mul_pd(a, _mm_sub_pd(_mm_mul_pd(d, r2), _mm_mul_pd(r1, e))),
	                                        _mm_mul_pd(b, _mm_sub_pd(_mm_mul_pd(b, r2), _mm_mul_pd(r1, cc)))),
	                             _mm_mul_pd(r0, C1)),
	                  det);
	const __m128d two = _mm_set1_pd(2.0);
	__m128d val = _mm_mul_pd(_mm_mul_pd(q[0], y[0]), y[0]);
	val = _mm_add_pd(val, _mm_mul_pd(_mm_mul_pd(_mm_mul_pd(two, q[1]), y[0]), y[1]));
	val = _mm_add_pd(val, _mm_mul_pd(_mm_mul_pd(_mm_mul_pd(two, q[2]), y[0]), y[2]));
	val = _mm_add_pd(val, _mm_mul_pd(_mm_mul_pd(two, q[3]), y[0]));
	val = _mm_add_pd(val, _mm_mul_pd(_mm_mul_pd(q[4], y[1]), y[1]));
	val = _mm_add_pd(val, _mm_mul_pd(_mm_mul_pd(_mm_mul_pd(two, q[5]), y[1]), y[2]));
	val = _mm_add_pd(val, _mm_mul_pd(_mm_mul_pd(two, q[6]), y[1]));
	val = _mm_add_pd(val, _mm_mul_pd(_mm_mul_pd(q[7], y[2]), y[2]));
	val = _mm_add_pd(val, _mm_mul_pd(_mm_mul_pd(two, q[8]), y[2]));
	val = _mm_add_pd(val, q[9]);
	val = _mm_and_pd(_mm_cmpgt_pd(val, zero), val);
	__m128d dy = zero;
	for (int i = 0; i < 3; i++) {
		__m128d x = _mm_sub_pd(y[i], c[i]);
		dy = _mm_add_pd(dy, _mm_mul_pd(x, x));
	}
	val = _mm_add_pd(val, _mm_sub_pd(_mm_mul_pd(mu, dy), _mm_mul_pd(_mm_mul_pd(mu, R), R)));
	__m128d ym = _mm_add_pd(max_pd2(max_pd2(abs_pd2(c[0]), abs_pd2(c[1])), abs_pd2(c[2])), R);
	__m128d lin = _mm_add_pd(_mm_add_pd(abs_pd2(q[3]), abs_pd2(q[6])), abs_pd2(q[8]));
	__m128d sq = _mm_add_pd(_mm_add_pd(_mm_add_pd(abs_pd2(q[0]), abs_pd2(q[4])), abs_pd2(q[7])),
	                        _mm_mul_pd(two, _mm_add_pd(_mm_add_pd(abs_pd2(q[1]), abs_pd2(q[2])), abs_pd2(q[5]))));
	__m128d mag = _mm_add_pd(_mm_add_pd(abs_pd2(q[9]), _mm_mul_pd(_mm_mul_pd(two, lin), ym)), _mm_mul_pd(_mm_mul_pd(sq, ym), ym));
	val = _mm_sub_pd(val, _mm_mul_pd(_mm_set1_pd(1e-12), mag));
	/* The caller's tests (tr > 0 and finite, |det| > 0, val > 0 and
	 * finite) lane by lane: a lane that fails them gives +0. */
	const __m128d inf = _mm_set1_pd(HUGE_VAL);
	__m128d ok = _mm_and_pd(_mm_cmpgt_pd(tr, zero), _mm_cmplt_pd(tr, inf));
	ok = _mm_and_pd(ok, _mm_cmpgt_pd(abs_pd2(det), zero));
	ok = _mm_and_pd(ok, _mm_and_pd(_mm_cmpgt_pd(val, zero), _mm_cmplt_pd(val, inf)));
	return _mm_and_pd(ok, val);
}
#endif

/* A lower bound of the summed posed error (not normalised) of any
 * placement x within r of bary skinned with any convex combination of
 * the influences of the k vertices v: the bound for operations whose
 * vertices' influences differ. Per pose p, the posed location y = sum_j
 * w_j (L_j x + t_j) lies within R_p of c_p, the mean of the points z_j =
 * L_j bary + t_j over the joints j of the vertices (R_p = max_j |z_j -
 * c_p| + r max |L|, L any skin matrix's linear part, the Frobenius norm
 * bounding the spectral one).
 * The pose's summed quadric f satisfies, for every y, f(y) >= f(y_mu) +
 * mu |y_mu - c_p|^2 - mu |y - c_p|^2, y_mu the minimiser of f + mu |. -
 * c_p|^2 (a regularised solve, sound where f is singular), so f(y) >=
 * f(y_mu) + mu |y_mu - c_p|^2 - mu R_p^2: near each pose's own least
 * error, far above the bind pose's term alone. Slack covers the rounding
 * of the exact sum (float weights, cancellation in the quadric's value).
 * Returns -1 when it does not apply. */
static double posed_min_bound(mlod_bgm *g, const int *v, int k, const double *bary, double r)
{
	int J = g->joint_count, nj = 0;
	uint16_t joint[3 * MLOD_MAX_INFLUENCES];
	if (J <= 0)
		return -1.0;
	for (int i = 0; i < k; i++) {
		const mlod_influences *in = &g->inf[v[i]];
		if (in->count <= 0)
			return -1.0;
		for (int a = 0; a < in->count && a < MLOD_MAX_INFLUENCES; a++) {
			int s = 0;
			while (s < nj && joint[s] != in->joints[a])
				s++;
			if (s == nj)
				joint[nj++] = in->joints[a];
		}
	}
	size_t P = (size_t)g->pose_count;
	if (!(g->skin_norm > 0.0)) {
		/* The largest Frobenius norm of a skin matrix's linear part. */
		for (size_t m = 0; m < P * (size_t)J; m++) {
			double l = 0.0;
			for (int i = 0; i < 3; i++)
				for (int e = 0; e < 3; e++)
					l += (double)g->skin[12 * m + 4 * (size_t)i + (size_t)e] * g->skin[12 * m + 4 * (size_t)i + (size_t)e];
			g->skin_norm = max_d(g->skin_norm, sqrt(l));
		}
	}
	size_t D = (size_t)g->qpose_count;
	const double *qv[3];
	for (int i = 0; i < k; i++)
		qv[i] = g->quadric + (size_t)v[i] * D * 10;
	double lb = 0.0, rl = r * g->skin_norm, inv = 1.0 / nj;
	size_t p = 0;
#ifdef __SSE2__
	/* Two stored poses at a time, 2i in the low lane and 2i + 1 in the
	 * high one: every lane the same products, sums and tests, in the same
	 * order, as pose_min_bound's (SSE2 rounds as scalar code), and the
	 * poses' terms added in pose order. */
	if (g->skin2) {
		/* A last odd stored pose the same way, in both lanes (its own
		 * g->skin2 block, the vertices' entries doubled in last), the low
		 * lane taken. */
		size_t pairs = D / 2, n = (D + 1) / 2;
		_Alignas(16) double last[3][20];
		const double *ql[3];
		if (D & 1)
			for (int i = 0; i < k; i++) {
				for (int e = 0; e < 10; e++)
					last[i][2 * e] = last[i][2 * e + 1] = qv[i][20 * pairs + (size_t)e];
				ql[i] = last[i];
			}
		/* A pose that fails the tests gives +0, which leaves lb (from +0,
		 * never -0) as it was. With every pose stored, in order, the
		 * terms go to lb as they come; else pose p's term is its stored
		 * pose's: every stored pair's terms first (each stored pose is
		 * some pose's), then the sum in pose order (beyond PMB_MAX stored
		 * poses, one pose at a time below). */
		enum { PMB_MAX = 128 };
		double t[PMB_MAX];
		int all = D == P;
		if (all || 2 * n <= PMB_MAX) {
			for (size_t i2 = 0; i2 < n; i2++) {
				double val[2];
				const double *qp[3];
				for (int i = 0; i < k; i++)
					qp[i] = i2 < pairs ? qv[i] + 20 * i2 : ql[i];
				_mm_storeu_pd(all ? val : t + 2 * i2, pose_min_bound2(g, joint, nj, qp, k, i2, bary, rl, inv));
				if (all) {
					lb += val[0];
					if (i2 < pairs)
						lb += val[1];
				}
			}
			if (!all)
				for (size_t q = 0; q < P; q++)
					lb += t[g->qmap[q]];
			p = P;
		}
	}
#endif
	for (; p < P; p++) {
		double val = pose_min_bound(g, joint, nj, qv, k, p, bary, rl, inv);
		if (val > 0.0 && isfinite(val))
			lb += val;
	}
	return lb;
}

/* A weak key's bound before its normalising and tie-break, by the
 * collapsed nodes in their order (c = -1 for an edge). */
struct bgm_lbmemo {
	int a, b, c; /* a = -1: empty */
	double lb;
};

static unsigned lbmemo_hash(int a, int b, int c)
{
	unsigned h = (unsigned)a * 0x9E3779B1u;
	h = (h ^ (h >> 15)) + (unsigned)b * 0x85EBCA77u;
	h = (h ^ (h >> 13)) + (unsigned)c * 0xC2B2AE3Du;
	return h ^ (h >> 16);
}

/* The slot of (a, b, c): its entry, or the empty slot where it goes. */
BGM_INLINE struct bgm_lbmemo *lbmemo_slot(struct bgm_lbmemo *t, int cap, int a, int b, int c)
{
	unsigned m = (unsigned)cap - 1u, i = lbmemo_hash(a, b, c) & m;
	while (t[i].a >= 0 && !(t[i].a == a && t[i].b == b && t[i].c == c))
		i = (i + 1u) & m;
	return &t[i];
}

/* Remembers lb for (a, b, c) (nothing when out of memory: it is worked
 * out again next time). */
static void lbmemo_put(mlod_bgm *g, int a, int b, int c, double lb)
{
	if (2 * (g->lbmemo_count + 1) > g->lbmemo_cap) {
		int cap = g->lbmemo_cap > 0 ? 2 * g->lbmemo_cap : 1024;
		struct bgm_lbmemo *t = malloc(sizeof *t * (size_t)cap);
		if (!t)
			return;
		for (int i = 0; i < cap; i++)
			t[i].a = -1;
		for (int i = 0; i < g->lbmemo_cap; i++)
			if (g->lbmemo[i].a >= 0)
				*lbmemo_slot(t, cap, g->lbmemo[i].a, g->lbmemo[i].b, g->lbmemo[i].c) = g->lbmemo[i];
		free(g->lbmemo);
		g->lbmemo = t;
		g->lbmemo_cap = cap;
	}
	struct bgm_lbmemo *e = lbmemo_slot(g->lbmemo, g->lbmemo_cap, a, b, c);
	if (e->a < 0)
		g->lbmemo_count++;
	e->a = a, e->b = b, e->c = c, e->lb = lb;
}

/* A lower bound of the cost plan() finds for operation op on face f,
 * from the quadrics alone (no patch, no validity): the least over every
 * placement plan() may try, valid or not, plus plan()'s compactness
 * tie-break (of t, or of the edge's faces). Most queued operations die
 * with their face before they come up, so they are planned only when
 * popped, and go back with their cost when it is above the bound.
 *
 * The exact posed cost skins each placement with its own (Power
 * Skinning) influences. When the collapsed vertices share theirs, every
 * placement has them too, and the exact cost is the sum of the vertices'
 * posed quadrics pulled back into bind space (bgm_quadric_rest), the
 * bound being then the cost itself when the cheapest placement is valid.
 * Otherwise the bound is the bind pose's term alone, which no influence
 * changes (one skin matrix for every influence: quadric.c),
 * the other poses' terms not being negative; the optimal placement,
 * unknown here, lies within sqrt(lmax) of the barycenter (plan() drops
 * it beyond), where the convex quadric is at least its tangent plane at
 * the barycenter; or, when higher, posed_min_bound's sum over poses of
 * each pose's least error near where any of these placements can go,
 * whatever its weights. The fast cost (mlod_bgm_options.fast_cost) is the
 * pulled-back sum for every operation. */
BGM_INLINE double lower_key(mlod_bgm *g, int f, int op, int *weak)
{
	const bgm_face *F = &g->faces[f];
	int K = op == OP_TRIANGLE ? 3 : 2, v[3];
	double Q[10] = {0}, wsum = 0.0, bary[3] = {0, 0, 0}, x[3];
	const double *P[3];
	int same = 1;
	for (int j = 0; j < K; j++) {
		v[j] = F->n[op == OP_TRIANGLE ? j : (op + j) % 3];
		P[j] = g->nodes[v[j]].p;
		for (int i = 0; i < 3; i++)
			bary[i] += P[j][i] / K;
		wsum += g->rquad[(size_t)v[j] * BGM_RQUAD + 10];
		if (j > 0 && same)
			same = same_influences(&g->inf[v[0]], &g->inf[v[j]]);
	}
	double tie = collapse_tie(g, f, op, K);
	double lb, margin = 1.0;
	struct bgm_lbmemo *hit;
	if (same || g->opt.fast_cost) {
		for (int j = 0; j < K; j++) {
			const double *r = bgm_quadric_rest(g, v[j]);
#ifdef __SSE2__
			/* two entries at a time, each the same sum */
			_mm_storeu_pd(Q, _mm_add_pd(_mm_loadu_pd(Q), _mm_loadu_pd(r)));
			_mm_storeu_pd(Q + 2, _mm_add_pd(_mm_loadu_pd(Q + 2), _mm_loadu_pd(r + 2)));
			_mm_storeu_pd(Q + 4, _mm_add_pd(_mm_loadu_pd(Q + 4), _mm_loadu_pd(r + 4)));
			_mm_storeu_pd(Q + 6, _mm_add_pd(_mm_loadu_pd(Q + 6), _mm_loadu_pd(r + 6)));
			_mm_storeu_pd(Q + 8, _mm_add_pd(_mm_loadu_pd(Q + 8), _mm_loadu_pd(r + 8)));
#else
			for (int k = 0; k < 10; k++)
				Q[k] += r[k];
#endif
		}
		lb = bgm_quadric_eval(Q, bary);
		for (int j = 0; j < K; j++)
			lb = fmin(lb, bgm_quadric_eval(Q, P[j]));
		if (optimal_like(g) && bgm_quadric_solve(Q, bary, x) == 0)
			lb = fmin(lb, bgm_quadric_eval(Q, x));
	} else if (g->lbmemo_cap > 0 &&
	           (hit = lbmemo_slot(g->lbmemo, g->lbmemo_cap, v[0], v[1], K == 3 ? v[2] : -1))->a >= 0) {
		/* Worked out before for these nodes: the bound depends on nothing
		 * else (their bind positions, quadrics and influences, and the
		 * skin matrices, none of which changes). */
		lb = hit->lb;
		margin = 1.0 - 1e-9;
		*weak = 1;
	} else {
		/* the bind pose's entries: bgm_qat(P, 0, k) = st k */
		size_t st = bgm_qat(g->qpose_count, 0, 1);
		for (int j = 0; j < K; j++) {
			const double *q = g->quadric + (size_t)v[j] * (size_t)g->qpose_count * 10;
			Q[0] += q[0], Q[1] += q[st], Q[2] += q[2 * st], Q[3] += q[3 * st], Q[4] += q[4 * st];
			Q[5] += q[5 * st], Q[6] += q[6 * st], Q[7] += q[7 * st], Q[8] += q[8 * st], Q[9] += q[9 * st];
		}
		/* Pose 0 takes every bind position x to A x + t, one matrix
		 * (g->pose0) whatever the influences: its term is Q(A x + t), whose
		 * gradient in bind space is A^T times Q's there. */
		double yb[3], yp[3][3];
		const double *xb = bary, *xp[3] = {P[0], P[1], K == 3 ? P[2] : NULL};
		if (g->pose0_mapped) {
			const double *A = g->pose0;
			for (int i = 0; i < 3; i++)
				yb[i] = A[4 * i] * bary[0] + A[4 * i + 1] * bary[1] + A[4 * i + 2] * bary[2] + A[4 * i + 3];
			for (int j = 0; j < K; j++) {
				for (int i = 0; i < 3; i++)
					yp[j][i] = A[4 * i] * P[j][0] + A[4 * i + 1] * P[j][1] + A[4 * i + 2] * P[j][2] + A[4 * i + 3];
				xp[j] = yp[j];
			}
			xb = yb;
		}
		lb = bgm_quadric_eval(Q, xb);
		for (int j = 0; j < K; j++)
			lb = fmin(lb, bgm_quadric_eval(Q, xp[j]));
		if (optimal_like(g)) {
			double lmax = 0.0, gr[3], gl = 0.0;
			for (int e = 0; e < (K == 3 ? 3 : 1); e++) {
				double l = 0.0;
				for (int i = 0; i < 3; i++)
					l += (P[e][i] - P[(e + 1) % K][i]) * (P[e][i] - P[(e + 1) % K][i]);
				lmax = fmax(lmax, l);
			}
			gr[0] = Q[0] * xb[0] + Q[1] * xb[1] + Q[2] * xb[2] + Q[3];
			gr[1] = Q[1] * xb[0] + Q[4] * xb[1] + Q[5] * xb[2] + Q[6];
			gr[2] = Q[2] * xb[0] + Q[5] * xb[1] + Q[7] * xb[2] + Q[8];
			if (g->pose0_mapped) {
				const double *A = g->pose0;
				double w[3] = {gr[0], gr[1], gr[2]};
				for (int i = 0; i < 3; i++)
					gr[i] = A[i] * w[0] + A[4 + i] * w[1] + A[8 + i] * w[2];
			}
			for (int i = 0; i < 3; i++)
				gl += gr[i] * gr[i];
			double t = bgm_quadric_eval(Q, xb) - 2.0 * sqrt(gl) * sqrt(lmax) * (1.0 + 1e-9);
			lb = fmin(lb, t > 0.0 ? t : 0.0);
			lb = fmax(lb, posed_min_bound(g, v, K, bary, sqrt(lmax)));
		} else {
			/* Barycenter and vertices: within the longest edge too. */
			double lmax = 0.0;
			for (int e = 0; e < (K == 3 ? 3 : 1); e++) {
				double l = 0.0;
				for (int i = 0; i < 3; i++)
					l += (P[e][i] - P[(e + 1) % K][i]) * (P[e][i] - P[(e + 1) % K][i]);
				lmax = fmax(lmax, l);
			}
			lb = fmax(lb, posed_min_bound(g, v, K, bary, sqrt(lmax)));
		}
		lbmemo_put(g, v[0], v[1], K == 3 ? v[2] : -1, lb);
		margin = 1.0 - 1e-9; /* rounding: stay below the exact sum */
		*weak = 1;
	}
	double key = (wsum > 0.0 ? lb / wsum : 0.0) * margin + TIE_WEIGHT * tie;
	if (!*weak) {
		/* Along a border as the flags stand: plan()'s factor (exact_bound
		 * takes it for the others). */
		int nb = 0;
		for (int j = 0; j < K; j++)
			nb += (g->nodes[v[j]].flags & BGM_BORDER) != 0;
		if (nb >= 2)
			key *= border_factor(g);
	}
	return key;
}

/* A lower bound of plan()'s exact cost for operation op on face f that
 * is tighter than lower_key's bind-pose bound: the least exact cost over
 * every placement plan() may try, valid or not, with the arithmetic of
 * plan(), so that it is the planned cost when that placement is valid.
 * It skips the patch: operations whose bound rises above the queue's
 * head go back without being planned, and most die before they return. */
static double exact_bound(mlod_bgm *g, int f, int op, memo *mm)
{
	const bgm_face *F = &g->faces[f];
	struct plan pv; /* only k and v[] are used */
	int K = pv.k = op == OP_TRIANGLE ? 3 : 2;
	double bary[3] = {0, 0, 0}, cand[MAX_CANDIDATES][3], wsum = 0.0, *Q = g->qsum;
	const double *P[3];
	mlod_v3 V[3];
	mlod_influences in3[3];
	int nc = 0;
	for (int j = 0; j < K; j++) {
		pv.v[j] = F->n[op == OP_TRIANGLE ? j : (op + j) % 3];
		P[j] = g->nodes[pv.v[j]].p;
	}
	for (int i = 0; i < 3; i++)
		for (int j = 0; j < K; j++)
			bary[i] += P[j][i] / K;
	for (int j = 0; j < K; j++) {
		V[j] = (mlod_v3){(float)P[j][0], (float)P[j][1], (float)P[j][2]};
		in3[j] = g->inf[pv.v[j]];
	}
	int q_ready = 0, role[MAX_CANDIDATES];
	if (mm->known & MEMO_WSUM) {
		wsum = mm->wsum;
	} else {
		sum_quadrics(g, &pv, Q);
		q_ready = 1;
		for (int p = 0; p < g->pose_count; p++)
			wsum += Q[bgm_qat(g->qpose_count, g->qmap[p], 0)] + Q[bgm_qat(g->qpose_count, g->qmap[p], 4)] +
			        Q[bgm_qat(g->qpose_count, g->qmap[p], 7)];
		mm->wsum = wsum;
		mm->known |= MEMO_WSUM;
	}
	if (optimal_like(g)) {
		mlod_influences w;
		double opt[3];
		if (!mm->opt_state) {
			if (!q_ready)
				sum_quadrics(g, &pv, Q), q_ready = 1;
			skin_role(mm, 4, V, in3, K, bary, &w);
			mm->opt_state = bgm_quadric_optimum(g, Q, &w, bary, mm->opt) == 0 ? 1 : 2;
		}
		memcpy(opt, mm->opt, sizeof opt);
		if (mm->opt_state == 1) {
			if (near_collapsed(P, K, bary, opt)) {
				role[nc] = 0;
				memcpy(cand[nc++], opt, sizeof cand[0]);
			}
		}
	}
	for (int j = 0; j < K; j++) {
		role[nc] = 1 + j;
		memcpy(cand[nc++], P[j], sizeof cand[0]);
	}
	int vertex = g->opt.placement == MLOD_PLACE_VERTEX;
	if (!vertex) {
		role[nc] = 4;
		memcpy(cand[nc++], bary, sizeof cand[0]);
	}
	if (g->opt.placement == MLOD_PLACE_HYBRID && g->opt.cost == MLOD_COST_POSED)
		for (int j = 0; j < K; j++) { /* kept whole */
			role[nc] = 5 + j;
			memcpy(cand[nc++], P[j], sizeof cand[0]);
		}
	/* The least sum so far (the least stays the least divided by wsum):
	 * a candidate's sum stops once it reaches it, its terms being
	 * positive, and is then neither the least nor memoised (plan() sums
	 * it when it needs it). */
	double best = HUGE_VAL, least = HUGE_VAL;
	for (int k = 0; k < nc; k++) {
		mlod_influences w;
		if (vertex)
			w = in3[role[k] - 1]; /* as plan() skins it */
		else if (role[k] >= 5)
			w = in3[role[k] - 5];
		else
			skin_role(mm, role[k], V, in3, K, cand[k], &w);
		if (g->joint_count > 0 && w.count == 0)
			continue;
		double e, reached;
		if (mm->known >> role[k] & 1u) {
			e = mm->e[role[k]];
		} else {
			if (!q_ready)
				sum_quadrics(g, &pv, Q), q_ready = 1;
			e = bgm_quadric_error_reach(g, Q, &w, cand[k], least, &reached);
			if (e == HUGE_VAL && least < HUGE_VAL) {
				/* at least the least: the minimum stays; plan() may
				 * skip it (plan_stop) */
				mm->ge[role[k]] = reached;
				mm->stopped |= 1u << role[k];
				continue;
			}
			mm->e[role[k]] = e;
			mm->known |= 1u << role[k];
		}
		/* As plan(): a free end with the vertex's own influences costs
		 * what the vertex kept whole costs. */
		if (!vertex && role[k] >= 1 && role[k] <= 3 && g->opt.placement == MLOD_PLACE_HYBRID &&
		    same_influences(&w, &in3[role[k] - 1])) {
			mm->e[role[k] + 4] = e;
			mm->known |= 1u << (role[k] + 4);
		}
		least = fmin(least, e);
		best = fmin(best, wsum > 0.0 ? e / wsum : 0.0);
	}
	if (best == HUGE_VAL)
		best = 0.0;
	double tie = collapse_tie(g, f, op, K);
	/* Along a border (two border vertices as the flags stand), plan()'s
	 * cost is border_factor() times this: so is the bound, and such an
	 * operation goes back at it without being planned first. */
	int nb = 0;
	for (int j = 0; j < K; j++)
		nb += (g->nodes[pv.v[j]].flags & BGM_BORDER) != 0;
	if (nb >= 2)
		return (best + TIE_WEIGHT * tie) * border_factor(g);
	return best + TIE_WEIGHT * tie;
}

/* Queues operation op on face f (new, or back from being blocked). */
static int push_op(mlod_bgm *g, int f, int op, struct plan *scratch)
{
	const bgm_face *F = &g->faces[f];
	for (int i = 0; i < 3; i++) {
		if (op != OP_TRIANGLE && i != op && i != (op + 1) % 3)
			continue;
		int fl = g->nodes[F->n[i]].flags;
		if ((fl & BGM_LOCKED) || !(fl & BGM_ELIGIBLE) || (!borders_ok(g) && (fl & BGM_BORDER)))
			return 0; /* never collapsible while these nodes live */
	}
	double key;
	int weak = 0;
	if (lazy_keys(g)) {
		key = lower_key(g, f, op, &weak);
	} else if (g->opt.cost == MLOD_COST_POSED) {
		if (!plan(g, f, op, !g->opt.fast_cost, scratch, NULL)) {
			g->opstate[f] |= (unsigned char)BLOCKED(op);
			return 0;
		}
		key = scratch->cost;
	} else {
		key = bgm_compactness(g->nodes[F->n[0]].p, g->nodes[F->n[1]].p, g->nodes[F->n[2]].p);
	}
	g->opstate[f] |= (unsigned char)QUEUED(op);
	return heap_push(&g->heap, key, f, op, weak, -1);
}

/* 1 when the face across edge e of face f holds a queue entry for that
 * edge. An edge has two faces and is queued from one of them. */
BGM_INLINE int queued_across(const mlod_bgm *g, int f, int e)
{
	const bgm_face *F = &g->faces[f];
	int across = F->adj[e];
	if (across < 0)
		return 0;
	const bgm_face *A = &g->faces[across];
	for (int k = 0; k < 3; k++)
		if (A->n[k] == F->n[(e + 1) % 3] && A->n[(k + 1) % 3] == F->n[e])
			return (g->opstate[across] & QUEUED(k)) != 0;
	return 0;
}

/* Queues face f's triangle collapse and its edges, as the option asks,
 * except edges the face across has queued. The queue is lazy: a popped
 * entry is planned (with the posed cost, queued under lower_key's bound,
 * for the first time) and goes back with its cost when that is above its
 * key; one whose cost fell (its neighbourhood changed which placements
 * are valid) waits at its old key, an approximation that saves
 * re-planning every operation around each collapse. */
static int push_face(mlod_bgm *g, int f, struct plan *scratch)
{
	if (g->opt.op != MLOD_OP_EDGE && push_op(g, f, OP_TRIANGLE, scratch))
		return -1;
	if (g->opt.op == MLOD_OP_TRIANGLE)
		return 0;
	for (int e = 0; e < 3; e++)
		if (!queued_across(g, f, e) && push_op(g, f, e, scratch))
			return -1;
	return 0;
}

/* 1 when node v has a live edge with one face. */
static int on_border(const mlod_bgm *g, int v)
{
	const bgm_node *n = &g->nodes[v];
	for (int i = 0; i < n->inc_count; i++) {
		const bgm_face *F = &g->faces[g->inc[n->inc_first + i]];
		for (int e = 0; e < 3; e++)
			if (F->adj[e] < 0 && (F->n[e] == v || F->n[(e + 1) % 3] == v))
				return 1;
	}
	return 0;
}

/* Applies a planned collapse; returns 0, or -1 when out of memory. */
static int apply(mlod_bgm *g, struct plan *pl)
{
	int rec = g->record_count, stamp = rec + 1;
	if (bgm_grow((void **)&g->records, &g->record_cap, rec + 1, sizeof *g->records) ||
	    bgm_grow((void **)&g->removed, &g->removed_cap, g->removed_len + pl->nf, sizeof *g->removed))
		return -1;
	int v = bgm_add_node(g);
	if (v < 0)
		return -1;
	bgm_node *N = &g->nodes[v];
	for (int i = 0; i < 3; i++)
		N->p[i] = pl->pos[i];
	g->inf[v] = pl->inf;
	int fl = 0, K = pl->k;
	for (int i = 0; i < K; i++)
		fl |= g->nodes[pl->v[i]].flags & BGM_BORDER;
	if (bgm_node_eligible(g, &pl->inf))
		fl |= BGM_ELIGIBLE;
	N->flags = fl;
	if (g->lay.morph_stride > 0) {
		float *m = g->morph + (size_t)v * (size_t)g->lay.morph_stride;
		for (int k = 0; k < g->lay.morph_stride; k++) {
			double x = 0.0;
			for (int i = 0; i < K; i++)
				x += pl->lambda[i] * g->morph[(size_t)pl->v[i] * (size_t)g->lay.morph_stride + (size_t)k];
			m[k] = (float)x;
		}
	}
	if (g->pose_count > 0) {
		/* The parents' sums, each from 0 in their order (sum_quadrics). */
		sum_quadrics(g, pl, g->quadric + (size_t)v * (size_t)g->qpose_count * 10);
		bgm_quadric_rest_reset(g, v);
	}

	/* New wedges. Snapped: one per wedge group, a copy of the snap vertex's
	 * wedge there. Free (no texture seam at a, b, c): the attributes
	 * interpolated inside t, except that corners of a vertex with hard
	 * normal edges keep their own normals (so faceted meshes stay
	 * faceted); equal results share a wedge. */
	int gw[MAX_WEDGES], cw[MAX_PATCH];
	int S = g->lay.stride;
	if (pl->whole) {
		/* One new wedge per wedge of v[snap] taken, a copy of it. */
		for (int j = 0; j < pl->nk; j++) {
			int prev = -1;
			for (int i = 0; i < j && prev < 0; i++)
				if (pl->src[i] == pl->src[j])
					prev = cw[i];
			if (prev >= 0) {
				cw[j] = prev;
				continue;
			}
			if ((cw[j] = bgm_add_wedge(g, v)) < 0)
				return -1;
			if (S > 0)
				memcpy(g->wedge_attr + (size_t)cw[j] * (size_t)S, g->wedge_attr + (size_t)pl->src[j] * (size_t)S,
				       sizeof(float) * (size_t)S);
		}
	} else if (pl->snap >= 0) {
		for (int k = 0; k < pl->ngroups; k++) {
			if ((gw[k] = bgm_add_wedge(g, v)) < 0)
				return -1;
			for (int i = 0; i < pl->nw; i++)
				if (pl->group[i] == k && g->wedge_node[pl->wedges[i]] == pl->v[pl->snap] && S > 0)
					memcpy(g->wedge_attr + (size_t)gw[k] * (size_t)S, g->wedge_attr + (size_t)pl->wedges[i] * (size_t)S,
					       sizeof(float) * (size_t)S);
		}
		for (int j = 0; j < pl->nk; j++)
			cw[j] = gw[pl->group[wedge_slot(pl, g->faces[pl->kept[j]].w[pl->corner[j]])]];
	} else {
		int base = bgm_add_wedge(g, v), T = g->prim->target_count;
		if (base < 0)
			return -1;
		/* The collapsed vertices' wedges in t (an edge: its two ends). */
		const bgm_face *TF = &g->faces[pl->t];
		int tw[3] = {TF->w[0], TF->w[1], TF->w[2]};
		if (K == 2)
			tw[0] = TF->w[pl->op], tw[1] = TF->w[(pl->op + 1) % 3], tw[2] = tw[0];
		interpolate_wedge(g, base, tw, pl->lambda);
		for (int j = 0; j < pl->nk; j++) {
			int w = g->faces[pl->kept[j]].w[pl->corner[j]], x = g->wedge_node[w];
			int o = x == pl->v[0] ? 0 : x == pl->v[1] ? 1 : 2;
			cw[j] = base;
			if (!pl->hard[o] || S == 0)
				continue;
			/* The interpolated wedge with this corner's own normals. */
			int nw = bgm_add_wedge(g, v);
			if (nw < 0)
				return -1;
			float *dst = g->wedge_attr + (size_t)nw * (size_t)S;
			const float *own = g->wedge_attr + (size_t)w * (size_t)S;
			memcpy(dst, g->wedge_attr + (size_t)base * (size_t)S, sizeof(float) * (size_t)S);
			for (int k = 0; k < S; k++)
				if (is_normal_float(&g->lay, k, T))
					dst[k] = own[k];
			cw[j] = nw;
			for (int prev = base; prev < nw; prev++) /* this collapse's wedges are contiguous */
				if (memcmp(g->wedge_attr + (size_t)prev * (size_t)S, dst, sizeof(float) * (size_t)S) == 0) {
					cw[j] = prev;
					g->wedge_count--; /* drop the duplicate just made (the last) */
					break;
				}
		}
	}

	/* Remove the patch. */
	for (int j = 0; j < pl->nf; j++) {
		bgm_face *f = &g->faces[pl->faces[j]];
		f->death = stamp;
		unsigned queued = g->opstate[pl->faces[j]] >> 4;
		g->heap.dead += (int)(queued & 1u) + (int)(queued >> 1 & 1u) + (int)(queued >> 2 & 1u) + (int)(queued >> 3 & 1u);
		g->opstate[pl->faces[j]] = DEAD;
		for (int k = 0; k < 3; k++)
			bgm_inc_remove(g, f->n[k], pl->faces[j]);
		g->removed[g->removed_len + j] = pl->faces[j];
	}
	for (int i = 0; i < K; i++)
		g->nodes[pl->v[i]].flags |= BGM_DEAD;
	g->live_triangles -= pl->nf;

	/* Re-mesh it around v-bar. */
	int first = g->face_count;
	for (int j = 0; j < pl->nk; j++) {
		const bgm_face *old = &g->faces[pl->kept[j]];
		int w[3];
		for (int k = 0; k < 3; k++)
			w[k] = old->w[k];
		w[pl->corner[j]] = cw[j];
		int f = bgm_add_face(g, w, stamp);
		if (f < 0)
			return -1;
		for (int k = 0; k < 3; k++)
			if (bgm_inc_add(g, g->faces[f].n[k], f))
				return -1;
	}
	g->live_triangles += pl->nk;
	/* The dual graph of the new faces. */
	for (int j = 0; j < pl->nk; j++) {
		int f = first + j, ci = pl->corner[j];
		bgm_face *F = &g->faces[f];
		const bgm_face *old = &g->faces[pl->kept[j]];
		int p = F->n[(ci + 1) % 3], q = F->n[(ci + 2) % 3];
		/* (p, q): the face that was across it, or its replacement. */
		int across = old->adj[(ci + 1) % 3];
		int repl = -1;
		for (int k = 0; k < pl->nk && across >= 0; k++)
			if (pl->kept[k] == across)
				repl = first + k;
		if (repl >= 0) {
			F->adj[(ci + 1) % 3] = repl;
		} else if (across >= 0) {
			F->adj[(ci + 1) % 3] = across;
			bgm_face *A = &g->faces[across];
			for (int k = 0; k < 3; k++)
				if (A->adj[k] == pl->kept[j])
					A->adj[k] = f;
		}
		/* (v-bar, p) and (q, v-bar): the new faces whose links end at p
		 * and start at q. */
		for (int k = 0; k < pl->nk; k++) {
			const bgm_face *G = &g->faces[first + k];
			int ck = pl->corner[k];
			if (G->n[(ck + 2) % 3] == p)
				F->adj[ci] = first + k;
			if (G->n[(ck + 1) % 3] == q)
				F->adj[(ci + 2) % 3] = first + k;
		}
	}

	/* Border flags as the new faces leave them: a collapse along a border
	 * can close a hole, leaving v-bar or a ring vertex inside. */
	/* Each node once (v-bar is a corner of every new face, a ring vertex
	 * of one or two): on_border reads faces, not flags. */
	int seen[2 * MAX_PATCH + 1], ns = 0;
	for (int j = 0; j < pl->nk; j++)
		for (int k = 0; k < 3; k++) {
			int x = g->faces[first + j].n[k], dup = 0;
			for (int i = 0; i < ns && !dup; i++)
				dup = seen[i] == x;
			if (dup)
				continue;
			seen[ns++] = x;
			bgm_node *n = &g->nodes[x];
			if (on_border(g, x))
				n->flags |= BGM_BORDER;
			else
				n->flags &= ~BGM_BORDER;
		}

	mlod_vsplit *r = &g->records[g->record_count++];
	memset(r, 0, sizeof *r);
	for (int i = 0; i < 3; i++)
		r->parents[i] = pl->v[i];
	r->parent_count = K;
	r->node = v;
	r->snapped = pl->snap;
	r->removed_first = g->removed_len;
	r->removed_count = pl->nf;
	r->added_first = first;
	r->added_count = pl->nk;
	r->triangles = g->live_triangles;
	r->capped = pl->capped;
	r->cost = pl->cost;
	g->removed_len += pl->nf;
	g->caps += pl->capped;
	g->snaps += pl->snap >= 0;
	if (grow_face_arrays(g))
		return -1;
	/* Each new face stands for what the face it replaced stood for. */
	for (int j = 0; j < pl->nk; j++)
		memcpy(g->fref + 4 * (size_t)(first + j), pl->rnormal[j], 4 * sizeof *g->fref);
	return 0;
}

mlod_result mlod_bgm_simplify(mlod_bgm *g, int target, int max_collapses, mlod_error *err)
{
	if (!g)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_bgm_simplify: NULL");
	double t0 = bgm_seconds();
	mlod_result r = MLOD_OK;
	struct plan *pl = malloc(sizeof *pl), *scratch = malloc(sizeof *scratch);
	if (!g->qsum && g->pose_count > 0)
		g->qsum = malloc(sizeof(double) * 10 * (size_t)g->pose_count);
	if (!pl || !scratch || grow_face_arrays(g) || (g->pose_count > 0 && !g->qsum)) {
		r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory simplifying");
		goto done;
	}
	if (!g->heap.ready) {
		g->heap.ready = 1;
		g->swept = g->record_count;
		g->heap.memo_free = -1;
		for (int f = 0; f < g->face_count; f++)
			if (g->faces[f].death == BGM_ALIVE && push_face(g, f, scratch)) {
				r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory simplifying");
				goto done;
			}
	}
	int done_count = 0;
	while ((target <= 0 || g->live_triangles > target) && (max_collapses <= 0 || done_count < max_collapses)) {
		if (g->heap.count == 0) {
			/* Nothing else collapses: without --allow-border, open borders
			 * go last (every prefix before is what it was without them).
			 * Every live face is queued again, border collapses with it. */
			if (!borders_ok(g) && g->border_edges > 0)
				g->border_phase = 1;
			else if (g->record_count == g->swept)
				break;
			g->swept = g->record_count;
			g->heap.dead = 0;
			for (int f = 0; f < g->opstate_cap; f++)
				g->opstate[f] = f < g->face_count && g->faces[f].death != BGM_ALIVE ? DEAD : 0;
			for (int f = 0; f < g->face_count; f++)
				if (g->faces[f].death == BGM_ALIVE && push_face(g, f, scratch)) {
					r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory simplifying");
					goto done;
				}
			continue;
		}
		/* Mostly dead entries: drop them at once (the same order). */
		if (g->heap.dead > 256 && 2 * g->heap.dead > g->heap.count && !g->heap.unordered && !g->heap.no_purge) {
			heap_purge(&g->heap, g->opstate, DEAD);
			continue;
		}
		heap_entry e = heap_pop(&g->heap);
		if (g->opstate[e.face] == DEAD) {
			g->heap.dead -= g->heap.dead > 0;
			memo_release(&g->heap, e.memo);
			continue;
		}
		/* An operation going back keeps what its placements cost. */
		memo local, *mm = e.memo >= 0 ? &g->heap.memo[e.memo] : &local;
		if (e.memo < 0) {
			/* Nothing known: the rest is read only once its bit says it
			 * was written (not cleared at every pop: w[] is large). */
			local.opt_state = 0;
			local.known = local.skinned = local.stopped = 0;
			local.next_free = -1;
		}
		double back = -1.0;
		if (e.weak) {
			double b = exact_bound(g, e.face, e.op, mm);
			if (b > e.key * (1.0 + 1e-9) + 1e-300)
				back = b;
		}
		if (back < 0.0) {
			g->opstate[e.face] &= (unsigned char)~QUEUED(e.op);
			if (!plan(g, e.face, e.op, !g->opt.fast_cost, pl, g->opt.fast_cost ? NULL : mm)) {
				memo_release(&g->heap, e.memo);
				g->refused++;
				g->opstate[e.face] |= (unsigned char)BLOCKED(e.op);
				continue;
			}
			if (g->opt.cost == MLOD_COST_POSED && pl->cost > e.key * (1.0 + 1e-9) + 1e-300) {
				g->opstate[e.face] |= (unsigned char)QUEUED(e.op);
				back = pl->cost;
			}
		}
		if (back >= 0.0) {
			int slot = e.memo;
			if (slot < 0 && !g->opt.fast_cost && (slot = memo_add(&g->heap, &local)) < 0) {
				r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory simplifying");
				goto done;
			}
			if (heap_push(&g->heap, back, e.face, e.op, 0, slot)) {
				r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory simplifying");
				goto done;
			}
			continue;
		}
		memo_release(&g->heap, e.memo);
		int first = g->face_count;
		if (apply(g, pl)) {
			r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory simplifying");
			goto done;
		}
		done_count++;
		g->records[g->record_count - 1].seconds = g->collapse_seconds + (bgm_seconds() - t0);
		/* Queue the new faces, and give blocked faces around the patch
		 * another chance: their neighbourhood changed. */
		for (int f = first; f < g->face_count; f++)
			if (push_face(g, f, scratch)) {
				r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory simplifying");
				goto done;
			}
		int v = g->node_count - 1;
		const bgm_node *N = &g->nodes[v];
		for (int k = 0; k < N->inc_count; k++) {
			const bgm_face *F = &g->faces[g->inc[N->inc_first + k]];
			for (int i = 0; i < 3; i++) {
				if (F->n[i] == v)
					continue;
				int ring = F->n[i];
				const bgm_node *L = &g->nodes[ring];
				for (int m = 0; m < L->inc_count; m++) {
					int h = g->inc[L->inc_first + m];
					if (h >= first || !(g->opstate[h] & ALL_BLOCKED))
						continue;
					/* Its triangle, and its edges that end at the ring
					 * vertex (the others' patches did not change). */
					const bgm_face *H = &g->faces[h];
					unsigned retry = BLOCKED(OP_TRIANGLE);
					for (int e = 0; e < 3; e++)
						if (H->n[e] == ring || H->n[(e + 1) % 3] == ring)
							retry |= BLOCKED(e);
					unsigned bits = g->opstate[h] & retry;
					g->opstate[h] &= (unsigned char)~retry;
					for (int op = 0; op <= OP_TRIANGLE; op++)
						if ((bits >> op & 1u) && (op == OP_TRIANGLE || !queued_across(g, h, op)) &&
						    push_op(g, h, op, scratch)) {
							r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory simplifying");
							goto done;
						}
				}
			}
		}
	}
done:
	free(pl);
	free(scratch);
	g->collapse_seconds += bgm_seconds() - t0;
	return r;
}
