/*
 * meshlevels.c: the mesh level policy (mlod_mesh.h): the BGM of every triangle
 * primitive of a character, levels by triangle ratio (each primitive's,
 * or the whole character's budget shared by posed cost) or down to a
 * posed error bound, each measured against the full character.
 */
#include <math.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "meshlevels.h"
#include "bgm.h" /* bgm_seconds */

/* One primitive of one instance. */
struct mlod_mesh_part {
	mlod_bgm *bgm;          /* NULL: left as it is */
	int triangles;
	int k;                  /* the level being made: its prefix */
};

mlod_bgm *mlod_mesh_part_bgm_(const mlod_mesh_levels *L, int i, int p)
{
	return L->parts && L->parts[i] ? L->parts[i][p].bgm : NULL;
}

const char *mlod_mesh_cost_name(mlod_mesh_cost c)
{
	return c == MLOD_COST_COMPACTNESS ? "compactness" : "posed";
}

const char *mlod_mesh_op_name(mlod_collapse_op op)
{
	return op == MLOD_OP_TRIANGLE ? "triangle" : op == MLOD_OP_EDGE ? "edge" : op == MLOD_OP_MIXED ? "mixed" : "default";
}

const char *mlod_mesh_budget_name(mlod_mesh_budget b)
{
	return b == MLOD_BUDGET_PRIMITIVE ? "primitive" : "character";
}

const char *mlod_mesh_placement_name(mlod_placement p)
{
	return p == MLOD_PLACE_BARYCENTER ? "barycenter"
	       : p == MLOD_PLACE_VERTEX   ? "vertex"
	       : p == MLOD_PLACE_HYBRID   ? "hybrid"
	                                  : "optimal";
}

int mlod_mesh_placement_parse(const char *s, mlod_placement *p, double *error)
{
	static const char *const names[] = {"barycenter", "optimal", "vertex", "hybrid"};
	for (int i = 0; i < 4; i++)
		if (strcmp(s, names[i]) == 0) {
			*p = (mlod_placement)(MLOD_PLACE_BARYCENTER + i);
			if (*p == MLOD_PLACE_HYBRID)
				*error = 0.0;
			return 0;
		}
	if (strncmp(s, "hybrid=", 7) != 0 || !s[7])
		return -1;
	char *end;
	double pct = strtod(s + 7, &end);
	if (*end || !(pct > 0.0) || !(pct <= 100.0))
		return -1;
	*p = MLOD_PLACE_HYBRID;
	*error = pct;
	return 0;
}

const char *mlod_mesh_eligibility_name(mlod_eligibility e)
{
	return e == MLOD_ELIGIBLE_LITERAL ? "literal" : e == MLOD_ELIGIBLE_BEND ? "bend" : "all";
}

void mlod_mesh_resolve(mlod_bgm_options *opt, mlod_mesh_budget *budget)
{
	mlod_bgm_options_resolve(opt);
	if (budget && *budget == MLOD_BUDGET_DEFAULT) /* measured: see mlod-bgm(1) */
		*budget = opt->cost == MLOD_COST_POSED ? MLOD_BUDGET_CHARACTER : MLOD_BUDGET_PRIMITIVE;
	if (!(opt->tau > 0.0))
		opt->tau = 1.0;
	if (opt->hybrid_error == 0.0) /* a negative or NaN share: mlod_bgm_build refuses it */
		opt->hybrid_error = MLOD_MESH_HYBRID_ERROR;
	if (opt->influence_budget == 0.0)
		opt->influence_budget = MLOD_MESH_INFLUENCE_BUDGET > 0.0 ? MLOD_MESH_INFLUENCE_BUDGET : -1.0;
}

static int primitive_triangles(const mlod_primitive *p)
{
	if (p->mode != 4)
		return 0;
	return (p->index_count > 0 ? p->index_count : p->vertex_count) / 3;
}

int mlod_mesh_has_surface(const mlod_mesh *m)
{
	for (int p = 0; p < m->primitive_count; p++)
		if (primitive_triangles(&m->primitives[p]) > 0 && bgm_has_triangle(&m->primitives[p]))
			return 1;
	return 0;
}

int mlod_mesh_triangle_primitives(const mlod_character *c)
{
	int n = 0;
	for (int i = 0; i < c->instance_count; i++)
		for (int p = 0; p < c->meshes[c->instances[i].mesh].primitive_count; p++) {
			const mlod_primitive *pr = &c->meshes[c->instances[i].mesh].primitives[p];
			n += primitive_triangles(pr) > 0 && bgm_has_triangle(pr);
		}
	return n;
}

