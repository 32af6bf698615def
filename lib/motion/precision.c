/*
 * precision.c: a level's value precision (beyond the paper), and its
 * counts and measures (motion_level_finish).
 *
 * Keys go within (1 - share) of the bound (motion_removal_bound: the
 * frames and keys methods spend that part); the values are then rounded
 * (rounding.c), so that few bits vary and gzip/zstd compress them well:
 * the coarsest level grid whose measured error stays within the bound is
 * found (translations on it, rotations and scales finer by their joint's
 * reach), then each channel takes coarser grids while the bound holds
 * (the refinement, on up to MOTION_LANES threads: tasks.c). By default
 * (auto) rotations go on the lattice of normalised shorts and
 * translations and scales stay float32 on power-of-two grids; float
 * keeps every value float32, with the first and last keys exact.
 *
 * Errors are measured by levelerror.c's walks; the refinement keeps the
 * rounded level's local transforms and world matrices at every sample,
 * so a try recomputes only the channel's joint and its subtree.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "motion/motion_internal.h"

#define DEFAULT_PRECISION_SHARE 0.1 /* of a max-error bound left to rounding (bench/RESULTS.md) */
#define GRID_RANGE 48     /* grids tried: from 2^48 times finer than the bound up to it */
#define CHANNEL_COARSER 8 /* per channel, up to this many doublings beyond the level's grid */
#define REFINE_STRIDE 8

/* The part of a max-error bound the keys (or frames) may spend: with auto
 * precision, the rest is left to rounding the values. */
double motion_removal_bound(const mlod_motion *m, double bound)
{
	if (m->opt.precision == MLOD_MOTION_PRECISION_FULL)
		return bound;
	double share = m->opt.precision_share > 0.0 && m->opt.precision_share < 1.0 ? m->opt.precision_share
	                                                                            : DEFAULT_PRECISION_SHARE;
	return bound * (1.0 - share);
}

/* The rounding refinement's arrays, in m->scratch (carved the same way
 * at every call, so that what one call leaves there the next finds):
 * the level as rounded (shared), and per lane (a thread of the
 * refinement, up to m->threads) a try's and the best fit's. */
typedef struct refine_lane {
	mlod_trs *Lj, *Lj2;                      /* samples (2) */
	mlod_mat4 *T, *T2, *LMj, *LMj2;          /* samples * joints (2), samples (2) */
	int *sub, *pos, *ppos;                   /* joints */
} refine_lane;

typedef struct refine_bufs {
	mlod_trs *L;                             /* samples * joints */
	mlod_mat4 *W, *LM;                       /* samples * joints */
	int lanes;
	refine_lane lane[MOTION_LANES];
} refine_bufs;

static int refine_bufs_get(mlod_motion *m, refine_bufs *b)
{
	int F = m->samples, J = m->s->joint_count, lanes = motion_lanes(m);
	size_t FJ = (size_t)F * (size_t)J;
	size_t per_lane = 2 * eval_carve_size(sizeof(mlod_mat4) * FJ) + 2 * eval_carve_size(sizeof(mlod_trs) * (size_t)F) +
	                  2 * eval_carve_size(sizeof(mlod_mat4) * (size_t)F) + 3 * eval_carve_size(sizeof(int) * (size_t)J);
	size_t need = eval_carve_size(sizeof(mlod_trs) * FJ) + 2 * eval_carve_size(sizeof(mlod_mat4) * FJ) +
	              (size_t)lanes * per_lane;
	char *at = eval_scratch_get(&m->scratch, need);
	memset(b, 0, sizeof *b);
	if (!at)
		return 0;
	b->L = eval_carve(&at, sizeof *b->L * FJ);
	b->W = eval_carve(&at, sizeof *b->W * FJ);
	b->LM = eval_carve(&at, sizeof *b->LM * FJ);
	b->lanes = lanes;
	for (int i = 0; i < lanes; i++) {
		refine_lane *l = &b->lane[i];
		l->T = eval_carve(&at, sizeof *l->T * FJ);
		l->T2 = eval_carve(&at, sizeof *l->T2 * FJ);
		l->Lj = eval_carve(&at, sizeof *l->Lj * (size_t)F);
		l->Lj2 = eval_carve(&at, sizeof *l->Lj2 * (size_t)F);
		l->LMj = eval_carve(&at, sizeof *l->LMj * (size_t)F);
		l->LMj2 = eval_carve(&at, sizeof *l->LMj2 * (size_t)F);
		l->sub = eval_carve(&at, sizeof(int) * (size_t)J);
		l->pos = eval_carve(&at, sizeof(int) * (size_t)J);
		l->ppos = eval_carve(&at, sizeof(int) * (size_t)J);
	}
	return 1;
}

