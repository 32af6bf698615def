/*
 * lowerbound.c: lower bounds of an operation's posed cost (what
 * bgm_plan_op would find), from the quadrics alone: no patch, no
 * validity. The queue (collapse.c) waits on them: most queued operations
 * die with their face before they come up, so they are planned only
 * when popped, and go back with their cost when it is above the bound.
 *
 * bgm_lower_key is an operation's first key: the cost itself where the
 * collapsed vertices share their influences, else the bind pose's term
 * or, when higher, posed_min_bound's sum over poses of each pose's least
 * error near where a placement can go (SSE2: two stored poses at a time,
 * each lane the scalar arithmetic), remembered by collapsed nodes
 * (bgm_lbmemo). bgm_exact_bound is the tighter bound taken when a weak
 * key comes up: the least exact cost over every placement, with
 * bgm_plan_op's arithmetic, kept in the operation's bgm_memo.
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#ifdef __SSE2__
#include <emmintrin.h>
#endif

#include "collapse.h"

/* fmax without the library call (the same value: NaN gives the other
 * argument; the arguments here are never zeros of both signs). */
static inline double max_d(double a, double b)
{
	return a != a ? b : b != b ? a : a > b ? a : b;
}

/* posed_min_bound's term for pose p (not added when not above 0 or not
 * finite; -1 when the pose gives none). */
static inline double pose_min_bound(const mlod_bgm *g, const uint16_t *joint, int nj, const double *const qv[3], int k,
                                    size_t p, const double *bary, double rl, double inv)
{
	int J = g->joint_count;
	const float *S = g->skin + p * (size_t)J * 12;
	double z[3 * MLOD_MAX_INFLUENCES][3], c[3] = {0, 0, 0};
	for (int j = 0; j < nj; j++) {
		const float *m = S + 12 * (size_t)joint[j];
		for (int i = 0; i < 3; i++) {
			z[j][i] = (double)m[4 * i] * bary[0] + (double)m[4 * i + 1] * bary[1] + (double)m[4 * i + 2] * bary[2] +
			          (double)m[4 * i + 3];
			c[i] += z[j][i];
		}
	}
	for (int i = 0; i < 3; i++)
		c[i] *= inv;
	double spread = 0.0, far = 0.0;
	for (int j = 0; j < nj; j++) {
		double d = 0.0, a = 0.0;
		for (int i = 0; i < 3; i++) {
			d += (z[j][i] - c[i]) * (z[j][i] - c[i]);
			a += z[j][i] * z[j][i];
		}
		spread = max_d(spread, d);
		far = max_d(far, a);
	}
	double R = (sqrt(spread) + rl) * (1.0 + 1e-6) + 1e-6 * (sqrt(far) + rl);
	double q[10], q0[10], q1[10], q2[10];
	int D = g->qpose_count, sp = g->qmap[p]; /* pose p's stored pose */
	bgm_quadric_get(qv[0], D, sp, q0);
	if (k == 1) {
		memcpy(q, q0, sizeof q);
	} else if (k == 2) {
		bgm_quadric_get(qv[1], D, sp, q1);
		for (int e = 0; e < 10; e++)
			q[e] = q0[e] + q1[e];
	} else {
		bgm_quadric_get(qv[1], D, sp, q1);
		bgm_quadric_get(qv[2], D, sp, q2);
		for (int e = 0; e < 10; e++)
			q[e] = q0[e] + q1[e] + q2[e];
	}
	double tr = q[0] + q[4] + q[7];
	if (!(tr > 0.0) || !isfinite(tr))
		return -1.0;
	double mu = 1e-5 * tr, y[3];
	double a = q[0] + mu, b = q[1], cc = q[2], d = q[4] + mu, e = q[5], f = q[7] + mu;
	double det = a * (d * f - e * e) - b * (b * f - cc * e) + cc * (b * e - cc * d);
	if (!(fabs(det) > 0.0))
		return -1.0;
	double r0 = -q[3] + mu * c[0], r1 = -q[6] + mu * c[1], r2 = -q[8] + mu * c[2];
	y[0] = (r0 * (d * f - e * e) - b * (r1 * f - e * r2) + cc * (r1 * e - d * r2)) / det;
	y[1] = (a * (r1 * f - e * r2) - r0 * (b * f - cc * e) + cc * (b * r2 - r1 * cc)) / det;
	y[2] = (a * (d * r2 - r1 * e) - b * (b * r2 - r1 * cc) + r0 * (b * e - cc * d)) / det;
	/* bgm_quadric_eval(q, y), written out here (the same sum) */
	double val = q[0] * y[0] * y[0] + 2 * q[1] * y[0] * y[1] + 2 * q[2] * y[0] * y[2] + 2 * q[3] * y[0] +
	             q[4] * y[1] * y[1] + 2 * q[5] * y[1] * y[2] + 2 * q[6] * y[1] + q[7] * y[2] * y[2] + 2 * q[8] * y[2] + q[9];
	double dy = 0.0;
	val = val > 0.0 ? val : 0.0;
	for (int i = 0; i < 3; i++)
		dy += (y[i] - c[i]) * (y[i] - c[i]);
	val += mu * dy - mu * R * R;
	/* Rounding: the terms of the quadric's value at a point within R of
	 * c, far above the errors of the sums here and in bgm_plan_op(). */
	double ym = max_d(max_d(fabs(c[0]), fabs(c[1])), fabs(c[2])) + R;
	double mag = fabs(q[9]) + 2.0 * (fabs(q[3]) + fabs(q[6]) + fabs(q[8])) * ym +
	             (fabs(q[0]) + fabs(q[4]) + fabs(q[7]) + 2.0 * (fabs(q[1]) + fabs(q[2]) + fabs(q[5]))) * ym * ym;
	val -= 1e-12 * mag;
	return val;
}

