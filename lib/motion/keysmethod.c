/*
 * keysmethod.c: the keys method, levels as selections of keys of the
 * common clip, driven the same way as the frames method (framesmethod.c)
 * with the key reduction's error budget (keyreduce.c) in place of the
 * threshold: for an error bound, the budget is the part of the bound the
 * keys may spend (precision.c), retried smaller when float rounding lets
 * the measured error pass the bound; for a fraction of the keys, a
 * bisection on the budget. Each level starts from the keys the previous
 * one kept; its values are then rounded and measured (precision.c).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "motion/motion_internal.h"

#define KEYS_RETRIES 6

static double point_distance(const mlod_motion *m)
{
	return m->opt.point_distance > 0.0 ? m->opt.point_distance : mlod_motion_point_distance(m->s, 0);
}

/* Runs the key reduction with budget from the current keys into kept;
 * returns the clip's largest error, or -1 with err set. */
static double keys_try(mlod_motion *m, double budget, unsigned char *kept, mlod_clip *clip, mlod_error *err)
{
	size_t size = (size_t)m->common.channel_count * (size_t)m->frames;
	memcpy(kept, m->kept, size);
	memset(clip, 0, sizeof *clip);
	double e = -1.0;
	if (keyreduce_run(m->s, m->orig, &m->common, budget, point_distance(m), m->sub, kept, m->cache0, &e, &m->scratch,
	                  &m->kstate, m->threads, err) != MLOD_OK)
		return -1.0;
	if (motion_clip_from_kept(m, kept, clip) != 0) {
		mlod_clip_free(clip);
		mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
		return -1.0;
	}
	/* keyreduce measured the clip as motion_level_max_error does, unless it
	 * could not. */
	return e >= 0.0 && m->clip_end_ok ? e : motion_level_max_error(m, clip);
}

/* The keys method's next level up to its rounding: the keys kept (out's
 * clip, method and threshold; the rest zero), which the next level builds
 * on; *known gets the clip's motion_level_max_error. */
mlod_result motion_keys_reduce(mlod_motion *m, mlod_motion_target target, double value, mlod_motion_level *out,
                               double *known, mlod_error *err)
{
	char q[MLOD_NAME_TEXT_SIZE]; /* the clip's name in a message */
	if (target == MLOD_MOTION_THRESHOLD)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "thresholds are frame distances: they need the frames method");
	size_t size = (size_t)m->common.channel_count * (size_t)m->frames;
	unsigned char *kept = malloc(size), *best = malloc(size);
	mlod_clip clip, best_clip;
	double best_budget = -1.0, best_error = -1.0; /* best_clip's motion_level_max_error */
	memset(&best_clip, 0, sizeof best_clip);
	mlod_result r = MLOD_OK;
	if (!kept || !best) {
		free(kept);
		free(best);
		return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
	}
	if (target == MLOD_MOTION_MAX_ERROR) {
		/* The budget bounds a stricter metric; retry smaller if float
		 * rounding lets the measured error pass the bound. */
		double budget = motion_removal_bound(m, value) * (1.0 - 1e-5);
		for (int t = 0; t < KEYS_RETRIES && best_budget < 0.0; t++, budget *= 0.9) {
			double e = keys_try(m, budget, kept, &clip, err);
			if (e < 0.0) {
				r = err ? err->code : MLOD_ERR_NOMEM;
				break;
			}
			if (e <= value) {
				memcpy(best, kept, size);
				best_clip = clip;
				best_budget = budget;
				best_error = e;
			} else {
				mlod_clip_free(&clip);
			}
		}
		if (r == MLOD_OK && best_budget < 0.0) {
			mlod_clip c0;
			double e = keys_try(m, 0.0, kept, &c0, err);
			mlod_clip_free(&c0);
			r = mlod_fail(err, MLOD_ERR_LIMIT, "clip %s: no keys level within %g: the %s already deviates by %g",
			              mlod_name_text(m->orig->name, 1, q, sizeof q), value, m->info.resampled ? "resampled clip" : "previous level", e);
		}
	} else {
		long target_keys = (long)floor(value * (double)mlod_clip_key_count(m->orig));
		double lo = 0.0, hi = m->height;
		/* Grow hi until it reaches the target (or everything is constant). */
		for (int g = 0; g < 12 && r == MLOD_OK; g++) {
			double e = keys_try(m, hi, kept, &clip, err);
			if (e < 0.0) {
				r = err ? err->code : MLOD_ERR_NOMEM;
				break;
			}
			long keys = mlod_clip_key_count(&clip);
			mlod_clip_free(&best_clip);
			memcpy(best, kept, size);
			best_clip = clip;
			best_budget = hi;
			best_error = e;
			if (keys <= target_keys)
				break;
			lo = hi;
			hi *= 4.0;
		}
		for (int step = 0; step < MOTION_SEARCH_STEPS / 2 && r == MLOD_OK && mlod_clip_key_count(&best_clip) <= target_keys;
		     step++) {
			double mid = 0.5 * (lo + hi);
			double e = keys_try(m, mid, kept, &clip, err);
			if (e < 0.0) {
				r = err ? err->code : MLOD_ERR_NOMEM;
				break;
			}
			if (mlod_clip_key_count(&clip) <= target_keys) {
				mlod_clip_free(&best_clip);
				memcpy(best, kept, size);
				best_clip = clip;
				best_budget = mid;
				best_error = e;
				hi = mid;
			} else {
				mlod_clip_free(&clip);
				lo = mid;
			}
		}
	}
	free(kept);
	if (r != MLOD_OK) {
		free(best);
		mlod_clip_free(&best_clip);
		return r;
	}
	memset(out, 0, sizeof *out);
	out->method = MLOD_MOTION_KEYS;
	out->threshold = best_budget;
	out->clip = best_clip;
	free(m->kept);
	m->kept = best;
	*known = best_error;
	return MLOD_OK;
}

/* The keys level's rounding and measures (motion_level_finish); m may be any
 * motion of the clip with the same options (the rounding reads only the
 * setup, not the keys method's state). Frees the level on a failure. */
mlod_result motion_keys_finish(mlod_motion *m, mlod_motion_target target, double value, long max_bytes, double known,
                               mlod_motion_level *l, mlod_error *err)
{
	mlod_result r = motion_level_finish(m, l, target == MLOD_MOTION_MAX_ERROR ? value : -1.0, max_bytes, known, err);
	if (r != MLOD_OK)
		mlod_motion_level_free(l);
	return r;
}

mlod_result motion_keys_level(mlod_motion *m, mlod_motion_target target, double value, long max_bytes,
                              mlod_motion_level *out, mlod_error *err)
{
	double known = -1.0;
	mlod_result r = motion_keys_reduce(m, target, value, out, &known, err);
	return r != MLOD_OK ? r : motion_keys_finish(m, target, value, max_bytes, known, out, err);
}
