/*
 * rt_eval.c: motion sampling (the bake side's mlod_clip_sample semantics),
 * the pose of a skeleton level folded at run time, the palette and the
 * skinning of a mesh level into the caller's buffers (mlod_rt.h,
 * "Evaluation").
 */
#include <float.h>
#include <math.h>
#include <string.h>

#include "rt_internal.h"

/* ---------------------------------------------------------------- */
/* Sampling (as lib/model/pose.c's sample_channel)                   */
/* ---------------------------------------------------------------- */

/* The key i with times[i] <= t < times[i + 1], for times[0] < t <
 * times[n - 1] and times increasing (the pack reader checks it; for views
 * unchecked, but i stays within 0 .. n - 2 whatever the times): the one
 * key a binary search finds, without its branches (a conditional move per
 * halving instead of a mispredicted jump). */
static uint32_t find_key(const float *times, uint32_t n, float t)
{
	const float *base = times;
	uint32_t len = n - 1; /* the key is in [base, base + len) */
	while (len > 1) {
		const uint32_t half = len / 2;
		base = base[half] <= t ? base + half : base;
		len -= half;
	}
	return (uint32_t)(base - times);
}

/* Where t falls in a channel's key times: on key k (clamped, or one key),
 * or between keys i and i + 1 at u. Channels sharing a key-time array
 * (the pack's, mlod(5)) share it, so pose_joints finds it once. */
typedef struct rt_key_pos {
	const float *times;
	uint32_t n;
	int32_t k; /* >= 0: on key k; -1: between i and i + 1 */
	uint32_t i;
	float u, dt;
} rt_key_pos;

static void key_pos(const float *times, uint32_t n, float t, rt_key_pos *p)
{
	p->times = times, p->n = n;
	if (n == 1 || !(t > times[0])) {
		p->k = 0;
	} else if (t >= times[n - 1]) {
		p->k = (int32_t)n - 1;
	} else {
		p->k = -1;
		p->i = find_key(times, n, t);
		const float t0 = times[p->i], t1 = times[p->i + 1];
		p->dt = t1 - t0;
		p->u = (t - t0) / p->dt;
	}
}

/* mlod_quat_normalize, inline, in doubles, but for one division: times
 * 1 / n instead of four divisions by n. The two differ by at most an ulp
 * of a double (1e-16), so the floats they round to agree but for a rare
 * last bit (a double within 1e-16 of a float's rounding boundary). */
static inline void quat_norm(const float *q, float *out)
{
	const double n = sqrt((double)q[0] * q[0] + (double)q[1] * q[1] + (double)q[2] * q[2] + (double)q[3] * q[3]);
	if (!(n > 0.0) || !isfinite(n)) {
		out[0] = out[1] = out[2] = 0.0f, out[3] = 1.0f;
		return;
	}
	const double r = 1.0 / n;
	out[0] = (float)(q[0] * r), out[1] = (float)(q[1] * r), out[2] = (float)(q[2] * r), out[3] = (float)(q[3] * r);
}

/* lib/core/math.c's quat_blend, in doubles, with quat_norm's one
 * division. */
static inline void quat_blend(const float *a, double wa, const float *b, double wb, float *out)
{
	const double x = wa * a[0] + wb * b[0], y = wa * a[1] + wb * b[1];
	const double z = wa * a[2] + wb * b[2], w = wa * a[3] + wb * b[3];
	const double n = sqrt(x * x + y * y + z * z + w * w);
	if (!(n > 0.0)) {
		out[0] = out[1] = out[2] = 0.0f, out[3] = 1.0f;
		return;
	}
	const double r = 1.0 / n;
	out[0] = (float)(x * r), out[1] = (float)(y * r), out[2] = (float)(z * r), out[3] = (float)(w * r);
}

/* The series of slerp_weights_near, shared by the scalar slerp and the
 * batches (slerp_batch) so that both evaluate the same expressions in the
 * same order (the same doubles): RT_THETA2(y) = acos(1 - y)^2, RT_SINC(v)
 * = sin(sqrt v) / sqrt v, RT_COSR(v) = cos(sqrt v). */
#define RT_THETA2(y)                                                                                    \
	((y) * (2.0                                                                                     \
	  + (y) * (0.33333333333333331                                                                  \
	    + (y) * (0.088888888888888892                                                               \
	      + (y) * (0.028571428571428571                                                             \
	        + (y) * (0.010158730158730159                                                           \
	          + (y) * (0.0038480038480038481                                                        \
	            + (y) * (0.0015222872365729509                                                      \
	              + (y) * (0.0006216006216006216                                                    \
	                + (y) * (0.00026001594629045609                                                 \
	                  + (y) * (0.00011084890341856287                                               \
	                    + (y) * (4.7986538276434138e-05 + (y) * 2.1037576563219316e-05))))))))))))
#define RT_SINC(v)                                                                                             \
	(1.0 + (v) * (-0.16666666666666666 +                                                                   \
	              (v) * (0.0083333333333333332 +                                                           \
	                     (v) * (-0.00019841269841269841 +                                                  \
	                            (v) * (2.7557319223985893e-06 +                                            \
	                                   (v) * (-2.505210838544172e-08 +                                     \
	                                          (v) * (1.6059043836821613e-10 +                              \
	                                                 (v) * (-7.6471637318198164e-13 +                      \
	                                                        (v) * 2.8114572543455206e-15))))))))
#define RT_COSR(v)                                                                                \
	(1.0                                                                                      \
	  + (v) * (-0.5                                                                           \
	    + (v) * (0.041666666666666664                                                         \
	      + (v) * (-0.0013888888888888889                                                     \
	        + (v) * (2.4801587301587302e-05                                                   \
	          + (v) * (-2.7557319223985888e-07                                                \
	            + (v) * (2.08767569878681e-09                                                 \
	              + (v) * (-1.1470745597729725e-11                                            \
	                + (v) * (4.7794773323873853e-14 + (v) * -1.5619206968586225e-16)))))))))

/* cos(t theta) and sin(t theta) / sin theta for theta = acos(d), 0.9 <= d
 * <= 1, t in [0, 1], by power series in doubles instead of acos, sin and
 * cos: with y = 1 - d (exact), x = theta^2 = 2 sum_n (2y)^n / (n^2
 * binomial(2n, n)) (as 4 asin(sqrt(y / 2))^2; 12 terms, y <= 0.1: the
 * next is below 1e-17 of x); then with S(z) = sin(sqrt z) / sqrt z and
 * C(z) = cos(sqrt z) (Taylor, 9 and 10 terms for z <= x <= 0.21),
 * sin(t theta) / sin theta = t S(t^2 x) / S(x) and cos(t theta) =
 * C(t^2 x). Against acos, sin and cos over 2e5 random d and t the weight
 * differs by at most 3e-14 of itself and the cosine by 1.2e-16, like the
 * one-sine identity below, far below a float's 6e-8. */
static inline void slerp_weights_near(double d, double t, double *ct, double *wb)
{
	const double y = 1.0 - d;
	/* Horner, written out */
	const double x = RT_THETA2(y);
	const double z = t * t * x;
	const double sx = RT_SINC(x), sz = RT_SINC(z);
	*ct = RT_COSR(z);
	*wb = t * sz / sx;
}

/* mlod_quat_slerp(a, b, t), the same doubles; unit: a and b are their own
 * normalisation (the channel's bit in ctx->chan_bits), which it then
 * skips. */
static inline void quat_slerp(const float *a, const float *b, float t, int unit, float *out)
{
	float na[4], nb[4];
	if (!unit) {
		quat_norm(a, na), quat_norm(b, nb);
		a = na, b = nb;
	}
	double d = (double)a[0] * b[0] + (double)a[1] * b[1] + (double)a[2] * b[2] + (double)a[3] * b[3];
	const double sign = d < 0.0 ? -1.0 : 1.0;
	d = fabs(d);
	if (d > 0.9995) { /* nearly parallel: the chord is the arc */
		quat_blend(a, 1.0 - t, b, sign * t, out);
		return;
	}
	/* The weights sin((1 - t) theta) / sin theta and sin(t theta) / sin
	 * theta with one sine and one cosine (of t theta) instead of three
	 * sines: sin theta = sqrt(1 - d^2) and sin((1 - t) theta) = sin theta
	 * cos(t theta) - d sin(t theta). Both are exact in reals; in double
	 * they differ from mlod_quat_slerp's by ~1e-13 of the weight (d <=
	 * 0.9995 keeps 1 - d^2 >= 1e-3), far below a float's 6e-8, so the
	 * blended floats agree but for a rare last bit. */
	double ct, wb;
	if (d >= 0.9) { /* theta <= 26 degrees, most key pairs: no acos, sin, cos */
		slerp_weights_near(d, t, &ct, &wb);
	} else {
		const double theta = acos(d), s = sqrt(1.0 - d * d);
		ct = cos(t * theta), wb = sin(t * theta) / s;
	}
	quat_blend(a, ct - d * wb, b, sign * wb, out);
}

/* ---------------------------------------------------------------- */
/* Rotation slerps in batches                                        */
/* ---------------------------------------------------------------- */