#ifdef __SSE2__
/* max_d lane by lane. */
static inline __m128d max_pd2(__m128d a, __m128d b)
{
	__m128d an = _mm_cmpunord_pd(a, a), bn = _mm_cmpunord_pd(b, b), gt = _mm_cmpgt_pd(a, b);
	__m128d take_a = _mm_andnot_pd(an, _mm_or_pd(bn, gt));
	return _mm_or_pd(_mm_and_pd(take_a, a), _mm_andnot_pd(take_a, b));
}

static inline __m128d abs_pd2(__m128d x)
{
	return _mm_andnot_pd(_mm_set1_pd(-0.0), x);
}

/* pose_min_bound for poses p and p + 1 (lanes 0 and 1), every step
 * done whatever the tests: val, tr and det per pose, for the caller to
 * test as pose_min_bound does. */
BGM_INLINE __m128d pose_min_bound2(const mlod_bgm *g, const uint16_t *joint, int nj, const double *const qv[3],
                                   int k, size_t i2, const double *bary, double rl, double inv)
{
	int J = g->joint_count;
	/* g->skin2: the skin matrices as doubles, poses p and p + 1 side by side
	 * (block i2 = p / 2); qv: the k vertices' quadrics of that pair */
	const double *S = g->skin2 + i2 * (size_t)J * 24;
	const __m128d bx = _mm_set1_pd(bary[0]), by = _mm_set1_pd(bary[1]), bz = _mm_set1_pd(bary[2]);
	const __m128d zero = _mm_setzero_pd();
	/* Three rows and sums in registers; |z_j|^2 and its running maximum as
	 * the joints come (it needs no c). A square is +0 or above, or NaN, so
	 * the sums of three squares are the ones from 0 (0 + x x = x x). */
	__m128d z[3 * MLOD_MAX_INFLUENCES][3], c0 = zero, c1 = zero, c2 = zero, far = zero;
	for (int j = 0; j < nj; j++) {
		const double *m = S + 24 * (size_t)joint[j];
#define ROW(i) _mm_add_pd(_mm_add_pd(_mm_add_pd(_mm_mul_pd(_mm_load_pd(m + 8 * (i)), bx), \
                                                _mm_mul_pd(_mm_load_pd(m + 8 * (i) + 2), by)), \
                                     _mm_mul_pd(_mm_load_pd(m + 8 * (i) + 4), bz)), \
                          _mm_load_pd(m + 8 * (i) + 6))
		__m128d z0 = ROW(0), z1 = ROW(1), z2 = ROW(2);
