/*
 * packmotion.c: the motion levels and their MOTION chunks: level 0, the
 * levels by bound, the rotation lattice and its shifts, the keys as
 * encoded (packwrite_internal.h).
 */
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pack/packwrite_internal.h"

/* ------------------------------------------------------------------ */
/* Motion                                                              */
/* ------------------------------------------------------------------ */

static int double_asc(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return (x > y) - (x < y);
}

double pack_motion_point_distance(const struct ctx *x)
{
	/* A BVH, or a glb made from one (its record's source): the BVH rule. */
	return x->opt->point_distance > 0.0
	           ? x->opt->point_distance
	           : mlod_motion_point_distance(&x->v.skeleton, !mlod_record_from_bvh(&x->rec, x->format));
}

/* Level 0 of each clip: the clip as read, or (unless lossless_motion or a
 * zero bound) the level lib/motion builds from it within the level-0
 * bound, methods and precision as for the coarser levels (fewer bytes
 * wins). The same for computed and piped levels, which are made from the
 * clip as read too. A clip keeps its keys as read when it has fewer than 3
 * frames, when no level meets the bound (a resampled cubic clip that
 * deviates more) or when the level would not have fewer key bytes. */
static mlod_result motion_level0(struct ctx *x)
{
	const mlod_character *c = &x->v;
	for (int q = 0; q < c->clip_count; q++)
		x->clips[q].level0 = &c->clips[q];
	double e0 = x->opt->motion_level0_percent ? x->opt->motion_level0_error * x->height / 100.0
	                                          : x->opt->motion_level0_error;
	/* A clip that is a pack's level 0 (mlod-pack -x: motion_level0 in its
	 * record) keeps its keys and that pack's error: reducing it again
	 * would stack a second error on the first. */
	unsigned char *packed = calloc((size_t)c->clip_count + 1, 1);
	if (!packed)
		return mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
	for (int q = 0; x->doc && q < c->clip_count; q++) {
		double pe = 0.0;
		int found = 0;
		mlod_result rr = c->clips[q].gltf_index >= 0
		                     ? mlod_record_read_motion0(x->doc, c->clips[q].gltf_index, &pe, &found, x->err)
		                     : MLOD_OK;
		if (rr != MLOD_OK) {
			free(packed);
			return rr;
		}
		if (found) {
			packed[q] = 1;
			x->clips[q].packed = 1;
			x->clips[q].error0 = (float)pe;
		}
	}
	if (c->clip_count == 0 || x->opt->lossless_motion || !(e0 > 0.0)) {
		free(packed);
		return MLOD_OK;
	}
	x->level0_owned = calloc((size_t)c->clip_count, sizeof *x->level0_owned);
	if (!x->level0_owned) {
		free(packed);
		return mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
	}
	mlod_motion_options mo = {0};
	mo.point_distance = pack_motion_point_distance(x);
	mo.precision = MLOD_MOTION_PRECISION_FULL; /* every level keeps the clip's own values (mlod(5) MOTION levels) */
	mlod_result r = MLOD_OK;
	int kept = 0;
	for (int q = 0; r == MLOD_OK && q < c->clip_count; q++) {
		mlod_motion *m[2] = {NULL, NULL};
		if (packed[q])
			continue;
		for (int i = 0; r == MLOD_OK && i < 2; i++)
			r = i == 0 ? mlod_motion_create(c, q, &mo, &m[i], x->err) : mlod_motion_create_like(m[0], &m[i], x->err);
		if (r == MLOD_OK && mlod_motion_timeline_info(m[0])->frames >= 3) {
			static const mlod_motion_method methods[2] = {MLOD_MOTION_FRAMES, MLOD_MOTION_KEYS};
			mlod_motion_level best;
			mlod_error why = {0};
			mlod_result e = mlod_motion_next_level_best(m, methods, 2, MLOD_MOTION_MAX_ERROR, e0, &best, &why);
			if (e == MLOD_OK && best.keys < mlod_clip_key_count(&c->clips[q])) {
				x->level0_owned[q] = best;
				x->clips[q].level0 = &x->level0_owned[q].clip;
				x->clips[q].error0 = (float)best.error.max;
				x->clips[q].bound0 = e0;
			} else if (e == MLOD_OK || e == MLOD_ERR_LIMIT) {
				if (e == MLOD_OK)
					mlod_motion_level_free(&best);
				kept++;
			} else {
				if (x->err)
					*x->err = why;
				r = e;
			}
		} else if (r == MLOD_OK) {
			kept++;
		}
		for (int i = 0; i < 2; i++)
			mlod_motion_free(m[i]);
	}
	if (r == MLOD_OK && kept) {
		char text[96];
		snprintf(text, sizeof text, "%d clip(s) keep every key at motion level 0", kept);
		pack_note(x, text);
	}
	int npacked = 0;
	for (int q = 0; q < c->clip_count; q++)
		npacked += packed[q];
	if (r == MLOD_OK && npacked) {
		char text[96];
		snprintf(text, sizeof text, "%d clip(s) are a pack's motion level 0: kept as they are", npacked);
		pack_note(x, text);
	}
	free(packed);
	return r;
}

