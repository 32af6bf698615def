/*
 * skelgraph.c: the Multiresolution Skeletal Graph and the extraction of
 * skeleton levels (paper 4.1.3).
 *
 * A kinematic sub-chain starts at a non-minor joint, goes down one of its
 * children and follows minor joints until it meets non-minor ones, which
 * end it. Its transitive closure links every joint of the chain to every
 * descendant in the chain, weighted by the bone length along the chain.
 *
 * A level at threshold E disables the minor joints whose energy is below E
 * and takes the minimum spanning tree (Kruskal) of the enabled joints over
 * the closure edges. Only ancestor-descendant pairs are edges, so the tree
 * reconnects each kept joint to its nearest kept ancestor; ties between
 * equal lengths (zero-length bones) go to the deeper ancestor, which keeps
 * that equivalence exact.
 */
#include <stdlib.h>
#include <string.h>

#include "skeleton/mlod_skeleton.h"

/* The closure of a real skeleton has a few thousand edges; this bounds
 * hostile input (one chain of n joints has n(n-1)/2). */
#define MAX_CLOSURE_EDGES 4000000

void mlod_skelgraph_free(mlod_skelgraph *g)
{
	if (!g)
		return;
	free(g->joint_parent);
	free(g->chain_start);
	free(g->chain_joints);
	free(g->edges);
	memset(g, 0, sizeof *g);
}

void mlod_skel_level_free(mlod_skel_level *l)
{
	if (!l)
		return;
	free(l->kept);
	free(l->parent);
	free(l->remap);
	memset(l, 0, sizeof *l);
}

static int is_minor(const mlod_joint_info *info, int j)
{
	return info[j].label == MLOD_LABEL_MINOR;
}

/* Depths of joints for the tie-break, read from info. */
static const mlod_joint_info *sort_info;

static int edge_order(const void *pa, const void *pb)
{
	const mlod_skelgraph_edge *a = pa, *b = pb;
	if (a->length != b->length)
		return a->length < b->length ? -1 : 1;
	int da = sort_info[a->a].depth, db = sort_info[b->a].depth;
	if (da != db)
		return da > db ? -1 : 1; /* deeper ancestor first */
	if (a->b != b->b)
		return a->b < b->b ? -1 : 1;
	return (a->a > b->a) - (a->a < b->a);
}