#undef ROW
		z[j][0] = z0, z[j][1] = z1, z[j][2] = z2;
		c0 = _mm_add_pd(c0, z0), c1 = _mm_add_pd(c1, z1), c2 = _mm_add_pd(c2, z2);
		__m128d a = _mm_add_pd(_mm_add_pd(_mm_mul_pd(z0, z0), _mm_mul_pd(z1, z1)), _mm_mul_pd(z2, z2));
		/* max_d(far, a): a is +0 or above, or NaN (then far, never NaN,
		 * stays, as maxpd gives its second operand) */
		far = _mm_max_pd(a, far);
	}
	const __m128d vinv = _mm_set1_pd(inv);
	c0 = _mm_mul_pd(c0, vinv), c1 = _mm_mul_pd(c1, vinv), c2 = _mm_mul_pd(c2, vinv);
	__m128d c[3] = {c0, c1, c2};
	__m128d spread = zero;
	for (int j = 0; j < nj; j++) {
		__m128d x0 = _mm_sub_pd(z[j][0], c0), x1 = _mm_sub_pd(z[j][1], c1), x2 = _mm_sub_pd(z[j][2], c2);
		__m128d d = _mm_add_pd(_mm_add_pd(_mm_mul_pd(x0, x0), _mm_mul_pd(x1, x1)), _mm_mul_pd(x2, x2));
		/* max_d(spread, d), as far above */
		spread = _mm_max_pd(d, spread);
	}
	const __m128d vrl = _mm_set1_pd(rl);
	__m128d R = _mm_add_pd(_mm_mul_pd(_mm_add_pd(_mm_sqrt_pd(spread), vrl), _mm_set1_pd(1.0 + 1e-6)),
	                       _mm_mul_pd(_mm_set1_pd(1e-6), _mm_add_pd(_mm_sqrt_pd(far), vrl)));
	__m128d q[10];
	/* poses p and p + 1 side by side (bgm_qat): entry e at 2 e */
	const double *a0 = qv[0];
	if (k == 1) {
		for (int e = 0; e < 10; e++)
			q[e] = _mm_load_pd(a0 + 2 * e);
	} else if (k == 2) {
		const double *a1 = qv[1];
#define Q2(e) q[e] = _mm_add_pd(_mm_load_pd(a0 + 2 * (e)), _mm_load_pd(a1 + 2 * (e)))
		Q2(0), Q2(1), Q2(2), Q2(3), Q2(4), Q2(5), Q2(6), Q2(7), Q2(8), Q2(9);
#undef Q2
	} else {
		const double *a1 = qv[1], *a2 = qv[2];
#define Q3(e) q[e] = _mm_add_pd(_mm_add_pd(_mm_load_pd(a0 + 2 * (e)), _mm_load_pd(a1 + 2 * (e))), _mm_load_pd(a2 + 2 * (e)))
		Q3(0), Q3(1), Q3(2), Q3(3), Q3(4), Q3(5), Q3(6), Q3(7), Q3(8), Q3(9);
#undef Q3
	}
	__m128d tr = _mm_add_pd(_mm_add_pd(q[0], q[4]), q[7]);
	__m128d mu = _mm_mul_pd(_mm_set1_pd(1e-5), tr);
	__m128d a = _mm_add_pd(q[0], mu), b = q[1], cc = q[2], d = _mm_add_pd(q[4], mu), e = q[5], f = _mm_add_pd(q[7], mu);
	__m128d A1 = _mm_sub_pd(_mm_mul_pd(d, f), _mm_mul_pd(e, e));
	__m128d B1 = _mm_sub_pd(_mm_mul_pd(b, f), _mm_mul_pd(cc, e));
	__m128d C1 = _mm_sub_pd(_mm_mul_pd(b, e), _mm_mul_pd(cc, d));
	__m128d det = _mm_add_pd(_mm_sub_pd(_mm_mul_pd(a, A1), _mm_mul_pd(b, B1)), _mm_mul_pd(cc, C1));
	const __m128d neg = _mm_set1_pd(-0.0);
	__m128d r0 = _mm_add_pd(_mm_xor_pd(q[3], neg), _mm_mul_pd(mu, c[0]));
	__m128d r1 = _mm_add_pd(_mm_xor_pd(q[6], neg), _mm_mul_pd(mu, c[1]));
	__m128d r2 = _mm_add_pd(_mm_xor_pd(q[8], neg), _mm_mul_pd(mu, c[2]));
	__m128d F1 = _mm_sub_pd(_mm_mul_pd(r1, f), _mm_mul_pd(e, r2));  /* r1 f - e r2 */
	__m128d y[3];
	y[0] = _mm_div_pd(_mm_add_pd(_mm_sub_pd(_mm_mul_pd(r0, A1), _mm_mul_pd(b, F1)),
	                             _mm_mul_pd(cc, _mm_sub_pd(_mm_mul_pd(r1, e), _mm_mul_pd(d, r2)))),
	                  det);
	y[1] = _mm_div_pd(_mm_add_pd(_mm_sub_pd(_mm_mul_pd(a, F1), _mm_mul_pd(r0, B1)),
	                             _mm_mul_pd(cc, _mm_sub_pd(_mm_mul_pd(b, r2), _mm_mul_pd(r1, cc)))),
	                  det);
	y[2] = _mm_div_pd(_mm_add_pd(_mm_sub_pd(_mm_mul_pd(a, _mm_sub_pd(_mm_mul_pd(d, r2), _mm_mul_pd(r1, e))),
	                                        _mm_mul_pd(b, _mm_sub_pd(_mm_mul_pd(b, r2), _mm_mul_pd(r1, cc)))),
	                             _mm_mul_pd(r0, C1)),
	                  det);
	const __m128d two = _mm_set1_pd(2.0);
	__m128d val = _mm_mul_pd(_mm_mul_pd(q[0], y[0]), y[0]);
	val = _mm_add_pd(val, _mm_mul_pd(_mm_mul_pd(_mm_mul_pd(two, q[1]), y[0]), y[1]));
	val = _mm_add_pd(val, _mm_mul_pd(_mm_mul_pd(_mm_mul_pd(two, q[2]), y[0]), y[2]));
	val = _mm_add_pd(val, _mm_mul_pd(_mm_mul_pd(two, q[3]), y[0]));
	val = _mm_add_pd(val, _mm_mul_pd(_mm_mul_pd(q[4], y[1]), y[1]));
	val = _mm_add_pd(val, _mm_mul_pd(_mm_mul_pd(_mm_mul_pd(two, q[5]), y[1]), y[2]));
	val = _mm_add_pd(val, _mm_mul_pd(_mm_mul_pd(two, q[6]), y[1]));
	val = _mm_add_pd(val, _mm_mul_pd(_mm_mul_pd(q[7], y[2]), y[2]));
	val = _mm_add_pd(val, _mm_mul_pd(_mm_mul_pd(two, q[8]), y[2]));
	val = _mm_add_pd(val, q[9]);
	val = _mm_and_pd(_mm_cmpgt_pd(val, zero), val);
	__m128d dy = zero;
	for (int i = 0; i < 3; i++) {
		__m128d x = _mm_sub_pd(y[i], c[i]);
		dy = _mm_add_pd(dy, _mm_mul_pd(x, x));
	}
	val = _mm_add_pd(val, _mm_sub_pd(_mm_mul_pd(mu, dy), _mm_mul_pd(_mm_mul_pd(mu, R), R)));
	__m128d ym = _mm_add_pd(max_pd2(max_pd2(abs_pd2(c[0]), abs_pd2(c[1])), abs_pd2(c[2])), R);
	__m128d lin = _mm_add_pd(_mm_add_pd(abs_pd2(q[3]), abs_pd2(q[6])), abs_pd2(q[8]));
	__m128d sq = _mm_add_pd(_mm_add_pd(_mm_add_pd(abs_pd2(q[0]), abs_pd2(q[4])), abs_pd2(q[7])),
	                        _mm_mul_pd(two, _mm_add_pd(_mm_add_pd(abs_pd2(q[1]), abs_pd2(q[2])), abs_pd2(q[5]))));
	__m128d mag = _mm_add_pd(_mm_add_pd(abs_pd2(q[9]), _mm_mul_pd(_mm_mul_pd(two, lin), ym)), _mm_mul_pd(_mm_mul_pd(sq, ym), ym));
	val = _mm_sub_pd(val, _mm_mul_pd(_mm_set1_pd(1e-12), mag));
	/* The caller's tests (tr > 0 and finite, |det| > 0, val > 0 and
	 * finite) lane by lane: a lane that fails them gives +0. */
	const __m128d inf = _mm_set1_pd(HUGE_VAL);
	__m128d ok = _mm_and_pd(_mm_cmpgt_pd(tr, zero), _mm_cmplt_pd(tr, inf));
	ok = _mm_and_pd(ok, _mm_cmpgt_pd(abs_pd2(det), zero));
	ok = _mm_and_pd(ok, _mm_and_pd(_mm_cmpgt_pd(val, zero), _mm_cmplt_pd(val, inf)));
	return _mm_and_pd(ok, val);
}
#endif

