/*
 * levels.c: the levels of several clips at once, on threads
 * (mlod_motion_build_levels).
 *
 * Two ways to share the work, with the same results:
 * - one item per clip (when there are at least as many clips as threads,
 *   or no keys method): each level is mlod_motion_next_level_best's,
 *   whose methods after the first stop early where they cannot win;
 * - two items per clip (fewer clips than threads): the keys method's
 *   choice of keys, level after level (mlod_motion_keys_reduce: a level's
 *   keys depend only on the previous level's keys), and a finisher that
 *   takes each level's keys as they come, rounds and measures them
 *   (mlod_motion_keys_finish, on a copy of the keys item's motion) and
 *   builds the other method's level as mlod_motion_next_level_best does,
 *   with the keys level's bytes as its limit; the levels are then chosen
 *   as mlod_motion_next_level_best chooses. So level k's rounding and the
 *   frames method's level k overlap level k + 1's choice of keys. The
 *   choice of keys and the rounding's refinement also run on `threads`
 *   threads each (mlod_motion_set_threads; tasks.c). Items are handed out
 *   in index order and a clip's keys item comes first, so the one the
 *   finisher waits for has always started.
 * - three items per clip, the second way with the other method's levels
 *   on a third item, when the keys method is the last one (so built
 *   first): level k of the other method takes the limit the finisher
 *   hands over once it has rounded keys level k, and the finisher goes
 *   on to keys level k + 1 meanwhile. Only the third item waits on the
 *   finisher, never the other way, so fewer threads than items only
 *   delay it.
 */
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#include "motion/mlod_motion.h"
#include "motion/motion_eval.h"
#include "motion/motion_internal.h"

typedef struct build_ctx {
	const mlod_character *c;
	const int *clips;
	const mlod_motion_options *opt;
	const mlod_motion_method *methods;
	int method_count;
	int keys;                    /* the index of the keys method (the second way) */
	int threads;                 /* of the keys method's choice of keys (the second way) */
	const mlod_motion_spec *specs;
	int spec_count;
	mlod_motion_clip_levels *out;
	/* Per clip and method (the second way): the chain of levels. */
	mlod_motion_level *chain;    /* [clip][method][spec] */
	mlod_result *chain_result;   /* [clip][method][spec]; -1: not built */
	mlod_error *chain_error;     /* [clip][method][spec] */
	double *known;               /* [clip][spec]: the keys level's error before rounding */
	mlod_result *create_result;  /* [clip][method] */
	mlod_error *create_error;    /* [clip][method] */
	mlod_result *fin_result;     /* [clip]: the finisher's own motion */
	mlod_error *fin_error;       /* [clip] */
	mlod_motion_timeline *info;  /* [clip][method] */
	/* The keys levels as they are chosen: how many per clip, under lock;
	 * the finisher waits. */
	pthread_mutex_t lock;
	pthread_cond_t more;
	int *published;              /* [clip] */
	/* The keys item's motion, once made (or not: its create_result), for
	 * the finisher to copy; the finisher frees it once the keys item has
	 * published every level. */
	mlod_motion **kmotion;       /* [clip] */
	int *made;                   /* [clip] */
	/* The third way (frames_own): the finisher hands the frames method
	 * its motion (fmade: handed over, fmotion NULL when there is none)
	 * and, level by level, the limit it would have given it (limit[clip]
	 * [spec]; rounded: the levels handed over; stop: the finisher's list
	 * ended before that level). */
	int frames_own;
	mlod_motion **fmotion;       /* [clip] */
	int *fmade;                  /* [clip] */
	long *limit;                 /* [clip][spec] */
	int *rounded;                /* [clip] */
	int *fin_stop;               /* [clip]: the level the finisher's list ended at, or spec_count */
} build_ctx;

#define NOT_BUILT ((mlod_result)-1)

static int skipped(mlod_motion_method method, mlod_motion_target target)
{
	return !mlod_motion_method_applies(method, target);
}

