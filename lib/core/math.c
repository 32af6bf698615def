/*
 * math.c: vectors, quaternions, Euler angles and 4x4 matrices.
 *
 * Matrices are column-major (m[col * 4 + row]); quaternions are (x, y, z, w).
 * Euler order "ABC" means R = RA * RB * RC. Angles are recovered from the
 * rotation matrix by permuting the axes so that every order reduces to XYZ
 * (odd permutations mirror the frame, which negates the angles), and the
 * last angle is solved after the first is known so that the result always
 * reproduces the rotation, also at gimbal lock. Internal arithmetic that
 * loses precision easily (Euler extraction, decomposition, inverse) is done
 * in double.
 */
#include <ctype.h>
#include <math.h>
#include <stddef.h>

#include "mlod_core.h"

double mlod_wrap_angle(double a)
{
	a = fmod(a + MLOD_PI, 2.0 * MLOD_PI);
	if (a <= 0.0)
		a += 2.0 * MLOD_PI;
	return a - MLOD_PI;
}

/* ---------------------------------------------------------------- */
/* Vectors                                                           */
/* ---------------------------------------------------------------- */

mlod_v3 mlod_v3_add(mlod_v3 a, mlod_v3 b)
{
	mlod_v3 r = { a.x + b.x, a.y + b.y, a.z + b.z };
	return r;
}

mlod_v3 mlod_v3_sub(mlod_v3 a, mlod_v3 b)
{
	mlod_v3 r = { a.x - b.x, a.y - b.y, a.z - b.z };
	return r;
}

mlod_v3 mlod_v3_scale(mlod_v3 a, float s)
{
	mlod_v3 r = { a.x * s, a.y * s, a.z * s };
	return r;
}

float mlod_v3_dot(mlod_v3 a, mlod_v3 b)
{
	return a.x * b.x + a.y * b.y + a.z * b.z;
}

mlod_v3 mlod_v3_cross(mlod_v3 a, mlod_v3 b)
{
	mlod_v3 r = { a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x };
	return r;
}

float mlod_v3_length(mlod_v3 a)
{
	return sqrtf(mlod_v3_dot(a, a));
}

/* ---------------------------------------------------------------- */
/* Quaternions                                                       */
/* ---------------------------------------------------------------- */

mlod_quat mlod_quat_identity(void)
{
	mlod_quat q = { 0.0f, 0.0f, 0.0f, 1.0f };
	return q;
}

mlod_quat mlod_quat_mul(mlod_quat a, mlod_quat b)
{
	mlod_quat r;
	r.x = a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y;
	r.y = a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x;
	r.z = a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w;
	r.w = a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z;
	return r;
}

static double quat_dot(mlod_quat a, mlod_quat b)
{
	return (double)a.x * b.x + (double)a.y * b.y + (double)a.z * b.z + (double)a.w * b.w;
}

double mlod_quat4_length(double x, double y, double z, double w)
{
	const double v[4] = { x, y, z, w };
	double m = 0.0;
	for (int i = 0; i < 4; i++) {
		if (!isfinite(v[i]))
			return NAN;
		m = fmax(m, fabs(v[i]));
	}
	if (m == 0.0)
		return 0.0;
	double s = 0.0;
	for (int i = 0; i < 4; i++)
		s += (v[i] / m) * (v[i] / m);
	return m * sqrt(s);
}

mlod_quat mlod_quat_normalize(mlod_quat q)
{
	double n = sqrt(quat_dot(q, q));
	if (!(n > 0.0) || !isfinite(n))
		return mlod_quat_identity();
	mlod_quat r = { (float)(q.x / n), (float)(q.y / n), (float)(q.z / n), (float)(q.w / n) };
	return r;
}

mlod_quat mlod_quat_conjugate(mlod_quat q)
{
	mlod_quat r = { -q.x, -q.y, -q.z, q.w };
	return r;
}

