/*
 * influence.c: fewer joint influences on the mesh levels (beyond the
 * paper), so that far instances skin fewer. A skinned vertex of a level
 * loses its smallest influence while the vertex, posed by linear blend
 * skinning at every training pose, stays within a budget of where its own
 * influences put it (morph offsets not applied, as the posed error does
 * not apply them either): the budget is a fraction
 * (mlod_bgm_options.influence_budget) of the level's mean posed error,
 * measured before. The dropped weight goes where it moves the vertex
 * least: spread over the others in proportion, or all to one of them.
 * Each vertex is decided on its own, so the result is the same at any
 * thread count. Pruned levels are measured again, so their reported
 * errors are those of what is written; a level whose Hausdorff error rose
 * is tried again under a smaller budget, then left as it was.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "meshlevels.h"
#include "bgm.h" /* bgm_seconds */

/* A vertex's nonzero influences of set 0, largest weight first (ties:
 * lower joint first). */
typedef struct infl {
	int n;
	uint16_t j[4];
	float w[4];
} infl;

static void sort_infl(infl *a)
{
	for (int x = 1; x < a->n; x++)
		for (int y = x; y > 0; y--) {
			int swap = a->w[y] > a->w[y - 1] || (a->w[y] == a->w[y - 1] && a->j[y] < a->j[y - 1]);
			if (!swap)
				break;
			uint16_t tj = a->j[y];
			float tw = a->w[y];
			a->j[y] = a->j[y - 1], a->w[y] = a->w[y - 1];
			a->j[y - 1] = tj, a->w[y - 1] = tw;
		}
}

/* Weights summing to 1 in float: the largest takes what the others leave. */
static void settle(infl *a)
{
	sort_infl(a);
	float rest = 0.0f;
	for (int k = a->n - 1; k >= 1; k--)
		rest += a->w[k];
	a->w[0] = 1.0f - rest;
}

/* The largest distance, over the poses, between the vertex with weights
 * a and with the original weights o: q holds the vertex moved by each of
 * o's joints at each pose (q[3 * (P * k + t)]), and a's joints are o's. */
static double displacement(const infl *o, const infl *a, const float *q, int P)
{
	double d = 0.0;
	for (int t = 0; t < P; t++) {
		double e[3] = { 0.0, 0.0, 0.0 };
		for (int k = 0; k < o->n; k++) {
			double w = -(double)o->w[k];
			for (int m = 0; m < a->n; m++)
				if (a->j[m] == o->j[k])
					w += a->w[m];
			const float *p = q + 3 * ((size_t)P * k + t);
			e[0] += w * p[0], e[1] += w * p[1], e[2] += w * p[2];
		}
		double l = sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
		if (l > d)
			d = l;
	}
	return d;
}

/* Prunes vertex v of p (skin matrices mats: P poses of joint_count);
 * returns the influences dropped. */
static int prune_vertex(mlod_primitive *p, int v, const mlod_mat4 *mats, int joint_count, int P, double budget,
                        float *q)
{
	infl o = { 0 };
	for (int k = 0; k < 4; k++) {
		float w = p->weights[0][4 * v + k];
		uint16_t j = p->joints[0][4 * v + k];
		if (w > 0.0f && j < joint_count)
			o.j[o.n] = j, o.w[o.n] = w, o.n++;
		else if (w != 0.0f)
			return 0; /* not ours to judge */
	}
	if (o.n < 2)
		return 0;
	for (int k = 0; k < o.n; k++)
		for (int m = 0; m < k; m++)
			if (o.j[k] == o.j[m])
				return 0; /* a joint twice: left as it is */
	sort_infl(&o);
	const float *pos = p->positions + 3 * (size_t)v;
	mlod_v3 b = { pos[0], pos[1], pos[2] };
	for (int k = 0; k < o.n; k++)
		for (int t = 0; t < P; t++) {
			mlod_v3 r = mlod_mat4_point(&mats[(size_t)t * joint_count + o.j[k]], b);
			float *d = q + 3 * ((size_t)P * k + t);
			d[0] = r.x, d[1] = r.y, d[2] = r.z;
		}
	infl cur = o;
	while (cur.n > 1) {
		/* drop the smallest: spread (m = -1) or given to m */
		infl best = { 0 };
		double best_d = INFINITY;
		for (int m = -1; m < cur.n - 1; m++) {
			infl c = cur;
			float drop = c.w[c.n - 1];
			c.n--;
			if (m < 0) {
				double s = 0.0;
				for (int k = 0; k < c.n; k++)
					s += c.w[k];
				for (int k = 0; k < c.n; k++)
					c.w[k] = (float)(c.w[k] / s);
			} else
				c.w[m] += drop;
			if (c.n == 1)
				c.w[0] = 1.0f;
			settle(&c);
			double d = displacement(&o, &c, q, P);
			if (d < best_d)
				best = c, best_d = d;
		}
		if (!(best_d <= budget))
			break;
		cur = best;
	}
	if (cur.n == o.n)
		return 0;
	for (int k = 0; k < 4; k++) {
		p->joints[0][4 * v + k] = k < cur.n ? cur.j[k] : 0;
		p->weights[0][4 * v + k] = k < cur.n ? cur.w[k] : 0.0f;
	}
	return o.n - cur.n;
}