static void note(mlod_mesh_levels *L, const char *fmt, ...)
#if defined(__GNUC__)
	__attribute__((format(printf, 2, 3)))
#endif
	;

static void note(mlod_mesh_levels *L, const char *fmt, ...)
{
	char text[sizeof L->notes];
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(text, sizeof text, fmt, ap);
	va_end(ap);
	mlod_mesh_note_(L, text);
}

static mlod_result nomem(mlod_error *err)
{
	return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
}

/* The training and measuring poses. Each clip gives 2 to 8 (training)
 * and 2 to 4 (measuring) frames, fewer per clip the more clips there are;
 * past MLOD_MESH_MAX_POSE_CLIPS clips, that many of them, evenly spaced in
 * file order, give 2 each, so that the poses, which each hold a posed copy
 * of the mesh, stay bounded (100 clips made 209 measuring poses: 839 MB at
 * 50k triangles). */
static mlod_result make_poses(mlod_mesh_levels *L, mlod_error *err)
{
	mlod_character sub = *L->c; /* a view: the same clips, or some of them */
	mlod_clip *picked = NULL;
	if (L->c->clip_count > MLOD_MESH_MAX_POSE_CLIPS) {
		picked = malloc(sizeof *picked * MLOD_MESH_MAX_POSE_CLIPS);
		if (!picked)
			return nomem(err);
		for (int i = 0; i < MLOD_MESH_MAX_POSE_CLIPS; i++)
			picked[i] = L->c->clips[(long)i * L->c->clip_count / MLOD_MESH_MAX_POSE_CLIPS];
		sub.clips = picked;
		sub.clip_count = MLOD_MESH_MAX_POSE_CLIPS;
		note(L, "%d clips: the posed cost and the measures take the frames of %d of them, evenly spaced",
		     L->c->clip_count, MLOD_MESH_MAX_POSE_CLIPS);
	}
	int clips = sub.clip_count > 0 ? sub.clip_count : 1;
	int per_train = 24 / clips, per_measure = 16 / clips;
	per_train = per_train < 2 ? 2 : per_train > 8 ? 8 : per_train;
	per_measure = per_measure < 2 ? 2 : per_measure > 4 ? 4 : per_measure; /* mlod_clip_times: 1 means all */
	mlod_result r = mlod_pose_set_make(&sub, 0, per_train, MLOD_MESH_RANDOM_POSES, MLOD_MESH_TRAIN_SEED,
	                                   MLOD_MESH_RANDOM_ANGLE, &L->train, err);
	if (r == MLOD_OK)
		r = mlod_pose_set_make(&sub, 1, per_measure, MLOD_MESH_RANDOM_POSES, MLOD_MESH_MEASURE_SEED,
		                       MLOD_MESH_RANDOM_ANGLE, &L->measure, err);
	free(picked);
	return r;
}

/* The primitives of mlod_mesh_levels_init, built and simplified one per
 * work item (part[2k], part[2k + 1]: its instance and primitive). */
typedef struct part_job {
	mlod_mesh_levels *L;
	double min_ratio;
	int *part;
	mlod_error *errs;
	mlod_result *result;
	int parts;
	int defer;              /* build only: the collapses wait (chain_pending) */
} part_job;

static void part_job_free(part_job *j)
{
	free(j->part);
	free(j->errs);
	free(j->result);
}

static mlod_result part_one(void *ctx, int k)
{
	part_job *j = ctx;
	mlod_mesh_levels *L = j->L;
	int i = j->part[2 * k], p = j->part[2 * k + 1];
	const mlod_instance *in = &L->c->instances[i];
	mlod_mesh_part *pt = &L->parts[i][p];
	if (pt->triangles < 4 || in->node < 0)
		return MLOD_OK;
	mlod_result r = mlod_bgm_build(L->c, i, p, &L->opt, &pt->bgm, &j->errs[k]);
	if (r == MLOD_OK && !j->defer) {
		/* A character budget may take any primitive further than the
		 * ratio: its chain goes as far as it goes (the same collapses as
		 * stopping at the ratio and going on after). Either way the chain
		 * is then final, and what only the collapses use is freed. */
		int target = j->min_ratio > 0.0 && L->budget != MLOD_BUDGET_CHARACTER ? (int)ceil(j->min_ratio * pt->triangles)
		                                                                      : 0;
		r = mlod_bgm_simplify(pt->bgm, target, 0, &j->errs[k]);
		bgm_release_collapse_state(pt->bgm);
	}
	/* an unsupported primitive is skipped, not an error of the whole */
	j->result[k] = r;
	return MLOD_OK;
}