mlod_result pack_motion_levels(struct ctx *x)
{
	const mlod_character *c = &x->v;
	mlod_result r = MLOD_OK;
	x->clips = calloc((size_t)c->clip_count + 1, sizeof *x->clips);
	if (!x->clips)
		return mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
	if ((r = motion_level0(x)) != MLOD_OK)
		return r;
	if (c->clip_count == 0 || x->opt->no_motion_levels)
		return MLOD_OK;
	/* The input's levels: "<clip>@lod<k>" animations with a record. */
	int from_input = 0;
	for (int i = 0; r == MLOD_OK && x->doc && i < x->in->clip_count; i++) {
		mlod_record_motion_level ml;
		int found = 0;
		if (x->in->clips[i].gltf_index < 0)
			continue;
		if ((r = mlod_record_read_motion(x->doc, x->in->clips[i].gltf_index, &ml, &found, x->err)) != MLOD_OK ||
		    !found)
			continue;
		for (int q = 0; q < c->clip_count; q++)
			if (c->clips[q].gltf_index == ml.source_animation && ml.level >= 1 &&
			    ml.level <= MLOD_PACK_MAX_MOTION_LEVELS) {
				struct clip_levels *cl = &x->clips[q];
				if (!ml.has_pack_error && ml.missing_joint_error)
					return mlod_fail(x->err, MLOD_ERR_PARSE,
					                 "animation %d: extras.mlod: no error (pack_error or joint_error)",
					                 x->in->clips[i].gltf_index);
				cl->clip[ml.level - 1] = &x->in->clips[i];
				cl->error[ml.level - 1] = (float)(ml.has_pack_error ? ml.pack_error : ml.joint_error.max);
				cl->bound[ml.level - 1] = ml.has_bound && !ml.has_pack_error ? ml.bound : 0.0;
				cl->count = ml.level > cl->count ? ml.level : cl->count;
				from_input = 1;
			}
	}
	if (r != MLOD_OK)
		return r;
	for (int q = 0; q < c->clip_count; q++) /* an unpacked pack's clips: its levels, maybe none */
		from_input |= x->clips[q].packed;
	if (from_input) {
		x->st->motion.from_input = 1;
		for (int q = 0; q < c->clip_count; q++) { /* a gap repeats the finer level */
			struct clip_levels *cl = &x->clips[q];
			int gap = 0;
			for (int k = 0; k < cl->count; k++)
				if (!cl->clip[k]) {
					cl->clip[k] = k ? cl->clip[k - 1] : cl->level0;
					cl->error[k] = k ? cl->error[k - 1] : cl->error0;
					gap = 1;
				}
			/* levels held to their bounds (motion_hold) only when every
			 * one has its bound, in increasing order, as mlod-motion's */
			for (int k = 0; k < cl->count; k++)
				gap |= !(cl->bound[k] > (k ? cl->bound[k - 1] : 0.0));
			for (int k = 0; gap && k < cl->count; k++)
				cl->bound[k] = 0.0;
		}
		return MLOD_OK;
	}
	/* Computed: per bound, the frames and keys methods; fewer bytes wins. */
	int nb = x->opt->motion_bound_count;
	double bounds[MLOD_PACK_MAX_MOTION_LEVELS];
	for (int b = 0; b < nb; b++)
		bounds[b] = x->opt->motion_percent[b] ? x->opt->motion_bounds[b] * x->height / 100.0 : x->opt->motion_bounds[b];
	qsort(bounds, (size_t)nb, sizeof *bounds, double_asc);
	mlod_motion_options mo = {0};
	mo.point_distance = pack_motion_point_distance(x);
	mo.precision = MLOD_MOTION_PRECISION_FULL; /* every level keeps the clip's own values (mlod(5) MOTION levels) */
	x->owned_levels = calloc((size_t)c->clip_count * (size_t)(nb > 0 ? nb : 1), sizeof *x->owned_levels);
	if (!x->owned_levels)
		return mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
	int short_clips = 0, missed = 0;
	for (int q = 0; r == MLOD_OK && q < c->clip_count; q++) {
		mlod_motion *m[2] = {NULL, NULL};
		for (int i = 0; r == MLOD_OK && i < 2; i++)
			r = i == 0 ? mlod_motion_create(c, q, &mo, &m[i], x->err) : mlod_motion_create_like(m[0], &m[i], x->err);
		mlod_error fit = {0};
		if (r == MLOD_OK && mlod_motion_timeline_info(m[0])->frames < 3)
			short_clips++;
		else if (r == MLOD_OK && nb > 0 &&
		         mlod_motion_keys_fit(c->skeleton.joint_count, mlod_motion_timeline_info(m[0])->frames,
		                              MLOD_DEFAULT_SUBDIVIDE, c->clips[q].name, &fit) != MLOD_OK) {
			char text[MLOD_ERROR_MESSAGE_SIZE + 80];
			snprintf(text, sizeof text, "the keys method is left out, the levels come from the frames method alone: %s",
			         fit.message);
			pack_warn(x, text);
		}
		if (r == MLOD_OK && mlod_motion_timeline_info(m[0])->frames >= 3)
			for (int b = 0; r == MLOD_OK && b < nb; b++) {
				static const mlod_motion_method methods[2] = {MLOD_MOTION_FRAMES, MLOD_MOTION_KEYS};
				mlod_motion_level best;
				mlod_error why = {0};
				mlod_result e = mlod_motion_next_level_best(m, methods, 2, MLOD_MOTION_MAX_ERROR, bounds[b], &best, &why);
				if (e == MLOD_ERR_LIMIT) {
					missed++;
					continue;
				}
				if (e != MLOD_OK) {
					if (x->err)
						*x->err = why;
					r = e;
					break;
				}
				struct clip_levels *cl = &x->clips[q];
				x->owned_levels[x->owned_count] = best;
				cl->clip[cl->count] = &x->owned_levels[x->owned_count++].clip;
				cl->bound[cl->count] = bounds[b];
				cl->error[cl->count++] = (float)best.error.max;
			}
		for (int i = 0; i < 2; i++)
			mlod_motion_free(m[i]);
	}
	if (short_clips) {
		char text[96];
		snprintf(text, sizeof text, "%d clip(s) with fewer than 3 frames: no motion levels", short_clips);
		pack_note(x, text);
	}
	if (missed) {
		char text[96];
		snprintf(text, sizeof text, "%d motion level(s) met no bound", missed);
		pack_warn(x, text);
	}
	return r;
}

/* 1 when a non-cubic channel's keys all hold one value (bit for bit). */
static int constant_channel(const mlod_channel *ch)
{
	if (ch->interp == MLOD_INTERP_CUBICSPLINE || ch->key_count < 2)
		return 0;
	int comps = ch->path == MLOD_PATH_ROTATION ? 4 : 3;
	for (int k = 1; k < ch->key_count; k++)
		if (memcmp(ch->values + (size_t)comps * k, ch->values, sizeof(float) * (size_t)comps) != 0)
			return 0;
	return 1;
}

/* 1 when every time t of the arrays is within tol * max(|t|, step) of
 * (float)(tick * step) for a tick in 0..UINT32_MAX (tol 0: exactly), and
 * the ticks and their times increase strictly; *max_tick is the largest. */
