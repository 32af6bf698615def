/*
 * levelerror.c: a level clip's error, walked sample by sample.
 *
 * Error bounds are checked on the point error of every joint at every
 * sample of the common timeline (mlod_motion_point_error: the joint's
 * origin and every point within point_distance of it, or within its End
 * Site), computed with the same sampling and forward kinematics as
 * mlod_joint_deviation, so a bound met here is met there for joint and
 * End Site positions; both methods answer to the same bound, so they can
 * be compared at it. The samples are the frames and, by default, the
 * midpoints between them (options.subdivide): a level and its source
 * each interpolate their own keys, and between two frames they can differ
 * more than at either (bench/RESULTS.md, test bound_holds_between_frames).
 * The reported error is mlod_joint_deviation_at's at the same samples.
 *
 * The level is posed with the fast forms of motion_eval.h and compared
 * with the clip as read (the motion's cache, motion.c). A walk within a
 * bound stops at the first sample above it; with the world matrices
 * kept, it leaves them to the rounding's refinement (precision.c). Both
 * run on up to MOTION_LANES threads, a range of samples each, with the
 * serial walk's floats.
 */
#include <math.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "motion/motion_internal.h"

#define LEVEL_STRIDE 16 /* of the walks within a bound: every LEVEL_STRIDE-th sample first */

/* Level clips have the common clip's channels: m's buffers serve. */
void motion_walk_begin(mlod_motion *m, const mlod_clip *clip, motion_walk *w)
{
	w->clip = clip;
	w->fast = clip->channel_count <= m->common.channel_count && eval_clip_ok(clip);
	w->segs = m->walk_segs;
	w->local = m->walk_local;
	for (int i = 0; w->fast && i < clip->channel_count; i++)
		w->segs[i].k = -1, w->segs[i].ready = 0;
	mlod_pose_rest(m->s, w->local);
}

/* The clip as read at sample f (cached or posed into m->world0). */
static const mlod_mat4 *orig_world(mlod_motion *m, int f)
{
	if (m->cache0)
		return m->cache0 + (size_t)f * (size_t)m->s->joint_count;
	motion_pose_at(m, m->orig, m->st[f], m->world0);
	return m->world0;
}

/* The level at sample f (samples in increasing order) into m->world. */
static void walk_pose(mlod_motion *m, motion_walk *w, int f)
{
	if (w->fast) {
		/* Every sample sets the same paths: the rest of local stays rest. */
		eval_sample(w->clip, w->segs, m->st[f], w->local);
		eval_pose_world(m->s, w->local, m->world);
	} else {
		motion_pose_at(m, w->clip, m->st[f], m->world);
	}
}

/* mlod_v3_length(mlod_v3_sub(mlod_mat4_point(a, o), mlod_mat4_point(b, o))),
 * inline: the same float operations in the same order (motion_level_measure
 * and measure_lane take it 627,342 times on CMU 01_01's levels). */
EVAL_INLINE double point_gap(const mlod_mat4 *a, const mlod_mat4 *b, mlod_v3 o)
{
	const float *x = a->m, *y = b->m;
	float px = x[0] * o.x + x[4] * o.y + x[8] * o.z + x[12], py = x[1] * o.x + x[5] * o.y + x[9] * o.z + x[13],
	      pz = x[2] * o.x + x[6] * o.y + x[10] * o.z + x[14];
	float qx = y[0] * o.x + y[4] * o.y + y[8] * o.z + y[12], qy = y[1] * o.x + y[5] * o.y + y[9] * o.z + y[13],
	      qz = y[2] * o.x + y[6] * o.y + y[10] * o.z + y[14];
	float dx = px - qx, dy = py - qy, dz = pz - qz;
	return sqrtf(dx * dx + dy * dy + dz * dz);
}

/* motion_level_within_keep and motion_level_measure (with its world matrices
 * given) on motion_lanes(m) threads, a range of samples each: every sample's
 * floats are computed alone (its own walk state: eval_sample's floats do
 * not depend on the samples before), so they are the serial walk's. */
typedef struct walk_par {
	mlod_motion *m;
	const mlod_clip *clip;
	double bound;
	mlod_trs *L;
	mlod_mat4 *LM, *W;
	const mlod_mat4 *known;
	int lanes;
	atomic_int failed, oom, nan;
	double *d;                   /* the measure: per sample, its distances in the serial order */
	int per;                     /* distances per sample */
	double worst[MOTION_LANES], max[MOTION_LANES];
} walk_par;

static void lane_range(const walk_par *x, int i, int *lo, int *hi)
{
	long S = x->m->samples;
	*lo = (int)(S * i / x->lanes);
	*hi = (int)(S * (i + 1) / x->lanes);
}