/* Items [0, parts) are the primitives (part_one); the last one keeps the
 * full character posed at every measuring pose, in pose order (so that
 * every later pose's hierarchy is refitted from pose 0's), with
 * mlod_pose_set_keep: work the levels' measure would do first, done while
 * the primitives collapse. A pose that cannot be kept is not an error
 * here: the measure then poses the character itself, and reports what is
 * wrong. */
static mlod_result part_or_poses(void *ctx, int k)
{
	part_job *j = ctx;
	if (k < j->parts)
		return part_one(ctx, k);
	for (int p = 0; p < j->L->measure.count; p++)
		mlod_pose_set_keep(&j->L->measure, j->L->c, p, NULL);
	return MLOD_OK;
}

mlod_result mlod_mesh_levels_init(mlod_mesh_levels *L, const mlod_character *c, const mlod_bgm_options *opt,
                                  mlod_mesh_budget budget, double min_ratio, mlod_error *err)
{
	memset(L, 0, sizeof *L);
	L->c = c;
	L->opt = *opt;
	L->budget = budget;
	mlod_mesh_resolve(&L->opt, &L->budget);
	int unsupported = 0, morphs = 0;
	mlod_result r = make_poses(L, err);
	if (r != MLOD_OK)
		return r;
	L->eta = calloc((size_t)c->skeleton.joint_count + 1, sizeof *L->eta);
	L->parts = calloc((size_t)c->instance_count + 1, sizeof *L->parts);
	if (!L->eta || !L->parts)
		return nomem(err);
	if ((r = mlod_joint_weight_average(c, L->eta, err)) != MLOD_OK)
		return r;
	L->opt.eta = L->eta;
	L->opt.poses = &L->train;
	L->measure.threads = L->opt.threads;
	mlod_pose_set_bound_mean(&L->measure, 1); /* the same max, the mean an upper bound: mlod-bgm(1) */
	int n = 0;
	for (int i = 0; i < c->instance_count; i++)
		n += c->meshes[c->instances[i].mesh].primitive_count;
	part_job j = { L, min_ratio, calloc(2 * (size_t)n + 1, sizeof *j.part), calloc((size_t)n + 1, sizeof *j.errs),
	               calloc((size_t)n + 1, sizeof *j.result), n, 0 };
	if (!j.part || !j.errs || !j.result) {
		part_job_free(&j);
		return nomem(err);
	}
	for (int i = 0, at = 0; i < c->instance_count; i++) {
		const mlod_instance *in = &c->instances[i];
		const mlod_mesh *m = &c->meshes[in->mesh];
		L->parts[i] = calloc((size_t)m->primitive_count + 1, sizeof **L->parts);
		if (!L->parts[i]) {
			part_job_free(&j);
			return nomem(err);
		}
		for (int p = 0; p < m->primitive_count; p++) {
			const mlod_primitive *pr = &m->primitives[p];
			mlod_mesh_part *pt = &L->parts[i][p];
			pt->triangles = primitive_triangles(pr);
			L->triangles += pt->triangles;
			L->vertices += pr->vertex_count;
			j.part[2 * at] = i, j.part[2 * at + 1] = p, at++;
			j.defer += pt->triangles >= 4 && in->node >= 0;
		}
	}
	/* One primitive collapses on one thread: with more, its collapses
	 * wait for the levels, which are measured meanwhile (by_ratio). */
	j.defer = j.defer == 1 && L->opt.threads >= 2;
	/* Each primitive's BGM is built and simplified on its own: in
	 * parallel, with the results gathered in primitive order; and the
	 * full character kept posed at each measuring pose meanwhile. */
	mlod_parallel_for(n + 1, L->opt.threads, part_or_poses, &j);
	for (int k = 0; k < n; k++) {
		int i = j.part[2 * k], p = j.part[2 * k + 1];
		const mlod_instance *in = &c->instances[i];
		const mlod_primitive *pr = &c->meshes[in->mesh].primitives[p];
		mlod_mesh_part *pt = &L->parts[i][p];
		if (j.result[k] == MLOD_ERR_UNSUPPORTED) {
			unsupported++;
			continue;
		}
		if (j.result[k] != MLOD_OK) {
			if (err)
				*err = j.errs[k];
			r = j.result[k];
			part_job_free(&j);
			return r;
		}
		if (!pt->bgm)
			continue;
		mlod_bgm_info info;
		mlod_bgm_get_info(pt->bgm, &info);
		L->build_seconds += info.build_seconds;
		L->degenerate += info.dropped;
		L->simplified++;
		L->statics += in->skin < 0 && in->joint < 0;
		morphs += pr->target_count > 0;
	}
	if (j.defer && L->simplified == 1) {
		L->chain_pending = 1;
		L->chain_ratio = min_ratio;
	}
	part_job_free(&j);
	if (L->statics)
		note(L, "%d primitive(s) of static meshes (no joint, no skin) simplified in world space", L->statics);
	if (unsupported)
		note(L, "%d primitive(s) that are not triangles, or whose every triangle repeats a corner or has no area, left "
		     "as they are", unsupported);
	if (morphs)
		note(L, "%d primitive(s) with morph targets: offsets interpolated like positions", morphs);
	if (L->degenerate)
		note(L, "%d triangle(s) with two corners at one position (no area) left out of the levels", L->degenerate);
	return MLOD_OK;
}