static int ticks_fit(const float *const *arr, const int *cnt, int n, double step, double tol, uint32_t *max_tick)
{
	uint32_t mx = 0;
	if (!(step > 0) || !isfinite(step))
		return 0;
	for (int a = 0; a < n; a++) {
		float prev = 0;
		for (int k = 0; k < cnt[a]; k++) {
			double q = floor((double)arr[a][k] / step + 0.5);
			if (!(q >= 0 && q <= 4294967295.0))
				return 0;
			float t = (float)(q * step);
			double lim = tol * (fabs((double)arr[a][k]) > step ? fabs((double)arr[a][k]) : step);
			if (tol == 0 ? t != arr[a][k] : !(fabs((double)t - arr[a][k]) <= lim))
				return 0;
			if (k > 0 && !(t > prev))
				return 0;
			prev = t;
			mx = (uint32_t)q > mx ? (uint32_t)q : mx;
		}
	}
	*max_tick = mx;
	return 1;
}

/* The time step of a chunk's key-time arrays, or 0 to keep them f32. The
 * candidates: 1 / the nearest whole frame rate to the smallest key
 * interval d; the smallest positive key time (a clip sampled as
 * (float)(k * step)); the largest time over its whole number of d; d.
 * The first that gives every time back exactly wins; else, unless exact,
 * the first within MLOD_PACK_TICK_TOLERANCE (times summed frame by frame
 * in f32). A chunk with a STEP channel asks for exact times: a STEP
 * channel jumps at its key times, so a key read back a hair late gives
 * the key before at the key's own time (the whole step's error there). */
static double time_step(const float *const *arr, const int *cnt, int n, int exact, uint32_t *max_tick)
{
	double d = 0, first = 0, last = 0;
	for (int a = 0; a < n; a++)
		for (int k = 0; k < cnt[a]; k++) {
			double t = arr[a][k], e = k > 0 ? t - (double)arr[a][k - 1] : 0;
			if (e > 0 && (d == 0 || e < d))
				d = e;
			if (t > 0 && (first == 0 || t < first))
				first = t;
			last = t > last ? t : last;
		}
	if (d == 0)
		return 0;
	double fps = floor(1.0 / d + 0.5), frames = floor(last / d + 0.5);
	double cand[5] = {fps >= 1 && fps <= 100000 ? 1.0 / fps : 0, first, frames >= 1 ? last / frames : 0,
	                  frames >= 1 ? (double)(float)(last / frames) : 0, d};
	for (int pass = 0; pass < (exact ? 1 : 2); pass++)
		for (int i = 0; i < 5; i++)
			if (cand[i] > 0 && ticks_fit(arr, cnt, n, cand[i], pass ? MLOD_PACK_TICK_TOLERANCE : 0, max_tick))
				return cand[i];
	return 0;
}

/* A rotation key's lattice value the reader rebuilds (mlod(5) ROTQ): the
 * component big from the three others n (big's own entry ignored), as
 * lib/motion rounds onto the lattice of normalised shorts. */
static long rotq_big(const long *n, int big)
{
	double sum = 0.0;
	for (int c = 0; c < 4; c++)
		if (c != big) {
			float f = (float)((double)n[c] / 32767.0);
			sum += (double)f * f;
		}
	return lrint(sqrt(sum < 1.0 ? 1.0 - sum : 0.0) * 32767.0);
}

/* One 'ROTQ' key: the three components other than the one at index big
 * (in index order), then big. When r is a lattice point (n / 32767) whose
 * component big, made non-negative, is what the reader rebuilds from the
 * other three (as lib/motion's levels are), it comes back exactly (up to
 * the sign); else r is normalised, big is its largest component, made
 * non-negative, and the three go to the nearest lattice points. */
static void rotq_encode(const float *r, int16_t *out, int shift)
{
	long n[4], m[4];
	if (shift > 0) { /* the normalised key, its three smaller components on the coarser lattice */
		double len = 0.0, u[4];
		int big = 0;
		for (int c = 0; c < 4; c++)
			len += (double)r[c] * r[c];
		len = len > 0.0 ? sqrt(len) : 1.0;
		for (int c = 0; c < 4; c++) {
			u[c] = r[c] / len;
			big = fabs(u[c]) > fabs(u[big]) ? c : big;
		}
		double sign = u[big] < 0 ? -1.0 : 1.0, step = ldexp(1.0, shift);
		long lim = 32767L >> shift;
		for (int c = 0, i = 0; c < 4; c++)
			if (c != big) {
				long k = lrint(sign * u[c] * 32767.0 / step);
				out[i++] = (int16_t)(k > lim ? lim : k < -lim ? -lim : k);
			}
		out[3] = (int16_t)(big | shift << 2);
		return;
	}
	int order[4] = {0, 1, 2, 3};
	for (int c = 0; c < 4; c++) {
		double e = r[c] > 1 ? 1 : r[c] < -1 ? -1 : r[c];
		n[c] = lrint(e * 32767.0);
	}
	for (int i = 1; i < 4; i++) /* by decreasing |n|, index order on ties */
		for (int j = i; j > 0 && labs(n[order[j]]) > labs(n[order[j - 1]]); j--) {
			int t = order[j];
			order[j] = order[j - 1], order[j - 1] = t;
		}
	int big = -1;
	for (int i = 0; i < 4 && big < 0; i++) {
		int b = order[i];
		long sign = n[b] < 0 ? -1 : 1;
		for (int c = 0; c < 4; c++)
			m[c] = sign * n[c];
		if (rotq_big(m, b) == m[b])
			big = b;
	}
	if (big < 0) {
		double len = 0.0, u[4];
		for (int c = 0; c < 4; c++)
			len += (double)r[c] * r[c];
		len = len > 0.0 ? sqrt(len) : 1.0;
		big = 0;
		for (int c = 0; c < 4; c++) {
			u[c] = r[c] / len;
			big = fabs(u[c]) > fabs(u[big]) ? c : big;
		}
		double sign = u[big] < 0 ? -1.0 : 1.0;
		for (int c = 0; c < 4; c++) {
			double e = sign * u[c];
			m[c] = lrint((e > 1 ? 1 : e < -1 ? -1 : e) * 32767.0);
		}
	}
	for (int c = 0, i = 0; c < 4; c++)
		if (c != big)
			out[i++] = (int16_t)m[c];
	out[3] = (int16_t)big;
}

void pack_motion_img_free(motion_img *m)
{
	for (int i = 0; m && i < m->n; i++)
		free(m->ch[i].times), free(m->ch[i].rot), free(m->ch[i].vec);
	if (m)
		free(m->ch), memset(m, 0, sizeof *m);
}

