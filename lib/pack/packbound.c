/*
 * packbound.c: the mesh levels: the input's (mlod-bgm's) bound to
 * skeleton levels (issue 11), or computed (packwrite_internal.h).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pack/packwrite_internal.h"

/* ------------------------------------------------------------------ */
/* Mesh                                                                */
/* ------------------------------------------------------------------ */
/* ------------------------------------------------------------------ */
/* Input mesh levels bound to skeleton levels (issue 11)               */
/* ------------------------------------------------------------------ */

/* The input's mesh level k (0-based) of instance i and its skin: *mesh
 * the input character's mesh (NULL: the instance has no level node
 * there), *skin the input skin of the level node (-1: none). */
static mlod_result input_level(struct ctx *x, int k, int i, const mlod_mesh **mesh, int *skin)
{
	int gm = -1, gs = -1;
	*mesh = NULL;
	*skin = -1;
	if (!x->level_node[k] || x->level_node[k][i] < 0)
		return MLOD_OK;
	mlod_result r = mlod_gltf_node_refs(x->doc, x->level_node[k][i], &gm, &gs, x->err);
	if (r != MLOD_OK)
		return r;
	int mi = pack_mesh_of_gltf(x->in, gm);
	if (mi < 0)
		return mlod_fail(x->err, MLOD_ERR_PARSE, "mesh level %d of node %d: its mesh %d was not read", k + 1,
		                 x->v.instances[i].node, gm);
	*mesh = &x->in->meshes[mi];
	*skin = pack_skin_of_gltf(&x->in->skeleton, gs);
	return MLOD_OK;
}

/* Whether the input's mesh level k of skinned instance i is skinned with
 * another skin than the instance's: a skeleton level's, on which
 * mlod-bgm after mlod-skelgraph (or mlod-pack -x) wrote it, moving each
 * influence of a joint that level removes to the joint's stand-in. Its
 * weights on the full skin are lost. */
static mlod_result level_bound(struct ctx *x, int k, int i, int *bound)
{
	const mlod_mesh *m;
	int ls;
	*bound = 0;
	mlod_result r = input_level(x, k, i, &m, &ls);
	if (r == MLOD_OK && m && x->v.instances[i].skin >= 0 && ls >= 0)
		*bound = x->view_skin[ls] != x->v.instances[i].skin;
	return r;
}

static int same_floats(const float *a, const float *b, long n)
{
	return (!a && !b) || (a && b && memcmp(a, b, sizeof *a * (size_t)n) == 0);
}

/* Whether the levels of L have the input's triangles: each level node's
 * primitives the same positions and indices, and no simplified primitive
 * where the input has no level node. */
static mlod_result same_triangles(struct ctx *x, const mlod_mesh_levels *L, int *same)
{
	const mlod_character *c = &x->v;
	*same = L->count == x->mesh_count;
	for (int k = 0; *same && k < L->count; k++)
		for (int i = 0; *same && i < c->instance_count; i++) {
			const mlod_mesh *im, *lm = &L->levels[k].meshes[i];
			int ls;
			mlod_result r = input_level(x, k, i, &im, &ls);
			if (r != MLOD_OK)
				return r;
			if (!im) {
				for (int p = 0; *same && p < lm->primitive_count; p++)
					*same = !L->levels[k].owned[i][p];
				continue;
			}
			*same = im->primitive_count == lm->primitive_count;
			for (int p = 0; *same && p < lm->primitive_count; p++) {
				const mlod_primitive *a = &im->primitives[p], *b = &lm->primitives[p];
				*same = a->mode == b->mode && a->vertex_count == b->vertex_count &&
				        a->index_count == b->index_count &&
				        same_floats(a->positions, b->positions, 3L * a->vertex_count) &&
				        ((!a->indices && !b->indices) ||
				         (a->indices && b->indices &&
				          memcmp(a->indices, b->indices, sizeof *a->indices * (size_t)a->index_count) == 0));
			}
		}
	return MLOD_OK;
}

