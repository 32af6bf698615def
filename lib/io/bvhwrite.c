/*
 * bvhwrite.c: writes BVH (Biovision Hierarchy) motion capture text.
 *
 * Writing samples one clip at a uniform frame time. Each joint's BVH frame
 * is its rigid world frame: where the skeleton is rigid (unit scales) the
 * BVH local transform is the joint's local TRS itself (rest rotations and a
 * root's base are folded into the rotation channels), elsewhere it is
 * derived from the world matrices, so joint positions are reproduced even
 * under scale. A joint whose layout cannot express its motion (a translation
 * that differs from its OFFSET without position channels, a rotation about
 * an axis it has no channel for) is given the missing channels. Euler
 * angles continue across +-180 degrees from frame to frame. Positions are
 * written as the shortest decimal that reads back as the same float,
 * angles to 1e-5 degree; numbers are formatted by hand, without the
 * locale. Joint names get '_' for blanks and braces.
 */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/bvh_internal.h"
#include "io/mlod_io.h"

/* ================================================================== */
/* Writer                                                              */
/* ================================================================== */

/* Decimal digits of v into buf (no sign); returns the length. */
static size_t utoa(unsigned long long v, char *buf)
{
	char tmp[24];
	size_t n = 0;
	do {
		tmp[n++] = (char)('0' + v % 10);
		v /= 10;
	} while (v);
	for (size_t i = 0; i < n; i++)
		buf[i] = tmp[n - 1 - i];
	return n;
}

/* Formats v with at most dec decimals, trailing zeros trimmed, "-0" as
 * "0", without the C library (so without its locale). Values too large for
 * fixed notation, and tiny ones asked for many decimals, get an exponent.
 * buf holds at least 48 bytes. */
static void format_number(double v, int dec, char *buf)
{
	size_t k = 0;
	if (!isfinite(v))
		v = 0.0;
	if (dec > 18)
		dec = 18;
	while (dec > 0 && fabs(v) * bvh_pow10_exact(dec) >= 9.0e15)
		dec--;
	double a = fabs(v);
	if (a >= 9.0e15 || (a > 0.0 && a < 1e-9 && dec > 9)) {
		/* Scientific: 9 significant digits. */
		int e = (int)floor(log10(a));
		double m = a / pow(10.0, e);
		if (m >= 10.0) {
			m /= 10.0;
			e++;
		} else if (m < 1.0) {
			m *= 10.0;
			e--;
		}
		format_number(v < 0 ? -m : m, 8, buf);
		k = strlen(buf);
		buf[k++] = 'e';
		if (e < 0)
			buf[k++] = '-';
		k += utoa((unsigned long long)(e < 0 ? -e : e), buf + k);
		buf[k] = 0;
		return;
	}
	unsigned long long p = 1;
	for (int i = 0; i < dec; i++)
		p *= 10;
	unsigned long long r = (unsigned long long)(a * (double)p + 0.5);
	unsigned long long ip = r / p, fp = r % p;
	if (v < 0 && r != 0)
		buf[k++] = '-';
	k += utoa(ip, buf + k);
	if (fp) {
		buf[k++] = '.';
		for (int i = dec - 1; i >= 0; i--) {
			buf[k + (size_t)i] = (char)('0' + fp % 10);
			fp /= 10;
		}
		k += (size_t)dec;
		while (buf[k - 1] == '0')
			k--;
	}
	buf[k] = 0;
}

/* The shortest decimal that reads back as the same float. */
static void format_float_exact(float f, char *buf)
{
	double a = fabs((double)f);
	int lead = a > 0.0 ? (int)floor(log10(a)) : 0;
	for (int sig = 6; sig <= 9; sig++) {
		int dec = sig - 1 - lead;
		format_number(f, dec < 0 ? 0 : dec, buf);
		double back;
		if (bvh_parse_number(buf, strlen(buf), &back) == BVH_NUM_OK && (float)back == f)
			return;
	}
}

/* A joint's channel layout while writing. */
typedef struct layout {
	unsigned char ch[6];
	int n;
	int pos_mask, rot_mask;   /* bit a: the layout has the channel for axis a */
	mlod_euler_order euler;
	int need_pos, need_rot;   /* the motion needs the missing channels */
} layout;

