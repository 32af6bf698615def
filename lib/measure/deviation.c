/*
 * deviation.c: symmetric surface deviation between two triangle meshes.
 *
 * Samples of each mesh (the vertices its triangles use, and its triangle
 * centroids) are projected to the nearest point of the other surface.
 * Nearest points come from a bounding volume hierarchy over the target's
 * triangles (object-median splits on the longest axis, so the depth is
 * logarithmic; leaves of up to 8), searched up from the seed triangle's
 * leaf (each other subtree nearer child first) and pruned by box
 * distance, each query seeded with the previous sample's triangle
 * (or, given warm starts, surface.h, with the triangle that was nearest to
 * the same sample at another pose: a tighter first bound; the search stays
 * exact, so the result does not depend on the seed);
 * a leaf's triangle is skipped when its plane is already farther than the
 * best. The samples are visited in the leaf order of their own mesh's
 * hierarchy, so consecutive queries are neighbours, and summed in the
 * mesh's order afterwards. Point-triangle distance is the Voronoi-region
 * method of Ericson, "Real-Time Collision Detection" (2005), 5.1.5;
 * degenerate triangles are measured as their three edges. Single-threaded
 * and in a fixed order, so deterministic. A mesh can be kept with its
 * hierarchy (mlod_surface, surface.h) and measured against many others.
 * With warm starts' bound (surface.h) only the samples that may raise the
 * max are searched, the others counted with their distance to their warm
 * triangle; hierarchies are then built (or refitted from the same mesh's
 * at another pose) only when a search needs them, and the triangles'
 * degenerate flags are made once per mesh (a kept surface's once per
 * pose, for every level), not once per sample. A refitted hierarchy fits
 * its boxes from the mesh and keeps no triangles: a search makes a leaf's
 * (corners, plane) from the mesh each time it reaches that leaf. A bounded
 * pose searches a few hundred samples (mlod-bgm on the 50k-triangle
 * tubeman: 18,145 searches in 48 level-poses), which reach few of its
 * leaves, and kept triangles cost 120 bytes each per pose. */
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "measure/mlod_measure.h"
#include "measure/surface.h"

#define LEAF_SIZE 8
/* points_dist2 inlined whole: gcc -O2 inlined only its degenerate test,
 * calling the rest (4.6 million calls from bound_distances on mlod-bgm's
 * 50k-triangle tubeman) */
#if defined(__GNUC__)
#define DEV_INLINE static inline __attribute__((always_inline))
#else
#define DEV_INLINE static inline
#endif
#define MAX_DEPTH 64 /* object-median splits of < 2^31 triangles stay far below */

typedef struct node {
	double lo[3], hi[3];
	int first; /* leaf: first triangle; inner: index of the left child (right is next) */
	int count; /* leaf: triangle count; inner: 0 */
} node;

typedef struct tri {
	double a[3], b[3], c[3];
	double n[3];    /* unit normal (0 for a degenerate triangle) */
	double off;     /* n . a */
	double a1;      /* |a| in the 1-norm: plane_dist2's slack */
	int degenerate;
} tri;

struct mlod_bvh {
	node *nodes;
	int node_count;
	tri *tris;  /* in leaf order */
	int *order; /* the mesh's triangle at each place of tris */
	int *place; /* the place in tris of each of the mesh's triangles */
	int *parent; /* each node's parent (the root's: -1) */
	int *leaf;   /* the leaf holding each place of tris */
	int tri_count;
	int borrowed; /* order, place, parent and leaf belong to the tree this one was refitted from */
	/* A refitted tree (tris NULL) makes a leaf's triangles from mesh
	 * when a search first reaches it (leaf_tris), into blocks of its own
	 * (leaf_tri: per node, NULL until then), under lock when searches
	 * share the tree. A bounded pose searches a few hundred samples,
	 * which reach a few of its leaves (mlod-bgm on the 207k-triangle
	 * tubeman: 1.6-6.9% of them): room for all, as a built tree has,
	 * would cost 120 bytes a triangle a pose. */
	const mlod_posed *mesh;
	_Atomic(tri *) *leaf_tri;
	struct tri_block *blocks;
	pthread_mutex_t *lock;
};

#define TRI_BLOCK 1024 /* triangles of a refitted tree's block */
struct tri_block {
	struct tri_block *next;
	int used;
	tri t[];
};
typedef struct mlod_bvh bvh;

/* ---------------------------------------------------------------- */
/* Point-triangle distance                                           */
/* ---------------------------------------------------------------- */

static double dot3(const double *u, const double *v)
{
	return u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
}

static void sub3(const double *u, const double *v, double *out)
{
	out[0] = u[0] - v[0], out[1] = u[1] - v[1], out[2] = u[2] - v[2];
}

static double dist2_to(const double *p, const double *q)
{
	double d[3];
	sub3(p, q, d);
	return dot3(d, d);
}

/* Squared distance from p to the segment a + s (b - a), s in [0, 1]. */
static double segment_dist2(const double *p, const double *a, const double *b)
{
	double ab[3], ap[3], q[3];
	sub3(b, a, ab);
	sub3(p, a, ap);
	double len2 = dot3(ab, ab), s = len2 > 0.0 ? dot3(ap, ab) / len2 : 0.0;
	s = s < 0.0 ? 0.0 : s > 1.0 ? 1.0 : s;
	for (int i = 0; i < 3; i++)
		q[i] = a[i] + s * ab[i];
	return dist2_to(p, q);
}

/* Squared distance from p to the triangle a b c (Ericson, 5.1.5);
 * degenerate (is_degenerate) measured as its three edges. */