/* A lower bound of the summed posed error (not normalised) of any
 * placement x within r of bary skinned with any convex combination of
 * the influences of the k vertices v: the bound for operations whose
 * vertices' influences differ. Per pose p, the posed location y = sum_j
 * w_j (L_j x + t_j) lies within R_p of c_p, the mean of the points z_j =
 * L_j bary + t_j over the joints j of the vertices (R_p = max_j |z_j -
 * c_p| + r max |L|, L any skin matrix's linear part, the Frobenius norm
 * bounding the spectral one).
 * The pose's summed quadric f satisfies, for every y, f(y) >= f(y_mu) +
 * mu |y_mu - c_p|^2 - mu |y - c_p|^2, y_mu the minimiser of f + mu |. -
 * c_p|^2 (a regularised solve, sound where f is singular), so f(y) >=
 * f(y_mu) + mu |y_mu - c_p|^2 - mu R_p^2: near each pose's own least
 * error, far above the bind pose's term alone. Slack covers the rounding
 * of the exact sum (float weights, cancellation in the quadric's value).
 * Returns -1 when it does not apply. */
static double posed_min_bound(mlod_bgm *g, const int *v, int k, const double *bary, double r)
{
	int J = g->joint_count, nj = 0;
	uint16_t joint[3 * MLOD_MAX_INFLUENCES];
	if (J <= 0)
		return -1.0;
	for (int i = 0; i < k; i++) {
		const mlod_influences *in = &g->inf[v[i]];
		if (in->count <= 0)
			return -1.0;
		for (int a = 0; a < in->count && a < MLOD_MAX_INFLUENCES; a++) {
			int s = 0;
			while (s < nj && joint[s] != in->joints[a])
				s++;
			if (s == nj)
				joint[nj++] = in->joints[a];
		}
	}
	size_t P = (size_t)g->pose_count;
	if (!(g->skin_norm > 0.0)) {
		/* The largest Frobenius norm of a skin matrix's linear part. */
		for (size_t m = 0; m < P * (size_t)J; m++) {
			double l = 0.0;
			for (int i = 0; i < 3; i++)
				for (int e = 0; e < 3; e++)
					l += (double)g->skin[12 * m + 4 * (size_t)i + (size_t)e] * g->skin[12 * m + 4 * (size_t)i + (size_t)e];
			g->skin_norm = max_d(g->skin_norm, sqrt(l));
		}
	}
	size_t D = (size_t)g->qpose_count;
	const double *qv[3];
	for (int i = 0; i < k; i++)
		qv[i] = g->quadric + (size_t)g->qslot[v[i]] * D * 10;
	double lb = 0.0, rl = r * g->skin_norm, inv = 1.0 / nj;
	size_t p = 0;
#ifdef __SSE2__
	/* Two stored poses at a time, 2i in the low lane and 2i + 1 in the
	 * high one: every lane the same products, sums and tests, in the same
	 * order, as pose_min_bound's (SSE2 rounds as scalar code), and the
	 * poses' terms added in pose order. */
	if (g->skin2) {
		/* A last odd stored pose the same way, in both lanes (its own
		 * g->skin2 block, the vertices' entries doubled in last), the low
		 * lane taken. */
		size_t pairs = D / 2, n = (D + 1) / 2;
		_Alignas(16) double last[3][20];
		const double *ql[3];
		if (D & 1)
			for (int i = 0; i < k; i++) {
				for (int e = 0; e < 10; e++)
					last[i][2 * e] = last[i][2 * e + 1] = qv[i][20 * pairs + (size_t)e];
				ql[i] = last[i];
			}
		/* A pose that fails the tests gives +0, which leaves lb (from +0,
		 * never -0) as it was. With every pose stored, in order, the
		 * terms go to lb as they come; else pose p's term is its stored
		 * pose's: every stored pair's terms first (each stored pose is
		 * some pose's), then the sum in pose order (beyond PMB_MAX stored
		 * poses, one pose at a time below). */
		enum { PMB_MAX = 128 };
		double t[PMB_MAX];
		int all = D == P;
		if (all || 2 * n <= PMB_MAX) {
			for (size_t i2 = 0; i2 < n; i2++) {
				double val[2];
				const double *qp[3];
				for (int i = 0; i < k; i++)
					qp[i] = i2 < pairs ? qv[i] + 20 * i2 : ql[i];
				_mm_storeu_pd(all ? val : t + 2 * i2, pose_min_bound2(g, joint, nj, qp, k, i2, bary, rl, inv));
				if (all) {
					lb += val[0];
					if (i2 < pairs)
						lb += val[1];
				}
			}
			if (!all)
				for (size_t q = 0; q < P; q++)
					lb += t[g->qmap[q]];
			p = P;
		}
	}
#endif
	for (; p < P; p++) {
		double val = pose_min_bound(g, joint, nj, qv, k, p, bary, rl, inv);
		if (val > 0.0 && isfinite(val))
			lb += val;
	}
	return lb;
}

