/*
 * keyreduce.c: per-channel key reduction under a hierarchical error bound.
 *
 * Beyond the paper (whose motion layer, 4.3, removes whole frames; see
 * motiontree.c): each animated channel of each joint keeps only the keys it
 * needs, in the manner of ozz-animation's keyframe optimizer and of ACL's
 * "virtual vertex" error (Frechette, "Animation Compression Library").
 * The error of a joint at a frame is the point error (pointerror.c)
 *
 *     |o' - o| + r * sigma_max(A' - A)
 *
 * where o, A are the origin and the 3x3 linear part of the joint's world
 * matrix as read, o', A' those of the reduced clip, and r the larger of
 * point_distance and the joint's End Site offset: it bounds how far any
 * point within r of the joint moves (for a pure rotation error of angle
 * t it is 2 r sin(t/2), the exact displacement of the farthest point).
 * A key may go only if, at every sample of the common timeline (its
 * frames and the `subdivide - 1` times between each two), this error
 * stays within the bound for the joint and every descendant, given every
 * other channel as it currently is; the check is exact (the same
 * sampling and float forward kinematics as mlod_clip_sample and
 * mlod_pose_world), so the bound holds for the final clip at every sample.
 *
 * Search: per channel, from a kept key, the farthest key the segment can
 * reach is found by galloping (2, 3, 5, 9, ... keys ahead) then bisection,
 * and the keys in between go. Channels are swept root first, in rounds
 * whose budget grows (a quarter of the bound, a half, ...), so no channel
 * spends the whole budget before the others had a share (4 rounds, root
 * first, measured best of 1/2/4/8 rounds and root or leaves first on the
 * samples). Last, a channel whose last value equals its first and that
 * fits that constant collapses to one key; the first and last frames of
 * every channel are thus kept exactly.
 *
 * Threads: a channel's reduction reads and writes only its joint's local
 * transforms and the world matrices of its joint's subtree (and the
 * parent's world matrices, which it only reads). Two channels whose
 * joints are not one below the other touch disjoint parts, so their
 * reductions commute. The sweeps' sequence of tasks (a channel at a
 * round) then runs on several threads, each task once every earlier task
 * of a joint above, below or the same has finished: the result is the
 * sequence's, bit for bit, at any thread count. Each thread has its own
 * check buffers (a lane); the subtree's world matrices of a check go to
 * shared buffers, in the check's own joints' columns.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "motion/mlod_motion.h"
#include "motion/motion_eval.h"

#define MAX_FRAME_JOINTS MLOD_KEYREDUCE_MAX_SAMPLES /* frames * joints the caches may hold */
#define ROUNDS 4
#define MAX_LANES 8              /* threads of one key reduction */

/* What a thread's checks need of their own. */
typedef struct lane {
	mlod_trs *lb[2];         /* S: the channel's joint's local transform in a check */
	mlod_mat4 *lmb[2];       /* S: its matrix */
	int good;                /* which buffers hold the last check that fitted */
	const mlod_channel *good_ch; /* and of what: channel, samples */
	int good_lo, good_hi;
	unsigned *stamp;         /* S: the check that took the sample first */
	unsigned stamp_now;
	int *K;                  /* F: a channel's kept frames */
} lane;

typedef struct reducer {
	const mlod_skeleton *s;
	const mlod_clip *common;
	int F, J;
	int per;                 /* samples per frame interval: frame f is sample f * per */
	int S;                   /* samples: (F - 1) * per + 1 */
	float *times;            /* S sample times */
	double *radius;          /* per joint */
	int *sub_start, *sub;    /* per joint: the joint and its descendants, parents first */
	int *subp;               /* the parent of each entry of sub */
	mlod_mat4 *w0;           /* S * J: world matrices as read */
	int own_w0;              /* 0: the caller's */
	mlod_trs *lc;            /* S * J: current local transforms */
	mlod_mat4 *lm;           /* S * J: their matrices */
	mlod_mat4 *wc;           /* S * J: current world matrices */
	mlod_mat4 *wb[2];        /* S * J: world matrices of a check (the subtree's; a lane's good
	                            buffer is its own lane's good index) */
	unsigned char *kept;
	int lanes;
	int avx2;                /* the AVX2 copy of the checks (eval_avx2) */
	lane lane[MAX_LANES];
	eval_scratch own;        /* the arrays above (lc to the lanes') when no scratch is given */
	/* The tasks on threads: task t is channel t % C at round t / C + 1
	 * (ROUNDS + 1: the collapse). */
	double bound;
	int tasks, C;
	unsigned char *related;  /* C * C: the channels' joints are one below the other (or the same) */
} reducer;

static int comps_of(const mlod_channel *ch)
{
	return ch->path == MLOD_PATH_ROTATION ? 4 : 3;
}