static mlod_result alloc_levels(mlod_motion_clip_levels *o, int n)
{
	o->levels = calloc((size_t)n, sizeof *o->levels);
	o->results = calloc((size_t)n, sizeof *o->results);
	o->errors = calloc((size_t)n, sizeof *o->errors);
	return o->levels && o->results && o->errors ? MLOD_OK : MLOD_ERR_NOMEM;
}

/* The first way: one clip, every level through mlod_motion_next_level_best. */
static mlod_result clip_item(void *ctx, int k)
{
	build_ctx *b = ctx;
	mlod_motion_clip_levels *o = &b->out[k];
	mlod_motion *m[2] = { NULL, NULL };
	int n = b->method_count;
	for (int i = 0; i < n; i++) {
		o->result = i == 0 ? mlod_motion_create(b->c, b->clips[k], b->opt, &m[i], &o->error)
		                   : mlod_motion_create_like(m[0], &m[i], &o->error);
		if (o->result != MLOD_OK)
			goto done;
	}
	o->timeline = *mlod_motion_timeline_info(m[0]);
	if (o->timeline.frames < 3)
		goto done;
	if (alloc_levels(o, b->spec_count) != MLOD_OK) {
		o->result = mlod_fail(&o->error, MLOD_ERR_NOMEM, "out of memory");
		goto done;
	}
	for (int s = 0; s < b->spec_count; s++) {
		o->level_count = s + 1;
		o->results[s] = mlod_motion_next_level_best(m, b->methods, n, b->specs[s].target, b->specs[s].value,
		                                            &o->levels[s], &o->errors[s]);
		if (o->results[s] != MLOD_OK && o->results[s] != MLOD_ERR_LIMIT)
			break;
	}
done:
	for (int i = 0; i < n; i++)
		mlod_motion_free(m[i]);
	return MLOD_OK;
}

/* The keys levels of clip k up to s - 1 are chosen (all: s is
 * spec_count). */
static void publish(build_ctx *b, int k, int s)
{
	pthread_mutex_lock(&b->lock);
	b->published[k] = s;
	pthread_cond_broadcast(&b->more);
	pthread_mutex_unlock(&b->lock);
}

static void set_made(build_ctx *b, int k, mlod_motion *m)
{
	pthread_mutex_lock(&b->lock);
	b->kmotion[k] = m;
	b->made[k] = 1;
	pthread_cond_broadcast(&b->more);
	pthread_mutex_unlock(&b->lock);
}

static mlod_motion *wait_made(build_ctx *b, int k)
{
	pthread_mutex_lock(&b->lock);
	while (!b->made[k])
		pthread_cond_wait(&b->more, &b->lock);
	mlod_motion *m = b->kmotion[k];
	pthread_mutex_unlock(&b->lock);
	return m;
}

static void wait_keys(build_ctx *b, int k, int s)
{
	pthread_mutex_lock(&b->lock);
	while (b->published[k] <= s)
		pthread_cond_wait(&b->more, &b->lock);
	pthread_mutex_unlock(&b->lock);
}

/* The third way: the finisher hands over clip k's frames motion. */
static void set_fmade(build_ctx *b, int k, mlod_motion *m)
{
	pthread_mutex_lock(&b->lock);
	b->fmotion[k] = m;
	b->fmade[k] = 1;
	pthread_cond_broadcast(&b->more);
	pthread_mutex_unlock(&b->lock);
}

/* The third way: the finisher is done with clip k's level s (its limit
 * set), or its list ended at level stop. */
static void set_rounded(build_ctx *b, int k, int s, int stop)
{
	pthread_mutex_lock(&b->lock);
	b->rounded[k] = s;
	if (stop >= 0 && stop < b->fin_stop[k])
		b->fin_stop[k] = stop;
	pthread_cond_broadcast(&b->more);
	pthread_mutex_unlock(&b->lock);
}

/* Waits for the finisher's level s of clip k; 0 when its list ended
 * before it. */
static int wait_rounded(build_ctx *b, int k, int s)
{
	pthread_mutex_lock(&b->lock);
	while (b->rounded[k] <= s && b->fin_stop[k] > s)
		pthread_cond_wait(&b->more, &b->lock);
	int go = b->fin_stop[k] > s;
	pthread_mutex_unlock(&b->lock);
	return go;
}