/* A weak key's bound before its normalising and tie-break, by the
 * collapsed nodes in their order (c = -1 for an edge). */
struct bgm_lbmemo {
	int a, b, c; /* a = -1: empty */
	double lb;
};

static unsigned lbmemo_hash(int a, int b, int c)
{
	unsigned h = (unsigned)a * 0x9E3779B1u;
	h = (h ^ (h >> 15)) + (unsigned)b * 0x85EBCA77u;
	h = (h ^ (h >> 13)) + (unsigned)c * 0xC2B2AE3Du;
	return h ^ (h >> 16);
}

/* The slot of (a, b, c): its entry, or the empty slot where it goes. */
BGM_INLINE struct bgm_lbmemo *lbmemo_slot(struct bgm_lbmemo *t, int cap, int a, int b, int c)
{
	unsigned m = (unsigned)cap - 1u, i = lbmemo_hash(a, b, c) & m;
	while (t[i].a >= 0 && !(t[i].a == a && t[i].b == b && t[i].c == c))
		i = (i + 1u) & m;
	return &t[i];
}

/* Remembers lb for (a, b, c) (nothing when out of memory: it is worked
 * out again next time). */
static void lbmemo_put(mlod_bgm *g, int a, int b, int c, double lb)
{
	if (2 * (g->lbmemo_count + 1) > g->lbmemo_cap) {
		int cap = g->lbmemo_cap > 0 ? 2 * g->lbmemo_cap : 1024;
		struct bgm_lbmemo *t = malloc(sizeof *t * (size_t)cap);
		if (!t)
			return;
		for (int i = 0; i < cap; i++)
			t[i].a = -1;
		for (int i = 0; i < g->lbmemo_cap; i++)
			if (g->lbmemo[i].a >= 0)
				*lbmemo_slot(t, cap, g->lbmemo[i].a, g->lbmemo[i].b, g->lbmemo[i].c) = g->lbmemo[i];
		free(g->lbmemo);
		g->lbmemo = t;
		g->lbmemo_cap = cap;
	}
	struct bgm_lbmemo *e = lbmemo_slot(g->lbmemo, g->lbmemo_cap, a, b, c);
	if (e->a < 0)
		g->lbmemo_count++;
	e->a = a, e->b = b, e->c = c, e->lb = lb;
}

