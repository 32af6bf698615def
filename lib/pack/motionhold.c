/*
 * motionhold.c: the motion levels held to their bounds as read back
 * (motion_hold), the lattice shifts kept where they pay
 * (motion_shift_choice), and a MOTION chunk's error as the reader returns
 * it (img_error) (packwrite_internal.h).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pack/packwrite_internal.h"

static int img_as_read(const motion_img *img, const mlod_clip *clip);

/* Encodes clip q's MOTION chunks (levels A - 1 to 0) as the pack will:
 * *bytes gets their stored bytes, and toc (not NULL) each level's TOC
 * error as the chunk loop of mlod_pack_write states it (0 first). */
static mlod_result motion_trial(struct ctx *x, int A, int q, size_t *bytes, double *toc)
{
	motion_img img[2] = {{0, NULL}, {0, NULL}};
	mlod_result r = MLOD_OK;
	*bytes = 0;
	for (int k = A - 1; r == MLOD_OK && k >= 0; k--) {
		chunks c = {0};
		const mlod_clip *cl = k == 0 ? x->clips[q].level0 : x->clips[q].clip[k - 1];
		float e = k == 0 ? x->clips[q].error0 : x->clips[q].error[k - 1];
		r = pack_motion_chunk(x, cl, k, q, e, k + 1 < A ? &img[!(k & 1)] : NULL, &img[k & 1], &c);
		for (int i = 0; i < c.n; i++)
			*bytes += c.c[i].size, free(c.c[i].data);
		free(c.c);
		if (r == MLOD_OK && toc) {
			double me = e > 0.0f ? pack_img_error(x, q, cl, &img[k & 1], x->err) : 0.0;
			if (me < 0)
				r = MLOD_ERR_NOMEM;
			toc[k] = (float)me > e ? (double)(float)me : (double)e;
		}
	}
	pack_motion_img_free(&img[0]), pack_motion_img_free(&img[1]);
	return r;
}

/* Clip q's levels made again (motion_hold) as motion_level0 and
 * motion_levels make them: with chains bit 0, level 0 within b0 (0: the
 * clip as read), or the clip as read where the level would not have fewer
 * keys; with bit 1, levels 1 to count within b[0] to b[count - 1], each
 * from the one before (the nested levels of lib/motion); a level that
 * meets no bound repeats the finer one. The levels from count to A - 2
 * repeat the coarsest. */
static mlod_result levels_remake(struct ctx *x, int q, int A, int chains, double b0, const double *b)
{
	const mlod_character *c = &x->v;
	struct clip_levels *cl = &x->clips[q];
	mlod_motion_level lv[MLOD_PACK_MAX_MOTION_LEVELS + 1];
	memset(lv, 0, sizeof lv);
	mlod_motion_options mo = {0};
	mo.point_distance = pack_motion_point_distance(x);
	mo.precision = MLOD_MOTION_PRECISION_FULL;
	static const mlod_motion_method methods[2] = {MLOD_MOTION_FRAMES, MLOD_MOTION_KEYS};
	mlod_result r = MLOD_OK;
	for (int chain = 0; r == MLOD_OK && chain < 2; chain++) {
		int n = !(chains >> chain & 1) ? 0 : chain == 0 ? b0 > 0.0 : cl->count;
		mlod_motion *m[2] = {NULL, NULL};
		for (int i = 0; r == MLOD_OK && n > 0 && i < 2; i++)
			r = i == 0 ? mlod_motion_create(c, q, &mo, &m[i], x->err) : mlod_motion_create_like(m[0], &m[i], x->err);
		for (int k = 0; r == MLOD_OK && k < n; k++) {
			mlod_motion_level *l = &lv[chain == 0 ? 0 : k + 1];
			mlod_error why = {0};
			mlod_result e = mlod_motion_next_level_best(m, methods, 2, MLOD_MOTION_MAX_ERROR, chain == 0 ? b0 : b[k], l,
			                                            &why);
			if (e == MLOD_ERR_LIMIT) {
				memset(l, 0, sizeof *l);
			} else if (e != MLOD_OK) {
				if (x->err)
					*x->err = why;
				r = e;
			}
		}
		for (int i = 0; i < 2; i++)
			mlod_motion_free(m[i]);
	}
	if (r == MLOD_OK && lv[0].clip.channels && !(lv[0].keys < mlod_clip_key_count(&c->clips[q])))
		mlod_motion_level_free(&lv[0]);
	for (int k = 0; k <= MLOD_PACK_MAX_MOTION_LEVELS; k++) {
		if (r != MLOD_OK) {
			mlod_motion_level_free(&lv[k]);
		} else if (chains >> (k > 0) & 1) {
			mlod_motion_level_free(&cl->remade[k]);
			cl->remade[k] = lv[k];
		}
	}
	if (r != MLOD_OK)
		return r;
	if (chains & 1) {
		int l0 = cl->remade[0].clip.channels != NULL;
		cl->level0 = l0 ? &cl->remade[0].clip : &c->clips[q];
		cl->error0 = l0 ? (float)cl->remade[0].error.max : 0.0f;
	}
	cl->chain_remade |= (chains & 2) != 0;
	for (int k = 0; k < A - 1; k++) { /* repeats point at the finer level again (it may be new) */
		const mlod_motion_level *l = &cl->remade[k + 1];
		if (k < cl->count && !cl->chain_remade) {
			continue;
		} else if (k < cl->count && l->clip.channels) {
			cl->clip[k] = &l->clip;
			cl->error[k] = (float)l->error.max;
		} else {
			cl->clip[k] = k ? cl->clip[k - 1] : cl->level0;
			cl->error[k] = k ? cl->error[k - 1] : cl->error0;
		}
	}
	return MLOD_OK;
}