mlod_v3 mlod_quat_rotate(mlod_quat q, mlod_v3 v)
{
	/* v + 2w (u x v) + 2 u x (u x v), u the vector part */
	mlod_v3 u = { q.x, q.y, q.z };
	mlod_v3 t = mlod_v3_scale(mlod_v3_cross(u, v), 2.0f);
	return mlod_v3_add(mlod_v3_add(v, mlod_v3_scale(t, q.w)), mlod_v3_cross(u, t));
}

mlod_quat mlod_quat_axis_angle(mlod_v3 axis, float angle)
{
	double n = sqrt((double)axis.x * axis.x + (double)axis.y * axis.y + (double)axis.z * axis.z);
	if (!(n > 0.0))
		return mlod_quat_identity();
	double s = sin(0.5 * angle) / n;
	mlod_quat q = { (float)(axis.x * s), (float)(axis.y * s), (float)(axis.z * s),
	                (float)cos(0.5 * angle) };
	return q;
}

/* Weighted sum wa*a + wb*b in double, normalised. */
static mlod_quat quat_blend(mlod_quat a, double wa, mlod_quat b, double wb)
{
	double x = wa * a.x + wb * b.x, y = wa * a.y + wb * b.y;
	double z = wa * a.z + wb * b.z, w = wa * a.w + wb * b.w;
	double n = sqrt(x * x + y * y + z * z + w * w);
	if (!(n > 0.0))
		return mlod_quat_identity();
	mlod_quat r = { (float)(x / n), (float)(y / n), (float)(z / n), (float)(w / n) };
	return r;
}

mlod_quat mlod_quat_slerp(mlod_quat a, mlod_quat b, float t)
{
	a = mlod_quat_normalize(a);
	b = mlod_quat_normalize(b);
	double d = quat_dot(a, b);
	double sign = d < 0.0 ? -1.0 : 1.0;
	d = fabs(d);
	if (d > 0.9995) /* nearly parallel: the chord is the arc */
		return quat_blend(a, 1.0 - t, b, sign * t);
	double theta = acos(d), s = sin(theta);
	return quat_blend(a, sin((1.0 - t) * theta) / s, b, sign * sin(t * theta) / s);
}

mlod_quat mlod_quat_nlerp(mlod_quat a, mlod_quat b, float t)
{
	double sign = quat_dot(a, b) < 0.0 ? -1.0 : 1.0;
	return quat_blend(a, 1.0 - t, b, sign * t);
}

float mlod_quat_angle(mlod_quat a, mlod_quat b)
{
	/* r = conj(a) * b; the angle of r is 2 atan2(|xyz|, |w|), accurate near 0 and pi */
	mlod_quat r = mlod_quat_mul(mlod_quat_conjugate(mlod_quat_normalize(a)), mlod_quat_normalize(b));
	double v = sqrt((double)r.x * r.x + (double)r.y * r.y + (double)r.z * r.z);
	return (float)(2.0 * atan2(v, fabs((double)r.w)));
}

/* ---------------------------------------------------------------- */
/* Euler angles                                                      */
/* ---------------------------------------------------------------- */

/* Axes of each order, outermost first: order ABC is RA * RB * RC. */
static const int euler_axes[6][3] = {
	{ 0, 1, 2 }, { 0, 2, 1 }, { 1, 0, 2 }, { 1, 2, 0 }, { 2, 0, 1 }, { 2, 1, 0 }
};
static const char *const euler_names[6] = { "XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX" };

static int euler_valid(mlod_euler_order order)
{
	return (int)order >= 0 && (int)order < 6;
}

mlod_quat mlod_quat_from_euler(mlod_euler_order order, const float angles[3])
{
	if (!euler_valid(order))
		order = MLOD_EULER_XYZ;
	const int *ax = euler_axes[order];
	mlod_quat q = mlod_quat_identity();
	for (int n = 0; n < 3; n++) {
		mlod_v3 axis = { ax[n] == 0, ax[n] == 1, ax[n] == 2 };
		q = mlod_quat_mul(q, mlod_quat_axis_angle(axis, angles[ax[n]]));
	}
	return mlod_quat_normalize(q);
}