/* A lower bound of the cost bgm_plan_op() finds for operation op on face f,
 * from the quadrics alone (no patch, no validity): the least over every
 * placement bgm_plan_op() may try, valid or not, plus bgm_plan_op()'s compactness
 * tie-break (of t, or of the edge's faces). Most queued operations die
 * with their face before they come up, so they are planned only when
 * popped, and go back with their cost when it is above the bound.
 *
 * The exact posed cost skins each placement with its own (Power
 * Skinning) influences. When the collapsed vertices share theirs, every
 * placement has them too, and the exact cost is the sum of the vertices'
 * posed quadrics pulled back into bind space (bgm_quadric_rest), the
 * bound being then the cost itself when the cheapest placement is valid.
 * Otherwise the bound is the bind pose's term alone, which no influence
 * changes (one skin matrix for every influence: quadric.c),
 * the other poses' terms not being negative; the optimal placement,
 * unknown here, lies within sqrt(lmax) of the barycenter (bgm_plan_op() drops
 * it beyond), where the convex quadric is at least its tangent plane at
 * the barycenter; or, when higher, posed_min_bound's sum over poses of
 * each pose's least error near where any of these placements can go,
 * whatever its weights. The fast cost (mlod_bgm_options.fast_cost) is the
 * pulled-back sum for every operation. */
