/*
 * bgm.c: the BindGraphMesh (Savoye & Meyer 2008, 4.2.1): a mesh with its
 * embedded dual graph and the joint influences of its nodes.
 *
 * glTF splits vertices wherever an attribute is discontinuous (UV and
 * normal seams). The BGM welds them by position for topology, so that a
 * seam is not a border, and keeps each seam side's attributes as a
 * "wedge" (one per distinct glTF vertex of the node), so collapses
 * neither tear seams nor smear textures (the wedge rules are in
 * collapseplan.c). Vertices weld only when their influences and morph target
 * offsets are equal too: welding vertices that deform differently would
 * tear the mesh when posed. Rigid meshes under a joint are skinned to it
 * with weight 1 (influence id 0); static meshes have no influences.
 *
 * The dual graph is the face adjacency across each edge. Edges with one
 * face are borders; nodes on edges with more than two faces, on edges
 * whose two faces disagree on winding, or whose faces do not form one fan
 * (a disk, or a half-disk on a border) are locked: no collapse touches
 * them, so the simplification never makes the mesh less manifold than
 * its input. Triangles with two corners on one node are dropped.
 */
#define _POSIX_C_SOURCE 199309L /* clock_gettime */

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bgm.h"

/* Whether corners a, b, c (vertex indices) make a triangle of nonzero
 * area. */
static int has_area(const float *pos, uint32_t a, uint32_t b, uint32_t c)
{
	const float *A = pos + 3 * (size_t)a, *B = pos + 3 * (size_t)b, *C = pos + 3 * (size_t)c;
	const double u[3] = {B[0] - A[0], B[1] - A[1], B[2] - A[2]}, v[3] = {C[0] - A[0], C[1] - A[1], C[2] - A[2]};
	const double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
	return n[0] != 0.0 || n[1] != 0.0 || n[2] != 0.0;
}

int bgm_has_triangle(const mlod_primitive *p)
{
	if (p->index_count == 0) {
		for (int t = 0; t + 2 < p->vertex_count; t += 3)
			if (!p->positions || has_area(p->positions, (uint32_t)t, (uint32_t)t + 1, (uint32_t)t + 2))
				return 1;
		return 0;
	}
	for (int t = 0; t + 2 < p->index_count; t += 3) {
		const uint32_t *ix = p->indices + t;
		if (ix[0] != ix[1] && ix[1] != ix[2] && ix[0] != ix[2] &&
		    (!p->positions || (ix[0] < (uint32_t)p->vertex_count && ix[1] < (uint32_t)p->vertex_count &&
		                       ix[2] < (uint32_t)p->vertex_count && has_area(p->positions, ix[0], ix[1], ix[2]))))
			return 1;
	}
	return 0;
}

