/*
 * skellevels.c: the skeleton level policy (mlod_skeleton.h): levels at given
 * energy thresholds or joint fractions, and the default chain (13%, 26%
 * and 39% of the joints removed in the paper's order, within an error
 * bound, the last found by bisection), each level applied to the
 * character and measured.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "skeleton/mlod_skeleton.h"

mlod_result mlod_skel_levels_init(mlod_skel_levels *L, const mlod_character *c, const mlod_joint_info *info,
                                  mlod_error *err)
{
	memset(L, 0, sizeof *L);
	L->c = c;
	L->info = info;
	mlod_result r = mlod_skelgraph_build(&c->skeleton, info, &L->graph, err);
	if (r != MLOD_OK)
		return r;
	L->height = mlod_skeleton_height(&c->skeleton);
	L->order = malloc(sizeof(int) * ((size_t)c->skeleton.joint_count + 1));
	if (!L->order) {
		mlod_skelgraph_free(&L->graph);
		return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
	}
	L->minor_count = mlod_skel_removal_order(&c->skeleton, info, L->order);
	L->has_mesh = c->instance_count > 0;
	L->cache = L->has_mesh ? mlod_skel_pose_cache_new() : NULL; /* NULL only costs time */
	return MLOD_OK;
}

void mlod_skel_built_free(mlod_skel_built *b)
{
	mlod_skel_level_free(&b->skel);
	mlod_character_free(&b->c);
	memset(b, 0, sizeof *b);
}

void mlod_skel_levels_free(mlod_skel_levels *L)
{
	for (int k = 0; k < L->count; k++)
		mlod_skel_built_free(&L->levels[k]);
	mlod_skelgraph_free(&L->graph);
	mlod_skel_pose_cache_free(L->cache);
	free(L->order);
	memset(L, 0, sizeof *L);
}

static mlod_result measure(const mlod_skel_levels *L, mlod_skel_built *b, mlod_error *err)
{
	const mlod_character *c = L->c;
	/* a_to_b: the renumbering of kept joints. */
	int *newidx = malloc(sizeof(int) * ((size_t)c->skeleton.joint_count + 1));
	if (!newidx)
		return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
	for (int j = 0, k = 0; j < c->skeleton.joint_count; j++)
		newidx[j] = b->skel.kept[j] ? k++ : -1;
	mlod_result r = mlod_joint_deviation(c, &b->c, b->skel.remap, newidx, MLOD_SKEL_SAMPLES, &b->joint, err);
	free(newidx);
	if (r != MLOD_OK)
		return r;
	b->bound_error = 100.0 * b->joint.max / L->height;
	if (L->has_mesh) {
		if ((r = mlod_skel_vertex_deviation(c, &b->c, MLOD_SKEL_SAMPLES, L->cache, &b->vertex, err)) != MLOD_OK)
			return r;
		b->has_mesh_error = 1;
		b->bound_error = b->vertex.max * b->vertex.scale / L->height;
	}
	return MLOD_OK;
}

mlod_result mlod_skel_levels_make(const mlod_skel_levels *L, double threshold, int removed, mlod_skel_built *out,
                                  mlod_error *err)
{
	mlod_result r;
	memset(out, 0, sizeof *out);
	if (threshold >= 0.0)
		r = mlod_skelgraph_extract(&L->graph, L->info, threshold, &out->skel, err);
	else
		r = mlod_skelgraph_extract_first(&L->graph, L->info, L->order,
		                                 removed < L->minor_count ? removed : L->minor_count, &out->skel, err);
	if (r == MLOD_OK)
		r = mlod_skel_level_apply(L->c, &out->skel, &out->c, &out->stats, err);
	if (r == MLOD_OK)
		r = measure(L, out, err);
	if (r != MLOD_OK)
		mlod_skel_built_free(out);
	return r;
}