/* Chooses clip q's shifts (no_shifts): with them or without, whichever
 * stores fewer bytes; toc (not NULL) gets the levels' TOC errors with
 * that choice (motion_trial). */
static mlod_result motion_shifts_pick(struct ctx *x, int A, int q, double *toc)
{
	size_t bytes[2] = {0, 0};
	for (int pass = 0; pass < 2; pass++) {
		x->clips[q].no_shifts = pass;
		mlod_result r = motion_trial(x, A, q, &bytes[pass], pass == 0 ? toc : NULL);
		if (r != MLOD_OK)
			return r;
	}
	x->clips[q].no_shifts = bytes[1] <= bytes[0];
	if (toc && x->clips[q].no_shifts)
		return motion_trial(x, A, q, &bytes[1], toc);
	return MLOD_OK;
}

/* A level above its bound (0: none), its TOC error toc. */
static int above(double bound, double toc)
{
	return bound > 0.0 && toc > bound;
}

/* A level's bound in the round after round `round` (motion_hold): its
 * bound in this one, used, less 1.05 times its TOC error's excess over
 * bound, twice that each round, and at least a quarter of used. */
static double tighter_bound(double used, double bound, double toc, int round)
{
	double next = used - ldexp(1.05, round) * (toc - bound);
	return next > 0.25 * used ? next : 0.25 * used;
}

/* Every level of clip q with a bound (clip_levels.bound0 and bound)
 * holds it as the reader returns its keys (its TOC error): while one
 * measures above its bound, the levels are made again (levels_remake),
 * that level's within its bound less 1.05 times the excess (twice that
 * each round, at least a quarter of the bound before), and the shifts
 * chosen again (they follow the smallest TOC error). After
 * MLOD_PACK_HOLD_ROUNDS rounds a level 0 still above its bound is the clip
 * as read (TOC error 0). */
static mlod_result motion_hold(struct ctx *x, int A, int q)
{
	struct clip_levels *cl = &x->clips[q];
	double b0 = cl->bound0, b[MLOD_PACK_MAX_MOTION_LEVELS], toc[MLOD_PACK_MAX_MOTION_LEVELS + 1];
	int hold = b0 > 0.0;
	for (int k = 0; k < MLOD_PACK_MAX_MOTION_LEVELS; k++)
		b[k] = cl->bound[k], hold |= k < cl->count && b[k] > 0.0;
	mlod_result r = motion_shifts_pick(x, A, q, hold ? toc : NULL);
	for (int round = 0; r == MLOD_OK && hold; round++) {
		int over = above(cl->bound0, toc[0]);
		for (int k = 0; k < cl->count && k < A - 1; k++)
			over |= above(cl->bound[k], toc[k + 1]);
		if (!over)
			break;
		int chains = 0;
		if (round == MLOD_PACK_HOLD_ROUNDS) {
			if (!above(cl->bound0, toc[0]))
				break;
			b0 = 0.0, hold = 0, chains = 1;
		} else {
			if (above(cl->bound0, toc[0]))
				b0 = tighter_bound(b0, cl->bound0, toc[0], round), chains |= 1;
			for (int k = 0; k < cl->count && k < A - 1; k++)
				if (above(cl->bound[k], toc[k + 1]))
					b[k] = tighter_bound(b[k], cl->bound[k], toc[k + 1], round), chains |= 2;
		}
		if ((r = levels_remake(x, q, A, chains, b0, b)) == MLOD_OK)
			r = motion_shifts_pick(x, A, q, hold ? toc : NULL);
	}
	return r;
}