double bgm_lower_key(mlod_bgm *g, int f, int op, int *weak)
{
	const bgm_face *F = &g->faces[f];
	int K = op == OP_TRIANGLE ? 3 : 2, v[3];
	double Q[10] = {0}, wsum = 0.0, bary[3] = {0, 0, 0}, x[3];
	const double *P[3];
	int same = 1;
	for (int j = 0; j < K; j++) {
		v[j] = F->n[op == OP_TRIANGLE ? j : (op + j) % 3];
		P[j] = g->nodes[v[j]].p;
		for (int i = 0; i < 3; i++)
			bary[i] += P[j][i] / K;
		wsum += g->rquad[(size_t)g->qslot[v[j]] * BGM_RQUAD + 10];
		if (j > 0 && same)
			same = bgm_same_influences(&g->inf[v[0]], &g->inf[v[j]]);
	}
	double tie = bgm_collapse_tie(g, f, op, K);
	double lb, margin = 1.0;
	struct bgm_lbmemo *hit;
	if (same || g->opt.fast_cost) {
		for (int j = 0; j < K; j++) {
			const double *r = bgm_quadric_rest(g, v[j]);
#ifdef __SSE2__
			/* two entries at a time, each the same sum */
			_mm_storeu_pd(Q, _mm_add_pd(_mm_loadu_pd(Q), _mm_loadu_pd(r)));
			_mm_storeu_pd(Q + 2, _mm_add_pd(_mm_loadu_pd(Q + 2), _mm_loadu_pd(r + 2)));
			_mm_storeu_pd(Q + 4, _mm_add_pd(_mm_loadu_pd(Q + 4), _mm_loadu_pd(r + 4)));
			_mm_storeu_pd(Q + 6, _mm_add_pd(_mm_loadu_pd(Q + 6), _mm_loadu_pd(r + 6)));
			_mm_storeu_pd(Q + 8, _mm_add_pd(_mm_loadu_pd(Q + 8), _mm_loadu_pd(r + 8)));
#else
			for (int k = 0; k < 10; k++)
				Q[k] += r[k];
#endif
		}
		lb = bgm_quadric_eval(Q, bary);
		for (int j = 0; j < K; j++)
			lb = fmin(lb, bgm_quadric_eval(Q, P[j]));
		if (bgm_optimal_like(g) && bgm_quadric_solve(Q, bary, x) == 0)
			lb = fmin(lb, bgm_quadric_eval(Q, x));
	} else if (g->lbmemo_cap > 0 &&
	           (hit = lbmemo_slot(g->lbmemo, g->lbmemo_cap, v[0], v[1], K == 3 ? v[2] : -1))->a >= 0) {
		/* Worked out before for these nodes: the bound depends on nothing
		 * else (their bind positions, quadrics and influences, and the
		 * skin matrices, none of which changes). */
		lb = hit->lb;
		margin = 1.0 - 1e-9;
		*weak = 1;
	} else {
		/* the bind pose's entries: bgm_qat(P, 0, k) = st k */
		size_t st = bgm_qat(g->qpose_count, 0, 1);
		for (int j = 0; j < K; j++) {
			const double *q = g->quadric + (size_t)g->qslot[v[j]] * (size_t)g->qpose_count * 10;
			Q[0] += q[0], Q[1] += q[st], Q[2] += q[2 * st], Q[3] += q[3 * st], Q[4] += q[4 * st];
			Q[5] += q[5 * st], Q[6] += q[6 * st], Q[7] += q[7 * st], Q[8] += q[8 * st], Q[9] += q[9 * st];
		}
		/* Pose 0 takes every bind position x to A x + t, one matrix
		 * (g->pose0) whatever the influences: its term is Q(A x + t), whose
		 * gradient in bind space is A^T times Q's there. */
		double yb[3], yp[3][3];
		const double *xb = bary, *xp[3] = {P[0], P[1], K == 3 ? P[2] : NULL};
		if (g->pose0_mapped) {
			const double *A = g->pose0;
			for (int i = 0; i < 3; i++)
				yb[i] = A[4 * i] * bary[0] + A[4 * i + 1] * bary[1] + A[4 * i + 2] * bary[2] + A[4 * i + 3];
			for (int j = 0; j < K; j++) {
				for (int i = 0; i < 3; i++)
					yp[j][i] = A[4 * i] * P[j][0] + A[4 * i + 1] * P[j][1] + A[4 * i + 2] * P[j][2] + A[4 * i + 3];
				xp[j] = yp[j];
			}
			xb = yb;
		}
		lb = bgm_quadric_eval(Q, xb);
		for (int j = 0; j < K; j++)
			lb = fmin(lb, bgm_quadric_eval(Q, xp[j]));
		if (bgm_optimal_like(g)) {
			double lmax = 0.0, gr[3], gl = 0.0;
			for (int e = 0; e < (K == 3 ? 3 : 1); e++) {
				double l = 0.0;
				for (int i = 0; i < 3; i++)
					l += (P[e][i] - P[(e + 1) % K][i]) * (P[e][i] - P[(e + 1) % K][i]);
				lmax = fmax(lmax, l);
			}
			gr[0] = Q[0] * xb[0] + Q[1] * xb[1] + Q[2] * xb[2] + Q[3];
			gr[1] = Q[1] * xb[0] + Q[4] * xb[1] + Q[5] * xb[2] + Q[6];
			gr[2] = Q[2] * xb[0] + Q[5] * xb[1] + Q[7] * xb[2] + Q[8];
			if (g->pose0_mapped) {
				const double *A = g->pose0;
				double w[3] = {gr[0], gr[1], gr[2]};
				for (int i = 0; i < 3; i++)
					gr[i] = A[i] * w[0] + A[4 + i] * w[1] + A[8 + i] * w[2];
			}
			for (int i = 0; i < 3; i++)
				gl += gr[i] * gr[i];
			double t = bgm_quadric_eval(Q, xb) - 2.0 * sqrt(gl) * sqrt(lmax) * (1.0 + 1e-9);
			lb = fmin(lb, t > 0.0 ? t : 0.0);
			lb = fmax(lb, posed_min_bound(g, v, K, bary, sqrt(lmax)));
		} else {
			/* Barycenter and vertices: within the longest edge too. */
			double lmax = 0.0;
			for (int e = 0; e < (K == 3 ? 3 : 1); e++) {
				double l = 0.0;
				for (int i = 0; i < 3; i++)
					l += (P[e][i] - P[(e + 1) % K][i]) * (P[e][i] - P[(e + 1) % K][i]);
				lmax = fmax(lmax, l);
			}
			lb = fmax(lb, posed_min_bound(g, v, K, bary, sqrt(lmax)));
		}
		lbmemo_put(g, v[0], v[1], K == 3 ? v[2] : -1, lb);
		margin = 1.0 - 1e-9; /* rounding: stay below the exact sum */
		*weak = 1;
	}
	double key = (wsum > 0.0 ? lb / wsum : 0.0) * margin + TIE_WEIGHT * tie;
	if (!*weak) {
		/* Along a border as the flags stand: bgm_plan_op()'s factor
		 * (bgm_exact_bound takes it for the others). */
		int nb = 0;
		for (int j = 0; j < K; j++)
			nb += (g->nodes[v[j]].flags & BGM_BORDER) != 0;
		if (nb >= 2)
			key *= bgm_border_factor(g);
	}
	return key;
}

/* A lower bound of bgm_plan_op()'s exact cost for operation op on face f that
 * is tighter than bgm_lower_key's bind-pose bound: the least exact cost over
 * every placement bgm_plan_op() may try, valid or not, with the arithmetic of
 * bgm_plan_op(), so that it is the planned cost when that placement is valid.
 * It skips the patch: operations whose bound rises above the queue's
 * head go back without being planned, and most die before they return. */
