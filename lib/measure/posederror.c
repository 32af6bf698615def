/*
 * posederror.c: how far a mesh level strays from the full character where
 * it matters, posed (the measure of Savoye & Meyer 2008, 4.2, "simplifying
 * deforming meshes using a standard algorithm is error prone", made
 * quantitative).
 *
 * A pose set holds joint world matrices for the rest pose, evenly spaced
 * times of each clip, and random poses: each joint's rest rotation turned
 * about a random axis by a random angle up to a bound (SplitMix64, so a
 * seed gives the same poses on every machine). At each pose both
 * characters are skinned and compared with mlod_surface_deviation
 * (symmetric point-to-surface, % of the full character's diagonal). A set
 * made here keeps, per pose, the posed full character with its search
 * hierarchy (struct mlod_pose_cache): measuring every level of a character
 * builds that hierarchy once per pose. The full character is still posed
 * at every call, and the kept one used only when it is the same, byte for
 * byte (or, kept with mlod_pose_set_keep, not posed again). Each level's
 * first pose is measured first (mlod_posed_errors: the levels in
 * parallel), recording every sample's nearest triangle in both
 * directions, and the other poses (of every level, in parallel) start
 * their searches from those: skinning moves a sample and its nearest
 * triangle together, so the first bound is nearly always the answer
 * (mlod-bgm on a 50k-triangle tubeman: 2.1 full point-triangle distances
 * and 24 nodes a query, from 5.4 and 29). The result is the same, bit for
 * bit, as the search is exact. With mlod_pose_set_bound_mean (mlod-bgm's
 * levels), the other poses search only the samples whose distance to
 * their recorded triangle could raise the max (mlod_warm's bound): the
 * same max, a mean at least the exact one, and on the 50k-triangle
 * tubeman 1.5 s of mlod-bgm's 2.9 s CPU saved (bench/RESULTS.md, Run 16).
 */
#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#include "measure/mlod_measure.h"
#include "measure/surface.h"

static uint64_t splitmix(uint64_t *s)
{
	uint64_t z = (*s += 0x9e3779b97f4a7c15ull);
	z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
	z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
	return z ^ (z >> 31);
}

/* Uniform in [0, 1). */
static double uniform(uint64_t *s)
{
	return (double)(splitmix(s) >> 11) * (1.0 / 9007199254740992.0);
}

/* Per pose of a set: the full character posed there with its hierarchy,
 * made by the first mlod_posed_error that needs it and then kept as it is
 * (a later call with another full character does without). */
struct mlod_pose_cache {
	pthread_mutex_t lock;
	int count;
	mlod_surface **full;
	unsigned char *linked; /* per pose: mlod_surface_like tried (pose 0's hierarchy to refit) */
	int bound_mean; /* mlod_pose_set_bound_mean */
	const mlod_character **owner; /* per pose: mlod_pose_set_keep's full character, kept
	                               * there (checked): not posed again */
};

static struct mlod_pose_cache *cache_make(int count)
{
	struct mlod_pose_cache *c = calloc(1, sizeof *c);
	if (!c)
		return NULL;
	c->full = calloc((size_t)(count > 0 ? count : 1), sizeof *c->full);
	c->linked = calloc((size_t)(count > 0 ? count : 1), 1);
	c->owner = calloc((size_t)(count > 0 ? count : 1), sizeof *c->owner);
	if (!c->full || !c->linked || !c->owner || pthread_mutex_init(&c->lock, NULL) != 0) {
		free(c->full);
		free(c->linked);
		free(c->owner);
		free(c);
		return NULL;
	}
	c->count = count;
	return c;
}

/* Frees the kept full characters, the last pose first (the others share
 * pose 0's triangles and refit its hierarchy), and what was known of them. */
static void cache_clear(struct mlod_pose_cache *c)
{
	for (int k = c->count - 1; k >= 0; k--) {
		mlod_surface_free(c->full[k]);
		c->full[k] = NULL;
		c->linked[k] = 0;
		c->owner[k] = NULL;
	}
}