/* The character budget: ratio of all simplified triangles, shared among
 * the primitives by posed cost (mlod_bgm_share_budget). Sets each part's
 * k. */
static mlod_result character_prefixes(mlod_mesh_levels *L, double ratio, mlod_error *err)
{
	const mlod_character *c = L->c;
	int n = 0, at = 0;
	long total = 0;
	for (int i = 0; i < c->instance_count; i++)
		n += c->meshes[c->instances[i].mesh].primitive_count;
	mlod_bgm **bgms = calloc((size_t)n + 1, sizeof *bgms);
	int *prefix = calloc((size_t)n + 1, sizeof *prefix);
	if (!bgms || !prefix) {
		free(bgms);
		free(prefix);
		return nomem(err);
	}
	for (int i = 0; i < c->instance_count; i++)
		for (int p = 0; p < c->meshes[c->instances[i].mesh].primitive_count; p++) {
			mlod_mesh_part *pt = &L->parts[i][p];
			bgms[at++] = pt->bgm;
			total += mlod_bgm_triangles(pt->bgm, 0); /* 0 without a BGM; degenerate faces dropped */
		}
	mlod_bgm_share_budget(bgms, n, (long)ceil(ratio * (double)total), prefix);
	at = 0;
	for (int i = 0; i < c->instance_count; i++)
		for (int p = 0; p < c->meshes[c->instances[i].mesh].primitive_count; p++)
			L->parts[i][p].k = prefix[at++];
	free(bgms);
	free(prefix);
	return MLOD_OK;
}

static void free_level(const mlod_mesh_levels *L, mlod_mesh_level *lv)
{
	for (int i = 0; lv->meshes && i < L->c->instance_count; i++) {
		for (int p = 0; lv->owned && lv->owned[i] && p < lv->meshes[i].primitive_count; p++)
			if (lv->owned[i][p])
				mlod_primitive_free(&lv->meshes[i].primitives[p]);
		free(lv->meshes[i].primitives);
		if (lv->owned)
			free(lv->owned[i]);
	}
	free(lv->meshes);
	free(lv->owned);
	free(lv->skins);
	free(lv->view.instances);
	memset(lv, 0, sizeof *lv);
}

/* Extracts the level at ratio (with the primitive budget, per primitive
 * the shortest prefix within ratio of its triangles; with the character
 * budget, character_prefixes), not yet measured. */