/* The training poses' skin matrices of every skin: P * joint_count of
 * skin s at mats[s]. */
static mlod_result skin_mats(const mlod_mesh_levels *L, mlod_mat4 ***out, mlod_error *err)
{
	const mlod_skeleton *sk = &L->c->skeleton;
	const int P = L->train.count;
	mlod_mat4 **m = calloc((size_t)sk->skin_count + 1, sizeof *m);
	if (!m)
		return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
	*out = m;
	for (int s = 0; s < sk->skin_count; s++) {
		int jc = sk->skins[s].joint_count;
		if (!(m[s] = malloc(sizeof **m * ((size_t)P * jc + 1))))
			return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
		for (int t = 0; t < P; t++)
			mlod_skin_matrices(&sk->skins[s], L->train.world + (size_t)t * L->train.joint_count,
			                   m[s] + (size_t)t * jc);
	}
	return MLOD_OK;
}

static int prunable(const mlod_mesh_levels *L, const mlod_mesh_level *lv, int i, int p)
{
	const mlod_primitive *pr = &lv->meshes[i].primitives[p];
	return L->c->instances[i].skin >= 0 && lv->owned[i] && lv->owned[i][p] && pr->weight_set_count == 1 &&
	       pr->weights[0] && pr->joints[0];
}

/* Prunes level lv (budget in scene units); returns the influences dropped
 * (and the vertices that lost any in *vertices). */
static long prune_level(const mlod_mesh_levels *L, mlod_mesh_level *lv, mlod_mat4 *const *mats, double budget,
                        float *q, long *vertices)
{
	const mlod_character *c = L->c;
	long dropped = 0;
	for (int i = 0; i < c->instance_count; i++) {
		int s = c->instances[i].skin;
		for (int p = 0; p < lv->meshes[i].primitive_count; p++) {
			mlod_primitive *pr = &lv->meshes[i].primitives[p];
			if (!prunable(L, lv, i, p))
				continue;
			for (int v = 0; v < pr->vertex_count; v++) {
				int d = prune_vertex(pr, v, mats[s], c->skeleton.skins[s].joint_count, L->train.count, budget, q);
				dropped += d;
				*vertices += d > 0;
			}
		}
	}
	return dropped;
}

/* The weights and joints of a level's skinned primitives (those
 * prune_level may change), saved to put back. */
typedef struct saved {
	float *w;
	uint16_t *j;
} saved;

/* put 0: saves lv's weights into sv (allocating); 1: puts them back. */
static mlod_result save_level(const mlod_mesh_levels *L, mlod_mesh_level *lv, saved *sv, int put, mlod_error *err)
{
	size_t n = 0;
	for (int i = 0; i < L->c->instance_count; i++)
		for (int p = 0; p < lv->meshes[i].primitive_count; p++)
			n += prunable(L, lv, i, p) ? 4 * (size_t)lv->meshes[i].primitives[p].vertex_count : 0;
	if (!put) {
		sv->w = malloc(sizeof *sv->w * (n + 1));
		sv->j = malloc(sizeof *sv->j * (n + 1));
		if (!sv->w || !sv->j)
			return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
	}
	size_t at = 0;
	for (int i = 0; i < L->c->instance_count; i++)
		for (int p = 0; p < lv->meshes[i].primitive_count; p++) {
			if (!prunable(L, lv, i, p))
				continue;
			mlod_primitive *pr = &lv->meshes[i].primitives[p];
			size_t m = 4 * (size_t)pr->vertex_count;
			if (put) {
				memcpy(pr->weights[0], sv->w + at, m * sizeof *sv->w);
				memcpy(pr->joints[0], sv->j + at, m * sizeof *sv->j);
			} else {
				memcpy(sv->w + at, pr->weights[0], m * sizeof *sv->w);
				memcpy(sv->j + at, pr->joints[0], m * sizeof *sv->j);
			}
			at += m;
		}
	return MLOD_OK;
}