/* Rounds src's values into clip with level grid g and adjustments adj;
 * is the error within bound? With rb, as motion_level_within_keep into its L,
 * LM and W (*kept). */
static int round_fits_keep(mlod_motion *m, const mlod_clip *src, mlod_clip *clip, int g, const int *adj, int *e,
                           double bound, refine_bufs *rb, int *kept)
{
	motion_channel_exps(m, src, g, adj, e);
	motion_round_clip(src, clip, e, MOTION_SHORTS(m));
	if (rb)
		return motion_level_within_keep(m, clip, bound, rb->L, rb->LM, rb->W, kept);
	return motion_level_within(m, clip, bound);
}

static int round_fits(mlod_motion *m, const mlod_clip *src, mlod_clip *clip, int g, const int *adj, int *e,
                      double bound)
{
	return round_fits_keep(m, src, clip, g, adj, e, bound, NULL, NULL);
}

/* Per-channel refinement: each channel in turn goes to coarser grids
 * (adj[i] + 1, + 2, ...) while the bound holds. The rounded clip's local
 * transforms and world matrices are kept at every common frame, so a try
 * recomputes only the channel's joint and its descendants, with the same
 * operations as mlod_pose_world. Needs m->cache0. walked: the buffers
 * (refine_bufs) already hold the clip as rounded with g and adj at every
 * sample (motion_level_within_keep of it fitted). Returns -1 when out of
 * memory; clip is then rounded with adj as it was.
 *
 * A channel's refinement reads and writes its joint's local transforms
 * and the world matrices of its joint's subtree only (and reads the
 * parent's): channels of joints that are not one below the other commute,
 * and run on up to m->threads threads (motion_run_tasks), with the
 * result of the channels in order. */
typedef struct refine_ctx {
	mlod_motion *m;
	const mlod_clip *src;
	mlod_clip *clip;
	int g, stride;
	int *adj, *e;
	double bound;
	refine_bufs *rb;
} refine_ctx;