double bgm_seconds(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Grows *p (holding *cap elements of size) to hold need; 0 or -1. */
int bgm_grow(void **p, int *cap, int need, size_t size)
{
	if (need <= *cap)
		return 0;
	if (need > INT_MAX / 2)
		return -1;
	int n = *cap > 0 ? *cap : 16;
	while (n < need)
		n *= 2;
	void *q = realloc(*p, (size_t)n * size);
	if (!q)
		return -1;
	*p = q;
	*cap = n;
	return 0;
}

double bgm_compactness(const double *a, const double *b, const double *c)
{
	double u[3], v[3], w[3], n[3];
	for (int i = 0; i < 3; i++)
		u[i] = b[i] - a[i], v[i] = c[i] - a[i], w[i] = c[i] - b[i];
	n[0] = u[1] * v[2] - u[2] * v[1];
	n[1] = u[2] * v[0] - u[0] * v[2];
	n[2] = u[0] * v[1] - u[1] * v[0];
	double area = 0.5 * sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
	double l2 = u[0] * u[0] + u[1] * u[1] + u[2] * u[2] + v[0] * v[0] + v[1] * v[1] + v[2] * v[2] + w[0] * w[0] +
	            w[1] * w[1] + w[2] * w[2];
	if (!(l2 > 0.0))
		return 0.0;
	return 4.0 * sqrt(3.0) * area / l2;
}

int bgm_node_eligible(const mlod_bgm *g, const mlod_influences *inf)
{
	if (g->joint_count == 0)
		return 1;
	return mlod_vertex_eligible(g->opt.eligibility, g->tau, inf, g->joint_map, g->eta);
}

int bgm_add_node(mlod_bgm *g)
{
	if (bgm_grow((void **)&g->nodes, &g->node_cap, g->node_count + 1, sizeof *g->nodes))
		return -1;
	/* The parallel arrays follow the same capacity. */
	if (g->node_aux_cap < g->node_cap) {
		void *p = realloc(g->inf, (size_t)g->node_cap * sizeof *g->inf);
		if (!p)
			return -1;
		g->inf = p;
		if (g->lay.morph_stride > 0) {
			p = realloc(g->morph, (size_t)g->node_cap * (size_t)g->lay.morph_stride * sizeof *g->morph);
			if (!p)
				return -1;
			g->morph = p;
		}
		g->node_aux_cap = g->node_cap;
	}
	/* A node made after bgm_quadrics_build (by a collapse) needs only
	 * its row's index: it reuses a parent's row (bgm_apply). */
	if (g->qslot && g->qslot_cap < g->node_cap) {
		void *p = realloc(g->qslot, (size_t)g->node_cap * sizeof *g->qslot);
		if (!p)
			return -1;
		g->qslot = p;
		g->qslot_cap = g->node_cap;
	}
	int n = g->node_count++;
	memset(&g->nodes[n], 0, sizeof g->nodes[n]);
	memset(&g->inf[n], 0, sizeof g->inf[n]);
	if (g->lay.morph_stride > 0)
		memset(g->morph + (size_t)n * (size_t)g->lay.morph_stride, 0, sizeof(float) * (size_t)g->lay.morph_stride);
	/* Its posed quadrics (once there are any) are the caller's to write:
	 * the one caller after bgm_quadrics_build, bgm_apply (collapseapply.c),
	 * writes every entry and resets its pulled-back quadric. */
	return n;
}

int bgm_add_wedge(mlod_bgm *g, int node)
{
	int cap = g->wedge_cap;
	if (bgm_grow((void **)&g->wedge_node, &cap, g->wedge_count + 1, sizeof *g->wedge_node))
		return -1;
	if (cap != g->wedge_cap) {
		void *p = realloc(g->wedge_source, (size_t)cap * sizeof *g->wedge_source);
		if (!p)
			return -1;
		g->wedge_source = p;
		if (g->lay.stride > 0) {
			p = realloc(g->wedge_attr, (size_t)cap * (size_t)g->lay.stride * sizeof *g->wedge_attr);
			if (!p)
				return -1;
			g->wedge_attr = p;
		}
		g->wedge_cap = cap;
	}
	int w = g->wedge_count++;
	g->wedge_node[w] = node;
	g->wedge_source[w] = -1;
	if (g->lay.stride > 0)
		memset(g->wedge_attr + (size_t)w * (size_t)g->lay.stride, 0, sizeof(float) * (size_t)g->lay.stride);
	return w;
}

int bgm_add_face(mlod_bgm *g, const int *w, int birth)
{
	if (bgm_grow((void **)&g->faces, &g->face_cap, g->face_count + 1, sizeof *g->faces))
		return -1;
	int f = g->face_count++;
	bgm_face *F = &g->faces[f];
	for (int i = 0; i < 3; i++) {
		F->w[i] = w[i];
		F->n[i] = g->wedge_node[w[i]];
		F->adj[i] = -1;
	}
	F->birth = birth;
	F->death = BGM_ALIVE;
	return f;
}

/* Incidence lists live in one pool; a list that outgrows its slot moves
 * to the end of the pool with twice the room. */
int bgm_inc_add(mlod_bgm *g, int node, int face)
{
	bgm_node *n = &g->nodes[node];
	if (n->inc_count == n->inc_cap) {
		int cap = n->inc_cap > 0 ? 2 * n->inc_cap : 8;
		if (bgm_grow((void **)&g->inc, &g->inc_cap, g->inc_len + cap, sizeof *g->inc))
			return -1;
		memcpy(g->inc + g->inc_len, g->inc + n->inc_first, sizeof(int) * (size_t)n->inc_count);
		n->inc_first = g->inc_len;
		n->inc_cap = cap;
		g->inc_len += cap;
	}
	g->inc[n->inc_first + n->inc_count++] = face;
	return 0;
}

void bgm_inc_remove(mlod_bgm *g, int node, int face)
{
	bgm_node *n = &g->nodes[node];
	int *list = g->inc + n->inc_first;
	for (int i = 0; i < n->inc_count; i++)
		if (list[i] == face) {
			memmove(list + i, list + i + 1, sizeof(int) * (size_t)(n->inc_count - i - 1));
			n->inc_count--;
			return;
		}
}

/* ---------------------------------------------------------------- */
/* Hashing for the weld                                              */
/* ---------------------------------------------------------------- */

static uint64_t hash_bytes(uint64_t h, const void *data, size_t n)
{
	const unsigned char *p = data;
	for (size_t i = 0; i < n; i++) {
		h ^= p[i];
		h *= 1099511628211ull;
	}
	return h;
}

/* -0.0 and 0.0 weld. */
static float canon(float x)
{
	return x == 0.0f ? 0.0f : x;
}

/* The weld key of input vertex v: position, influences, morph offsets. */
static size_t vertex_key(const mlod_bgm *g, int v, float *key)
{
	const mlod_primitive *p = g->prim;
	size_t n = 0;
	for (int i = 0; i < 3; i++)
		key[n++] = canon(p->positions[3 * v + i]);
	for (int t = 0; t < p->target_count; t++)
		if (p->targets[t].positions)
			for (int i = 0; i < 3; i++)
				key[n++] = canon(p->targets[t].positions[3 * v + i]);
	return n;
}

/* The attribute floats of input vertex v in layout order. */
static void wedge_values(const mlod_bgm *g, int v, float *out)
{
	const mlod_primitive *p = g->prim;
	const bgm_layout *L = &g->lay;
	if (L->normal >= 0)
		memcpy(out + L->normal, p->normals + 3 * v, 3 * sizeof(float));
	if (L->tangent >= 0)
		memcpy(out + L->tangent, p->tangents + 4 * v, 4 * sizeof(float));
	for (int k = 0; k < MLOD_MAX_SETS; k++) {
		if (L->uv[k] >= 0)
			memcpy(out + L->uv[k], p->uvs[k] + 2 * v, 2 * sizeof(float));
		if (L->color[k] >= 0)
			memcpy(out + L->color[k], p->colors[k] + 4 * v, 4 * sizeof(float));
	}
	for (int t = 0; t < p->target_count; t++) {
		if (L->target_normal >= 0 && p->targets[t].normals)
			memcpy(out + L->target_normal + 3 * t, p->targets[t].normals + 3 * v, 3 * sizeof(float));
		if (L->target_tangent >= 0 && p->targets[t].tangents)
			memcpy(out + L->target_tangent + 3 * t, p->targets[t].tangents + 3 * v, 3 * sizeof(float));
	}
	for (int i = 0; i < L->stride; i++)
		out[i] = canon(out[i]);
}

/* Influences of input vertex v, merged by joint, normalised, sorted by
 * joint (so equal influences compare equal). */
static void vertex_influences(const mlod_bgm *g, int v, mlod_influences *out)
{
	const mlod_primitive *p = g->prim;
	memset(out, 0, sizeof *out);
	if (g->rigid) {
		out->count = 1;
		out->joints[0] = 0;
		out->weights[0] = 1.0f;
		return;
	}
	if (!g->skinned)
		return;
	double w[MLOD_MAX_INFLUENCES];
	for (int s = 0; s < p->weight_set_count && s < MLOD_MAX_SETS; s++)
		for (int k = 0; k < 4; k++) {
			float x = p->weights[s][4 * v + k];
			uint16_t j = p->joints[s][4 * v + k];
			if (!(x > 0.0f) || j >= g->joint_count)
				continue;
			int i = 0;
			while (i < out->count && out->joints[i] != j)
				i++;
			if (i == out->count) {
				out->joints[i] = j;
				w[i] = 0.0;
				out->count++;
			}
			w[i] += x;
		}
	double sum = 0.0;
	for (int i = 0; i < out->count; i++)
		sum += w[i];
	if (!(sum > 0.0)) {
		out->count = 0;
		return;
	}
	/* Sort by joint. */
	for (int i = 1; i < out->count; i++) {
		uint16_t j = out->joints[i];
		double x = w[i];
		int k = i;
		while (k > 0 && out->joints[k - 1] > j) {
			out->joints[k] = out->joints[k - 1];
			w[k] = w[k - 1];
			k--;
		}
		out->joints[k] = j;
		w[k] = x;
	}
	for (int i = 0; i < out->count; i++)
		out->weights[i] = (float)(w[i] / sum);
}

/* Vertex and hybrid placement: input vertex v's influences as it has them (its
 * weight sets in order, trailing zero weights dropped, not merged,
 * normalised or sorted), so that a level's vertex copied from it is
 * written with the same joints and weights, bit for bit. */
static void raw_influences(const mlod_bgm *g, int v, mlod_influences *out)
{
	const mlod_primitive *p = g->prim;
	if (g->rigid || !g->skinned) {
		vertex_influences(g, v, out);
		return;
	}
	memset(out, 0, sizeof *out);
	int last = 0;
	for (int s = 0; s < p->weight_set_count && s < MLOD_MAX_SETS; s++)
		for (int k = 0; k < 4; k++) {
			float x = p->weights[s][4 * v + k];
			uint16_t j = p->joints[s][4 * v + k];
			if (!(x >= 0.0f) || j >= g->joint_count)
				continue;
			out->joints[out->count] = j;
			out->weights[out->count++] = x;
			if (x > 0.0f)
				last = out->count;
		}
	out->count = last;
}

/* ---------------------------------------------------------------- */
/* Building                                                          */
/* ---------------------------------------------------------------- */

struct edge_rec {
	uint64_t key; /* min node << 32 | max node */
	int face;
	int e;        /* edge e of face: n[e] -> n[e + 1] */
	int forward;  /* n[e] < n[e + 1] */
};

/* Sorts edges (made face after face, edge after edge) by key, then
 * face, then edge, through tmp: a stable counting sort by the high node,
 * then by the low one (nodes below n), which keeps equal keys in the
 * order they were made. Returns -1 when out of memory. */
static int sort_edges(struct edge_rec *edges, struct edge_rec *tmp, int ne, int n)
{
	int *count = malloc(sizeof *count * ((size_t)n + 1));
	if (!count)
		return -1;
	for (int pass = 0; pass < 2; pass++) {
		struct edge_rec *from = pass == 0 ? edges : tmp, *to = pass == 0 ? tmp : edges;
		int shift = pass == 0 ? 0 : 32;
		memset(count, 0, sizeof *count * ((size_t)n + 1));
		for (int i = 0; i < ne; i++)
			count[(uint32_t)(from[i].key >> shift)]++;
		for (int v = 0, at = 0; v < n; v++) {
			int c = count[v];
			count[v] = at;
			at += c;
		}
		for (int i = 0; i < ne; i++)
			to[count[(uint32_t)(from[i].key >> shift)]++] = from[i];
	}
	free(count);
	return 0;
}

int bgm_link_ok(const int *from, const int *to, int m, int path_ok)
{
	if (m == 0)
		return 1;
	/* Each link vertex: at most one outgoing and one incoming edge (no
	 * value twice in from[], nor in to[]), no loop. The vertices in a
	 * small open-addressed table: where each is in from[] and in to[]. */
	enum { BITS = 9, SIZE = 1 << BITS };
	if (m > SIZE / 2)
		return 0; /* a link this long (callers give at most MAX_PATCH, 128): leave it alone */
	int bits = 4;
	while ((1 << bits) < 2 * m)
		bits++;
	unsigned mask = (1u << bits) - 1u;
	int key[SIZE], fi[SIZE], ti[SIZE];
	for (unsigned i = 0; i <= mask; i++)
		key[i] = -1;
	for (int pass = 0; pass < 2; pass++)
		for (int i = 0; i < m; i++) {
			int x = pass == 0 ? from[i] : to[i];
			if (x < 0)
				return 0; /* not a node */
			unsigned h = (((unsigned)x * 0x9E3779B1u) & 0xFFFFFFFFu) >> (32 - bits);
			while (key[h] >= 0 && key[h] != x)
				h = (h + 1u) & mask;
			if (key[h] < 0)
				key[h] = x, fi[h] = ti[h] = -1;
			int *slot = pass == 0 ? &fi[h] : &ti[h];
			if (*slot >= 0 || from[i] == to[i])
				return 0;
			*slot = i;
		}
	/* A start: an edge nothing comes into (the last such, as ever). */
	int starts = 0, start = 0;
	for (int i = 0; i < m; i++) {
		unsigned h = (((unsigned)from[i] * 0x9E3779B1u) & 0xFFFFFFFFu) >> (32 - bits);
		while (key[h] != from[i])
			h = (h + 1u) & mask;
		if (ti[h] < 0) {
			starts++;
			start = i;
		}
	}
	if (starts > 1 || (starts == 1 && !path_ok))
		return 0;
	/* Walk from the start; every edge must be visited once. */
	int at = start, steps = 1;
	for (;;) {
		int x = to[at], next = -1;
		unsigned h = (((unsigned)x * 0x9E3779B1u) & 0xFFFFFFFFu) >> (32 - bits);
		while (key[h] >= 0 && key[h] != x)
			h = (h + 1u) & mask;
		if (key[h] == x)
			next = fi[h];
		if (next < 0 || next == start)
			break;
		at = next;
		if (++steps > m)
			return 0;
	}
	if (steps != m)
		return 0;
	return starts == 1 || m >= 3;
}

/* Is the link of node v (the directed edges p -> q of its faces
 * (v, p, q)) one fan? */
static int fan_ok(const mlod_bgm *g, int v, int path_ok)
{
	const bgm_node *n = &g->nodes[v];
	enum { MAXF = 64 };
	int from[MAXF], to[MAXF], m = n->inc_count;
	if (m > MAXF)
		return 0; /* valence this high: leave it alone */
	for (int i = 0; i < m; i++) {
		const bgm_face *f = &g->faces[g->inc[n->inc_first + i]];
		int c = f->n[0] == v ? 0 : f->n[1] == v ? 1 : 2;
		from[i] = f->n[(c + 1) % 3];
		to[i] = f->n[(c + 2) % 3];
	}
	return bgm_link_ok(from, to, m, path_ok);
}

static mlod_result build(mlod_bgm *g, const mlod_character *c, const mlod_instance *in, mlod_error *err)
{
	const mlod_primitive *p = g->prim;
	int nv = p->vertex_count;
	int ni = p->index_count > 0 ? p->index_count : nv;
	mlod_result r = MLOD_OK;
	float *key = NULL, *attr = NULL, *attr2 = NULL;
	int *table = NULL, *vnode = NULL, *vwedge = NULL, *wtable = NULL;
	struct edge_rec *edges = NULL;
	mlod_influences *vinf = NULL;

	/* Layout. */
	bgm_layout *L = &g->lay;
	L->stride = 0;
	L->normal = p->normals ? (L->stride += 3) - 3 : -1;
	L->tangent = p->tangents ? (L->stride += 4) - 4 : -1;
	for (int k = 0; k < MLOD_MAX_SETS; k++) {
		L->uv[k] = k < p->uv_set_count && p->uvs[k] ? (L->stride += 2) - 2 : -1;
		L->color[k] = k < p->color_set_count && p->colors[k] ? (L->stride += 4) - 4 : -1;
	}
	int tn = 0, tt = 0, tp = 0;
	for (int t = 0; t < p->target_count; t++) {
		tn |= p->targets[t].normals != NULL;
		tt |= p->targets[t].tangents != NULL;
		tp |= p->targets[t].positions != NULL;
	}
	L->target_normal = tn ? (L->stride += 3 * p->target_count) - 3 * p->target_count : -1;
	L->target_tangent = tt ? (L->stride += 3 * p->target_count) - 3 * p->target_count : -1;
	L->morph_stride = tp ? 3 * p->target_count : 0;

	size_t keylen = 3 + (size_t)L->morph_stride;
	key = malloc(sizeof(float) * keylen * (size_t)nv);
	vinf = malloc(sizeof *vinf * (size_t)nv);
	vnode = malloc(sizeof(int) * (size_t)nv);
	vwedge = malloc(sizeof(int) * (size_t)nv);
	int tsize = 16;
	while (tsize < 2 * nv)
		tsize *= 2;
	table = malloc(sizeof(int) * (size_t)tsize);
	wtable = malloc(sizeof(int) * (size_t)tsize);
	attr = malloc(sizeof(float) * ((size_t)L->stride + 1));
	attr2 = malloc(sizeof(float) * ((size_t)L->stride + 1));
	if (!key || !vinf || !vnode || !vwedge || !table || !wtable || !attr || !attr2) {
		r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory building the BindGraphMesh (%d vertices)", nv);
		goto done;
	}

	/* Weld: nodes by position, influences and morph offsets. */
	for (int i = 0; i < tsize; i++)
		table[i] = wtable[i] = -1;
	for (int v = 0; v < nv; v++) {
		float *k = key + keylen * (size_t)v;
		vertex_key(g, v, k);
		vertex_influences(g, v, &vinf[v]);
		uint64_t h = hash_bytes(1469598103934665603ull, k, sizeof(float) * keylen);
		h = hash_bytes(h, &vinf[v].count, sizeof vinf[v].count);
		h = hash_bytes(h, vinf[v].joints, sizeof(uint16_t) * (size_t)vinf[v].count);
		h = hash_bytes(h, vinf[v].weights, sizeof(float) * (size_t)vinf[v].count);
		size_t slot = (size_t)h & (size_t)(tsize - 1);
		int node = -1;
		while (table[slot] >= 0) {
			int u = table[slot]; /* an input vertex that made a node */
			if (memcmp(key + keylen * (size_t)u, k, sizeof(float) * keylen) == 0 && bgm_same_influences(&vinf[u], &vinf[v])) {
				node = vnode[u];
				break;
			}
			slot = (slot + 1) & (size_t)(tsize - 1);
		}
		if (node < 0) {
			if ((node = bgm_add_node(g)) < 0) {
				r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory building the BindGraphMesh");
				goto done;
			}
			table[slot] = v;
			for (int i = 0; i < 3; i++)
				g->nodes[node].p[i] = p->positions[3 * v + i];
			if (g->opt.placement == MLOD_PLACE_VERTEX || g->opt.placement == MLOD_PLACE_HYBRID)
				raw_influences(g, v, &g->inf[node]);
			else
				g->inf[node] = vinf[v];
			for (int i = 0; i < L->morph_stride; i++)
				g->morph[(size_t)node * (size_t)L->morph_stride + (size_t)i] = k[3 + i];
		}
		vnode[v] = node;

		/* Wedges: distinct attribute sets of a node. */
		wedge_values(g, v, attr);
		uint64_t wh = hash_bytes(1469598103934665603ull, &node, sizeof node);
		wh = hash_bytes(wh, attr, sizeof(float) * (size_t)L->stride);
		slot = (size_t)wh & (size_t)(tsize - 1);
		int wedge = -1;
		while (wtable[slot] >= 0) {
			int u = wtable[slot];
			if (vnode[u] == node) {
				wedge_values(g, u, attr2);
				if (memcmp(attr, attr2, sizeof(float) * (size_t)L->stride) == 0) {
					wedge = vwedge[u];
					break;
				}
			}
			slot = (slot + 1) & (size_t)(tsize - 1);
		}
		if (wedge < 0) {
			if ((wedge = bgm_add_wedge(g, node)) < 0) {
				r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory building the BindGraphMesh");
				goto done;
			}
			wtable[slot] = v;
			g->wedge_source[wedge] = v;
			if (L->stride > 0)
				memcpy(g->wedge_attr + (size_t)wedge * (size_t)L->stride, attr, sizeof(float) * (size_t)L->stride);
		}
		vwedge[v] = wedge;
	}

	/* Faces; degenerate ones (two corners on a node) are dropped. */
	for (int t = 0; t + 2 < ni; t += 3) {
		int w[3];
		for (int i = 0; i < 3; i++) {
			uint32_t v = p->index_count > 0 ? p->indices[t + i] : (uint32_t)(t + i);
			w[i] = vwedge[v];
		}
		int a = g->wedge_node[w[0]], b = g->wedge_node[w[1]], cc = g->wedge_node[w[2]];
		if (a == b || b == cc || a == cc) {
			g->dropped++;
			continue;
		}
		if (bgm_add_face(g, w, 0) < 0) {
			r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory building the BindGraphMesh");
			goto done;
		}
	}
	g->input_triangles = g->face_count;
	g->live_triangles = g->face_count;

	/* Incidence lists, with room to grow. */
	{
		int total = 0;
		for (int f = 0; f < g->face_count; f++)
			for (int i = 0; i < 3; i++)
				g->nodes[g->faces[f].n[i]].inc_cap++;
		for (int v = 0; v < g->node_count; v++) {
			g->nodes[v].inc_cap += 4;
			g->nodes[v].inc_first = total;
			total += g->nodes[v].inc_cap;
		}
		if (bgm_grow((void **)&g->inc, &g->inc_cap, total + 1, sizeof *g->inc)) {
			r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory building the BindGraphMesh");
			goto done;
		}
		g->inc_len = total;
		for (int f = 0; f < g->face_count; f++)
			for (int i = 0; i < 3; i++) {
				bgm_node *n = &g->nodes[g->faces[f].n[i]];
				g->inc[n->inc_first + n->inc_count++] = f;
			}
	}

	/* The dual graph, borders, non-manifold edges. */
	edges = malloc(sizeof *edges * (size_t)(3 * g->face_count + 1));
	if (!edges) {
		r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory building the dual graph");
		goto done;
	}
	int ne = 0;
	for (int f = 0; f < g->face_count; f++)
		for (int e = 0; e < 3; e++) {
			int a = g->faces[f].n[e], b = g->faces[f].n[(e + 1) % 3];
			int lo = a < b ? a : b, hi = a < b ? b : a;
			edges[ne++] = (struct edge_rec){((uint64_t)(uint32_t)lo << 32) | (uint32_t)hi, f, e, a < b};
		}
	{
		struct edge_rec *tmp = malloc(sizeof *tmp * ((size_t)ne + 1));
		int bad = !tmp || sort_edges(edges, tmp, ne, g->node_count);
		free(tmp);
		if (bad) {
			r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory building the dual graph");
			goto done;
		}
	}
	for (int i = 0; i < ne;) {
		int j = i;
		while (j < ne && edges[j].key == edges[i].key)
			j++;
		int a = (int)(edges[i].key >> 32), b = (int)(edges[i].key & 0xffffffffu);
		if (j - i == 1) {
			g->border_edges++;
			g->nodes[a].flags |= BGM_BORDER;
			g->nodes[b].flags |= BGM_BORDER;
		} else if (j - i == 2 && edges[i].forward != edges[i + 1].forward) {
			g->faces[edges[i].face].adj[edges[i].e] = edges[i + 1].face;
			g->faces[edges[i + 1].face].adj[edges[i + 1].e] = edges[i].face;
		} else {
			if (j - i > 2)
				g->nonmanifold_edges++;
			g->nodes[a].flags |= BGM_LOCKED | BGM_BORDER;
			g->nodes[b].flags |= BGM_LOCKED | BGM_BORDER;
		}
		i = j;
	}

	/* Fans, seams, weightless skinned nodes, eligibility. */
	for (int v = 0; v < g->node_count; v++) {
		bgm_node *n = &g->nodes[v];
		if (!(n->flags & BGM_LOCKED) && !fan_ok(g, v, (n->flags & BGM_BORDER) != 0))
			n->flags |= BGM_LOCKED;
		if (g->joint_count > 0 && g->inf[v].count == 0)
			n->flags |= BGM_LOCKED;
		if (bgm_node_eligible(g, &g->inf[v]))
			n->flags |= BGM_ELIGIBLE;
		int first = -1, seam = 0;
		for (int i = 0; i < n->inc_count; i++) {
			const bgm_face *f = &g->faces[g->inc[n->inc_first + i]];
			int w = f->w[f->n[0] == v ? 0 : f->n[1] == v ? 1 : 2];
			if (first < 0)
				first = w;
			else if (w != first)
				seam = 1;
		}
		g->seam_nodes += seam;
		g->locked_nodes += (n->flags & BGM_LOCKED) != 0;
		g->eligible_nodes += (n->flags & BGM_ELIGIBLE) && !(n->flags & BGM_LOCKED);
	}

	/* Posed quadrics, for the posed cost and the optimal placement. */
	if (g->opt.cost == MLOD_COST_POSED || g->opt.placement == MLOD_PLACE_OPTIMAL || g->opt.placement == MLOD_PLACE_HYBRID)
		r = bgm_quadrics_build(g, c, in, err);

done:
	free(key);
	free(vinf);
	free(vnode);
	free(vwedge);
	free(table);
	free(wtable);
	free(attr);
	free(attr2);
	free(edges);
	return r;
}

void mlod_bgm_options_resolve(mlod_bgm_options *opt)
{
	if (opt->cost == MLOD_COST_DEFAULT)
		opt->cost = MLOD_COST_POSED;
	/* as measured: see mlod-bgm(1) and bench/RESULTS.md */
	if (opt->placement == MLOD_PLACE_DEFAULT)
		opt->placement = opt->cost == MLOD_COST_COMPACTNESS ? MLOD_PLACE_BARYCENTER : MLOD_PLACE_OPTIMAL;
	if (opt->placement == MLOD_PLACE_HYBRID && opt->cost == MLOD_COST_COMPACTNESS)
		opt->placement = MLOD_PLACE_OPTIMAL; /* it weighs posed costs, which compactness has not */
	if (opt->op == MLOD_OP_DEFAULT)
		opt->op = opt->cost == MLOD_COST_COMPACTNESS ? MLOD_OP_TRIANGLE : MLOD_OP_EDGE;
	if (opt->eligibility == MLOD_ELIGIBLE_DEFAULT)
		opt->eligibility = opt->cost == MLOD_COST_COMPACTNESS ? MLOD_ELIGIBLE_BEND : MLOD_ELIGIBLE_ALL;
}

mlod_result mlod_bgm_build(const mlod_character *c, int instance, int primitive, const mlod_bgm_options *opt,
                           mlod_bgm **out, mlod_error *err)
{
	if (!c || !out)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_bgm_build: NULL argument");
	*out = NULL;
	double t0 = bgm_seconds();
	if (instance < 0 || instance >= c->instance_count)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "instance %d does not exist (%d instances)", instance,
		                 c->instance_count);
	const mlod_instance *in = &c->instances[instance];
	if (in->mesh < 0 || in->mesh >= c->mesh_count || in->skin >= c->skeleton.skin_count ||
	    in->joint >= c->skeleton.joint_count)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "instance %d refers outside the character", instance);
	const mlod_mesh *mesh = &c->meshes[in->mesh];
	if (primitive < 0 || primitive >= mesh->primitive_count)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "instance %d: primitive %d does not exist", instance, primitive);
	const mlod_primitive *p = &mesh->primitives[primitive];
	if (p->mode != 4)
		return mlod_fail(err, MLOD_ERR_UNSUPPORTED, "mesh %d primitive %d: mode %d is not triangles", in->mesh,
		                 primitive, p->mode);
	if (p->vertex_count <= 0 || !p->positions || p->vertex_count > (1 << 26))
		return mlod_fail(err, MLOD_ERR_UNSUPPORTED, "mesh %d primitive %d: %d vertices", in->mesh, primitive,
		                 p->vertex_count);
	if (p->index_count < 0 || (p->index_count > 0 && !p->indices) || p->index_count > (1 << 28) ||
	    p->target_count < 0 || (p->target_count > 0 && !p->targets) || p->target_count > 256 ||
	    p->uv_set_count < 0 || p->uv_set_count > MLOD_MAX_SETS || p->color_set_count < 0 ||
	    p->color_set_count > MLOD_MAX_SETS || p->weight_set_count < 0 || p->weight_set_count > MLOD_MAX_SETS)
		return mlod_fail(err, MLOD_ERR_PARSE, "mesh %d primitive %d: malformed", in->mesh, primitive);
	for (int i = 0; i < p->index_count; i++)
		if (p->indices[i] >= (uint32_t)p->vertex_count)
			return mlod_fail(err, MLOD_ERR_PARSE, "mesh %d primitive %d: index %d out of range", in->mesh, primitive, i);
	for (long i = 0; i < 3L * p->vertex_count; i++)
		if (!isfinite(p->positions[i]))
			return mlod_fail(err, MLOD_ERR_PARSE, "mesh %d primitive %d: position not finite", in->mesh, primitive);
	for (int s = 0; s < p->weight_set_count; s++)
		if (!p->joints[s] || !p->weights[s])
			return mlod_fail(err, MLOD_ERR_PARSE, "mesh %d primitive %d: weight set %d has no data", in->mesh,
			                 primitive, s);
	if (!bgm_has_triangle(p))
		return mlod_fail(err, MLOD_ERR_UNSUPPORTED, "mesh %d primitive %d: no triangle has an area", in->mesh,
		                 primitive);

	mlod_bgm *g = calloc(1, sizeof *g);
	if (!g)
		return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory building the BindGraphMesh");
	g->prim = p;
	if (opt)
		g->opt = *opt;
	mlod_bgm_options_resolve(&g->opt);
	if (g->opt.op != MLOD_OP_TRIANGLE && g->opt.cost != MLOD_COST_POSED) {
		free(g);
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "edge collapses need the posed cost");
	}
	if ((unsigned)g->opt.cost > MLOD_COST_POSED || (unsigned)g->opt.placement > MLOD_PLACE_HYBRID ||
	    !(g->opt.hybrid_error >= 0.0) || !isfinite(g->opt.hybrid_error) ||
	    (unsigned)g->opt.op > MLOD_OP_MIXED || (unsigned)g->opt.eligibility > MLOD_ELIGIBLE_ALL ||
	    !(g->opt.tau >= 0.0) || !isfinite(g->opt.tau)) {
		free(g);
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_bgm_build: bad options");
	}
	g->tau = g->opt.tau > 0.0 ? g->opt.tau : 1.0;
	if (g->opt.hybrid_error == 0.0)
		g->opt.hybrid_error = MLOD_MESH_HYBRID_ERROR;
	g->opt.eta = NULL; /* owned copy below */
	g->opt.poses = opt ? opt->poses : NULL;

	mlod_result r = MLOD_OK;
	g->skeleton_joints = c->skeleton.joint_count;
	g->eta = malloc(sizeof(double) * ((size_t)g->skeleton_joints + 1));
	if (!g->eta) {
		r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory building the BindGraphMesh");
		goto fail;
	}
	if (opt && opt->eta)
		memcpy(g->eta, opt->eta, sizeof(double) * (size_t)g->skeleton_joints);
	else if ((r = mlod_joint_weight_average(c, g->eta, err)) != MLOD_OK)
		goto fail;

	if (in->skin >= 0 && p->weight_set_count > 0) {
		const mlod_skin *skin = &c->skeleton.skins[in->skin];
		g->skinned = 1;
		g->joint_count = skin->joint_count;
		g->joint_map = malloc(sizeof(int) * ((size_t)skin->joint_count + 1));
		if (!g->joint_map) {
			r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory building the BindGraphMesh");
			goto fail;
		}
		memcpy(g->joint_map, skin->joints, sizeof(int) * (size_t)skin->joint_count);
	} else if (in->skin < 0 && in->joint >= 0) {
		g->rigid = 1;
		g->joint_count = 1;
		g->joint_map = malloc(sizeof(int));
		if (!g->joint_map) {
			r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory building the BindGraphMesh");
			goto fail;
		}
		g->joint_map[0] = in->joint;
	}
	g->input_vertices = p->vertex_count;
	if ((r = build(g, c, in, err)) != MLOD_OK)
		goto fail;
	g->build_seconds = bgm_seconds() - t0;
	*out = g;
	return MLOD_OK;