/* Sets one path of a local transform from comps values, as mlod_clip_sample does. */
EVAL_INLINE void set_path(mlod_trs *l, mlod_path path, const float *v)
{
	switch (path) {
	case MLOD_PATH_TRANSLATION: l->t.x = v[0], l->t.y = v[1], l->t.z = v[2]; break;
	case MLOD_PATH_SCALE: l->s.x = v[0], l->s.y = v[1], l->s.z = v[2]; break;
	case MLOD_PATH_ROTATION: l->r = eval_normalize((mlod_quat){ v[0], v[1], v[2], v[3] }); break;
	}
}

/* Does the joint's world matrix w stay within budget of w0? A float
 * bound of the point error decides first (the same answer); only when it
 * cannot, mlod_motion_point_within with its early exits. */
EVAL_INLINE int within(const reducer *R, int j, const mlod_mat4 *w, const mlod_mat4 *w0, double budget, int wide)
{
	if (eval_error_bound_w(w, w0, R->radius[j], wide) <= budget)
		return 1; /* the same answer as below, from a float bound */
#if EVAL_HAVE_AVX2
	if (R->avx2)
		return motion_point_within_avx2(w, w0, R->radius[j], budget);
#endif
	return mlod_motion_point_within(w, w0, R->radius[j], budget);
}

/* The channel's value at sample f and the subtree's world matrices with
 * it, into the spare buffers; is every joint within budget? Compiled
 * twice (sample_check_generic, sample_check_avx2: motion_eval.h), the
 * same floats. */
EVAL_INLINE int sample_check_body(reducer *R, lane *L, const mlod_channel *ch, const float *va, const float *vb, float t0,
                        float dt, eval_seg *seg, int constant, int f, double budget, int wide)
{
	const mlod_skeleton *s = R->s;
	int j = ch->joint, p = s->joints[j].parent, comps = comps_of(ch), spare = 1 - L->good;
	const int *sub = R->sub + R->sub_start[j], *subp = R->subp + R->sub_start[j];
	int nsub = R->sub_start[j + 1] - R->sub_start[j];
	float v[4];
	if (constant || ch->interp == MLOD_INTERP_STEP) {
		memcpy(v, va, sizeof(float) * (size_t)comps);
	} else {
		/* As mlod_clip_sample computes it from the two keys, with the
		 * slerp's per-segment part done once. */
		const float u = (R->times[f] - t0) / dt;
		if (comps == 4) {
			mlod_quat q = eval_slerp(seg, va, vb, u);
			v[0] = q.x, v[1] = q.y, v[2] = q.z, v[3] = q.w;
		} else {
			for (int c = 0; c < 3; c++)
				v[c] = va[c] + (vb[c] - va[c]) * u;
		}
	}
	size_t base = (size_t)f * (size_t)R->J;
	mlod_trs *l = &L->lb[spare][f];
	mlod_mat4 *lm = &L->lmb[spare][f], *w = R->wb[spare] + base;
	*l = R->lc[base + (size_t)j];
	set_path(l, ch->path, v);
	*lm = eval_from_trs(l);
	w[j] = p < 0 ? eval_mul(&s->joints[j].base, lm) : eval_mul_affine_w(&R->wc[base + (size_t)p], lm, wide);
	if (!within(R, j, &w[j], &R->w0[base + (size_t)j], budget, wide))
		return 0;
	for (int k = 1; k < nsub; k++) {
		int d = sub[k], dp = subp[k];
		w[d] = eval_mul_affine_w(&w[dp], &R->lm[base + (size_t)d], wide);
		if (!within(R, d, &w[d], &R->w0[base + (size_t)d], budget, wide))
			return 0;
	}
	return 1;
}

#define SAMPLE_CHECK_ARGS                                                                                              \
	reducer *R, lane *L, const mlod_channel *ch, const float *va, const float *vb, float t0, float dt, eval_seg *seg, \
	        int constant, int f, double budget
static int sample_check_generic(SAMPLE_CHECK_ARGS)
{
	return sample_check_body(R, L, ch, va, vb, t0, dt, seg, constant, f, budget, 0);
}
#if EVAL_HAVE_AVX2
EVAL_TARGET_AVX2 static int sample_check_avx2(SAMPLE_CHECK_ARGS)
{
	return sample_check_body(R, L, ch, va, vb, t0, dt, seg, constant, f, budget, 1);
}
#define sample_check(R, ...) \
	((R)->avx2 ? sample_check_avx2(R, __VA_ARGS__) : sample_check_generic(R, __VA_ARGS__))
#else
#define sample_check sample_check_generic
#endif

/* The samples lo..hi not stamped id, in order, each as sample_check
 * checks it but inline (most of a check's samples come here): 0 at the
 * first that does not fit. Compiled twice as sample_check. */