/* Levels are nested: finest (most joints) first. */
static void sort_levels(mlod_skel_levels *L)
{
	for (int a = 1; a < L->count; a++)
		for (int b = a; b > 0 && L->levels[b].skel.kept_count > L->levels[b - 1].skel.kept_count; b--) {
			mlod_skel_built t = L->levels[b];
			L->levels[b] = L->levels[b - 1];
			L->levels[b - 1] = t;
		}
}

static mlod_result add(mlod_skel_levels *L, double threshold, int removed, mlod_error *err)
{
	if (L->count >= MLOD_SKEL_MAX_LEVELS)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "at most %d skeleton levels", MLOD_SKEL_MAX_LEVELS);
	mlod_result r = mlod_skel_levels_make(L, threshold, removed, &L->levels[L->count], err);
	if (r == MLOD_OK)
		L->count++;
	return r;
}

mlod_result mlod_skel_levels_thresholds(mlod_skel_levels *L, const double *thresholds, int n, mlod_error *err)
{
	for (int k = 0; k < n; k++) {
		mlod_result r = add(L, thresholds[k], 0, err);
		if (r != MLOD_OK)
			return r;
	}
	sort_levels(L);
	return MLOD_OK;
}

mlod_result mlod_skel_levels_fractions(mlod_skel_levels *L, const double *kept, int n, mlod_error *err)
{
	int joints = L->c->skeleton.joint_count;
	for (int k = 0; k < n; k++) {
		mlod_result r = add(L, -1.0, (int)lround((1.0 - kept[k]) * joints), err);
		if (r != MLOD_OK)
			return r;
	}
	sort_levels(L);
	return MLOD_OK;
}

/* The default chain through mlod_level_search_run: the parameter is the
 * number of joints removed. */
struct chain {
	mlod_skel_levels *L;
	int kept; /* joints removed by the last level kept */
};

struct made {
	mlod_skel_built b;
	int removed;
};

static mlod_result chain_make(void *ctx, double x, int in_chain, void **level, double *error, mlod_error *err)
{
	struct chain *ch = ctx;
	int removed = (int)x;
	if (in_chain && removed <= ch->kept)
		return (mlod_result)1;
	struct made *m = malloc(sizeof *m);
	if (!m)
		return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
	mlod_result r = mlod_skel_levels_make(ch->L, -1.0, removed, &m->b, err);
	if (r != MLOD_OK) {
		free(m);
		return r;
	}
	m->removed = removed;
	*error = m->b.bound_error;
	*level = m;
	return MLOD_OK;
}

static int chain_keep(void *ctx, void *level)
{
	struct chain *ch = ctx;
	struct made *m = level;
	ch->kept = m->removed;
	ch->L->levels[ch->L->count++] = m->b;
	free(m);
	return 1;
}

static void chain_drop(void *ctx, void *level)
{
	struct made *m = level;
	(void)ctx;
	mlod_skel_built_free(&m->b);
	free(m);
}

mlod_result mlod_skel_levels_default(mlod_skel_levels *L, double max_error, mlod_error *err)
{
	static const double fractions[] = {MLOD_SKEL_REMOVED_DEFAULT};
	enum { N = sizeof fractions / sizeof *fractions };
	double removed[N];
	int n = L->c->skeleton.joint_count;
	for (int i = 0; i < N; i++) {
		int r = (int)lround(fractions[i] * n);
		removed[i] = r > L->minor_count ? L->minor_count : r;
	}
	struct chain ch = {L, 0};
	mlod_level_search s = {removed, N, 0.0, 1, 0, max_error, &ch, chain_make, chain_keep, chain_drop};
	mlod_result r = mlod_level_search_run(&s, err);
	sort_levels(L);
	return r;
}

void mlod_skel_levels_records(const mlod_skel_levels *L, mlod_skel_level_record *out)
{
	for (int k = 0; k < L->count; k++) {
		const mlod_skel_built *b = &L->levels[k];
		out[k] = (mlod_skel_level_record){&b->skel, &b->c, b->vertex, b->joint, L->height};
		if (!b->has_mesh_error)
			out[k].vertex.scale = 0.0;
	}
}
