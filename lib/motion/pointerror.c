/*
 * pointerror.c: the point error, the bound both motion methods answer to
 * (the frames method of framesmethod.c and the key reduction of keyreduce.c):
 *
 *     |o' - o| + r * sigma_max(A' - A)
 *
 * where o, A are the origin and the 3x3 linear part of a joint's world
 * matrix as read, o', A' those of a level, and r the joint's point
 * distance. It bounds how far any point within r of the joint moves (for
 * a pure rotation error of angle t it is 2 r sin(t/2), the exact
 * displacement of the farthest point).
 */
#include <math.h>

#include "motion/mlod_motion.h"
#include "motion/motion_eval.h"

/* Largest singular value of a 3x3 matrix given by columns (a[c * 3 + r]). */
static double sigma_max(const double a[9])
{
	/* B = A^T A, symmetric positive semi-definite. */
	double b[3][3];
	for (int i = 0; i < 3; i++)
		for (int j = 0; j < 3; j++)
			b[i][j] = a[0 * 3 + i] * a[0 * 3 + j] + a[1 * 3 + i] * a[1 * 3 + j] + a[2 * 3 + i] * a[2 * 3 + j];
	double p1 = b[0][1] * b[0][1] + b[0][2] * b[0][2] + b[1][2] * b[1][2];
	double q = (b[0][0] + b[1][1] + b[2][2]) / 3.0, lambda;
	if (p1 <= 1e-30 * (q * q + 1e-300)) {
		lambda = fmax(b[0][0], fmax(b[1][1], b[2][2]));
	} else {
		double p2 = (b[0][0] - q) * (b[0][0] - q) + (b[1][1] - q) * (b[1][1] - q) + (b[2][2] - q) * (b[2][2] - q) +
		            2.0 * p1;
		double p = sqrt(p2 / 6.0), c[3][3];
		for (int i = 0; i < 3; i++)
			for (int j = 0; j < 3; j++)
				c[i][j] = (b[i][j] - (i == j ? q : 0.0)) / p;
		double det = c[0][0] * (c[1][1] * c[2][2] - c[1][2] * c[2][1]) - c[0][1] * (c[1][0] * c[2][2] - c[1][2] * c[2][0]) +
		             c[0][2] * (c[1][0] * c[2][1] - c[1][1] * c[2][0]);
		double r = det / 2.0;
		r = r < -1.0 ? -1.0 : r > 1.0 ? 1.0 : r;
		lambda = q + 2.0 * p * cos(acos(r) / 3.0);
		/* Rounding: never below the largest diagonal entry. */
		lambda = fmax(lambda, fmax(b[0][0], fmax(b[1][1], b[2][2])));
	}
	return lambda > 0.0 ? sqrt(lambda) * (1.0 + 1e-9) : 0.0;
}

/* Is base + rad * sigma_max(a) <= limit (rad >= 0)? Exactly that answer,
 * from bounds of sigma_max(a) as computed where they fall on one side of
 * the limit (the sum is monotone in it), cheapest first, and sigma_max
 * only between them. B = A^T A as sigma_max forms it; sigma_max's
 * eigenvalue is never below B's largest diagonal entry (the same floats),
 * nor above B's largest absolute row sum (Gershgorin), nor, but for its
 * rounding (far below 1e-7 relative, even where two eigenvalues meet and
 * acos loses half the digits), below the Rayleigh quotient of any vector,
 * here B's column of that diagonal entry (a rotation's error
 * A' - A = A (R - I) has two equal singular values and that column lies
 * in their plane: the quotient is the largest eigenvalue). The 1e-5
 * margins cover the roundings 100 times over. */