static size_t chain_at(const build_ctx *b, int k, int i, int s)
{
	return ((size_t)k * (size_t)b->method_count + (size_t)i) * (size_t)b->spec_count + (size_t)s;
}

/* The second way, item 2k: the keys method's choice of keys of clip k,
 * level after level, into its chain (unfinished: not rounded, not
 * measured). */
static void keys_item(build_ctx *b, int k)
{
	int i = b->keys;
	size_t ci = (size_t)k * (size_t)b->method_count + (size_t)i;
	mlod_motion *m = NULL;
	b->create_result[ci] = motion_create_on(b->c, b->clips[k], b->opt, b->threads, &m, &b->create_error[ci]);
	if (b->create_result[ci] == MLOD_OK) {
		b->info[ci] = *mlod_motion_timeline_info(m);
		mlod_motion_set_threads(m, b->threads);
	}
	set_made(b, k, m);
	if (b->create_result[ci] == MLOD_OK) {
		for (int s = 0; s < b->spec_count && b->info[ci].frames >= 3; s++) {
			if (!skipped(MLOD_MOTION_KEYS, b->specs[s].target)) {
				size_t at = chain_at(b, k, i, s);
				mlod_result r = mlod_motion_keys_reduce(m, b->specs[s].target, b->specs[s].value, &b->chain[at],
				                                        &b->known[(size_t)k * (size_t)b->spec_count + (size_t)s],
				                                        &b->chain_error[at]);
				b->chain_result[at] = r;
				if (r != MLOD_OK && r != MLOD_ERR_LIMIT)
					break;
			}
			publish(b, k, s + 1);
		}
	}
	publish(b, k, b->spec_count); /* the rest will not come; m is the finisher's to free */
}

/* The second way, item 2k + 1: clip k's levels in the order
 * mlod_motion_next_level_best makes them (the last method first, each
 * later one limited by the bytes of the best finished level so far), the
 * keys method's from the keys item's choice, rounded and measured here. */
