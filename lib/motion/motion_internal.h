/*
 * motion_internal.h: internal to lib/motion. The motion object
 * (struct mlod_motion) and what its files share; motion_eval.h has the
 * fast sampling, kinematics and point error they measure with.
 *
 * The files of the motion levels, each calling only those below it:
 *
 *   nextlevel.c     the public level calls: a method's next level, the
 *                   best of several methods
 *   framesmethod.c  the frames method: a line of the tree by threshold,
 *                   key fraction or error bound
 *   keysmethod.c    the keys method: keyreduce.c driven by fraction or
 *                   error bound
 *   motion.c        the motion object: its setup from a clip, shared by
 *                   the motions made like it
 *   motiontree.c    the multiresolution motion tree: lines of frames
 *                   fused by frame distance
 *   precision.c     a level's values rounded to the coarsest grids that
 *                   keep its error, and its counts and measures
 *   rounding.c      values rounded to a grid or to normalised shorts
 *   levelerror.c    a level clip walked sample by sample: its largest
 *                   point error, whether it is within a bound, on threads
 *   levelclip.c     level clips made from a line of the tree or a key
 *                   selection
 *   distance.c      the frame distance and the point distance
 *   memo.c          a memo of values by three ints
 *
 * Hot helpers that more than one file calls are static inline here, so
 * that they stay inlined where they were (the build is -O2 without LTO).
 */
#ifndef MLOD_MOTION_INTERNAL_H
#define MLOD_MOTION_INTERNAL_H

#include <limits.h>
#include <stdatomic.h>

#include "motion/mlod_motion.h"
#include "motion/motion_eval.h"

#define MOTION_SEARCH_STEPS 24 /* bisection steps: the threshold to 2^-24 of its range */
#define MOTION_LANES 8         /* threads of the rounding's refinement and walks at most */

/* ---------------------------------------------------------------- */
/* memo.c                                                            */
/* ---------------------------------------------------------------- */

/* Memo of values keyed by three ints (the first never negative), by
 * open addressing: the tree's frame distances and residuals between
 * frames of the common timeline, the frames method's segments within a
 * bound. All zero: empty. */
typedef struct motion_memo_slot {
	int a, b, c; /* a = -1: empty */
	double v;
} motion_memo_slot;

typedef struct motion_memo {
	motion_memo_slot *slot;
	size_t cap, n; /* cap a power of two */
} motion_memo;

/* 1 and *v when (a, b, c) was put, else 0. */
int motion_memo_get(const motion_memo *mo, int a, int b, int c, double *v);
/* Remembers v for (a, b, c) (nothing when out of memory or full). */
void motion_memo_put(motion_memo *mo, int a, int b, int c, double v);
/* Empties the memo and frees its slots. */
void motion_memo_clear(motion_memo *mo);

/* ---------------------------------------------------------------- */
/* The motion object (motion.c)                                      */
/* ---------------------------------------------------------------- */

/* A frame of a line of the tree: its time, the channel values (V floats,
 * laid out by channel) and the Euler angles of its rotation channels. */
typedef struct motion_node {
	double time;
	int leaves;      /* original frames it stands for */
	int frame;       /* the common frame it is (removal), or -1 (averaged) */
	float *values;   /* V floats, then 3 * rotation channels Euler angles */
} motion_node;

typedef struct motion_line {
	int n;
	motion_node *v;
} motion_line;

/* The setup's owners: mlod_motion_create's motion and those made like it
 * (mlod_motion_create_like) share its read-only arrays (common, st,
 * weight, offset, euler_slot, constant, radius, reach_exp, cache0); the
 * last one freed frees them. */
typedef struct motion_refs {
	atomic_int n;
} motion_refs;

struct mlod_motion {
	const mlod_character *c;
	motion_refs *refs;     /* NULL: the setup is this motion's alone */
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
	eval_seg *walk_segs;   /* per channel: sampling level clips (motion_walk) */
	int clip_end_ok;       /* no sample time past the clip's duration (level clips are not clamped) */
	mlod_trs *walk_local;  /* per joint */
	/* State of each method: the last line of the tree, the keys kept. */
	motion_line tree;
	int tree_started;      /* tree holds line 0 or a later one (motion_tree_start) */
	double tree_total;     /* motion_line_distance of tree, or < 0: not yet */
	unsigned char *kept;   /* channel_count * frames */
	motion_memo *memo;     /* the tree's distances and residuals */
	motion_memo *segmemo;  /* frames level under way: segments of lines within its bound */
	eval_scratch scratch;  /* the large arrays of the key reduction and of the rounding's refinement */
	keyreduce_state kstate; /* the last key reduction's end state */
	int threads;           /* of the key reduction (mlod_motion_set_threads) */
};

