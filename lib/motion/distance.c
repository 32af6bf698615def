/*
 * distance.c: the frame distance of the paper (4.1.2, mlod-motion(1)
 * Frame distance) and the point distance of the error bounds.
 *
 * For each joint, the energy weight (h - depth) / h (h = tree height,
 * max depth + 1, as in label.c) times the total absolute change of its
 * three Euler angles divided by pi (the axis range Max(R) without joint
 * limits). Angles are taken in the joint's own order, differences
 * wrapped into (-pi, pi] and the nearer of the two Euler triples of the
 * rotation used, so q against -q and 179 against -179 degrees is no
 * motion. Beyond the paper, translation change over the skeleton height
 * and scale change are added, so root motion counts.
 *
 * mlod_motion_frame_distance measures two poses so; the tree
 * (motiontree.c) measures its frames with the same terms
 * (motion_euler_change, motion_joint_weights on the setup's weights).
 */
#include <math.h>
#include <stdlib.h>

#include "motion/motion_internal.h"

double mlod_motion_point_distance(const mlod_skeleton *s, int metres)
{
	if (metres)
		return MLOD_POINT_DISTANCE_METRES;
	double h = mlod_skeleton_height(s);
	return (h > 0.0 ? h : 1.0) / 18.0;
}

/* Sum of |wrapped differences| between two Euler triples of one order,
 * the nearer of the two triples of b: (A, B, C) and (A + pi, pi - B, C + pi)
 * over the order's axes, outermost first. */
double motion_euler_change(mlod_euler_order order, const float *ea, const float *eb)
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
void motion_joint_weights(const mlod_skeleton *s, double *w)
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
	motion_joint_weights(s, w);
	double height = mlod_skeleton_height(s), d = 0.0;
	for (int j = 0; j < s->joint_count; j++) {
		float ea[3], eb[3];
		mlod_quat_to_euler(s->joints[j].euler, a[j].r, ea);
		mlod_quat_to_euler(s->joints[j].euler, b[j].r, eb);
		d += w[j] * (motion_euler_change(s->joints[j].euler, ea, eb) / MLOD_PI + v3_dist(a[j].t, b[j].t) / height +
		             v3_dist(a[j].s, b[j].s));
	}
	free(w);
	return d;
}

/* ---------------------------------------------------------------- */