EVAL_INLINE int sigma_decide(const double a[9], double rad, double base, double limit)
{
	double b[3][3];
	/* Written out: b[i][j] = sum over c of a[c * 3 + i] a[c * 3 + j], in
	 * sigma_max's order. */
#define SIGMA_B(i, j) (a[0 * 3 + i] * a[0 * 3 + j] + a[1 * 3 + i] * a[1 * 3 + j] + a[2 * 3 + i] * a[2 * 3 + j])
	b[0][0] = SIGMA_B(0, 0), b[1][1] = SIGMA_B(1, 1), b[2][2] = SIGMA_B(2, 2);
	b[0][1] = b[1][0] = SIGMA_B(0, 1), b[0][2] = b[2][0] = SIGMA_B(0, 2), b[1][2] = b[2][1] = SIGMA_B(1, 2);
#undef SIGMA_B
	int k = b[1][1] > b[0][0] ? 1 : 0;
	if (b[2][2] > b[k][k])
		k = 2;
	double diag = b[k][k]; /* the largest (or a NaN's place: then 0 below) */
	if (!(base + rad * (diag > 0.0 ? sqrt(diag) * (1.0 + 1e-9) : 0.0) <= limit))
		return 0;
	double g = 0.0;
	for (int i = 0; i < 3; i++) {
		double row = fabs(b[i][0]) + fabs(b[i][1]) + fabs(b[i][2]);
		if (!(row <= g))
			g = row; /* a NaN stays */
	}
	if (base + rad * (sqrt(g) * (1.0 + 1e-5)) <= limit)
		return 1;
	const double *v = b[k];
	double vv = 0.0, vbv = 0.0;
	for (int i = 0; i < 3; i++) {
		vv += v[i] * v[i];
		vbv += v[i] * (b[i][0] * v[0] + b[i][1] * v[1] + b[i][2] * v[2]);
	}
	if (vv > 0.0 && vbv > 0.0 && base + rad * (sqrt(vbv / vv) * (1.0 - 1e-5)) > limit)
		return 0;
	return base + rad * sigma_max(a) <= limit;
}

int eval_point_error_within(const mlod_mat4 *w, const mlod_mat4 *w0, double radius, double limit)
{
	double d[3], m[9];
	for (int r = 0; r < 3; r++)
		d[r] = (double)w->m[12 + r] - w0->m[12 + r];
	for (int c = 0; c < 3; c++)
		for (int r = 0; r < 3; r++)
			m[c * 3 + r] = (double)w->m[c * 4 + r] - w0->m[c * 4 + r];
	/* mlod_motion_point_error's sum, compared */
	return sigma_decide(m, radius, sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]), limit);
}

double mlod_motion_point_error(const mlod_mat4 *a, const mlod_mat4 *b, double radius)
{
	double d[3], m[9];
	for (int r = 0; r < 3; r++)
		d[r] = (double)a->m[12 + r] - b->m[12 + r];
	for (int c = 0; c < 3; c++)
		for (int r = 0; r < 3; r++)
			m[c * 3 + r] = (double)a->m[c * 4 + r] - b->m[c * 4 + r];
	return sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) + radius * sigma_max(m);
}

EVAL_INLINE int point_within(const mlod_mat4 *w, const mlod_mat4 *w0, double radius, double budget)
{
	double dx = (double)w->m[12] - w0->m[12], dy = (double)w->m[13] - w0->m[13], dz = (double)w->m[14] - w0->m[14];
	double dp = sqrt(dx * dx + dy * dy + dz * dz);
	if (!(dp <= budget))
		return 0;
	double a[9], frob = 0.0;
	for (int c = 0; c < 3; c++)
		for (int r = 0; r < 3; r++) {
			a[c * 3 + r] = (double)w->m[c * 4 + r] - w0->m[c * 4 + r];
			frob += a[c * 3 + r] * a[c * 3 + r];
		}
	double room = budget - dp, rad = radius;
	if (rad * rad * frob <= room * room)
		return 1; /* sigma_max <= Frobenius norm */
	return sigma_decide(a, rad, 0.0, room); /* 0 + x is x */
}

int mlod_motion_point_within(const mlod_mat4 *w, const mlod_mat4 *w0, double radius, double budget)
{
	return point_within(w, w0, radius, budget);
}

#if EVAL_HAVE_AVX2
/* mlod_motion_point_within compiled for AVX2 (motion_eval.h): the same answer. */
EVAL_TARGET_AVX2 int motion_point_within_avx2(const mlod_mat4 *w, const mlod_mat4 *w0, double radius, double budget)
{
	return point_within(w, w0, radius, budget);
}
#endif