static void finish_item(build_ctx *b, int k)
{
	int n = b->method_count;
	mlod_motion *m[2] = { NULL, NULL }, *fin = NULL;
	size_t base = (size_t)k * (size_t)n;
	/* The other method's motion and the one the keys levels are rounded
	 * on: copies of the keys item's (mlod_motion_create_like reads only
	 * its setup, which the keys method does not change); when that could
	 * not be made, the other method fails as it would have. */
	mlod_motion *keys = wait_made(b, k);
	size_t ki = base + (size_t)b->keys;
	int made = keys != NULL;
	for (int i = 0; i < n; i++) {
		if (i == b->keys)
			continue;
		size_t ci = base + (size_t)i;
		if (!keys) {
			b->create_result[ci] = b->create_result[ki];
			b->create_error[ci] = b->create_error[ki];
			continue;
		}
		b->create_result[ci] = mlod_motion_create_like(keys, &m[i], &b->create_error[ci]);
		if (b->create_result[ci] != MLOD_OK)
			made = 0;
		else
			b->info[ci] = *mlod_motion_timeline_info(m[i]);
		mlod_motion_set_threads(m[i], b->threads);
	}
	if (made) {
		b->fin_result[k] = mlod_motion_create_like(keys, &fin, &b->fin_error[k]);
		made = b->fin_result[k] == MLOD_OK;
		mlod_motion_set_threads(fin, b->threads);
	}
	int frames = made ? mlod_motion_timeline_info(fin)->frames : 0;
	if (b->frames_own) {
		/* The frames method (index 0, after the keys method) is the
		 * frames item's, on its motion. */
		int use = made && frames >= 3;
		set_fmade(b, k, use ? m[0] : NULL);
		if (use)
			m[0] = NULL; /* the frames item's to free */
		else
			set_rounded(b, k, 0, 0);
	}
	int s_end = b->spec_count;
	for (int s = 0; s < b->spec_count && frames >= 3; s++) {
		const mlod_motion_spec *sp = &b->specs[s];
		long limit = -1; /* the best finished level's bytes so far */
		int stop = 0;
		for (int i = n - 1; i >= 0 && !stop; i--) {
			if (skipped(b->methods[i], sp->target))
				continue;
			if (b->frames_own && i != b->keys) {
				/* The frames item's, with this limit. */
				b->limit[(size_t)k * (size_t)b->spec_count + (size_t)s] = limit;
				set_rounded(b, k, s + 1, -1);
				continue;
			}
			size_t at = chain_at(b, k, i, s);
			mlod_result r;
			if (i == b->keys) {
				wait_keys(b, k, s);
				r = b->chain_result[at];
				if (r == NOT_BUILT) { /* the keys item stopped before it */
					stop = 1;
					break;
				}
				if (r == MLOD_OK)
					r = b->chain_result[at] =
						mlod_motion_keys_finish(fin, sp->target, sp->value, limit,
						                        b->known[(size_t)k * (size_t)b->spec_count + (size_t)s], &b->chain[at],
						                        &b->chain_error[at]);
			} else {
				r = b->chain_result[at] = mlod_motion_next_level_under(m[i], b->methods[i], sp->target, sp->value,
				                                                       limit, &b->chain[at], &b->chain_error[at]);
			}
			if (r == MLOD_OK && !b->chain[at].unfinished && (limit < 0 || b->chain[at].bytes < limit))
				limit = b->chain[at].bytes;
			if (r != MLOD_OK && r != MLOD_ERR_LIMIT)
				stop = 1; /* mlod_motion_next_level_best ends here */
		}
		if (stop) {
			s_end = s;
			break;
		}
		if (b->frames_own)
			set_rounded(b, k, s + 1, -1); /* also when the frames method is skipped here */
	}
	if (b->frames_own)
		set_rounded(b, k, b->rounded[k], s_end);
	for (int i = 0; i < n; i++)
		mlod_motion_free(m[i]);
	mlod_motion_free(fin);
	wait_keys(b, k, b->spec_count - 1); /* the keys item is done with its motion */
	mlod_motion_free(keys);
}

/* The third way, item 3k + 2: the frames method's levels of clip k
 * (method 0, which mlod_motion_next_level_best builds after the keys
 * method's), each with the limit the finisher hands over once it has
 * rounded the keys level: the finisher goes on to the next keys level
 * meanwhile. A frames level that fails ends its chain here, as it ends
 * mlod_motion_next_level_best's list (gather stops at its level). */
static void frames_item(build_ctx *b, int k)
{
	pthread_mutex_lock(&b->lock);
	while (!b->fmade[k])
		pthread_cond_wait(&b->more, &b->lock);
	mlod_motion *m = b->fmotion[k];
	pthread_mutex_unlock(&b->lock);
	for (int s = 0; m && s < b->spec_count; s++) {
		if (!wait_rounded(b, k, s))
			break;
		const mlod_motion_spec *sp = &b->specs[s];
		if (skipped(b->methods[0], sp->target))
			continue;
		size_t at = chain_at(b, k, 0, s);
		mlod_result r = b->chain_result[at] =
			mlod_motion_next_level_under(m, b->methods[0], sp->target, sp->value,
			                             b->limit[(size_t)k * (size_t)b->spec_count + (size_t)s], &b->chain[at],
			                             &b->chain_error[at]);
		if (r != MLOD_OK && r != MLOD_ERR_LIMIT)
			break;
	}
	mlod_motion_free(m);
}

static mlod_result split_item(void *ctx, int item)
{
	build_ctx *b = ctx;
	int per = b->frames_own ? 3 : 2;
	if (item % per == 0)
		keys_item(b, item / per);
	else if (item % per == 1)
		finish_item(b, item / per);
	else
		frames_item(b, item / per);
	return MLOD_OK;
}

/* The level mlod_motion_next_level_best would give from the chains' level
 * s of clip k (taking it over). */
