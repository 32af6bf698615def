/*
 * nextlevel.c: the public level calls of a motion: the next level of a
 * method (the frames method, framesmethod.c, or the keys method,
 * keysmethod.c), the keys method in its two halves (its choice of keys,
 * its rounding and measures: levels.c overlaps them on threads), and the
 * best level of several methods, the smallest in bytes (ties to the
 * smaller error). A clip without joint channels has empty levels.
 */
#include <math.h>
#include <string.h>

#include "motion/motion_internal.h"

mlod_result mlod_motion_next_level(mlod_motion *m, mlod_motion_method method, mlod_motion_target target,
                                   double value, mlod_motion_level *out, mlod_error *err)
{
	return mlod_motion_next_level_under(m, method, target, value, -1, out, err);
}

static mlod_result level_args(const mlod_motion *m, mlod_motion_target target, double value, mlod_motion_level *out,
                              mlod_error *err)
{
	if (!m || !out)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_motion_next_level: NULL argument");
	memset(out, 0, sizeof *out);
	if (!(value >= 0.0) || !isfinite(value) || (target == MLOD_MOTION_FRACTION && value > 1.0))
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "bad level value %g", value);
	if ((unsigned)target > MLOD_MOTION_MAX_ERROR)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "bad level target %d", (int)target);
	return MLOD_OK;
}

/* Every level of a clip without joint channels (no frames): the clip
 * with no channels, no keys, no error. */
static mlod_result empty_level(const mlod_motion *m, mlod_motion_method method, mlod_motion_level *out,
                               mlod_error *err)
{
	memset(out, 0, sizeof *out);
	if (motion_level_clip_init(m, &out->clip) != 0) {
		mlod_clip_free(&out->clip);
		return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
	}
	out->method = method;
	return MLOD_OK;
}

mlod_result mlod_motion_keys_reduce(mlod_motion *m, mlod_motion_target target, double value, mlod_motion_level *out,
                                    double *known, mlod_error *err)
{
	mlod_result r = level_args(m, target, value, out, err);
	if (r == MLOD_OK && !known)
		r = mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_motion_keys_reduce: NULL argument");
	if (r == MLOD_OK && m->frames == 0) {
		*known = 0.0;
		return empty_level(m, MLOD_MOTION_KEYS, out, err);
	}
	return r != MLOD_OK ? r : motion_keys_reduce(m, target, value, out, known, err);
}

mlod_result mlod_motion_keys_finish(mlod_motion *m, mlod_motion_target target, double value, long max_bytes,
                                    double known, mlod_motion_level *l, mlod_error *err)
{
	if (!m || !l || l->method != MLOD_MOTION_KEYS)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_motion_keys_finish: bad arguments");
	if (l->clip.channel_count != m->common.channel_count)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_motion_keys_finish: the level is not of this clip");
	if (m->frames == 0)
		return MLOD_OK; /* empty_level: nothing to round or measure */
	return motion_keys_finish(m, target, value, max_bytes, known, l, err);
}

mlod_result mlod_motion_next_level_under(mlod_motion *m, mlod_motion_method method, mlod_motion_target target,
                                         double value, long max_bytes, mlod_motion_level *out, mlod_error *err)
{
	mlod_result r = level_args(m, target, value, out, err);
	if (r != MLOD_OK)
		return r;
	if (m->frames == 0 && (method == MLOD_MOTION_FRAMES || method == MLOD_MOTION_KEYS))
		return empty_level(m, method, out, err);
	switch (method) {
	case MLOD_MOTION_FRAMES: return motion_frames_level(m, target, value, max_bytes, out, err);
	case MLOD_MOTION_KEYS: return motion_keys_level(m, target, value, max_bytes, out, err);
	}
	return mlod_fail(err, MLOD_ERR_INVALID_ARG, "bad method %d", (int)method);
}

int mlod_motion_method_applies(mlod_motion_method method, mlod_motion_target target)
{
	return !(method == MLOD_MOTION_KEYS && target == MLOD_MOTION_THRESHOLD);
}

int mlod_motion_level_wins(const mlod_motion_level *l, const mlod_motion_level *best, int have)
{
	return !l->unfinished &&
	       (!have || l->bytes < best->bytes || (l->bytes == best->bytes && !(best->error.max < l->error.max)));
}

int motion_best_take(mlod_motion_level *best, int *have, mlod_motion_level *l)
{
	if (!mlod_motion_level_wins(l, best, *have))
		return 0;
	if (*have)
		mlod_motion_level_free(best);
	*best = *l;
	*have = 1;
	return 1;
}

mlod_result motion_best_end(int have, int limited, const mlod_error *why, mlod_error *err)
{
	if (have)
		return MLOD_OK;
	if (limited < 0)
		return mlod_fail(err, MLOD_ERR_LIMIT, "no method makes a level for this target");
	if (err)
		*err = *why;
	return MLOD_ERR_LIMIT;
}

mlod_result mlod_motion_next_level_best(mlod_motion *const *m, const mlod_motion_method *methods, int n,
                                        mlod_motion_target target, double value, mlod_motion_level *out,
                                        mlod_error *err)
{
	if (!m || !methods || !out || n < 1)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_motion_next_level_best: bad arguments");
	memset(out, 0, sizeof *out);
	int ok = 0, limited = -1;
	mlod_error why = {0};
	for (int i = n - 1; i >= 0; i--) {
		if (!mlod_motion_method_applies(methods[i], target))
			continue;
		mlod_motion_level l;
		mlod_error e = {0};
		mlod_result r = mlod_motion_next_level_under(m[i], methods[i], target, value, ok ? out->bytes : -1, &l, &e);
		if (r == MLOD_ERR_LIMIT) {
			why = e, limited = i; /* ends with the earliest method's reason */
			continue;
		}
		if (r != MLOD_OK) {
			if (ok)
				mlod_motion_level_free(out);
			if (err)
				*err = e;
			return r;
		}
		if (!motion_best_take(out, &ok, &l))
			mlod_motion_level_free(&l);
	}
	return motion_best_end(ok, limited, &why, err);
}