fail:
	mlod_bgm_free(g);
	return r;
}

void mlod_bgm_free(mlod_bgm *g)
{
	if (!g)
		return;
	free(g->joint_map);
	free(g->eta);
	free(g->nodes);
	free(g->inf);
	free(g->morph);
	free(g->wedge_node);
	free(g->wedge_source);
	free(g->wedge_attr);
	free(g->faces);
	free(g->inc);
	free(g->records);
	free(g->removed);
	bgm_release_collapse_state(g);
	free(g);
}

void bgm_release_collapse_state(mlod_bgm *g)
{
	if (!g)
		return;
	free(g->quadric);
	free(g->qmap);
	free(g->qslot);
	free(g->qpose);
	free(g->rquad);
	free(g->qsum);
	free(g->skin);
	free(g->skin2);
	free(g->opstate);
	free(g->ftie);
	free(g->fgeo);
	free(g->fref);
	free(g->lbmemo);
	free(g->heap.e);
	free(g->heap.memo);
	g->quadric = g->rquad = g->qsum = g->skin2 = NULL;
	g->qmap = g->qpose = g->qslot = NULL;
	g->skin = NULL;
	g->opstate = NULL;
	g->ftie = g->fgeo = g->fref = NULL;
	g->lbmemo = NULL;
	g->heap.e = NULL;
	g->heap.memo = NULL;
	g->quadric_cap = g->opstate_cap = g->ftie_cap = g->qslot_cap = 0;
	g->released = 1;
	g->lbmemo_count = g->lbmemo_cap = 0;
	g->heap.count = g->heap.cap = 0;
	g->heap.memo_count = g->heap.memo_cap = g->heap.memo_free = 0;
}