EVAL_INLINE void refine_one_body(void *ctx, int lane, int i, int wide)
{
	refine_ctx *x = ctx;
	mlod_motion *m = x->m;
	const mlod_skeleton *s = m->s;
	const mlod_clip *src = x->src;
	mlod_clip *clip = x->clip;
	int F = m->samples, J = s->joint_count, g = x->g, stride = x->stride, *adj = x->adj, *e = x->e;
	double bound = x->bound;
	refine_lane *rl = &x->rb->lane[lane];
	mlod_trs *L = x->rb->L, *Lj = rl->Lj, *Lj2 = rl->Lj2;
	mlod_mat4 *W = x->rb->W, *T = rl->T, *T2 = rl->T2, *LM = x->rb->LM, *LMj = rl->LMj, *LMj2 = rl->LMj2;
	int *sub = rl->sub, *pos = rl->pos, *ppos = rl->ppos;
	const float *times = m->st;
	mlod_channel *ch = &clip->channels[i];
	int j = ch->joint, ns = 0, fast = ch->interp != MLOD_INTERP_CUBICSPLINE;
	if (ch->key_count < 3)
		return; /* its first and last keys stay exact: nothing to round */
	for (int d = j; d < J; d++) { /* j and its descendants, parents first */
		int a = d;
		while (a > j)
			a = s->joints[a].parent;
		if (a == j)
			pos[d] = ns, sub[ns++] = d;
	}
	for (int k = 1; k < ns; k++) /* below j, the parent is in the subtree, before */
		ppos[k] = pos[s->joints[sub[k]].parent];
	const int pj = s->joints[j].parent;
	/* The coarsest adjustment up to CHANNEL_COARSER that fits: the
	 * largest first, then bisection (a try that does not fit usually
	 * stops within a few samples, one that fits checks them all). The
	 * try's local transform of j and world matrices of its subtree go
	 * to Lj, LMj and T (ns per sample); those of the best fit so far
	 * are kept in Lj2, LMj2, T2. */
	int ok_adj = adj[i], bad_adj = CHANNEL_COARSER + 1, have = 0;
	for (int want = CHANNEL_COARSER; bad_adj - ok_adj > 1; want = ok_adj + (bad_adj - ok_adj) / 2) {
		adj[i] = want;
		e[i] = motion_channel_exp(m, &src->channels[i], g, adj[i]);
		motion_round_channel(&src->channels[i], ch, e[i], MOTION_SHORTS(m));
		int ok = 1;
		eval_seg seg = { -1, 0, 0, { 0, 0, 0, 1 }, { 0, 0, 0, 1 }, 0.0, 0.0, 0.0 };
		/* Every stride-th sample first, then the rest in order. */
		for (int pass = stride > 1 ? 0 : 1; pass < 2 && ok; pass++)
			for (int f = 0; f < F && ok; f += pass ? 1 : stride) {
				if (pass == 1 && stride > 1 && f % stride == 0)
					continue;
				mlod_trs *lf = L + (size_t)f * (size_t)J, l = lf[j];
				const mlod_mat4 *wf = W + (size_t)f * (size_t)J, *lmf = LM + (size_t)f * (size_t)J;
				mlod_mat4 *w = T + (size_t)f * (size_t)ns;
				const mlod_mat4 *w0 = m->cache0 + (size_t)f * (size_t)J;
				if (fast) {
					float t = times[f], v[4];
					if (!(t > 0.0f))
						t = 0.0f;
					if (t > clip->duration)
						t = clip->duration;
					eval_channel(ch, &seg, t, v);
					switch (ch->path) {
					case MLOD_PATH_TRANSLATION: l.t.x = v[0], l.t.y = v[1], l.t.z = v[2]; break;
					case MLOD_PATH_SCALE: l.s.x = v[0], l.s.y = v[1], l.s.z = v[2]; break;
					case MLOD_PATH_ROTATION: l.r = eval_normalize((mlod_quat){ v[0], v[1], v[2], v[3] }); break;
					}
				} else {
					mlod_channel_sample(ch, clip->duration, times[f], &l);
				}
				Lj[f] = l;
				LMj[f] = eval_from_trs(&l);
				w[0] = pj < 0 ? eval_mul(&s->joints[j].base, &LMj[f]) : eval_mul_affine_w(&wf[pj], &LMj[f], wide);
				ok = eval_within_w(&w[0], &w0[j], m->radius[j], bound, wide);
				for (int k = 1; k < ns && ok; k++) {
					int d = sub[k];
					w[k] = eval_mul_affine_w(&w[ppos[k]], &lmf[d], wide);
					ok = eval_within_w(&w[k], &w0[d], m->radius[d], bound, wide);
				}
			}
		if (ok) {
			mlod_trs *tl = Lj;
			mlod_mat4 *tm = LMj, *tt = T;
			Lj = Lj2, LMj = LMj2, T = T2;
			Lj2 = tl, LMj2 = tm, T2 = tt;
			ok_adj = want, have = 1;
		} else {
			bad_adj = want;
		}
	}
	adj[i] = ok_adj;
	e[i] = motion_channel_exp(m, &src->channels[i], g, adj[i]);
	motion_round_channel(&src->channels[i], ch, e[i], MOTION_SHORTS(m));
	if (!have)
		return;
	for (int f = 0; f < F; f++) {
		mlod_mat4 *wf = W + (size_t)f * (size_t)J;
		L[(size_t)f * (size_t)J + (size_t)j] = Lj2[f];
		LM[(size_t)f * (size_t)J + (size_t)j] = LMj2[f];
		for (int k = 0; k < ns; k++)
			wf[sub[k]] = T2[(size_t)f * (size_t)ns + (size_t)k];
	}
}

/* refine_one_body compiled twice (motion_eval.h): the same floats. */
static void refine_one_generic(void *ctx, int lane, int i)
{
	refine_one_body(ctx, lane, i, 0);
}
#if EVAL_HAVE_AVX2
EVAL_TARGET_AVX2 static void refine_one_avx2(void *ctx, int lane, int i)
{
	refine_one_body(ctx, lane, i, 1);
}
#endif