EVAL_INLINE mlod_result within_lane_body(void *ctx, int i, int wide)
{
	walk_par *x = ctx;
	mlod_motion *m = x->m;
	const mlod_skeleton *s = m->s;
	const int J = s->joint_count;
	int lo, hi;
	lane_range(x, i, &lo, &hi);
	eval_seg *segs = malloc(sizeof *segs * (size_t)(x->clip->channel_count > 0 ? x->clip->channel_count : 1));
	mlod_trs *local = malloc(sizeof *local * (size_t)J);
	if (!segs || !local) {
		free(segs);
		free(local);
		atomic_store(&x->oom, 1);
		return MLOD_OK;
	}
	for (int c = 0; c < x->clip->channel_count; c++)
		segs[c].k = -1, segs[c].ready = 0;
	mlod_pose_rest(s, local);
	int ok = 1, n = hi - lo, stride = n >= 4 * LEVEL_STRIDE ? LEVEL_STRIDE : 1;
	for (int pass = stride > 1 ? 0 : 1; pass < 2 && ok; pass++)
		for (int f = lo; f < hi && ok; f += pass ? 1 : stride) {
			if (pass == 1 && stride > 1 && (f - lo) % stride == 0)
				continue;
			if (atomic_load_explicit(&x->failed, memory_order_relaxed))
				ok = 0;
			size_t base = (size_t)f * (size_t)J;
			const mlod_mat4 *w0 = m->cache0 + base;
			mlod_trs *lf = x->L + base;
			mlod_mat4 *lmf = x->LM + base, *wf = x->W + base;
			eval_sample(x->clip, segs, m->st[f], local);
			memcpy(lf, local, sizeof *lf * (size_t)J);
			for (int j = 0; j < J; j++) {
				int p = s->joints[j].parent;
				lmf[j] = eval_from_trs(&lf[j]);
				wf[j] = p < 0 ? eval_mul(&s->joints[j].base, &lmf[j]) : eval_mul_affine_w(&wf[p], &lmf[j], wide);
			}
			for (int j = 0; j < J && ok; j++)
				ok = eval_within_w(&wf[j], &w0[j], m->radius[j], x->bound, wide);
			if (!ok)
				atomic_store(&x->failed, 1);
		}
	free(segs);
	free(local);
	return MLOD_OK;
}

/* within_lane_body compiled twice (motion_eval.h): the same floats. */
static mlod_result within_lane_generic(void *ctx, int i)
{
	return within_lane_body(ctx, i, 0);
}
#if EVAL_HAVE_AVX2
EVAL_TARGET_AVX2 static mlod_result within_lane_avx2(void *ctx, int i)
{
	return within_lane_body(ctx, i, 1);
}
#endif

/* motion_level_within_keep into L, LM and W on lanes: 1 or 0, or -1 when it
 * could not (the caller walks alone). */
static int level_within_par(mlod_motion *m, const mlod_clip *clip, double bound, mlod_trs *L, mlod_mat4 *LM,
                            mlod_mat4 *W, int lanes)
{
	walk_par x;
	memset(&x, 0, sizeof x);
	x.m = m, x.clip = clip, x.bound = bound, x.L = L, x.LM = LM, x.W = W, x.lanes = lanes;
	atomic_init(&x.failed, 0);
	atomic_init(&x.oom, 0);
	atomic_init(&x.nan, 0);
	mlod_result (*lane)(void *, int) = within_lane_generic;
#if EVAL_HAVE_AVX2
	if (eval_avx2())
		lane = within_lane_avx2;
#endif
	mlod_parallel_for(lanes, lanes, lane, &x);
	if (atomic_load(&x.oom))
		return -1;
	return !atomic_load(&x.failed);
}

static mlod_result measure_lane(void *ctx, int i)
{
	walk_par *x = ctx;
	mlod_motion *m = x->m;
	const mlod_skeleton *s = m->s;
	const int J = s->joint_count;
	int lo, hi;
	lane_range(x, i, &lo, &hi);
	double worst = 0.0, max = 0.0;
	for (int f = lo; f < hi; f++) {
		const mlod_mat4 *w0 = m->cache0 + (size_t)f * (size_t)J, *wl = x->known + (size_t)f * (size_t)J;
		double *d = x->d + (size_t)f * (size_t)x->per;
		for (int j = 0; j < J; j++) {
			double e = eval_error_over(&wl[j], &w0[j], m->radius[j], worst);
			if (e >= 0.0 && !(e <= worst))
				worst = e;
			else if (e != e) {
				atomic_store(&x->nan, 1);
				return MLOD_OK;
			}
			for (int k = 0; k < 1 + (s->joints[j].has_end_site != 0); k++) {
				mlod_v3 o = { 0, 0, 0 };
				if (k == 1)
					o = s->joints[j].end_site;
				double dist = point_gap(&w0[j], &wl[j], o);
				*d++ = dist;
				if (dist > max)
					max = dist;
			}
		}
	}
	x->worst[i] = worst;
	x->max[i] = max;
	return MLOD_OK;
}