static void cache_free(struct mlod_pose_cache *c)
{
	if (!c)
		return;
	cache_clear(c);
	free(c->full);
	free(c->linked);
	free(c->owner);
	pthread_mutex_destroy(&c->lock);
	free(c);
}

/* Pose k's kept full character, made from a when it has none yet (or
 * NULL); its hierarchy, for a pose after the first, refitted from pose
 * 0's when that pose is kept by then (tried once, under the lock, before
 * any call uses it: so which poses refit does not depend on the order
 * poses were kept in). */
static mlod_result cache_keep(struct mlod_pose_cache *c, int k, const mlod_posed *a, mlod_surface **out,
                              mlod_error *err)
{
	pthread_mutex_lock(&c->lock);
	mlod_surface *s = c->full[k], *first = c->full[0];
	pthread_mutex_unlock(&c->lock);
	*out = NULL;
	if (!s && a) {
		/* after the first pose, its triangles shared when they are a's
		 * (pose 0 is freed last) */
		mlod_surface *made;
		mlod_result r = mlod_surface_make_like(a, k > 0 ? first : NULL, &made, err);
		if (r != MLOD_OK)
			return r;
		pthread_mutex_lock(&c->lock);
		if (!c->full[k])
			c->full[k] = made, made = NULL;
		s = c->full[k];
		pthread_mutex_unlock(&c->lock);
		mlod_surface_free(made); /* another call kept its own first */
	}
	if (s && k > 0) {
		pthread_mutex_lock(&c->lock);
		if (!c->linked[k] && c->full[0]) {
			mlod_surface_like(s, c->full[0]);
			c->linked[k] = 1;
		}
		pthread_mutex_unlock(&c->lock);
	}
	*out = s;
	return MLOD_OK;
}

/* The kept full character at pose k when it is a, made from a when pose
 * k has none yet; NULL otherwise, or when it cannot be made (the caller
 * then measures a itself, and reports why). */
static const mlod_surface *cache_get(struct mlod_pose_cache *c, int k, const mlod_posed *a)
{
	if (!c || k >= c->count)
		return NULL;
	mlod_surface *s;
	cache_keep(c, k, a, &s, NULL);
	return s && mlod_surface_is(s, a) ? s : NULL;
}

/* The kept full character at pose k without posing full, when full is
 * the one mlod_pose_set_keep kept there; else NULL. */
static const mlod_surface *cache_owned(struct mlod_pose_cache *c, int k, const mlod_character *full)
{
	if (!c || k >= c->count)
		return NULL;
	pthread_mutex_lock(&c->lock);
	int owned = c->owner[k] == full && c->full[k];
	pthread_mutex_unlock(&c->lock);
	mlod_surface *s = NULL;
	if (owned)
		cache_keep(c, k, NULL, &s, NULL);
	return s;
}

mlod_result mlod_pose_set_keep(const mlod_pose_set *s, const mlod_character *full, int k, mlod_error *err)
{
	if (!s || !full)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_pose_set_keep: NULL argument");
	if (k < 0 || k >= s->count || full->skeleton.joint_count != s->joint_count)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_pose_set_keep: pose %d of %d, %d joints for %d", k, s->count,
		                 full->skeleton.joint_count, s->joint_count);
	struct mlod_pose_cache *c = s->cache;
	if (!c)
		return MLOD_OK;
	mlod_posed a = {0};
	mlod_result r = mlod_pose_character(full, s->world + (size_t)k * (size_t)s->joint_count, &a, err);
	mlod_surface *kept = NULL;
	if (r == MLOD_OK)
		r = cache_keep(c, k, &a, &kept, err);
	if (r == MLOD_OK && mlod_surface_is(kept, &a)) { /* else kept for another: mlod_posed_error measures its own */
		pthread_mutex_lock(&c->lock);
		c->owner[k] = full;
		pthread_mutex_unlock(&c->lock);
		/* every call's first pose searches pose 0's; the bounded poses
		 * (mlod_pose_set_bound_mean) nearly always some sample of each
		 * other pose: refitted from pose 0's, when that one is kept */
		if (k == 0 || c->bound_mean)
			r = mlod_surface_build(kept, err);
	}
	mlod_posed_free(&a);
	return r;
}