DEV_INLINE double points_dist2(const double *p, const double *a, const double *b, const double *c, int degenerate)
{
	if (degenerate) {
		double d = segment_dist2(p, a, b), e = segment_dist2(p, b, c), f = segment_dist2(p, c, a);
		return fmin(d, fmin(e, f));
	}
	double ab[3], ac[3], ap[3], bp[3], cp[3], q[3];
	sub3(b, a, ab);
	sub3(c, a, ac);
	sub3(p, a, ap);
	double d1 = dot3(ab, ap), d2 = dot3(ac, ap);
	if (d1 <= 0.0 && d2 <= 0.0)
		return dist2_to(p, a); /* vertex region a */
	sub3(p, b, bp);
	double d3 = dot3(ab, bp), d4 = dot3(ac, bp);
	if (d3 >= 0.0 && d4 <= d3)
		return dist2_to(p, b); /* vertex region b */
	double vc = d1 * d4 - d3 * d2;
	if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) { /* edge ab */
		double v = d1 / (d1 - d3);
		for (int i = 0; i < 3; i++)
			q[i] = a[i] + v * ab[i];
		return dist2_to(p, q);
	}
	sub3(p, c, cp);
	double d5 = dot3(ab, cp), d6 = dot3(ac, cp);
	if (d6 >= 0.0 && d5 <= d6)
		return dist2_to(p, c); /* vertex region c */
	double vb = d5 * d2 - d1 * d6;
	if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) { /* edge ac */
		double w = d2 / (d2 - d6);
		for (int i = 0; i < 3; i++)
			q[i] = a[i] + w * ac[i];
		return dist2_to(p, q);
	}
	double va = d3 * d6 - d5 * d4;
	if (va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0) { /* edge bc */
		double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
		for (int i = 0; i < 3; i++)
			q[i] = b[i] + w * (c[i] - b[i]);
		return dist2_to(p, q);
	}
	double denom = 1.0 / (va + vb + vc), v = vb * denom, w = vc * denom; /* face */
	for (int i = 0; i < 3; i++)
		q[i] = a[i] + ab[i] * v + ac[i] * w;
	return dist2_to(p, q);
}

static double triangle_dist2(const double *p, const tri *t)
{
	return points_dist2(p, t->a, t->b, t->c, t->degenerate);
}

/* A triangle is degenerate when its area is negligible against its edges:
 * then the face formula would divide by (nearly) zero. */
DEV_INLINE int points_degenerate(const double *a, const double *b, const double *c)
{
	double ab[3], ac[3];
	sub3(b, a, ab);
	sub3(c, a, ac);
	double n[3] = { ab[1] * ac[2] - ab[2] * ac[1], ab[2] * ac[0] - ab[0] * ac[2], ab[0] * ac[1] - ab[1] * ac[0] };
	return dot3(n, n) <= 1e-12 * dot3(ab, ab) * dot3(ac, ac);
}

static int is_degenerate(const tri *t)
{
	return points_degenerate(t->a, t->b, t->c);
}

/* ---------------------------------------------------------------- */
/* Hierarchy                                                         */
/* ---------------------------------------------------------------- */

/* A triangle being placed: its centroid and index, moved together so
 * that the build reads memory in order. */
typedef struct item {
	float c[3];
	int t;
} item;

typedef struct builder {
	bvh *out;
	const mlod_posed *mesh;
	item *items;      /* permuted into leaf order */
} builder;

/* Rearranges items[lo, hi) so that items[nth] has the nth smallest centroid
 * along axis and no smaller one comes after it (quickselect). */
static void select_nth(const builder *b, int lo, int hi, int nth, int axis)
{
	item *o = b->items;
	while (hi - lo > 1) {
		float pivot = o[lo + (hi - lo) / 2].c[axis];
		int i = lo, j = hi - 1;
		while (i <= j) {
			while (o[i].c[axis] < pivot)
				i++;
			while (o[j].c[axis] > pivot)
				j--;
			if (i <= j) {
				item tmp = o[i];
				o[i] = o[j], o[j] = tmp;
				i++, j--;
			}
		}
		/* now [lo, j] <= pivot <= [i, hi) and (j, i) == pivot */
		if (nth <= j)
			hi = j + 1;
		else if (nth >= i)
			lo = i;
		else
			return;
	}
}

/* Builds the subtree of items[lo, hi) at nodes[index]: a leaf for a few
 * triangles, else two children split at the median centroid along the
 * axis where centroids spread most. Boxes are merged bottom-up. */
static void build_node(builder *b, int index, int lo, int hi)
{
	node *n = &b->out->nodes[index];
	float lo3[3] = { INFINITY, INFINITY, INFINITY }, hi3[3] = { -INFINITY, -INFINITY, -INFINITY };
	if (hi - lo <= LEAF_SIZE) {
		for (int k = lo; k < hi; k++) {
			const uint32_t *ix = b->mesh->indices + 3 * (size_t)b->items[k].t;
			for (int v = 0; v < 3; v++)
				for (int a = 0; a < 3; a++) {
					float x = b->mesh->positions[3 * (size_t)ix[v] + a];
					lo3[a] = x < lo3[a] ? x : lo3[a];
					hi3[a] = x > hi3[a] ? x : hi3[a];
				}
		}
		for (int a = 0; a < 3; a++)
			n->lo[a] = lo3[a], n->hi[a] = hi3[a];
		n->first = lo;
		n->count = hi - lo;
		for (int k = lo; k < hi; k++)
			b->out->leaf[k] = index;
		return;
	}
	for (int k = lo; k < hi; k++)
		for (int a = 0; a < 3; a++) {
			float x = b->items[k].c[a];
			lo3[a] = x < lo3[a] ? x : lo3[a];
			hi3[a] = x > hi3[a] ? x : hi3[a];
		}
	int axis = 0;
	for (int a = 1; a < 3; a++)
		if (hi3[a] - lo3[a] > hi3[axis] - lo3[axis])
			axis = a;
	int mid = lo + (hi - lo) / 2;
	select_nth(b, lo, hi, mid, axis);
	int left = b->out->node_count;
	b->out->node_count += 2;
	b->out->parent[left] = b->out->parent[left + 1] = index;
	build_node(b, left, lo, mid);
	build_node(b, left + 1, mid, hi);
	n = &b->out->nodes[index];
	const node *l = &b->out->nodes[left], *r = &b->out->nodes[left + 1];
	for (int a = 0; a < 3; a++) {
		n->lo[a] = l->lo[a] < r->lo[a] ? l->lo[a] : r->lo[a];
		n->hi[a] = l->hi[a] > r->hi[a] ? l->hi[a] : r->hi[a];
	}
	n->first = left;
	n->count = 0;
}

static void fill_tris(const mlod_posed *m, bvh *out);