/* The input's levels rebuilt on the full skin from level 0: mlod-bgm's
 * levels do not depend on the skeleton levels (it binds them to those
 * only after measuring them), so the same ratios (the stage record's)
 * and options (mlod-pack's own: the record holds no other) give the
 * same triangles, with their weights on the full skin and their posed
 * errors. *rebuilt 0 (and nothing kept) when the record has no ratio for
 * every level (mlod-pack -x writes none), the rebuild gives other
 * triangles (mlod-bgm ran with options the record does not hold) or
 * fails but for memory. */
static mlod_result rebuild_levels(struct ctx *x, int *rebuilt)
{
	double ratios[MLOD_MESH_MAX_LEVELS];
	int n = x->mesh_count, same = 0;
	*rebuilt = 0;
	if (x->rec.mesh_level_count != n)
		return MLOD_OK;
	for (int k = 0; k < n; k++) {
		const mlod_record_mesh_level *l = &x->rec.mesh_levels[k];
		if (l->level != k + 1 || l->missing_ratio || !(l->ratio > 0.0 && l->ratio < 1.0) ||
		    (k > 0 && !(l->ratio < ratios[k - 1])))
			return MLOD_OK;
		ratios[k] = l->ratio;
	}
	mlod_bgm_options bo = x->opt->bgm;
	mlod_mesh_budget budget = x->opt->budget;
	mlod_mesh_resolve(&bo, &budget);
	mlod_result r = mlod_mesh_levels_init(&x->ML, &x->v, &bo, budget, ratios[n - 1], x->err);
	x->has_ML = 1;
	if (r == MLOD_OK)
		r = mlod_mesh_levels_by_ratio(&x->ML, ratios, n, x->err);
	if (r == MLOD_OK)
		r = same_triangles(x, &x->ML, &same);
	if (r != MLOD_OK || !same) {
		mlod_mesh_levels_free(&x->ML);
		x->has_ML = 0;
		/* levels that cannot be made again are measured instead */
		return r == MLOD_ERR_NOMEM ? r : MLOD_OK;
	}
	for (int k = 0; k < n; k++) {
		x->level_mesh[k] = x->ML.levels[k].meshes;
		x->mesh_error[k] = (float)(x->ML.levels[k].error.max * x->diag / 100.0);
	}
	*rebuilt = 1;
	return MLOD_OK;
}

/* The character at input mesh level k as the pack stores it: each
 * instance's level mesh (level 0's where it has none), the weights of a
 * level bound to a skeleton level's skin mapped to the full skin as
 * mesh_parts maps them (level_joint_map). view->instances must hold the
 * instances, meshes one mesh per instance; the primitives of bound
 * levels go to prims from *nprim on and their joint arrays to own from
 * *nown on (the caller's to free). */
static mlod_result stored_level(struct ctx *x, int k, mlod_character *view, mlod_mesh *meshes,
                                mlod_primitive *prims, int *nprim, uint16_t **own, int *nown)
{
	const mlod_character *c = &x->v;
	mlod_instance *inst = view->instances;
	*view = *c;
	view->instances = inst;
	view->meshes = meshes;
	view->mesh_count = c->instance_count;
	for (int i = 0; i < c->instance_count; i++) {
		const mlod_instance *in = &c->instances[i];
		const mlod_mesh *m;
		int ls;
		mlod_result r = input_level(x, k, i, &m, &ls);
		if (r != MLOD_OK)
			return r;
		meshes[i] = m ? *m : c->meshes[in->mesh];
		inst[i] = *in;
		inst[i].mesh = i;
		if (!m || in->skin < 0 || ls < 0 || x->view_skin[ls] == in->skin)
			continue;
		const mlod_skin *lsk = &x->in->skeleton.skins[ls];
		int *map = pack_level_joint_map(&c->skeleton, lsk, &c->skeleton.skins[in->skin]);
		if (!map)
			return mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
		mlod_primitive *q = prims + *nprim;
		*nprim += m->primitive_count;
		for (int p = 0; p < m->primitive_count; p++) {
			q[p] = m->primitives[p];
			for (int s = 0; s < q[p].weight_set_count && s < MLOD_MAX_SETS; s++) {
				if (!q[p].joints[s])
					continue;
				uint16_t *j = malloc(sizeof *j * 4 * ((size_t)q[p].vertex_count + 1));
				if (!j) {
					free(map);
					return mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
				}
				own[(*nown)++] = j;
				for (long v = 0; v < 4L * q[p].vertex_count; v++) {
					int a = m->primitives[p].joints[s][v];
					j[v] = (uint16_t)(a < lsk->joint_count ? map[a] : 0);
				}
				q[p].joints[s] = j;
			}
		}
		meshes[i].primitives = q;
		free(map);
	}
	return MLOD_OK;
}