/* A far instance's pose is mostly slerps (the tubeman's coarsest motion
 * level: 27 animated rotation channels), each a chain of dependent
 * double operations (the series, two square roots and divisions) that
 * the CPU cannot overlap much one channel after the other. So the
 * LINEAR rotation channels between two keys are gathered (up to
 * RT_SLERP_BATCH, in the level's order) and slerped RT_SLERP_LANES at a
 * time, one channel per lane of double vectors: per lane quat_slerp's and
 * then quat_norm's operations, in their order, on the same doubles (IEEE
 * per lane; no fused multiply-add: -std=c11 does not contract), so the
 * same floats as one channel at a time. The rare lanes that take
 * another branch of quat_slerp (nearly parallel, or more than 26
 * degrees apart) or the identity (a zero or non-finite length) are redone
 * for that lane alone, as quat_slerp does. */
#define RT_SLERP_BATCH 8
#define RT_SLERP_LANES 8

typedef struct rt_slerp_batch {
	float a[4][RT_SLERP_BATCH], b[4][RT_SLERP_BATCH]; /* the two keys, normalised, by component */
	float t[RT_SLERP_BATCH];
	uint32_t joint[RT_SLERP_BATCH];
	uint32_t n;
} rt_slerp_batch;

#if defined(__GNUC__) && !defined(MLOD_RT_NO_VECTOR_EXT)
typedef double rt_d4 __attribute__((vector_size(8 * RT_SLERP_LANES)));
typedef float rt_f4 __attribute__((vector_size(4 * RT_SLERP_LANES)));

#if defined(__SSE2__) && !defined(MLOD_RT_NO_SSE2)
#include <emmintrin.h>
/* IEEE square roots, two lanes per instruction (as sqrt is). */
static inline void sqrt_d4(rt_d4 *v)
{
	for (int k = 0; k < RT_SLERP_LANES; k += 2) {
		__m128d h;
		memcpy(&h, (const char *)v + 8 * k, sizeof h);
		h = _mm_sqrt_pd(h);
		memcpy((char *)v + 8 * k, &h, sizeof h);
	}
}
#else
static inline void sqrt_d4(rt_d4 *v)
{
	for (int k = 0; k < RT_SLERP_LANES; k++)
		(*v)[k] = sqrt((*v)[k]);
}
#endif

static inline void ld_d4(const float *p, rt_d4 *out)
{
	rt_f4 f;
	memcpy(&f, p, sizeof f);
	*out = __builtin_convertvector(f, rt_d4);
}

/* GCC on x86-64 Linux: also built for AVX2 (VEX encoding, 4 doubles per
 * instruction; the same operations), picked at load by the CPU. 8 lanes
 * (two independent chains of 4 with AVX2, four of 2 with SSE2) ran a far
 * tubeman instance 5% faster than 4 (2.49 against 2.62 us, best of 3). */
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__) && \
	!defined(MLOD_RT_NO_CLONES)
#define RT_EVAL_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define RT_EVAL_CLONES
#endif

/* Lanes k0 .. k0 + RT_SLERP_LANES - 1 of the batch (all of them filled)
 * into local[]. */
RT_EVAL_CLONES static void slerp_lanes(const rt_slerp_batch *b, uint32_t k0, mlod_trs *local)
{
	rt_d4 a0, a1, a2, a3, b0, b1, b2, b3, t;
	ld_d4(&b->a[0][k0], &a0), ld_d4(&b->a[1][k0], &a1), ld_d4(&b->a[2][k0], &a2), ld_d4(&b->a[3][k0], &a3);
	ld_d4(&b->b[0][k0], &b0), ld_d4(&b->b[1][k0], &b1), ld_d4(&b->b[2][k0], &b2), ld_d4(&b->b[3][k0], &b3);
	ld_d4(&b->t[k0], &t);
	rt_d4 d = a0 * b0 + a1 * b1 + a2 * b2 + a3 * b3;
	rt_d4 sign;
	for (int k = 0; k < RT_SLERP_LANES; k++)
		sign[k] = d[k] < 0.0 ? -1.0 : 1.0, d[k] = fabs(d[k]);
	/* slerp_weights_near's series, every lane */
	const rt_d4 y = 1.0 - d;
	const rt_d4 x = RT_THETA2(y);
	const rt_d4 z = t * t * x;
	const rt_d4 sx = RT_SINC(x), sz = RT_SINC(z);
	const rt_d4 ct = RT_COSR(z);
	rt_d4 wb = t * sz / sx;
	rt_d4 wa = ct - d * wb;
	wb = sign * wb;
	/* quat_slerp's other branches, lane by lane */
	for (int k = 0; k < RT_SLERP_LANES; k++) {
		if (d[k] > 0.9995) {
			wa[k] = 1.0 - t[k], wb[k] = sign[k] * t[k];
		} else if (!(d[k] >= 0.9)) {
			const double theta = acos(d[k]), s = sqrt(1.0 - d[k] * d[k]);
			const double c = cos(t[k] * theta), w = sin(t[k] * theta) / s;
			wa[k] = c - d[k] * w, wb[k] = sign[k] * w;
		}
	}
	/* quat_blend */
	const rt_d4 qx = wa * a0 + wb * b0, qy = wa * a1 + wb * b1;
	const rt_d4 qz = wa * a2 + wb * b2, qw = wa * a3 + wb * b3;
	rt_d4 n = qx * qx + qy * qy + qz * qz + qw * qw;
	sqrt_d4(&n);
	const rt_d4 r = 1.0 / n;
	rt_f4 fx = __builtin_convertvector(qx * r, rt_f4), fy = __builtin_convertvector(qy * r, rt_f4);
	rt_f4 fz = __builtin_convertvector(qz * r, rt_f4), fw = __builtin_convertvector(qw * r, rt_f4);
	for (int k = 0; k < RT_SLERP_LANES; k++)
		if (!(n[k] > 0.0))
			fx[k] = fy[k] = fz[k] = 0.0f, fw[k] = 1.0f;
	/* then quat_norm, as sample_channel does */
	const rt_d4 dx = __builtin_convertvector(fx, rt_d4), dy = __builtin_convertvector(fy, rt_d4);
	const rt_d4 dz = __builtin_convertvector(fz, rt_d4), dw = __builtin_convertvector(fw, rt_d4);
	rt_d4 n2 = dx * dx + dy * dy + dz * dz + dw * dw;
	sqrt_d4(&n2);
	const rt_d4 r2 = 1.0 / n2;
	const rt_f4 ox = __builtin_convertvector(dx * r2, rt_f4), oy = __builtin_convertvector(dy * r2, rt_f4);
	const rt_f4 oz = __builtin_convertvector(dz * r2, rt_f4), ow = __builtin_convertvector(dw * r2, rt_f4);
	for (int k = 0; k < RT_SLERP_LANES; k++) {
		mlod_trs *l = &local[b->joint[k0 + (uint32_t)k]];
		if (!(n2[k] > 0.0) || !isfinite(n2[k]))
			l->r.x = l->r.y = l->r.z = 0.0f, l->r.w = 1.0f;
		else
			l->r.x = ox[k], l->r.y = oy[k], l->r.z = oz[k], l->r.w = ow[k];
	}
}
#define RT_HAVE_SLERP_LANES 1
#endif

/* Slerps the batch's channels into local[] (in its order, so a joint with
 * two rotation channels ends with the later one, as one at a time) and
 * empties it. */
static void slerp_flush(rt_slerp_batch *restrict b, mlod_trs *local)
{
	uint32_t k = 0;
#if defined(RT_HAVE_SLERP_LANES)
	/* A last partial group is filled with copies of the batch's last
	 * channel: stored after it, the same floats. */
	for (uint32_t e = b->n; e % RT_SLERP_LANES && b->n; e++) {
		for (int c = 0; c < 4; c++)
			b->a[c][e] = b->a[c][b->n - 1], b->b[c][e] = b->b[c][b->n - 1];
		b->t[e] = b->t[b->n - 1], b->joint[e] = b->joint[b->n - 1];
	}
	for (; k < b->n; k += RT_SLERP_LANES)
		slerp_lanes(b, k, local);
#else
	for (; k < b->n; k++) {
		const float qa[4] = { b->a[0][k], b->a[1][k], b->a[2][k], b->a[3][k] };
		const float qb[4] = { b->b[0][k], b->b[1][k], b->b[2][k], b->b[3][k] };
		float q[4], o[4];
		quat_slerp(qa, qb, b->t[k], 1, q);
		quat_norm(q, o);
		mlod_trs *l = &local[b->joint[k]];
		l->r.x = o[0], l->r.y = o[1], l->r.z = o[2], l->r.w = o[3];
	}
#endif
	b->n = 0;
}

/* The local matrices' 3x3 parts of joints j[0 .. 8) (from local[]) as
 * rt_trs_cols makes them, lane k of lm[c * 8 + k] entry c (m[0], m[1],
 * m[2], m[4], ..., m[10]): the same doubles per lane, in the same order,
 * so the same floats; 8 joints at a time, so that the chain of world
 * matrices after does not wait on each joint's division. */