/* Rotation matrix of a quaternion, r[row][col], in double. */
static void quat_to_rows(mlod_quat q, double r[3][3])
{
	double x = q.x, y = q.y, z = q.z, w = q.w;
	double n = x * x + y * y + z * z + w * w;
	double s = n > 0.0 ? 2.0 / n : 0.0;
	r[0][0] = 1 - s * (y * y + z * z); r[0][1] = s * (x * y - w * z);     r[0][2] = s * (x * z + w * y);
	r[1][0] = s * (x * y + w * z);     r[1][1] = 1 - s * (x * x + z * z); r[1][2] = s * (y * z - w * x);
	r[2][0] = s * (x * z - w * y);     r[2][1] = s * (y * z + w * x);     r[2][2] = 1 - s * (x * x + y * y);
}

void mlod_quat_to_euler(mlod_euler_order order, mlod_quat q, float angles[3])
{
	if (!euler_valid(order))
		order = MLOD_EULER_XYZ;
	const int *ax = euler_axes[order];
	/* Even permutations of XYZ keep handedness; odd ones mirror it. */
	int odd = (ax[1] - ax[0] + 3) % 3 != 1;
	double r[3][3], m[3][3];
	quat_to_rows(q, r);
	for (int i = 0; i < 3; i++)
		for (int j = 0; j < 3; j++)
			m[i][j] = r[ax[i]][ax[j]];

	/* m = Rx(a) Ry(b) Rz(c): m[1][2] = -sin a cos b, m[2][2] = cos a cos b. */
	/* cb = hypot(m[1][2], m[2][2]) only decides cb > 1e-7. Its square
	 * in doubles (relative error a few 2^-53, or far below 1e-14 when it
	 * underflows) decides it alike 1% away from the limit; between, or
	 * for a NaN, hypot does. */
	double cb2 = m[1][2] * m[1][2] + m[2][2] * m[2][2];
	int tilt = cb2 >= 1.01e-14 ? 1 : cb2 <= 0.99e-14 ? 0 : hypot(m[1][2], m[2][2]) > 1e-7;
	double a = tilt ? atan2(-m[1][2], m[2][2]) : 0.0;
	double ca = cos(a), sa = sin(a);
	double b = atan2(m[0][2], -sa * m[1][2] + ca * m[2][2]);
	/* Rx(a)^T m = Ry(b) Rz(c), whose row 1 is (sin c, cos c, 0). */
	double c = atan2(ca * m[1][0] + sa * m[2][0], ca * m[1][1] + sa * m[2][1]);
	double sign = odd ? -1.0 : 1.0;
	angles[ax[0]] = (float)(sign * a);
	angles[ax[1]] = (float)(sign * b);
	angles[ax[2]] = (float)(sign * c);
}

int mlod_euler_order_parse(const char *s, mlod_euler_order *out)
{
	if (!s || !s[0] || !s[1] || !s[2] || s[3])
		return -1;
	for (int o = 0; o < 6; o++) {
		const char *n = euler_names[o];
		if (toupper((unsigned char)s[0]) == n[0] && toupper((unsigned char)s[1]) == n[1] &&
		    toupper((unsigned char)s[2]) == n[2]) {
			if (out)
				*out = (mlod_euler_order)o;
			return 0;
		}
	}
	return -1;
}

const char *mlod_euler_order_name(mlod_euler_order order)
{
	return euler_valid(order) ? euler_names[order] : "?";
}

const int *mlod_euler_axes(mlod_euler_order order)
{
	return euler_axes[euler_valid(order) ? order : MLOD_EULER_XYZ];
}

/* ---------------------------------------------------------------- */
/* Matrices                                                          */
/* ---------------------------------------------------------------- */

mlod_mat4 mlod_mat4_identity(void)
{
	mlod_mat4 r = { { 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1 } };
	return r;
}

mlod_mat4 mlod_mat4_mul(const mlod_mat4 *a, const mlod_mat4 *b)
{
	mlod_mat4 r;
	for (int c = 0; c < 4; c++)
		for (int row = 0; row < 4; row++) {
			float s = 0.0f;
			for (int k = 0; k < 4; k++)
				s += a->m[k * 4 + row] * b->m[c * 4 + k];
			r.m[c * 4 + row] = s;
		}
	return r;
}