/* The input's levels that are bound to skeleton levels measured again as
 * the pack stores them: posed under the full skeleton with their stored
 * weights, against level 0, at mlod-bgm's measuring poses (rest pose, up
 * to 4 times per clip, 8 random poses: meshlevels.c make_poses). Each
 * such level's error becomes the larger of that and the input's. */
static mlod_result measure_bound_levels(struct ctx *x, const int *bound)
{
	const mlod_character *c = &x->v;
	int n = x->mesh_count, nprim = 0, nown = 0, count = 0;
	for (int i = 0; i < c->instance_count; i++)
		for (int k = 0; k < n; k++) {
			const mlod_mesh *m;
			int ls;
			mlod_result r = input_level(x, k, i, &m, &ls);
			if (r != MLOD_OK)
				return r;
			nprim += m ? m->primitive_count : 0;
		}
	mlod_character *views = calloc((size_t)n + 1, sizeof *views);
	const mlod_character **lv = calloc((size_t)n + 1, sizeof *lv);
	mlod_mesh *meshes = calloc((size_t)n * (size_t)c->instance_count + 1, sizeof *meshes);
	mlod_instance *inst = calloc((size_t)n * (size_t)c->instance_count + 1, sizeof *inst);
	mlod_primitive *prims = calloc((size_t)nprim + 1, sizeof *prims);
	uint16_t **own = calloc((size_t)nprim * MLOD_MAX_SETS + 1, sizeof *own);
	mlod_deviation *dev = calloc((size_t)n + 1, sizeof *dev);
	int *which = calloc((size_t)n + 1, sizeof *which);
	mlod_pose_set poses = {0};
	mlod_result r = MLOD_OK;
	if (!views || !lv || !meshes || !inst || !prims || !own || !dev || !which)
		r = mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
	for (int k = 0, used = 0; r == MLOD_OK && k < n; k++) {
		if (!bound[k])
			continue;
		views[count].instances = inst + (size_t)count * (size_t)c->instance_count;
		r = stored_level(x, k, &views[count], meshes + (size_t)count * (size_t)c->instance_count, prims, &used, own,
		                 &nown);
		lv[count] = &views[count];
		which[count++] = k;
	}
	if (r == MLOD_OK && count > 0) {
		int clips = c->clip_count > 0 ? c->clip_count : 1, per = 16 / clips;
		mlod_bgm_options bo = x->opt->bgm;
		mlod_mesh_budget budget = x->opt->budget;
		mlod_mesh_resolve(&bo, &budget);
		per = per < 2 ? 2 : per > 4 ? 4 : per;
		r = mlod_pose_set_make(c, 1, per, MLOD_MESH_RANDOM_POSES, MLOD_MESH_MEASURE_SEED, MLOD_MESH_RANDOM_ANGLE,
		                       &poses, x->err);
		poses.threads = bo.threads;
		if (r == MLOD_OK) {
			mlod_pose_set_bound_mean(&poses, 1);
			r = mlod_posed_errors(c, lv, count, &poses, dev, x->err);
		}
	}
	for (int q = 0; r == MLOD_OK && q < count; q++) {
		float e = (float)(dev[q].max * x->diag / 100.0);
		if (e > x->mesh_error[which[q]])
			x->mesh_error[which[q]] = e;
	}
	mlod_pose_set_free(&poses);
	for (int i = 0; i < nown; i++)
		free(own[i]);
	free(views);
	free(lv);
	free(meshes);
	free(inst);
	free(prims);
	free(own);
	free(dev);
	free(which);
	return r;
}