#if defined(RT_HAVE_SLERP_LANES) && RT_SLERP_LANES == 8
RT_EVAL_CLONES static void trs_lanes(const mlod_trs *local, const uint32_t *j, float *restrict lm)
{
	rt_f4 fx, fy, fz, fw, fsx, fsy, fsz;
	for (int k = 0; k < 8; k++) {
		const mlod_trs *t = &local[j[k]];
		fx[k] = t->r.x, fy[k] = t->r.y, fz[k] = t->r.z, fw[k] = t->r.w;
		fsx[k] = t->s.x, fsy[k] = t->s.y, fsz[k] = t->s.z;
	}
	const rt_d4 x = __builtin_convertvector(fx, rt_d4), y = __builtin_convertvector(fy, rt_d4);
	const rt_d4 z = __builtin_convertvector(fz, rt_d4), w = __builtin_convertvector(fw, rt_d4);
	const rt_d4 sx = __builtin_convertvector(fsx, rt_d4), sy = __builtin_convertvector(fsy, rt_d4);
	const rt_d4 sz = __builtin_convertvector(fsz, rt_d4);
	const rt_d4 n = x * x + y * y + z * z + w * w;
	rt_d4 s = 2.0 / n;
	for (int k = 0; k < 8; k++)
		if (!(n[k] > 0.0))
			s[k] = 0.0;
	const rt_f4 m[9] = {
		__builtin_convertvector((1 - s * (y * y + z * z)) * sx, rt_f4),
		__builtin_convertvector(s * (x * y + w * z) * sx, rt_f4),
		__builtin_convertvector(s * (x * z - w * y) * sx, rt_f4),
		__builtin_convertvector(s * (x * y - w * z) * sy, rt_f4),
		__builtin_convertvector((1 - s * (x * x + z * z)) * sy, rt_f4),
		__builtin_convertvector(s * (y * z + w * x) * sy, rt_f4),
		__builtin_convertvector(s * (x * z + w * y) * sz, rt_f4),
		__builtin_convertvector(s * (y * z - w * x) * sz, rt_f4),
		__builtin_convertvector((1 - s * (x * x + y * y)) * sz, rt_f4),
	};
	memcpy(lm, m, sizeof m);
}
#else
static void trs_lanes(const mlod_trs *local, const uint32_t *j, float *restrict lm)
{
	for (int k = 0; k < 8; k++) {
		float m[16];
		rt_trs_cols(&local[j[k]], m);
		static const int at[9] = { 0, 1, 2, 4, 5, 6, 8, 9, 10 };
		for (int c = 0; c < 9; c++)
			lm[8 * c + k] = m[at[c]];
	}
}
#endif

/* Adds the LINEAR rotation channel between keys a and b at t (of joint
 * j) to the batch, the keys normalised unless unit says they are. */
static inline void slerp_push(rt_slerp_batch *b, const float *qa, const float *qb, float t, int unit, uint32_t j,
                              mlod_trs *local)
{
	if (b->n == RT_SLERP_BATCH)
		slerp_flush(b, local);
	float na[4], nb[4];
	if (!unit) {
		quat_norm(qa, na), quat_norm(qb, nb);
		qa = na, qb = nb;
	}
	const uint32_t k = b->n++;
	for (int c = 0; c < 4; c++)
		b->a[c][k] = qa[c], b->b[c][k] = qb[c];
	b->t[k] = t, b->joint[k] = j;
}

/* One channel between keys p->i and p->i + 1 (LINEAR or CUBICSPLINE), as
 * lib/model/pose.c's sample_channel followed, for rotations, by
 * sample_one's normalisation. */
static void sample_channel(const mlod_pack_channel *ch, const rt_key_pos *p, int comps, int unit, float *out)
{
	const int cubic = ch->rec.interp == 2;
	const size_t stride = cubic ? 3 * (size_t)comps : (size_t)comps;
	const float *v = ch->values;
	const float u = p->u;
	const float *a = v + (size_t)p->i * stride, *b = v + (size_t)(p->i + 1) * stride;
	if (!cubic) { /* LINEAR */
		if (comps == 4) {
			float q[4];
			quat_slerp(a, b, u, unit, q);
			quat_norm(q, out);
		} else {
			for (int c = 0; c < comps; c++)
				out[c] = a[c] + (b[c] - a[c]) * u;
		}
		return;
	}
	/* CUBICSPLINE: glTF Appendix C */
	const float dt = p->dt;
	const float u2 = u * u, u3 = u2 * u;
	const float h00 = 2 * u3 - 3 * u2 + 1, h10 = u3 - 2 * u2 + u;
	const float h01 = -2 * u3 + 3 * u2, h11 = u3 - u2;
	float q[4];
	for (int c = 0; c < comps; c++)
		q[c] = h00 * a[comps + c] + h10 * dt * a[2 * comps + c] + h01 * b[comps + c] + h11 * dt * b[c];
	if (comps == 4)
		quat_norm(q, out);
	else
		memcpy(out, q, 3 * sizeof *out);
}

/* Channel i of m into local, *p the last key position found (a key-time
 * array shared with the channel before is searched once). flags: the
 * motion unit's channel bits, nbits of them (ctx->chan_bits; NULL:
 * none). A value read from a key (one key, clamped, STEP: a constant
 * channel is stored as one key) is copied here; sample_channel
 * interpolates. */
static inline void sample_one(const mlod_pack_motion *m, uint32_t i, const uint8_t *flags, uint32_t nbits, float t,
                              rt_key_pos *p, mlod_trs *local, rt_slerp_batch *sb)
{
	const mlod_pack_channel *ch = &m->channels[i];
	const uint32_t n = ch->rec.key_count;
	if (n < 1)
		return;
	const int rot = ch->rec.path != 0 && ch->rec.path != 2;
	const int unit = rot && flags && i < nbits ? (flags[i >> 3] >> (i & 7)) & 1 : 0;
	const int comps = rot ? 4 : 3;
	const float *key;
	float v[4];
	uint32_t k = 0;
	if (n > 1) {
		if (ch->times != p->times || n != p->n)
			key_pos(ch->times, n, t, p);
		k = p->k >= 0 ? (uint32_t)p->k : p->i;
	}
	if (n == 1 || p->k >= 0 || ch->rec.interp == 1) { /* on a key, or STEP */
		const int cubic = ch->rec.interp == 2;
		key = ch->values + (size_t)k * (cubic ? 3 * (size_t)comps : (size_t)comps) + (cubic ? comps : 0);
		if (rot && !unit) {
			quat_norm(key, v);
			key = v;
		}
	} else if (rot && ch->rec.interp == 0) { /* LINEAR rotation: slerped in the batch */
		const float *a = ch->values + (size_t)p->i * 4;
		slerp_push(sb, a, a + 4, p->u, unit, ch->rec.joint, local);
		return;
	} else {
		sample_channel(ch, p, comps, unit, v);
		key = v;
	}
	mlod_trs *l = &local[ch->rec.joint];
	if (rot) /* after the batch's slerps of the same joint */
		for (uint32_t k = 0; k < sb->n; k++)
			if (sb->joint[k] == ch->rec.joint) {
				slerp_flush(sb, local);
				break;
			}
	if (rot)
		l->r.x = key[0], l->r.y = key[1], l->r.z = key[2], l->r.w = key[3];
	else if (ch->rec.path == 0)
		l->t.x = key[0], l->t.y = key[1], l->t.z = key[2];
	else
		l->s.x = key[0], l->s.y = key[1], l->s.z = key[2];
}

/* ---------------------------------------------------------------- */
/* Scratch                                                           */
/* ---------------------------------------------------------------- */

mlod_rt_scratch *mlod_rt_scratch_create(mlod_rt_ctx *ctx)
{
	if (!ctx)
		return NULL;
	const size_t J = ctx->joint_count, P = ctx->palette_size;
	size_t bytes = sizeof(mlod_rt_scratch) + J * sizeof(mlod_trs) + 16 * sizeof(float) * (J + P) + 64 + J * 5 +
	               (9 * sizeof(float) + sizeof(uint32_t)) * (J + 8) + P * sizeof(uint32_t) + 4;
	mlod_rt_scratch *s = rt_alloc(ctx, bytes);
	if (!s)
		return NULL;
	memset(s, 0, bytes);
	s->owner = ctx;
	/* one block: the floats on a 16-byte boundary */
	uintptr_t a = ((uintptr_t)(s + 1) + 15) & ~(uintptr_t)15;
	s->world = (float *)a;
	s->palette = s->world + 16 * J;
	s->lm = s->palette + 16 * P;
	s->local = (mlod_trs *)(s->lm + 9 * (J + 8));
	s->plan_posed = (uint32_t *)(s->local + J);
	s->anim_joints = s->plan_posed + J;
	s->pal_mark = s->anim_joints + J + 8;
	s->plan_need = (uint8_t *)(s->pal_mark + P);
	return s;
}

void mlod_rt_scratch_destroy(mlod_rt_ctx *ctx, mlod_rt_scratch *s)
{
	if (ctx && s)
		rt_free(ctx, s);
}