void mlod_bgm_get_info(const mlod_bgm *g, mlod_bgm_info *out)
{
	memset(out, 0, sizeof *out);
	if (!g)
		return;
	out->vertices = g->input_vertices;
	out->nodes = g->node_count - g->record_count;
	out->triangles = g->input_triangles;
	out->dropped = g->dropped;
	out->border_edges = g->border_edges;
	out->nonmanifold_edges = g->nonmanifold_edges;
	out->seam_nodes = g->seam_nodes;
	out->locked_nodes = g->locked_nodes;
	out->eligible_nodes = g->eligible_nodes;
	out->collapses = g->record_count;
	out->live_triangles = g->live_triangles;
	out->caps = g->caps;
	out->snaps = g->snaps;
	out->refused = g->refused;
	out->build_seconds = g->build_seconds;
	out->collapse_seconds = g->collapse_seconds;
}

const mlod_vsplit *mlod_bgm_sequence(const mlod_bgm *g, int *count)
{
	if (count)
		*count = g ? g->record_count : 0;
	return g ? g->records : NULL;
}

const int *mlod_bgm_removed_faces(const mlod_bgm *g)
{
	return g ? g->removed : NULL;
}

int mlod_bgm_triangles(const mlod_bgm *g, int prefix)
{
	if (!g)
		return 0;
	if (prefix <= 0 || g->record_count == 0)
		return g->input_triangles;
	if (prefix > g->record_count)
		prefix = g->record_count;
	return g->records[prefix - 1].triangles;
}