mlod_result mlod_pose_set_make(const mlod_character *c, int bind, int per_clip, int random, uint64_t seed,
                               float max_angle, mlod_pose_set *out, mlod_error *err)
{
	if (!c || !out)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_pose_set_make: NULL argument");
	memset(out, 0, sizeof *out);
	if (per_clip < 0 || random < 0 || random > 100000 || !isfinite(max_angle))
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_pose_set_make: bad counts or angle");
	const mlod_skeleton *s = &c->skeleton;
	int J = s->joint_count;
	long total = (bind ? 1 : 0) + random;
	float **times = calloc((size_t)c->clip_count + 1, sizeof *times);
	int *counts = calloc((size_t)c->clip_count + 1, sizeof *counts);
	mlod_trs *rest = malloc(sizeof *rest * ((size_t)J + 1)), *local = malloc(sizeof *local * ((size_t)J + 1));
	mlod_result r = MLOD_OK;
	if (!times || !counts || !rest || !local) {
		r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory making poses");
		goto done;
	}
	for (int k = 0; per_clip > 0 && k < c->clip_count; k++) {
		counts[k] = mlod_clip_times(&c->clips[k], per_clip, &times[k]);
		if (counts[k] < 0) {
			counts[k] = 0;
			r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory making poses");
			goto done;
		}
		total += counts[k];
	}
	if ((size_t)total * (size_t)(J > 0 ? J : 1) > ((size_t)1 << 26)) {
		r = mlod_fail(err, MLOD_ERR_LIMIT, "%ld poses of %d joints is too many", total, J);
		goto done;
	}
	out->world = malloc(sizeof *out->world * (size_t)(total > 0 ? total : 1) * (size_t)(J > 0 ? J : 1));
	if (!out->world) {
		r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory making poses");
		goto done;
	}
	out->joint_count = J;
	mlod_pose_rest(s, rest);
	int n = 0;
	if (bind)
		mlod_pose_world(s, rest, out->world + (size_t)n++ * (size_t)J);
	for (int k = 0; k < c->clip_count; k++)
		for (int i = 0; i < counts[k]; i++) {
			memcpy(local, rest, sizeof *local * (size_t)J);
			mlod_clip_sample(&c->clips[k], times[k][i], local);
			mlod_pose_world(s, local, out->world + (size_t)n++ * (size_t)J);
		}
	uint64_t state = seed;
	for (int i = 0; i < random; i++) {
		memcpy(local, rest, sizeof *local * (size_t)J);
		for (int j = 0; j < J; j++) {
			mlod_v3 axis;
			double len2;
			do {
				axis.x = (float)(2.0 * uniform(&state) - 1.0);
				axis.y = (float)(2.0 * uniform(&state) - 1.0);
				axis.z = (float)(2.0 * uniform(&state) - 1.0);
				len2 = (double)axis.x * axis.x + (double)axis.y * axis.y + (double)axis.z * axis.z;
			} while (len2 > 1.0 || len2 < 1e-6);
			float angle = (float)((2.0 * uniform(&state) - 1.0) * max_angle);
			local[j].r = mlod_quat_normalize(mlod_quat_mul(local[j].r, mlod_quat_axis_angle(axis, angle)));
		}
		mlod_pose_world(s, local, out->world + (size_t)n++ * (size_t)J);
	}
	out->count = n;
	if (!(out->cache = cache_make(n)))
		r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory making poses");
done:
	for (int k = 0; times && k < c->clip_count; k++)
		free(times[k]);
	free(times);
	free(counts);
	free(rest);
	free(local);
	if (r != MLOD_OK)
		mlod_pose_set_free(out);
	return r;
}

void mlod_pose_set_forget(const mlod_pose_set *s)
{
	if (s && s->cache)
		cache_clear(s->cache);
}