/* ---------------------------------------------------------------- */
/* Pose and palette                                                  */
/* ---------------------------------------------------------------- */

/* The level-0 or level-k posing tables of the instance's skeleton level. */
static const rt_unit *skel_unit(const mlod_rt_ctx *ctx, const mlod_rt_state *st)
{
	const rt_unit *u = rt_unit_get(ctx, MLOD_RT_SKELETON, st->level[MLOD_RT_SKELETON], 0);
	return u && u->level > 0 && u->state == RT_UNIT_RESIDENT ? u : NULL;
}

static float sample_time(const mlod_rt_ctx *ctx, const mlod_rt_state *st)
{
	const float dur = ctx->clip_duration[st->clip];
	float t = st->time;
	if ((st->flags & MLOD_RT_LOOP) && dur > 0.0f && (t >= dur || t < 0.0f)) {
		t = fmodf(t, dur);
		if (t < 0.0f)
			t += dur;
	}
	if (!(t > 0.0f))
		t = 0.0f; /* also NaN */
	if (t > dur)
		t = dur;
	return t;
}

/* Poses the npose joints posed[] (increasing: parents first; needed[]
 * flags them) of the instance: each joint's local transform (the rest
 * transform, then the motion level's channels of it) and its world
 * matrix. A joint without channels or whose channels all have one key
 * (u->fixed) takes the local matrix made at open or at the level's load,
 * the same floats; only the others' channels are sampled, in the level's
 * order (u->anim). */
static void pose_joints(const mlod_rt_ctx *ctx, mlod_rt_scratch *s, const mlod_rt_state *st, const uint32_t *posed,
                        uint32_t npose, const uint8_t *needed)
{
	const mlod_pack_joint_rec *jr = ctx->skel->joints;
	mlod_trs *local = s->local;
	float *W = s->world;
	const rt_unit *mu = NULL;
	if (ctx->clip_count) {
		mu = rt_unit_get(ctx, MLOD_RT_MOTION, st->level[MLOD_RT_MOTION], st->clip);
		if (mu && mu->state != RT_UNIT_RESIDENT)
			mu = NULL;
	}
	if (!mu) { /* the rest pose */
		for (uint32_t i = 0; i < npose; i++) {
			const uint32_t j = posed[i];
			rt_mat_mul(jr[j].parent < 0 ? jr[j].base : W + 16 * (size_t)jr[j].parent, ctx->rest_mat + 16 * (size_t)j,
			           W + 16 * (size_t)j);
		}
		return;
	}
	const mlod_pack_motion *m = mu->motion;
	const uint8_t *flags = mu->chan_flags;
	const uint32_t nbits = 8 * ctx->chan_bytes;
	const float t = sample_time(ctx, st);
	uint32_t na = 0;
	for (uint32_t i = 0; i < npose; i++)
		if (!mu->fixed[posed[i]]) {
			local[posed[i]] = ctx->rest_local[posed[i]];
			s->anim_joints[na++] = posed[i];
		}
	rt_key_pos p = { NULL, 0, 0, 0, 0.0f, 0.0f };
	rt_slerp_batch sb;
	sb.n = 0;
	for (uint32_t a = 0; a < mu->anim_count; a++) {
		const uint32_t i = mu->anim[a];
		if (needed[m->channels[i].rec.joint])
			sample_one(m, i, flags, nbits, t, &p, local, &sb);
	}
	slerp_flush(&sb, local);
	/* the animated joints' local matrices, 8 at a time (a last partial
	 * group repeats the last joint), then the chain of world matrices */
	for (uint32_t k = na; k % 8; k++)
		s->anim_joints[k] = s->anim_joints[na - 1];
	for (uint32_t k = 0; k < na; k += 8)
		trs_lanes(local, s->anim_joints + k, s->lm + 9 * (size_t)k);
	for (uint32_t i = 0, a = 0; i < npose; i++) {
		const uint32_t j = posed[i];
		const float *parent = jr[j].parent < 0 ? jr[j].base : W + 16 * (size_t)jr[j].parent;
		const uint32_t f = mu->fixed[j];
		if (f) {
			rt_mat_mul(parent, f == 1 ? ctx->rest_mat + 16 * (size_t)j : mu->static_mat + 16 * (size_t)(f - 2),
			           W + 16 * (size_t)j);
		} else {
			const float tr[3] = { local[j].t.x, local[j].t.y, local[j].t.z };
			rt_mat_mul_rs(parent, s->lm + 9 * (size_t)(a & ~7u) + (a & 7u), 8, tr, W + 16 * (size_t)j);
			a++;
		}
	}
}

mlod_result mlod_rt_pose(const mlod_rt_ctx *ctx, mlod_rt_scratch *s, uint32_t id, const float **world,
                         const uint32_t **joints, uint32_t *joint_count, mlod_error *err)
{
	if (!ctx || !s)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_rt_pose: NULL argument");
	if (s->owner != ctx)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_rt_pose: the scratch was made for another context");
	if (!rt_live(ctx, id))
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "instance %u is not alive", id);
	const mlod_rt_state *st = &ctx->inst[rt_slot(ctx, id)].st;
	const rt_unit *su = skel_unit(ctx, st);
	pose_joints(ctx, s, st, su ? su->plan.posed : ctx->all_joints, su ? su->plan.posed_count : ctx->joint_count,
	            su ? su->plan.needed : ctx->all_needed);
	s->skel_unit = su;
	s->id = id;
	s->posed = 1;
	s->paletted = 0;
	if (world)
		*world = s->world;
	if (joints)
		*joints = su ? su->plan.kept : ctx->all_joints;
	if (joint_count)
		*joint_count = su ? su->plan.kept_count : ctx->joint_count;
	return MLOD_OK;
}

/* The joint palette entry e follows under the skeleton level su (NULL:
 * level 0), and its bind matrix. */
static inline uint32_t entry_joint(const mlod_rt_ctx *ctx, const rt_unit *su, uint32_t e)
{
	return su ? su->plan.palette_joint[e] : ctx->pal_joint0[e];
}

static inline const float *entry_bind(const mlod_rt_ctx *ctx, const rt_unit *su, uint32_t e)
{
	return su ? su->plan.palette_bind + 16 * (size_t)e : ctx->pal_bind0[e];
}

/* The first entry with entry e's joint and bind (e itself when none
 * before it): its matrix is e's, bit for bit. */
static inline uint32_t entry_src(const mlod_rt_ctx *ctx, const rt_unit *su, uint32_t e)
{
	return su ? su->plan.palette_src[e] : ctx->pal_src0[e];
}

/* The skin plan of mesh level mu under skeleton level su in s: the joints
 * that its palette entries and rigid parts follow, with their ancestors
 * (removed ones too: they are folded at run time), flagged and listed in
 * increasing order. Kept while the same levels are resident (ctx->unit_gen),
 * so a crowd at the same levels builds it once. */
static void skin_plan(const mlod_rt_ctx *ctx, mlod_rt_scratch *s, const rt_unit *su, const rt_unit *mu)
{
	if (s->plan_valid && s->plan_skel == su && s->plan_mesh == mu && s->plan_gen == ctx->unit_gen)
		return;
	const uint32_t J = ctx->joint_count;
	const mlod_pack_joint_rec *jr = ctx->skel->joints;
	uint8_t *need = s->plan_need;
	memset(need, 0, J);
	for (uint32_t k = 0; k < mu->pal_used_count + mu->rigid_count; k++) {
		int32_t j;
		if (k < mu->pal_used_count)
			j = (int32_t)entry_joint(ctx, su, mu->pal_used[k]);
		else
			j = (int32_t)mu->rigid[k - mu->pal_used_count], j = su ? su->plan.stand[j] : j;
		for (; j >= 0 && !need[j]; j = jr[j].parent)
			need[j] = 1;
	}
	s->plan_count = 0;
	for (uint32_t j = 0; j < J; j++)
		if (need[j])
			s->plan_posed[s->plan_count++] = j;
	s->plan_skel = su, s->plan_mesh = mu, s->plan_gen = ctx->unit_gen, s->plan_valid = 1;
}

static void build_palette(const mlod_rt_ctx *ctx, mlod_rt_scratch *s)
{
	const rt_unit *su = s->skel_unit;
	for (uint32_t e = 0; e < ctx->palette_size; e++) {
		const uint32_t f = entry_src(ctx, su, e);
		if (f != e)
			memcpy(s->palette + 16 * (size_t)e, s->palette + 16 * (size_t)f, 16 * sizeof(float));
		else
			rt_mat_mul(s->world + 16 * (size_t)entry_joint(ctx, su, e), entry_bind(ctx, su, e),
			           s->palette + 16 * (size_t)e);
	}
	s->paletted = 1;
}

