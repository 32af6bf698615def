/*
 * motion.c: the multiresolution motion tree and motion levels (paper 4.3,
 * with the energy weight of 4.1.2).
 *
 * Savoye & Meyer merge "nearby postures": two neighbouring frames fuse
 * when the distance between them, "the energy needed to move all joints
 * from one frame to the other", is below a threshold, by "removing a frame
 * from among the two or by merging the two into a single frame, preserving
 * the duration". We read it so (mlod-motion(1), Common timeline, Frame
 * distance, The multiresolution motion tree):
 *
 * - Common timeline (timeline.c). A clip is first put on frames shared by all its
 *   channels: its own keys when they agree, else the union of the key
 *   times (exact for LINEAR and STEP), with CUBICSPLINE intervals
 *   subdivided to at least cubic_rate frames per second.
 * - Frame distance. For each joint, the energy weight (h - depth) / h
 *   (h = tree height, max depth + 1, as in label.c) times the total
 *   absolute change of its three Euler angles divided by pi (the axis
 *   range Max(R) without joint limits). Angles are taken in the joint's
 *   own order, differences wrapped into (-pi, pi] and the nearer of the
 *   two Euler triples of the rotation used, so q against -q and 179
 *   against -179 degrees is no motion. Beyond the paper, translation
 *   change over the skeleton height and scale change are added, so root
 *   motion counts.
 * - The tree. Line 0 is every frame. One pass scans neighbouring pairs
 *   left to right and fuses each disjoint pair closer than the threshold,
 *   giving the next line; a level at threshold T is the line reached when
 *   no neighbouring pair is closer than T any more (passes repeat). A
 *   level is built from the previous one, so levels are nested. Removal
 *   keeps the frame of the pair that linear interpolation of its
 *   neighbours reproduces worse; averaging puts one frame at the pair's
 *   mean time (frames weighted by how many original frames they stand
 *   for). The first and last frames are pinned: a pair holding one
 *   keeps it as it is, so the duration is kept.
 * - Levels are chosen by threshold, by the fraction of keys kept
 *   (bisection on the threshold), or by an error bound (bisection on the
 *   threshold, accepting only thresholds whose level measures within the
 *   bound at every frame of the common timeline). Removal measured better
 *   than averaging (bench/RESULTS.md) and is the default.
 * - The keys method (keyreduce.c) is driven from here the same way, with
 *   the error budget in place of the threshold.
 * - Value precision (beyond the paper). Keys go within (1 - share) of
 *   the bound; the values are then rounded, so that few bits vary and
 *   gzip/zstd compress them well: the coarsest level grid whose measured
 *   error stays within the bound is bisected (translations on it,
 *   rotations and scales finer by their joint's reach), then each channel
 *   takes coarser grids while the bound holds. A rotation's three smaller
 *   components are rounded and its largest recomputed from them, so it
 *   stays (about) unit. By default (auto) rotations go on the lattice of
 *   normalised shorts, as gltfpack stores them (core glTF), and
 *   translations and scales stay float32 on power-of-two grids; float
 *   keeps every value float32, with the first and last keys exact.
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
 */
#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "motion/mlod_motion.h"
#include "motion/motion_eval.h"

#define SEARCH_STEPS 24 /* bisection steps: the threshold to 2^-24 of its range */
#define MAX_CACHED 1000000L /* frames * joints whose world matrices as read are cached */
#define KEYS_RETRIES 6
#define DEFAULT_PRECISION_SHARE 0.1 /* of a max-error bound left to rounding (bench/RESULTS.md) */

static int comps_of(const mlod_channel *ch)
{
	return ch->path == MLOD_PATH_ROTATION ? 4 : 3;
}

double mlod_motion_point_distance(const mlod_skeleton *s, int metres)
{
	if (metres)
		return MLOD_POINT_DISTANCE_METRES;
	double h = mlod_skeleton_height(s);
	return (h > 0.0 ? h : 1.0) / 18.0;
}

/* ---------------------------------------------------------------- */
/* Frame distance                                                    */
/* ---------------------------------------------------------------- */

/* Sum of |wrapped differences| between two Euler triples of one order,
 * the nearer of the two triples of b: (A, B, C) and (A + pi, pi - B, C + pi)
 * over the order's axes, outermost first. */
static double euler_change(mlod_euler_order order, const float *ea, const float *eb)
{
	const int *ax = mlod_euler_axes(order);
	double d1 = 0.0, d2 = 0.0;
	for (int a = 0; a < 3; a++)
		d1 += fabs(eval_wrap_angle((double)eb[a] - ea[a]));
	double alt[3];
	alt[ax[0]] = eb[ax[0]] + MLOD_PI;
	alt[ax[1]] = MLOD_PI - eb[ax[1]];
	alt[ax[2]] = eb[ax[2]] + MLOD_PI;
	/* d2's partial sums only grow (each term is >= 0, and rounding is
	 * monotonic): once d1 is below one, it is below d2. */
	for (int a = 0; a < 3; a++) {
		d2 += fabs(eval_wrap_angle(alt[a] - ea[a]));
		if (d1 < d2)
			return d1;
	}
	return d1 < d2 ? d1 : d2;
}

/* Energy weights (h - depth) / h, h = max depth + 1 (label.c's weight). */
static void joint_weights(const mlod_skeleton *s, double *w)
{
	int *depth = malloc(sizeof(int) * (size_t)(s->joint_count > 0 ? s->joint_count : 1));
	int max_depth = 0;
	for (int j = 0; j < s->joint_count; j++) {
		int p = s->joints[j].parent;
		int d = p >= 0 && p < j && depth ? depth[p] + 1 : 0;
		if (depth)
			depth[j] = d;
		if (d > max_depth)
			max_depth = d;
		w[j] = d; /* for now */
	}
	double h = max_depth + 1.0;
	for (int j = 0; j < s->joint_count; j++)
		w[j] = (h - w[j]) / h;
	free(depth);
}

static double v3_dist(mlod_v3 a, mlod_v3 b)
{
	double dx = (double)a.x - b.x, dy = (double)a.y - b.y, dz = (double)a.z - b.z;
	return sqrt(dx * dx + dy * dy + dz * dz);
}

double mlod_motion_frame_distance(const mlod_skeleton *s, const mlod_trs *a, const mlod_trs *b)
{
	if (!s || !a || !b || s->joint_count <= 0)
		return 0.0;
	double *w = malloc(sizeof(double) * (size_t)s->joint_count);
	if (!w)
		return HUGE_VAL;
	joint_weights(s, w);
	double height = mlod_skeleton_height(s), d = 0.0;
	for (int j = 0; j < s->joint_count; j++) {
		float ea[3], eb[3];
		mlod_quat_to_euler(s->joints[j].euler, a[j].r, ea);
		mlod_quat_to_euler(s->joints[j].euler, b[j].r, eb);
		d += w[j] * (euler_change(s->joints[j].euler, ea, eb) / MLOD_PI + v3_dist(a[j].t, b[j].t) / height +
		             v3_dist(a[j].s, b[j].s));
	}
	free(w);
	return d;
}

/* ---------------------------------------------------------------- */
/* The motion context                                                */
/* ---------------------------------------------------------------- */

/* Memo of the tree's frame distances and residuals between frames of the
 * common timeline: they depend only on the frames (a node that is frame f
 * has its values), and the bisection on the threshold rebuilds the tree
 * from the same line many times. Keys (a, b, -1) for a distance, (p, x, q)
 * for a residual. */
typedef struct memo_slot {
	int a, b, c; /* a = -1: empty */
	double v;
} memo_slot;

typedef struct memo {
	memo_slot *slot;
	size_t cap, n; /* cap a power of two */
} memo;

#define MEMO_MAX ((size_t)1 << 21) /* slots at most */

static size_t memo_hash(int a, int b, int c)
{
	unsigned long long h = (unsigned)a * 0x9E3779B97F4A7C15ull;
	h ^= (unsigned)b * 0xC2B2AE3D27D4EB4Full + (h >> 29);
	h ^= (unsigned)c * 0x165667B19E3779F9ull + (h >> 31);
	return (size_t)(h ^ (h >> 32));
}

static int memo_get(const memo *mo, int a, int b, int c, double *v)
{
	if (!mo->slot)
		return 0;
	for (size_t i = memo_hash(a, b, c) & (mo->cap - 1);; i = (i + 1) & (mo->cap - 1)) {
		const memo_slot *e = &mo->slot[i];
		if (e->a < 0)
			return 0;
		if (e->a == a && e->b == b && e->c == c) {
			*v = e->v;
			return 1;
		}
	}
}

