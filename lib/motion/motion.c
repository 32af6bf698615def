/*
 * motion.c: the motion object (mlod_motion_create): a clip set up for
 * its levels of detail (paper 4.3, with the energy weight of 4.1.2).
 *
 * The setup puts the clip on frames shared by all its channels (the
 * common timeline, timeline.c), and works out once what every level
 * reads: the sample times (the frames and, by default, the midpoints
 * between them: options.subdivide), the joints' energy weights
 * (distance.c), where each channel's values lie in a node of the tree,
 * which channels are constant, each joint's radius (the point distance,
 * or its End Site's if farther) and reach (how far the points it carries
 * are, which scales the rounding of its rotations: precision.c), and,
 * when it fits in MAX_CACHED matrices, the clip as read at every sample,
 * on threads (the same matrices at any count). Motions made like it
 * (mlod_motion_create_like) share that setup, each with the state of its
 * own methods: the last line of the tree (motiontree.c), the keys kept
 * (keysmethod.c), the memos and buffers.
 *
 * The levels themselves come from nextlevel.c; motion_internal.h maps
 * the files.
 */
#include <limits.h>
#include <math.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "motion/motion_internal.h"

#define MAX_CACHED 1000000L /* frames * joints whose world matrices as read are cached */

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
	motion_line_free(&m->tree);
	free(m->kept);
	if (m->memo)
		motion_memo_clear(m->memo);
	free(m->memo);
	if (m->segmemo)
		motion_memo_clear(m->segmemo);
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
	motion_joint_weights(s, m->weight);
	if (F > 0) {
		mlod_motion_sample_times(m->common.channels[0].times, F, m->sub, m->st);
		m->clip_end_ok = m->st[m->samples - 1] <= src->duration;
	}
	for (int i = 0; i < nch; i++) {
		const mlod_channel *ch = &m->common.channels[i];
		int comps = motion_comps(ch);
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
					motion_pose_at(m, src, m->st[f], w);
				}
			}
		}
	}
	/* Level 0 of each method: every frame, every key (the tree's line
	 * is made when the frames method first needs it: motion_tree_start). */
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