static mlod_result choose(build_ctx *b, int k, int s, mlod_motion_level *out, mlod_error *err)
{
	int n = b->method_count, ok = 0, limited = -1;
	size_t base = (size_t)k * (size_t)n;
	mlod_error why = { 0 };
	memset(out, 0, sizeof *out);
	for (int i = n - 1; i >= 0; i--) {
		if (skipped(b->methods[i], b->specs[s].target))
			continue;
		size_t at = (base + (size_t)i) * (size_t)b->spec_count + (size_t)s;
		mlod_result r = b->chain_result[at];
		mlod_motion_level *l = &b->chain[at];
		if (r == MLOD_ERR_LIMIT) {
			why = b->chain_error[at], limited = i;
			continue;
		}
		if (r != MLOD_OK) {
			if (ok)
				mlod_motion_level_free(out);
			if (err)
				*err = b->chain_error[at];
			return r;
		}
		if (motion_best_take(out, &ok, l))
			memset(l, 0, sizeof *l); /* taken over */
	}
	return motion_best_end(ok, limited, &why, err);
}

/* Gathers clip k from its chains, in the order the first way meets
 * results and failures. */
static void gather(build_ctx *b, int k)
{
	mlod_motion_clip_levels *o = &b->out[k];
	int n = b->method_count;
	size_t base = (size_t)k * (size_t)n;
	for (int i = 0; i < n; i++)
		if (b->create_result[base + (size_t)i] != MLOD_OK) {
			o->result = b->create_result[base + (size_t)i];
			o->error = b->create_error[base + (size_t)i];
			return;
		}
	if (b->fin_result[k] != MLOD_OK) {
		o->result = b->fin_result[k];
		o->error = b->fin_error[k];
		return;
	}
	o->timeline = b->info[base];
	if (o->timeline.frames < 3)
		return;
	if (alloc_levels(o, b->spec_count) != MLOD_OK) {
		o->result = mlod_fail(&o->error, MLOD_ERR_NOMEM, "out of memory");
		return;
	}
	for (int s = 0; s < b->spec_count; s++) {
		o->level_count = s + 1;
		for (int i = 0; i < n; i++) {
			size_t at = (base + (size_t)i) * (size_t)b->spec_count + (size_t)s;
			if (!skipped(b->methods[i], b->specs[s].target) && b->chain_result[at] == NOT_BUILT) {
				/* An earlier level of this method failed, which ended
				 * the list there: not reached. */
				b->chain_result[at] = MLOD_ERR_NOMEM;
				mlod_fail(&b->chain_error[at], MLOD_ERR_NOMEM, "out of memory");
			}
		}
		o->results[s] = choose(b, k, s, &o->levels[s], &o->errors[s]);
		if (o->results[s] != MLOD_OK && o->results[s] != MLOD_ERR_LIMIT)
			break;
	}
}