static int refine_conflict(void *ctx, int u, int t)
{
	const refine_ctx *x = ctx;
	return eval_joints_related(x->m->s, x->clip->channels[u].joint, x->clip->channels[t].joint);
}

static int refine_channels(mlod_motion *m, const mlod_clip *src, mlod_clip *clip, int g, int *adj, int *e,
                           double bound, const mlod_mat4 **world, int walked)
{
	const mlod_skeleton *s = m->s;
	int F = m->samples, J = s->joint_count, n = clip->channel_count;
	refine_bufs rb;
	int got = refine_bufs_get(m, &rb);
	mlod_trs *L = rb.L;
	mlod_mat4 *W = rb.W, *LM = rb.LM;
	const float *times = m->st;
	motion_channel_exps(m, src, g, adj, e);
	motion_round_clip(src, clip, e, MOTION_SHORTS(m));
	if (!got)
		return -1;
	motion_walk walk;
	motion_walk_begin(m, clip, &walk);
	for (int f = 0; f < F && !walked; f++) {
		mlod_trs *lf = L + (size_t)f * (size_t)J;
		if (walk.fast) {
			eval_sample(clip, walk.segs, times[f], walk.local);
			memcpy(lf, walk.local, sizeof *lf * (size_t)J);
			eval_pose_world(s, lf, W + (size_t)f * (size_t)J);
		} else {
			mlod_pose_rest(s, lf);
			mlod_clip_sample(clip, times[f], lf);
			mlod_pose_world(s, lf, W + (size_t)f * (size_t)J);
		}
		for (int j = 0; j < J; j++)
			LM[(size_t)f * (size_t)J + (size_t)j] = eval_from_trs(&lf[j]);
	}
	/* Samples every REFINE_STRIDE-th first (they are independent, and a
	 * try that fails usually fails sooner), then the others in order. */
	refine_ctx x = { m, src, clip, g, F >= 4 * REFINE_STRIDE ? REFINE_STRIDE : 1, adj, e, bound, &rb };
	motion_task_fn one = refine_one_generic;
#if EVAL_HAVE_AVX2
	if (eval_avx2())
		one = refine_one_avx2;
#endif
	if (motion_run_tasks(n, rb.lanes, refine_conflict, one, &x) != MLOD_OK)
		return -1;
	*world = W; /* in m->scratch: valid until its next use */
	return 0;
}

/* A level's measures, taken while rounding it. */
typedef struct level_meas {
	int valid;            /* the level as it now is was measured */
	double point_error;
	mlod_deviation dev;
} level_meas;

/* Rounds the level's values to the coarsest grids that keep its point
 * error within bound: first one level grid (bisection on its exponent),
 * then each channel coarser while the bound holds. Sets *grid to the
 * level grid (0 when nothing was rounded). Returns -1 when out of memory. */