static mlod_result bvh_build(const mlod_posed *m, bvh *out, mlod_error *err)
{
	int n = m->triangle_count;
	builder b = { out, m, malloc((size_t)n * sizeof *b.items) };
	out->nodes = malloc((size_t)2 * n * sizeof *out->nodes);
	out->tris = malloc((size_t)n * sizeof *out->tris);
	out->order = malloc((size_t)n * sizeof *out->order);
	out->place = malloc((size_t)n * sizeof *out->place);
	out->parent = malloc((size_t)2 * n * sizeof *out->parent);
	out->leaf = malloc((size_t)n * sizeof *out->leaf);
	out->node_count = 1;
	out->tri_count = n;
	if (!b.items || !out->nodes || !out->tris || !out->order || !out->place || !out->parent || !out->leaf) {
		free(b.items);
		return mlod_fail(err, MLOD_ERR_NOMEM, "deviation: cannot allocate a hierarchy of %d triangles", n);
	}
	for (int t = 0; t < n; t++) {
		const uint32_t *ix = m->indices + 3 * (size_t)t;
		b.items[t].t = t;
		for (int a = 0; a < 3; a++)
			b.items[t].c[a] = (m->positions[3 * (size_t)ix[0] + a] + m->positions[3 * (size_t)ix[1] + a] +
			                   m->positions[3 * (size_t)ix[2] + a]) / 3.0f;
	}
	out->parent[0] = -1;
	build_node(&b, 0, 0, n);
	node *fit = realloc(out->nodes, (size_t)out->node_count * sizeof *out->nodes);
	if (fit)
		out->nodes = fit;
	for (int k = 0; k < n; k++) {
		out->order[k] = b.items[k].t;
		out->place[out->order[k]] = k;
	}
	free(b.items);
	fill_tris(m, out);
	return MLOD_OK;
}

/* The triangles of m in the tree's leaf order, with their normals. */
static void fill_tri(const mlod_posed *m, int face, tri *t);

static void fill_tris(const mlod_posed *m, bvh *out)
{
	for (int k = 0; k < out->tri_count; k++)
		fill_tri(m, out->order[k], &out->tris[k]);
}

/* Triangle face of m into t, with its normal. */
static void fill_tri(const mlod_posed *m, int face, tri *t)
{
	const uint32_t *ix = m->indices + 3 * (size_t)face;
	for (int a = 0; a < 3; a++) {
		t->a[a] = m->positions[3 * (size_t)ix[0] + a];
		t->b[a] = m->positions[3 * (size_t)ix[1] + a];
		t->c[a] = m->positions[3 * (size_t)ix[2] + a];
	}
	double ab[3], ac[3];
	sub3(t->b, t->a, ab);
	sub3(t->c, t->a, ac);
	double nn[3] = { ab[1] * ac[2] - ab[2] * ac[1], ab[2] * ac[0] - ab[0] * ac[2], ab[0] * ac[1] - ab[1] * ac[0] };
	double n2 = dot3(nn, nn), len = sqrt(n2);
	t->degenerate = n2 <= 1e-12 * dot3(ab, ab) * dot3(ac, ac); /* is_degenerate, its cross product shared */
	for (int a = 0; a < 3; a++)
		t->n[a] = t->degenerate || !(len > 0.0) ? 0.0 : nn[a] / len;
	t->off = t->n[0] * t->a[0] + t->n[1] * t->a[1] + t->n[2] * t->a[2];
	t->a1 = fabs(t->a[0]) + fabs(t->a[1]) + fabs(t->a[2]);
}

/* A hierarchy of the same mesh at another pose (the same triangles, other
 * positions): from's tree and order, its boxes fitted again bottom-up
 * (children come after their parent). Looser than one built there, it
 * costs a search a little more, a build far more; a search's result does
 * not depend on the tree. */
static mlod_result bvh_refit(const bvh *from, const mlod_posed *m, pthread_mutex_t *lock, bvh *out, mlod_error *err)
{
	memset(out, 0, sizeof *out);
	out->nodes = malloc((size_t)from->node_count * sizeof *out->nodes);
	out->leaf_tri = calloc((size_t)from->node_count, sizeof *out->leaf_tri);
	out->borrowed = 1;
	if (!out->nodes || !out->leaf_tri)
		return mlod_fail(err, MLOD_ERR_NOMEM, "deviation: cannot allocate a hierarchy of %d triangles", from->tri_count);
	out->node_count = from->node_count;
	out->tri_count = from->tri_count;
	out->order = from->order, out->place = from->place, out->parent = from->parent, out->leaf = from->leaf;
	out->mesh = m, out->lock = lock;
	for (int i = out->node_count - 1; i >= 0; i--) {
		node *n = &out->nodes[i];
		n->first = from->nodes[i].first, n->count = from->nodes[i].count;
		for (int a = 0; a < 3; a++)
			n->lo[a] = INFINITY, n->hi[a] = -INFINITY;
		if (n->count > 0)
			for (int k = n->first; k < n->first + n->count; k++) {
				/* the corners as fill_tri makes them, read from the mesh */
				const uint32_t *ix = m->indices + 3 * (size_t)out->order[k];
				const float *u = m->positions + 3 * (size_t)ix[0], *v = m->positions + 3 * (size_t)ix[1],
				            *w = m->positions + 3 * (size_t)ix[2];
				const struct { double a[3], b[3], c[3]; } c = { { u[0], u[1], u[2] }, { v[0], v[1], v[2] },
				                                                 { w[0], w[1], w[2] } }, *t = &c;
				for (int a = 0; a < 3; a++) {
					double lo = t->a[a] < t->b[a] ? t->a[a] : t->b[a], hi = t->a[a] > t->b[a] ? t->a[a] : t->b[a];
					lo = t->c[a] < lo ? t->c[a] : lo, hi = t->c[a] > hi ? t->c[a] : hi;
					n->lo[a] = lo < n->lo[a] ? lo : n->lo[a];
					n->hi[a] = hi > n->hi[a] ? hi : n->hi[a];
				}
			}
		else
			for (int a = 0; a < 3; a++) {
				const node *l = &out->nodes[n->first], *r = &out->nodes[n->first + 1];
				n->lo[a] = l->lo[a] < r->lo[a] ? l->lo[a] : r->lo[a];
				n->hi[a] = l->hi[a] > r->hi[a] ? l->hi[a] : r->hi[a];
			}
	}
	return MLOD_OK;
}

static void bvh_free(bvh *b)
{
	free(b->nodes);
	free(b->tris);
	free(b->leaf_tri);
	while (b->blocks) {
		struct tri_block *next = b->blocks->next;
		free(b->blocks);
		b->blocks = next;
	}
	if (!b->borrowed) {
		free(b->order);
		free(b->place);
		free(b->parent);
		free(b->leaf);
	}
}

/* Squared distance from p to the node's box: p less its clamp to the box
 * on each axis (so the compiler needs no branch). */
static inline double box_dist2(const double *p, const node *n)
{
	double d2 = 0.0;
	for (int a = 0; a < 3; a++) {
		double c = p[a] > n->lo[a] ? p[a] : n->lo[a];
		c = c < n->hi[a] ? c : n->hi[a];
		double d = p[a] - c;
		d2 += d * d;
	}
	return d2;
}