mlod_result mlod_motion_build_levels(const mlod_character *c, const int *clips, int clip_count,
                                     const mlod_motion_options *opt, const mlod_motion_method *methods,
                                     int method_count, const mlod_motion_spec *specs, int spec_count, int threads,
                                     mlod_motion_clip_levels *out, mlod_error *err)
{
	if (!c || (!clips && clip_count > 0) || clip_count < 0 || !methods || method_count < 1 || method_count > 2 ||
	    (!specs && spec_count > 0) || spec_count < 0 || (!out && clip_count > 0))
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_motion_build_levels: bad arguments");
	if (clip_count == 0)
		return MLOD_OK;
	memset(out, 0, sizeof *out * (size_t)clip_count);
	build_ctx b;
	memset(&b, 0, sizeof b);
	b.c = c;
	b.clips = clips;
	b.opt = opt;
	b.methods = methods;
	b.method_count = method_count;
	b.specs = specs;
	b.spec_count = spec_count;
	b.out = out;
	b.threads = threads;
	b.keys = -1;
	for (int i = 0; i < method_count; i++)
		if (methods[i] == MLOD_MOTION_KEYS)
			b.keys = i;
	if (threads <= 1 || b.keys < 0 || clip_count >= threads) {
		mlod_parallel_for(clip_count, threads, clip_item, &b);
		return MLOD_OK;
	}
	size_t chains = (size_t)clip_count * (size_t)method_count, levels = chains * (size_t)spec_count;
	b.chain = calloc(levels + 1, sizeof *b.chain);
	b.chain_result = malloc(sizeof *b.chain_result * (levels + 1));
	b.chain_error = calloc(levels + 1, sizeof *b.chain_error);
	b.known = calloc((size_t)clip_count * (size_t)spec_count + 1, sizeof *b.known);
	b.fin_result = calloc((size_t)clip_count, sizeof *b.fin_result);
	b.fin_error = calloc((size_t)clip_count, sizeof *b.fin_error);
	b.create_result = calloc(chains, sizeof *b.create_result);
	b.create_error = calloc(chains, sizeof *b.create_error);
	b.info = calloc(chains, sizeof *b.info);
	b.published = calloc((size_t)clip_count, sizeof *b.published);
	b.kmotion = calloc((size_t)clip_count, sizeof *b.kmotion);
	b.made = calloc((size_t)clip_count, sizeof *b.made);
	/* The third way when the keys method comes last (it is built first)
	 * and the other one has its own item. */
	b.frames_own = method_count == 2 && b.keys == 1;
	int frames_ok = 1;
	if (b.frames_own) {
		b.fmotion = calloc((size_t)clip_count, sizeof *b.fmotion);
		b.fmade = calloc((size_t)clip_count, sizeof *b.fmade);
		b.limit = calloc((size_t)clip_count * (size_t)spec_count + 1, sizeof *b.limit);
		b.rounded = calloc((size_t)clip_count, sizeof *b.rounded);
		b.fin_stop = malloc(sizeof *b.fin_stop * (size_t)clip_count);
		frames_ok = b.fmotion && b.fmade && b.limit && b.rounded && b.fin_stop;
		for (int k = 0; frames_ok && k < clip_count; k++)
			b.fin_stop[k] = spec_count;
	}
	mlod_result r = MLOD_OK;
	int sync = 0;
	if (b.published && b.kmotion && b.made && pthread_mutex_init(&b.lock, NULL) == 0) {
		if (pthread_cond_init(&b.more, NULL) == 0)
			sync = 1;
		else
			pthread_mutex_destroy(&b.lock);
	}
	if (!b.chain || !b.chain_result || !b.chain_error || !b.known || !b.fin_result || !b.fin_error || !b.create_result || !b.create_error || !b.info || !sync || !frames_ok) {
		r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
	} else {
		for (size_t i = 0; i < levels; i++)
			b.chain_result[i] = NOT_BUILT;
		if (b.frames_own) /* one more worker per clip: the frames item waits on the finisher */
			mlod_parallel_for(3 * clip_count, threads + clip_count, split_item, &b);
		else
			mlod_parallel_for(2 * clip_count, threads, split_item, &b);
		for (int k = 0; k < clip_count; k++)
			gather(&b, k);
	}
	for (size_t i = 0; b.chain && i < levels; i++)
		mlod_motion_level_free(&b.chain[i]);
	free(b.chain);
	free(b.chain_result);
	free(b.chain_error);
	free(b.known);
	free(b.fin_result);
	free(b.fin_error);
	free(b.create_result);
	free(b.create_error);
	free(b.info);
	free(b.published);
	free(b.kmotion);
	free(b.made);
	free(b.fmotion);
	free(b.fmade);
	free(b.limit);
	free(b.rounded);
	free(b.fin_stop);
	if (sync) {
		pthread_cond_destroy(&b.more);
		pthread_mutex_destroy(&b.lock);
	}
	return r;
}

void mlod_motion_clip_levels_free(mlod_motion_clip_levels *out, int count)
{
	for (int k = 0; out && k < count; k++) {
		for (int s = 0; out[k].levels && s < out[k].level_count; s++)
			if (out[k].results[s] == MLOD_OK)
				mlod_motion_level_free(&out[k].levels[s]);
		free(out[k].levels);
		free(out[k].results);
		free(out[k].errors);
		memset(&out[k], 0, sizeof out[k]);
	}
}