/* Input mesh levels bound to skeleton levels lose their weights on the
 * joints those levels remove, and the runtime shows a mesh level at any
 * skeleton level: at a finer one than the level's own, the removed joints
 * no longer move it, and its error as measured before the binding does
 * not hold (tubeman after mlod-skelgraph | mlod-bgm: mesh level 2 0.2323
 * through the runtime at one clip time, stated 0.174). Such levels are
 * rebuilt on the full skin when that gives the input's triangles
 * (rebuild_levels), else measured again as stored (measure_bound_levels),
 * with a warning either way. */
static mlod_result bound_levels(struct ctx *x)
{
	const mlod_character *c = &x->v;
	int bound[MLOD_MESH_MAX_LEVELS] = {0}, count = 0, rebuilt = 0;
	char list[96] = "";
	for (int k = 0; k < x->mesh_count; k++) {
		for (int i = 0; i < c->instance_count && !bound[k]; i++) {
			mlod_result r = level_bound(x, k, i, &bound[k]);
			if (r != MLOD_OK)
				return r;
		}
		if (bound[k]) {
			size_t n = strlen(list);
			snprintf(list + n, sizeof list - n, "%s%d", count++ ? ", " : "", k + 1);
		}
	}
	if (!count)
		return MLOD_OK;
	mlod_result r = rebuild_levels(x, &rebuilt);
	if (r == MLOD_OK && !rebuilt)
		r = measure_bound_levels(x, bound);
	if (r != MLOD_OK)
		return r;
	int ratios = x->rec.mesh_level_count == x->mesh_count;
	for (int k = 0; ratios && k < x->mesh_count; k++)
		ratios = !x->rec.mesh_levels[k].missing_ratio;
	char text[800];
	snprintf(text, sizeof text,
	         "mesh level%s %s of the input %s on skeleton levels' skins (the weights of the joints those levels "
	         "remove moved to their stand-ins): %s",
	         count > 1 ? "s" : "", list, count > 1 ? "are" : "is",
	         rebuilt ? "the mesh levels are made again on the full skin from level 0 with the stage record's "
	                   "ratios (the same triangles)"
	         : ratios ? "made again with the stage record's ratios and these mesh options they have other triangles "
	                    "(mlod-bgm's options differ: the same -p and --influence-budget may give them): "
	                    "their posed error measured again under the full skeleton with the weights as stored"
	                  : "the stage record has no ratios to make them again with: their posed error measured "
	                    "again under the full skeleton with the weights as stored");
	pack_warn(x, text);
	return MLOD_OK;
}

static int ratio_desc(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return (x < y) - (x > y);
}