#define SAMPLE_REST_ARGS                                                                                          \
	reducer *R, lane *L, const mlod_channel *ch, const float *va, const float *vb, float t0, float dt, eval_seg *seg, \
	        int constant, int lo, int hi, const unsigned *stamp, unsigned id, double budget
EVAL_INLINE int sample_rest_body(SAMPLE_REST_ARGS, int wide)
{
	for (int f = lo; f <= hi; f++)
		if (stamp[f] != id && !sample_check_body(R, L, ch, va, vb, t0, dt, seg, constant, f, budget, wide))
			return 0;
	return 1;
}
static int sample_rest_generic(SAMPLE_REST_ARGS)
{
	return sample_rest_body(R, L, ch, va, vb, t0, dt, seg, constant, lo, hi, stamp, id, budget, 0);
}
#if EVAL_HAVE_AVX2
EVAL_TARGET_AVX2 static int sample_rest_avx2(SAMPLE_REST_ARGS)
{
	return sample_rest_body(R, L, ch, va, vb, t0, dt, seg, constant, lo, hi, stamp, id, budget, 1);
}
#define sample_rest(R, ...) ((R)->avx2 ? sample_rest_avx2(R, __VA_ARGS__) : sample_rest_generic(R, __VA_ARGS__))
#else
#define sample_rest sample_rest_generic
#endif

/* Checks channel ch taking, at samples lo..hi (inclusive), the values of
 * the segment between its keys at frames a and b (or a's value, constant).
 * The samples are independent (each needs only the current matrices at
 * that sample), so they go in the order that finds a failure soonest: the
 * frames of the keys the segment removes first (gone[0..ngone - 1], the
 * last first: there the segment departs most from what was kept), then
 * every SWEEP_STRIDE-th sample, then the others in order. The answer is
 * the same in any order. When every sample fits, the results become the
 * good buffers, which sweep_commit applies. */
#define SWEEP_STRIDE 8
static int sweep_check(reducer *R, lane *L, const mlod_channel *ch, int a, int b, int lo, int hi, int constant,
                       double budget, const int *gone, int ngone)
{
	int comps = comps_of(ch);
	eval_seg seg = { -1, 0, 0, { 0, 0, 0, 1 }, { 0, 0, 0, 1 }, 0.0, 0.0, 0.0 };
	const float *va = ch->values + (size_t)a * (size_t)comps, *vb = ch->values + (size_t)b * (size_t)comps;
	const float t0 = R->times[a * R->per], dt = R->times[b * R->per] - t0;
	int stride = hi - lo + 1 >= 4 * SWEEP_STRIDE ? SWEEP_STRIDE : 1;
	unsigned id = ++L->stamp_now, *stamp = L->stamp;
	if (id == 0) { /* wrapped: start the stamps again */
		memset(stamp, 0, sizeof(unsigned) * (size_t)R->S);
		id = L->stamp_now = 1;
	}
	for (int k = ngone - 1; k >= 0; k--) {
		int f = gone[k] * R->per;
		stamp[f] = id;
		if (!sample_check(R, L, ch, va, vb, t0, dt, &seg, constant, f, budget))
			return 0;
	}
	for (int f = lo; f <= hi && stride > 1; f += stride)
		if (stamp[f] != id) {
			stamp[f] = id;
			if (!sample_check(R, L, ch, va, vb, t0, dt, &seg, constant, f, budget))
				return 0;
		}
	if (!sample_rest(R, L, ch, va, vb, t0, dt, &seg, constant, lo, hi, stamp, id, budget)) /* in memory order */
		return 0;
	L->good = 1 - L->good;
	L->good_ch = ch, L->good_lo = lo, L->good_hi = hi;
	return 1;
}

/* Applies the last check that fitted (channel ch at samples lo..hi). */
static void sweep_commit(reducer *R, lane *L, const mlod_channel *ch, int a, int b, int lo, int hi, int constant)
{
	if (L->good_ch != ch || L->good_lo != lo || L->good_hi != hi)
		sweep_check(R, L, ch, a, b, lo, hi, constant, HUGE_VAL, NULL, 0); /* not reached: the last fit is the one applied */
	int j = ch->joint, g = L->good;
	const int *sub = R->sub + R->sub_start[j];
	int nsub = R->sub_start[j + 1] - R->sub_start[j];
	for (int f = lo; f <= hi; f++) {
		size_t base = (size_t)f * (size_t)R->J;
		R->lc[base + (size_t)j] = L->lb[g][f];
		R->lm[base + (size_t)j] = L->lmb[g][f];
		for (int k = 0; k < nsub; k++)
			R->wc[base + (size_t)sub[k]] = R->wb[g][base + (size_t)sub[k]];
	}
	L->good_ch = NULL;
}