static void layout_masks(layout *l)
{
	l->pos_mask = l->rot_mask = 0;
	for (int i = 0; i < l->n; i++) {
		if (l->ch[i] < MLOD_BVH_XROT)
			l->pos_mask |= 1 << l->ch[i];
		else
			l->rot_mask |= 1 << (l->ch[i] - MLOD_BVH_XROT);
	}
}

/* Gives the layout every channel its motion needs: all three positions
 * first, then the rotations in the Euler order (present ones stay). */
static void layout_complete(layout *l)
{
	layout o = *l;
	l->n = 0;
	if (o.need_pos || o.pos_mask) {
		for (int i = 0; i < o.n; i++)
			if (!o.need_pos && o.ch[i] < MLOD_BVH_XROT)
				l->ch[l->n++] = o.ch[i];
		if (o.need_pos)
			for (int a = 0; a < 3; a++)
				l->ch[l->n++] = (unsigned char)(MLOD_BVH_XPOS + a);
	}
	if (o.need_rot) {
		for (int a = 0; a < 3; a++)
			l->ch[l->n++] = (unsigned char)(MLOD_BVH_XROT + mlod_euler_axes(l->euler)[a]);
	} else {
		for (int i = 0; i < o.n; i++)
			if (o.ch[i] >= MLOD_BVH_XROT)
				l->ch[l->n++] = o.ch[i];
	}
	layout_masks(l);
}

/* The two Euler solutions of q in the layout's order: the principal one
 * and (a + pi, pi - b, c + pi). */
static void euler_solutions(const layout *l, mlod_quat q, double sol[2][3])
{
	float a[3];
	mlod_quat_to_euler(l->euler, q, a);
	const int *ax = mlod_euler_axes(l->euler);
	for (int i = 0; i < 3; i++)
		sol[0][i] = a[i];
	sol[1][ax[0]] = mlod_wrap_angle(a[ax[0]] + MLOD_PI);
	sol[1][ax[1]] = mlod_wrap_angle(MLOD_PI - a[ax[1]]);
	sol[1][ax[2]] = mlod_wrap_angle(a[ax[2]] + MLOD_PI);
}

#define ANGLE_TOL 1e-5

/* Does solution s leave the axes the layout has no channel for at 0? */
static int fits_layout(const layout *l, const double s[3])
{
	for (int a = 0; a < 3; a++)
		if (!(l->rot_mask & (1 << a)) && fabs(mlod_wrap_angle(s[a])) > ANGLE_TOL)
			return 0;
	return 1;
}

/* The Euler angles to write for q: a solution that fits the layout,
 * continued from the previous frame (each angle within 2 pi of the
 * principal value) so that players interpolating angles do not spin. */
static void euler_pick(const layout *l, mlod_quat q, const double *prev, double out[3])
{
	double sol[2][3], best = HUGE_VAL;
	euler_solutions(l, q, sol);
	/* With a partial layout only solutions that fit it are candidates
	 * (both when neither fits, which pass 1 has ruled out). */
	int fit[2] = { 1, 1 };
	if (l->rot_mask != 7) {
		fit[0] = fits_layout(l, sol[0]);
		fit[1] = fits_layout(l, sol[1]);
		if (!fit[0] && !fit[1])
			fit[0] = fit[1] = 1;
	}
	memcpy(out, sol[0], sizeof sol[0]);
	for (int s = 0; s < 2; s++) {
		if (!fit[s])
			continue;
		double cand[3], cost = 0.0;
		for (int a = 0; a < 3; a++) {
			cand[a] = sol[s][a];
			if (!prev)
				continue;
			/* The 2 pi turn of the angle nearest to the previous frame. */
			double bestd = HUGE_VAL;
			for (int k = -1; k <= 1; k++) {
				double x = sol[s][a] + k * 2.0 * MLOD_PI, dd = fabs(x - prev[a]);
				if (dd < bestd) {
					bestd = dd;
					cand[a] = x;
				}
			}
			cost += bestd * bestd;
		}
		if (cost < best) {
			best = cost;
			memcpy(out, cand, sizeof cand);
		}
	}
	for (int a = 0; a < 3; a++)
		if (!(l->rot_mask & (1 << a)))
			out[a] = 0.0;
}