/* Per clip, whether its MOTION chunks (levels A - 1 to 0) store fewer
 * bytes with the rotation lattice shifts or without (the shifts change
 * the keys' bases and their sign choices, which can cost more than they
 * save). Sets no_shifts where they do not pay. */
mlod_result pack_motion_shift_choice(struct ctx *x, int A)
{
	for (int q = 0; q < x->v.clip_count; q++) {
		/* A pack's level 0 and its levels (an input of mlod-pack -x):
		 * their keys are on that pack's lattices and grids already. The
		 * shifts chosen again are kept where every level's keys go back
		 * exactly as read (the same shifts, or coarser ones the keys
		 * happen to sit on), else none: each level keeps the error that
		 * pack measured, never rounded a second time. */
		if (x->clips[q].packed) {
			motion_img img[2] = {{0, NULL}, {0, NULL}};
			int same = 1;
			x->clips[q].no_shifts = 0;
			for (int k = A - 1; same && k >= 0; k--) {
				chunks c = {0};
				const mlod_clip *cl = k == 0 ? x->clips[q].level0 : x->clips[q].clip[k - 1];
				mlod_result r = pack_motion_chunk(x, cl, k, q, k == 0 ? x->clips[q].error0 : x->clips[q].error[k - 1],
				                                  k + 1 < A ? &img[!(k & 1)] : NULL, &img[k & 1], &c);
				for (int i = 0; i < c.n; i++)
					free(c.c[i].data);
				free(c.c);
				if (r != MLOD_OK) {
					pack_motion_img_free(&img[0]), pack_motion_img_free(&img[1]);
					return r;
				}
				same = img_as_read(&img[k & 1], cl);
			}
			pack_motion_img_free(&img[0]), pack_motion_img_free(&img[1]);
			x->clips[q].no_shifts = !same;
			continue;
		}
		mlod_result r = motion_hold(x, A, q);
		if (r != MLOD_OK)
			return r;
	}
	return MLOD_OK;
}

/* The largest point error (mlod_motion_point_error, the point distance's
 * radius) of every joint of clip as the reader returns it (img: its keys
 * as the MOTION chunk holds them) against clip q as read, at its common
 * timeline frames and midpoints, rounded up to 8 significant bits (at
 * most 0.4% more), so that the float noise of an input read two ways
 * gives the same TOC error (cli/pack_bvh_stages; RESULTS Run 85); -1
 * when out of memory. The clip as read is posed once per clip (kept in
 * clip_levels: motion_hold measures each level round after round). */