mlod_result mlod_skelgraph_build(const mlod_skeleton *s, const mlod_joint_info *info,
                                 mlod_skelgraph *out, mlod_error *err)
{
	int n = s->joint_count;
	memset(out, 0, sizeof *out);
	if (n <= 0)
		return mlod_fail(err, MLOD_ERR_PARSE, "the skeleton has no joints");

	/* Bone lengths from the rest pose in world space. */
	mlod_trs *local = malloc(sizeof *local * (size_t)n);
	mlod_mat4 *world = malloc(sizeof *world * (size_t)n);
	float *bone = malloc(sizeof(float) * (size_t)n);
	int *chain_depth = malloc(sizeof(int) * (size_t)n);
	int *stack = malloc(sizeof(int) * (size_t)n);
	int *first_child = malloc(sizeof(int) * (size_t)n), *next_sibling = malloc(sizeof(int) * (size_t)n);
	out->chain_joints = malloc(sizeof(int) * 2 * (size_t)n);
	out->chain_start = malloc(sizeof(int) * ((size_t)n + 1));
	out->joint_parent = malloc(sizeof(int) * (size_t)n);
	mlod_result r = MLOD_OK;
	if (!out->joint_parent || !local || !world || !bone || !chain_depth || !stack || !first_child || !next_sibling || !out->chain_joints ||
	    !out->chain_start) {
		r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory building the skeletal graph");
		goto done;
	}
	mlod_pose_rest(s, local);
	mlod_pose_world(s, local, world);
	for (int j = n - 1; j >= 0; j--) {
		first_child[j] = -1;
		next_sibling[j] = -1;
	}
	for (int j = n - 1; j >= 0; j--) {
		int p = s->joints[j].parent;
		out->joint_parent[j] = p;
		bone[j] = 0.0f;
		if (p >= 0) {
			mlod_v3 a = {world[p].m[12], world[p].m[13], world[p].m[14]};
			mlod_v3 b = {world[j].m[12], world[j].m[13], world[j].m[14]};
			bone[j] = mlod_v3_length(mlod_v3_sub(b, a));
			next_sibling[j] = first_child[p];
			first_child[p] = j;
		}
	}

	/* Chains: one per (non-minor joint, child), walked depth first so each
	 * chain lists parents before children. chain_depth[j] counts j's
	 * ancestors inside its chain, which is its number of closure edges. */
	size_t edges = 0;
	int count = 0, used = 0;
	for (int t = 0; t < n; t++) {
		if (is_minor(info, t))
			continue;
		for (int c = first_child[t]; c >= 0; c = next_sibling[c]) {
			out->chain_start[count] = used;
			out->chain_joints[used++] = t;
			int top = 0;
			stack[top++] = c;
			chain_depth[c] = 1;
			while (top > 0) {
				int j = stack[--top];
				out->chain_joints[used++] = j;
				edges += (size_t)chain_depth[j];
				if (!is_minor(info, j))
					continue; /* a non-minor joint ends the chain */
				for (int k = first_child[j]; k >= 0; k = next_sibling[k]) {
					chain_depth[k] = chain_depth[j] + 1;
					stack[top++] = k;
				}
			}
			count++;
			if (edges > MAX_CLOSURE_EDGES)
				break;
		}
		if (edges > MAX_CLOSURE_EDGES)
			break;
	}
	out->chain_start[count] = used;
	out->chain_count = count;
	out->joint_count = n;
	if (edges > MAX_CLOSURE_EDGES) {
		r = mlod_fail(err, MLOD_ERR_LIMIT, "the skeletal graph would have %zu closure edges (limit %d)",
		              edges, MAX_CLOSURE_EDGES);
		goto done;
	}
	out->edges = malloc(sizeof *out->edges * (edges ? edges : 1));
	if (!out->edges) {
		r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory building the skeletal graph");
		goto done;
	}
	for (int k = 0; k < count; k++) {
		int t = out->chain_joints[out->chain_start[k]];
		for (int i = out->chain_start[k] + 1; i < out->chain_start[k + 1]; i++) {
			int j = out->chain_joints[i];
			float length = 0.0f;
			for (int a = j; a != t; a = s->joints[a].parent) {
				length += bone[a];
				mlod_skelgraph_edge e = {s->joints[a].parent, j, length};
				out->edges[out->edge_count++] = e;
			}
		}
	}
	sort_info = info;
	qsort(out->edges, (size_t)out->edge_count, sizeof *out->edges, edge_order);
	sort_info = NULL;
done:
	free(local);
	free(world);
	free(bone);
	free(chain_depth);
	free(stack);
	free(first_child);
	free(next_sibling);
	if (r != MLOD_OK)
		mlod_skelgraph_free(out);
	return r;
}

static int find(int *uf, int x)
{
	while (uf[x] != x) {
		uf[x] = uf[uf[x]];
		x = uf[x];
	}
	return x;
}