/* Floats per key of a channel. */
static inline int motion_comps(const mlod_channel *ch)
{
	return ch->path == MLOD_PATH_ROTATION ? 4 : 3;
}

/* Poses the skeleton with clip at t into world. */
static inline void motion_pose_at(mlod_motion *m, const mlod_clip *clip, float t, mlod_mat4 *world)
{
	mlod_pose_rest(m->s, m->local);
	mlod_clip_sample(clip, t, m->local);
	mlod_pose_world(m->s, m->local, world);
}

/* Threads of the rounding's refinement and of the walks on lanes. */
static inline int motion_lanes(const mlod_motion *m)
{
	return m->threads < 1 ? 1 : m->threads > MOTION_LANES ? MOTION_LANES : m->threads;
}

/* ---------------------------------------------------------------- */
/* distance.c                                                        */
/* ---------------------------------------------------------------- */

/* Sum of |wrapped differences| between two Euler triples of one order,
 * the nearer of the two triples of b. */
double motion_euler_change(mlod_euler_order order, const float *ea, const float *eb);
/* Energy weights (h - depth) / h of the skeleton's joints into w. */
void motion_joint_weights(const mlod_skeleton *s, double *w);

/* ---------------------------------------------------------------- */
/* levelclip.c                                                       */
/* ---------------------------------------------------------------- */

/* Starts a level clip like the source: name, duration, frame rate, the
 * common clip's channel count (channels zeroed); -1 when out of memory. */
int motion_level_clip_init(const mlod_motion *m, mlod_clip *clip);
/* The level clip of a line of the tree; -1 when out of memory. */
int motion_clip_from_line(const mlod_motion *m, const motion_line *l, mlod_clip *clip);
/* The level clip of a key selection (channel_count * frames); -1 when
 * out of memory. */
int motion_clip_from_kept(const mlod_motion *m, const unsigned char *kept, mlod_clip *clip);
/* A deep copy of a level clip, or -1 when out of memory. */
int motion_clip_copy(const mlod_clip *src, mlod_clip *dst);

/* ---------------------------------------------------------------- */
/* levelerror.c                                                      */
/* ---------------------------------------------------------------- */

/* Walks the samples of a level clip: its pose at each sample into
 * world, with the fast sampling of motion_eval.h (the clip's channels are
 * LINEAR or STEP) or mlod_clip_sample. */
typedef struct motion_walk {
	const mlod_clip *clip;
	int fast;
	eval_seg *segs;   /* per channel */
	mlod_trs *local;  /* per joint: the rest pose with the animated paths set */
} motion_walk;

/* Starts a walk of a level clip in m's buffers. */
void motion_walk_begin(mlod_motion *m, const mlod_clip *clip, motion_walk *w);
/* Largest point error of a level clip over every joint and sample. */
double motion_level_max_error(mlod_motion *m, const mlod_clip *clip);
/* A level's largest point error and deviation in one walk (known: its
 * world matrices at every sample, or NULL); 0 when it could not. */
int motion_level_measure(mlod_motion *m, const mlod_clip *clip, const mlod_mat4 *known, double *point_error,
                         mlod_deviation *dev);
/* Is motion_level_max_error(m, clip) <= bound? With L, LM and W, the
 * level's local transforms, their matrices and world matrices are kept
 * there (*kept). */
int motion_level_within_keep(mlod_motion *m, const mlod_clip *clip, double bound, mlod_trs *L, mlod_mat4 *LM,
                             mlod_mat4 *W, int *kept);
int motion_level_within(mlod_motion *m, const mlod_clip *clip, double bound);
/* motion_level_within over samples lo..hi only. */
int motion_level_within_range(mlod_motion *m, const mlod_clip *clip, double bound, int lo, int hi);

/* ---------------------------------------------------------------- */
/* rounding.c                                                        */
/* ---------------------------------------------------------------- */