void mlod_pose_set_bound_mean(mlod_pose_set *s, int on)
{
	if (s && s->cache)
		s->cache->bound_mean = on != 0;
}

void mlod_pose_set_free(mlod_pose_set *s)
{
	if (!s)
		return;
	free(s->world);
	cache_free(s->cache);
	memset(s, 0, sizeof *s);
}

/* One pose of mlod_posed_error: both characters posed and compared. */
typedef struct posed_job {
	const mlod_character *full, *level;
	const mlod_pose_set *poses;
	mlod_deviation *d;      /* per pose */
	mlod_error *errs;       /* per pose */
	mlod_warm warm;         /* nearest triangles at the first pose, warm starts for the others */
	int first;              /* the pose of item 0 */
} posed_job;

static mlod_result posed_one(void *ctx, int item)
{
	posed_job *j = ctx;
	int k = j->first + item;
	const mlod_mat4 *world = j->poses->world + (size_t)k * (size_t)j->poses->joint_count;
	mlod_posed a = {0}, b = {0};
	mlod_result r = MLOD_OK;
	/* the full character kept by mlod_pose_set_keep needs no posing */
	const mlod_surface *kept = cache_owned(j->poses->cache, k, j->full);
	if (!kept && (r = mlod_pose_character(j->full, world, &a, &j->errs[k])) == MLOD_OK)
		kept = cache_get(j->poses->cache, k, &a);
	if (r == MLOD_OK && (r = mlod_pose_character(j->level, world, &b, &j->errs[k])) == MLOD_OK) {
		if (kept && j->warm.record) { /* the first pose, alone: the warm starts' memory */
			const mlod_posed *m = mlod_surface_mesh(kept);
			j->warm.a_count = m->vertex_count + m->triangle_count;
			j->warm.b_count = b.vertex_count + b.triangle_count;
			j->warm.a = calloc((size_t)j->warm.a_count, sizeof *j->warm.a);
			j->warm.b = calloc((size_t)j->warm.b_count, sizeof *j->warm.b);
			if (!j->warm.a || !j->warm.b) {
				free(j->warm.a);
				free(j->warm.b);
				j->warm.a = j->warm.b = NULL;
			}
		}
		r = kept ? mlod_surface_deviation_to(kept, &b, j->warm.a ? &j->warm : NULL, &j->d[k], &j->errs[k])
		         : mlod_surface_deviation(&a, &b, &j->d[k], &j->errs[k]);
	}
	mlod_posed_free(&a);
	mlod_posed_free(&b);
	return r;
}

/* The levels of mlod_posed_errors, in one mlod_parallel_for: item i < count
 * is the first pose of level i (recording the warm starts); then item
 * count + i * per + p is pose p + 1 of level i, which waits until level
 * i's first pose is done (items are handed out in order, so every first
 * pose has started by then: no barrier between the two kinds, and no
 * wait that a barrier would not have). */
typedef struct posed_batch {
	posed_job *jobs;
	int count, per;
	int bound;
	unsigned char *done;   /* per level: its first pose measured */
	pthread_mutex_t lock;
	pthread_cond_t cond;
} posed_batch;

static mlod_result batch_item(void *ctx, int item)
{
	posed_batch *b = ctx;
	if (item < b->count) {
		posed_job *j = &b->jobs[item];
		mlod_result r = posed_one(j, 0);
		pthread_mutex_lock(&b->lock);
		j->warm.record = 0, j->first = 1, j->warm.bound = b->bound;
		b->done[item] = r == MLOD_OK ? 1 : 2;
		pthread_cond_broadcast(&b->cond);
		pthread_mutex_unlock(&b->lock);
		return r;
	}
	item -= b->count;
	int i = item / b->per;
	pthread_mutex_lock(&b->lock);
	while (!b->done[i])
		pthread_cond_wait(&b->cond, &b->lock);
	int ok = b->done[i] == 1;
	pthread_mutex_unlock(&b->lock);
	/* a level whose first pose failed reports that failure, not its others */
	return ok ? posed_one(&b->jobs[i], item % b->per) : MLOD_OK;
}