double bgm_exact_bound(mlod_bgm *g, int f, int op, bgm_memo *mm)
{
	const bgm_face *F = &g->faces[f];
	bgm_plan pv; /* only k and v[] are used */
	int K = pv.k = op == OP_TRIANGLE ? 3 : 2;
	double bary[3] = {0, 0, 0}, cand[MAX_CANDIDATES][3], wsum = 0.0, *Q = g->qsum;
	const double *P[3];
	mlod_v3 V[3];
	mlod_influences in3[3];
	int nc = 0;
	for (int j = 0; j < K; j++) {
		pv.v[j] = F->n[op == OP_TRIANGLE ? j : (op + j) % 3];
		P[j] = g->nodes[pv.v[j]].p;
	}
	for (int i = 0; i < 3; i++)
		for (int j = 0; j < K; j++)
			bary[i] += P[j][i] / K;
	for (int j = 0; j < K; j++) {
		V[j] = (mlod_v3){(float)P[j][0], (float)P[j][1], (float)P[j][2]};
		in3[j] = g->inf[pv.v[j]];
	}
	int q_ready = 0, role[MAX_CANDIDATES];
	if (mm->known & MEMO_WSUM) {
		wsum = mm->wsum;
	} else {
		bgm_sum_quadrics(g, &pv, Q);
		q_ready = 1;
		for (int p = 0; p < g->pose_count; p++)
			wsum += Q[bgm_qat(g->qpose_count, g->qmap[p], 0)] + Q[bgm_qat(g->qpose_count, g->qmap[p], 4)] +
			        Q[bgm_qat(g->qpose_count, g->qmap[p], 7)];
		mm->wsum = wsum;
		mm->known |= MEMO_WSUM;
	}
	if (bgm_optimal_like(g)) {
		mlod_influences w;
		double opt[3];
		if (!mm->opt_state) {
			if (!q_ready)
				bgm_sum_quadrics(g, &pv, Q), q_ready = 1;
			bgm_skin_role(mm, 4, V, in3, K, bary, &w);
			mm->opt_state = bgm_quadric_optimum(g, Q, &w, bary, mm->opt) == 0 ? 1 : 2;
		}
		memcpy(opt, mm->opt, sizeof opt);
		if (mm->opt_state == 1) {
			if (bgm_near_collapsed(P, K, bary, opt)) {
				role[nc] = 0;
				memcpy(cand[nc++], opt, sizeof cand[0]);
			}
		}
	}
	for (int j = 0; j < K; j++) {
		role[nc] = 1 + j;
		memcpy(cand[nc++], P[j], sizeof cand[0]);
	}
	int vertex = g->opt.placement == MLOD_PLACE_VERTEX;
	if (!vertex) {
		role[nc] = 4;
		memcpy(cand[nc++], bary, sizeof cand[0]);
	}
	if (g->opt.placement == MLOD_PLACE_HYBRID && g->opt.cost == MLOD_COST_POSED)
		for (int j = 0; j < K; j++) { /* kept whole */
			role[nc] = 5 + j;
			memcpy(cand[nc++], P[j], sizeof cand[0]);
		}
	/* The least sum so far (the least stays the least divided by wsum): a
	 * candidate's sum stops once it reaches it, its terms being positive,
	 * and is then neither the least nor memoised (bgm_plan_op() sums it
	 * when it needs it). */
	double best = HUGE_VAL, least = HUGE_VAL;
	for (int k = 0; k < nc; k++) {
		mlod_influences w;
		if (vertex)
			w = in3[role[k] - 1]; /* as bgm_plan_op() skins it */
		else if (role[k] >= 5)
			w = in3[role[k] - 5];
		else
			bgm_skin_role(mm, role[k], V, in3, K, cand[k], &w);
		if (g->joint_count > 0 && w.count == 0)
			continue;
		double e, reached;
		if (mm->known >> role[k] & 1u) {
			e = mm->e[role[k]];
		} else {
			if (!q_ready)
				bgm_sum_quadrics(g, &pv, Q), q_ready = 1;
			e = bgm_quadric_error_reach(g, Q, &w, cand[k], least, &reached);
			if (e == HUGE_VAL && least < HUGE_VAL) {
				/* at least the least: the minimum stays;
				 * bgm_plan_op() may skip it (plan_stop) */
				mm->ge[role[k]] = reached;
				mm->stopped |= 1u << role[k];
				continue;
			}
			mm->e[role[k]] = e;
			mm->known |= 1u << role[k];
		}
		/* As bgm_plan_op(): a free end with the vertex's own
		 * influences costs what the vertex kept whole costs. */
		if (!vertex && role[k] >= 1 && role[k] <= 3 && g->opt.placement == MLOD_PLACE_HYBRID &&
		    bgm_same_influences(&w, &in3[role[k] - 1])) {
			mm->e[role[k] + 4] = e;
			mm->known |= 1u << (role[k] + 4);
		}
		least = fmin(least, e);
		best = fmin(best, wsum > 0.0 ? e / wsum : 0.0);
	}
	if (best == HUGE_VAL)
		best = 0.0;
	double tie = bgm_collapse_tie(g, f, op, K);
	/* Along a border (two border vertices as the flags stand),
	 * bgm_plan_op()'s cost is bgm_border_factor() times this: so is the
	 * bound, and such an operation goes back at it without being planned
	 * first. */
	int nb = 0;
	for (int j = 0; j < K; j++)
		nb += (g->nodes[pv.v[j]].flags & BGM_BORDER) != 0;
	if (nb >= 2)
		return (best + TIE_WEIGHT * tie) * bgm_border_factor(g);
	return best + TIE_WEIGHT * tie;
}