int mlod_bgm_prefix_for(const mlod_bgm *g, int target)
{
	if (!g || g->input_triangles <= target)
		return 0;
	/* Triangle counts only decrease along the sequence: bisect. */
	int lo = 0, hi = g->record_count;
	if (hi == 0 || g->records[hi - 1].triangles > target)
		return g->record_count;
	while (hi - lo > 1) {
		int mid = (lo + hi) / 2;
		if (g->records[mid - 1].triangles <= target)
			hi = mid;
		else
			lo = mid;
	}
	return hi;
}

/* ---------------------------------------------------------------- */
/* Consistency check (tests)                                         */
/* ---------------------------------------------------------------- */

/* Whether sequence a's next record goes before b's in
 * mlod_bgm_share_budget: lower cost, then the lower index (a scan in
 * index order keeps the first of equal costs). */
static int share_before(mlod_bgm *const *bgms, const int *prefix, int a, int b)
{
	double ca = bgms[a]->records[prefix[a]].cost, cb = bgms[b]->records[prefix[b]].cost;
	return ca < cb || (!(cb < ca) && a < b);
}

static void share_sift(mlod_bgm *const *bgms, const int *prefix, int *heap, int count, int at)
{
	for (;;) {
		int l = 2 * at + 1, m = at;
		if (l < count && share_before(bgms, prefix, heap[l], heap[m]))
			m = l;
		if (l + 1 < count && share_before(bgms, prefix, heap[l + 1], heap[m]))
			m = l + 1;
		if (m == at)
			return;
		int t = heap[at];
		heap[at] = heap[m], heap[m] = t;
		at = m;
	}
}

