/* test_math.c: vectors, quaternions, Euler angles and matrices. */
#include "test.h"

#define PI 3.14159265358979323846

/* Deterministic uniform numbers in [lo, hi). */
static unsigned rng_state = 12345u;
static double rnd(double lo, double hi)
{
	rng_state = rng_state * 1664525u + 1013904223u;
	return lo + (hi - lo) * (double)(rng_state >> 8) / (double)(1u << 24);
}

static mlod_quat rnd_quat(void)
{
	mlod_v3 axis = { (float)rnd(-1, 1), (float)rnd(-1, 1), (float)rnd(-1, 1) };
	return mlod_quat_axis_angle(axis, (float)rnd(-PI, PI));
}

static double mat_diff(const mlod_mat4 *a, const mlod_mat4 *b)
{
	double d = 0.0;
	for (int i = 0; i < 16; i++)
		d = fmax(d, fabs((double)a->m[i] - b->m[i]));
	return d;
}

/* The 3x3 rotation about one axis, as a mat4. */
static mlod_mat4 axis_rot(int axis, double angle)
{
	mlod_mat4 m = mlod_mat4_identity();
	int i = (axis + 1) % 3, j = (axis + 2) % 3;
	float c = (float)cos(angle), s = (float)sin(angle);
	m.m[i * 4 + i] = c;
	m.m[j * 4 + j] = c;
	m.m[i * 4 + j] = s;  /* column i, row j */
	m.m[j * 4 + i] = -s; /* column j, row i */
	return m;
}

static mlod_mat4 rot_mat(mlod_quat q)
{
	mlod_trs t = mlod_trs_identity();
	t.r = q;
	return mlod_mat4_from_trs(&t);
}

TEST(vectors)
{
	mlod_v3 a = { 1, 2, 3 }, b = { -4, 5, 0.5f };
	mlod_v3 c = mlod_v3_cross(a, b);
	CHECK_NEAR(mlod_v3_dot(c, a), 0, 1e-5);
	CHECK_NEAR(mlod_v3_dot(c, b), 0, 1e-5);
	CHECK_NEAR(c.x, 2 * 0.5 - 3 * 5, 1e-6);
	CHECK_NEAR(mlod_v3_dot(a, b), -4 + 10 + 1.5, 1e-6);
	CHECK_NEAR(mlod_v3_length(a), sqrt(14.0), 1e-6);
	mlod_v3 d = mlod_v3_sub(mlod_v3_add(a, b), mlod_v3_scale(b, 2));
	CHECK_NEAR(d.x, 5, 1e-6);
	CHECK_NEAR(d.y, -3, 1e-6);
	CHECK_NEAR(d.z, 2.5, 1e-6);
}

TEST(quat_rotate_matches_matrix)
{
	for (int k = 0; k < 200; k++) {
		mlod_quat q = rnd_quat();
		mlod_v3 v = { (float)rnd(-2, 2), (float)rnd(-2, 2), (float)rnd(-2, 2) };
		mlod_mat4 m = rot_mat(q);
		mlod_v3 a = mlod_quat_rotate(q, v), b = mlod_mat4_vector(&m, v);
		CHECK_NEAR(a.x, b.x, 1e-5);
		CHECK_NEAR(a.y, b.y, 1e-5);
		CHECK_NEAR(a.z, b.z, 1e-5);
	}
	/* 90 degrees about z takes x to y */
	mlod_v3 z = { 0, 0, 2 }, x = { 1, 0, 0 };
	mlod_v3 r = mlod_quat_rotate(mlod_quat_axis_angle(z, (float)(PI / 2)), x);
	CHECK_NEAR(r.x, 0, 1e-6);
	CHECK_NEAR(r.y, 1, 1e-6);
}

TEST(quat_mul_composes)
{
	for (int k = 0; k < 100; k++) {
		mlod_quat a = rnd_quat(), b = rnd_quat();
		mlod_mat4 ma = rot_mat(a), mb = rot_mat(b), mab = mlod_mat4_mul(&ma, &mb);
		mlod_mat4 m = rot_mat(mlod_quat_mul(a, b));
		CHECK(mat_diff(&m, &mab) < 1e-5);
		mlod_quat i = mlod_quat_mul(a, mlod_quat_conjugate(a));
		CHECK_NEAR(mlod_quat_angle(i, mlod_quat_identity()), 0, 1e-3);
	}
	mlod_quat zero = { 0, 0, 0, 0 };
	CHECK(mlod_quat_normalize(zero).w == 1.0f);
	mlod_v3 none = { 0, 0, 0 };
	CHECK(mlod_quat_axis_angle(none, 1.0f).w == 1.0f);
}