static void memo_put(memo *mo, int a, int b, int c, double v)
{
	if (2 * (mo->n + 1) > mo->cap) { /* at most half full */
		size_t cap = mo->cap ? 2 * mo->cap : 4096;
		if (cap > MEMO_MAX)
			return;
		memo_slot *slot = malloc(sizeof *slot * cap);
		if (!slot)
			return;
		for (size_t i = 0; i < cap; i++)
			slot[i].a = -1;
		for (size_t k = 0; k < mo->cap; k++) {
			const memo_slot *e = &mo->slot[k];
			if (e->a < 0)
				continue;
			size_t i = memo_hash(e->a, e->b, e->c) & (cap - 1);
			while (slot[i].a >= 0)
				i = (i + 1) & (cap - 1);
			slot[i] = *e;
		}
		free(mo->slot);
		mo->slot = slot;
		mo->cap = cap;
	}
	size_t i = memo_hash(a, b, c) & (mo->cap - 1);
	while (mo->slot[i].a >= 0)
		i = (i + 1) & (mo->cap - 1);
	mo->slot[i] = (memo_slot){ a, b, c, v };
	mo->n++;
}

/* A frame of a line of the tree: its time, the channel values (V floats,
 * laid out by channel) and the Euler angles of its rotation channels. */
typedef struct fnode {
	double time;
	int leaves;      /* original frames it stands for */
	int frame;       /* the common frame it is (removal), or -1 (averaged) */
	float *values;   /* V floats, then 3 * rotation channels Euler angles */
} fnode;

typedef struct line {
	int n;
	fnode *v;
} line;

/* The setup's owners: mlod_motion_create's motion and those made like it
 * (mlod_motion_create_like) share its read-only arrays (common, st,
 * weight, offset, euler_slot, constant, radius, reach_exp, cache0); the
 * last one freed frees them. */
typedef struct setup_refs {
	atomic_int n;
} setup_refs;

struct mlod_motion {
	const mlod_character *c;
	setup_refs *refs;      /* NULL: the setup is this motion's alone */
	const mlod_skeleton *s;
	const mlod_clip *orig;
	mlod_motion_options opt;
	mlod_clip common;
	mlod_motion_timeline info;
	int frames;
	int sub;               /* samples per frame interval (mlod_motion_options.subdivide) */
	int samples;           /* (frames - 1) * sub + 1 */
	float *st;             /* sample times: frame f is sample f * sub */
	double height;
	double *weight;        /* per joint */
	int value_count;       /* V */
	int rot_count;
	int *offset;           /* per channel: first value in a node */
	int *euler_slot;       /* per channel: Euler slot of a rotation channel, else -1 */
	unsigned char *constant; /* per channel: the same value at every frame */
	double *radius;        /* per joint: the point distance, or its End Site's if farther */
	int *reach_exp;        /* per joint: -ceil(log2(2 reach)), reach the farthest point it carries */
	mlod_trs *local;
	mlod_mat4 *world, *world0;
	mlod_mat4 *cache0;     /* samples * joints world matrices as read, or NULL */
	eval_seg *walk_segs;   /* per channel: sampling level clips (level_walk) */
	int clip_end_ok;       /* no sample time past the clip's duration (level clips are not clamped) */
	mlod_trs *walk_local;  /* per joint */
	/* State of each method: the last line of the tree, the keys kept. */
	line tree;
	int tree_started;      /* tree holds line 0 or a later one (tree_start) */
	double tree_total;     /* total_neighbour_distance of tree, or < 0: not yet */
	unsigned char *kept;   /* channel_count * frames */
	memo *memo;            /* the tree's distances and residuals */
	memo *segmemo;         /* frames level under way: segments of lines within its bound */
	eval_scratch scratch;  /* the large arrays of the key reduction and of refine_channels */
	keyreduce_state kstate; /* the last key reduction's end state */
	int threads;           /* of the key reduction (mlod_motion_set_threads) */
};

static void line_free(line *l)
{
	for (int i = 0; l->v && i < l->n; i++)
		free(l->v[i].values);
	free(l->v);
	l->v = NULL;
	l->n = 0;
}

void mlod_motion_free(mlod_motion *m)
{
	if (!m)
		return;
	if (!m->refs || atomic_fetch_sub(&m->refs->n, 1) == 1) {
		free(m->refs);
		mlod_clip_free(&m->common);
		free(m->st);
		free(m->weight);
		free(m->offset);
		free(m->euler_slot);
		free(m->constant);
		free(m->radius);
		free(m->reach_exp);
		free(m->cache0);
	}
	free(m->local);
	free(m->world);
	free(m->world0);
	free(m->walk_segs);
	free(m->walk_local);
	line_free(&m->tree);
	free(m->kept);
	if (m->memo)
		free(m->memo->slot);
	free(m->memo);
	if (m->segmemo)
		free(m->segmemo->slot);
	free(m->segmemo);
	free(m->scratch.p);
	keyreduce_state_free(&m->kstate);
	free(m);
}

void mlod_motion_set_threads(mlod_motion *m, int threads)
{
	if (m)
		m->threads = threads < 1 ? 1 : threads;
}

const mlod_motion_timeline *mlod_motion_timeline_info(const mlod_motion *m)
{
	return m ? &m->info : NULL;
}

/* Poses the skeleton with clip at t into world. */
static void pose_at(mlod_motion *m, const mlod_clip *clip, float t, mlod_mat4 *world)
{
	mlod_pose_rest(m->s, m->local);
	mlod_clip_sample(clip, t, m->local);
	mlod_pose_world(m->s, m->local, world);
}

/* Fills node values from common frame f, and its Euler angles (with
 * skip_constant, not those of constant channels, which node_distance
 * leaves out). */
static void node_euler_of(const mlod_motion *m, fnode *nd, int skip_constant)
{
	for (int i = 0; i < m->common.channel_count; i++) {
		int slot = m->euler_slot[i];
		if (slot < 0 || (skip_constant && m->constant[i]))
			continue;
		const float *q = nd->values + m->offset[i];
		mlod_quat r = { q[0], q[1], q[2], q[3] };
		mlod_quat_to_euler(m->s->joints[m->common.channels[i].joint].euler, r, nd->values + m->value_count + 3 * slot);
	}
}

static void node_euler(const mlod_motion *m, fnode *nd)
{
	node_euler_of(m, nd, 0);
}

static int node_from_frame(const mlod_motion *m, int f, fnode *nd)
{
	nd->values = malloc(sizeof(float) * (size_t)(m->value_count + 3 * m->rot_count + 1));
	if (!nd->values)
		return -1;
	nd->time = m->common.channels[0].times[f];
	nd->leaves = 1;
	nd->frame = f;
	for (int i = 0; i < m->common.channel_count; i++) {
		const mlod_channel *ch = &m->common.channels[i];
		int comps = comps_of(ch);
		memcpy(nd->values + m->offset[i], ch->values + (size_t)f * (size_t)comps, sizeof(float) * (size_t)comps);
	}
	node_euler(m, nd);
	return 0;
}

/* Per joint, how far the points it carries reach in the rest pose: the
 * farthest descendant origin plus that joint's radius. Rounding a
 * rotation or scale by d moves them by about 2 reach d. */
static int reach_exps(mlod_motion *m)
{
	const mlod_skeleton *s = m->s;
	int n = s->joint_count;
	double *reach = malloc(sizeof(double) * (size_t)n);
	m->reach_exp = malloc(sizeof(int) * (size_t)n);
	if (!reach || !m->reach_exp) {
		free(reach);
		return -1;
	}
	mlod_pose_rest(s, m->local);
	mlod_pose_world(s, m->local, m->world);
	for (int j = 0; j < n; j++)
		reach[j] = m->radius[j];
	for (int d = 0; d < n; d++) {
		mlod_v3 pd = mlod_mat4_point(&m->world[d], (mlod_v3){0, 0, 0});
		for (int a = s->joints[d].parent; a >= 0; a = s->joints[a].parent) {
			mlod_v3 pa = mlod_mat4_point(&m->world[a], (mlod_v3){0, 0, 0});
			double r = mlod_v3_length(mlod_v3_sub(pd, pa)) + m->radius[d];
			if (r > reach[a])
				reach[a] = r;
		}
	}
	for (int j = 0; j < n; j++) {
		double r = 2.0 * reach[j];
		m->reach_exp[j] = r > 0.0 && isfinite(r) ? -(int)ceil(log2(r)) : 0;
	}
	free(reach);
	return 0;
}

/* The clip as read at every sample (m->cache0), samples [i S / n,
 * (i + 1) S / n) in item i, each with its own sampling state: a
 * sample's matrices do not depend on the samples before it. */
typedef struct cache_ctx {
	mlod_motion *m;
	const mlod_clip *src;
	int n;
	atomic_int failed;
} cache_ctx;

static mlod_result cache_item(void *ctx, int i)
{
	cache_ctx *x = ctx;
	mlod_motion *m = x->m;
	int n = m->s->joint_count, nch = x->src->channel_count;
	eval_seg *segs = malloc(sizeof *segs * (size_t)(nch > 0 ? nch : 1));
	mlod_trs *local = malloc(sizeof *local * (size_t)n);
	if (!segs || !local) {
		atomic_store(&x->failed, 1);
	} else {
		for (int k = 0; k < nch; k++)
			segs[k].k = -1, segs[k].ready = 0;
		mlod_pose_rest(m->s, local);
		int f0 = (int)((long)i * m->samples / x->n), f1 = (int)((long)(i + 1) * m->samples / x->n);
		for (int f = f0; f < f1; f++) {
			eval_sample(x->src, segs, m->st[f], local);
			eval_pose_world(m->s, local, m->cache0 + (size_t)f * (size_t)n);
		}
	}
	free(segs);
	free(local);
	return MLOD_OK;
}