#define MOTION_NO_ROUNDING INT_MIN
/* Rotations on the lattice of normalised shorts (auto precision). */
#define MOTION_SHORTS(m) ((m)->opt.precision == MLOD_MOTION_PRECISION_AUTO)

/* The grid exponent of a channel for the level grid 2^g: translations
 * on 2^g, rotations and scales finer by their joint's reach; plus adj. */
static inline int motion_channel_exp(const mlod_motion *m, const mlod_channel *ch, int g, int adj)
{
	return g + adj + (ch->path == MLOD_PATH_TRANSLATION ? 0 : m->reach_exp[ch->joint]);
}
/* motion_channel_exp of every channel of clip, with adj[i], into e. */
void motion_channel_exps(const mlod_motion *m, const mlod_clip *clip, int g, const int *adj, int *e);
/* b gets a's values rounded to the grid 2^e (MOTION_NO_ROUNDING: as
 * they are); with shorts a rotation goes on the lattice of normalised
 * shorts. */
void motion_round_channel(const mlod_channel *a, mlod_channel *b, int e, int shorts);
/* motion_round_channel of every channel, channel i to 2^e[i]. */
void motion_round_clip(const mlod_clip *src, mlod_clip *dst, const int *e, int shorts);

/* ---------------------------------------------------------------- */
/* precision.c                                                       */
/* ---------------------------------------------------------------- */

/* The part of a max-error bound the keys (or frames) may spend. */
double motion_removal_bound(const mlod_motion *m, double bound);
/* The fewest bytes a level clip can store whatever its values' rounding. */
long motion_least_bytes(const mlod_motion *m, const mlod_clip *clip);
/* Fills the level's counts and its error, after rounding its values
 * within bound (< 0: a level chosen by threshold or fraction); known:
 * the clip's motion_level_max_error, or < 0. */
mlod_result motion_level_finish(mlod_motion *m, mlod_motion_level *out, double bound, long max_bytes, double known,
                                mlod_error *err);

/* ---------------------------------------------------------------- */
/* motiontree.c                                                      */
/* ---------------------------------------------------------------- */

void motion_line_free(motion_line *l);
/* The tree's first line, every frame, unless made: 0, or -1 when out of
 * memory. */
int motion_tree_start(mlod_motion *m);
/* The line reached from in when no neighbouring pair is closer than T;
 * -1 when out of memory. */
int motion_tree_level(const mlod_motion *m, motion_line *in, double T, motion_line *out);
/* The sum of the distances between neighbours of a line. */
double motion_line_distance(const mlod_motion *m, const motion_line *l);
/* The keys of the level clip of a line. */
long motion_line_keys(const mlod_motion *m, const motion_line *l);

/* ---------------------------------------------------------------- */
/* nextlevel.c, framesmethod.c, keysmethod.c                         */
/* ---------------------------------------------------------------- */

/* The auto method's pick over the methods' levels, for
 * mlod_motion_next_level_best and the threaded builder (levels.c):
 * motion_best_take moves *l into *best when it wins
 * (mlod_motion_level_wins; the level it beats is freed) and returns 1,
 * else leaves *l to the caller and returns 0; motion_best_end ends the
 * pick: MLOD_OK with a level, else MLOD_ERR_LIMIT with the reason of the
 * earliest method that hit its limit (why, limited >= 0) or, when none
 * applied, its own. */
int motion_best_take(mlod_motion_level *best, int *have, mlod_motion_level *l);
mlod_result motion_best_end(int have, int limited, const mlod_error *why, mlod_error *err);

/* The frames method's next level. */
mlod_result motion_frames_level(mlod_motion *m, mlod_motion_target target, double value, long max_bytes,
                                mlod_motion_level *out, mlod_error *err);
/* The keys method's next level up to its rounding (*known: the clip's
 * motion_level_max_error), its rounding and measures, and both. */
mlod_result motion_keys_reduce(mlod_motion *m, mlod_motion_target target, double value, mlod_motion_level *out,
                               double *known, mlod_error *err);
mlod_result motion_keys_finish(mlod_motion *m, mlod_motion_target target, double value, long max_bytes, double known,
                               mlod_motion_level *l, mlod_error *err);
mlod_result motion_keys_level(mlod_motion *m, mlod_motion_target target, double value, long max_bytes,
                              mlod_motion_level *out, mlod_error *err);

#endif /* MLOD_MOTION_INTERNAL_H */