/* box_dist2 of two nodes at once (a node's children, l and l + 1): each
 * lane does box_dist2's operations in its order (max, min, subtract,
 * square, sum over the axes from 0), so the bits are the same. */
static inline void box_pair_dist2(const double *p, const node *l, double *dl, double *dr)
{
#if defined(__SSE2__)
	const node *r = l + 1;
	__m128d d2 = _mm_setzero_pd();
	for (int a = 0; a < 3; a++) {
		__m128d pa = _mm_set1_pd(p[a]);
		__m128d c = _mm_max_pd(pa, _mm_set_pd(r->lo[a], l->lo[a])); /* p > lo ? p : lo */
		c = _mm_min_pd(c, _mm_set_pd(r->hi[a], l->hi[a]));          /* c < hi ? c : hi */
		__m128d d = _mm_sub_pd(pa, c);
		d2 = _mm_add_pd(d2, _mm_mul_pd(d, d));
	}
	*dl = _mm_cvtsd_f64(d2);
	*dr = _mm_cvtsd_f64(_mm_unpackhi_pd(d2, d2));
#else
	*dl = box_dist2(p, l);
	*dr = box_dist2(p, l + 1);
#endif
}

/* A lower bound of triangle_dist2: the squared distance to the
 * triangle's plane, |n . p - n . a|, less a slack (1e-12 of |p| + |a| in
 * the 1-norm, p1 and t->a1: no less than the 1e-12 of |p - a| this test
 * once took, and a thousand times the rounding of either dot product) so
 * that rounding can never make it exceed the distance triangle_dist2
 * computes. A triangle skipped by it could not have been nearer; and as
 * a triangle no nearer than the best changes nothing (neither the best
 * nor the hint), the result is the same as without the test, or with any
 * other lower bound. */
static inline double plane_dist2(const double *p, double p1, const tri *t)
{
	double d = fabs(p[0] * t->n[0] + p[1] * t->n[1] + p[2] * t->n[2] - t->off);
	d -= 1e-12 * (p1 + t->a1);
	return d > 0.0 ? d * d : 0.0;
}

/* A refitted tree's leaf at, its triangles made from its mesh (as a
 * built tree's are) into its blocks, each leaf once; into buf (LEAF_SIZE
 * of them), not kept, when there is no memory for a block. */
static const tri *leaf_fill(const bvh *b, int at, tri *buf)
{
	bvh *w = (bvh *)b; /* only the blocks and leaf_tri change, under the lock */
	const node *n = &b->nodes[at];
	if (b->lock)
		pthread_mutex_lock(b->lock);
	tri *t = atomic_load_explicit(&b->leaf_tri[at], memory_order_relaxed);
	if (!t) {
		struct tri_block *k = b->blocks;
		if (!k || k->used + n->count > TRI_BLOCK) {
			k = malloc(sizeof *k + TRI_BLOCK * sizeof k->t[0]);
			if (k)
				k->next = b->blocks, k->used = 0, w->blocks = k;
		}
		t = k ? k->t + k->used : buf;
		for (int i = 0; i < n->count; i++)
			fill_tri(b->mesh, b->order[n->first + i], &t[i]);
		if (k) {
			k->used += n->count;
			atomic_store_explicit(&w->leaf_tri[at], t, memory_order_release);
		}
	}
	if (b->lock)
		pthread_mutex_unlock(b->lock);
	return t;
}

/* The triangles of leaf at, place k at [k - its first]: a built tree's
 * own, a refitted tree's made when first needed (leaf_fill). */
static inline const tri *leaf_tris(const bvh *b, int at, tri *buf)
{
	if (b->tris)
		return b->tris + b->nodes[at].first;
	const tri *t = atomic_load_explicit(&b->leaf_tri[at], memory_order_acquire);
	return t ? t : leaf_fill(b, at, buf);
}

/* The nearest triangle in the subtree at node at (at_d2: p's squared
 * distance to its box) if nearer than best: searched nearer child first,
 * pruned by box distance, a leaf's triangle skipped when its plane is
 * already farther than the best, or when it is skip. p1: |p| in the
 * 1-norm (plane_dist2's), made once per query by the caller. */
static double subtree_nearest2(const bvh *b, const double *p, double p1, int at, double at_d2, double best, int skip,
                               int *hint)
{
	struct { int node; double d2; } stack[MAX_DEPTH + 1];
	tri buf[LEAF_SIZE];
	int top = 0;
	for (;;) {
		const node *n = &b->nodes[at];
		if (at_d2 < best && n->count == 0) {
			/* on into the nearer child; the farther one waits on the stack */
			int l = n->first, r = n->first + 1;
			double dl, dr;
			box_pair_dist2(p, &b->nodes[l], &dl, &dr);
			int near = dl <= dr ? l : r, far = dl <= dr ? r : l;
			double dnear = dl <= dr ? dl : dr, dfar = dl <= dr ? dr : dl;
			if (dfar < best)
				stack[top].node = far, stack[top++].d2 = dfar;
			at = near, at_d2 = dnear;
			continue;
		}
		if (at_d2 < best) {
			const tri *t = leaf_tris(b, at, buf);
			for (int i = 0, k = n->first; i < n->count; i++, k++) {
				if (k == skip || plane_dist2(p, p1, &t[i]) >= best)
					continue;
				double d = triangle_dist2(p, &t[i]);
				if (d < best)
					best = d, *hint = k;
			}
		}
		if (top == 0)
			return best;
		--top;
		at = stack[top].node, at_d2 = stack[top].d2;
	}
}

/* Squared distance from p to the nearest triangle. *hint is a triangle to
 * start from (updated to the nearest one), which makes neighbouring
 * queries cheap. The search goes up from the hint's leaf: its other
 * triangles, then at each ancestor the other child's subtree (pruned by
 * its box when no nearer than the best so far). The leaf and those
 * subtrees make the whole tree, so the result is the nearest, as from the
 * root down; starting next to the answer, it tests about one box per
 * level instead of two per level and more. */
static double bvh_nearest2(const bvh *b, const double *p, int *hint)
{
	const int start = *hint; /* measured here, so skipped in its leaf */
	int at = b->leaf[start];
	tri buf[LEAF_SIZE];
	double best = triangle_dist2(p, &leaf_tris(b, at, buf)[start - b->nodes[at].first]);
	const double p1 = fabs(p[0]) + fabs(p[1]) + fabs(p[2]);
	best = subtree_nearest2(b, p, p1, at, 0.0, best, start, hint);
	for (int up = b->parent[at]; up >= 0; at = up, up = b->parent[up]) {
		int other = at & 1 ? at + 1 : at - 1; /* children come in pairs from 1: left odd, right even */
		double d2 = box_dist2(p, &b->nodes[other]);
		if (d2 < best)
			best = subtree_nearest2(b, p, p1, other, d2, best, -1, hint);
	}
	return best;
}