mlod_result mlod_motion_create(const mlod_character *c, int clip, const mlod_motion_options *opt,
                               mlod_motion **out, mlod_error *err)
{
	return motion_create_on(c, clip, opt, 1, out, err);
}

mlod_result motion_create_on(const mlod_character *c, int clip, const mlod_motion_options *opt, int threads,
                             mlod_motion **out, mlod_error *err)
{
	if (out)
		*out = NULL;
	if (!c || !out)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_motion_create: NULL argument");
	if (clip < 0 || clip >= c->clip_count)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "no clip %d (the character has %d)", clip, c->clip_count);
	const mlod_skeleton *s = &c->skeleton;
	if (s->joint_count <= 0)
		return mlod_fail(err, MLOD_ERR_PARSE, "the skeleton has no joints");
	const mlod_clip *src = &c->clips[clip];
	char q[MLOD_NAME_TEXT_SIZE];
	for (int i = 0; i < src->channel_count; i++)
		if (src->channels && (src->channels[i].joint < 0 || src->channels[i].joint >= s->joint_count))
			return mlod_fail(err, MLOD_ERR_PARSE, "clip %s channel %d: joint %d out of range",
			                 mlod_name_text(src->name, 1, q, sizeof q), i, src->channels[i].joint);
	mlod_motion *m = calloc(1, sizeof *m);
	if (!m)
		return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
	m->c = c;
	m->s = s;
	m->orig = src;
	if (opt)
		m->opt = *opt;
	mlod_result r = mlod_motion_common_clip(src, opt, &m->common, &m->info, err);
	if (r != MLOD_OK) {
		mlod_motion_free(m);
		return r;
	}
	int n = s->joint_count, nch = m->common.channel_count, F = m->info.frames;
	m->frames = F;
	m->sub = opt && opt->subdivide > 0 ? opt->subdivide : MLOD_DEFAULT_SUBDIVIDE;
	if (m->sub > MLOD_MAX_SUBDIVIDE || (opt && opt->subdivide < 0)) {
		mlod_motion_free(m);
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "subdivide %d is not in 0..%d", opt->subdivide, MLOD_MAX_SUBDIVIDE);
	}
	if ((unsigned)m->opt.precision > MLOD_MOTION_PRECISION_FULL) {
		mlod_motion_free(m);
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "unknown precision %d", (int)m->opt.precision);
	}
	if (F > 0 && (double)(F - 1) * m->sub + 1.0 > (double)INT_MAX / 16) {
		mlod_motion_free(m);
		return mlod_fail(err, MLOD_ERR_UNSUPPORTED, "%d frames at %d samples each are too many", F, m->sub);
	}
	/* A clip without joint channels has no frames and no samples: its
	 * levels are empty (empty_level). Sizes below are at least 1. */
	m->samples = F > 0 ? (F - 1) * m->sub + 1 : 0;
	m->st = malloc(sizeof(float) * (size_t)(m->samples + 1));
	m->height = mlod_skeleton_height(s);
	if (!(m->height > 0.0))
		m->height = 1.0;
	m->weight = malloc(sizeof(double) * (size_t)n);
	m->offset = malloc(sizeof(int) * (size_t)(nch + 1));
	m->euler_slot = malloc(sizeof(int) * (size_t)(nch + 1));
	m->constant = malloc((size_t)nch + 1);
	m->local = malloc(sizeof *m->local * (size_t)n);
	m->world = malloc(sizeof *m->world * (size_t)n);
	m->world0 = malloc(sizeof *m->world0 * (size_t)n);
	m->radius = malloc(sizeof(double) * (size_t)n);
	m->walk_segs = malloc(sizeof *m->walk_segs * (size_t)(nch + 1));
	m->walk_local = malloc(sizeof *m->walk_local * (size_t)n);
	if (!m->st || !m->weight || !m->offset || !m->euler_slot || !m->constant || !m->local || !m->world || !m->world0 ||
	    !m->radius || !m->walk_segs || !m->walk_local) {
		mlod_motion_free(m);
		return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
	}
	joint_weights(s, m->weight);
	if (F > 0) {
		mlod_motion_sample_times(m->common.channels[0].times, F, m->sub, m->st);
		m->clip_end_ok = m->st[m->samples - 1] <= src->duration;
	}
	for (int i = 0; i < nch; i++) {
		const mlod_channel *ch = &m->common.channels[i];
		int comps = comps_of(ch);
		m->offset[i] = m->value_count;
		m->value_count += comps;
		m->euler_slot[i] = comps == 4 ? m->rot_count++ : -1;
		m->constant[i] = 1;
		for (int f = 1; f < F && m->constant[i]; f++)
			m->constant[i] = memcmp(ch->values, ch->values + (size_t)f * (size_t)comps, sizeof(float) * (size_t)comps) == 0;
	}
	double pd = opt && opt->point_distance > 0.0 ? opt->point_distance : mlod_motion_point_distance(s, 0);
	for (int j = 0; j < n; j++) {
		double es = s->joints[j].has_end_site ? mlod_v3_length(s->joints[j].end_site) : 0.0;
		m->radius[j] = es > pd ? es : pd;
	}
	if (reach_exps(m) != 0) {
		mlod_motion_free(m);
		return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
	}
	if (m->samples > 0 && (double)m->samples * n <= (double)MAX_CACHED &&
	    (m->cache0 = malloc(sizeof(mlod_mat4) * (size_t)m->samples * (size_t)n)) != NULL) {
		/* mlod_clip_sample and mlod_pose_world, faster (motion_eval.h)
		 * when the clip is LINEAR or STEP. */
		int fast = eval_clip_ok(src) && src->channel_count <= nch;
		if (fast && threads > 1) {
			cache_ctx x;
			x.m = m, x.src = src, x.n = threads < MLOD_MAX_THREADS ? threads : MLOD_MAX_THREADS;
			atomic_init(&x.failed, 0);
			if (mlod_parallel_for(x.n, x.n, cache_item, &x) != MLOD_OK || x.failed) {
				mlod_motion_free(m);
				return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
			}
		} else {
			for (int i = 0; fast && i < src->channel_count; i++)
				m->walk_segs[i].k = -1, m->walk_segs[i].ready = 0;
			mlod_pose_rest(s, m->walk_local);
			for (int f = 0; f < m->samples; f++) {
				mlod_mat4 *w = m->cache0 + (size_t)f * (size_t)n;
				if (fast) {
					eval_sample(src, m->walk_segs, m->st[f], m->walk_local);
					eval_pose_world(s, m->walk_local, w);
				} else {
					pose_at(m, src, m->st[f], w);
				}
			}
		}
	}
	/* Level 0 of each method: every frame, every key (the tree's line
	 * is made when the frames method first needs it: tree_start). */
	m->kept = malloc((size_t)nch * (size_t)F + 1);
	m->memo = calloc(1, sizeof *m->memo);
	m->segmemo = calloc(1, sizeof *m->segmemo);
	m->refs = malloc(sizeof *m->refs);
	if (!m->kept || !m->memo || !m->segmemo || !m->refs) {
		mlod_motion_free(m);
		return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
	}
	atomic_init(&m->refs->n, 1);
	memset(m->kept, 1, (size_t)nch * (size_t)F);
	*out = m;
	return MLOD_OK;
}

static int clip_copy(const mlod_clip *src, mlod_clip *dst);

mlod_result mlod_motion_create_like(const mlod_motion *first, mlod_motion **out, mlod_error *err)
{
	if (out)
		*out = NULL;
	if (!first || !out)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_motion_create_like: NULL argument");
	if (!first->refs)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_motion_create_like: not a motion made by mlod_motion_create");
	mlod_motion *m = calloc(1, sizeof *m);
	if (!m)
		return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
	/* What mlod_motion_create computes from the character, the clip and
	 * the options, shared (read-only from here on); each method's state
	 * starts afresh. */
	atomic_fetch_add(&first->refs->n, 1);
	m->refs = first->refs;
	m->c = first->c;
	m->s = first->s;
	m->orig = first->orig;
	m->opt = first->opt;
	m->info = first->info;
	m->frames = first->frames;
	m->sub = first->sub;
	m->samples = first->samples;
	m->height = first->height;
	m->value_count = first->value_count;
	m->rot_count = first->rot_count;
	m->clip_end_ok = first->clip_end_ok;
	int n = first->s->joint_count, nch = first->common.channel_count, F = first->frames;
	m->common = first->common;
	m->st = first->st;
	m->weight = first->weight;
	m->offset = first->offset;
	m->euler_slot = first->euler_slot;
	m->constant = first->constant;
	m->radius = first->radius;
	m->reach_exp = first->reach_exp;
	m->cache0 = first->cache0;
	m->local = malloc(sizeof *m->local * (size_t)n);
	m->world = malloc(sizeof *m->world * (size_t)n);
	m->world0 = malloc(sizeof *m->world0 * (size_t)n);
	m->walk_segs = malloc(sizeof *m->walk_segs * (size_t)(nch + 1));
	m->walk_local = malloc(sizeof *m->walk_local * (size_t)n);
	m->kept = malloc((size_t)nch * (size_t)F + 1);
	m->memo = calloc(1, sizeof *m->memo);
	m->segmemo = calloc(1, sizeof *m->segmemo);
	if (!m->local || !m->world || !m->world0 || !m->walk_segs || !m->walk_local || !m->kept || !m->memo || !m->segmemo) {
		mlod_motion_free(m);
		return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
	}
	for (int i = 0; i < nch; i++)
		m->walk_segs[i].k = -1, m->walk_segs[i].ready = 0;
	mlod_pose_rest(m->s, m->walk_local);
	memset(m->kept, 1, (size_t)nch * (size_t)F);
	*out = m;
	return MLOD_OK;
}