long mlod_bgm_share_budget(mlod_bgm *const *bgms, int n, long target, int *prefix)
{
	long live = 0;
	for (int i = 0; i < n; i++) {
		prefix[i] = 0;
		live += bgms[i] ? bgms[i]->input_triangles : 0;
	}
	/* The sequences with records left in a heap by their next record's
	 * cost: the same choices as a scan of every sequence per collapse,
	 * which made this quadratic in parts (4,000 parts of 12 triangles:
	 * half of mlod-bgm's time; a scale probe). */
	int *heap = malloc(sizeof *heap * (size_t)(n > 0 ? n : 1)), count = 0;
	if (heap) {
		for (int i = 0; i < n; i++)
			if (bgms[i] && bgms[i]->record_count > 0)
				heap[count++] = i;
		for (int at = count / 2 - 1; at >= 0; at--)
			share_sift(bgms, prefix, heap, count, at);
		while (live > target && count > 0) {
			int best = heap[0];
			const mlod_bgm *g = bgms[best];
			live = live - (prefix[best] ? g->records[prefix[best] - 1].triangles : g->input_triangles) +
			       g->records[prefix[best]].triangles;
			if (++prefix[best] >= g->record_count)
				heap[0] = heap[--count];
			share_sift(bgms, prefix, heap, count, 0);
		}
		free(heap);
		return live;
	}
	while (live > target) { /* out of memory for the heap: the scan */
		int best = -1;
		for (int i = 0; i < n; i++) {
			const mlod_bgm *g = bgms[i];
			if (g && prefix[i] < g->record_count &&
			    (best < 0 || g->records[prefix[i]].cost < bgms[best]->records[prefix[best]].cost))
				best = i;
		}
		if (best < 0)
			break; /* nothing more comes off */
		const mlod_bgm *g = bgms[best];
		live = live - (prefix[best] ? g->records[prefix[best] - 1].triangles : g->input_triangles) +
		       g->records[prefix[best]].triangles;
		prefix[best]++;
	}
	return live;
}