mlod_result pack_mesh_levels(struct ctx *x)
{
	const mlod_character *c = &x->v;
	mlod_result r = MLOD_OK;
	if (x->opt->no_mesh_levels || mlod_mesh_triangle_primitives(c) == 0)
		return MLOD_OK;
	/* The input's levels: MSFT_lod level nodes with a mesh level record. */
	int max = 0;
	int *nodes = malloc(sizeof(int) * MLOD_MESH_MAX_LEVELS * ((size_t)c->instance_count + 1));
	if (!nodes)
		return mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
	for (size_t i = 0; i < MLOD_MESH_MAX_LEVELS * ((size_t)c->instance_count + 1); i++)
		nodes[i] = -1;
	double node_error[MLOD_MESH_MAX_LEVELS] = {0}, node_pack_error[MLOD_MESH_MAX_LEVELS];
	int no_error = 0;
	for (int k = 0; k < MLOD_MESH_MAX_LEVELS; k++)
		node_pack_error[k] = -1.0;
	for (int i = 0; r == MLOD_OK && i < c->instance_count; i++) {
		int m = 0;
		r = pack_level_nodes(x, c->instances[i].node, nodes + MLOD_MESH_MAX_LEVELS * i, &m, node_error, node_pack_error,
		                     &no_error);
		max = m > max ? m : max;
	}
	if (r == MLOD_OK && max > 0) {
		x->st->mesh.from_input = 1;
		for (int k = 0; k < max; k++) {
			x->level_node[k] = malloc(sizeof(int) * ((size_t)c->instance_count + 1));
			if (!x->level_node[k]) {
				r = mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
				break;
			}
			x->mesh_count = k + 1;
			for (int i = 0; i < c->instance_count; i++)
				x->level_node[k][i] = nodes[MLOD_MESH_MAX_LEVELS * i + k];
			/* The scene's record, else the largest of the level nodes';
			 * the pack error of a record from mlod-pack -x before the
			 * measured error in percent. */
			int scene = 0;
			x->mesh_error[k] = (float)(node_pack_error[k] >= 0.0 ? node_pack_error[k] : node_error[k] * x->diag / 100.0);
			for (int q = 0; q < x->rec.mesh_level_count; q++) {
				const mlod_record_mesh_level *l = &x->rec.mesh_levels[q];
				if (l->level != k + 1 || (l->missing_error && !l->has_pack_error))
					continue;
				x->mesh_error[k] = (float)(l->has_pack_error ? l->pack_error : l->error.max * x->diag / 100.0);
				scene = 1;
			}
			if (!scene && no_error) {
				r = mlod_fail(x->err, MLOD_ERR_PARSE,
				              "mesh level %d: no error (pack_error or error_percent) in the level nodes' "
				              "or the scene's extras.mlod",
				              k + 1);
				break;
			}
		}
		free(nodes);
		return r == MLOD_OK ? bound_levels(x) : r;
	}
	free(nodes);
	if (r != MLOD_OK)
		return r;
	/* An empty list: an unpacked pack that had level 0 alone. */
	if (x->rec.has_mesh_levels && x->rec.mesh_level_count == 0 && x->rec.has_pack) {
		x->st->mesh.from_input = 1;
		return MLOD_OK;
	}
	/* Computed, as mlod-bgm does with the same options. */
	double ratios[MLOD_MESH_MAX_LEVELS];
	int n = x->opt->ratio_count;
	memcpy(ratios, x->opt->ratios, sizeof ratios);
	qsort(ratios, (size_t)n, sizeof *ratios, ratio_desc);
	mlod_bgm_options bo = x->opt->bgm;
	mlod_mesh_budget budget = x->opt->budget;
	mlod_mesh_resolve(&bo, &budget);
	int by_error = x->opt->mesh_max_error >= 0.0;
	r = mlod_mesh_levels_init(&x->ML, c, &bo, budget, by_error || n == 0 ? 0.0 : ratios[n - 1], x->err);
	x->has_ML = 1;
	if (r == MLOD_OK)
		r = by_error ? mlod_mesh_levels_by_error(&x->ML, x->opt->mesh_max_error, x->err)
		             : mlod_mesh_levels_by_ratio(&x->ML, ratios, n, x->err);
	if (r != MLOD_OK)
		return r;
	if (by_error && x->ML.count == 0)
		pack_note(x, "no mesh level within the mesh's max error");
	for (int k = 0; k < x->ML.count; k++) {
		x->level_mesh[k] = x->ML.levels[k].meshes;
		x->mesh_error[k] = (float)(x->ML.levels[k].error.max * x->diag / 100.0);
	}
	x->mesh_count = x->ML.count;
	return MLOD_OK;
}