/* ---------------------------------------------------------------- */
/* Levels as clips, and their error                                   */
/* ---------------------------------------------------------------- */

/* Starts a level clip like the source: name, duration, frame rate. */
static int level_clip_init(const mlod_motion *m, mlod_clip *clip)
{
	memset(clip, 0, sizeof *clip);
	clip->name = mlod_strdup(m->orig->name);
	clip->duration = m->orig->duration;
	clip->frame_time = m->orig->frame_time;
	clip->frame_count = m->orig->frame_count;
	clip->gltf_index = m->orig->gltf_index;
	clip->channel_count = m->common.channel_count;
	clip->channels = clip->channel_count > 0 ? calloc((size_t)clip->channel_count, sizeof *clip->channels) : NULL;
	return clip->name && (clip->channels || clip->channel_count == 0) ? 0 : -1;
}

/* The clip must reach the last frame: a channel with a single key gets a
 * second, equal key there when no channel does. */
static int keep_duration(const mlod_motion *m, mlod_clip *clip)
{
	float end = m->common.channels[0].times[m->frames - 1];
	int single = -1;
	for (int i = 0; i < clip->channel_count; i++) {
		const mlod_channel *ch = &clip->channels[i];
		if (ch->times[ch->key_count - 1] == end)
			return 0;
		if (ch->key_count == 1 && single < 0)
			single = i;
	}
	if (single < 0)
		return 0;
	mlod_channel *ch = &clip->channels[single];
	int comps = comps_of(ch);
	float *t = realloc(ch->times, 2 * sizeof(float)), *v;
	if (!t)
		return -1;
	ch->times = t;
	v = realloc(ch->values, 2 * (size_t)comps * sizeof(float));
	if (!v)
		return -1;
	ch->values = v;
	t[1] = end;
	memcpy(v + comps, v, (size_t)comps * sizeof(float));
	ch->key_count = 2;
	return 0;
}

/* The level clip of a line of the tree; exactly constant channels keep
 * one key. */
static int clip_from_line(const mlod_motion *m, const line *l, mlod_clip *clip)
{
	if (level_clip_init(m, clip) != 0)
		return -1;
	for (int i = 0; i < clip->channel_count; i++) {
		const mlod_channel *src = &m->common.channels[i];
		mlod_channel *ch = &clip->channels[i];
		int comps = comps_of(src), keys = m->constant[i] ? 1 : l->n;
		ch->joint = src->joint;
		ch->path = src->path;
		ch->interp = src->interp;
		ch->key_count = keys;
		ch->times = malloc(sizeof(float) * (size_t)keys);
		ch->values = malloc(sizeof(float) * (size_t)keys * (size_t)comps);
		if (!ch->times || !ch->values)
			return -1;
		float prev = -FLT_MAX;
		for (int k = 0; k < keys; k++) {
			float t = (float)l->v[k].time;
			if (!(t > prev))
				t = nextafterf(prev, FLT_MAX);
			ch->times[k] = prev = t;
			memcpy(ch->values + (size_t)k * (size_t)comps, l->v[k].values + m->offset[i], sizeof(float) * (size_t)comps);
		}
	}
	return keep_duration(m, clip);
}

/* The level clip of a key selection. */
static int clip_from_kept(const mlod_motion *m, const unsigned char *kept, mlod_clip *clip)
{
	if (level_clip_init(m, clip) != 0)
		return -1;
	int F = m->frames;
	for (int i = 0; i < clip->channel_count; i++) {
		const mlod_channel *src = &m->common.channels[i];
		mlod_channel *ch = &clip->channels[i];
		const unsigned char *k = kept + (size_t)i * (size_t)F;
		int comps = comps_of(src), keys = 0;
		for (int f = 0; f < F; f++)
			keys += k[f] != 0;
		ch->joint = src->joint;
		ch->path = src->path;
		ch->interp = src->interp;
		ch->key_count = keys;
		ch->times = malloc(sizeof(float) * (size_t)(keys > 0 ? keys : 1));
		ch->values = malloc(sizeof(float) * (size_t)(keys > 0 ? keys : 1) * (size_t)comps);
		if (!ch->times || !ch->values || keys == 0)
			return -1;
		for (int f = 0, n = 0; f < F; f++) {
			if (!k[f])
				continue;
			ch->times[n] = src->times[f];
			memcpy(ch->values + (size_t)n * (size_t)comps, src->values + (size_t)f * (size_t)comps,
			       sizeof(float) * (size_t)comps);
			n++;
		}
	}
	return keep_duration(m, clip);
}

/* Walks the samples of a level clip: its pose at each sample into
 * world, with the fast sampling of motion_eval.h (the clip's channels are
 * LINEAR or STEP) or mlod_clip_sample. */
typedef struct level_walk {
	const mlod_clip *clip;
	int fast;
	eval_seg *segs;   /* per channel */
	mlod_trs *local;  /* per joint: the rest pose with the animated paths set */
} level_walk;

#define REFINE_LANES 8 /* threads of the rounding's refinement and walks at most */
static int refine_lanes(const mlod_motion *m);
static int level_within_par(mlod_motion *m, const mlod_clip *clip, double bound, mlod_trs *L, mlod_mat4 *LM,
                            mlod_mat4 *W, int lanes);
static int level_measure_par(mlod_motion *m, const mlod_mat4 *known, double *point_error, mlod_deviation *dev,
                             int lanes);

/* Level clips have the common clip's channels: m's buffers serve. */
static void walk_begin(mlod_motion *m, const mlod_clip *clip, level_walk *w)
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
	pose_at(m, m->orig, m->st[f], m->world0);
	return m->world0;
}

/* The level at sample f (samples in increasing order) into m->world. */
static void walk_pose(mlod_motion *m, level_walk *w, int f)
{
	if (w->fast) {
		/* Every sample sets the same paths: the rest of local stays rest. */
		eval_sample(w->clip, w->segs, m->st[f], w->local);
		eval_pose_world(m->s, w->local, m->world);
	} else {
		pose_at(m, w->clip, m->st[f], m->world);
	}
}

/* Largest point error (mlod_motion_point_error) of a level clip over
 * every joint and every sample of the common timeline (frames and the
 * times between them), in scene units. It bounds the joint and End Site
 * position error. A NaN error counts as the worst and ends the walk.
 */
/* mlod_v3_length(mlod_v3_sub(mlod_mat4_point(a, o), mlod_mat4_point(b, o))),
 * inline: the same float operations in the same order (level_measure_of
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

static double level_max_error(mlod_motion *m, const mlod_clip *clip)
{
	level_walk w;
	walk_begin(m, clip, &w);
	double worst = 0.0;
	for (int f = 0; f < m->samples; f++) {
		const mlod_mat4 *w0 = orig_world(m, f);
		walk_pose(m, &w, f);
		for (int j = 0; j < m->s->joint_count; j++) {
			double e = eval_error_over(&m->world[j], &w0[j], m->radius[j], worst);
			if (e >= 0.0 && !(e <= worst))
				worst = e;
			else if (e != e)
				worst = e; /* NaN counts as the worst */
		}
		if (!(worst <= HUGE_VAL))
			break;
	}
	return worst;
}

/* A level's measures in one walk: *point_error gets level_max_error's
 * value and *dev mlod_joint_deviation_at's at the same samples (the same
 * sums in the same order, from the same world matrices: the level's from
 * the same float operations, and the clip as read from its cache).
 * Returns 0 when it could not (no cache, or a NaN error): the caller then
 * measures as those functions do. */