mlod_result mlod_rt_palette(const mlod_rt_ctx *ctx, mlod_rt_scratch *s, const float **palette, uint32_t *count,
                            mlod_error *err)
{
	if (!ctx || !s)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_rt_palette: NULL argument");
	if (s->owner != ctx)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_rt_palette: the scratch was made for another context");
	if (!s->posed)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_rt_palette: no pose in the scratch (call mlod_rt_pose)");
	if (s->posed == 2) { /* mlod_rt_skin posed only what its mesh level reads: the whole pose */
		mlod_result r = mlod_rt_pose(ctx, s, s->id, NULL, NULL, NULL, err);
		if (r)
			return r;
	}
	if (!s->paletted)
		build_palette(ctx, s);
	if (palette)
		*palette = s->palette;
	if (count)
		*count = ctx->palette_size;
	return MLOD_OK;
}

/* ---------------------------------------------------------------- */
/* Skinning                                                          */
/* ---------------------------------------------------------------- */

/* Morphing goes through a buffer on the stack, this many vertices at a
 * time: no allocation. A multiple of RT_SKIN_RUN, so each stretch starts
 * a run of the part's buckets. */
enum { RT_MORPH_RUN = 2 * RT_SKIN_RUN };

/* The instance's morph weights for part i of a level and the targets to
 * apply (*nt), or NULL when every weight is 0 (nothing to do). */
static const float *part_morph(const mlod_rt_ctx *ctx, uint32_t id, uint32_t i, const mlod_pack_part *p,
                               uint32_t *nt)
{
	if (i >= ctx->morph_parts || !p->targets)
		return NULL;
	uint32_t k = ctx->morph_offset[i + 1] - ctx->morph_offset[i];
	if (p->rec.target_count < k)
		k = p->rec.target_count;
	const float *w = ctx->morph_weights + (size_t)rt_slot(ctx, id) * ctx->morph_total + ctx->morph_offset[i];
	for (uint32_t t = 0; t < k; t++)
		if (w[t] != 0.0f && p->targets[t]) {
			*nt = k;
			return w;
		}
	return NULL;
}

/* Positions v0 .. v0 + n - 1 of p morphed into out: the position plus
 * each target's delta times its weight, targets in order. */
static void morph_range(const mlod_pack_part *p, const float *w, uint32_t nt, size_t v0, size_t n,
                        float *restrict out)
{
	memcpy(out, p->positions + 3 * v0, 3 * n * sizeof(float));
	for (uint32_t t = 0; t < nt; t++) {
		if (w[t] == 0.0f || !p->targets[t])
			continue;
		const float wt = w[t];
		const float *restrict d = p->targets[t] + 3 * v0;
		for (size_t k = 0; k < 3 * n; k++)
			out[k] += wt * d[k];
	}
}

/* A rigid part's normals need no renormalising when M's linear part is a
 * rotation times a scale s > 0 and its normals are unit: then M n / s is
 * M n normalised. The Gram matrix of M's columns, over s^2 = its first
 * entry, differs from the identity by at most RT_UNIT_TOL in every entry
 * (0 in the first), so its eigenvalues lie within 1 +- 3 RT_UNIT_TOL and
 * | U n | within 1 +- 2 RT_UNIT_TOL of | n |, which rt_prepare_mesh checked to
 * be within RT_UNIT_TOL of 1: U n is M n normalised to within
 * 3 RT_UNIT_TOL of its length (and float rounding), in the same
 * direction. Returns 1 and U = M / s (the first three columns) when so,
 * else 0. */
static int rigid_unit(const float *M, float *U)
{
	const double a0 = M[0], a1 = M[1], a2 = M[2], b0 = M[4], b1 = M[5], b2 = M[6], c0 = M[8], c1 = M[9],
	             c2 = M[10];
	const double s2 = a0 * a0 + a1 * a1 + a2 * a2, tol = RT_UNIT_TOL * s2;
	if (!(s2 > 1e-30 && s2 < 1e30))
		return 0;
	const double d[5] = { b0 * b0 + b1 * b1 + b2 * b2 - s2, c0 * c0 + c1 * c1 + c2 * c2 - s2,
		              a0 * b0 + a1 * b1 + a2 * b2, a0 * c0 + a1 * c1 + a2 * c2, b0 * c0 + b1 * c1 + b2 * c2 };
	int ok = 1;
	for (int k = 0; k < 5; k++)
		ok &= fabs(d[k]) <= tol;
	if (!ok)
		return 0;
	const double is = 1.0 / sqrt(s2);
	for (int k = 0; k < 12; k++)
		U[k] = (float)(M[k] * is);
	return 1;
}

/* The joint whose world matrix a rigid part (p->rec.joint >= 0) reads:
 * its own, or its stand-in's when the skeleton level su removed it. */
static inline uint32_t rigid_joint(const rt_unit *su, const mlod_pack_part *p)
{
	const uint32_t j = (uint32_t)p->rec.joint;
	return su ? (uint32_t)su->plan.stand[j] : j;
}

/* The matrix of a rigid or static part (p->rec.skin < 0): Wj, the world
 * matrix of rigid_joint (through the stand-in's rest transform to the
 * joint when su removed it), times its offset; a static part's offset
 * alone (Wj not read). mlod_rt_skin, mlod_rt_bounds and
 * mlod_rt_skin_stale (with a kept Wj) all take it from here, so a bound
 * holds the floats the skin writes. */
static void rigid_matrix(const rt_unit *su, const float *Wj, const mlod_pack_part *p, float *M)
{
	if (p->rec.joint < 0) {
		memcpy(M, p->rec.offset, 16 * sizeof(float));
		return;
	}
	const uint32_t j = (uint32_t)p->rec.joint;
	if (su && su->plan.stand[j] != (int32_t)j) {
		float t[16];
		rt_mat_mul(Wj, su->plan.rel + 16 * (size_t)j, t);
		rt_mat_mul(t, p->rec.offset, M);
	} else {
		rt_mat_mul(Wj, p->rec.offset, M);
	}
}

/* Wj for rigid_matrix in the world matrices W (W itself for a static
 * part, which does not read it). */
static inline const float *rigid_world(const rt_unit *su, const float *W, const mlod_pack_part *p)
{
	return p->rec.joint < 0 ? W : W + 16 * (size_t)rigid_joint(su, p);
}

/* The palette entries the mesh level mu reads, W[joint] times the bind
 * matrix; built for AVX2 too where the pose is (the same floats). */
#if defined(RT_EVAL_CLONES)
RT_EVAL_CLONES
#endif
static void palette_entries(const mlod_rt_ctx *ctx, mlod_rt_scratch *s, const rt_unit *su, const rt_unit *mu,
                            const float *W, float *palette)
{
	if (++s->pal_stamp == 0) {
		memset(s->pal_mark, 0, ctx->palette_size * sizeof *s->pal_mark);
		s->pal_stamp = 1;
	}
	for (uint32_t k = 0; k < mu->pal_used_count; k++) {
		const uint32_t e = mu->pal_used[k], f = entry_src(ctx, su, e);
		if (f != e && s->pal_mark[f] == s->pal_stamp)
			memcpy(palette + 16 * (size_t)e, palette + 16 * (size_t)f, 16 * sizeof(float));
		else
			rt_mat_mul(W + 16 * (size_t)entry_joint(ctx, su, e), entry_bind(ctx, su, e), palette + 16 * (size_t)e);
		s->pal_mark[e] = s->pal_stamp;
	}
}

/* What mlod_rt_skin and mlod_rt_bounds share, for a live instance id:
 * poses only what its mesh level reads (the joints its palette entries
 * and rigid parts follow, with their ancestors) into s->world, makes
 * those palette entries in s->palette, and stamps the scratch as posed
 * for id (so mlod_rt_palette then poses in full). *su and *mu: the
 * skeleton and mesh levels shown. Without a mesh, nothing is posed and
 * *mu is NULL. MLOD_ERR_INVALID_ARG when the mesh level shown is not
 * resident, MLOD_ERR_LIMIT when it has more vertices than capacity. */
static mlod_result pose_mesh_level(const mlod_rt_ctx *ctx, mlod_rt_scratch *s, uint32_t id, uint32_t capacity,
                                   const rt_unit **su, const rt_unit **mu, mlod_error *err)
{
	const mlod_rt_state *st = &ctx->inst[rt_slot(ctx, id)].st;
	*su = skel_unit(ctx, st);
	*mu = NULL;
	if (ctx->levels[MLOD_RT_MESH] > 0) {
		const rt_unit *m = rt_unit_get(ctx, MLOD_RT_MESH, st->level[MLOD_RT_MESH], 0);
		if (!m || m->state != RT_UNIT_RESIDENT)
			return mlod_fail(err, MLOD_ERR_INVALID_ARG, "instance %u shows no resident mesh level", id);
		if (m->vertex_count > capacity)
			return mlod_fail(err, MLOD_ERR_LIMIT, "mesh level %u has %u vertices, the buffers hold %u", m->level,
			                 m->vertex_count, capacity);
		*mu = m;
		/* The pose and palette entries of the call before, when they are
		 * of this instance as it still is (a cull's mlod_rt_bounds, then
		 * mlod_rt_skin): the same floats, made once. */
		if (s->posed == 2 && s->id == id && s->pose_unit_gen == ctx->unit_gen && s->skel_unit == *su && s->pose_mesh == m &&
		    s->pose_time == st->time && s->pose_clip == st->clip &&
		    s->pose_motion_level == st->level[MLOD_RT_MOTION])
			return MLOD_OK;
		skin_plan(ctx, s, *su, m);
		pose_joints(ctx, s, st, s->plan_posed, s->plan_count, s->plan_need);
	}
	s->skel_unit = *su;
	s->id = id;
	s->posed = 2;
	s->paletted = 0;
	s->pose_unit_gen = ctx->unit_gen, s->pose_mesh = *mu;
	s->pose_time = st->time, s->pose_clip = st->clip, s->pose_motion_level = st->level[MLOD_RT_MOTION];
	if (*mu)
		palette_entries(ctx, s, *su, *mu, s->world, s->palette);
	return MLOD_OK;
}