/* ---------------------------------------------------------------- */
/* Measuring                                                         */
/* ---------------------------------------------------------------- */

static mlod_result check_mesh(const mlod_posed *m, const char *which, mlod_error *err)
{
	if (!m || m->vertex_count <= 0 || m->triangle_count <= 0 || !m->positions || !m->indices)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "deviation: mesh %s is empty", which);
	/* the common case first: every index in range, every vertex finite
	 * (each vertex once, not once per corner); else the corners in order,
	 * to name the first bad one */
	int ok = 1;
	for (long i = 0; i < 3L * m->triangle_count; i++)
		ok &= m->indices[i] < (uint32_t)m->vertex_count;
	for (long i = 0; ok && i < 3L * m->vertex_count; i++)
		ok &= isfinite(m->positions[i]) != 0;
	if (ok)
		return MLOD_OK;
	for (long i = 0; i < 3L * m->triangle_count; i++) {
		uint32_t v = m->indices[i];
		if (v >= (uint32_t)m->vertex_count)
			return mlod_fail(err, MLOD_ERR_INVALID_ARG, "deviation: mesh %s: index %ld is %u, out of range (%d vertices)",
			                 which, i, v, m->vertex_count);
		for (int a = 0; a < 3; a++)
			if (!isfinite(m->positions[3 * (size_t)v + a]))
				return mlod_fail(err, MLOD_ERR_PARSE, "deviation: mesh %s: vertex %u is not finite", which, v);
	}
	return MLOD_OK;
}

/* Adds the distances of from's samples to the surface in to. The samples
 * are visited in the leaf order of from's own hierarchy (each triangle's
 * vertices, then its centroid), so that neighbouring queries are near one
 * another and each starts from a close triangle; the distances are then
 * summed in the mesh's order (used vertices, then triangles), so the sum
 * does not depend on the visiting order. */
static mlod_result measure(const mlod_posed *from, const bvh *from_bvh, const bvh *to, const int *warm, int *near,
                           double *sum, double *max, long *count, mlod_error *err)
{
	double *dv = malloc(((size_t)from->vertex_count + (size_t)from->triangle_count) * sizeof *dv);
	if (!dv)
		return mlod_fail(err, MLOD_ERR_NOMEM, "deviation: cannot allocate %d distances",
		                 from->vertex_count + from->triangle_count);
	double *dt = dv + from->vertex_count;
	/* only vertices on the surface count: unreferenced ones are not part of it (-1) */
	for (int v = 0; v < from->vertex_count; v++)
		dv[v] = -1.0;
	int hint = 0;
	for (int k = 0; k < from->triangle_count; k++) {
		int t = from_bvh->order[k];
		const uint32_t *ix = from->indices + 3 * (size_t)t;
		for (int c = 0; c < 3; c++) {
			if (dv[ix[c]] >= 0.0)
				continue;
			const float *q = from->positions + 3 * (size_t)ix[c];
			const double p[3] = { q[0], q[1], q[2] };
			if (warm && (unsigned)warm[ix[c]] < (unsigned)to->tri_count)
				hint = to->place[warm[ix[c]]];
			dv[ix[c]] = sqrt(bvh_nearest2(to, p, &hint));
			if (near)
				near[ix[c]] = to->order[hint];
		}
		double p[3];
		for (int a = 0; a < 3; a++)
			p[a] = ((double)from->positions[3 * (size_t)ix[0] + a] + from->positions[3 * (size_t)ix[1] + a] +
			        from->positions[3 * (size_t)ix[2] + a]) / 3.0;
		if (warm && (unsigned)warm[from->vertex_count + t] < (unsigned)to->tri_count)
			hint = to->place[warm[from->vertex_count + t]];
		dt[t] = sqrt(bvh_nearest2(to, p, &hint));
		if (near)
			near[from->vertex_count + t] = to->order[hint];
	}
	double s = *sum, m = *max;
	long n = *count;
	for (int v = 0; v < from->vertex_count; v++)
		if (dv[v] >= 0.0) {
			s += dv[v];
			m = dv[v] > m ? dv[v] : m;
			n++;
		}
	for (int t = 0; t < from->triangle_count; t++) {
		s += dt[t];
		m = dt[t] > m ? dt[t] : m;
		n++;
	}
	*sum = s, *max = m, *count = n;
	free(dv);
	return MLOD_OK;
}

/* Triangle t of m, as the hierarchy keeps it (without its normal). */
static void mesh_tri(const mlod_posed *m, int t, tri *out)
{
	const uint32_t *ix = m->indices + 3 * (size_t)t;
	for (int a = 0; a < 3; a++) {
		out->a[a] = m->positions[3 * (size_t)ix[0] + a];
		out->b[a] = m->positions[3 * (size_t)ix[1] + a];
		out->c[a] = m->positions[3 * (size_t)ix[2] + a];
	}
	out->degenerate = is_degenerate(out);
}

/* A mesh measured against, with its hierarchy built when first needed
 * (under lock when there is one: a kept surface, shared by calls). */
typedef struct target {
	const mlod_posed *mesh;
	bvh *tree;
	int *built;
	pthread_mutex_t *lock;
	const bvh *like; /* the same triangles' tree at another pose, refitted (NULL: built) */
	const unsigned char *degen; /* its triangles' degenerate_flags (NULL: made when needed) */
	const unsigned char *used;  /* the vertices its triangles use (NULL: marked when needed) */
} target;

static mlod_result target_tree(const target *t, const bvh **out, mlod_error *err)
{
	mlod_result r = MLOD_OK;
	if (t->lock)
		pthread_mutex_lock(t->lock);
	if (!*t->built) {
		if (t->like && t->like->tri_count == t->mesh->triangle_count)
			r = bvh_refit(t->like, t->mesh, t->lock, t->tree, err);
		else
			r = bvh_build(t->mesh, t->tree, err);
		if (r == MLOD_OK)
			*t->built = 1;
		else {
			bvh_free(t->tree); /* what was allocated before the failure */
			memset(t->tree, 0, sizeof *t->tree);
		}
	}
	if (t->lock)
		pthread_mutex_unlock(t->lock);
	*out = t->tree;
	return r;
}

/* The sample at place i of from (its vertices, then its triangles'
 * centroids); 0 for a vertex no triangle uses (not on the surface). */