mlod_mat4 mlod_mat4_from_trs(const mlod_trs *trs)
{
	double r[3][3];
	quat_to_rows(trs->r, r);
	const float s[3] = { trs->s.x, trs->s.y, trs->s.z };
	mlod_mat4 m;
	for (int c = 0; c < 3; c++) {
		for (int row = 0; row < 3; row++)
			m.m[c * 4 + row] = (float)(r[row][c] * s[c]);
		m.m[c * 4 + 3] = 0.0f;
	}
	m.m[12] = trs->t.x;
	m.m[13] = trs->t.y;
	m.m[14] = trs->t.z;
	m.m[15] = 1.0f;
	return m;
}

static double det3(double a[3][3])
{
	return a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
	       a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
	       a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
}

/* Quaternion of an orthonormal rotation matrix r[row][col] (Shepperd's method). */
static mlod_quat quat_from_rows(double r[3][3])
{
	double x, y, z, w, tr = r[0][0] + r[1][1] + r[2][2];
	if (tr > 0.0) {
		double s = 2.0 * sqrt(tr + 1.0);
		w = 0.25 * s; x = (r[2][1] - r[1][2]) / s; y = (r[0][2] - r[2][0]) / s; z = (r[1][0] - r[0][1]) / s;
	} else if (r[0][0] > r[1][1] && r[0][0] > r[2][2]) {
		double s = 2.0 * sqrt(1.0 + r[0][0] - r[1][1] - r[2][2]);
		w = (r[2][1] - r[1][2]) / s; x = 0.25 * s; y = (r[0][1] + r[1][0]) / s; z = (r[0][2] + r[2][0]) / s;
	} else if (r[1][1] > r[2][2]) {
		double s = 2.0 * sqrt(1.0 + r[1][1] - r[0][0] - r[2][2]);
		w = (r[0][2] - r[2][0]) / s; x = (r[0][1] + r[1][0]) / s; y = 0.25 * s; z = (r[1][2] + r[2][1]) / s;
	} else {
		double s = 2.0 * sqrt(1.0 + r[2][2] - r[0][0] - r[1][1]);
		w = (r[1][0] - r[0][1]) / s; x = (r[0][2] + r[2][0]) / s; y = (r[1][2] + r[2][1]) / s; z = 0.25 * s;
	}
	if (w < 0.0) { /* canonical sign */
		x = -x; y = -y; z = -z; w = -w;
	}
	mlod_quat q = { (float)x, (float)y, (float)z, (float)w };
	return mlod_quat_normalize(q);
}

/* Replaces q (det > 0) by its closest rotation: the polar factor, by the
 * iteration Q <- (Q + Q^-T) / 2, which converges quadratically. */
static void orthonormalize(double q[3][3])
{
	for (int it = 0; it < 30; it++) {
		double d = det3(q), cof[3][3], change = 0.0;
		if (d == 0.0)
			return;
		for (int i = 0; i < 3; i++)
			for (int j = 0; j < 3; j++) {
				int i1 = (i + 1) % 3, i2 = (i + 2) % 3, j1 = (j + 1) % 3, j2 = (j + 2) % 3;
				cof[i][j] = q[i1][j1] * q[i2][j2] - q[i1][j2] * q[i2][j1];
			}
		for (int i = 0; i < 3; i++)
			for (int j = 0; j < 3; j++) {
				double n = 0.5 * (q[i][j] + cof[i][j] / d); /* Q^-T = cof / det */
				change += fabs(n - q[i][j]);
				q[i][j] = n;
			}
		if (change < 1e-15)
			return;
	}
}

