/*
 * framesmethod.c: the frames method, levels as lines of the
 * multiresolution motion tree (motiontree.c).
 *
 * Levels are chosen by threshold, by the fraction of keys kept
 * (bisection on the threshold), or by an error bound (bisection on the
 * threshold, accepting only thresholds whose level measures within the
 * bound at every sample of the common timeline: levelerror.c). Removal
 * measured better than averaging (bench/RESULTS.md) and is the default.
 * The next level builds on the last line chosen; a level that cannot win
 * under a byte limit is left unfinished. Its values are then rounded and
 * measured (precision.c).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "motion/motion_internal.h"

/* motion_level_within for the clip c of line l (motion_clip_from_line),
 * through the segment memo: every channel of c is keyed at the line's frames
 * (or constant), so its pose at the samples from frame p up to the next frame
 * q of the line (the last sample too when q is the last frame) depends on p
 * and q alone. The bisection on the threshold tries lines that share most of
 * their segments. The memo holds one bound: motion_frames_level clears it. */
static int line_within(mlod_motion *m, const motion_line *l, const mlod_clip *c, double bound)
{
	int usable = m->sub > 0 && c->duration >= m->common.channels[0].times[m->frames - 1] && l->n >= 2 &&
	             l->v[0].frame == 0 && l->v[l->n - 1].frame == m->frames - 1;
	for (int k = 0; usable && k < l->n; k++)
		usable = l->v[k].frame >= 0 && (k == 0 || l->v[k].frame > l->v[k - 1].frame);
	if (!usable)
		return motion_level_within(m, c, bound);
	for (int k = 0; k + 1 < l->n; k++) {
		int p = l->v[k].frame, q = l->v[k + 1].frame;
		double v;
		if (motion_memo_get(m->segmemo, p, q, -3, &v)) {
			if (v == 0.0)
				return 0;
			continue;
		}
		int hi = q == m->frames - 1 ? m->samples - 1 : q * m->sub - 1;
		int ok = motion_level_within_range(m, c, bound, p * m->sub, hi);
		motion_memo_put(m->segmemo, p, q, -3, ok);
		if (!ok)
			return 0;
	}
	return 1;
}

/* The frames method: the next line of the tree, by threshold, by the
 * fraction of keys kept or by an error bound. */
mlod_result motion_frames_level(mlod_motion *m, mlod_motion_target target, double value, long max_bytes,
                                mlod_motion_level *out, mlod_error *err)
{
	if (motion_tree_start(m) != 0)
		return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
	motion_line best = { 0, NULL };
	double T = 0.0;
	char q[MLOD_NAME_TEXT_SIZE]; /* the clip's name in a message */
	motion_memo_clear(m->segmemo);
	if (target == MLOD_MOTION_THRESHOLD) {
		T = value;
		if (motion_tree_level(m, &m->tree, T, &best) != 0)
			return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
	} else {
		/* Bisection on T: lo is acceptable, hi is not (or is the top). */
		/* The same tree's sum again at the next level, when this one is
		 * left unfinished (on CMU 01_01 every frames level: 2 x 2,751
		 * node distances saved). */
		if (!(m->tree_total >= 0.0))
			m->tree_total = motion_line_distance(m, &m->tree);
		double hi = 2.0 * m->tree_total + 1e-9, lo = 0.0;
		long budget = target == MLOD_MOTION_FRACTION ? (long)floor(value * (double)mlod_clip_key_count(m->orig)) : 0;
		for (int step = 0; step <= MOTION_SEARCH_STEPS; step++) {
			double t = step == 0 ? hi : 0.5 * (lo + hi);
			motion_line l = { 0, NULL };
			if (motion_tree_level(m, &m->tree, t, &l) != 0)
				return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
			int ok;
			if (target == MLOD_MOTION_FRACTION) {
				ok = motion_line_keys(m, &l) <= budget; /* here "ok" means small enough: search the smallest T */
			} else {
				mlod_clip c;
				if (motion_clip_from_line(m, &l, &c) != 0) {
					mlod_clip_free(&c);
					motion_line_free(&l);
					motion_line_free(&best);
					return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
				}
				ok = line_within(m, &l, &c, motion_removal_bound(m, value));
				if (!ok && max_bytes >= 0 && motion_least_bytes(m, &c) > max_bytes) {
					/* The level would be finer than this line, so larger
					 * (the tree's lines grow finer as the threshold goes
					 * down): it cannot win. Left unfinished; the next
					 * frames level builds on the last finished one. */
					memset(out, 0, sizeof *out);
					out->method = MLOD_MOTION_FRAMES;
					out->threshold = t;
					out->keys = mlod_clip_key_count(&c);
					out->bytes = motion_least_bytes(m, &c);
					out->unfinished = 1;
					mlod_clip_free(&c);
					motion_line_free(&l);
					motion_line_free(&best);
					return MLOD_OK;
				}
				mlod_clip_free(&c);
			}
			if (target == MLOD_MOTION_FRACTION) {
				if (ok) {
					motion_line_free(&best);
					best = l;
					T = t;
					hi = t;
				} else {
					motion_line_free(&l);
					lo = t;
				}
				if (step == 0 && !ok)
					break; /* even merging everything keeps too many: take the coarsest */
			} else {
				if (ok) {
					motion_line_free(&best);
					best = l;
					T = t;
					lo = t;
					if (step == 0)
						break;
				} else {
					motion_line_free(&l);
					hi = t;
				}
			}
		}
		if (!best.v) {
			/* Fraction: even the top is too many keys, so take it; error: T = 0,
			 * the previous line, whose error must be within the bound. */
			T = target == MLOD_MOTION_FRACTION ? hi : 0.0;
			if (motion_tree_level(m, &m->tree, T, &best) != 0)
				return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
			if (target == MLOD_MOTION_MAX_ERROR) {
				mlod_clip c;
				int bad = motion_clip_from_line(m, &best, &c) != 0;
				double e = bad ? 0.0 : motion_level_max_error(m, &c);
				mlod_clip_free(&c);
				if (bad) {
					motion_line_free(&best);
					return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
				}
				if (!(e <= value)) {
					motion_line_free(&best);
					return mlod_fail(err, MLOD_ERR_LIMIT,
					                 "clip %s: no frames level within %g: the %s already deviates by %g",
					                 mlod_name_text(m->orig->name, 1, q, sizeof q),
					                 value, m->info.resampled ? "resampled clip" : "previous level", e);
				}
			}
		}
	}
	memset(out, 0, sizeof *out);
	out->method = MLOD_MOTION_FRAMES;
	out->threshold = T;
	if (motion_clip_from_line(m, &best, &out->clip) != 0) {
		motion_line_free(&best);
		mlod_motion_level_free(out);
		return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
	}
	motion_line_free(&m->tree);
	m->tree = best;
	m->tree_total = -1.0;
	mlod_result r = motion_level_finish(m, out, target == MLOD_MOTION_MAX_ERROR ? value : -1.0, max_bytes, -1.0, err);
	if (r != MLOD_OK)
		mlod_motion_level_free(out);
	return r;
}