mlod_result mlod_posed_error(const mlod_character *full, const mlod_character *level, const mlod_pose_set *poses,
                             mlod_deviation *out, mlod_error *err)
{
	return mlod_posed_errors(full, &level, 1, poses, out, err);
}

mlod_result mlod_posed_errors(const mlod_character *full, const mlod_character *const *levels, int count,
                              const mlod_pose_set *poses, mlod_deviation *out, mlod_error *err)
{
	if (!full || (count > 0 && (!levels || !out)) || !poses)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_posed_error: NULL argument");
	for (int i = 0; i < count; i++)
		if (!levels[i])
			return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_posed_error: NULL argument");
	if (count <= 0)
		return MLOD_OK;
	memset(out, 0, sizeof *out * (size_t)count);
	for (int i = 0; i < count; i++)
		if (poses->joint_count != full->skeleton.joint_count || levels[i]->skeleton.joint_count != full->skeleton.joint_count)
			return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_posed_error: poses of %d joints for %d and %d joints",
			                 poses->joint_count, full->skeleton.joint_count, levels[i]->skeleton.joint_count);
	if (poses->count <= 0)
		return MLOD_OK;
	const int P = poses->count;
	posed_job *jobs = calloc((size_t)count, sizeof *jobs);
	mlod_deviation *d = calloc((size_t)count * (size_t)P, sizeof *d);
	mlod_error *errs = calloc((size_t)count * (size_t)P, sizeof *errs);
	if (!jobs || !d || !errs) {
		free(jobs);
		free(d);
		free(errs);
		return mlod_fail(err, MLOD_ERR_NOMEM, "mlod_posed_error: out of memory for %d poses of %d levels", P, count);
	}
	for (int i = 0; i < count; i++) {
		posed_job *j = &jobs[i];
		j->full = full, j->level = levels[i], j->poses = poses;
		j->d = d + (size_t)i * (size_t)P, j->errs = errs + (size_t)i * (size_t)P;
		j->warm.record = 1;
	}
	/* Each level's first pose, recording each sample's nearest triangle;
	 * then the other poses of every level start from those (only the
	 * search's speed depends on them, never a result). Without the memory
	 * for them, a level's poses are measured cold. Every item writes only
	 * its own level and pose: the work is spread over the levels and
	 * poses, and the results do not depend on the thread count. */
	posed_batch b = { jobs, count, P - 1, poses->cache && poses->cache->bound_mean, calloc((size_t)count, 1),
	                  PTHREAD_MUTEX_INITIALIZER, PTHREAD_COND_INITIALIZER };
	mlod_result r;
	if (!b.done)
		r = mlod_fail(&errs[0], MLOD_ERR_NOMEM, "mlod_posed_error: out of memory for %d levels", count);
	else
		r = mlod_parallel_for(count * P, poses->threads, batch_item, &b);
	free(b.done);
	pthread_mutex_destroy(&b.lock);
	pthread_cond_destroy(&b.cond);
	if (r != MLOD_OK) {
		/* the first failure, in level order then pose order, of the items run */
		for (long k = 0; k < (long)count * P; k++)
			if (errs[k].code != MLOD_OK) {
				if (err)
					*err = errs[k];
				break;
			}
	} else
		for (int i = 0; i < count; i++) {
			/* summed in pose order, so the thread count cannot change a bit */
			double sum = 0.0;
			for (int k = 0; k < P; k++) {
				sum += jobs[i].d[k].mean;
				if (jobs[i].d[k].max > out[i].max)
					out[i].max = jobs[i].d[k].max;
				out[i].scale = jobs[i].d[k].scale;
			}
			out[i].mean = sum / P;
		}
	for (int i = 0; i < count; i++) {
		free(jobs[i].warm.a);
		free(jobs[i].warm.b);
		mlod_warm_release(&jobs[i].warm);
	}
	free(jobs);
	free(d);
	free(errs);
	return r;
}