TEST(quat_angle_sign_invariant)
{
	mlod_v3 y = { 0, 1, 0 };
	mlod_quat a = mlod_quat_axis_angle(y, 0.3f), b = mlod_quat_axis_angle(y, 1.0f);
	mlod_quat nb = { -b.x, -b.y, -b.z, -b.w };
	CHECK_NEAR(mlod_quat_angle(a, b), 0.7, 1e-6);
	CHECK_NEAR(mlod_quat_angle(a, nb), 0.7, 1e-6);
	CHECK_NEAR(mlod_quat_angle(b, nb), 0, 1e-6);
	/* 350 degrees one way is 10 degrees the other */
	mlod_quat c = mlod_quat_axis_angle(y, (float)(350 * PI / 180));
	CHECK_NEAR(mlod_quat_angle(mlod_quat_identity(), c), 10 * PI / 180, 1e-5);
	mlod_quat d = mlod_quat_axis_angle(y, (float)PI);
	CHECK_NEAR(mlod_quat_angle(mlod_quat_identity(), d), PI, 1e-6);
	/* small angles stay accurate */
	mlod_quat e = mlod_quat_axis_angle(y, 1e-4f);
	CHECK_NEAR(mlod_quat_angle(mlod_quat_identity(), e), 1e-4, 1e-8);
}

TEST(slerp_endpoints_and_shortest_path)
{
	for (int k = 0; k < 100; k++) {
		mlod_quat a = rnd_quat(), b = rnd_quat();
		CHECK_NEAR(mlod_quat_angle(mlod_quat_slerp(a, b, 0), a), 0, 1e-3);
		CHECK_NEAR(mlod_quat_angle(mlod_quat_slerp(a, b, 1), b), 0, 1e-3);
		CHECK_NEAR(mlod_quat_angle(mlod_quat_nlerp(a, b, 0), a), 0, 1e-3);
		CHECK_NEAR(mlod_quat_angle(mlod_quat_nlerp(a, b, 1), b), 0, 1e-3);
		/* slerp moves at constant speed along the shorter arc */
		double total = mlod_quat_angle(a, b);
		mlod_quat m = mlod_quat_slerp(a, b, 0.25f);
		CHECK_NEAR(mlod_quat_angle(a, m), 0.25 * total, 1e-3);
		CHECK_NEAR(mlod_quat_angle(m, b), 0.75 * total, 1e-3);
		/* b and -b give the same path */
		mlod_quat nb = { -b.x, -b.y, -b.z, -b.w };
		CHECK_NEAR(mlod_quat_angle(mlod_quat_slerp(a, nb, 0.4f), mlod_quat_slerp(a, b, 0.4f)), 0, 1e-3);
		CHECK_NEAR(mlod_quat_angle(mlod_quat_nlerp(a, nb, 0.4f), mlod_quat_nlerp(a, b, 0.4f)), 0, 1e-3);
	}
	/* 0 to 350 degrees goes the short way through -5 degrees */
	mlod_v3 x = { 1, 0, 0 };
	mlod_quat a = mlod_quat_identity(), b = mlod_quat_axis_angle(x, (float)(350 * PI / 180));
	mlod_quat m = mlod_quat_slerp(a, b, 0.5f);
	CHECK_NEAR(mlod_quat_angle(m, mlod_quat_axis_angle(x, (float)(-5 * PI / 180))), 0, 1e-4);
}

static const char *const order_names[6] = { "XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX" };

TEST(euler_matches_matrix_products)
{
	for (int o = 0; o < 6; o++) {
		for (int k = 0; k < 50; k++) {
			float ang[3] = { (float)rnd(-PI, PI), (float)rnd(-PI, PI), (float)rnd(-PI, PI) };
			/* the product of axis rotations in the order the name lists them */
			mlod_mat4 m = mlod_mat4_identity();
			for (int n = 0; n < 3; n++) {
				int axis = order_names[o][n] - 'X';
				mlod_mat4 r = axis_rot(axis, ang[axis]);
				m = mlod_mat4_mul(&m, &r);
			}
			mlod_mat4 q = rot_mat(mlod_quat_from_euler((mlod_euler_order)o, ang));
			CHECK_MSG(mat_diff(&m, &q) < 1e-5, "order %s", order_names[o]);
		}
	}
	/* the header's example: ZXY is Rz * Rx * Ry */
	float ang[3] = { 0.3f, -0.7f, 1.1f };
	mlod_mat4 rz = axis_rot(2, 1.1), rx = axis_rot(0, 0.3), ry = axis_rot(1, -0.7);
	mlod_mat4 zx = mlod_mat4_mul(&rz, &rx), zxy = mlod_mat4_mul(&zx, &ry);
	mlod_mat4 q = rot_mat(mlod_quat_from_euler(MLOD_EULER_ZXY, ang));
	CHECK(mat_diff(&zxy, &q) < 1e-6);
}