/* The writer's state: the layouts and rest values, and one posed frame. */
typedef struct writer {
	const mlod_character *c;
	const mlod_clip *clip;
	int n;
	double ft;           /* seconds per frame */
	long frames;
	layout *lay;
	mlod_v3 *offset;     /* BVH OFFSETs */
	mlod_v3 *end;        /* End Site OFFSETs */
	double pos_tol;      /* a translation this far from its OFFSET needs channels */
	int *base_rigid;     /* roots: base is a rigid transform */
	mlod_quat *base_q;   /* roots: rotation of the base */
	/* The current pose. */
	mlod_trs *local;
	mlod_mat4 *world;
	int *rigid;          /* the joint's world transform is rigid (unit scales above and at it) */
	int *have_frame;     /* fw_q / fw_p computed for this pose */
	mlod_quat *fw_q;     /* rotation of the world matrix */
	mlod_v3 *fw_p;       /* position of the world matrix */
	mlod_v3 *t;          /* BVH local translation */
	mlod_quat *q;        /* BVH local rotation */
	/* Output. */
	int *order;          /* joints in file order (depth first) */
	double *prev;        /* last frame's Euler angles, 3 per joint */
	mlod_buf b;
} writer;

static int unit_scale(mlod_v3 s)
{
	return fabsf(s.x - 1.0f) <= 1e-6f && fabsf(s.y - 1.0f) <= 1e-6f && fabsf(s.z - 1.0f) <= 1e-6f;
}

static int finite_v3(mlod_v3 v)
{
	return isfinite(v.x) && isfinite(v.y) && isfinite(v.z);
}

/* The rigid frame (rotation, position) of joint j's world matrix. */
static void world_frame(writer *w, int j)
{
	if (w->have_frame[j])
		return;
	mlod_trs trs;
	const mlod_mat4 *m = &w->world[j];
	if (mlod_mat4_to_trs(m, &trs, 1e-4f) < 0) {
		/* Singular: keep the parent's orientation. */
		int p = w->c->skeleton.joints[j].parent;
		if (p >= 0) {
			world_frame(w, p);
			trs.r = w->fw_q[p];
		} else {
			trs.r = mlod_quat_identity();
		}
	}
	w->fw_q[j] = mlod_quat_normalize(trs.r);
	w->fw_p[j].x = m->m[12];
	w->fw_p[j].y = m->m[13];
	w->fw_p[j].z = m->m[14];
	w->have_frame[j] = 1;
}

/* Computes the BVH local transforms (w->t, w->q) of the pose in w->local.
 * A joint's BVH frame is the rigid part of its world transform. */
static void bvh_locals(writer *w)
{
	const mlod_skeleton *s = &w->c->skeleton;
	mlod_pose_world(s, w->local, w->world);
	memset(w->have_frame, 0, (size_t)w->n * sizeof *w->have_frame);
	for (int j = 0; j < w->n; j++) {
		const mlod_joint *jt = &s->joints[j];
		const mlod_trs *l = &w->local[j];
		int p = jt->parent;
		int parent_rigid = p < 0 ? w->base_rigid[j] : w->rigid[p];
		w->rigid[j] = parent_rigid && unit_scale(l->s);
		if (parent_rigid && p >= 0) {
			/* The BVH frame of the parent is its world frame. */
			w->t[j] = l->t;
			w->q[j] = l->r;
		} else if (parent_rigid) {
			/* A root below a rigid base: fold the base in. */
			w->t[j] = mlod_mat4_point(&jt->base, l->t);
			w->q[j] = mlod_quat_mul(w->base_q[j], l->r);
		} else {
			/* Scale above: go through the world matrices. */
			world_frame(w, j);
			mlod_quat pq = mlod_quat_identity();
			mlod_v3 pp = { 0.0f, 0.0f, 0.0f };
			if (p >= 0) {
				world_frame(w, p);
				pq = w->fw_q[p];
				pp = w->fw_p[p];
			}
			mlod_quat inv = mlod_quat_conjugate(pq);
			w->t[j] = mlod_quat_rotate(inv, mlod_v3_sub(w->fw_p[j], pp));
			w->q[j] = mlod_quat_mul(inv, w->fw_q[j]);
		}
		w->q[j] = mlod_quat_normalize(w->q[j]);
	}
}

