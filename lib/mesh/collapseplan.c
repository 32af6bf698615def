/*
 * collapseplan.c: an operation worked out before it is applied
 * (bgm_plan_op): its patch (the faces around the collapsed vertices),
 * whether it is valid, and the cheapest valid placement of v-bar with
 * its weights, attribute weights and cost.
 *
 * The validity checks are those collapse.c lists: locked or ineligible
 * vertices, a pinched or closed border, a patch that would not be one fan
 * around v-bar, a re-meshed face degenerate, turned too far from its
 * normal or its reference, or facing away from its corners' NORMAL
 * attribute, and wedge groups that cannot be carried over at a texture
 * seam. The placements tried are the posed quadric's optimum, the
 * collapsed vertices, the barycenter, and (hybrid) the vertices kept
 * whole, each priced by its posed cost with its Power Skinning weights
 * (collapsecost.c); a candidate's sum stops once it cannot win.
 */
#include <math.h>
#include <string.h>

#include "collapse.h"

#define FLIP_COS 0.2        /* a re-meshed face may turn by less than ~78 degrees */
#define REF_COS 0.0         /* and face less than 90 degrees away from its reference (78:
                             * the robot's 10% level 5.54% -> 10.19% Hausdorff, bench/RESULTS.md) */
#define DEGENERATE 1e-3     /* compactness under which a new face counts as degenerate */

/* Face h's reference normal (0-2) and its length (3): an input face's
 * own bgm_face_normal; a face a collapse made has the reference of the
 * face it replaced (the same face with its v-bar corner moved), so each
 * face keeps the orientation of the input face it descends from. */
static const double *face_ref(mlod_bgm *g, int h)
{
	double *r = g->fref + 4 * (size_t)h;
	if (isnan(r[3]))
		memcpy(r, bgm_face_geo(g, h), 4 * sizeof *r); /* only input faces: apply sets the others' */
	return r;
}

static int find(int *parent, int i)
{
	while (parent[i] != i)
		i = parent[i] = parent[parent[i]];
	return i;
}