TEST(euler_round_trip_all_orders)
{
	for (int o = 0; o < 6; o++) {
		mlod_euler_order order = (mlod_euler_order)o;
		for (int k = 0; k < 2000; k++) {
			/* the middle angle within (-pi/2, pi/2) makes the angles unique */
			const char *name = order_names[o];
			float ang[3], back[3];
			for (int i = 0; i < 3; i++)
				ang[i] = (float)rnd(-PI * 0.999, PI * 0.999);
			ang[name[1] - 'X'] = (float)rnd(-PI / 2 * 0.99, PI / 2 * 0.99);
			mlod_quat q = mlod_quat_from_euler(order, ang);
			mlod_quat_to_euler(order, q, back);
			for (int i = 0; i < 3; i++)
				CHECK_MSG(fabs(ang[i] - back[i]) < 1e-4, "%s angle %d: %g -> %g", name, i, ang[i], back[i]);
			CHECK(mlod_quat_angle(q, mlod_quat_from_euler(order, back)) < 2e-6);
			/* any rotation round trips as a rotation */
			mlod_quat r = rnd_quat();
			mlod_quat_to_euler(order, r, back);
			CHECK_MSG(mlod_quat_angle(r, mlod_quat_from_euler(order, back)) < 2e-6, "%s", name);
		}
	}
}

TEST(euler_gimbal_lock)
{
	for (int o = 0; o < 6; o++) {
		mlod_euler_order order = (mlod_euler_order)o;
		int mid = order_names[o][1] - 'X';
		for (int k = 0; k < 200; k++) {
			float ang[3] = { (float)rnd(-PI, PI), (float)rnd(-PI, PI), (float)rnd(-PI, PI) };
			/* exactly at, and from 1e-1 to 1e-8 away from, +-90 degrees on the middle axis */
			double off = (k % 4) == 0 ? 0.0 : rnd(-1, 1) * pow(10.0, -(k % 8) - 1);
			ang[mid] = (float)((k % 2 ? PI / 2 : -PI / 2) + off);
			mlod_quat q = mlod_quat_from_euler(order, ang), r;
			float back[3];
			mlod_quat_to_euler(order, q, back);
			for (int i = 0; i < 3; i++)
				CHECK(isfinite(back[i]) && fabs(back[i]) <= PI + 1e-6);
			r = mlod_quat_from_euler(order, back);
			CHECK_MSG(mlod_quat_angle(q, r) < 2e-6, "%s: %g", order_names[o], mlod_quat_angle(q, r));
		}
	}
}

/* Near gimbal lock the first angle is 0 exactly when hypot(m[1][2],
 * m[2][2]) <= 1e-7 (m: the rotation's rows, doubles from the float
 * quaternion); mlod_quat_to_euler decides most cases from the square,
 * which must agree, on both sides and close to the limit. */