/* Poses frame f (or the rest pose when f < 0) and computes its BVH locals. */
static void pose_frame(writer *w, long f)
{
	mlod_pose_rest(&w->c->skeleton, w->local);
	if (f >= 0 && w->clip)
		mlod_clip_sample(w->clip, (float)((double)f * w->ft), w->local);
	bvh_locals(w);
}

static int writer_alloc(writer *w)
{
	size_t n = (size_t)w->n;
	w->lay = calloc(n, sizeof *w->lay);
	w->offset = malloc(n * sizeof *w->offset);
	w->end = malloc(n * sizeof *w->end);
	w->base_rigid = calloc(n, sizeof *w->base_rigid);
	w->base_q = malloc(n * sizeof *w->base_q);
	w->local = malloc(n * sizeof *w->local);
	w->world = malloc(n * sizeof *w->world);
	w->rigid = malloc(n * sizeof *w->rigid);
	w->have_frame = malloc(n * sizeof *w->have_frame);
	w->fw_q = malloc(n * sizeof *w->fw_q);
	w->fw_p = malloc(n * sizeof *w->fw_p);
	w->t = malloc(n * sizeof *w->t);
	w->q = malloc(n * sizeof *w->q);
	w->order = malloc(n * sizeof *w->order);
	w->prev = malloc(n * 3 * sizeof *w->prev);
	return w->lay && w->offset && w->end && w->base_rigid && w->base_q && w->local && w->world && w->rigid &&
	       w->have_frame && w->fw_q && w->fw_p && w->t && w->q && w->order && w->prev;
}

static void writer_free(writer *w)
{
	free(w->lay);
	free(w->offset);
	free(w->end);
	free(w->base_rigid);
	free(w->base_q);
	free(w->local);
	free(w->world);
	free(w->rigid);
	free(w->have_frame);
	free(w->fw_q);
	free(w->fw_p);
	free(w->t);
	free(w->q);
	free(w->order);
	free(w->prev);
	mlod_buf_free(&w->b);
}

/* Each joint's layout as the character gives it (or the default), and the
 * bases of roots. */
static mlod_result writer_layouts(writer *w, mlod_error *err)
{
	static const unsigned char root6[6] = { MLOD_BVH_XPOS, MLOD_BVH_YPOS, MLOD_BVH_ZPOS,
	                                        MLOD_BVH_ZROT, MLOD_BVH_XROT, MLOD_BVH_YROT };
	for (int j = 0; j < w->n; j++) {
		const mlod_joint *jt = &w->c->skeleton.joints[j];
		layout *l = &w->lay[j];
		if (jt->channel_count < 0 || jt->channel_count > 6)
			return mlod_fail(err, MLOD_ERR_INVALID_ARG, "joint '%s' has %d BVH channels", jt->name,
			                 jt->channel_count);
		if (jt->channel_count > 0) {
			int seen = 0;
			for (int k = 0; k < jt->channel_count; k++) {
				int code = jt->channels[k];
				if (code > MLOD_BVH_ZROT || (seen & (1 << code)))
					return mlod_fail(err, MLOD_ERR_INVALID_ARG, "joint '%s' has an invalid BVH channel layout",
					                 jt->name);
				seen |= 1 << code;
				l->ch[l->n++] = (unsigned char)code;
			}
			mlod_euler_order fb = (int)jt->euler >= 0 && (int)jt->euler < 6 ? jt->euler : MLOD_EULER_ZXY;
			l->euler = bvh_layout_euler(l->ch, l->n, fb);
		} else {
			/* No layout: positions and ZXY on roots, ZXY elsewhere. */
			l->n = jt->parent < 0 ? 6 : 3;
			memcpy(l->ch, jt->parent < 0 ? root6 : root6 + 3, (size_t)l->n);
			l->euler = MLOD_EULER_ZXY;
		}
		layout_masks(l);
		w->base_q[j] = mlod_quat_identity();
		if (jt->parent < 0) {
			mlod_trs bt;
			if (mlod_mat4_to_trs(&jt->base, &bt, 1e-5f) == 0 && unit_scale(bt.s)) {
				w->base_rigid[j] = 1;
				w->base_q[j] = mlod_quat_normalize(bt.r);
			}
		}
	}
	return MLOD_OK;
}