/* As pack.c's base_channel and base_key. */
static const struct img_chan *img_channel(const motion_img *m, uint32_t joint)
{
	for (int i = 0; m && i < m->n; i++)
		if (m->ch[i].joint == joint && m->ch[i].path == MLOD_PATH_ROTATION &&
		    m->ch[i].interp != MLOD_INTERP_CUBICSPLINE)
			return &m->ch[i];
	return NULL;
}

static long img_key(const struct img_chan *c, float t)
{
	uint32_t lo = 0, hi = c ? c->keys : 0;
	while (lo < hi) {
		uint32_t mid = lo + (hi - lo) / 2;
		if (c->times[mid] < t)
			lo = mid + 1;
		else
			hi = mid;
	}
	return c && lo < c->keys && c->times[lo] == t ? (long)lo : -1;
}

/* A 'ROTQ' key on its base's key bn: the lattice point r is (else the
 * nearest to r normalised), with the sign nearer bn, minus bn, each
 * component wrapped to 16 bits (the reader adds bn back). */
static void rotq_encode_on(const float *r, const int16_t *bn, int16_t *out, int shift)
{
	long t[4];
	int lattice = 1;
	for (int c = 0; c < 4; c++) {
		double e = r[c] > 1 ? 1 : r[c] < -1 ? -1 : r[c];
		t[c] = lrint(e * 32767.0);
		lattice &= (float)((double)t[c] / 32767.0) == r[c];
	}
	if (!lattice) {
		double len = 0.0;
		for (int c = 0; c < 4; c++)
			len += (double)r[c] * r[c];
		len = len > 0.0 ? sqrt(len) : 1.0;
		for (int c = 0; c < 4; c++)
			t[c] = lrint(r[c] / len * 32767.0);
	}
	long dot = 0;
	for (int c = 0; c < 4; c++)
		dot += t[c] * bn[c];
	if (shift > 0) { /* the base key itself when within the shift's angle of r */
		double lr = 0.0, lb = 0.0, d2 = 0.0, sd = 0.0;
		for (int c = 0; c < 4; c++)
			lr += (double)r[c] * r[c], lb += (double)bn[c] * bn[c], sd += (double)r[c] * bn[c];
		lr = sqrt(lr), lb = sqrt(lb);
		for (int c = 0; c < 4; c++) {
			double e = (sd < 0 ? -r[c] : r[c]) / lr - bn[c] / lb;
			d2 += e * e;
		}
		if (lr > 0.0 && lb > 0.0 && 4.0 * asin(fmin(1.0, sqrt(d2) / 2.0)) <= mlod_pack_rotq_angle(shift) * (1.0 - 1e-6)) {
			memset(out, 0, 4 * sizeof *out);
			return;
		}
	}
	for (int c = 0; c < 4; c++)
		out[c] = (int16_t)(uint16_t)((uint16_t)(dot < 0 ? -t[c] : t[c]) - (uint16_t)bn[c]);
}

/* Format 9.0 (mlod(5) ROTQ): each 'ROTQ' key but a channel's first as
 * its difference to mlod_pack_rotq_predict's prediction, from the key
 * before as returned and the channel's next key on a base key,
 * zigzagged (mlod_pack_zigzag16). q and qd
 * hold the 'ROTQ' and 'ROTD' elements as pack_motion_chunk made them,
 * img the keys as returned; in the same order, q's elements change. */
static void rotq_residuals(const mlod_clip *clip, const motion_img *img, const motion_img *base, int16_t *q,
                           const int16_t *qd)
{
	size_t at_a = 0, at_d = 0;
	for (int i = 0; i < clip->channel_count; i++) {
		const mlod_channel *ch = &clip->channels[i];
		if (ch->path != MLOD_PATH_ROTATION || ch->interp == MLOD_INTERP_CUBICSPLINE)
			continue;
		const struct img_chan *ic = &img->ch[i];
		const struct img_chan *bc = img_channel(base, ic->joint);
		uint32_t keys = ic->keys, w = 0; /* w: the next key after v on a base key, keys if none */
		long bw = -1;
		for (uint32_t v = 0; v < keys; v++) {
			long b = img_key(bc, ic->times[v]);
			if (b >= 0) {
				at_d++;
				continue;
			}
			int16_t *e = q + 4 * at_a++;
			if (v == 0)
				continue;
			if (w <= v)
				for (w = v + 1, bw = -1; w < keys && (bw = img_key(bc, ic->times[w])) < 0; w++)
					;
			int16_t nx[4], pred[3];
			double f = 0.0;
			if (w < keys) {
				mlod_pack_rotq_key(qd + 4 * at_d, bc->rot + 4 * bw, NULL, nx);
				f = ((double)ic->times[v] - (double)ic->times[v - 1]) /
				    ((double)ic->times[w] - (double)ic->times[v - 1]);
			}
			mlod_pack_rotq_predict(e[3], ic->rot + 4 * (v - 1), w < keys ? nx : NULL, f, pred);
			for (int j = 0; j < 3; j++)
				e[j] = mlod_pack_zigzag16((int16_t)(uint16_t)((uint16_t)e[j] - (uint16_t)pred[j]));
		}
	}
}

double mlod_pack_rotq_angle(int shift)
{
	double h = sqrt(19.0) * ldexp(1.0, shift) / 65534.0;
	return 2.0 * asin(h < 1.0 ? h : 1.0) * (1.0 + 1e-9);
}

/* Joint j's rounding error bound in rotq_shifts: over its ancestors a,
 * j first, ra[a] reach(a, j) where a has a rotation lattice, and ta[a]
 * where its translations are on a grid (0 when exact). */
static double rotq_error(const mlod_skeleton *sk, int j, const double *ra, const double *ta, const unsigned char *rot,
                         const unsigned char *tr, const double *reach)
{
	int nj = sk->joint_count;
	double e = 0.0;
	for (int a = j; a >= 0; a = sk->joints[a].parent) {
		if (rot[a])
			e += ra[a] * reach[(size_t)a * nj + j];
		if (tr[a] && ta[a] > 0.0)
			e += ta[a];
	}
	return e;
}