/* motion_level_measure with known on lanes: the largest errors are the
 * largest of the ranges', the sum is taken over the stored distances in
 * the serial order. 1 or 0 as motion_level_measure, -1 when it could not. */
static int level_measure_par(mlod_motion *m, const mlod_mat4 *known, double *point_error, mlod_deviation *dev,
                             int lanes)
{
	const mlod_skeleton *s = m->s;
	walk_par x;
	memset(&x, 0, sizeof x);
	x.m = m, x.known = known, x.lanes = lanes;
	atomic_init(&x.failed, 0);
	atomic_init(&x.oom, 0);
	atomic_init(&x.nan, 0);
	for (int j = 0; j < s->joint_count; j++)
		x.per += 1 + (s->joints[j].has_end_site != 0);
	size_t count = (size_t)m->samples * (size_t)x.per;
	x.d = malloc(sizeof *x.d * (count ? count : 1));
	if (!x.d)
		return -1;
	mlod_parallel_for(lanes, lanes, measure_lane, &x);
	if (atomic_load(&x.nan)) {
		free(x.d);
		return 0;
	}
	double worst = 0.0, max = 0.0, sum = 0.0;
	for (int i = 0; i < lanes; i++) {
		if (x.worst[i] > worst)
			worst = x.worst[i];
		if (x.max[i] > max)
			max = x.max[i];
	}
	for (size_t k = 0; k < count; k++)
		sum += x.d[k];
	free(x.d);
	*point_error = worst;
	memset(dev, 0, sizeof *dev);
	dev->max = max;
	dev->mean = count ? sum / (double)count : 0.0;
	return 1;
}

/* Largest point error (mlod_motion_point_error) of a level clip over
 * every joint and every sample of the common timeline (frames and the
 * times between them), in scene units. It bounds the joint and End Site
 * position error. A NaN error counts as the worst and ends the walk.
 */
double motion_level_max_error(mlod_motion *m, const mlod_clip *clip)
{
	motion_walk w;
	motion_walk_begin(m, clip, &w);
	double worst = 0.0;
	for (int f = 0; f < m->samples; f++) {
		const mlod_mat4 *w0 = orig_world(m, f);
		walk_pose(m, &w, f);
		for (int j = 0; j < m->s->joint_count; j++) {
			double e = eval_error_over(&m->world[j], &w0[j], m->radius[j], worst);
			worst = eval_worst(worst, e);
		}
		if (!(worst <= HUGE_VAL))
			break;
	}
	return worst;
}

/* A level's measures in one walk: *point_error gets motion_level_max_error's
 * value and *dev mlod_joint_deviation_at's at the same samples (the same
 * sums in the same order, from the same world matrices: the level's from
 * the same float operations, and the clip as read from its cache).
 * Returns 0 when it could not (no cache, or a NaN error): the caller then
 * measures as those functions do. */
int motion_level_measure(mlod_motion *m, const mlod_clip *clip, const mlod_mat4 *known, double *point_error,
                         mlod_deviation *dev)
{
	if (!m->cache0)
		return 0;
	int lanes = motion_lanes(m);
	if (known && lanes > 1 && m->samples >= 64 * lanes) {
		int r = level_measure_par(m, known, point_error, dev, lanes);
		if (r >= 0)
			return r;
	}
	const mlod_skeleton *s = m->s;
	motion_walk w;
	motion_walk_begin(m, clip, &w);
	double worst = 0.0, sum = 0.0, max = 0.0;
	long count = 0;
	for (int f = 0; f < m->samples; f++) {
		const mlod_mat4 *w0 = orig_world(m, f);
		const mlod_mat4 *wl = m->world;
		if (known)
			wl = known + (size_t)f * (size_t)s->joint_count;
		else
			walk_pose(m, &w, f);
		for (int j = 0; j < s->joint_count; j++) {
			double e = eval_error_over(&wl[j], &w0[j], m->radius[j], worst);
			if (e >= 0.0 && !(e <= worst))
				worst = e;
			else if (e != e)
				return 0;
			for (int k = 0; k < 1 + (s->joints[j].has_end_site != 0); k++) {
				mlod_v3 o = { 0, 0, 0 };
				if (k == 1)
					o = s->joints[j].end_site;
				double d = point_gap(&w0[j], &wl[j], o);
				sum += d;
				count++;
				if (d > max)
					max = d;
			}
		}
	}
	*point_error = worst;
	memset(dev, 0, sizeof *dev);
	dev->max = max;
	dev->mean = count ? sum / (double)count : 0.0;
	return 1;
}