static mlod_result extract_level(mlod_mesh_levels *L, mlod_mesh_level *lv, double ratio, mlod_error *err)
{
	const mlod_character *c = L->c;
	mlod_result r = MLOD_OK;
	memset(lv, 0, sizeof *lv);
	lv->ratio = ratio;
	lv->meshes = calloc((size_t)c->instance_count + 1, sizeof *lv->meshes);
	lv->owned = calloc((size_t)c->instance_count + 1, sizeof *lv->owned);
	lv->skins = calloc((size_t)c->instance_count + 1, sizeof *lv->skins);
	if (!lv->meshes || !lv->owned || !lv->skins) {
		free_level(L, lv);
		return nomem(err);
	}
	double seconds = 0.0;
	if (L->budget == MLOD_BUDGET_CHARACTER && (r = character_prefixes(L, ratio, err)) != MLOD_OK) {
		free_level(L, lv);
		return r;
	}
	for (int i = 0; r == MLOD_OK && i < c->instance_count; i++) {
		const mlod_mesh *m = &c->meshes[c->instances[i].mesh];
		mlod_mesh *lm = &lv->meshes[i];
		lm->name = m->name;
		lm->gltf_index = m->gltf_index;
		lm->primitives = calloc((size_t)m->primitive_count + 1, sizeof *lm->primitives);
		lv->owned[i] = calloc((size_t)m->primitive_count + 1, 1);
		if (!lm->primitives || !lv->owned[i]) {
			r = nomem(err);
			break;
		}
		lm->primitive_count = m->primitive_count;
		for (int p = 0; p < m->primitive_count; p++) {
			mlod_mesh_part *pt = &L->parts[i][p];
			if (!pt->bgm) {
				lm->primitives[p] = m->primitives[p];
				lv->triangles += pt->triangles;
				lv->vertices += m->primitives[p].vertex_count;
				continue;
			}
			int k = L->budget == MLOD_BUDGET_CHARACTER ? pt->k
			                                             : mlod_bgm_prefix_for(pt->bgm, (int)ceil(ratio * pt->triangles));
			if ((r = mlod_bgm_extract(pt->bgm, k, c->instances[i].skin < 0, &lm->primitives[p], err)) != MLOD_OK)
				break;
			lv->owned[i][p] = 1;
			lv->triangles += lm->primitives[p].index_count / 3;
			lv->vertices += lm->primitives[p].vertex_count;
			int count;
			const mlod_vsplit *seq = mlod_bgm_sequence(pt->bgm, &count);
			for (int s = 0; s < k; s++)
				lv->caps += seq[s].capped;
			lv->collapses += k;
			if (k > 0)
				seconds += seq[k - 1].seconds;
		}
	}
	lv->collapse_seconds = seconds;
	lv->view = *c;
	lv->view.meshes = lv->meshes;
	lv->view.mesh_count = c->instance_count;
	lv->view.instances = NULL;
	if (r == MLOD_OK && !(lv->view.instances = malloc(sizeof *lv->view.instances * ((size_t)c->instance_count + 1))))
		r = nomem(err);
	if (r == MLOD_OK) {
		for (int i = 0; i < c->instance_count; i++) {
			lv->view.instances[i] = c->instances[i];
			lv->view.instances[i].mesh = i;
		}
	}
	if (r != MLOD_OK)
		free_level(L, lv);
	return r;
}

/* Extracts the level at ratio and measures it. */
static mlod_result make_level(mlod_mesh_levels *L, mlod_mesh_level *lv, double ratio, mlod_error *err)
{
	mlod_result r = extract_level(L, lv, ratio, err);
	if (r != MLOD_OK)
		return r;
	double t0 = bgm_seconds();
	if ((r = mlod_posed_error(L->c, &lv->view, &L->measure, &lv->error, err)) != MLOD_OK)
		free_level(L, lv);
	L->measure_seconds += bgm_seconds() - t0;
	return r;
}

/* Frees the levels from first on (made by a call that fails). */
static void drop_levels(mlod_mesh_levels *L, int first)
{
	while (L->count > first)
		free_level(L, &L->levels[--L->count]);
}

void mlod_mesh_levels_free(mlod_mesh_levels *L)
{
	for (int k = 0; k < L->count; k++)
		free_level(L, &L->levels[k]);
	for (int i = 0; L->parts && i < L->c->instance_count; i++) {
		for (int p = 0; L->parts[i] && p < L->c->meshes[L->c->instances[i].mesh].primitive_count; p++)
			mlod_bgm_free(L->parts[i][p].bgm);
		free(L->parts[i]);
	}
	free(L->parts);
	free(L->eta);
	mlod_pose_set_free(&L->train);
	mlod_pose_set_free(&L->measure);
	memset(L, 0, sizeof *L);
}

/* The one primitive waiting for its collapses (chain_pending). */
static mlod_mesh_part *pending_part(const mlod_mesh_levels *L)
{
	for (int i = 0; i < L->c->instance_count; i++)
		for (int p = 0; p < L->c->meshes[L->c->instances[i].mesh].primitive_count; p++)
			if (L->parts[i][p].bgm)
				return &L->parts[i][p];
	return NULL;
}

/* The floor of the pending chain: init's min_ratio of the primitive's
 * triangles (0, as far as it goes, with the character budget). */
static int chain_floor(const mlod_mesh_levels *L, const mlod_mesh_part *pt)
{
	if (L->budget == MLOD_BUDGET_CHARACTER || !(L->chain_ratio > 0.0))
		return 0;
	return (int)ceil(L->chain_ratio * pt->triangles);
}