static int sample_at(const mlod_posed *from, const unsigned char *used, long i, double *p)
{
	if (i < from->vertex_count) {
		if (!used[i])
			return 0;
		for (int a = 0; a < 3; a++)
			p[a] = from->positions[3 * (size_t)i + a];
		return 1;
	}
	const uint32_t *ix = from->indices + 3 * (size_t)(i - from->vertex_count);
	for (int a = 0; a < 3; a++)
		p[a] = ((double)from->positions[3 * (size_t)ix[0] + a] + from->positions[3 * (size_t)ix[1] + a] +
		        from->positions[3 * (size_t)ix[2] + a]) / 3.0;
	return 1;
}

/* Whether each triangle of m is degenerate (is_degenerate), into flags. */
static void degenerate_flags(const mlod_posed *m, unsigned char *flags)
{
	const float *x = m->positions;
	for (int t = 0; t < m->triangle_count; t++) {
		/* is_degenerate on the corners as mesh_tri makes them, without the copy */
		const uint32_t *ix = m->indices + 3 * (size_t)t;
		const float *u = x + 3 * (size_t)ix[0], *v = x + 3 * (size_t)ix[1], *w = x + 3 * (size_t)ix[2];
		const double a[3] = { u[0], u[1], u[2] }, b[3] = { v[0], v[1], v[2] }, c[3] = { w[0], w[1], w[2] };
		flags[t] = (unsigned char)points_degenerate(a, b, c);
	}
}

/* One way of measure's bounded form (mlod_warm's bound): each sample's
 * distance to its warm triangle in dist (-1: not a sample, INFINITY: no
 * warm triangle), from's vertices then its triangles; degen: onto's
 * triangles' degenerate_flags, made once per mesh rather than per sample.
 * Returns how many exceed top (the candidates to search), counted as
 * they are made rather than in a pass of their own. */
static long bound_distances(const mlod_posed *from, const unsigned char *used, const mlod_posed *onto, const unsigned char *degen, const int *warm, double top,
                            double *dist)
{
	long above = 0;
	const float *x = onto->positions, *f = from->positions;
	const long nv = from->vertex_count, n = nv + from->triangle_count;
	for (long i = 0; i < n; i++) {
		/* the sample as sample_at makes it, without its call and branch */
		double p[3];
		if (i < nv) {
			if (!used[i]) {
				dist[i] = -1.0;
				continue;
			}
			p[0] = f[3 * i], p[1] = f[3 * i + 1], p[2] = f[3 * i + 2];
		} else {
			const uint32_t *ix = from->indices + 3 * (size_t)(i - nv);
			const float *u = f + 3 * (size_t)ix[0], *v = f + 3 * (size_t)ix[1], *w = f + 3 * (size_t)ix[2];
			for (int a = 0; a < 3; a++)
				p[a] = ((double)u[a] + v[a] + w[a]) / 3.0;
		}
		dist[i] = INFINITY;
		if ((unsigned)warm[i] < (unsigned)onto->triangle_count) {
			const uint32_t *ix = onto->indices + 3 * (size_t)warm[i];
			const float *u = x + 3 * (size_t)ix[0], *v = x + 3 * (size_t)ix[1], *w = x + 3 * (size_t)ix[2];
			const double a[3] = { u[0], u[1], u[2] }, b[3] = { v[0], v[1], v[2] }, c[3] = { w[0], w[1], w[2] };
			dist[i] = sqrt(points_dist2(p, a, b, c, degen[warm[i]]));
		}
		above += dist[i] > top;
	}
	return above;
}

/* A sample whose bound may raise the max. */
typedef struct candidate {
	double bound;
	int way; /* 0: a's sample on b, 1: b's on a */
	int i;
} candidate;

/* Whether u is searched before v: larger bound first, then a's samples
 * before b's, then in the mesh's order (a total order). */
static int before(const candidate *u, const candidate *v)
{
	if (u->bound != v->bound)
		return u->bound > v->bound;
	return u->way != v->way ? u->way < v->way : u->i < v->i;
}

/* Moves c[at] down the heap of n (the first to search at the root). */
static void sift_down(candidate *c, long n, long at)
{
	candidate x = c[at];
	for (;;) {
		long l = 2 * at + 1;
		if (l >= n)
			break;
		if (l + 1 < n && before(&c[l + 1], &c[l]))
			l++;
		if (!before(&c[l], &x))
			break;
		c[at] = c[l];
		at = l;
	}
	c[at] = x;
}

/* Searches of a target before its hierarchy is built: each looks at every
 * triangle, which costs less than a build for a few. */
#define BRUTE_SEARCHES 0

/* Squared distance from p to the nearest triangle of the target, the
 * same bits as bvh_nearest2: by looking at every triangle for the first
 * few searches, through the hierarchy after. */
static mlod_result target_nearest2(const target *t, int *searches, const double *p, int warm, double *d2,
                                   mlod_error *err)
{
	const int tris = t->mesh->triangle_count;
	if (++*searches <= BRUTE_SEARCHES) {
		double best = INFINITY;
		for (int k = 0; k < tris; k++) {
			tri x;
			mesh_tri(t->mesh, k, &x);
			double d = triangle_dist2(p, &x);
			best = d < best ? d : best;
		}
		*d2 = best;
		return MLOD_OK;
	}
	const bvh *tree;
	mlod_result r = target_tree(t, &tree, err);
	if (r != MLOD_OK)
		return r;
	int hint = (unsigned)warm < (unsigned)tris ? tree->place[warm] : 0;
	*d2 = bvh_nearest2(tree, p, &hint);
	return MLOD_OK;
}

/* measure's bounded form (mlod_warm's bound), both ways: every sample's
 * distance to its warm triangle first; then the samples whose bound
 * exceeds *top (the floor in this pose's units) searched, largest bound
 * first, *top following the largest distance found, until the next bound
 * is no more than *top: none of the rest can raise the max. The sums then
 * in the mesh's order, a's samples then b's, as measure's. */