static int level_measure_of(mlod_motion *m, const mlod_clip *clip, const mlod_mat4 *known, double *point_error,
                            mlod_deviation *dev)
{
	if (!m->cache0)
		return 0;
	int lanes = refine_lanes(m);
	if (known && lanes > 1 && m->samples >= 64 * lanes) {
		int r = level_measure_par(m, known, point_error, dev, lanes);
		if (r >= 0)
			return r;
	}
	const mlod_skeleton *s = m->s;
	level_walk w;
	walk_begin(m, clip, &w);
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

/* level_measure_of walking the level clip. */
static int level_measure(mlod_motion *m, const mlod_clip *clip, double *point_error, mlod_deviation *dev)
{
	return level_measure_of(m, clip, NULL, point_error, dev);
}

/* Is level_max_error(m, clip) <= bound? It stops at the first error
 * above. The samples are independent: every LEVEL_STRIDE-th goes first
 * (a level that does not fit usually fails sooner), then the others in
 * order; the answer is the same. */
#define LEVEL_STRIDE 16
/* With L, LM, W (samples * joints each) and a clip eval_sample samples,
 * each sample visited leaves there the level's local transforms, their
 * matrices and its world matrices (the same floats as walk_pose and
 * eval_from_trs), and *kept is set: when the level fits, at every sample. */
EVAL_INLINE int level_within_keep_body(mlod_motion *m, const mlod_clip *clip, double bound, mlod_trs *L,
                                       mlod_mat4 *LM, mlod_mat4 *W, int *kept, int wide)
{
	level_walk w;
	walk_begin(m, clip, &w);
	const mlod_skeleton *s = m->s;
	const int J = s->joint_count, keep = L && w.fast;
	int ok = 1, stride = m->samples >= 4 * LEVEL_STRIDE ? LEVEL_STRIDE : 1;
	if (kept)
		*kept = keep;
	int lanes = refine_lanes(m);
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
static int level_within_keep(mlod_motion *m, const mlod_clip *clip, double bound, mlod_trs *L, mlod_mat4 *LM,
                             mlod_mat4 *W, int *kept)
{
#if EVAL_HAVE_AVX2
	if (eval_avx2())
		return level_within_keep_avx2(m, clip, bound, L, LM, W, kept);
#endif
	return level_within_keep_generic(m, clip, bound, L, LM, W, kept);
}

/* level_within_keep and level_measure_of (with its world matrices
 * given) on refine_lanes(m) threads, a range of samples each: every sample's
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
	double worst[REFINE_LANES], max[REFINE_LANES];
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

/* level_within_keep into L, LM and W on lanes: 1 or 0, or -1 when it
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

/* level_measure_of with known on lanes: the largest errors are the
 * largest of the ranges', the sum is taken over the stored distances in
 * the serial order. 1 or 0 as level_measure_of, -1 when it could not. */
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

static int level_within(mlod_motion *m, const mlod_clip *clip, double bound)
{
	return level_within_keep(m, clip, bound, NULL, NULL, NULL, NULL);
}


/* level_within over samples lo..hi only. */
static int level_within_range(mlod_motion *m, const mlod_clip *clip, double bound, int lo, int hi)
{
	level_walk w;
	walk_begin(m, clip, &w);
	int ok = 1;
	for (int f = lo; f <= hi && ok; f++) {
		const mlod_mat4 *w0 = orig_world(m, f);
		walk_pose(m, &w, f);
		for (int j = 0; j < m->s->joint_count && ok; j++)
			ok = eval_within(&m->world[j], &w0[j], m->radius[j], bound);
	}
	return ok;
}

/* level_within for the clip c of line l (clip_from_line), through the
 * segment memo: every channel of c is keyed at the line's frames (or
 * constant), so its pose at the samples from frame p up to the next frame
 * q of the line (the last sample too when q is the last frame) depends on
 * p and q alone. The bisection on the threshold tries lines that share
 * most of their segments. The memo holds one bound: frames_level clears
 * it. */
static int line_within(mlod_motion *m, const line *l, const mlod_clip *c, double bound)
{
	int usable = m->sub > 0 && c->duration >= m->common.channels[0].times[m->frames - 1] && l->n >= 2 &&
	             l->v[0].frame == 0 && l->v[l->n - 1].frame == m->frames - 1;
	for (int k = 0; usable && k < l->n; k++)
		usable = l->v[k].frame >= 0 && (k == 0 || l->v[k].frame > l->v[k - 1].frame);
	if (!usable)
		return level_within(m, c, bound);
	for (int k = 0; k + 1 < l->n; k++) {
		int p = l->v[k].frame, q = l->v[k + 1].frame;
		double v;
		if (memo_get(m->segmemo, p, q, -3, &v)) {
			if (v == 0.0)
				return 0;
			continue;
		}
		int hi = q == m->frames - 1 ? m->samples - 1 : q * m->sub - 1;
		int ok = level_within_range(m, c, bound, p * m->sub, hi);
		memo_put(m->segmemo, p, q, -3, ok);
		if (!ok)
			return 0;
	}
	return 1;
}

void mlod_motion_level_free(mlod_motion_level *l)
{
	if (!l)
		return;
	mlod_clip_free(&l->clip);
	memset(l, 0, sizeof *l);
}

/* The part of a max-error bound the keys (or frames) may spend: with auto
 * precision, the rest is left to rounding the values. */
static double removal_bound(const mlod_motion *m, double bound)
{
	if (m->opt.precision == MLOD_MOTION_PRECISION_FULL)
		return bound;
	double share = m->opt.precision_share > 0.0 && m->opt.precision_share < 1.0 ? m->opt.precision_share
	                                                                            : DEFAULT_PRECISION_SHARE;
	return bound * (1.0 - share);
}

/* ---------------------------------------------------------------- */
/* Value precision                                                   */
/* ---------------------------------------------------------------- */

#define NO_ROUNDING INT_MIN
#define SHORTS(m) ((m)->opt.precision == MLOD_MOTION_PRECISION_AUTO)
#define GRID_RANGE 48     /* grids tried: from 2^48 times finer than the bound up to it */
#define CHANNEL_COARSER 8 /* per channel, up to this many doublings beyond the level's grid */
#define REFINE_STRIDE 8

/* v rounded to the nearest multiple of 2^e. */
EVAL_INLINE float grid_round(float v, int e)
{
	return (float)ldexp(rint(ldexp((double)v, -e)), e);
}

/* Rounds a unit quaternion: its three smaller components to the grid 2^e,
 * the largest recomputed from them, so it stays unit (and the glTF
 * writer's normalisation leaves it as it is). */
EVAL_INLINE void round_quat(float *q, int e)
{
	int big = 0;
	for (int c = 1; c < 4; c++)
		if (fabsf(q[c]) > fabsf(q[big]))
			big = c;
	float r[4];
	double sum = 0.0;
	for (int c = 0; c < 4; c++)
		if (c != big) {
			r[c] = grid_round(q[c], e);
			sum += (double)r[c] * r[c];
		}
	if (!(sum < 1.0))
		return; /* a grid too coarse for this key: it stays as it is */
	r[big] = copysignf((float)sqrt(1.0 - sum), q[big]);
	mlod_quat n = mlod_quat_normalize((mlod_quat){ r[0], r[1], r[2], r[3] });
	q[0] = n.x, q[1] = n.y, q[2] = n.z, q[3] = n.w;
}

/* dst, laid out as src, gets src's values rounded: channel i to the grid
 * 2^e[i] (NO_ROUNDING: as they are). The first and last key of every
 * channel stay exact. */
/* The lattice of normalised shorts: n / 32767 as glTF readers decode it. */
EVAL_INLINE float short_value(long n)
{
	return (float)((double)n / 32767.0);
}

/* Rounds a unit quaternion onto the lattice of normalised shorts: its three
 * smaller components to multiples of step / 32767 (step a power of two),
 * the largest to the nearest lattice value that makes it unit. */
EVAL_INLINE void round_quat_short(float *q, double step)
{
	int big = 0;
	for (int c = 1; c < 4; c++)
		if (fabsf(q[c]) > fabsf(q[big]))
			big = c;
	double sum = 0.0;
	long n[4];
	for (int c = 0; c < 4; c++)
		if (c != big) {
			n[c] = lrint(rint((double)q[c] * 32767.0 / step) * step);
			n[c] = n[c] > 32767 ? 32767 : n[c] < -32767 ? -32767 : n[c];
			sum += (double)short_value(n[c]) * short_value(n[c]);
		}
	if (!(sum < 1.0)) /* a grid too coarse for this key: the finest lattice */
		for (int c = 0; c < 4; c++)
			n[c] = lrint((double)q[c] * 32767.0);
	else
		n[big] = lrint(copysign(sqrt(1.0 - sum), (double)q[big]) * 32767.0);
	for (int c = 0; c < 4; c++)
		q[c] = short_value(n[c]);
}

/* b gets a's values rounded to the grid 2^e (NO_ROUNDING: as they are),
 * the first and last keys exact; with shorts, a rotation goes on the
 * lattice of normalised shorts instead, every key (the ends on the finest
 * lattice). */
EVAL_INLINE void round_channel_body(const mlod_channel *a, mlod_channel *b, int e, int shorts)
{
	int comps = comps_of(a), n = a->key_count;
	memcpy(b->values, a->values, sizeof(float) * (size_t)n * (size_t)comps);
	b->short_values = 0;
	if (e == NO_ROUNDING)
		return;
	if (shorts && comps == 4 && a->interp != MLOD_INTERP_CUBICSPLINE) {
		int lattice = e + 15 > 0 ? e + 15 : 0; /* 2^e is about 2^(e + 15) / 32767 */
		const double step = ldexp(1.0, lattice); /* once a channel, not once a key */
		for (int k = 0; k < n; k++)
			round_quat_short(b->values + (size_t)k * 4u, k == 0 || k == n - 1 ? 1.0 : step);
		b->short_values = 1;
		return;
	}
	for (int k = 1; k + 1 < n; k++) {
		float *v = b->values + (size_t)k * (size_t)comps;
		if (comps == 4)
			round_quat(v, e);
		else
			for (int c = 0; c < 3; c++)
				v[c] = grid_round(v[c], e);
	}
}

/* round_channel_body compiled twice (motion_eval.h): the same floats (with
 * AVX2, rint is one instruction). */
static void round_channel_generic(const mlod_channel *a, mlod_channel *b, int e, int shorts)
{
	round_channel_body(a, b, e, shorts);
}
#if EVAL_HAVE_AVX2
EVAL_TARGET_AVX2 static void round_channel_avx2(const mlod_channel *a, mlod_channel *b, int e, int shorts)
{
	round_channel_body(a, b, e, shorts);
}
#endif
static void round_channel(const mlod_channel *a, mlod_channel *b, int e, int shorts)
{
#if EVAL_HAVE_AVX2
	if (eval_avx2()) {
		round_channel_avx2(a, b, e, shorts);
		return;
	}
#endif
	round_channel_generic(a, b, e, shorts);
}

static void round_clip(const mlod_clip *src, mlod_clip *dst, const int *e, int shorts)
{
	for (int i = 0; i < src->channel_count; i++)
		round_channel(&src->channels[i], &dst->channels[i], e[i], shorts);
}

/* A deep copy of a level clip, or -1 when out of memory. */
static int clip_copy(const mlod_clip *src, mlod_clip *dst)
{
	*dst = *src;
	dst->name = mlod_strdup(src->name);
	dst->channels = calloc((size_t)src->channel_count, sizeof *dst->channels);
	if (!dst->name || !dst->channels) {
		dst->channel_count = 0;
		return -1;
	}
	for (int i = 0; i < src->channel_count; i++) {
		const mlod_channel *a = &src->channels[i];
		mlod_channel *b = &dst->channels[i];
		size_t n = (size_t)a->key_count;
		*b = *a;
		b->values = NULL;
		b->times = malloc(sizeof(float) * n);
		b->values = malloc(sizeof(float) * n * (size_t)comps_of(a));
		if (!b->times || !b->values)
			return -1;
		memcpy(b->times, a->times, sizeof(float) * n);
		memcpy(b->values, a->values, sizeof(float) * n * (size_t)comps_of(a));
	}
	return 0;
}

/* The grid exponent of each channel for the level grid 2^g: translations
 * on 2^g, rotations and scales finer by their joint's reach; plus adj. */
static void channel_exps(const mlod_motion *m, const mlod_clip *clip, int g, const int *adj, int *e)
{
	for (int i = 0; i < clip->channel_count; i++) {
		const mlod_channel *ch = &clip->channels[i];
		e[i] = g + adj[i] + (ch->path == MLOD_PATH_TRANSLATION ? 0 : m->reach_exp[ch->joint]);
	}
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
	refine_lane lane[REFINE_LANES];
} refine_bufs;

static int refine_lanes(const mlod_motion *m)
{
	return m->threads < 1 ? 1 : m->threads > REFINE_LANES ? REFINE_LANES : m->threads;
}

static int refine_bufs_get(mlod_motion *m, refine_bufs *b)
{
	int F = m->samples, J = m->s->joint_count, lanes = refine_lanes(m);
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
 * is the error within bound? With rb, as level_within_keep into its L,
 * LM and W (*kept). */
static int round_fits_keep(mlod_motion *m, const mlod_clip *src, mlod_clip *clip, int g, const int *adj, int *e,
                           double bound, refine_bufs *rb, int *kept)
{
	channel_exps(m, src, g, adj, e);
	round_clip(src, clip, e, SHORTS(m));
	if (rb)
		return level_within_keep(m, clip, bound, rb->L, rb->LM, rb->W, kept);
	return level_within(m, clip, bound);
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
 * sample (level_within_keep of it fitted). Returns -1 when out of
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

/* The grid exponent of channel i for the level grid 2^g (channel_exps). */
static int channel_exp(const mlod_motion *m, const mlod_channel *ch, int g, int adj)
{
	return g + adj + (ch->path == MLOD_PATH_TRANSLATION ? 0 : m->reach_exp[ch->joint]);
}

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
		e[i] = channel_exp(m, &src->channels[i], g, adj[i]);
		round_channel(&src->channels[i], ch, e[i], SHORTS(m));
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
	e[i] = channel_exp(m, &src->channels[i], g, adj[i]);
	round_channel(&src->channels[i], ch, e[i], SHORTS(m));
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
	channel_exps(m, src, g, adj, e);
	round_clip(src, clip, e, SHORTS(m));
	if (!got)
		return -1;
	level_walk walk;
	walk_begin(m, clip, &walk);
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

/* Rounds the level's values to the coarsest grids that keep its point
 * error within bound: first one level grid (bisection on its exponent),
 * then each channel coarser while the bound holds. Sets *grid to the
 * level grid (0 when nothing was rounded). Returns -1 when out of memory. */
typedef struct level_meas {
	int valid;            /* the level as it now is was measured */
	double point_error;
	mlod_deviation dev;
} level_meas;

static int level_round(mlod_motion *m, mlod_clip *clip, double bound, double *grid, double known, level_meas *meas)
{
	int n = clip->channel_count;
	*grid = 0.0;
	meas->valid = 0;
	/* known: the clip's level_max_error when the caller measured it, or < 0. */
	if (!(bound > 0.0) || !isfinite(bound) || !(known >= 0.0 ? known <= bound : level_within(m, clip, bound)))
		return 0;
	mlod_clip src;
	memset(&src, 0, sizeof src);
	int *adj = calloc((size_t)n, sizeof(int)), *e = malloc(sizeof(int) * (size_t)n);
	int bad = !adj || !e || clip_copy(clip, &src) != 0;
	if (bad) {
		free(adj);
		free(e);
		mlod_clip_free(&src);
		return -1;
	}
	/* The coarsest grid from 2^(top - GRID_RANGE) to 2^top that fits,
	 * from the top down one grid at a time: a grid that does not fit is
	 * usually found so within a few samples (level_within), one that fits
	 * costs a whole walk, and this meets one (a bisection met about
	 * three a level). */
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
			e[i] = NO_ROUNDING;
		round_clip(&src, clip, e, SHORTS(m));
	} else {
		/* Channels in their order (measured as good as round robin or
		 * leaves first); the result is measured again as a whole. */
		const mlod_mat4 *world = NULL;
		if (m->cache0 && refine_channels(m, &src, clip, lo, adj, e, bound, &world, have_rb && walked) != 0)
			bad = 1, world = NULL;
		/* round_fits, measuring the level at the same time; refine_channels
		 * left the level's world matrices at every sample (the same floats
		 * as a walk of the clip). */
		channel_exps(m, &src, lo, adj, e);
		round_clip(&src, clip, e, SHORTS(m));
		meas->valid = level_measure_of(m, clip, world, &meas->point_error, &meas->dev) && meas->point_error <= bound;
		if (!meas->valid && !level_within(m, clip, bound)) {
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
static long least_bytes(const mlod_motion *m, const mlod_clip *clip)
{
	long least = mlod_clip_key_bytes(clip);
	for (int i = 0; SHORTS(m) && i < clip->channel_count; i++) {
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
static mlod_result level_finish(mlod_motion *m, mlod_motion_level *out, double bound, long max_bytes, double known,
                                mlod_error *err)
{
	level_meas meas = { 0, 0.0, { 0.0, 0.0, 0.0 } };
	out->keys = mlod_clip_key_count(&out->clip);
	out->bytes = mlod_clip_key_bytes(&out->clip);
	if (max_bytes >= 0) {
		/* Rounding keeps the keys. */
		long least = least_bytes(m, &out->clip);
		if (least > max_bytes) {
			out->bytes = least;
			out->unfinished = 1;
			return MLOD_OK;
		}
	}
	if (m->opt.precision != MLOD_MOTION_PRECISION_FULL) {
		if (bound < 0.0)
			bound = (known >= 0.0 ? known : level_max_error(m, &out->clip)) / removal_bound(m, 1.0);
		if (level_round(m, &out->clip, bound, &out->grid, known, &meas) != 0)
			return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
	}
	out->keys = mlod_clip_key_count(&out->clip);
	out->bytes = mlod_clip_key_bytes(&out->clip);
	if (meas.valid || level_measure(m, &out->clip, &meas.point_error, &meas.dev)) {
		out->point_error = meas.point_error;
		out->error = meas.dev;
		return MLOD_OK;
	}
	out->point_error = level_max_error(m, &out->clip);
	mlod_character a, b;
	memset(&a, 0, sizeof a);
	a.skeleton = m->s[0];
	a.clip_count = 1;
	b = a;
	a.clips = (mlod_clip *)m->orig;
	b.clips = &out->clip;
	return mlod_joint_deviation_at(&a, &b, m->st, m->samples, &out->error, err);
}

/* ---------------------------------------------------------------- */
/* The multiresolution motion tree                                   */
/* ---------------------------------------------------------------- */

static double node_distance(const mlod_motion *m, const fnode *a, const fnode *b)
{
	double d = 0.0;
	for (int i = 0; i < m->common.channel_count; i++) {
		if (m->constant[i])
			continue;
		const mlod_channel *ch = &m->common.channels[i];
		const float *va = a->values + m->offset[i], *vb = b->values + m->offset[i];
		double w = m->weight[ch->joint], term;
		if (ch->path == MLOD_PATH_ROTATION) {
			int slot = m->value_count + 3 * m->euler_slot[i];
			term = euler_change(m->s->joints[ch->joint].euler, a->values + slot, b->values + slot) / MLOD_PI;
		} else {
			double dx = (double)vb[0] - va[0], dy = (double)vb[1] - va[1], dz = (double)vb[2] - va[2];
			term = sqrt(dx * dx + dy * dy + dz * dz);
			if (ch->path == MLOD_PATH_TRANSLATION)
				term /= m->height;
		}
		d += w * term;
	}
	return d;
}

static int pinned(const mlod_motion *m, const fnode *nd)
{
	return nd->frame == 0 || nd->frame == m->frames - 1;
}

/* node_distance through the memo when both nodes are frames. */
static double frame_distance(const mlod_motion *m, const fnode *a, const fnode *b)
{
	double d;
	if (a->frame < 0 || b->frame < 0)
		return node_distance(m, a, b);
	if (memo_get(m->memo, a->frame, b->frame, -1, &d))
		return d;
	d = node_distance(m, a, b);
	memo_put(m->memo, a->frame, b->frame, -1, d);
	return d;
}

static double residual_of(const mlod_motion *m, const fnode *p, const fnode *x, const fnode *q);

/* How badly interpolating p and q reproduces x: the frame distance from x
 * to the interpolated frame, or -1 when out of memory. */
static double residual(const mlod_motion *m, const fnode *p, const fnode *x, const fnode *q)
{
	double d;
	if (p->frame < 0 || x->frame < 0 || q->frame < 0)
		return residual_of(m, p, x, q);
	if (memo_get(m->memo, p->frame, x->frame, q->frame, &d))
		return d;
	d = residual_of(m, p, x, q);
	if (d >= 0.0)
		memo_put(m->memo, p->frame, x->frame, q->frame, d);
	return d;
}

static double residual_of(const mlod_motion *m, const fnode *p, const fnode *x, const fnode *q)
{
	fnode tmp;
	tmp.values = malloc(sizeof(float) * (size_t)(m->value_count + 3 * m->rot_count + 1));
	if (!tmp.values)
		return -1.0;
	float u = (float)((x->time - p->time) / (q->time - p->time));
	/* Only what node_distance reads: the constant channels are left out. */
	for (int i = 0; i < m->common.channel_count; i++) {
		const mlod_channel *ch = &m->common.channels[i];
		if (m->constant[i])
			continue;
		const float *a = p->values + m->offset[i], *b = q->values + m->offset[i];
		float *o = tmp.values + m->offset[i];
		if (ch->interp == MLOD_INTERP_STEP) {
			memcpy(o, a, sizeof(float) * (size_t)comps_of(ch));
		} else if (ch->path == MLOD_PATH_ROTATION) {
			/* mlod_quat_normalize(mlod_quat_slerp(a, b, u)), inline (motion_eval.h) */
			eval_seg seg = { -1, 0, 0, { 0, 0, 0, 1 }, { 0, 0, 0, 1 }, 0.0, 0.0, 0.0 };
			mlod_quat r = eval_normalize(eval_slerp(&seg, a, b, u));
			o[0] = r.x, o[1] = r.y, o[2] = r.z, o[3] = r.w;
		} else {
			for (int c = 0; c < 3; c++)
				o[c] = a[c] + (b[c] - a[c]) * u;
		}
	}
	node_euler_of(m, &tmp, 1);
	double d = node_distance(m, x, &tmp);
	free(tmp.values);
	return d;
}

/* Fuses a and b into *o (which owns new values). With moved (a pass that
 * steals from l), a kept frame's values move to *o instead of being
 * copied, and moved marks it: it still serves as a neighbour until the
 * pass ends, as in tree_pass. */
static int fuse(const mlod_motion *m, const line *l, int i, fnode *o, unsigned char *moved)
{
	const fnode *a = &l->v[i], *b = &l->v[i + 1];
	size_t size = sizeof(float) * (size_t)(m->value_count + 3 * m->rot_count + 1);
	const fnode *keep = NULL;
	if (pinned(m, a))
		keep = a;
	else if (pinned(m, b))
		keep = b;
	else if (m->opt.merge == MLOD_MOTION_REMOVE) {
		/* Neighbours exist: neither a nor b is an end. */
		double ra = residual(m, &l->v[i - 1], a, b), rb = residual(m, a, b, &l->v[i + 2]);
		if (ra < 0.0 || rb < 0.0)
			return -1;
		keep = ra >= rb ? a : b; /* drop the one interpolation reproduces better */
	}
	if (keep && moved) {
		o->values = keep->values;
		moved[keep == a ? i : i + 1] = 1;
	} else {
		o->values = malloc(size);
		if (!o->values)
			return -1;
		if (keep)
			memcpy(o->values, keep->values, size);
	}
	if (keep) {
		o->time = keep->time;
		o->frame = keep->frame;
		o->leaves = a->leaves + b->leaves;
		return 0;
	}
	double wa = a->leaves, wb = b->leaves, sum = wa + wb;
	o->time = (wa * a->time + wb * b->time) / sum;
	o->frame = -1;
	o->leaves = a->leaves + b->leaves;
	for (int c = 0; c < m->common.channel_count; c++) {
		const mlod_channel *ch = &m->common.channels[c];
		const float *x = a->values + m->offset[c], *y = b->values + m->offset[c];
		float *v = o->values + m->offset[c];
		if (ch->path == MLOD_PATH_ROTATION) {
			double dot = (double)x[0] * y[0] + (double)x[1] * y[1] + (double)x[2] * y[2] + (double)x[3] * y[3];
			double sb = dot < 0.0 ? -wb : wb, q[4], n = 0.0;
			for (int k = 0; k < 4; k++) {
				q[k] = wa * x[k] + sb * y[k];
				n += q[k] * q[k];
			}
			n = sqrt(n);
			for (int k = 0; k < 4; k++)
				v[k] = n > 0.0 ? (float)(q[k] / n) : x[k];
		} else {
			for (int k = 0; k < 3; k++)
				v[k] = (float)((wa * x[k] + wb * y[k]) / sum);
		}
	}
	node_euler(m, o);
	return 0;
}

/* One pass of the tree: fuses disjoint neighbouring pairs closer than T.
 * With steal, frames that stay are moved from in rather than copied.
 * Returns the number of fusions, or -1 when out of memory. */
static int tree_pass(const mlod_motion *m, line *in, double T, line *out, int steal)
{
	out->v = calloc((size_t)(in->n > 0 ? in->n : 1), sizeof *out->v);
	out->n = 0;
	/* in's frames moved to out (steal): they still serve as neighbours
	 * below, with their frame numbers (the memo's keys). */
	unsigned char *moved = steal ? calloc((size_t)(in->n > 0 ? in->n : 1), 1) : NULL;
	if (!out->v || (steal && !moved)) {
		free(moved);
		return -1;
	}
	int fused = 0;
	for (int i = 0; i < in->n;) {
		fnode *o = &out->v[out->n];
		if (i + 1 < in->n && !(pinned(m, &in->v[i]) && pinned(m, &in->v[i + 1])) &&
		    frame_distance(m, &in->v[i], &in->v[i + 1]) < T) {
			if (fuse(m, in, i, o, moved) != 0) {
				fused = -1;
				break;
			}
			out->n++;
			fused++;
			i += 2;
		} else {
			size_t size = sizeof(float) * (size_t)(m->value_count + 3 * m->rot_count + 1);
			*o = in->v[i];
			if (steal) {
				/* in->v[i] still serves as a neighbour below: forget it after the pass. */
				moved[i] = 1;
			} else {
				o->values = malloc(size);
				if (!o->values)
					return -1;
				memcpy(o->values, in->v[i].values, size);
			}
			out->n++;
			i++;
		}
	}
	/* Also after a failure, so that in and out never share values. */
	for (int i = 0; steal && i < in->n; i++)
		if (moved[i])
			in->v[i].values = NULL; /* now owned by out */
	free(moved);
	return fused;
}

/* The line reached from in when no neighbouring pair is closer than T. */
static int tree_level(const mlod_motion *m, line *in, double T, line *out)
{
	line cur = { 0, NULL };
	int first = 1;
	for (;;) {
		line next = { 0, NULL };
		int fused = tree_pass(m, first ? in : &cur, T, &next, !first);
		if (fused < 0) {
			line_free(&next);
			line_free(&cur);
			return -1;
		}
		if (!first)
			line_free(&cur);
		cur = next;
		first = 0;
		if (fused == 0)
			break;
	}
	*out = cur;
	return 0;
}

/* The sum of the distances between neighbours of a line: fusing frames
 * only brings frames of the line together, so every pair fuses below
 * about that. */
static double total_neighbour_distance(const mlod_motion *m, const line *l)
{
	double d = 0.0;
	for (int i = 0; i + 1 < l->n; i++)
		d += node_distance(m, &l->v[i], &l->v[i + 1]);
	return d;
}

static long line_keys(const mlod_motion *m, const line *l)
{
	long keys = 0;
	for (int i = 0; i < m->common.channel_count; i++)
		keys += m->constant[i] ? 1 : l->n;
	return keys;
}

/* The frames method: the next line of the tree. */
/* The tree's first line, every frame, unless made: 0, or -1 when out of
 * memory. */
static int tree_start(mlod_motion *m)
{
	if (m->tree_started)
		return 0;
	line_free(&m->tree);
	m->tree.v = calloc((size_t)m->frames, sizeof *m->tree.v);
	if (!m->tree.v)
		return -1;
	for (int f = 0; f < m->frames; f++) {
		if (node_from_frame(m, f, &m->tree.v[f]) != 0)
			return -1;
		m->tree.n = f + 1;
	}
	m->tree_started = 1;
	m->tree_total = -1.0;
	return 0;
}

static mlod_result frames_level(mlod_motion *m, mlod_motion_target target, double value, long max_bytes,
                                mlod_motion_level *out, mlod_error *err)
{
	if (tree_start(m) != 0)
		return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
	line best = { 0, NULL };
	double T = 0.0;
	char q[MLOD_NAME_TEXT_SIZE]; /* the clip's name in a message */
	free(m->segmemo->slot);
	memset(m->segmemo, 0, sizeof *m->segmemo);
	if (target == MLOD_MOTION_THRESHOLD) {
		T = value;
		if (tree_level(m, &m->tree, T, &best) != 0)
			return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
	} else {
		/* Bisection on T: lo is acceptable, hi is not (or is the top). */
		/* The same tree's sum again at the next level, when this one is
		 * left unfinished (on CMU 01_01 every frames level: 2 x 2,751
		 * node distances saved). */
		if (!(m->tree_total >= 0.0))
			m->tree_total = total_neighbour_distance(m, &m->tree);
		double hi = 2.0 * m->tree_total + 1e-9, lo = 0.0;
		long budget = target == MLOD_MOTION_FRACTION ? (long)floor(value * (double)mlod_clip_key_count(m->orig)) : 0;
		for (int step = 0; step <= SEARCH_STEPS; step++) {
			double t = step == 0 ? hi : 0.5 * (lo + hi);
			line l = { 0, NULL };
			if (tree_level(m, &m->tree, t, &l) != 0)
				return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
			int ok;
			if (target == MLOD_MOTION_FRACTION) {
				ok = line_keys(m, &l) <= budget; /* here "ok" means small enough: search the smallest T */
			} else {
				mlod_clip c;
				if (clip_from_line(m, &l, &c) != 0) {
					mlod_clip_free(&c);
					line_free(&l);
					line_free(&best);
					return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
				}
				ok = line_within(m, &l, &c, removal_bound(m, value));
				if (!ok && max_bytes >= 0 && least_bytes(m, &c) > max_bytes) {
					/* The level would be finer than this line, so larger
					 * (the tree's lines grow finer as the threshold goes
					 * down): it cannot win. Left unfinished; the next
					 * frames level builds on the last finished one. */
					memset(out, 0, sizeof *out);
					out->method = MLOD_MOTION_FRAMES;
					out->threshold = t;
					out->keys = mlod_clip_key_count(&c);
					out->bytes = least_bytes(m, &c);
					out->unfinished = 1;
					mlod_clip_free(&c);
					line_free(&l);
					line_free(&best);
					return MLOD_OK;
				}
				mlod_clip_free(&c);
			}
			if (target == MLOD_MOTION_FRACTION) {
				if (ok) {
					line_free(&best);
					best = l;
					T = t;
					hi = t;
				} else {
					line_free(&l);
					lo = t;
				}
				if (step == 0 && !ok)
					break; /* even merging everything keeps too many: take the coarsest */
			} else {
				if (ok) {
					line_free(&best);
					best = l;
					T = t;
					lo = t;
					if (step == 0)
						break;
				} else {
					line_free(&l);
					hi = t;
				}
			}
		}
		if (!best.v) {
			/* Fraction: even the top is too many keys, so take it; error: T = 0,
			 * the previous line, whose error must be within the bound. */
			T = target == MLOD_MOTION_FRACTION ? hi : 0.0;
			if (tree_level(m, &m->tree, T, &best) != 0)
				return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
			if (target == MLOD_MOTION_MAX_ERROR) {
				mlod_clip c;
				int bad = clip_from_line(m, &best, &c) != 0;
				double e = bad ? 0.0 : level_max_error(m, &c);
				mlod_clip_free(&c);
				if (bad) {
					line_free(&best);
					return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
				}
				if (!(e <= value)) {
					line_free(&best);
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
	if (clip_from_line(m, &best, &out->clip) != 0) {
		line_free(&best);
		mlod_motion_level_free(out);
		return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
	}
	line_free(&m->tree);
	m->tree = best;
	m->tree_total = -1.0;
	mlod_result r = level_finish(m, out, target == MLOD_MOTION_MAX_ERROR ? value : -1.0, max_bytes, -1.0, err);
	if (r != MLOD_OK)
		mlod_motion_level_free(out);
	return r;
}

/* ---------------------------------------------------------------- */
/* The keys method                                                   */
/* ---------------------------------------------------------------- */

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
	if (clip_from_kept(m, kept, clip) != 0) {
		mlod_clip_free(clip);
		mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
		return -1.0;
	}
	/* keyreduce measured the clip as level_max_error does, unless it
	 * could not. */
	return e >= 0.0 && m->clip_end_ok ? e : level_max_error(m, clip);
}

/* The keys method's next level up to its rounding: the keys kept (out's
 * clip, method and threshold; the rest zero), which the next level builds
 * on; *known gets the clip's level_max_error. */
static mlod_result keys_reduce(mlod_motion *m, mlod_motion_target target, double value, mlod_motion_level *out,
                               double *known, mlod_error *err)
{
	char q[MLOD_NAME_TEXT_SIZE]; /* the clip's name in a message */
	if (target == MLOD_MOTION_THRESHOLD)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "thresholds are frame distances: they need the frames method");
	size_t size = (size_t)m->common.channel_count * (size_t)m->frames;
	unsigned char *kept = malloc(size), *best = malloc(size);
	mlod_clip clip, best_clip;
	double best_budget = -1.0, best_error = -1.0; /* best_clip's level_max_error */
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
		double budget = removal_bound(m, value) * (1.0 - 1e-5);
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
		for (int step = 0; step < SEARCH_STEPS / 2 && r == MLOD_OK && mlod_clip_key_count(&best_clip) <= target_keys;
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

/* The keys level's rounding and measures (level_finish); m may be any
 * motion of the clip with the same options (the rounding reads only the
 * setup, not the keys method's state). Frees the level on a failure. */
static mlod_result keys_finish(mlod_motion *m, mlod_motion_target target, double value, long max_bytes, double known,
                               mlod_motion_level *l, mlod_error *err)
{
	mlod_result r = level_finish(m, l, target == MLOD_MOTION_MAX_ERROR ? value : -1.0, max_bytes, known, err);
	if (r != MLOD_OK)
		mlod_motion_level_free(l);
	return r;
}

static mlod_result keys_level(mlod_motion *m, mlod_motion_target target, double value, long max_bytes,
                              mlod_motion_level *out, mlod_error *err)
{
	double known = -1.0;
	mlod_result r = keys_reduce(m, target, value, out, &known, err);
	return r != MLOD_OK ? r : keys_finish(m, target, value, max_bytes, known, out, err);
}

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
	if (level_clip_init(m, &out->clip) != 0) {
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
	return r != MLOD_OK ? r : keys_reduce(m, target, value, out, known, err);
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
	return keys_finish(m, target, value, max_bytes, known, l, err);
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
	case MLOD_MOTION_FRAMES: return frames_level(m, target, value, max_bytes, out, err);
	case MLOD_MOTION_KEYS: return keys_level(m, target, value, max_bytes, out, err);
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
		if (mlod_motion_level_wins(&l, out, ok)) {
			if (ok)
				mlod_motion_level_free(out);
			*out = l;
			ok = 1;
		} else {
			mlod_motion_level_free(&l);
		}
	}
	if (ok)
		return MLOD_OK;
	if (limited < 0)
		return mlod_fail(err, MLOD_ERR_LIMIT, "no method makes a level for this target");
	if (err)
		*err = why;
	return MLOD_ERR_LIMIT;
}