mlod_result mlod_bgm_check(const mlod_bgm *g, mlod_error *err)
{
	if (!g)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_bgm_check: NULL");
	int live = 0;
	for (int f = 0; f < g->face_count; f++) {
		const bgm_face *F = &g->faces[f];
		if (F->death != BGM_ALIVE)
			continue;
		live++;
		for (int e = 0; e < 3; e++) {
			int a = F->n[e], b = F->n[(e + 1) % 3];
			if (a == b)
				return mlod_fail(err, MLOD_ERR_PARSE, "face %d is degenerate", f);
			if (g->nodes[a].flags & BGM_DEAD)
				return mlod_fail(err, MLOD_ERR_PARSE, "face %d uses collapsed node %d", f, a);
			if (g->wedge_node[F->w[e]] != a)
				return mlod_fail(err, MLOD_ERR_PARSE, "face %d corner %d: wedge of another node", f, e);
			int h = F->adj[e];
			if (h < 0)
				continue;
			const bgm_face *H = &g->faces[h];
			if (H->death != BGM_ALIVE)
				return mlod_fail(err, MLOD_ERR_PARSE, "face %d: dual graph names dead face %d", f, h);
			int back = -1;
			for (int k = 0; k < 3; k++)
				if (H->n[k] == b && H->n[(k + 1) % 3] == a)
					back = k;
			if (back < 0 || H->adj[back] != f)
				return mlod_fail(err, MLOD_ERR_PARSE, "faces %d and %d: dual graph not symmetric", f, h);
		}
		for (int i = 0; i < 3; i++) {
			const bgm_node *n = &g->nodes[F->n[i]];
			int found = 0;
			for (int k = 0; k < n->inc_count; k++)
				found |= g->inc[n->inc_first + k] == f;
			if (!found)
				return mlod_fail(err, MLOD_ERR_PARSE, "face %d missing from node %d's list", f, F->n[i]);
		}
	}
	if (live != g->live_triangles)
		return mlod_fail(err, MLOD_ERR_PARSE, "%d live faces, %d counted", live, g->live_triangles);
	for (int v = 0; v < g->node_count; v++) {
		const bgm_node *n = &g->nodes[v];
		for (int k = 0; k < n->inc_count; k++) {
			const bgm_face *F = &g->faces[g->inc[n->inc_first + k]];
			if (F->death != BGM_ALIVE || (F->n[0] != v && F->n[1] != v && F->n[2] != v))
				return mlod_fail(err, MLOD_ERR_PARSE, "node %d lists face %d wrongly", v, g->inc[n->inc_first + k]);
		}
		if (!(n->flags & (BGM_LOCKED | BGM_DEAD)) && !fan_ok(g, v, (n->flags & BGM_BORDER) != 0))
			return mlod_fail(err, MLOD_ERR_PARSE, "node %d: its faces are not one fan", v);
	}
	return MLOD_OK;
}