/* The minimum spanning tree of the joints with out->kept set. */
static mlod_result extract(const mlod_skelgraph *g, mlod_skel_level *out, mlod_error *err)
{
	int n = g->joint_count;
	out->parent = malloc(sizeof(int) * (size_t)n);
	out->remap = malloc(sizeof(int) * (size_t)n);
	int *uf = malloc(sizeof(int) * (size_t)n);
	if (!out->parent || !out->remap || !uf) {
		free(uf);
		mlod_skel_level_free(out);
		return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory extracting a skeleton level");
	}
	out->kept_count = 0;
	for (int j = 0; j < n; j++) {
		out->kept_count += out->kept[j];
		out->parent[j] = -1;
		uf[j] = j;
	}
	/* Kruskal over the closure edges between enabled joints. Each edge runs
	 * from an ancestor to a descendant, so the chosen edge of a joint names
	 * its parent in the level. */
	for (int e = 0; e < g->edge_count; e++) {
		const mlod_skelgraph_edge *edge = &g->edges[e];
		if (!out->kept[edge->a] || !out->kept[edge->b])
			continue;
		int ra = find(uf, edge->a), rb = find(uf, edge->b);
		if (ra == rb)
			continue;
		uf[rb] = ra;
		out->parent[edge->b] = edge->a;
	}
	free(uf);
	/* Every kept joint but a root must have found its parent: the chains
	 * connect the whole skeleton through non-minor joints. */
	for (int j = 0; j < n; j++) {
		if (out->kept[j] && g->joint_parent[j] >= 0 && out->parent[j] < 0) {
			mlod_skel_level_free(out);
			return mlod_fail(err, MLOD_ERR_PARSE, "joint %d is not connected to a root in the skeletal graph", j);
		}
	}
	/* Stand-ins: a removed joint maps to its nearest kept ancestor, which
	 * has a smaller index and is already resolved. Roots are never minor. */
	for (int j = 0; j < n; j++)
		out->remap[j] = out->kept[j] ? j : out->remap[g->joint_parent[j]];
	return MLOD_OK;
}

static mlod_result level_init(const mlod_skelgraph *g, mlod_skel_level *out, mlod_error *err)
{
	memset(out, 0, sizeof *out);
	out->joint_count = g->joint_count;
	out->kept = calloc((size_t)(g->joint_count > 0 ? g->joint_count : 1), 1);
	if (!out->kept)
		return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory extracting a skeleton level");
	return MLOD_OK;
}

mlod_result mlod_skelgraph_extract(const mlod_skelgraph *g, const mlod_joint_info *info,
                                   double threshold, mlod_skel_level *out, mlod_error *err)
{
	mlod_result r = level_init(g, out, err);
	if (r != MLOD_OK)
		return r;
	out->threshold = threshold;
	for (int j = 0; j < g->joint_count; j++)
		out->kept[j] = !is_minor(info, j) || info[j].energy >= threshold;
	return extract(g, out, err);
}

mlod_result mlod_skelgraph_extract_first(const mlod_skelgraph *g, const mlod_joint_info *info,
                                         const int *order, int removed, mlod_skel_level *out,
                                         mlod_error *err)
{
	mlod_result r = level_init(g, out, err);
	if (r != MLOD_OK)
		return r;
	memset(out->kept, 1, (size_t)g->joint_count);
	for (int i = 0; i < removed; i++) {
		int j = order[i];
		if (j < 0 || j >= g->joint_count || !is_minor(info, j)) {
			mlod_skel_level_free(out);
			return mlod_fail(err, MLOD_ERR_INVALID_ARG, "removal order entry %d (joint %d) is not a minor joint", i, j);
		}
		out->kept[j] = 0;
		out->threshold = info[j].energy;
	}
	return extract(g, out, err);
}

/* Sort key of the removal order. */
static int removal_order_cmp(const void *pa, const void *pb)
{
	int a = *(const int *)pa, b = *(const int *)pb;
	if (sort_info[a].energy != sort_info[b].energy)
		return sort_info[a].energy < sort_info[b].energy ? -1 : 1;
	if (sort_info[a].depth != sort_info[b].depth)
		return sort_info[a].depth > sort_info[b].depth ? -1 : 1;
	return (a > b) - (a < b);
}

int mlod_skel_removal_order(const mlod_skeleton *s, const mlod_joint_info *info, int *order)
{
	int n = 0;
	for (int j = 0; j < s->joint_count; j++)
		if (is_minor(info, j))
			order[n++] = j;
	sort_info = info;
	qsort(order, (size_t)n, sizeof *order, removal_order_cmp);
	sort_info = NULL;
	return n;
}