TEST(euler_tilt_limit)
{
	int near_below = 0, near_above = 0, between = 0;
	for (int k = 0; k < 40000; k++) {
		/* at the lock, then each component a few floats away */
		float ang[3] = { (float)rnd(-PI, PI), (float)(PI / 2), (float)rnd(-PI, PI) };
		mlod_quat q = mlod_quat_from_euler(MLOD_EULER_XYZ, ang);
		float *c[4] = { &q.x, &q.y, &q.z, &q.w };
		for (int i = 0; i < 4; i++)
			for (int u = (int)rnd(0, 7) - 3; u != 0; u += u > 0 ? -1 : 1)
				*c[i] = nextafterf(*c[i], u > 0 ? 2.0f : -2.0f);
		/* the rows as mlod_quat_to_euler computes them (XYZ: no permutation) */
		double x = q.x, y = q.y, z = q.z, w = q.w, n = x * x + y * y + z * z + w * w, s = n > 0.0 ? 2.0 / n : 0.0;
		double m12 = s * (y * z - w * x), m22 = 1 - s * (x * x + y * y), cb = hypot(m12, m22);
		double a = atan2(-m12, m22);
		if (!(fabs(a) > 1e-3))
			continue; /* a first angle that could round to 0 by itself */
		float back[3];
		mlod_quat_to_euler(MLOD_EULER_XYZ, q, back);
		CHECK_MSG((back[0] != 0.0f) == (cb > 1e-7), "cb %.17g angle %g", cb, back[0]);
		if (cb > 0.94e-7 && cb <= 1e-7)
			near_below++;
		if (cb > 1e-7 && cb < 1.06e-7)
			near_above++;
		double cb2 = m12 * m12 + m22 * m22;
		if (cb2 > 0.99e-14 && cb2 < 1.01e-14)
			between++;
	}
	printf("# euler_tilt_limit: %d just below the limit, %d just above, %d decided by hypot\n", near_below,
	       near_above, between);
	CHECK(near_below > 0 && near_above > 0);
}

TEST(euler_order_names)
{
	for (int o = 0; o < 6; o++) {
		mlod_euler_order p;
		CHECK(strcmp(mlod_euler_order_name((mlod_euler_order)o), order_names[o]) == 0);
		CHECK(mlod_euler_order_parse(order_names[o], &p) == 0 && p == (mlod_euler_order)o);
	}
	mlod_euler_order p = MLOD_EULER_XYZ;
	CHECK(mlod_euler_order_parse("zxy", &p) == 0 && p == MLOD_EULER_ZXY);
	CHECK(mlod_euler_order_parse("XXY", &p) == -1);
	CHECK(mlod_euler_order_parse("XY", &p) == -1);
	CHECK(mlod_euler_order_parse("XYZW", &p) == -1);
	CHECK(mlod_euler_order_parse("", &p) == -1);
	CHECK(mlod_euler_order_parse(NULL, &p) == -1);
}

TEST(trs_round_trip)
{
	for (int k = 0; k < 500; k++) {
		mlod_trs t = { { (float)rnd(-5, 5), (float)rnd(-5, 5), (float)rnd(-5, 5) }, rnd_quat(),
		               { (float)rnd(0.2, 3), (float)rnd(0.2, 3), (float)rnd(0.2, 3) } };
		if (k % 5 == 0)
			t.s.x = -t.s.x; /* a mirror */
		mlod_mat4 m = mlod_mat4_from_trs(&t), m2;
		mlod_trs d;
		CHECK(mlod_mat4_to_trs(&m, &d, 1e-4f) == 0);
		m2 = mlod_mat4_from_trs(&d);
		CHECK(mat_diff(&m, &m2) < 1e-4);
		CHECK_NEAR(d.t.x, t.t.x, 1e-6);
		CHECK_NEAR(d.t.z, t.t.z, 1e-6);
		CHECK_NEAR(d.s.x, t.s.x, 1e-4);
		CHECK_NEAR(d.s.y, t.s.y, 1e-4);
		CHECK_NEAR(d.s.z, t.s.z, 1e-4);
		CHECK(mlod_quat_angle(d.r, t.r) < 1e-3);
	}
	mlod_trs id;
	mlod_mat4 i = mlod_mat4_identity();
	CHECK(mlod_mat4_to_trs(&i, &id, 1e-5f) == 0);
	CHECK(id.r.w == 1.0f && id.s.x == 1.0f && id.t.x == 0.0f);
}