mlod_result mlod_rt_skin(const mlod_rt_ctx *ctx, mlod_rt_scratch *s, uint32_t id, float *positions,
                         size_t pos_stride, float *normals, size_t nrm_stride, uint32_t capacity,
                         uint32_t *vertex_count, mlod_error *err)
{
	if (vertex_count)
		*vertex_count = 0;
	if (!ctx || !s || !positions)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_rt_skin: NULL argument");
	if (s->owner != ctx)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_rt_skin: the scratch was made for another context");
	if (pos_stride < 12 || pos_stride % 4 || (normals && (nrm_stride < 12 || nrm_stride % 4)))
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_rt_skin: strides must be multiples of 4, at least 12");
	if (!rt_live(ctx, id))
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "instance %u is not alive", id);
	const rt_unit *su, *mu;
	mlod_result r = pose_mesh_level(ctx, s, id, capacity, &su, &mu, err);
	if (r != MLOD_OK || !mu)
		return r;
	const float *W = s->world;
	size_t base = 0;
	float morphed[3 * RT_MORPH_RUN];
	float M[16], U[12];
	int m_ok = 0, m_unit = -1;
	int32_t m_joint = -1;
	const float *m_off = NULL;
	for (uint32_t i = 0; i < mu->mesh->part_count; i++) {
		const mlod_pack_part *p = &mu->mesh->parts[i];
		const uint32_t n = p->rec.vertex_count;
		float *op = (float *)((char *)positions + base * pos_stride);
		float *on = normals ? (float *)((char *)normals + base * nrm_stride) : NULL;
		const int skinned = p->rec.skin >= 0;
		const float *pal = skinned ? s->palette + 16 * (size_t)ctx->skin_offset[p->rec.skin] : NULL;
		/* A rigid or static part's matrix, kept for the next part when it
		 * follows the same joint with the same offset (the robot's mesh
		 * levels have 15 rigid parts on 12 joints). */
		if (!skinned && !(m_ok && p->rec.joint == m_joint &&
		                  (m_off == p->rec.offset || memcmp(m_off, p->rec.offset, sizeof M) == 0))) {
			rigid_matrix(su, rigid_world(su, W, p), p, M);
			m_ok = 1, m_joint = p->rec.joint, m_off = p->rec.offset, m_unit = -1;
		}
		/* Rigid and static parts with unit normals: skip renormalising
		 * when M allows (rigid_unit, once per matrix). */
		int unit = 0;
		if (!skinned && on && p->normals && mu->skin_order_at[i]) {
			if (m_unit < 0)
				m_unit = rigid_unit(M, U);
			unit = m_unit;
		}
		uint32_t nt = 0;
		const float *mw = part_morph(ctx, id, i, p, &nt);
		/* The whole part at once, or runs of RT_MORPH_RUN when morphed. */
		for (size_t v0 = 0; v0 < n;) {
			const size_t m = mw && n - v0 > RT_MORPH_RUN ? RT_MORPH_RUN : n - v0;
			const float *pos = p->positions + 3 * v0;
			if (mw) {
				morph_range(p, mw, nt, v0, m, morphed);
				pos = morphed;
			}
			const float *nrm = p->normals ? p->normals + 3 * v0 : NULL;
			float *o = (float *)((char *)op + v0 * pos_stride);
			float *onr = on ? (float *)((char *)on + v0 * nrm_stride) : NULL;
			if (skinned) {
				const uint8_t *ord = mu->skin_order + mu->skin_order_at[i];
				rt_skin_lbs_ordered(m, pos, onr ? nrm : NULL, p->joints + 4 * v0, p->weights + 4 * v0, pal, o,
				                    pos_stride, onr, nrm_stride, ord + v0, ord + n + 5 * (v0 / RT_SKIN_RUN));
				if (onr && !nrm)
					for (size_t v = 0; v < m; v++) {
						float *x = (float *)((char *)onr + v * nrm_stride);
						x[0] = x[1] = x[2] = 0.0f;
					}
			} else {
				rt_transform(m, pos, nrm, M, unit ? U : NULL, o, pos_stride, onr, nrm_stride);
			}
			v0 += m;
		}
		base += n;
	}
	if (vertex_count)
		*vertex_count = (uint32_t)base;
	return MLOD_OK;
}

/* ---------------------------------------------------------------- */
/* Bounds                                                            */
/* ---------------------------------------------------------------- */

/* The relative rounding allowance of mlod_rt_bounds: the kernels sum
 * products of floats (a blended matrix of up to 4 palette entries, then
 * its product with a morphed position), each to within a few units in the
 * last place (6e-8) of the magnitudes summed; 1e-5 of those magnitudes
 * covers them more than 10 times over. */
#define RT_BOUND_ROUND 1e-5

static inline double dmin(double a, double b) { return a < b ? a : b; }
static inline double dmax(double a, double b) { return a > b ? a : b; }

/* Takes [a, b] into the box's axis i, adding both to *probe: a NaN,
 * which dmin and dmax would let a later bound wash out, stays there (as
 * do infinities of both signs, a box that is all of space anyway). */
static inline void widen(double *lo, double *hi, int i, double a, double b, double *probe)
{
	*probe += a + b;
	lo[i] = dmin(lo[i], a);
	hi[i] = dmax(hi[i], b);
}

/* How far instance id's morph weights move a part's positions at most at
 * mesh level mu: sum |w_t| times target t's longest delta, the largest
 * such sum over the parts, which widens every ball (mlod_rt_bounds,
 * mlod_rt_skin_stale). */
static double morph_growth(const mlod_rt_ctx *ctx, const rt_unit *mu, uint32_t id)
{
	const mlod_pack_mesh *m = mu->mesh;
	double grow = 0;
	for (uint32_t i = 0; i < m->part_count && i < ctx->morph_parts; i++) {
		uint32_t k = ctx->morph_offset[i + 1] - ctx->morph_offset[i];
		const uint32_t have = mu->bound_morph_at[i + 1] - mu->bound_morph_at[i];
		if (have < k)
			k = have;
		const float *w = ctx->morph_weights + (size_t)rt_slot(ctx, id) * ctx->morph_total + ctx->morph_offset[i];
		const float *d = mu->bound_morph + mu->bound_morph_at[i];
		double g = 0;
		for (uint32_t t = 0; t < k; t++)
			g += fabs((double)w[t]) * d[t];
		grow = dmax(grow, g);
	}
	return grow;
}

/* The box of a set of points under the affine M (column-major), from its
 * bounds before M: centre c, half extents h of their box and, with r >= 0,
 * the radius of a ball about c that holds them. On axis i the centre is
 * x_i = (M c)_i and the half extent e_i the smaller of sum_j |M_ij| h_j
 * (the box's image) and r |M's row i| (the ball's: an ellipsoid's box
 * exactly), each a bound of the points' images; m_i is the magnitude the
 * kernels sum there, (|M_i0| + |M_i1| + |M_i2|) (|c|_1 + |h|_1) + |M_i3|,
 * for the rounding allowance. */
static inline void box_image(const float *M, const double *c, const double *h, double r, double *x, double *e,
                             double *m)
{
	const double cn = fabs(c[0]) + fabs(c[1]) + fabs(c[2]) + h[0] + h[1] + h[2];
	for (int i = 0; i < 3; i++) {
		const double a0 = M[i], a1 = M[4 + i], a2 = M[8 + i], t = M[12 + i];
		const double f0 = fabs(a0), f1 = fabs(a1), f2 = fabs(a2);
		x[i] = a0 * c[0] + a1 * c[1] + a2 * c[2] + t;
		e[i] = f0 * h[0] + f1 * h[1] + f2 * h[2];
		if (r >= 0)
			e[i] = dmin(e[i], r * sqrt(a0 * a0 + a1 * a1 + a2 * a2));
		m[i] = (f0 + f1 + f2) * cn + fabs(t);
	}
}