/* Removes what keys it can from one channel at one budget. */
static void reduce_channel(reducer *R, lane *L, int c, double budget)
{
	int *K = L->K;
	const mlod_channel *ch = &R->common->channels[c];
	unsigned char *row = R->kept + (size_t)c * (size_t)R->F;
	int nk = 0;
	const int q = R->per;
	for (int f = 0; f < R->F; f++)
		if (row[f])
			K[nk++] = f;
	for (int i = 0; i + 2 < nk + 0 && i < nk - 1;) {
		int ok = i + 1, fail = nk, step = 1, probe = i + 2;
		while (probe < nk) {
			if (sweep_check(R, L, ch, K[i], K[probe], K[i] * q + 1, K[probe] * q - 1, 0, budget, K + i + 1, probe - i - 1)) {
				ok = probe;
				step *= 2;
				probe = i + 1 + step;
			} else {
				fail = probe;
				break;
			}
		}
		if (fail == nk && ok < nk - 1) {
			if (sweep_check(R, L, ch, K[i], K[nk - 1], K[i] * q + 1, K[nk - 1] * q - 1, 0, budget, K + i + 1, nk - 2 - i))
				ok = nk - 1;
			else
				fail = nk - 1;
		}
		while (fail - ok > 1) {
			int mid = ok + (fail - ok) / 2;
			if (sweep_check(R, L, ch, K[i], K[mid], K[i] * q + 1, K[mid] * q - 1, 0, budget, K + i + 1, mid - i - 1))
				ok = mid;
			else
				fail = mid;
		}
		if (ok > i + 1) {
			sweep_commit(R, L, ch, K[i], K[ok], K[i] * q + 1, K[ok] * q - 1, 0);
			for (int k = i + 1; k < ok; k++)
				row[K[k]] = 0;
		}
		i = ok;
	}
}

/* Collapses a channel to its first key when that constant fits. */
static void collapse_channel(reducer *R, lane *L, int c, double budget)
{
	const mlod_channel *ch = &R->common->channels[c];
	unsigned char *row = R->kept + (size_t)c * (size_t)R->F;
	int first = -1, count = 0;
	for (int f = 0; f < R->F; f++)
		if (row[f]) {
			if (first < 0)
				first = f;
			count++;
		}
	if (count < 2 || first != 0)
		return;
	/* The last frame must stay exact: only a channel that ends where it
	 * starts can become its first key. */
	int comps = comps_of(ch);
	if (memcmp(ch->values, ch->values + (size_t)(R->F - 1) * (size_t)comps, sizeof(float) * (size_t)comps) != 0)
		return;
	if (!sweep_check(R, L, ch, 0, 0, 1, R->S - 1, 1, budget, NULL, 0))
		return;
	sweep_commit(R, L, ch, 0, 0, 1, R->S - 1, 1);
	memset(row + 1, 0, (size_t)R->F - 1);
}

/* Task t of the sweeps (reducer.tasks). */
static void run_task(reducer *R, lane *L, int t)
{
	int c = t % R->C, round = t / R->C + 1;
	if (round <= ROUNDS)
		reduce_channel(R, L, c, R->bound * round / ROUNDS);
	else
		collapse_channel(R, L, c, R->bound);
}

static void task_item(void *ctx, int lane, int t)
{
	reducer *R = ctx;
	run_task(R, &R->lane[lane], t);
}

static int task_conflict(void *ctx, int u, int t)
{
	const reducer *R = ctx;
	return R->related[(size_t)(u % R->C) * (size_t)R->C + (size_t)(t % R->C)];
}

/* The sweeps: every task in order, or on threads lanes (the same result). */
static mlod_result run_tasks(reducer *R)
{
	if (R->lanes <= 1) {
		for (int t = 0; t < R->tasks; t++)
			run_task(R, &R->lane[0], t);
		return MLOD_OK;
	}
	R->related = malloc((size_t)R->C * (size_t)R->C);
	if (!R->related)
		return MLOD_ERR_NOMEM;
	for (int a = 0; a < R->C; a++)
		for (int b = 0; b < R->C; b++)
			R->related[(size_t)a * (size_t)R->C + (size_t)b] = (unsigned char)eval_joints_related(
				R->s, R->common->channels[a].joint, R->common->channels[b].joint);
	return motion_run_tasks(R->tasks, R->lanes, task_conflict, task_item, R);
}

static void reducer_free(reducer *R)
{
	free(R->times);
	free(R->radius);
	free(R->sub_start);
	free(R->sub);
	free(R->subp);
	if (R->own_w0)
		free(R->w0);
	free(R->related);
	free(R->own.p); /* lc to the lanes': in the scratch */
}