int mlod_mat4_to_trs(const mlod_mat4 *m, mlod_trs *out, float tol)
{
	*out = mlod_trs_identity();
	for (int i = 0; i < 16; i++)
		if (!isfinite(m->m[i]))
			return -1;
	out->t.x = m->m[12];
	out->t.y = m->m[13];
	out->t.z = m->m[14];

	double a[3][3], len[3], q[3][3];
	for (int c = 0; c < 3; c++) {
		for (int row = 0; row < 3; row++)
			a[row][c] = m->m[c * 4 + row];
		len[c] = sqrt(a[0][c] * a[0][c] + a[1][c] * a[1][c] + a[2][c] * a[2][c]);
		if (!(len[c] > 0.0))
			return -1;
	}
	double det = det3(a);
	if (fabs(det) < 1e-6 * len[0] * len[1] * len[2])
		return -1;

	/* Normalised columns; a negative determinant is a mirror, given to x. */
	for (int c = 0; c < 3; c++)
		for (int row = 0; row < 3; row++)
			q[row][c] = a[row][c] / len[c] * (c == 0 && det < 0.0 ? -1.0 : 1.0);
	int shear = 0;
	for (int i = 0; i < 3; i++)
		for (int j = i + 1; j < 3; j++) {
			double d = q[0][i] * q[0][j] + q[1][i] * q[1][j] + q[2][i] * q[2][j];
			if (fabs(d) > tol)
				shear = 1;
		}
	if (m->m[3] != 0.0f || m->m[7] != 0.0f || m->m[11] != 0.0f || m->m[15] != 1.0f)
		shear = 1; /* projective: not affine, no TRS expresses it */
	orthonormalize(q);

	/* The best scale for that rotation: projection of each column on its axis. */
	double s[3];
	for (int c = 0; c < 3; c++)
		s[c] = a[0][c] * q[0][c] + a[1][c] * q[1][c] + a[2][c] * q[2][c];
	out->r = quat_from_rows(q);
	out->s.x = (float)s[0];
	out->s.y = (float)s[1];
	out->s.z = (float)s[2];
	return shear;
}