static mlod_result measure_bound(const target *ta, const target *tb, const mlod_warm *warm, double top, double *sum,
                                 double *max, long *count, mlod_error *err)
{
	const mlod_posed *m[2] = { ta->mesh, tb->mesh };
	const target *onto[2] = { tb, ta };
	const int *w[2] = { warm->a, warm->b };
	long n[2] = { (long)m[0]->vertex_count + m[0]->triangle_count, (long)m[1]->vertex_count + m[1]->triangle_count };
	/* a kept surface's used vertices are marked once per pose, for every level */
	unsigned char *own[2] = { ta->used ? NULL : calloc((size_t)m[0]->vertex_count, 1),
	                          tb->used ? NULL : calloc((size_t)m[1]->vertex_count, 1) };
	const unsigned char *used[2] = { ta->used ? ta->used : own[0], tb->used ? tb->used : own[1] };
	double *dist[2] = { malloc(sizeof(double) * (size_t)n[0]), malloc(sizeof(double) * (size_t)n[1]) };
	unsigned char *made[2] = { NULL, NULL };
	const unsigned char *degen[2] = { onto[0]->degen, onto[1]->degen };
	candidate *c = NULL;
	mlod_result r = MLOD_OK;
	for (int way = 0; way < 2; way++)
		if (!degen[way] && (made[way] = malloc((size_t)onto[way]->mesh->triangle_count)))
			degenerate_flags(onto[way]->mesh, made[way]), degen[way] = made[way];
	if (!used[0] || !used[1] || !dist[0] || !dist[1] || !degen[0] || !degen[1]) {
		r = mlod_fail(err, MLOD_ERR_NOMEM, "deviation: cannot allocate %ld distances", n[0] + n[1]);
		goto done;
	}
	long candidates = 0;
	for (int way = 0; way < 2; way++) {
		for (long k = 0; own[way] && k < 3L * m[way]->triangle_count; k++)
			own[way][m[way]->indices[k]] = 1;
		candidates += bound_distances(m[way], used[way], onto[way]->mesh, degen[way], w[way], top,
		                              dist[way]);
	}
	if (candidates > 0 && !(c = malloc(sizeof *c * (size_t)candidates))) {
		r = mlod_fail(err, MLOD_ERR_NOMEM, "deviation: cannot allocate %ld candidates", candidates);
		goto done;
	}
	candidates = 0;
	for (int way = 0; way < 2; way++)
		for (long i = 0; i < n[way]; i++)
			if (dist[way][i] > top)
				c[candidates].bound = dist[way][i], c[candidates].way = way, c[candidates++].i = (int)i;
	/* in before's order, taken from a heap: the search usually stops
	 * after a few, and sorting them all cost more than the searches */
	for (long k = candidates / 2 - 1; k >= 0; k--)
		sift_down(c, candidates, k);
	int searches[2] = { 0, 0 };
	for (long left = candidates; left > 0 && c[0].bound > top;) {
		int way = c[0].way, i = c[0].i;
		c[0] = c[--left];
		sift_down(c, left, 0);
		double p[3], d2;
		sample_at(m[way], used[way], i, p);
		if ((r = target_nearest2(onto[way], &searches[way], p, w[way][i], &d2, err)) != MLOD_OK)
			goto done;
		dist[way][i] = sqrt(d2);
		top = dist[way][i] > top ? dist[way][i] : top;
	}
	double s = *sum, mx = *max;
	long cnt = *count;
	for (int way = 0; way < 2; way++)
		for (long i = 0; i < n[way]; i++)
			if (dist[way][i] >= 0.0) {
				s += dist[way][i];
				mx = dist[way][i] > mx ? dist[way][i] : mx;
				cnt++;
			}
	*sum = s, *max = mx, *count = cnt;
done:
	free(made[0]);
	free(made[1]);
	free(own[0]);
	free(own[1]);
	free(dist[0]);
	free(dist[1]);
	free(c);
	return r;
}

/* Diagonal of the bounding box of the vertices a's triangles use (each
 * once, marked first; by corner when out of memory: the same box). */
static double diagonal(const mlod_posed *m)
{
	double lo[3] = { INFINITY, INFINITY, INFINITY }, hi[3] = { -INFINITY, -INFINITY, -INFINITY };
	unsigned char *used = calloc((size_t)m->vertex_count + 1, 1);
	if (used) {
		for (long i = 0; i < 3L * m->triangle_count; i++)
			used[m->indices[i]] = 1;
		for (int v = 0; v < m->vertex_count; v++)
			if (used[v])
				for (int a = 0; a < 3; a++) {
					double x = m->positions[3 * (size_t)v + a];
					lo[a] = x < lo[a] ? x : lo[a];
					hi[a] = x > hi[a] ? x : hi[a];
				}
		free(used);
	} else
		for (long i = 0; i < 3L * m->triangle_count; i++)
			for (int a = 0; a < 3; a++) {
				double x = m->positions[3 * (size_t)m->indices[i] + a];
				lo[a] = x < lo[a] ? x : lo[a];
				hi[a] = x > hi[a] ? x : hi[a];
			}
	return sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
	            (hi[2] - lo[2]) * (hi[2] - lo[2]));
}

/* Adds both directions between a (with its hierarchy ta) and b. */
static mlod_result both_ways(const target *ta, const mlod_posed *b, double diag, mlod_warm *warm,
                             mlod_deviation *out, mlod_error *err)
{
	bvh tb = { 0 };
	int b_built = 0;
	const target onto_b = { b, &tb, &b_built, NULL, warm && !warm->record ? warm->b_tree : NULL, NULL, NULL };
	const mlod_posed *a = ta->mesh;
	const bvh *tree_a, *tree_b;
	double sum = 0.0, max = 0.0;
	long count = 0;
	mlod_result r;
	const int *wa = warm && !warm->record ? warm->a : NULL, *wb = warm && !warm->record ? warm->b : NULL;
	int *na = warm && warm->record ? warm->a : NULL, *nb = warm && warm->record ? warm->b : NULL;
	if (warm && warm->bound && !warm->record) {
		/* the recording pose's max, as a fraction of the diagonal there, in
		 * this pose's units, a little less so that rounding cannot let a
		 * bound past it; the hierarchies built only if a sample is searched */
		r = measure_bound(ta, &onto_b, warm, warm->floor * diag * (1.0 - 1e-12), &sum, &max, &count, err);
	} else if (!(r = target_tree(ta, &tree_a, err)) && !(r = target_tree(&onto_b, &tree_b, err)) &&
	           !(r = measure(a, tree_a, tree_b, wa, na, &sum, &max, &count, err)))
		r = measure(b, tree_b, tree_a, wb, nb, &sum, &max, &count, err);
	if (!r && warm && warm->record)
		warm->floor = max / diag;
	if (b_built && !r && warm && warm->record && !warm->b_tree && (warm->b_tree = malloc(sizeof tb)))
		*warm->b_tree = tb; /* for the other poses to refit */
	else if (b_built)
		bvh_free(&tb);
	if (r)
		return r;
	out->mean = 100.0 * sum / (double)count / diag;
	out->max = 100.0 * max / diag;
	out->scale = diag;
	return MLOD_OK;
}