/* The rest pose gives the OFFSETs, the End Sites and the skeleton's extent. */
static mlod_result writer_rest(writer *w, mlod_error *err)
{
	pose_frame(w, -1);
	for (int j = 0; j < w->n; j++) {
		const mlod_joint *jt = &w->c->skeleton.joints[j];
		w->offset[j] = w->t[j];
		w->end[j] = jt->end_site;
		if (jt->has_end_site && !w->rigid[j]) {
			/* Scaled: the End Site's place in the joint's rigid frame. */
			world_frame(w, j);
			mlod_v3 e = mlod_mat4_point(&w->world[j], jt->end_site);
			w->end[j] = mlod_quat_rotate(mlod_quat_conjugate(w->fw_q[j]), mlod_v3_sub(e, w->fw_p[j]));
		}
		if (!finite_v3(w->offset[j]) || !finite_v3(w->end[j]))
			return mlod_fail(err, MLOD_ERR_INVALID_ARG, "joint '%s' has a non-finite rest transform", jt->name);
	}
	/* A numeric tolerance: the largest extent, not the height. */
	double extent = mlod_skeleton_extent(&w->c->skeleton);
	if (!(extent > 0.0) || !isfinite(extent))
		extent = 1.0;
	w->pos_tol = 1e-6 * extent;
	return MLOD_OK;
}

/* Pass 1 over the frames: a joint whose translation leaves its OFFSET on
 * an axis it has no position channel for, or that turns about an axis it
 * has no rotation channel for, gets the missing channels. */
static mlod_result writer_widen(writer *w, mlod_error *err)
{
	for (long f = 0; f < w->frames; f++) {
		pose_frame(w, f);
		for (int j = 0; j < w->n; j++) {
			layout *l = &w->lay[j];
			mlod_quat q = w->q[j];
			if (!finite_v3(w->t[j]) || !isfinite(q.x) || !isfinite(q.y) || !isfinite(q.z) || !isfinite(q.w))
				return mlod_fail(err, MLOD_ERR_INVALID_ARG, "joint '%s' has a non-finite transform in frame %ld",
				                 w->c->skeleton.joints[j].name, f + 1);
			float d[3] = { w->t[j].x - w->offset[j].x, w->t[j].y - w->offset[j].y, w->t[j].z - w->offset[j].z };
			for (int a = 0; a < 3; a++)
				if (!(l->pos_mask & (1 << a)) && fabs(d[a]) > w->pos_tol)
					l->need_pos = 1;
			if (l->rot_mask != 7 && !l->need_rot) {
				double sol[2][3];
				euler_solutions(l, q, sol);
				if (!fits_layout(l, sol[0]) && !fits_layout(l, sol[1]))
					l->need_rot = 1;
			}
		}
	}
	for (int j = 0; j < w->n; j++)
		if (w->lay[j].need_pos || w->lay[j].need_rot)
			layout_complete(&w->lay[j]);
	return MLOD_OK;
}

/* A joint name safe for BVH: no blanks, braces or control bytes. */
static void put_name(mlod_buf *b, const char *name, int index)
{
	if (!name || !*name) {
		char num[24];
		num[utoa((unsigned long long)index, num)] = 0;
		mlod_buf_append_str(b, "joint");
		mlod_buf_append_str(b, num);
		return;
	}
	for (const char *p = name; *p; p++) {
		unsigned char c = (unsigned char)*p;
		mlod_buf_append_char(b, c <= 0x20 || c == 0x7f || c == '{' || c == '}' ? '_' : (char)c);
	}
}

static void put_indent(mlod_buf *b, int depth)
{
	for (int i = 0; i < depth && i < 64; i++)
		mlod_buf_append_char(b, '\t');
}

static void put_offset(mlod_buf *b, int depth, mlod_v3 v)
{
	char num[64];
	float c[3] = { v.x, v.y, v.z };
	put_indent(b, depth);
	mlod_buf_append_str(b, "OFFSET");
	for (int i = 0; i < 3; i++) {
		format_float_exact(c[i], num);
		mlod_buf_append_char(b, ' ');
		mlod_buf_append_str(b, num);
	}
	mlod_buf_append_char(b, '\n');
}