/* Is motion_level_max_error(m, clip) <= bound? It stops at the first error
 * above. The samples are independent: every LEVEL_STRIDE-th goes first
 * (a level that does not fit usually fails sooner), then the others in
 * order; the answer is the same. */
/* With L, LM, W (samples * joints each) and a clip eval_sample samples,
 * each sample visited leaves there the level's local transforms, their
 * matrices and its world matrices (the same floats as walk_pose and
 * eval_from_trs), and *kept is set: when the level fits, at every sample. */
EVAL_INLINE int level_within_keep_body(mlod_motion *m, const mlod_clip *clip, double bound, mlod_trs *L,
                                       mlod_mat4 *LM, mlod_mat4 *W, int *kept, int wide)
{
	motion_walk w;
	motion_walk_begin(m, clip, &w);
	const mlod_skeleton *s = m->s;
	const int J = s->joint_count, keep = L && w.fast;
	int ok = 1, stride = m->samples >= 4 * LEVEL_STRIDE ? LEVEL_STRIDE : 1;
	if (kept)
		*kept = keep;
	int lanes = motion_lanes(m);
	if (keep && m->cache0 && lanes > 1 && m->samples >= 64 * lanes) {
		int r = level_within_par(m, clip, bound, L, LM, W, lanes);
		if (r >= 0)
			return r;
	}
	for (int pass = stride > 1 ? 0 : 1; pass < 2 && ok; pass++)
		for (int f = 0; f < m->samples && ok; f += pass ? 1 : stride) {
			if (pass == 1 && stride > 1 && f % stride == 0)
				continue;
			const mlod_mat4 *w0 = orig_world(m, f);
			const mlod_mat4 *wl = m->world;
			if (keep) {
				/* walk_pose (eval_sample, eval_pose_world) into the buffers */
				size_t base = (size_t)f * (size_t)J;
				mlod_trs *lf = L + base;
				mlod_mat4 *lmf = LM + base, *wf = W + base;
				eval_sample(clip, w.segs, m->st[f], w.local);
				memcpy(lf, w.local, sizeof *lf * (size_t)J);
				for (int j = 0; j < J; j++) {
					int p = s->joints[j].parent;
					lmf[j] = eval_from_trs(&lf[j]);
					wf[j] = p < 0 ? eval_mul(&s->joints[j].base, &lmf[j]) : eval_mul_affine_w(&wf[p], &lmf[j], wide);
				}
				wl = wf;
			} else {
				walk_pose(m, &w, f);
			}
			for (int j = 0; j < J && ok; j++)
				ok = eval_within_w(&wl[j], &w0[j], m->radius[j], bound, wide);
		}
	return ok;
}

/* level_within_keep_body compiled twice (motion_eval.h): the same floats. */
static int level_within_keep_generic(mlod_motion *m, const mlod_clip *clip, double bound, mlod_trs *L, mlod_mat4 *LM,
                                     mlod_mat4 *W, int *kept)
{
	return level_within_keep_body(m, clip, bound, L, LM, W, kept, 0);
}
#if EVAL_HAVE_AVX2
EVAL_TARGET_AVX2 static int level_within_keep_avx2(mlod_motion *m, const mlod_clip *clip, double bound, mlod_trs *L,
                                                   mlod_mat4 *LM, mlod_mat4 *W, int *kept)
{
	return level_within_keep_body(m, clip, bound, L, LM, W, kept, 1);
}
#endif
int motion_level_within_keep(mlod_motion *m, const mlod_clip *clip, double bound, mlod_trs *L, mlod_mat4 *LM,
                             mlod_mat4 *W, int *kept)
{
#if EVAL_HAVE_AVX2
	if (eval_avx2())
		return level_within_keep_avx2(m, clip, bound, L, LM, W, kept);
#endif
	return level_within_keep_generic(m, clip, bound, L, LM, W, kept);
}

int motion_level_within(mlod_motion *m, const mlod_clip *clip, double bound)
{
	return motion_level_within_keep(m, clip, bound, NULL, NULL, NULL, NULL);
}

/* motion_level_within over samples lo..hi only. */
int motion_level_within_range(mlod_motion *m, const mlod_clip *clip, double bound, int lo, int hi)
{
	motion_walk w;
	motion_walk_begin(m, clip, &w);
	int ok = 1;
	for (int f = lo; f <= hi && ok; f++) {
		const mlod_mat4 *w0 = orig_world(m, f);
		walk_pose(m, &w, f);
		for (int j = 0; j < m->s->joint_count && ok; j++)
			ok = eval_within(&m->world[j], &w0[j], m->radius[j], bound);
	}
	return ok;
}