static mlod_result check_args(const mlod_skeleton *s, const mlod_clip *original, const mlod_clip *common, double bound,
                              double point_distance, int subdivide, const unsigned char *kept, mlod_error *err)
{
	if (!s || !original || !common || !kept)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_keyreduce: NULL argument");
	if (!(bound >= 0.0) || !isfinite(bound) || !(point_distance >= 0.0) || !isfinite(point_distance))
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_keyreduce: bad bound %g or point distance %g", bound,
		                 point_distance);
	if (subdivide < 1 || subdivide > MLOD_MAX_SUBDIVIDE)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_keyreduce: subdivide %d is not 1 to %d", subdivide,
		                 MLOD_MAX_SUBDIVIDE);
	if (s->joint_count <= 0 || common->channel_count <= 0 || !common->channels)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_keyreduce: no joints or no channels");
	const mlod_channel *c0 = &common->channels[0];
	int F = c0->key_count;
	if (F <= 0)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_keyreduce: no frames");
	mlod_result fits = mlod_motion_keys_fit(s->joint_count, F, subdivide, common->name, err);
	if (fits != MLOD_OK)
		return fits;
	for (int c = 0; c < common->channel_count; c++) {
		const mlod_channel *ch = &common->channels[c];
		const unsigned char *row = kept + (size_t)c * (size_t)F;
		if (ch->key_count != F || !ch->times || !ch->values ||
		    memcmp(ch->times, c0->times, sizeof(float) * (size_t)F) != 0)
			return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_keyreduce: channel %d is not on the common timeline", c);
		if (ch->joint < 0 || ch->joint >= s->joint_count || (unsigned)ch->path > MLOD_PATH_SCALE ||
		    (ch->interp != MLOD_INTERP_LINEAR && ch->interp != MLOD_INTERP_STEP))
			return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_keyreduce: channel %d: bad joint, path or interpolation", c);
		if (!row[0])
			return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_keyreduce: channel %d does not keep its first frame", c);
	}
	for (int j = 0; j < s->joint_count; j++)
		if (s->joints[j].parent >= j)
			return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_keyreduce: joint %d comes before its parent", j);
	return MLOD_OK;
}

mlod_result mlod_motion_keys_fit(int joint_count, int frames, int subdivide, const char *name, mlod_error *err)
{
	char q[MLOD_NAME_TEXT_SIZE];
	if (((double)frames - 1.0) * subdivide * joint_count > (double)MAX_FRAME_JOINTS)
		return mlod_fail(err, MLOD_ERR_LIMIT,
		                 "clip %s: %d frames (%d samples each) of %d joints is more than the keys method holds (%ld); "
		                 "split the clip",
		                 mlod_name_text(name, 1, q, sizeof q), frames, subdivide, joint_count, MAX_FRAME_JOINTS);
	return MLOD_OK;
}

mlod_result mlod_keyreduce(const mlod_skeleton *s, const mlod_clip *original, const mlod_clip *common, double bound,
                           double point_distance, int subdivide, unsigned char *kept, mlod_error *err)
{
	return keyreduce_run(s, original, common, bound, point_distance, subdivide, kept, NULL, NULL, NULL, NULL, 1, err);
}

/* The reduction's starting state, on up to R->lanes threads (the same
 * floats at any count: each channel's and each sample's values are
 * computed alone). setup_item i: the kept keys' values of channels
 * [i C / n, (i + 1) C / n) into lc (a joint's channels set different
 * fields), prevk and nextk the item's; frames_item i: lm and wc of
 * samples [i S / n, (i + 1) S / n). */
typedef struct setup_ctx {
	reducer *R;
	int n;
	int *prevk, *nextk; /* n * F */
} setup_ctx;

/* Channel ch's path of l at sample f, from its kept keys (first and last
 * the first and last kept, a and b those around f), as mlod_clip_sample
 * computes it: seg is the slerp's per-segment part, kept while a stays. */
/* The first and last kept frames of a channel's row (-1, -1: none). */
static void kept_span(const unsigned char *row, int F, int *first, int *last)
{
	*first = *last = -1;
	for (int k = 0; k < F; k++)
		if (row[k]) {
			if (*first < 0)
				*first = k;
			*last = k;
		}
}