/* Takes the pending chain on until a level of ratio could be extracted
 * as from the whole chain: a collapse down to its triangle target (with
 * the character budget, what mlod_bgm_share_budget takes from the one
 * primitive) or the chain's end. ratio 0: to the end, as init would have. */
static mlod_result chain_to(mlod_mesh_levels *L, mlod_mesh_part *pt, double ratio, mlod_error *err)
{
	int floor_t = chain_floor(L, pt), t;
	if (ratio <= 0.0)
		t = floor_t;
	else {
		t = L->budget == MLOD_BUDGET_CHARACTER ? (int)ceil(ratio * (double)mlod_bgm_triangles(pt->bgm, 0))
		                                       : (int)ceil(ratio * pt->triangles);
		if (t < floor_t)
			t = floor_t;
	}
	mlod_result r = mlod_bgm_simplify(pt->bgm, t, 0, err);
	if (r != MLOD_OK || t <= 0)
		return r;
	/* simplify stops at or below t, or at the chain's end; one collapse
	 * at a time past it if ever not (a level's prefix must be final) */
	for (;;) {
		int count;
		mlod_bgm_sequence(pt->bgm, &count);
		if (count > 0 && mlod_bgm_triangles(pt->bgm, count) <= t)
			return MLOD_OK;
		if ((r = mlod_bgm_simplify(pt->bgm, 0, 1, err)) != MLOD_OK)
			return r;
		int after;
		mlod_bgm_sequence(pt->bgm, &after);
		if (after == count)
			return MLOD_OK; /* the end */
	}
}

/* The rest of a pending chain, before anything reads it whole. */
static mlod_result chain_finish(mlod_mesh_levels *L, mlod_error *err)
{
	if (!L->chain_pending)
		return MLOD_OK;
	L->chain_pending = 0;
	mlod_mesh_part *pt = pending_part(L);
	mlod_result r = chain_to(L, pt, 0.0, err);
	bgm_release_collapse_state(pt->bgm); /* the chain is final */
	return r;
}

/* Extracts the level at ratio, after the previous ones: 1 kept (in
 * L->levels), 0 dropped with a note, else a failure. */
static mlod_result next_level(mlod_mesh_levels *L, double ratio, mlod_error *err)
{
	mlod_mesh_level lv;
	mlod_result r = extract_level(L, &lv, ratio, err);
	if (r != MLOD_OK)
		return r;
	if (L->count > 0 && lv.triangles >= L->levels[L->count - 1].triangles) {
		note(L, "ratio %g gives no fewer triangles than %g: dropped", ratio, L->levels[L->count - 1].ratio);
		free_level(L, &lv);
		return MLOD_OK;
	}
	if (L->count == 0 && lv.triangles >= L->triangles - L->degenerate) {
		note(L, "ratio %g removes nothing: dropped", ratio);
		free_level(L, &lv);
		return MLOD_OK;
	}
	L->levels[L->count++] = lv;
	return (mlod_result)1;
}

/* by_ratio with a pending chain: item 0 takes the chain from level to
 * level and extracts each (never waiting); item 1 measures each level
 * once it is out, on the other threads while the chain goes on, on all
 * of them after. Each level is measured alone (mlod_posed_errors: its
 * poses summed in order), so the bits are those of one call for all. */
typedef struct pipe_job {
	mlod_mesh_levels *L;
	const double *ratios;
	int n, first, threads;
	int out, done;          /* levels out (L->count), the chain over */
	pthread_mutex_t lock;
	pthread_cond_t cond;
	mlod_result chain_r, measure_r;
	mlod_error chain_err, measure_err;
	double measure_seconds;
} pipe_job;

static void pipe_chain(pipe_job *pj)
{
	mlod_mesh_levels *L = pj->L;
	mlod_mesh_part *pt = pending_part(L);
	mlod_result r = MLOD_OK;
	for (int k = 0; r == MLOD_OK && k < pj->n && L->count < MLOD_MESH_MAX_LEVELS; k++) {
		if ((r = chain_to(L, pt, pj->ratios[k], &pj->chain_err)) != MLOD_OK)
			break;
		r = next_level(L, pj->ratios[k], &pj->chain_err);
		if (r == (mlod_result)1) {
			r = MLOD_OK;
			pthread_mutex_lock(&pj->lock);
			pj->out = L->count;
			pthread_cond_broadcast(&pj->cond);
			pthread_mutex_unlock(&pj->lock);
		}
	}
	if (r == MLOD_OK)
		r = chain_to(L, pt, 0.0, &pj->chain_err);
	bgm_release_collapse_state(pt->bgm); /* the chain is final */
	pthread_mutex_lock(&pj->lock);
	pj->chain_r = r;
	pj->done = 1;
	pthread_cond_broadcast(&pj->cond);
	pthread_mutex_unlock(&pj->lock);
}