double pack_img_error(struct ctx *x, int q, const mlod_clip *clip, const motion_img *img, mlod_error *err)
{
	const mlod_skeleton *sk = &x->v.skeleton;
	const mlod_clip *orig = &x->v.clips[q];
	struct clip_levels *cq = &x->clips[q];
	int nj = sk->joint_count;
	if (nj <= 0 || orig->channel_count <= 0 || img->n != clip->channel_count)
		return 0.0;
	if (!cq->world) {
		mlod_motion_options mo = {0};
		mlod_clip common;
		if (mlod_motion_common_clip(orig, &mo, &common, NULL, err) != MLOD_OK)
			return -1.0;
		int frames = common.channel_count > 0 ? common.channels[0].key_count : 0;
		int n = frames > 0 ? 2 * (frames - 1) + 1 : 0;
		float *t = malloc(sizeof *t * ((size_t)n + 1));
		mlod_mat4 *w = malloc(sizeof *w * ((size_t)n * nj + 1));
		mlod_trs *la = malloc(sizeof *la * (size_t)nj);
		if (!t || !w || !la) {
			free(t), free(w), free(la);
			mlod_clip_free(&common);
			mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
			return -1.0;
		}
		if (n > 0)
			mlod_motion_sample_times(common.channels[0].times, frames, 2, t);
		for (int i = 0; i < n; i++) {
			mlod_pose_rest(sk, la);
			mlod_clip_sample(orig, t[i], la);
			mlod_pose_world(sk, la, w + (size_t)i * nj);
		}
		free(la);
		mlod_clip_free(&common);
		cq->at = t, cq->world = w, cq->samples = n;
	}
	int n = cq->samples;
	const float *t = cq->at;
	mlod_clip dec = *clip;
	dec.channels = calloc((size_t)clip->channel_count + 1, sizeof *dec.channels);
	mlod_trs *lb = malloc(sizeof *lb * (size_t)nj);
	mlod_mat4 *wb = malloc(sizeof *wb * (size_t)nj);
	double worst = -1.0;
	if (!dec.channels || !lb || !wb) {
		mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
		goto done;
	}
	worst = 0.0;
	for (int i = 0; i < clip->channel_count && worst >= 0; i++) {
		const struct img_chan *ic = &img->ch[i];
		mlod_channel *d = &dec.channels[i];
		*d = clip->channels[i];
		d->short_values = 0;
		d->key_count = (int)ic->keys;
		d->times = ic->times;
		if (ic->rot) {
			if (!(d->values = malloc(sizeof *d->values * 4 * ic->keys)))
				worst = -1.0;
			for (size_t v = 0; d->values && v < 4 * (size_t)ic->keys; v++)
				d->values[v] = (float)(ic->rot[v] / 32767.0);
		} else if (ic->vec) {
			d->values = ic->vec;
		}
	}
	if (worst < 0) {
		mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
		goto done;
	}
	double pd = pack_motion_point_distance(x);
	for (int i = 0; i < n; i++) {
		const mlod_mat4 *wa = cq->world + (size_t)i * nj;
		mlod_pose_rest(sk, lb);
		mlod_clip_sample(&dec, t[i], lb);
		mlod_pose_world(sk, lb, wb);
		for (int j = 0; j < nj; j++) {
			double e = mlod_motion_point_error(&wa[j], &wb[j], pd);
			if (!(e <= worst))
				worst = isfinite(e) ? e : INFINITY;
		}
	}
	if (worst > 0.0 && isfinite(worst)) {
		int ex = 0;
		frexp(worst, &ex);
		worst = ldexp(ceil(ldexp(worst, 8 - ex)), ex - 8);
	}
done:
	for (int i = 0; dec.channels && i < clip->channel_count; i++)
		if (img->ch[i].rot)
			free(dec.channels[i].values);
	free(dec.channels), free(lb), free(wb);
	return worst;
}

/* 1 when every non-cubic rotation and translation or scale key of the
 * MOTION chunk img describes is the key of clip as read (a rotation up to
 * its sign). */
static int img_as_read(const motion_img *img, const mlod_clip *clip)
{
	for (int i = 0; i < img->n; i++) {
		const struct img_chan *ic = &img->ch[i];
		const mlod_channel *ch = NULL;
		if (!ic->rot && !ic->vec)
			continue;
		for (int j = 0; !ch && j < clip->channel_count; j++)
			if ((uint32_t)clip->channels[j].joint == ic->joint && (uint32_t)clip->channels[j].path == ic->path &&
			    clip->channels[j].interp != MLOD_INTERP_CUBICSPLINE)
				ch = &clip->channels[j];
		if (!ch || (uint32_t)ch->key_count != ic->keys)
			return 0;
		for (uint32_t v = 0; ic->rot && v < ic->keys; v++) {
			int plus = 1, minus = 1;
			for (int c = 0; c < 4; c++) {
				float r = (float)ic->rot[4 * v + c] / 32767.0f, w = ch->values[4 * (size_t)v + c];
				plus &= r == w;
				minus &= -r == w;
			}
			if (!plus && !minus)
				return 0;
		}
		if (ic->vec && memcmp(ic->vec, ch->values, sizeof(float) * 3 * ic->keys) != 0)
			return 0;
	}
	return 1;
}