/* Opens joint j at the given depth: name, brace, OFFSET, CHANNELS. */
static void put_joint_head(writer *w, int j, int depth)
{
	const mlod_joint *jt = &w->c->skeleton.joints[j];
	const layout *l = &w->lay[j];
	mlod_buf *b = &w->b;
	put_indent(b, depth);
	mlod_buf_append_str(b, jt->parent < 0 ? "ROOT " : "JOINT ");
	put_name(b, jt->name, j);
	mlod_buf_append_char(b, '\n');
	put_indent(b, depth);
	mlod_buf_append_str(b, "{\n");
	put_offset(b, depth + 1, w->offset[j]);
	put_indent(b, depth + 1);
	mlod_buf_append_str(b, "CHANNELS ");
	mlod_buf_append_char(b, (char)('0' + l->n));
	for (int k = 0; k < l->n; k++) {
		mlod_buf_append_char(b, ' ');
		mlod_buf_append_str(b, bvh_channel_names[l->ch[k]]);
	}
	mlod_buf_append_char(b, '\n');
}

/* Closes joint j: its End Site, then the brace. */
static void put_joint_tail(writer *w, int j, int depth)
{
	mlod_buf *b = &w->b;
	if (w->c->skeleton.joints[j].has_end_site) {
		put_indent(b, depth + 1);
		mlod_buf_append_str(b, "End Site\n");
		put_indent(b, depth + 1);
		mlod_buf_append_str(b, "{\n");
		put_offset(b, depth + 2, w->end[j]);
		put_indent(b, depth + 1);
		mlod_buf_append_str(b, "}\n");
	}
	put_indent(b, depth);
	mlod_buf_append_str(b, "}\n");
}

/* The HIERARCHY, depth first without recursion; fills w->order. */
static mlod_result write_hierarchy(writer *w, mlod_error *err)
{
	const mlod_skeleton *s = &w->c->skeleton;
	size_t n = (size_t)w->n;
	int *first_child = malloc(n * sizeof(int)), *next_sib = malloc(n * sizeof(int));
	int *stack = malloc(n * sizeof(int)), *cursor = malloc(n * sizeof(int));
	if (!first_child || !next_sib || !stack || !cursor) {
		free(first_child);
		free(next_sib);
		free(stack);
		free(cursor);
		return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
	}
	/* Children lists in index order. */
	for (int j = 0; j < w->n; j++)
		first_child[j] = next_sib[j] = -1;
	for (int j = w->n - 1; j >= 0; j--) {
		int p = s->joints[j].parent;
		if (p >= 0) {
			next_sib[j] = first_child[p];
			first_child[p] = j;
		}
	}
	mlod_buf_append_str(&w->b, "HIERARCHY\n");
	int count = 0;
	for (int root = 0; root < w->n; root++) {
		if (s->joints[root].parent >= 0)
			continue;
		int depth = 1;
		stack[0] = root;
		w->order[count++] = root;
		put_joint_head(w, root, 0);
		cursor[root] = first_child[root];
		while (depth > 0) {
			int j = stack[depth - 1];
			if (cursor[j] >= 0) {
				int ch = cursor[j];
				cursor[j] = next_sib[ch];
				w->order[count++] = ch;
				put_joint_head(w, ch, depth);
				cursor[ch] = first_child[ch];
				stack[depth++] = ch;
			} else {
				depth--;
				put_joint_tail(w, j, depth);
			}
		}
	}
	free(first_child);
	free(next_sib);
	free(stack);
	free(cursor);
	return MLOD_OK;
}

/* Pass 2 over the frames: the MOTION. Positions are written as the
 * shortest decimal of their float, angles to 1e-5 degree (2e-7 radian). */