EVAL_INLINE void setup_value(const reducer *R, const mlod_channel *ch, int first, int last, int a, int b, int f, eval_seg *seg,
                            mlod_trs *l)
{
	float v[4];
	int comps = comps_of(ch);
	if (first == last || f <= first * R->per || f >= last * R->per) {
		int k = f >= last * R->per && first != last ? last : first;
		memcpy(v, ch->values + (size_t)k * (size_t)comps, sizeof(float) * (size_t)comps);
	} else {
		/* As mlod_clip_sample computes it from the kept keys around f,
		 * the slerp's per-segment part done once a segment. */
		const float *va = ch->values + (size_t)a * (size_t)comps, *vb = ch->values + (size_t)b * (size_t)comps;
		const float t0 = R->times[a * R->per], dt = R->times[b * R->per] - t0;
		const float u = (R->times[f] - t0) / dt;
		if (ch->interp == MLOD_INTERP_STEP) {
			memcpy(v, va, sizeof(float) * (size_t)comps);
		} else if (comps == 4) {
			mlod_quat q = eval_slerp(seg, va, vb, u);
			v[0] = q.x, v[1] = q.y, v[2] = q.z, v[3] = q.w;
		} else {
			for (int c = 0; c < 3; c++)
				v[c] = va[c] + (vb[c] - va[c]) * u;
		}
	}
	set_path(l, ch->path, v);
}

static mlod_result setup_item(void *ctx, int i)
{
	setup_ctx *x = ctx;
	reducer *R = x->R;
	int *prevk = x->prevk + (size_t)i * (size_t)R->F, *nextk = x->nextk + (size_t)i * (size_t)R->F;
	int c0 = (int)((long)i * R->C / x->n), c1 = (int)((long)(i + 1) * R->C / x->n);
	for (int c = c0; c < c1; c++) {
		const mlod_channel *ch = &R->common->channels[c];
		const unsigned char *row = R->kept + (size_t)c * (size_t)R->F;
		int first, last;
		kept_span(row, R->F, &first, &last);
		for (int k = 0, p = -1; k < R->F; k++) /* prevk: the last kept at or before k */
			prevk[k] = p = row[k] ? k : p;
		for (int k = R->F - 1, n = -1; k >= 0; k--) { /* nextk: the first kept after k */
			nextk[k] = n;
			if (row[k])
				n = k;
		}
		eval_seg seg = { -1, 0, 0, { 0, 0, 0, 1 }, { 0, 0, 0, 1 }, 0.0, 0.0, 0.0 };
		int seg_a = -1;
		for (int f = 0; f < R->S; f++) {
			int a = prevk[f / R->per];
			if (a != seg_a)
				seg.ready = 0, seg_a = a;
			setup_value(R, ch, first, last, a, nextk[f / R->per], f, &seg,
			            &R->lc[(size_t)f * (size_t)R->J + (size_t)ch->joint]);
		}
	}
	return MLOD_OK;
}

static mlod_result frames_item(void *ctx, int i)
{
	setup_ctx *x = ctx;
	reducer *R = x->R;
	int f0 = (int)((long)i * R->S / x->n), f1 = (int)((long)(i + 1) * R->S / x->n);
	for (int f = f0; f < f1; f++) {
		size_t base = (size_t)f * (size_t)R->J;
		mlod_trs *l = R->lc + base;
		for (int j = 0; j < R->J; j++)
			R->lm[base + (size_t)j] = eval_from_trs(&l[j]); /* mlod_mat4_from_trs, inline */
		for (int j = 0; j < R->J; j++) {
			int p = R->s->joints[j].parent;
			/* mlod_mat4_mul; below a root, its affine form (the same floats) */
			R->wc[base + (size_t)j] = p < 0 ? eval_mul(&R->s->joints[j].base, &R->lm[base + (size_t)j])
			                                : eval_mul_affine(&R->wc[base + (size_t)p], &R->lm[base + (size_t)j]);
		}
	}
	return MLOD_OK;
}

/* Can the run take st's local transforms and matrices as its start? Only
 * when they were made from the same clip, skeleton, samples and w0 and
 * end on the keys it starts from (kept), and they are what setup_item and
 * frames_item would compute:
 *
 * - a sample that the last commit covering it (sweep_commit) set, or that
 *   no commit covered, holds the value from the kept keys around it,
 *   computed as setup_item computes it (sample_check: the same segment
 *   and u, a fresh slerp segment; collapse_channel: the first key), and
 *   the keys around it are still the kept ones around it: a key that
 *   goes makes its segment commit every sample between its neighbours;
 * - every commit recomputes the world matrices of its joint's subtree
 *   from the parent's, as frames_item does, so wc is the chain of lm;
 * - but a kept key's own sample holds the value its last setup computed
 *   with the next key then kept, which may have gone since: the slerp
 *   at u = 0 gives the key's normalised value whatever the next key, but
 *   for the sign of a zero, and a NaN or infinity in the next key. These
 *   samples are computed again here and compared bit for bit. */