/* Per joint, the lattice shift of the rotation keys of a motion level of
 * TOC error `error` whose channels are lvl's (mlod_pack_write.h
 * MLOD_PACK_ROTQ_SHARE): reach[g * nj + j] is the largest, over the
 * original clip's frames and midpoints, of joint j's distance to its
 * ancestor g (or itself) plus its point distance times its world scale;
 * a key of g off by angle a moves j's points by at most a times that. The
 * shifts go up one at a time, leaves first, round after round, while every
 * joint's sum of angle times reach stays within its budget: share *
 * error plus that sum at shift 0. tgrid gets each joint's translation
 * grid exponent (INT_MIN: exact), raised in the same rounds against the
 * same sums. */
static mlod_result rotq_shifts(struct ctx *x, const mlod_clip *orig, const mlod_clip *lvl, double error, int *shift,
                               int *tgrid)
{
	const mlod_skeleton *sk = &x->v.skeleton;
	int nj = sk->joint_count;
	for (int j = 0; j < nj; j++)
		shift[j] = 0, tgrid[j] = INT_MIN;
	if (!(error > 0.0) || nj <= 0 || orig->channel_count <= 0)
		return MLOD_OK;
	mlod_motion_options mo = {0};
	mlod_clip common;
	mlod_result r = mlod_motion_common_clip(orig, &mo, &common, NULL, x->err);
	if (r != MLOD_OK)
		return r;
	int frames = common.channel_count > 0 ? common.channels[0].key_count : 0, n = frames > 0 ? 2 * (frames - 1) + 1 : 0;
	double pd = pack_motion_point_distance(x), a0 = mlod_pack_rotq_angle(0);
	float *t = malloc(sizeof *t * ((size_t)n + 1));
	mlod_trs *loc = malloc(sizeof *loc * (size_t)nj);
	mlod_mat4 *w = malloc(sizeof *w * (size_t)nj);
	double *reach = calloc((size_t)nj * nj, sizeof *reach), *budget = calloc((size_t)nj, sizeof *budget);
	double *tmax = calloc((size_t)nj, sizeof *tmax), *ps = calloc((size_t)nj, sizeof *ps);
	unsigned char *rot = calloc((size_t)nj, 1), *tr = calloc((size_t)nj, 1);
	int *tl = calloc((size_t)nj, sizeof *tl), *tbase = calloc((size_t)nj, sizeof *tbase);
	if (!t || !loc || !w || !reach || !budget || !rot || !tmax || !ps || !tr || !tl || !tbase) {
		r = mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
		goto done;
	}
	if (n > 0)
		mlod_motion_sample_times(common.channels[0].times, frames, 2, t);
	for (int i = 0; i < lvl->channel_count; i++)
		if (lvl->channels[i].path == MLOD_PATH_ROTATION && lvl->channels[i].interp != MLOD_INTERP_CUBICSPLINE &&
		    lvl->channels[i].joint >= 0 && lvl->channels[i].joint < nj)
			rot[lvl->channels[i].joint] = 1;
	/* translations: grid 2^(tbase + tl), tbase the exponent of the ulp of
	 * the channel's largest |value| (tl 0: exact) */
	for (int i = 0; i < lvl->channel_count; i++) {
		const mlod_channel *ch = &lvl->channels[i];
		if (ch->path != MLOD_PATH_TRANSLATION || ch->interp == MLOD_INTERP_CUBICSPLINE || ch->joint < 0 ||
		    ch->joint >= nj)
			continue;
		tr[ch->joint] = 1;
		for (int k = 0; k < 3 * ch->key_count; k++)
			tmax[ch->joint] = fabs((double)ch->values[k]) > tmax[ch->joint] ? fabs((double)ch->values[k]) : tmax[ch->joint];
	}
	for (int j = 0; j < nj; j++) {
		int ex = 0;
		frexp(tmax[j], &ex);
		tbase[j] = ex - 24;
		if (!isfinite(tmax[j]) || !(tmax[j] > 0.0))
			tr[j] = 0;
	}
	if (n == 0)
		goto done; /* nothing to measure the reach on: shifts 0 */
	for (int i = 0; i < n; i++) {
		mlod_pose_rest(sk, loc);
		mlod_clip_sample(orig, t[i], loc);
		mlod_pose_world(sk, loc, w);
		for (int j = 0; j < nj; j++) {
			double rad = pd * mlod_mat4_sigma_bound(&w[j]);
			int pa = sk->joints[j].parent;
			double sp = mlod_mat4_sigma_bound(pa < 0 ? &sk->joints[j].base : &w[pa]);
			if (!(sp <= ps[j]))
				ps[j] = isfinite(sp) ? sp : INFINITY;
			for (int g = j; g >= 0; g = sk->joints[g].parent) {
				double d = 0.0;
				for (int c = 0; c < 3; c++)
					d += ((double)w[j].m[12 + c] - w[g].m[12 + c]) * ((double)w[j].m[12 + c] - w[g].m[12 + c]);
				d = sqrt(d) + rad;
				if (!(d <= reach[(size_t)g * nj + j])) /* NaN too: no coarser lattice */
					reach[(size_t)g * nj + j] = isfinite(d) ? d : INFINITY;
			}
		}
	}
	for (size_t i = 0; i < (size_t)nj * nj; i++)
		if (!isfinite(reach[i]) || (i < (size_t)nj && !isfinite(ps[i])))
			goto done; /* shifts 0 */
	for (int j = 0; j < nj; j++) {
		double b = MLOD_PACK_ROTQ_SHARE * error;
		for (int g = j; g >= 0; g = sk->joints[g].parent)
			if (rot[g])
				b += a0 * reach[(size_t)g * nj + j];
		budget[j] = b;
	}
	/* A translation of g off by the grid's half step per component moves
	 * g and every joint below it by at most sqrt(3) 2^(e - 1) times the
	 * scale of g's parent's world matrix (its base for a root).
	 * Joint j's error is the sum over its ancestors a (j included, from j
	 * up) of a's rotation term ra[a] reach(a, j) and translation term
	 * ta[a]; a coarser lattice of g is kept when every joint below g stays
	 * within its budget. The sums are kept per joint (sum[j]) and moved by
	 * each kept step, and a joint whose moved sum falls within a relative
	 * 1e-9 of its budget is summed again exactly, in the order above, so
	 * that every decision is that of the exact sums (which took time cubic
	 * in a chain's depth: a 500-joint chain 33 s, a scale probe). */
	double *ra = calloc((size_t)nj, sizeof *ra), *ta = calloc((size_t)nj, sizeof *ta);
	double *sum = calloc((size_t)nj, sizeof *sum), *delta = calloc((size_t)nj, sizeof *delta);
	int *below = malloc(sizeof *below * (size_t)nj);
	if (!ra || !ta || !sum || !delta || !below) {
		free(ra), free(ta), free(sum), free(delta), free(below);
		r = mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
		goto done;
	}
	double angle[MLOD_PACK_ROTQ_SHIFT_MAX + 1];
	for (int k = 0; k <= MLOD_PACK_ROTQ_SHIFT_MAX; k++)
		angle[k] = mlod_pack_rotq_angle(k);
	for (int a = 0; a < nj; a++)
		ra[a] = rot[a] ? angle[0] : 0.0;
	for (int j = 0; j < nj; j++)
		sum[j] = rotq_error(sk, j, ra, ta, rot, tr, reach);
	for (int changed = 1; changed;) {
		changed = 0;
		for (int g = nj - 1; g >= 0; g--)
			for (int kind = 0; kind < 2; kind++) {
				if (kind == 0 ? !rot[g] || shift[g] >= MLOD_PACK_ROTQ_SHIFT_MAX : !tr[g] || tl[g] >= 24)
					continue;
				double old = kind == 0 ? ra[g] : ta[g];
				double now = kind == 0 ? angle[shift[g] + 1]
				                       : sqrt(3.0) * ldexp(1.0, tbase[g] + tl[g]) * ps[g] * (1.0 + 1e-9);
				(kind == 0 ? ra : ta)[g] = now;
				int ok = 1, nb = 0;
				for (int j = 0; j < nj && ok; j++) {
					if (!(reach[(size_t)g * nj + j] > 0.0) && j != g)
						continue; /* not below g */
					delta[j] = kind == 0 ? (now - old) * reach[(size_t)g * nj + j] : now - old;
					double e = sum[j] + delta[j];
					if (fabs(e - budget[j]) <= 1e-9 * budget[j])
						e = rotq_error(sk, j, ra, ta, rot, tr, reach);
					ok = e <= budget[j];
					below[nb++] = j;
				}
				if (ok) {
					changed = 1;
					(kind == 0 ? shift : tl)[g]++;
					for (int i = 0; i < nb; i++)
						sum[below[i]] += delta[below[i]];
				} else {
					(kind == 0 ? ra : ta)[g] = old;
				}
			}
	}
	free(ra), free(ta), free(sum), free(delta), free(below);
	for (int j = 0; j < nj; j++)
		tgrid[j] = tr[j] && tl[j] > 0 ? tbase[j] + tl[j] : INT_MIN;
done:
	free(t), free(loc), free(w), free(reach), free(budget), free(rot), free(tmax), free(ps), free(tr), free(tl),
	    free(tbase);
	mlod_clip_free(&common);
	return r;
}