mlod_result mlod_surface_deviation(const mlod_posed *a, const mlod_posed *b,
                                   mlod_deviation *out, mlod_error *err)
{
	mlod_result r;
	if (!out)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "deviation: no output");
	if ((r = check_mesh(a, "a", err)) || (r = check_mesh(b, "b", err)))
		return r;
	double diag = diagonal(a);
	if (!(diag > 0.0))
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "deviation: mesh a has no extent (all its vertices coincide)");
	bvh ta = { 0 };
	int built = 0;
	const target onto_a = { a, &ta, &built, NULL, NULL, NULL, NULL };
	r = both_ways(&onto_a, b, diag, NULL, out, err);
	if (built)
		bvh_free(&ta);
	return r;
}

/* ---------------------------------------------------------------- */
/* A posed mesh kept with its hierarchy (surface.h)                  */
/* ---------------------------------------------------------------- */

struct mlod_surface {
	mlod_posed mesh;
	bvh tree;   /* built when first searched (target_tree) */
	int built;
	pthread_mutex_t lock;
	mlod_surface *like; /* mlod_surface_like */
	double diag;
	unsigned char *degen; /* its triangles' degenerate_flags, for every level's bounded measure */
	unsigned char *used;  /* the vertices its triangles use, for the same */
	int borrowed;         /* mesh.indices are those of the surface it was made like */
};

mlod_result mlod_surface_make(const mlod_posed *m, mlod_surface **out, mlod_error *err)
{
	return mlod_surface_make_like(m, NULL, out, err);
}

mlod_result mlod_surface_make_like(const mlod_posed *m, const mlod_surface *like, mlod_surface **out,
                                   mlod_error *err)
{
	mlod_result r;
	*out = NULL;
	if ((r = check_mesh(m, "a", err)))
		return r;
	double diag = diagonal(m);
	if (!(diag > 0.0))
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "deviation: mesh a has no extent (all its vertices coincide)");
	mlod_surface *s = calloc(1, sizeof *s);
	if (s && pthread_mutex_init(&s->lock, NULL) != 0) {
		free(s);
		s = NULL;
	}
	size_t pos = 3 * (size_t)m->vertex_count * sizeof *m->positions, ind = 3 * (size_t)m->triangle_count * sizeof *m->indices;
	if (s && like && like->mesh.triangle_count == m->triangle_count && !memcmp(like->mesh.indices, m->indices, ind)) {
		s->mesh.indices = like->mesh.indices; /* the same mesh at another pose: one copy of its triangles */
		s->borrowed = 1;
	}
	if (!s || !(s->mesh.positions = malloc(pos)) || (!s->borrowed && !(s->mesh.indices = malloc(ind))) ||
	    !(s->degen = malloc((size_t)m->triangle_count)) || !(s->used = calloc((size_t)m->vertex_count, 1))) {
		mlod_surface_free(s);
		return mlod_fail(err, MLOD_ERR_NOMEM, "deviation: out of memory");
	}
	memcpy(s->mesh.positions, m->positions, pos);
	if (!s->borrowed)
		memcpy(s->mesh.indices, m->indices, ind);
	s->mesh.vertex_count = m->vertex_count;
	s->mesh.triangle_count = m->triangle_count;
	s->diag = diag;
	degenerate_flags(&s->mesh, s->degen);
	for (long i = 0; i < 3L * m->triangle_count; i++)
		s->used[m->indices[i]] = 1;
	*out = s;
	return MLOD_OK;
}

const mlod_posed *mlod_surface_mesh(const mlod_surface *s)
{
	return &s->mesh;
}

mlod_result mlod_surface_build(mlod_surface *s, mlod_error *err)
{
	const bvh *like = NULL, *tree;
	if (s->like) {
		pthread_mutex_lock(&s->like->lock);
		like = s->like->built ? &s->like->tree : NULL;
		pthread_mutex_unlock(&s->like->lock);
	}
	const target t = { &s->mesh, &s->tree, &s->built, &s->lock, like, s->degen, s->used };
	return target_tree(&t, &tree, err);
}

void mlod_surface_like(mlod_surface *s, mlod_surface *like)
{
	if (like && like != s && like->mesh.triangle_count == s->mesh.triangle_count &&
	    !memcmp(like->mesh.indices, s->mesh.indices, 3 * (size_t)s->mesh.triangle_count * sizeof *s->mesh.indices))
		s->like = like;
}

void mlod_warm_release(mlod_warm *w)
{
	if (w && w->b_tree) {
		bvh_free(w->b_tree);
		free(w->b_tree);
		w->b_tree = NULL;
	}
}

void mlod_surface_free(mlod_surface *s)
{
	if (!s)
		return;
	if (s->built)
		bvh_free(&s->tree);
	pthread_mutex_destroy(&s->lock);
	if (s->borrowed)
		s->mesh.indices = NULL;
	mlod_posed_free(&s->mesh);
	free(s->degen);
	free(s->used);
	free(s);
}

int mlod_surface_is(const mlod_surface *s, const mlod_posed *m)
{
	return s->mesh.vertex_count == m->vertex_count && s->mesh.triangle_count == m->triangle_count &&
	       !memcmp(s->mesh.positions, m->positions, 3 * (size_t)m->vertex_count * sizeof *m->positions) &&
	       !memcmp(s->mesh.indices, m->indices, 3 * (size_t)m->triangle_count * sizeof *m->indices);
}

mlod_result mlod_surface_deviation_to(const mlod_surface *a, const mlod_posed *b, mlod_warm *warm,
                                      mlod_deviation *out, mlod_error *err)
{
	mlod_result r;
	if (!out)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "deviation: no output");
	if ((r = check_mesh(b, "b", err)))
		return r;
	if (warm && (warm->a_count != a->mesh.vertex_count + a->mesh.triangle_count ||
	             warm->b_count != b->vertex_count + b->triangle_count))
		warm = NULL; /* made for other meshes: measured without */
	mlod_surface *s = (mlod_surface *)a; /* only its lazily built hierarchy changes, under its lock */
	const bvh *like = NULL;
	if (s->like) {
		pthread_mutex_lock(&s->like->lock);
		like = s->like->built ? &s->like->tree : NULL;
		pthread_mutex_unlock(&s->like->lock);
	}
	const target onto_a = { &s->mesh, &s->tree, &s->built, &s->lock, like, s->degen, s->used };
	return both_ways(&onto_a, b, a->diag, warm, out, err);
}