static int state_fits(const reducer *R, const keyreduce_state *st, const mlod_mat4 *w0)
{
	size_t size = (size_t)R->C * (size_t)R->F;
	if (!st->valid || st->s != R->s || st->common != R->common || st->w0 != w0 || !w0 || st->per != R->per ||
	    st->nkept != size || st->fj != (size_t)R->S * (size_t)R->J || memcmp(st->kept, R->kept, size) != 0)
		return 0;
	for (int c = 0; c < R->C; c++) {
		const mlod_channel *ch = &R->common->channels[c];
		const unsigned char *row = R->kept + (size_t)c * (size_t)R->F;
		int first, last;
		kept_span(row, R->F, &first, &last);
		for (int k = first, next; k >= 0 && k <= last; k = next) {
			for (next = k + 1; next <= last && !row[next]; next++)
				;
			int f = k * R->per;
			size_t at = (size_t)f * (size_t)R->J + (size_t)ch->joint;
			mlod_trs l = st->lc[at];
			eval_seg seg = { -1, 0, 0, { 0, 0, 0, 1 }, { 0, 0, 0, 1 }, 0.0, 0.0, 0.0 };
			setup_value(R, ch, first, last, k, next <= last ? next : k, f, &seg, &l);
			if (memcmp(&l, &st->lc[at], sizeof l) != 0)
				return 0;
		}
	}
	return 1;
}