/* One MOTION chunk of level k of clip item. base: the clip's level k + 1
 * as the reader returns it (NULL: none, level k is the coarsest); its
 * rotation keys then build on it (MLOD_PACK_CHUNK_NESTED). img gets this
 * chunk as the reader returns it. */
mlod_result pack_motion_chunk(struct ctx *x, const mlod_clip *clip, int k, int item, float error,
                              const motion_img *base, motion_img *img, chunks *out)
{
	chunkb cb = {0};
	int n = clip->channel_count;
	mlod_pack_channel_rec *recs = calloc((size_t)n + 1, sizeof *recs);
	const float **arr = calloc((size_t)n + 1, sizeof *arr);
	int *cnt = calloc((size_t)n + 1, sizeof *cnt), na = 0;
	if (!recs || !arr || !cnt) {
		free(recs), free(arr), free(cnt);
		return mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
	}
	/* The distinct time arrays, in first-use order. */
	for (int i = 0; i < n; i++) {
		const mlod_channel *ch = &clip->channels[i];
		int konst = constant_channel(ch), keys = konst ? 1 : ch->key_count;
		const float *t = konst ? ch->times + ch->key_count - 1 : ch->times;
		int a = 0;
		while (a < na && !(cnt[a] == keys && memcmp(arr[a], t, sizeof(float) * (size_t)keys) == 0))
			a++;
		if (a == na)
			arr[na] = t, cnt[na++] = keys;
		recs[i] = (mlod_pack_channel_rec){(uint32_t)ch->joint, (uint32_t)ch->path, (uint32_t)ch->interp,
		                                  (uint32_t)keys, (uint32_t)a};
	}
	pack_cb_add(&cb, MLOD_STREAM_CHAN, (uint32_t)n, sizeof *recs, recs, 0);
	/* the rotation keys' lattice per joint: level 0 the finest */
	int nj = x->v.skeleton.joint_count, *shift = calloc((size_t)nj + 1, sizeof *shift);
	int *tgrid = malloc(sizeof *tgrid * ((size_t)nj + 1));
	for (int j = 0; tgrid && j < nj; j++)
		tgrid[j] = INT_MIN;
	if (!shift || !tgrid) {
		cb.fail = 1;
	} else if (item < x->v.clip_count && !x->clips[item].no_shifts) {
		/* one set of shifts for every level of the clip, from the
		 * smallest TOC error, level 0's included: a finer level's key on
		 * its base's then mostly stores zeros (below); per-level shifts
		 * cost more (mlod(5)) */
		double emin = error;
		const struct clip_levels *cl = &x->clips[item];
		emin = cl->error0 < emin ? cl->error0 : emin;
		for (int l = 0; l < cl->count; l++)
			emin = cl->error[l] < emin ? cl->error[l] : emin;
		struct clip_levels *cw = &x->clips[item];
		if (!(cw->has_shift && cw->shift_emin == emin)) {
			mlod_result sr = rotq_shifts(x, &x->v.clips[item], &x->v.clips[item], emin, shift, tgrid);
			if (sr != MLOD_OK) {
				free(shift), free(tgrid), free(recs), free(arr), free(cnt), pack_cb_free(&cb);
				return sr;
			}
			if (!cw->shift)
				cw->shift = malloc(sizeof *shift * ((size_t)nj + 1));
			if (!cw->tgrid)
				cw->tgrid = malloc(sizeof *tgrid * ((size_t)nj + 1));
			if (cw->shift && cw->tgrid) {
				memcpy(cw->shift, shift, sizeof *shift * (size_t)nj);
				memcpy(cw->tgrid, tgrid, sizeof *tgrid * (size_t)nj);
				cw->has_shift = 1, cw->shift_emin = emin;
			}
		} else {
			memcpy(shift, cw->shift, sizeof *shift * (size_t)nj);
			memcpy(tgrid, cw->tgrid, sizeof *tgrid * (size_t)nj);
		}
	}
	/* this chunk as the reader returns it: the channels */
	pack_motion_img_free(img);
	img->ch = calloc((size_t)n + 1, sizeof *img->ch);
	if (!img->ch)
		cb.fail = 1;
	else
		img->n = n;
	for (int i = 0; i < img->n; i++)
		img->ch[i] = (struct img_chan){recs[i].joint, recs[i].path, recs[i].interp, recs[i].key_count, NULL, NULL, NULL};
	int *ta = malloc(sizeof *ta * ((size_t)n + 1));
	if (!ta)
		cb.fail = 1;
	for (int i = 0; ta && i < n; i++)
		ta[i] = (int)recs[i].time;
	free(recs);
	uint32_t max_tick = 0;
	int steps = 0;
	for (int i = 0; i < img->n; i++)
		steps |= img->ch[i].interp == MLOD_INTERP_STEP;
	double step = time_step(arr, cnt, na, steps, &max_tick);
	pack_cb_add(&cb, MLOD_STREAM_STEP, 1, 8, &step, 0);
	/* The key times: one stream, the arrays one after the other; f32, or
	 * ticks, each array's first then each next minus the one before (the
	 * vertex codec's byte deltas then see second differences: nearly
	 * nothing for evenly sampled arrays); u16 raw, u32 where they do not
	 * fit or the vertex codec (a multiple of 4 bytes) applies. */
	size_t nt = 0;
	for (int a = 0; a < na; a++)
		nt += (size_t)cnt[a];
	int wide = max_tick > 65535 || x->opt->codec == MLOD_CODEC_MESHOPT;
	uint8_t *tk = malloc(4 * (nt + 1));
	float *dt = malloc(sizeof *dt * (nt + 1)); /* the times as the reader returns them */
	size_t *dt_at = malloc(sizeof *dt_at * ((size_t)na + 1));
	if (!tk || !dt || !dt_at) {
		cb.fail = 1;
	} else {
		size_t at = 0;
		for (int a = 0; a < na; a++)
			for (int q = 0; q < cnt[a]; q++, at++) {
				if (q == 0)
					dt_at[a] = at;
				dt[at] = arr[a][q];
				if (step == 0) {
					memcpy(tk + 4 * at, &arr[a][q], 4);
					continue;
				}
				uint32_t v = (uint32_t)floor((double)arr[a][q] / step + 0.5);
				dt[at] = (float)((double)v * step);
				if (q > 0) /* the tick before's difference */
					v -= (uint32_t)floor((double)arr[a][q - 1] / step + 0.5);
				if (wide)
					put_u32(tk + 4 * at, v);
				else
					put_u16(tk + 2 * at, (uint16_t)v);
			}
		if (step == 0)
			pack_cb_add(&cb, MLOD_STREAM_TIME, (uint32_t)nt, 4, tk, 0);
		else
			pack_cb_add(&cb, MLOD_STREAM_TICK, (uint32_t)nt, wide ? 4 : 2, tk, 0);
		/* Or 'TBIT' (format 3.0), each array's first tick then a bit per
		 * tick after it: whichever stores fewer bytes. */
		if (step > 0 && !cb.fail) {
			size_t nbits = 0;
			for (int a = 0; a < na; a++)
				if (cnt[a] > 0)
					nbits += (size_t)((uint32_t)floor((double)arr[a][cnt[a] - 1] / step + 0.5) -
					                  (uint32_t)floor((double)arr[a][0] / step + 0.5));
			size_t nw = (size_t)na + (nbits + 31) / 32;
			uint32_t *w = nw <= UINT32_MAX ? calloc(nw + 1, 4) : NULL;
			if (!w) {
				cb.fail = 1;
			} else {
				size_t b = 0;
				for (int a = 0; a < na; a++) {
					uint32_t first = cnt[a] > 0 ? (uint32_t)floor((double)arr[a][0] / step + 0.5) : 0;
					w[a] = first;
					for (int q = 1; q < cnt[a]; q++) {
						uint32_t tq = (uint32_t)floor((double)arr[a][q] / step + 0.5);
						uint32_t tp = (uint32_t)floor((double)arr[a][q - 1] / step + 0.5);
						b += tq - tp; /* the key's bit: the last of its gap */
						w[(size_t)na + (b - 1) / 32] |= 1u << ((b - 1) % 32);
					}
				}
				stream tb = {MLOD_STREAM_TBIT, (uint32_t)nw, 4, 0, (uint8_t *)w};
				const stream *st = &cb.s[cb.n - 1];
				int coded = x->opt->codec == MLOD_CODEC_MESHOPT;
				size_t bt = coded ? pack_stream_coded_bytes(&tb) : nw * 4;
				size_t bk = coded ? pack_stream_coded_bytes(st) : ((size_t)st->count * st->size + 3) & ~(size_t)3;
				if (bt < bk) {
					free(cb.s[--cb.n].data);
					pack_cb_add(&cb, MLOD_STREAM_TBIT, (uint32_t)nw, 4, w, 0);
				}
				free(w);
			}
		}
	}
	free(tk);
	free(arr);
	free(cnt);
	for (int i = 0; !cb.fail && i < img->n; i++) {
		struct img_chan *ic = &img->ch[i];
		ic->times = malloc(sizeof *ic->times * ic->keys);
		if (!ic->times) {
			cb.fail = 1;
			break;
		}
		memcpy(ic->times, dt + dt_at[ta[i]], sizeof *ic->times * ic->keys);
		if (ic->path == MLOD_PATH_ROTATION && ic->interp != MLOD_INTERP_CUBICSPLINE &&
		    !(ic->rot = malloc(sizeof *ic->rot * 4 * ic->keys)))
			cb.fail = 1;
		if (ic->path != MLOD_PATH_ROTATION && ic->interp != MLOD_INTERP_CUBICSPLINE &&
		    !(ic->vec = malloc(sizeof *ic->vec * 3 * ic->keys)))
			cb.fail = 1;
	}
	free(dt);
	free(dt_at);
	free(ta);
	/* The values: 'ROTQ' (non-cubic rotations), 'ROTF' (cubic rotations),
	 * 'VEC3' (translations and scales), each one stream of its channels'
	 * keys in channel order. */
	size_t nq = 0, nf = 0, nv = 0;
	for (int i = 0; i < n; i++) {
		const mlod_channel *ch = &clip->channels[i];
		size_t keys = constant_channel(ch) ? 1 : (size_t)ch->key_count;
		size_t per = ch->interp == MLOD_INTERP_CUBICSPLINE ? 3 : 1;
		if (ch->path == MLOD_PATH_ROTATION && per == 1)
			nq += keys;
		else if (ch->path == MLOD_PATH_ROTATION)
			nf += 3 * keys;
		else
			nv += per * keys;
	}
	int16_t *q = malloc(sizeof(int16_t) * 4 * (nq + 1)), *qd = malloc(sizeof(int16_t) * 4 * (nq + 1));
	uint32_t *vd = malloc(sizeof *vd * 3 * (nv + 1));
	size_t at_d = 0, at_a = 0, at_vd = 0;
	float *rf = malloc(sizeof(float) * 4 * (nf + 1)), *v3 = malloc(sizeof(float) * 3 * (nv + 1));
	if (!q || !qd || !vd || !rf || !v3)
		cb.fail = 1;
	size_t at_q = 0, at_f = 0, at_v = 0;
	for (int i = 0; i < n && !cb.fail; i++) {
		const mlod_channel *ch = &clip->channels[i];
		int konst = constant_channel(ch);
		uint32_t keys = konst ? 1 : (uint32_t)ch->key_count, per = ch->interp == MLOD_INTERP_CUBICSPLINE ? 3 : 1;
		if (ch->path == MLOD_PATH_ROTATION && per == 1) {
			/* on the base's key at the same time, if any; else on its own */
			struct img_chan *ic = &img->ch[i];
			const struct img_chan *bc = img_channel(base, ic->joint);
			for (uint32_t v = 0; v < keys; v++, at_q++) {
				long b = img_key(bc, ic->times[v]);
				int16_t *e = b >= 0 ? qd + 4 * at_d++ : q + 4 * at_a++;
				int sh = ic->joint < (uint32_t)nj ? shift[ic->joint] : 0;
				if (b >= 0)
					rotq_encode_on(ch->values + 4 * (size_t)v, bc->rot + 4 * b, e, sh);
				else
					rotq_encode(ch->values + 4 * (size_t)v, e, sh);
				mlod_pack_rotq_key(e, b >= 0 ? bc->rot + 4 * b : NULL, v > 0 ? ic->rot + 4 * (v - 1) : NULL,
				                   ic->rot + 4 * v);
			}
		} else if (ch->path == MLOD_PATH_ROTATION) {
			memcpy(rf + 4 * at_f, ch->values, sizeof(float) * 4 * 3 * keys);
			at_f += 3 * (size_t)keys;
		} else if (per == 3) {
			memcpy(v3 + 3 * at_v, ch->values, sizeof(float) * 3 * per * keys);
			at_v += (size_t)per * keys;
		} else {
			/* on the base's key at the same time, if any: the bit
			 * patterns' differences ('VECD'); else as they are */
			struct img_chan *ic = &img->ch[i];
			const struct img_chan *bc = NULL;
			for (int j = 0; base && j < base->n; j++)
				if (base->ch[j].joint == ic->joint && base->ch[j].path == ic->path &&
				    base->ch[j].interp != MLOD_INTERP_CUBICSPLINE)
					bc = &base->ch[j];
			/* a translation on its joint's grid (rotq_shifts), if any */
			int e = ch->path == MLOD_PATH_TRANSLATION && ic->joint < (uint32_t)nj ? tgrid[ic->joint] : INT_MIN;
			for (size_t c = 0; c < 3 * (size_t)keys; c++)
				ic->vec[c] = e == INT_MIN ? ch->values[c] : (float)ldexp(rint(ldexp((double)ch->values[c], -e)), e);
			for (uint32_t v = 0; v < keys; v++) {
				long b = img_key(bc, ic->times[v]);
				for (int c = 0; c < 3; c++) {
					uint32_t a, bb;
					memcpy(&a, ic->vec + 3 * (size_t)v + c, 4);
					if (b >= 0) {
						memcpy(&bb, bc->vec + 3 * b + c, 4);
						vd[3 * at_vd + c] = a - bb;
					} else {
						v3[3 * at_v + c] = ic->vec[3 * (size_t)v + c];
					}
				}
				if (b >= 0)
					at_vd++;
				else
					at_v++;
			}
		}
	}
	if (!cb.fail) { /* format 9.0: ROTQ's predicted, then ROTD's zigzagged */
		rotq_residuals(clip, img, base, q, qd);
		for (size_t c = 0; c < 4 * at_d; c++)
			qd[c] = mlod_pack_zigzag16(qd[c]);
	}
	free(shift);
	free(tgrid);
	pack_cb_add(&cb, MLOD_STREAM_ROTQ, (uint32_t)at_a, 8, q, 0);
	pack_cb_add(&cb, MLOD_STREAM_ROTD, (uint32_t)at_d, 8, qd, 0);
	pack_cb_add(&cb, MLOD_STREAM_ROTF, (uint32_t)nf, 16, rf, 0);
	pack_cb_add(&cb, MLOD_STREAM_VEC3, (uint32_t)at_v, 12, v3, 0);
	pack_cb_add(&cb, MLOD_STREAM_VECD, (uint32_t)at_vd, 12, vd, 0);
	free(q);
	free(qd);
	free(vd);
	free(rf);
	free(v3);
	mlod_result r = pack_cb_finish(&cb, x->opt->codec, out, MLOD_CHUNK_MOTION, MLOD_LAYER_MOTION, k, item, error,
	                                x->err);
	if (r == MLOD_OK && base)
		out->c[out->n - 1].flags = MLOD_PACK_CHUNK_NESTED;
	return r;
}