int mlod_mat4_invert(const mlod_mat4 *m, mlod_mat4 *out)
{
	double a[16], inv[16];
	for (int i = 0; i < 16; i++)
		a[i] = m->m[i];
	/* Cofactor expansion (the layout is symmetric in rows and columns,
	 * so the column-major storage needs no transposition). */
	inv[0] = a[5] * a[10] * a[15] - a[5] * a[11] * a[14] - a[9] * a[6] * a[15] + a[9] * a[7] * a[14] + a[13] * a[6] * a[11] - a[13] * a[7] * a[10];
	inv[4] = -a[4] * a[10] * a[15] + a[4] * a[11] * a[14] + a[8] * a[6] * a[15] - a[8] * a[7] * a[14] - a[12] * a[6] * a[11] + a[12] * a[7] * a[10];
	inv[8] = a[4] * a[9] * a[15] - a[4] * a[11] * a[13] - a[8] * a[5] * a[15] + a[8] * a[7] * a[13] + a[12] * a[5] * a[11] - a[12] * a[7] * a[9];
	inv[12] = -a[4] * a[9] * a[14] + a[4] * a[10] * a[13] + a[8] * a[5] * a[14] - a[8] * a[6] * a[13] - a[12] * a[5] * a[10] + a[12] * a[6] * a[9];
	inv[1] = -a[1] * a[10] * a[15] + a[1] * a[11] * a[14] + a[9] * a[2] * a[15] - a[9] * a[3] * a[14] - a[13] * a[2] * a[11] + a[13] * a[3] * a[10];
	inv[5] = a[0] * a[10] * a[15] - a[0] * a[11] * a[14] - a[8] * a[2] * a[15] + a[8] * a[3] * a[14] + a[12] * a[2] * a[11] - a[12] * a[3] * a[10];
	inv[9] = -a[0] * a[9] * a[15] + a[0] * a[11] * a[13] + a[8] * a[1] * a[15] - a[8] * a[3] * a[13] - a[12] * a[1] * a[11] + a[12] * a[3] * a[9];
	inv[13] = a[0] * a[9] * a[14] - a[0] * a[10] * a[13] - a[8] * a[1] * a[14] + a[8] * a[2] * a[13] + a[12] * a[1] * a[10] - a[12] * a[2] * a[9];
	inv[2] = a[1] * a[6] * a[15] - a[1] * a[7] * a[14] - a[5] * a[2] * a[15] + a[5] * a[3] * a[14] + a[13] * a[2] * a[7] - a[13] * a[3] * a[6];
	inv[6] = -a[0] * a[6] * a[15] + a[0] * a[7] * a[14] + a[4] * a[2] * a[15] - a[4] * a[3] * a[14] - a[12] * a[2] * a[7] + a[12] * a[3] * a[6];
	inv[10] = a[0] * a[5] * a[15] - a[0] * a[7] * a[13] - a[4] * a[1] * a[15] + a[4] * a[3] * a[13] + a[12] * a[1] * a[7] - a[12] * a[3] * a[5];
	inv[14] = -a[0] * a[5] * a[14] + a[0] * a[6] * a[13] + a[4] * a[1] * a[14] - a[4] * a[2] * a[13] - a[12] * a[1] * a[6] + a[12] * a[2] * a[5];
	inv[3] = -a[1] * a[6] * a[11] + a[1] * a[7] * a[10] + a[5] * a[2] * a[11] - a[5] * a[3] * a[10] - a[9] * a[2] * a[7] + a[9] * a[3] * a[6];
	inv[7] = a[0] * a[6] * a[11] - a[0] * a[7] * a[10] - a[4] * a[2] * a[11] + a[4] * a[3] * a[10] + a[8] * a[2] * a[7] - a[8] * a[3] * a[6];
	inv[11] = -a[0] * a[5] * a[11] + a[0] * a[7] * a[9] + a[4] * a[1] * a[11] - a[4] * a[3] * a[9] - a[8] * a[1] * a[7] + a[8] * a[3] * a[5];
	inv[15] = a[0] * a[5] * a[10] - a[0] * a[6] * a[9] - a[4] * a[1] * a[10] + a[4] * a[2] * a[9] + a[8] * a[1] * a[6] - a[8] * a[2] * a[5];

	double det = a[0] * inv[0] + a[1] * inv[4] + a[2] * inv[8] + a[3] * inv[12];
	/* Singular when the determinant is negligible against the column lengths. */
	double scale = 1.0;
	for (int c = 0; c < 4; c++)
		scale *= sqrt(a[c * 4] * a[c * 4] + a[c * 4 + 1] * a[c * 4 + 1] +
		              a[c * 4 + 2] * a[c * 4 + 2] + a[c * 4 + 3] * a[c * 4 + 3]);
	if (!isfinite(det) || !(fabs(det) > 1e-12 * scale))
		return -1;
	for (int i = 0; i < 16; i++)
		out->m[i] = (float)(inv[i] / det);
	return 0;
}

mlod_v3 mlod_mat4_point(const mlod_mat4 *m, mlod_v3 p)
{
	const float *a = m->m;
	mlod_v3 r = { a[0] * p.x + a[4] * p.y + a[8] * p.z + a[12],
	              a[1] * p.x + a[5] * p.y + a[9] * p.z + a[13],
	              a[2] * p.x + a[6] * p.y + a[10] * p.z + a[14] };
	return r;
}

mlod_v3 mlod_mat4_vector(const mlod_mat4 *m, mlod_v3 v)
{
	const float *a = m->m;
	mlod_v3 r = { a[0] * v.x + a[4] * v.y + a[8] * v.z,
	              a[1] * v.x + a[5] * v.y + a[9] * v.z,
	              a[2] * v.x + a[6] * v.y + a[10] * v.z };
	return r;
}

/* Gershgorin on M^T M (mlod_core.h). */
double mlod_mat4_sigma_bound(const mlod_mat4 *w)
{
	double g = 0.0;
	for (int a = 0; a < 3; a++) {
		double row = 0.0;
		for (int b = 0; b < 3; b++) {
			double d = 0.0;
			for (int r = 0; r < 3; r++)
				d += (double)w->m[4 * a + r] * w->m[4 * b + r];
			row += fabs(d);
		}
		g = row > g ? row : g;
	}
	return sqrt(g);
}

mlod_trs mlod_trs_identity(void)
{
	mlod_trs t = { { 0, 0, 0 }, { 0, 0, 0, 1 }, { 1, 1, 1 } };
	return t;
}