mlod_result mlod_rt_bounds(const mlod_rt_ctx *ctx, mlod_rt_scratch *s, uint32_t id, float min[3], float max[3],
                           mlod_error *err)
{
	if (!ctx || !s || !min || !max)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_rt_bounds: NULL argument");
	for (int k = 0; k < 3; k++)
		min[k] = FLT_MAX, max[k] = -FLT_MAX;
	if (s->owner != ctx)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_rt_bounds: the scratch was made for another context");
	if (!rt_live(ctx, id))
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "instance %u is not alive", id);
	/* The pose and the palette entries mlod_rt_skin makes (the same
	 * floats); without a mesh, the empty box. */
	const rt_unit *su, *mu;
	mlod_result r = pose_mesh_level(ctx, s, id, UINT32_MAX, &su, &mu, err);
	if (r != MLOD_OK || !mu)
		return r;
	const float *W = s->world;
	const mlod_pack_mesh *m = mu->mesh;
	const double grow = morph_growth(ctx, mu, id);
	/* Skinned vertices: per palette entry, the box of its points' images
	 * through the bind pose (the entry's matrix P on their bind-pose box and
	 * ball) and, where the inverse bind B has an inverse, through the
	 * joint's space (P B^-1, at level 0 the joint's world matrix, on their
	 * box there, which follows the bone): their intersection, widened by
	 * the rounding allowance of both (the kernels compute P x). */
	double lo[3] = { INFINITY, INFINITY, INFINITY }, hi[3] = { -INFINITY, -INFINITY, -INFINITY };
	double probe = 0; /* NaN once a bound came to NaN: a pose or palette not finite */
	for (uint32_t k = 0; k < mu->pal_used_count; k++) {
		const uint32_t e = mu->pal_used[k];
		const float *b = mu->bound_entry + 13 * (size_t)e, *P = s->palette + 16 * (size_t)e;
		if (!(b[6] >= 0.0f))
			continue;
		const double c1[3] = { b[0], b[1], b[2] }, h1[3] = { b[3] + grow, b[4] + grow, b[5] + grow };
		double x1[3], e1[3], m1[3];
		box_image(P, c1, h1, b[6] + grow, x1, e1, m1);
		if (b[10] >= 0.0f) {
			float M[16];
			rt_mat_mul(P, ctx->pal_bind_inv + 16 * (size_t)e, M);
			/* a morph delta d moves a joint-space point by B's linear part
			 * times d: at most |B's row i| |d| on axis i */
			double c2[3] = { b[7], b[8], b[9] }, h2[3] = { b[10], b[11], b[12] }, x2[3], e2[3], m2[3];
			if (grow > 0) {
				const float *B = ctx->pal_bind0[e];
				for (int i = 0; i < 3; i++)
					h2[i] += grow * sqrt((double)B[i] * B[i] + (double)B[4 + i] * B[4 + i] + (double)B[8 + i] * B[8 + i]);
			}
			box_image(M, c2, h2, -1, x2, e2, m2);
			for (int i = 0; i < 3; i++) {
				const double g = RT_BOUND_ROUND * (m1[i] + m2[i]);
				const double a1 = x1[i] - e1[i], b1 = x1[i] + e1[i];
				probe += a1 + b1; /* dmax and dmin drop a NaN of their first operand */
				widen(lo, hi, i, dmax(a1, x2[i] - e2[i]) - g, dmin(b1, x2[i] + e2[i]) + g, &probe);
			}
		} else {
			for (int i = 0; i < 3; i++) {
				const double g = RT_BOUND_ROUND * m1[i];
				widen(lo, hi, i, x1[i] - e1[i] - g, x1[i] + e1[i] + g, &probe);
			}
		}
	}
	/* Rigid and static parts: the matrix mlod_rt_skin makes for them. */
	for (uint32_t i = 0; i < m->part_count; i++) {
		const mlod_pack_part *p = &m->parts[i];
		const float *c = mu->bound_part + 7 * (size_t)i;
		if (p->rec.skin >= 0 || !(c[6] >= 0.0f))
			continue;
		float M[16];
		rigid_matrix(su, rigid_world(su, W, p), p, M);
		const double cc[3] = { c[0], c[1], c[2] }, hh[3] = { c[3] + grow, c[4] + grow, c[5] + grow };
		double x[3], ex[3], mg[3];
		box_image(M, cc, hh, c[6] + grow, x, ex, mg);
		for (int k = 0; k < 3; k++)
			widen(lo, hi, k, x[k] - ex[k] - RT_BOUND_ROUND * mg[k], x[k] + ex[k] + RT_BOUND_ROUND * mg[k], &probe);
	}
	if (isnan(probe)) { /* the kernels' outputs are not bounded: all of space, which no cull drops */
		for (int k = 0; k < 3; k++)
			min[k] = -INFINITY, max[k] = INFINITY;
		return MLOD_OK;
	}
	if (!(lo[0] <= hi[0]))
		return MLOD_OK; /* no vertex: the empty box */
	for (int k = 0; k < 3; k++) {
		float a = (float)lo[k], b = (float)hi[k];
		if ((double)a > lo[k])
			a = nextafterf(a, -INFINITY);
		if ((double)b < hi[k])
			b = nextafterf(b, INFINITY);
		min[k] = a, max[k] = b;
	}
	return MLOD_OK;
}

/* ---------------------------------------------------------------- */
/* Skinning only when the shown vertices went stale                  */
/* ---------------------------------------------------------------- */

/* The caller's record of the last skin of one instance
 * (mlod_rt_stale_size): this head, then 12 floats per joint (the 3x4
 * affine part of the world matrix the skin used, columns 0 .. 3, rows
 * 0 .. 2; valid at the joints the skin posed), then the instance's morph
 * weights. The palette entries and rigid parts' matrices of that skin are
 * made again from them by the same products (rt_mat_mul, rigid_matrix):
 * the same floats, in fewer bytes than a palette (RobotExpressive: 43
 * joints, 172 palette entries). All zero (valid 0): never skinned. The
 * context that wrote it is named by its open_tag: a record of another
 * context (another pack, or another open of the same pack: the same
 * layout, other instances) holds no skin of this one's. */
typedef struct rt_stale_head {
	uint32_t valid;           /* RT_STALE_VALID once it holds a skin */
	uint32_t id;              /* the instance skinned (its generation too) */
	uint32_t skel_level, mesh_level, clip;
	uint32_t tag_lo, tag_hi;  /* the writer's open_tag (two halves: the record is 4-byte aligned) */
	uint32_t hint;            /* the item whose bound went over at the last check */
} rt_stale_head;

#define RT_STALE_VALID 0x6d6c7331u

size_t mlod_rt_stale_size(const mlod_rt_ctx *ctx)
{
	if (!ctx)
		return 0;
	return sizeof(rt_stale_head) + 48 * (size_t)ctx->joint_count + 4 * (size_t)ctx->morph_total;
}

/* A kept world matrix (12 floats) as the 16 rt_mat_mul reads. */
static inline void affine16(const float *w, float *M)
{
	for (int c = 0; c < 4; c++)
		M[4 * c] = w[3 * c], M[4 * c + 1] = w[3 * c + 1], M[4 * c + 2] = w[3 * c + 2], M[4 * c + 3] = 0.0f;
	M[15] = 1.0f;
}

/* The change from the affine M0 to M1 (column-major 4x4), in double: D =
 * M1 - M0, its linear part l (l[3 j + i] = row i, column j) and
 * translation t; f2 = ||l||_F^2; per row i the magnitudes the kernels sum
 * with either matrix, a[i] = sum_j (|M0_ij| + |M1_ij|) and b[i] = |M0_i3|
 * + |M1_i3| (for the rounding allowance); same: 1 when D is 0 and finite. */
typedef struct rt_stale_delta {
	double l[9], t[3], a[3], b[3], f2;
	int same;
} rt_stale_delta;

static void stale_delta(const float *M0, const float *M1, rt_stale_delta *d)
{
	double f2 = 0, z = 0;
	for (int i = 0; i < 3; i++) {
		d->t[i] = (double)M1[12 + i] - M0[12 + i];
		d->b[i] = fabs((double)M0[12 + i]) + fabs((double)M1[12 + i]);
		z += d->t[i] * d->t[i];
		double a = 0;
		for (int j = 0; j < 3; j++) {
			const double l = (double)M1[4 * j + i] - M0[4 * j + i];
			d->l[3 * j + i] = l;
			f2 += l * l;
			a += fabs((double)M0[4 * j + i]) + fabs((double)M1[4 * j + i]);
		}
		d->a[i] = a;
	}
	d->f2 = f2;
	d->same = z == 0 && f2 == 0; /* NaN compares false */
}

/* How far a point of a set bounded by centre c (3), half extents h (3)
 * and ball radius r about c, each grown by g, moves under the change d: a
 * point x moves by D x = (l c + t) + l (x - c), at most |l c + t| plus the
 * smaller of ||l||_F (r + g) (the Frobenius norm bounds the spectral one)
 * and |(sum_j |l_ij| (h_j + g))_i| (the box's); plus the rounding of both
 * skins (RT_BOUND_ROUND of the magnitudes the kernels sum, as
 * mlod_rt_bounds allows, for each matrix, times sqrt 3 over the axes). 0
 * when the matrices are the same finite floats (the kernels then write
 * the same floats). NaN when any is not finite. */
