/*
 * rounding.c: values rounded so that few bits vary (beyond the paper),
 * and gzip/zstd compress them well.
 *
 * A level's channel is rounded to a grid 2^e (motion_channel_exp: the
 * level grid for translations, finer by their joint's reach for rotations
 * and scales), its first and last keys exact. A rotation's three smaller
 * components are rounded and its largest recomputed from them, so it
 * stays (about) unit. With auto precision, rotations go on the lattice
 * of normalised shorts instead, as gltfpack stores them (core glTF),
 * every key (the ends on the finest lattice). Which grids a level takes
 * is precision.c's search.
 */
#include <math.h>
#include <string.h>

#include "motion/motion_internal.h"

/* v rounded to the nearest multiple of 2^e. */
EVAL_INLINE float grid_round(float v, int e)
{
	return (float)ldexp(rint(ldexp((double)v, -e)), e);
}

/* Rounds a unit quaternion: its three smaller components to the grid 2^e,
 * the largest recomputed from them, so it stays unit (and the glTF
 * writer's normalisation leaves it as it is). */
EVAL_INLINE void round_quat(float *q, int e)
{
	int big = 0;
	for (int c = 1; c < 4; c++)
		if (fabsf(q[c]) > fabsf(q[big]))
			big = c;
	float r[4];
	double sum = 0.0;
	for (int c = 0; c < 4; c++)
		if (c != big) {
			r[c] = grid_round(q[c], e);
			sum += (double)r[c] * r[c];
		}
	if (!(sum < 1.0))
		return; /* a grid too coarse for this key: it stays as it is */
	r[big] = copysignf((float)sqrt(1.0 - sum), q[big]);
	mlod_quat n = mlod_quat_normalize((mlod_quat){ r[0], r[1], r[2], r[3] });
	q[0] = n.x, q[1] = n.y, q[2] = n.z, q[3] = n.w;
}

/* The lattice of normalised shorts: n / 32767 as glTF readers decode it. */
EVAL_INLINE float short_value(long n)
{
	return (float)((double)n / 32767.0);
}

/* Rounds a unit quaternion onto the lattice of normalised shorts: its three
 * smaller components to multiples of step / 32767 (step a power of two),
 * the largest to the nearest lattice value that makes it unit. */
EVAL_INLINE void round_quat_short(float *q, double step)
{
	int big = 0;
	for (int c = 1; c < 4; c++)
		if (fabsf(q[c]) > fabsf(q[big]))
			big = c;
	double sum = 0.0;
	long n[4];
	for (int c = 0; c < 4; c++)
		if (c != big) {
			n[c] = lrint(rint((double)q[c] * 32767.0 / step) * step);
			n[c] = n[c] > 32767 ? 32767 : n[c] < -32767 ? -32767 : n[c];
			sum += (double)short_value(n[c]) * short_value(n[c]);
		}
	if (!(sum < 1.0)) /* a grid too coarse for this key: the finest lattice */
		for (int c = 0; c < 4; c++)
			n[c] = lrint((double)q[c] * 32767.0);
	else
		n[big] = lrint(copysign(sqrt(1.0 - sum), (double)q[big]) * 32767.0);
	for (int c = 0; c < 4; c++)
		q[c] = short_value(n[c]);
}

/* b gets a's values rounded to the grid 2^e (MOTION_NO_ROUNDING: as they are),
 * the first and last keys exact; with shorts, a rotation goes on the
 * lattice of normalised shorts instead, every key (the ends on the finest
 * lattice). */
EVAL_INLINE void round_channel_body(const mlod_channel *a, mlod_channel *b, int e, int shorts)
{
	int comps = motion_comps(a), n = a->key_count;
	memcpy(b->values, a->values, sizeof(float) * (size_t)n * (size_t)comps);
	b->short_values = 0;
	if (e == MOTION_NO_ROUNDING)
		return;
	if (shorts && comps == 4 && a->interp != MLOD_INTERP_CUBICSPLINE) {
		int lattice = e + 15 > 0 ? e + 15 : 0; /* 2^e is about 2^(e + 15) / 32767 */
		const double step = ldexp(1.0, lattice); /* once a channel, not once a key */
		for (int k = 0; k < n; k++)
			round_quat_short(b->values + (size_t)k * 4u, k == 0 || k == n - 1 ? 1.0 : step);
		b->short_values = 1;
		return;
	}
	for (int k = 1; k + 1 < n; k++) {
		float *v = b->values + (size_t)k * (size_t)comps;
		if (comps == 4)
			round_quat(v, e);
		else
			for (int c = 0; c < 3; c++)
				v[c] = grid_round(v[c], e);
	}
}

/* round_channel_body compiled twice (motion_eval.h): the same floats (with
 * AVX2, rint is one instruction). */
static void round_channel_generic(const mlod_channel *a, mlod_channel *b, int e, int shorts)
{
	round_channel_body(a, b, e, shorts);
}
#if EVAL_HAVE_AVX2
EVAL_TARGET_AVX2 static void round_channel_avx2(const mlod_channel *a, mlod_channel *b, int e, int shorts)
{
	round_channel_body(a, b, e, shorts);
}
#endif
void motion_round_channel(const mlod_channel *a, mlod_channel *b, int e, int shorts)
{
#if EVAL_HAVE_AVX2
	if (eval_avx2()) {
		round_channel_avx2(a, b, e, shorts);
		return;
	}
#endif
	round_channel_generic(a, b, e, shorts);
}

/* dst, laid out as src, gets src's values rounded: channel i to the grid
 * 2^e[i] (MOTION_NO_ROUNDING: as they are), as motion_round_channel
 * leaves them. */
void motion_round_clip(const mlod_clip *src, mlod_clip *dst, const int *e, int shorts)
{
	for (int i = 0; i < src->channel_count; i++)
		motion_round_channel(&src->channels[i], &dst->channels[i], e[i], shorts);
}

void motion_channel_exps(const mlod_motion *m, const mlod_clip *clip, int g, const int *adj, int *e)
{
	for (int i = 0; i < clip->channel_count; i++)
		e[i] = motion_channel_exp(m, &clip->channels[i], g, adj[i]);
}