static int level_round(mlod_motion *m, mlod_clip *clip, double bound, double *grid, double known, level_meas *meas)
{
	int n = clip->channel_count;
	*grid = 0.0;
	meas->valid = 0;
	/* known: the clip's motion_level_max_error when the caller measured it, or < 0. */
	if (!(bound > 0.0) || !isfinite(bound) || !(known >= 0.0 ? known <= bound : motion_level_within(m, clip, bound)))
		return 0;
	mlod_clip src;
	memset(&src, 0, sizeof src);
	int *adj = calloc((size_t)n, sizeof(int)), *e = malloc(sizeof(int) * (size_t)n);
	int bad = !adj || !e || motion_clip_copy(clip, &src) != 0;
	if (bad) {
		free(adj);
		free(e);
		mlod_clip_free(&src);
		return -1;
	}
	/* The coarsest grid from 2^(top - GRID_RANGE) to 2^top that fits,
	 * from the top down one grid at a time: a grid that does not fit is
	 * usually found so within a few samples (motion_level_within), one
	 * that fits costs a whole walk, and this meets one (a bisection met
	 * about three a level). */
	/* With the cache, the walk of the grid that fits stays in the
	 * refinement's buffers, which it then starts from. */
	refine_bufs rb;
	int have_rb = m->cache0 && refine_bufs_get(m, &rb), walked = 0;
	int top = (int)ceil(log2(bound)) + 1, lo = top - GRID_RANGE, found = 0;
	for (int g = top; g >= lo && !found; g--)
		if (round_fits_keep(m, &src, clip, g, adj, e, bound, have_rb ? &rb : NULL, &walked))
			found = 1, lo = g;
	if (!found) {
		for (int i = 0; i < n; i++)
			e[i] = MOTION_NO_ROUNDING;
		motion_round_clip(&src, clip, e, MOTION_SHORTS(m));
	} else {
		/* Channels in their order (measured as good as round robin or
		 * leaves first); the result is measured again as a whole. */
		const mlod_mat4 *world = NULL;
		if (m->cache0 && refine_channels(m, &src, clip, lo, adj, e, bound, &world, have_rb && walked) != 0)
			bad = 1, world = NULL;
		/* round_fits, measuring the level at the same time; refine_channels
		 * left the level's world matrices at every sample (the same floats
		 * as a walk of the clip). */
		motion_channel_exps(m, &src, lo, adj, e);
		motion_round_clip(&src, clip, e, MOTION_SHORTS(m));
		meas->valid = motion_level_measure(m, clip, world, &meas->point_error, &meas->dev) && meas->point_error <= bound;
		if (!meas->valid && !motion_level_within(m, clip, bound)) {
			memset(adj, 0, sizeof(int) * (size_t)n); /* fitted in the bisection */
			round_fits(m, &src, clip, lo, adj, e, bound);
		}
		*grid = ldexp(1.0, lo);
	}
	free(adj);
	free(e);
	mlod_clip_free(&src);
	return bad ? -1 : 0;
}

/* The fewest bytes a level clip can store whatever its values' rounding:
 * with auto precision every rotation as shorts (8 bytes a key instead of
 * 16). */
long motion_least_bytes(const mlod_motion *m, const mlod_clip *clip)
{
	long least = mlod_clip_key_bytes(clip);
	for (int i = 0; MOTION_SHORTS(m) && i < clip->channel_count; i++) {
		const mlod_channel *ch = &clip->channels[i];
		if (ch->path == MLOD_PATH_ROTATION && ch->interp != MLOD_INTERP_CUBICSPLINE && !ch->short_values)
			least -= 8L * ch->key_count;
	}
	return least;
}

/* Fills the level's counts and its error as mlod_joint_deviation measures
 * it, after rounding its values within bound (< 0: a level chosen by
 * threshold or fraction, whose error e may grow to e / (1 - share), the
 * share a bound leaves to rounding). */
mlod_result motion_level_finish(mlod_motion *m, mlod_motion_level *out, double bound, long max_bytes, double known,
                                mlod_error *err)
{
	level_meas meas = { 0, 0.0, { 0.0, 0.0, 0.0 } };
	out->keys = mlod_clip_key_count(&out->clip);
	out->bytes = mlod_clip_key_bytes(&out->clip);
	if (max_bytes >= 0) {
		/* Rounding keeps the keys. */
		long least = motion_least_bytes(m, &out->clip);
		if (least > max_bytes) {
			out->bytes = least;
			out->unfinished = 1;
			return MLOD_OK;
		}
	}
	if (m->opt.precision != MLOD_MOTION_PRECISION_FULL) {
		if (bound < 0.0)
			bound = (known >= 0.0 ? known : motion_level_max_error(m, &out->clip)) / motion_removal_bound(m, 1.0);
		if (level_round(m, &out->clip, bound, &out->grid, known, &meas) != 0)
			return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
	}
	out->keys = mlod_clip_key_count(&out->clip);
	out->bytes = mlod_clip_key_bytes(&out->clip);
	if (meas.valid || motion_level_measure(m, &out->clip, NULL, &meas.point_error, &meas.dev)) {
		out->point_error = meas.point_error;
		out->error = meas.dev;
		return MLOD_OK;
	}
	out->point_error = motion_level_max_error(m, &out->clip);
	mlod_character a, b;
	memset(&a, 0, sizeof a);
	a.skeleton = m->s[0];
	a.clip_count = 1;
	b = a;
	a.clips = (mlod_clip *)m->orig;
	b.clips = &out->clip;
	return mlod_joint_deviation_at(&a, &b, m->st, m->samples, &out->error, err);
}