static double stale_move(const rt_stale_delta *d, const float *c, const float *h, double r, double g)
{
	if (d->same)
		return 0.0;
	const double cn = fabs(c[0]) + fabs(c[1]) + fabs(c[2]) + h[0] + h[1] + h[2] + 3 * g;
	const double h0 = h[0] + g, h1 = h[1] + g, h2 = h[2] + g;
	double u2 = 0, v2 = 0, mag = 0;
	for (int i = 0; i < 3; i++) {
		const double *l = d->l + i;
		const double u = d->t[i] + l[0] * c[0] + l[3] * c[1] + l[6] * c[2];
		const double v = fabs(l[0]) * h0 + fabs(l[3]) * h1 + fabs(l[6]) * h2;
		const double m = d->a[i] * cn + d->b[i];
		u2 += u * u, v2 += v * v;
		mag = dmax(mag, m) + 0 * m; /* a NaN stays */
	}
	const double ball = sqrt(d->f2) * (r + g), box = sqrt(v2);
	return sqrt(u2) + dmin(ball, box) + 0 * (ball + box) + RT_BOUND_ROUND * 1.7320508075688772 * mag;
}

/* Entries sharing a joint and a bind matrix (entry_src: skins sharing
 * joints) share their change: kept on the stack for the last few sources
 * met, by source index modulo RT_STALE_SLOTS. */
#define RT_STALE_SLOTS 16

mlod_result mlod_rt_skin_stale(const mlod_rt_ctx *ctx, mlod_rt_scratch *s, uint32_t id, const mlod_rt_select *sel,
                               float max_stale_pixels, void *record, size_t record_size, float *positions,
                               size_t pos_stride, float *normals, size_t nrm_stride, uint32_t capacity,
                               uint32_t *vertex_count, int *skinned, float *stale_pixels, mlod_error *err)
{
	if (vertex_count)
		*vertex_count = 0;
	if (skinned)
		*skinned = 0;
	if (stale_pixels)
		*stale_pixels = 0;
	if (!ctx || !s || !sel || !record || !positions)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_rt_skin_stale: NULL argument");
	if (s->owner != ctx)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_rt_skin_stale: the scratch was made for another context");
	if (pos_stride < 12 || pos_stride % 4 || (normals && (nrm_stride < 12 || nrm_stride % 4)))
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_rt_skin_stale: strides must be multiples of 4, at least 12");
	if (!(sel->fov_y > 0.0f && sel->fov_y < 3.14159265f) || !(sel->lines > 0.0f) || !isfinite(sel->lines))
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_rt_skin_stale: fov_y must lie in (0, pi), lines be > 0");
	if (!(max_stale_pixels >= 0.0f) || !isfinite(max_stale_pixels))
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_rt_skin_stale: max_stale_pixels must be finite, >= 0");
	if (record_size < mlod_rt_stale_size(ctx))
		return mlod_fail(err, MLOD_ERR_INVALID_ARG,
		                 "mlod_rt_skin_stale: a record of %zu bytes, this context's take %zu (mlod_rt_stale_size)",
		                 record_size, mlod_rt_stale_size(ctx));
	const rt_instance *in = rt_live(ctx, id);
	if (!in)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "instance %u is not alive", id);
	const mlod_rt_state *st = &in->st;
	const rt_unit *su, *mu;
	mlod_result r = pose_mesh_level(ctx, s, id, capacity, &su, &mu, err);
	if (r != MLOD_OK)
		return r;
	if (!mu) /* no mesh: nothing to keep */
		return mlod_rt_skin(ctx, s, id, positions, pos_stride, normals, nrm_stride, capacity, vertex_count, err);
	rt_stale_head *hd = record;
	float *rec_world = (float *)(hd + 1), *rec_morph = rec_world + 12 * (size_t)ctx->joint_count;
	const mlod_pack_mesh *m = mu->mesh;
	const uint32_t skel_level = su ? su->level : 0;
	const float *mw = ctx->morph_total ? ctx->morph_weights + (size_t)rt_slot(ctx, id) * ctx->morph_total : NULL;
	/* Anything but the pose changed since the kept skin: skin. */
	const uint32_t tag_lo = (uint32_t)ctx->open_tag, tag_hi = (uint32_t)(ctx->open_tag >> 32);
	int need = hd->valid != RT_STALE_VALID || hd->tag_lo != tag_lo || hd->tag_hi != tag_hi || hd->id != id ||
	           hd->skel_level != skel_level || hd->mesh_level != mu->level || hd->clip != st->clip ||
	           (mw && memcmp(rec_morph, mw, 4 * (size_t)ctx->morph_total) != 0);
	if (!need) {
		/* The distance a vertex may have moved for max_stale_pixels at the
		 * instance's distance: D pixels = D lines / (2 d tan(fov_y / 2)). */
		const double px = (double)sel->lines / (2.0 * (double)st->distance * tan(0.5 * (double)sel->fov_y));
		const double lim = (double)max_stale_pixels / px; /* d = 0: px infinite, lim 0 */
		const double grow = morph_growth(ctx, mu, id); /* the weights are unchanged */
		/* A skinned vertex is a convex combination of its entries' images:
		 * it moved at most the most any of its entries' points moved. An
		 * entry no vertex weighs (b[6] < 0) still multiplies: a matrix
		 * not finite there makes the output NaN, so it must skin. */
		/* Items: the level's palette entries (k < pal_used_count), then
		 * its parts (rigid ones move with their matrix; static and
		 * skinned ones are skipped here). The item that went over last
		 * time (hd->hint) first: a moving instance mostly goes over on
		 * the same limb, so its skin is decided after one item. */
		double most = 0;
		rt_stale_delta cache[RT_STALE_SLOTS];
		uint32_t tag[RT_STALE_SLOTS];
		for (int k = 0; k < RT_STALE_SLOTS; k++)
			tag[k] = UINT32_MAX;
		const uint32_t items = mu->pal_used_count + m->part_count;
		const uint32_t first = hd->hint < items ? hd->hint : 0;
		for (uint32_t n = 0; n < items && !need; n++) {
			const uint32_t k = n == 0 ? first : n <= first ? n - 1 : n;
			double mv = 0;
			if (k < mu->pal_used_count) {
				const uint32_t e = mu->pal_used[k], f = entry_src(ctx, su, e), slot = f % RT_STALE_SLOTS;
				const float *b = mu->bound_entry + 13 * (size_t)e;
				rt_stale_delta *d = &cache[slot];
				if (tag[slot] != f) {
					/* the matrix this entry had at the kept skin: the
					 * same product as then (rt_mat_mul of the same floats) */
					float W0[16], P0[16];
					affine16(rec_world + 12 * (size_t)entry_joint(ctx, su, e), W0);
					rt_mat_mul(W0, entry_bind(ctx, su, e), P0);
					stale_delta(P0, s->palette + 16 * (size_t)e, d);
					tag[slot] = f;
				}
				mv = b[6] >= 0.0f ? stale_move(d, b, b + 3, b[6], grow) : 0 * stale_move(d, b, b, 0, 0);
			} else {
				const uint32_t i = k - mu->pal_used_count;
				const mlod_pack_part *p = &m->parts[i];
				const float *c = mu->bound_part + 7 * (size_t)i;
				if (p->rec.skin >= 0 || p->rec.joint < 0 || !(c[6] >= 0.0f))
					continue; /* a static part does not move */
				const uint32_t sj = rigid_joint(su, p);
				float W0[16], M0[16], M1[16];
				affine16(rec_world + 12 * (size_t)sj, W0);
				rigid_matrix(su, s->world + 16 * (size_t)sj, p, M1);
				rigid_matrix(su, W0, p, M0);
				rt_stale_delta d;
				stale_delta(M0, M1, &d);
				mv = stale_move(&d, c, c + 3, c[6], grow);
			}
			need = !(mv <= lim);
			most = dmax(most, mv);
			if (need)
				hd->hint = k;
		}
		if (!need) {
			if (vertex_count)
				*vertex_count = mu->vertex_count;
			/* at d 0 (px infinite) only a pose that did not move
			 * at all gets here: 0, not 0 times infinity */
			if (stale_pixels)
				*stale_pixels = most > 0 ? (float)(most * px) : 0.0f;
			return MLOD_OK;
		}
	}
	/* Skin (the pose and palette entries above, as they are) and keep
	 * the world matrices it used. */
	r = mlod_rt_skin(ctx, s, id, positions, pos_stride, normals, nrm_stride, capacity, vertex_count, err);
	if (r != MLOD_OK) {
		hd->valid = 0;
		return r;
	}
	for (uint32_t k = 0; k < s->plan_count; k++) {
		const uint32_t j = s->plan_posed[k];
		const float *w = s->world + 16 * (size_t)j;
		float *o = rec_world + 12 * (size_t)j;
		for (int c = 0; c < 4; c++)
			o[3 * c] = w[4 * c], o[3 * c + 1] = w[4 * c + 1], o[3 * c + 2] = w[4 * c + 2];
	}
	if (mw)
		memcpy(rec_morph, mw, 4 * (size_t)ctx->morph_total);
	hd->valid = RT_STALE_VALID, hd->id = id, hd->skel_level = skel_level, hd->mesh_level = mu->level;
	hd->clip = st->clip, hd->tag_lo = tag_lo, hd->tag_hi = tag_hi;
	if (skinned)
		*skinned = 1;
	return MLOD_OK;
}