TEST(trs_shear_and_singular)
{
	mlod_trs t = mlod_trs_identity(), d;
	mlod_mat4 m = mlod_mat4_identity();
	m.m[4] = 0.5f; /* x += 0.5 y: shear */
	CHECK(mlod_mat4_to_trs(&m, &d, 1e-4f) == 1);
	CHECK(isfinite(d.s.x) && isfinite(d.r.w));
	/* the closest TRS: a mild rotation about z */
	CHECK_NEAR(d.r.x, 0, 1e-6);
	CHECK_NEAR(d.r.y, 0, 1e-6);
	CHECK(mlod_quat_angle(d.r, mlod_quat_identity()) < 0.5f);

	/* a non-uniform scale under a rotation, as a child of a rotated parent, shears */
	mlod_v3 z = { 0, 0, 1 };
	mlod_trs parent = t, child = t;
	parent.s.x = 2.0f;
	child.r = mlod_quat_axis_angle(z, 0.6f);
	mlod_mat4 mp = mlod_mat4_from_trs(&parent), mc = mlod_mat4_from_trs(&child);
	mlod_mat4 pc = mlod_mat4_mul(&mp, &mc);
	CHECK(mlod_mat4_to_trs(&pc, &d, 1e-4f) == 1);
	/* ...and uniform scale does not */
	parent.s.y = parent.s.z = 2.0f;
	mp = mlod_mat4_from_trs(&parent);
	pc = mlod_mat4_mul(&mp, &mc);
	CHECK(mlod_mat4_to_trs(&pc, &d, 1e-4f) == 0);
	CHECK_NEAR(d.s.y, 2, 1e-5);

	mlod_mat4 s = mlod_mat4_identity();
	s.m[5] = 0.0f;
	CHECK(mlod_mat4_to_trs(&s, &d, 1e-4f) == -1);
	s = mlod_mat4_identity();
	s.m[4] = 1.0f; /* column y equals column x */
	s.m[5] = 0.0f;
	s.m[0] = 1.0f;
	CHECK(mlod_mat4_to_trs(&s, &d, 1e-4f) == -1);
}

TEST(invert)
{
	for (int k = 0; k < 200; k++) {
		mlod_trs t = { { (float)rnd(-5, 5), (float)rnd(-5, 5), (float)rnd(-5, 5) }, rnd_quat(),
		               { (float)rnd(0.2, 3), (float)rnd(0.2, 3), (float)rnd(0.2, 3) } };
		mlod_mat4 m = mlod_mat4_from_trs(&t), inv, p, id = mlod_mat4_identity();
		if (k % 3 == 0)
			m.m[3] = (float)rnd(-0.1, 0.1); /* projective too */
		CHECK(mlod_mat4_invert(&m, &inv) == 0);
		p = mlod_mat4_mul(&m, &inv);
		CHECK(mat_diff(&p, &id) < 1e-4);
		p = mlod_mat4_mul(&inv, &m);
		CHECK(mat_diff(&p, &id) < 1e-4);
	}
	mlod_mat4 s = mlod_mat4_identity(), inv;
	s.m[10] = 0.0f;
	CHECK(mlod_mat4_invert(&s, &inv) == -1);
}

TEST(point_vector_mul)
{
	mlod_trs t = mlod_trs_identity();
	t.t.x = 1;
	t.t.y = 2;
	t.t.z = 3;
	t.s.x = 2;
	mlod_mat4 m = mlod_mat4_from_trs(&t);
	CHECK(m.m[12] == 1.0f && m.m[13] == 2.0f && m.m[14] == 3.0f); /* column-major */
	mlod_v3 p = { 1, 1, 1 };
	mlod_v3 a = mlod_mat4_point(&m, p), b = mlod_mat4_vector(&m, p);
	CHECK_NEAR(a.x, 3, 1e-6);
	CHECK_NEAR(a.y, 3, 1e-6);
	CHECK_NEAR(b.x, 2, 1e-6);
	CHECK_NEAR(b.z, 1, 1e-6);
	/* (A*B) p = A (B p) */
	mlod_trs u = { { -1, 0.5f, 2 }, rnd_quat(), { 1, 3, 0.5f } };
	mlod_mat4 n = mlod_mat4_from_trs(&u), mn = mlod_mat4_mul(&m, &n);
	mlod_v3 r1 = mlod_mat4_point(&mn, p), nb = mlod_mat4_point(&n, p), r2 = mlod_mat4_point(&m, nb);
	CHECK_NEAR(r1.x, r2.x, 1e-5);
	CHECK_NEAR(r1.y, r2.y, 1e-5);
	CHECK_NEAR(r1.z, r2.z, 1e-5);
}

int main(void)
{
	(void)terr; /* test.h's CHECK_OK buffer, unused here */
	RUN(vectors);
	RUN(quat_rotate_matches_matrix);
	RUN(quat_mul_composes);
	RUN(quat_angle_sign_invariant);
	RUN(slerp_endpoints_and_shortest_path);
	RUN(euler_matches_matrix_products);
	RUN(euler_round_trip_all_orders);
	RUN(euler_gimbal_lock);
	RUN(euler_tilt_limit);
	RUN(euler_order_names);
	RUN(trs_round_trip);
	RUN(trs_shear_and_singular);
	RUN(invert);
	RUN(point_vector_mul);
	TEST_EXIT();
}