/* Which of the collapsed vertices node n is (0 .. k-1), or -1. */
static int owner_of(const bgm_plan *pl, int n)
{
	/* v[2] is -1 for an edge (bgm_plan_op() sets it), never a node */
	return n == pl->v[0] ? 0 : n == pl->v[1] ? 1 : n == pl->v[2] ? 2 : -1;
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
				if (bgm_is_normal_float(L, k, T))
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

/* The NORMAL attribute bgm_apply() gives v-bar's corner of kept[j] (unit,
 * or 0 without normals): a copy of a wedge of the kept vertex or the
 * snap vertex, else interpolate_wedge's, the corner's own normal at a
 * hard edge. */
static void vbar_normal(const mlod_bgm *g, const bgm_plan *pl, int j, double *n, double *interp)
{
	const bgm_layout *L = &g->lay;
	n[0] = n[1] = n[2] = 0.0;
	if (L->normal < 0 || L->stride == 0)
		return;
	int S = L->stride, w = g->faces[pl->kept[j]].w[pl->corner[j]], from = -1;
	if (pl->whole) {
		from = pl->src[j];
	} else if (pl->snap >= 0) {
		int k = pl->group[bgm_wedge_slot(pl, w)];
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
 * of their corners, v-bar's as bgm_apply() will make it: a face facing more
 * than 90 degrees away from their sum is inside out where it is shaded.
 * (Checking the two other corners for every placement in geometry_ok as
 * well refused more: Ely's 10% level 1.31% -> 2.47% Hausdorff.) */
static int normals_ok(const mlod_bgm *g, const bgm_plan *pl)
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
static int geometry_ok(const mlod_bgm *g, const bgm_plan *pl, const double *x)
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

/* Vertex placement: which wedge of v[snap] each kept face's corner takes,
 * copied whole. Its own corners keep theirs; another vertex's corner the
 * one wedge of v[snap] in its wedge group (a texture seam: bgm_plan_op() made
 * sure there is exactly one), else (normals differ only: hard edges) the
 * wedge of v[snap] whose normal is nearest its own, the first of equals. */
static void vertex_wedges(const mlod_bgm *g, bgm_plan *pl, const int *owner)
{
	const bgm_layout *L = &g->lay;
	int S = L->stride, s = pl->snap;
	for (int j = 0; j < pl->nk; j++) {
		int w = g->faces[pl->kept[j]].w[pl->corner[j]], slot = bgm_wedge_slot(pl, w);
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

/* The patch of pl's collapsed vertices (pl->v, pl->k): its faces, those
 * removed (two or more collapsed vertices) and those kept, each kept
 * face's v-bar corner and the link edge opposite it (from[j] -> to[j]).
 * 0 when the operation is refused: a patch of more than MAX_PATCH faces,
 * a triangle whose patch has not exactly one face with all three
 * vertices, nothing kept, or a collapsed edge with more than two faces. */
static int plan_patch(const mlod_bgm *g, bgm_plan *pl, int *from, int *to)
{
	int K = pl->k;
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
	int all3 = 0;
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
	return 1;
}

/* The wedge groups of the patch: pl->wedges are the collapsed vertices'
 * wedges on its faces, owner[i] the collapsed vertex wedge i is of,
 * pl->group[i] its group (wedges joined through removed faces), and
 * per[k][o] how many wedges collapsed vertex o has in group k. 0 when
 * the patch has more than MAX_WEDGES of them. */
static int plan_wedge_groups(const mlod_bgm *g, bgm_plan *pl, int *owner, int (*per)[3])
{
	int parent[MAX_WEDGES];
	pl->nw = 0;
	for (int j = 0; j < pl->nf; j++) {
		const bgm_face *f = &g->faces[pl->faces[j]];
		for (int k = 0; k < 3; k++) {
			int o = owner_of(pl, f->n[k]);
			if (o < 0 || bgm_wedge_slot(pl, f->w[k]) >= 0)
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
			int s = bgm_wedge_slot(pl, f->w[k]);
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
	memset(per, 0, sizeof per[0] * (size_t)pl->ngroups); /* the groups' rows */
	for (int i = 0; i < pl->nw; i++)
		per[pl->group[i]][owner[i]]++;
	return 1;
}

/* The candidate placements of an operation: v-bar's position, its role
 * (bgm_memo), the collapsed vertex it is at (-1: none), whether that
 * vertex is kept whole, and the vertex v-bar snaps to (-1: free). */
typedef struct plan_cands {
	double x[MAX_CANDIDATES][3];
	int role[MAX_CANDIDATES], at[MAX_CANDIDATES], whole[MAX_CANDIDATES], snap[MAX_CANDIDATES];
	int n;
} plan_cands;

static void cand_add(plan_cands *c, const double *x, int role, int at, int whole, int snap)
{
	memcpy(c->x[c->n], x, sizeof c->x[c->n]);
	c->role[c->n] = role;
	c->at[c->n] = at;
	c->whole[c->n] = whole;
	c->snap[c->n++] = snap;
}

/* Where bgm_plan_op() stops summing a candidate of family fam: once it cannot
 * beat the best of its family (a whole vertex: nor be kept, costing more
 * than both the free best and the cap), with a margin far above
 * rounding, so that the choice is the one the full sum makes. */
BGM_INLINE double plan_stop(const mlod_bgm *g, const bgm_plan *pl, int fam, const int *bestf, const double *costf,
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

/* Works out operation op on face t (its triangle collapse, or the
 * collapse of one of its edges); returns 1 when it is valid (pl holds
 * the cheapest valid placement), else 0. */

int bgm_plan_op(mlod_bgm *g, int t, int op, int exact, bgm_plan *pl, bgm_memo *mm)
{
	const bgm_face *T = &g->faces[t];
	int allow_border = bgm_borders_ok(g);
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
	int from[MAX_PATCH], to[MAX_PATCH];
	if (!plan_patch(g, pl, from, to))
		return 0;
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
	int owner[MAX_WEDGES], per[MAX_WEDGES][3];
	if (!plan_wedge_groups(g, pl, owner, per))
		return 0;

	/* Candidate placements. */
	plan_cands c;
	c.n = 0;
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
			cand_add(&c, P[s], 1 + s, s, vertex, s);
		}
		if (c.n == 0)
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
			cand_add(&c, P[s], 1 + s, s, vertex, vertex ? s : -1);
		}
		if (K == 2 && nb == 2 && !vertex) {
			cand_add(&c, bary, 4, -1, 0, -1);
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
		bgm_sum_quadrics(g, pl, Q);
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
			cand_add(&c, P[s], 1 + s, s, 1, s);
		}
	} else if (!(special[0] || special[1] || special[2]) && !border) {
		if (bgm_optimal_like(g) && g->pose_count > 0) {
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
					bgm_sum_quadrics(g, pl, Q), q_ready = 1;
				bgm_skin_role(mm, 4, V, in3, K, bary, &w);
				found = bgm_quadric_optimum(g, Q, &w, bary, opt) == 0;
				if (mm) {
					mm->opt_state = found ? 1 : 2;
					memcpy(mm->opt, opt, sizeof opt);
				}
			}
			if (found && bgm_near_collapsed(P, K, bary, opt))
				cand_add(&c, opt, 0, -1, 0, -1);
			/* An edge may also go to either end (a half-edge collapse),
			 * with that end's attributes. */
			for (int s = 0; s < K && K == 2; s++) {
				cand_add(&c, P[s], 1 + s, s, 0, -1);
			}
		}
		cand_add(&c, bary, 4, -1, 0, -1);
	}
	if (hybrid) {
		/* Each collapsed vertex the placements above may go to (all of
		 * them away from seams and borders), kept whole too: last, so
		 * that the others' least cost is known when they are tried. */
		int n0 = c.n, any = !(special[0] || special[1] || special[2]) && !border;
		for (int s = 0; s < K; s++) {
			int offered = any;
			for (int i = 0; i < n0; i++)
				offered |= c.at[i] == s;
			if (!offered)
				continue;
			cand_add(&c, P[s], 5 + s, s, 1, s);
		}
	}

	/* The kept faces as they are, for geometry_ok: their normals and
	 * their references. */
	for (int i = 0; i < pl->nk; i++) {
		const double *o = bgm_face_geo(g, pl->kept[i]);
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
		tie = bgm_face_tie(g, t);
	} else {
		for (int j = 0; j < pl->nr; j++)
			tie += bgm_face_tie(g, pl->removed[j]) / pl->nr;
	}
	/* The fast posed cost does not depend on the influences: rank the
	 * candidates by it, and the first valid one is the choice (the one
	 * the loop below would make, ties going to the earlier). */
	int order[MAX_CANDIDATES];
	double ckey[MAX_CANDIDATES];
	int ranked = fast && g->opt.cost == MLOD_COST_POSED && !hybrid;
	for (int k = 0; k < c.n; k++) {
		order[k] = k;
		if (!ranked)
			continue;
		double e = g->pose_count > 0 ? bgm_quadric_eval(R, c.x[k]) : 0.0;
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
	for (int kk = 0; kk < c.n; kk++) {
		int k = order[kk], fam = hybrid && c.whole[k];
		int late = late_geo && (bestf[0] >= 0 || (mm && (mm->known >> c.role[k] & 1u)));
		/* A sum that stopped before (bgm_exact_bound's, or an earlier
		 * plan's) at a partial sum the stop here does not exceed
		 * stops here too (bgm_quadric_error_reach): not planned
		 * again. */
		if (late_geo && mm && bestf[0] >= 0 && (mm->stopped >> c.role[k] & 1u) && !(mm->known >> c.role[k] & 1u) &&
		    mm->ge[c.role[k]] >= plan_stop(g, pl, 0, bestf, costf, cap, tie, wsum))
			continue;
		if (ranked && bestf[0] >= 0)
			break;
		int at = c.at[k];
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
			int ok = fam == 1 && geo_at[at] >= 0 ? geo_at[at] : geometry_ok(g, pl, c.x[k]);
			if (hybrid && at >= 0 && !c.whole[k])
				geo_at[at] = ok;
			if (!ok)
				continue;
		}
		mlod_influences w;
		int capped = 0;
		if (c.whole[k])
			w = in3[c.at[k]]; /* the vertex's own influences, not blended */
		else
			capped = bgm_skin_role(mm, c.role[k], V, in3, K, c.x[k], &w);
		if (g->joint_count > 0 && w.count == 0)
			continue;
		double cost, d = 0.0;
		for (int i = 0; i < 3; i++)
			d += (c.x[k][i] - bary[i]) * (c.x[k][i] - bary[i]);
		if (g->opt.cost == MLOD_COST_POSED) {
			/* Area-normalised (a mean squared distance), so small
			 * features count as much as large ones. */
			double e = 0.0;
			if (ranked) {
				cost = ckey[k];
				goto take;
			} else if (g->pose_count > 0) {
				double stop = plan_stop(g, pl, fam, bestf, costf, cap, tie, wsum);
				int role = c.role[k];
				if (role >= 5 && (same_end >> (role - 5) & 1u)) {
					e = end_e[role - 5];
				} else if (mm && (mm->known >> role & 1u)) {
					e = mm->e[role];
				} else {
					if (!q_ready)
						bgm_sum_quadrics(g, pl, Q), q_ready = 1;
					double reached;
					e = bgm_quadric_error_reach(g, Q, &w, c.x[k], stop, &reached);
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
				if (hybrid && role >= 1 && role <= 3 && bgm_same_influences(&w, &in3[role - 1])) {
					end_e[role - 1] = e;
					same_end |= 1u << (role - 1);
				}
			}
			cost = (wsum > 0.0 ? e / wsum : 0.0) + TIE_WEIGHT * tie;
			if (g->opt.op == MLOD_OP_MIXED) /* per removed face: triangles and edges compete */
				cost /= pl->nr;
			if (bestf[fam] >= 0 && !(cost < costf[fam]))
				continue;
			if (late && !geometry_ok(g, pl, c.x[k]))
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
		pl->cost *= bgm_border_factor(g); /* the border moves (a lone border vertex stays put) */
	memcpy(pl->pos, c.x[best], sizeof pl->pos);
	pl->snap = c.snap[best];
	pl->whole = c.whole[best];
	if (pl->whole)
		vertex_wedges(g, pl, owner);
	if (c.at[best] >= 0) {
		pl->lambda[0] = pl->lambda[1] = pl->lambda[2] = 0.0;
		pl->lambda[c.at[best]] = 1.0;
	} else if (K == 3) {
		barycentric(P[0], P[1], P[2], pl->pos, pl->lambda);
	} else {
		segment_weights(P[0], P[1], pl->pos, pl->lambda);
	}
	return normals_ok(g, pl);
}