static void pipe_measure(pipe_job *pj)
{
	mlod_mesh_levels *L = pj->L;
	int next = pj->first;
	for (;;) {
		pthread_mutex_lock(&pj->lock);
		while (pj->out == next && !pj->done)
			pthread_cond_wait(&pj->cond, &pj->lock);
		int out = pj->out, done = pj->done;
		pthread_mutex_unlock(&pj->lock);
		if (out == next)
			return; /* the chain is over (or failed) */
		/* while the chain goes on, one level on the threads it leaves;
		 * after it, every level out at once on all of them */
		int count = done ? out - next : 1;
		L->measure.threads = done ? pj->threads : pj->threads - 1;
		const mlod_character *views[MLOD_MESH_MAX_LEVELS];
		mlod_deviation dev[MLOD_MESH_MAX_LEVELS];
		for (int k = 0; k < count; k++)
			views[k] = &L->levels[next + k].view;
		double t0 = bgm_seconds();
		mlod_result r = mlod_posed_errors(L->c, views, count, &L->measure, dev, &pj->measure_err);
		pj->measure_seconds += bgm_seconds() - t0;
		if (r != MLOD_OK) {
			pj->measure_r = r;
			return;
		}
		for (int k = 0; k < count; k++)
			L->levels[next + k].error = dev[k];
		next += count;
	}
}

static mlod_result pipe_item(void *ctx, int item)
{
	if (item == 0)
		pipe_chain(ctx);
	else
		pipe_measure(ctx);
	return MLOD_OK;
}

static mlod_result by_ratio_pipelined(mlod_mesh_levels *L, const double *ratios, int n, mlod_error *err)
{
	pipe_job pj = { L, ratios, n, L->count, L->measure.threads, L->count, 0, PTHREAD_MUTEX_INITIALIZER,
	                PTHREAD_COND_INITIALIZER, MLOD_OK, MLOD_OK, { 0 }, { 0 }, 0.0 };
	L->chain_pending = 0;
	/* item 0 never waits: one thread alone runs both, in order */
	mlod_parallel_for(2, 2, pipe_item, &pj);
	L->measure.threads = pj.threads;
	L->measure_seconds += pj.measure_seconds;
	pthread_mutex_destroy(&pj.lock);
	pthread_cond_destroy(&pj.cond);
	mlod_result r = pj.chain_r != MLOD_OK ? pj.chain_r : pj.measure_r;
	if (r != MLOD_OK) {
		if (err)
			*err = pj.chain_r != MLOD_OK ? pj.chain_err : pj.measure_err;
		drop_levels(L, pj.first);
	}
	return r;
}

/* The levels are measured: the full character posed at every measuring
 * pose is let go (a later call poses it again, with the same results). */
static mlod_result measured(mlod_mesh_levels *L, mlod_result r)
{
	mlod_pose_set_forget(&L->measure);
	return r;
}

static mlod_result by_ratio(mlod_mesh_levels *L, const double *ratios, int n, mlod_error *err);

mlod_result mlod_mesh_levels_by_ratio(mlod_mesh_levels *L, const double *ratios, int n, mlod_error *err)
{
	return measured(L, by_ratio(L, ratios, n, err));
}

static mlod_result by_ratio(mlod_mesh_levels *L, const double *ratios, int n, mlod_error *err)
{
	if (L->chain_pending) {
		const int first = L->count;
		mlod_result r = by_ratio_pipelined(L, ratios, n, err);
		return r != MLOD_OK ? r : mlod_mesh_prune_influences_(L, first, err);
	}
	/* The levels first (which are kept depends on their triangles only),
	 * then all of them measured at once: their poses spread over the
	 * threads, the same results as one level after another. */
	const int first = L->count;
	for (int k = 0; k < n && L->count < MLOD_MESH_MAX_LEVELS; k++) {
		mlod_result r = next_level(L, ratios[k], err);
		if (r != MLOD_OK && r != (mlod_result)1) {
			drop_levels(L, first);
			return r;
		}
	}
	const mlod_character *views[MLOD_MESH_MAX_LEVELS];
	mlod_deviation dev[MLOD_MESH_MAX_LEVELS];
	for (int k = first; k < L->count; k++)
		views[k - first] = &L->levels[k].view;
	double t0 = bgm_seconds();
	mlod_result r = mlod_posed_errors(L->c, views, L->count - first, &L->measure, dev, err);
	L->measure_seconds += bgm_seconds() - t0;
	if (r != MLOD_OK) {
		drop_levels(L, first);
		return r;
	}
	for (int k = first; k < L->count; k++)
		L->levels[k].error = dev[k - first];
	return mlod_mesh_prune_influences_(L, first, err);
}