mlod_result keyreduce_run(const mlod_skeleton *s, const mlod_clip *original, const mlod_clip *common, double bound,
                          double point_distance, int subdivide, unsigned char *kept, const mlod_mat4 *w0,
                          double *max_error, eval_scratch *scratch, keyreduce_state *state, int threads,
                          mlod_error *err)
{
	if (max_error)
		*max_error = -1.0;
	mlod_result r = check_args(s, original, common, bound, point_distance, subdivide, kept, err);
	if (r != MLOD_OK)
		return r;
	reducer R;
	memset(&R, 0, sizeof R);
	R.s = s;
	R.common = common;
	R.F = common->channels[0].key_count;
	R.J = s->joint_count;
	R.per = subdivide;
	R.S = (R.F - 1) * R.per + 1;
	R.kept = kept;
	R.C = common->channel_count;
	R.tasks = (ROUNDS + 1) * R.C;
	R.bound = bound;
	R.lanes = threads < 1 ? 1 : threads > MAX_LANES ? MAX_LANES : threads;
	R.avx2 = eval_avx2();
	size_t FJ = (size_t)R.S * (size_t)R.J;
	R.times = malloc(sizeof(float) * (size_t)R.S);
	R.radius = malloc(sizeof(double) * (size_t)R.J);
	R.sub_start = calloc((size_t)R.J + 1, sizeof(int));
	R.own_w0 = !w0;
	R.w0 = w0 ? (mlod_mat4 *)w0 : malloc(sizeof(mlod_mat4) * FJ); /* not written when given */
	{
		size_t S = (size_t)R.S;
		size_t F = (size_t)R.F;
		size_t per_lane = 2 * eval_carve_size(sizeof(mlod_trs) * S) + 2 * eval_carve_size(sizeof(mlod_mat4) * S) +
		                  eval_carve_size(sizeof(unsigned) * S) + eval_carve_size(sizeof(int) * F);
		size_t need = (state ? 0 : eval_carve_size(sizeof(mlod_trs) * FJ) + 2 * eval_carve_size(sizeof(mlod_mat4) * FJ)) +
		              2 * eval_carve_size(sizeof(mlod_mat4) * FJ) + (size_t)R.lanes * per_lane;
		char *at = eval_scratch_get(scratch ? scratch : &R.own, need);
		if (state && state->fj != FJ) {
			keyreduce_state_free(state);
			state->lc = malloc(sizeof(mlod_trs) * FJ);
			state->lm = malloc(sizeof(mlod_mat4) * FJ);
			state->wc = malloc(sizeof(mlod_mat4) * FJ);
			if (state->lc && state->lm && state->wc)
				state->fj = FJ;
			else
				keyreduce_state_free(state); /* and R.lc stays NULL: out of memory */
		}
		if (at && (!state || state->fj == FJ)) {
			if (state) {
				R.lc = state->lc, R.lm = state->lm, R.wc = state->wc;
			} else {
				R.lc = eval_carve(&at, sizeof(mlod_trs) * FJ);
				R.lm = eval_carve(&at, sizeof(mlod_mat4) * FJ);
				R.wc = eval_carve(&at, sizeof(mlod_mat4) * FJ);
			}
			for (int i = 0; i < 2; i++)
				R.wb[i] = eval_carve(&at, sizeof(mlod_mat4) * FJ);
			for (int n = 0; n < R.lanes; n++) {
				lane *L = &R.lane[n];
				L->stamp = eval_carve(&at, sizeof(unsigned) * S);
				memset(L->stamp, 0, sizeof(unsigned) * S);
				for (int i = 0; i < 2; i++) {
					L->lb[i] = eval_carve(&at, sizeof(mlod_trs) * S);
					L->lmb[i] = eval_carve(&at, sizeof(mlod_mat4) * S);
				}
				L->K = eval_carve(&at, sizeof(int) * F);
			}
		}
	}
	int *depth = malloc(sizeof(int) * (size_t)R.J);
	int *prevk = malloc(sizeof(int) * (size_t)R.F * (size_t)R.lanes);
	int *nextk = malloc(sizeof(int) * (size_t)R.F * (size_t)R.lanes);
	int *fill = NULL;
	if (!R.times || !R.radius || !R.sub_start || !R.w0 || !R.lc || !depth || !prevk || !nextk) {
		r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
		goto done;
	}
	/* Subtrees: joint j's descendants d (parents before children) are
	 * listed after j; sizes first. */
	long total = 0;
	for (int j = 0; j < R.J; j++) {
		const mlod_joint *jt = &s->joints[j];
		double es = jt->has_end_site ? mlod_v3_length(jt->end_site) : 0.0;
		R.radius[j] = es > point_distance ? es : point_distance;
		depth[j] = jt->parent < 0 ? 0 : depth[jt->parent] + 1;
		total += depth[j] + 1;
	}
	R.sub = malloc(sizeof(int) * (size_t)total);
	R.subp = malloc(sizeof(int) * (size_t)total);
	fill = calloc((size_t)R.J, sizeof(int));
	if (!R.sub || !R.subp || !fill) {
		r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
		goto done;
	}
	for (int d = 0; d < R.J; d++)
		for (int a = d; a >= 0; a = s->joints[a].parent)
			R.sub_start[a + 1]++;
	for (int j = 0; j < R.J; j++)
		R.sub_start[j + 1] += R.sub_start[j];
	for (int d = 0; d < R.J; d++) /* d in index order: parents first in every list */
		for (int a = d; a >= 0; a = s->joints[a].parent)
			R.subp[R.sub_start[a] + fill[a]] = s->joints[d].parent, R.sub[R.sub_start[a] + fill[a]++] = d;

	mlod_motion_sample_times(common->channels[0].times, R.F, R.per, R.times);
	if (state) {
		int fits = state_fits(&R, state, w0);
		state->valid = 0; /* until this run ends */
		state->reused = fits;
		if (fits)
			goto reduce;
	}
	/* The clip as read, and as currently kept. */
	for (int f = 0; f < R.S; f++) {
		size_t base = (size_t)f * (size_t)R.J;
		mlod_trs *l = R.lc + base;
		if (R.own_w0) {
			mlod_pose_rest(s, l);
			mlod_clip_sample(original, R.times[f], l);
			mlod_pose_world(s, l, R.w0 + base);
		}
		mlod_pose_rest(s, l);
	}
	/* The kept keys' values (those of mlod_clip_sample on the kept keys,
	 * each sample's kept neighbours looked up), channel by channel in
	 * order, as mlod_clip_sample sets them. */
	setup_ctx sx = { &R, R.lanes, prevk, nextk };
	mlod_parallel_for(sx.n, sx.n, setup_item, &sx);
	mlod_parallel_for(sx.n, sx.n, frames_item, &sx);
reduce:

	/* Rounds of reduce_channel over the channels at a growing budget, then
	 * collapse_channel over them at the whole bound. */
	if ((r = run_tasks(&R)) != MLOD_OK) {
		r = mlod_fail(err, r, "out of memory");
		goto done;
	}
	/* The largest point error of the result, as levelerror.c's
	 * motion_level_max_error measures the level clip of these keys: the same
	 * sampling (the kept values are mlod_clip_sample's on
	 * those keys) and kinematics, when no sample time is past the clip's
	 * duration (mlod_clip_sample would clamp it). */
	if (max_error && R.times[R.S - 1] <= common->duration) {
		double worst = 0.0;
		for (int f = 0; f < R.S; f++) {
			size_t base = (size_t)f * (size_t)R.J;
			for (int j = 0; j < R.J; j++) {
				double e = eval_error_over(&R.wc[base + (size_t)j], &R.w0[base + (size_t)j], R.radius[j], worst);
				worst = eval_worst(worst, e);
			}
			if (!(worst <= HUGE_VAL))
				break;
		}
		*max_error = worst != worst ? -1.0 : worst;
	}
	if (state) {
		size_t size = (size_t)R.C * (size_t)R.F;
		if (state->nkept != size) {
			free(state->kept);
			state->kept = malloc(size);
			state->nkept = state->kept ? size : 0;
		}
		if (state->kept) {
			memcpy(state->kept, kept, size);
			state->s = s, state->common = common, state->w0 = w0, state->per = R.per;
			state->valid = 1;
		}
	}
done:
	free(depth);
	free(prevk);
	free(nextk);
	free(fill);
	reducer_free(&R);
	return r;
}