/* Each level is pruned under the whole budget and measured again; a level
 * whose Hausdorff error (the one its switch distance and the pixel rule
 * use) rose is put back and tried under half the budget, then a quarter
 * (MLOD_INFLUENCE_TRIES budgets), and left as it was after that. */
#define MLOD_INFLUENCE_TRIES 3

mlod_result mlod_mesh_prune_influences_(mlod_mesh_levels *L, int first, mlod_error *err)
{
	if (!(L->opt.influence_budget > 0.0) || first >= L->count || L->train.count <= 0)
		return MLOD_OK;
	const mlod_skeleton *sk = &L->c->skeleton;
	mlod_mat4 **mats = NULL;
	saved sv[MLOD_MESH_MAX_LEVELS];
	memset(sv, 0, sizeof sv);
	mlod_deviation before[MLOD_MESH_MAX_LEVELS], dev[MLOD_MESH_MAX_LEVELS];
	const mlod_character *views[MLOD_MESH_MAX_LEVELS];
	int pending[MLOD_MESH_MAX_LEVELS], changed[MLOD_MESH_MAX_LEVELS];
	long drops[MLOD_MESH_MAX_LEVELS], moved[MLOD_MESH_MAX_LEVELS];
	double used[MLOD_MESH_MAX_LEVELS]; /* the budget a level was pruned under, 0: none */
	float *q = malloc(sizeof *q * 3 * 4 * ((size_t)L->train.count + 1));
	mlod_result r = q ? skin_mats(L, &mats, err) : mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
	for (int k = first; k < L->count; k++) {
		before[k] = L->levels[k].error;
		pending[k] = 1;
		used[k] = 0.0;
		if (r == MLOD_OK)
			r = save_level(L, &L->levels[k], &sv[k], 0, err);
	}
	double f = L->opt.influence_budget;
	for (int t = 0; r == MLOD_OK && t < MLOD_INFLUENCE_TRIES; t++, f /= 2) {
		int n = 0;
		for (int k = first; k < L->count; k++) {
			if (!pending[k])
				continue;
			mlod_mesh_level *lv = &L->levels[k];
			if (t > 0)
				save_level(L, lv, &sv[k], 1, err);
			double budget = f * before[k].mean / 100.0 * before[k].scale;
			moved[k] = 0;
			drops[k] = prune_level(L, lv, mats, budget, q, &moved[k]);
			if (drops[k] == 0) {
				pending[k] = 0; /* nothing within this budget, nor a smaller one */
				continue;
			}
			changed[n] = k;
			views[n++] = &lv->view;
		}
		if (n == 0)
			break;
		/* the levels' errors are those of the pruned meshes */
		double t0 = bgm_seconds();
		r = mlod_posed_errors(L->c, views, n, &L->measure, dev, err);
		L->measure_seconds += bgm_seconds() - t0;
		for (int x = 0; r == MLOD_OK && x < n; x++) {
			int k = changed[x];
			if (dev[x].max > before[k].max)
				continue; /* pending: put back, tried again under less */
			L->levels[k].error = dev[x];
			pending[k] = 0;
			used[k] = f;
		}
	}
	for (int k = first; k < L->count; k++) {
		char text[200];
		if (r == MLOD_OK && pending[k]) {
			save_level(L, &L->levels[k], &sv[k], 1, err);
			L->levels[k].error = before[k];
			snprintf(text, sizeof text, "level %d: influences kept (pruning raised its Hausdorff error)", k + 1);
			mlod_mesh_note_(L, text);
		} else if (r == MLOD_OK && used[k] > 0.0) {
			snprintf(text, sizeof text,
			         "level %d: %ld fewer influences on %ld vertices (budget %.3g%% of the diagonal)", k + 1,
			         drops[k], moved[k], used[k] * before[k].mean);
			mlod_mesh_note_(L, text);
		}
		free(sv[k].w);
		free(sv[k].j);
	}
	for (int s = 0; mats && s < sk->skin_count; s++)
		free(mats[s]);
	free(mats);
	free(q);
	return r;
}