/* By error, through mlod_level_search_run: the parameter is the ratio. */
static mlod_result search_make(void *ctx, double x, int chain, void **level, double *error, mlod_error *err)
{
	mlod_mesh_levels *L = ctx;
	mlod_mesh_level *lv = malloc(sizeof *lv);
	if (!lv)
		return nomem(err);
	mlod_result r = make_level(L, lv, x, err);
	if (r != MLOD_OK) {
		free(lv);
		return r;
	}
	if (chain && L->count > 0 && lv->triangles >= L->levels[L->count - 1].triangles) {
		free_level(L, lv); /* nothing more comes off */
		free(lv);
		return (mlod_result)1;
	}
	*level = lv;
	*error = lv->error.max;
	return MLOD_OK;
}

static void search_drop(void *ctx, void *level)
{
	free_level(ctx, level);
	free(level);
}

static int search_keep(void *ctx, void *level)
{
	mlod_mesh_levels *L = ctx;
	mlod_mesh_level *lv = level;
	if (L->count >= MLOD_MESH_MAX_LEVELS || (L->count > 0 && lv->triangles >= L->levels[L->count - 1].triangles)) {
		search_drop(ctx, level);
		return 0;
	}
	/* Fewer triangles at no more error: the level before is never chosen
	 * (the runtime switches by error), so this one takes its place. */
	mlod_mesh_level *prev = L->count > 0 ? &L->levels[L->count - 1] : NULL;
	if (prev && lv->error.max <= prev->error.max) {
		note(L, "the level at ratio %.4g (%d triangles) replaces the one at %.4g (%d): no more error", lv->ratio,
		     lv->triangles, prev->ratio, prev->triangles);
		free_level(L, prev);
		L->count--;
	}
	L->levels[L->count++] = *lv;
	free(lv);
	return 1;
}

mlod_result mlod_mesh_levels_by_error(mlod_mesh_levels *L, double bound, mlod_error *err)
{
	double ratios[MLOD_MESH_MAX_LEVELS];
	int n = 0;
	for (double ratio = 0.5; ratio >= MLOD_MESH_MIN_RATIO && n < MLOD_MESH_MAX_LEVELS; ratio /= 2)
		ratios[n++] = ratio;
	mlod_level_search s = {ratios, n, 1.0, 0, MLOD_MESH_BISECTIONS, bound, L, search_make, search_keep, search_drop};
	mlod_result r = chain_finish(L, err);
	if (L->opt.influence_budget > 0.0)
		note(L, "influences not pruned under an error bound");
	return measured(L, r != MLOD_OK ? r : mlod_level_search_run(&s, err));
}

void mlod_mesh_levels_totals(const mlod_mesh_levels *L, mlod_bgm_info *sum)
{
	memset(sum, 0, sizeof *sum);
	for (int i = 0; L->parts && i < L->c->instance_count; i++)
		for (int p = 0; p < L->c->meshes[L->c->instances[i].mesh].primitive_count; p++) {
			const mlod_bgm *g = L->parts[i][p].bgm;
			if (!g)
				continue;
			mlod_bgm_info in;
			mlod_bgm_get_info(g, &in);
			sum->nodes += in.nodes;
			sum->seam_nodes += in.seam_nodes;
			sum->border_edges += in.border_edges;
			sum->nonmanifold_edges += in.nonmanifold_edges;
			sum->locked_nodes += in.locked_nodes;
			sum->eligible_nodes += in.eligible_nodes;
			sum->dropped += in.dropped;
			sum->refused += in.refused;
			sum->snaps += in.snaps;
		}
}

int mlod_mesh_has_levels_(const mlod_mesh_levels *L, int i)
{
	const mlod_instance *in = &L->c->instances[i];
	if (in->node < 0)
		return 0;
	for (int p = 0; p < L->c->meshes[in->mesh].primitive_count; p++)
		if (L->parts[i][p].bgm)
			return 1;
	return 0;
}