static void write_motion(writer *w)
{
	mlod_buf *b = &w->b;
	char num[64];
	mlod_buf_append_str(b, "MOTION\nFrames: ");
	num[utoa((unsigned long long)w->frames, num)] = 0;
	mlod_buf_append_str(b, num);
	mlod_buf_append_str(b, "\nFrame Time: ");
	format_float_exact((float)w->ft, num);
	mlod_buf_append_str(b, num);
	mlod_buf_append_char(b, '\n');
	for (long f = 0; f < w->frames && b->status == MLOD_OK; f++) {
		pose_frame(w, f);
		int sep = 0;
		for (int i = 0; i < w->n; i++) {
			int j = w->order[i];
			const layout *l = &w->lay[j];
			double ang[3] = { 0.0, 0.0, 0.0 };
			if (l->rot_mask) {
				euler_pick(l, w->q[j], f > 0 ? w->prev + 3 * j : NULL, ang);
				memcpy(w->prev + 3 * j, ang, sizeof ang);
			}
			float pos[3] = { w->t[j].x, w->t[j].y, w->t[j].z };
			for (int k = 0; k < l->n; k++) {
				int code = l->ch[k];
				if (code < MLOD_BVH_XROT)
					format_float_exact(pos[code], num);
				else
					format_number(ang[code - MLOD_BVH_XROT] * (180.0 / MLOD_PI), 5, num);
				if (sep)
					mlod_buf_append_char(b, ' ');
				sep = 1;
				mlod_buf_append_str(b, num);
			}
		}
		mlod_buf_append_char(b, '\n');
	}
}

mlod_result mlod_bvh_write(const mlod_character *c, int clip, float frame_time, char **text, size_t *size,
                           mlod_error *err)
{
	if (text)
		*text = NULL;
	if (size)
		*size = 0;
	if (!c || !text)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_bvh_write: NULL argument");
	const mlod_skeleton *s = &c->skeleton;
	int n = s->joint_count;
	if (n <= 0 || !s->joints)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "the character has no joints to write as BVH");
	for (int j = 0; j < n; j++)
		if (s->joints[j].parent < -1 || s->joints[j].parent >= j)
			return mlod_fail(err, MLOD_ERR_INVALID_ARG, "joint %d: its parent %d does not come before it", j,
			                 s->joints[j].parent);
	if (!(frame_time >= 0.0f) || !isfinite(frame_time))
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "frame time %g must be positive (or 0 for the clip's own)",
		                 (double)frame_time);

	/* The clip; a character without clips (or clip < 0) gives the rest pose. */
	const mlod_clip *cl = NULL;
	if (clip >= 0 && clip < c->clip_count)
		cl = &c->clips[clip];
	else if (clip >= 0 && !(clip == 0 && c->clip_count == 0))
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "no clip %d (the character has %d)", clip, c->clip_count);

	/* Frames at ft from 0 until the frame that reaches the clip's end. */
	double ft = frame_time > 0.0f ? frame_time : cl && cl->frame_time > 0.0f ? cl->frame_time : 1.0 / 30.0;
	long frames = 1;
	if (cl && frame_time == 0.0f && cl->frame_time > 0.0f && cl->frame_count > 0) {
		frames = cl->frame_count;
	} else if (cl && cl->duration > 0.0f) {
		double f = ceil((double)cl->duration / ft - 1e-3) + 1.0;
		if (!(f <= BVH_MAX_FRAMES))
			return mlod_fail(err, MLOD_ERR_NOMEM, "clip '%s' at %g s per frame needs more than %d frames",
			                 cl->name ? cl->name : "", ft, BVH_MAX_FRAMES);
		frames = (long)f;
	}
	if (frames > BVH_MAX_FRAMES || (double)frames * n * 6 > BVH_MAX_WRITE_VALUES)
		return mlod_fail(err, MLOD_ERR_NOMEM, "%ld frames of %d joints is too much motion for one BVH file",
		                 frames, n);

	writer w;
	memset(&w, 0, sizeof w);
	w.c = c;
	w.clip = cl;
	w.n = n;
	w.ft = ft;
	w.frames = frames;
	mlod_result res = MLOD_OK;
	if (!writer_alloc(&w))
		res = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
	if (res == MLOD_OK)
		res = writer_layouts(&w, err);
	if (res == MLOD_OK)
		res = writer_rest(&w, err);
	if (res == MLOD_OK)
		res = writer_widen(&w, err);
	if (res == MLOD_OK)
		res = write_hierarchy(&w, err);
	if (res == MLOD_OK)
		write_motion(&w);
	if (res == MLOD_OK)
		res = mlod_buf_take(&w.b, text, size, "BVH", err);
	writer_free(&w);
	return res;
}
