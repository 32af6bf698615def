/*
 * motiontree.c: the multiresolution motion tree (paper 4.3;
 * mlod-motion(1), The multiresolution motion tree).
 *
 * Savoye & Meyer merge "nearby postures": two neighbouring frames fuse
 * when the distance between them, "the energy needed to move all joints
 * from one frame to the other", is below a threshold, by "removing a frame
 * from among the two or by merging the two into a single frame, preserving
 * the duration". We read it so:
 *
 * - Line 0 is every frame of the common timeline (timeline.c), a node
 *   per frame holding its channel values and Euler angles. One pass
 *   scans neighbouring pairs left to right and fuses each disjoint pair
 *   closer than the threshold (the frame distance of distance.c), giving
 *   the next line; a level at threshold T is the line reached when no
 *   neighbouring pair is closer than T any more (passes repeat). A level
 *   is built from the previous one, so levels are nested.
 * - Removal keeps the frame of the pair that linear interpolation of its
 *   neighbours reproduces worse (its residual); averaging puts one frame
 *   at the pair's mean time (frames weighted by how many original frames
 *   they stand for). The first and last frames are pinned: a pair holding
 *   one keeps it as it is, so the duration is kept.
 *
 * Distances and residuals between frames go through the motion's memo
 * (memo.c). The frames method (framesmethod.c) chooses the threshold.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "motion/motion_internal.h"

void motion_line_free(motion_line *l)
{
	for (int i = 0; l->v && i < l->n; i++)
		free(l->v[i].values);
	free(l->v);
	l->v = NULL;
	l->n = 0;
}

/* Fills node values from common frame f, and its Euler angles (with
 * skip_constant, not those of constant channels, which node_distance
 * leaves out). */
static void node_euler_of(const mlod_motion *m, motion_node *nd, int skip_constant)
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

static void node_euler(const mlod_motion *m, motion_node *nd)
{
	node_euler_of(m, nd, 0);
}

static int node_from_frame(const mlod_motion *m, int f, motion_node *nd)
{
	nd->values = malloc(sizeof(float) * (size_t)(m->value_count + 3 * m->rot_count + 1));
	if (!nd->values)
		return -1;
	nd->time = m->common.channels[0].times[f];
	nd->leaves = 1;
	nd->frame = f;
	for (int i = 0; i < m->common.channel_count; i++) {
		const mlod_channel *ch = &m->common.channels[i];
		int comps = motion_comps(ch);
		memcpy(nd->values + m->offset[i], ch->values + (size_t)f * (size_t)comps, sizeof(float) * (size_t)comps);
	}
	node_euler(m, nd);
	return 0;
}

/* The frame distance (distance.c) between two nodes, over the channels
 * that are not constant. */
static double node_distance(const mlod_motion *m, const motion_node *a, const motion_node *b)
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
			term = motion_euler_change(m->s->joints[ch->joint].euler, a->values + slot, b->values + slot) / MLOD_PI;
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

static int pinned(const mlod_motion *m, const motion_node *nd)
{
	return nd->frame == 0 || nd->frame == m->frames - 1;
}

/* node_distance through the memo when both nodes are frames. */
static double frame_distance(const mlod_motion *m, const motion_node *a, const motion_node *b)
{
	double d;
	if (a->frame < 0 || b->frame < 0)
		return node_distance(m, a, b);
	if (motion_memo_get(m->memo, a->frame, b->frame, -1, &d))
		return d;
	d = node_distance(m, a, b);
	motion_memo_put(m->memo, a->frame, b->frame, -1, d);
	return d;
}

/* How badly interpolating p and q reproduces x: the frame distance from x
 * to the interpolated frame, or -1 when out of memory. */
static double residual_of(const mlod_motion *m, const motion_node *p, const motion_node *x, const motion_node *q)
{
	motion_node tmp;
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
			memcpy(o, a, sizeof(float) * (size_t)motion_comps(ch));
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

/* residual_of through the memo when the three nodes are frames. */
static double residual(const mlod_motion *m, const motion_node *p, const motion_node *x, const motion_node *q)
{
	double d;
	if (p->frame < 0 || x->frame < 0 || q->frame < 0)
		return residual_of(m, p, x, q);
	if (motion_memo_get(m->memo, p->frame, x->frame, q->frame, &d))
		return d;
	d = residual_of(m, p, x, q);
	if (d >= 0.0)
		motion_memo_put(m->memo, p->frame, x->frame, q->frame, d);
	return d;
}

/* Fuses a and b into *o (which owns new values). With moved (a pass that
 * steals from l), a kept frame's values move to *o instead of being
 * copied, and moved marks it: it still serves as a neighbour until the
 * pass ends, as in tree_pass. */
static int fuse(const mlod_motion *m, const motion_line *l, int i, motion_node *o, unsigned char *moved)
{
	const motion_node *a = &l->v[i], *b = &l->v[i + 1];
	size_t size = sizeof(float) * (size_t)(m->value_count + 3 * m->rot_count + 1);
	const motion_node *keep = NULL;
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
static int tree_pass(const mlod_motion *m, motion_line *in, double T, motion_line *out, int steal)
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
		motion_node *o = &out->v[out->n];
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
int motion_tree_level(const mlod_motion *m, motion_line *in, double T, motion_line *out)
{
	motion_line cur = { 0, NULL };
	int first = 1;
	for (;;) {
		motion_line next = { 0, NULL };
		int fused = tree_pass(m, first ? in : &cur, T, &next, !first);
		if (fused < 0) {
			motion_line_free(&next);
			motion_line_free(&cur);
			return -1;
		}
		if (!first)
			motion_line_free(&cur);
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
double motion_line_distance(const mlod_motion *m, const motion_line *l)
{
	double d = 0.0;
	for (int i = 0; i + 1 < l->n; i++)
		d += node_distance(m, &l->v[i], &l->v[i + 1]);
	return d;
}

long motion_line_keys(const mlod_motion *m, const motion_line *l)
{
	long keys = 0;
	for (int i = 0; i < m->common.channel_count; i++)
		keys += m->constant[i] ? 1 : l->n;
	return keys;
}

/* The tree's first line, every frame, unless made: 0, or -1 when out of
 * memory. */
int motion_tree_start(mlod_motion *m)
{
	if (m->tree_started)
		return 0;
	motion_line_free(&m->tree);
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
