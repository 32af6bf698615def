/*
 * timeline.c: clips as the motion layer reads them: the common timeline
 * (every channel keyed at the same frames: the clip's own keys when its
 * channels agree, else the union of their key times from
 * mlod_clip_key_times, with CUBICSPLINE intervals subdivided to at least
 * cubic_rate frames per second), the sample times between frames where
 * bounds are checked, and the keys and bytes a clip stores. motion.c,
 * the methods, keyreduce.c and morphweights.c build on it.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "motion/mlod_motion.h"

#define DEFAULT_CUBIC_RATE 60.0
#define MAX_FRAMES 10000000
#define MAX_VALUES 200000000.0 /* floats of a common clip */

static int comps_of(const mlod_channel *ch)
{
	return ch->path == MLOD_PATH_ROTATION ? 4 : 3;
}

/* ---------------------------------------------------------------- */
/* Clips                                                             */
/* ---------------------------------------------------------------- */

void mlod_clip_free(mlod_clip *clip)
{
	if (!clip)
		return;
	for (int i = 0; clip->channels && i < clip->channel_count; i++) {
		free(clip->channels[i].times);
		free(clip->channels[i].values);
	}
	free(clip->channels);
	free(clip->name);
	memset(clip, 0, sizeof *clip);
}

long mlod_clip_key_count(const mlod_clip *clip)
{
	long n = 0;
	for (int i = 0; clip && i < clip->channel_count; i++)
		n += clip->channels[i].key_count;
	return n;
}

long mlod_clip_key_bytes(const mlod_clip *clip)
{
	long bytes = 0;
	if (!clip)
		return 0;
	for (int i = 0; i < clip->channel_count; i++) {
		const mlod_channel *ch = &clip->channels[i];
		long per_key = comps_of(ch) * (ch->interp == MLOD_INTERP_CUBICSPLINE ? 3 : 1);
		bytes += (long)ch->key_count * per_key * (ch->short_values ? 2 : 4);
		int shared = 0;
		for (int k = 0; k < i && !shared; k++) {
			const mlod_channel *o = &clip->channels[k];
			shared = o->key_count == ch->key_count &&
			         memcmp(o->times, ch->times, sizeof(float) * (size_t)ch->key_count) == 0;
		}
		if (!shared)
			bytes += (long)ch->key_count * 4;
	}
	return bytes;
}

void mlod_motion_sample_times(const float *times, int frames, int subdivide, float *out)
{
	int sub = subdivide > 0 ? subdivide : 1;
	for (int f = 0; f < frames; f++) {
		out[(size_t)f * (size_t)sub] = times[f];
		for (int i = 1; f + 1 < frames && i < sub; i++) {
			double t0 = times[f], t1 = times[f + 1];
			float t = (float)(t0 + (t1 - t0) * (double)i / (double)sub);
			/* Inside the interval (or on its start when it is too short). */
			out[(size_t)f * (size_t)sub + (size_t)i] = t > times[f] && t < times[f + 1] ? t : times[f];
		}
	}
}

static mlod_result check_clip(const mlod_clip *clip, mlod_error *err)
{
	char q[MLOD_NAME_TEXT_SIZE];
	const char *name = mlod_name_text(clip->name, 1, q, sizeof q);
	if (clip->channel_count < 0 || (clip->channel_count > 0 && !clip->channels))
		return mlod_fail(err, MLOD_ERR_PARSE, "clip %s: channel count %d without channels", name,
		                 clip->channel_count);
	for (int i = 0; i < clip->channel_count; i++) {
		const mlod_channel *ch = &clip->channels[i];
		if ((unsigned)ch->path > MLOD_PATH_SCALE || (unsigned)ch->interp > MLOD_INTERP_CUBICSPLINE)
			return mlod_fail(err, MLOD_ERR_PARSE, "clip %s channel %d: bad path or interpolation", name, i);
		if (ch->key_count <= 0 || !ch->times || !ch->values)
			return mlod_fail(err, MLOD_ERR_PARSE, "clip %s channel %d: no keys", name, i);
		int comps = comps_of(ch), stride = comps * (ch->interp == MLOD_INTERP_CUBICSPLINE ? 3 : 1);
		for (int k = 0; k < ch->key_count; k++) {
			float t = ch->times[k];
			if (!isfinite(t))
				return mlod_fail(err, MLOD_ERR_PARSE, "clip %s channel %d: key %d time is not finite", name, i, k);
			if (k == 0 && t < 0.0f)
				return mlod_fail(err, MLOD_ERR_PARSE,
				                 "clip %s channel %d: first key time %g is negative (glTF needs times >= 0)",
				                 name, i, (double)t);
			if (k > 0 && !(t > ch->times[k - 1]))
				return mlod_fail(err, MLOD_ERR_PARSE,
				                 "clip %s channel %d: key %d time %g does not follow %g (times must increase)",
				                 name, i, k, (double)t, (double)ch->times[k - 1]);
			const float *v = ch->values + (size_t)k * (size_t)stride;
			double len2 = 0.0;
			for (int c = 0; c < stride; c++)
				if (!isfinite(v[c]))
					return mlod_fail(err, MLOD_ERR_PARSE, "clip %s channel %d: key %d value is not finite", name,
					                 i, k);
			if (comps == 4) {
				const float *q = v + (ch->interp == MLOD_INTERP_CUBICSPLINE ? 4 : 0);
				for (int c = 0; c < 4; c++)
					len2 += (double)q[c] * q[c];
				if (!(len2 > 1e-12))
					return mlod_fail(err, MLOD_ERR_PARSE, "clip %s channel %d: key %d rotation is a zero quaternion",
					                 name, i, k);
			}
		}
	}
	return MLOD_OK;
}

/* Samples one channel of clip at t into out (comps floats), exactly as
 * mlod_clip_sample does. */
static void sample_one(const mlod_clip *clip, const mlod_channel *ch, float t, float *out)
{
	mlod_trs local = mlod_trs_identity();
	mlod_channel_sample(ch, clip->duration, t, &local);
	switch (ch->path) {
	case MLOD_PATH_TRANSLATION: out[0] = local.t.x, out[1] = local.t.y, out[2] = local.t.z; break;
	case MLOD_PATH_SCALE: out[0] = local.s.x, out[1] = local.s.y, out[2] = local.s.z; break;
	case MLOD_PATH_ROTATION: out[0] = local.r.x, out[1] = local.r.y, out[2] = local.r.z, out[3] = local.r.w; break;
	}
}

mlod_result mlod_motion_common_clip(const mlod_clip *clip, const mlod_motion_options *opt, mlod_clip *out,
                                    mlod_motion_timeline *info, mlod_error *err)
{
	mlod_motion_timeline inf;
	char q[MLOD_NAME_TEXT_SIZE];
	memset(&inf, 0, sizeof inf);
	if (!clip || !out)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_motion_common_clip: NULL argument");
	memset(out, 0, sizeof *out);
	mlod_result r = check_clip(clip, err);
	if (r != MLOD_OK)
		return r;
	if (clip->channel_count == 0) {
		/* No joint channels (an animation of a camera, of other nodes or
		 * of morph weights alone): a timeline of no frames. */
		out->name = mlod_strdup(clip->name);
		out->duration = clip->duration;
		out->frame_time = clip->frame_time;
		out->frame_count = clip->frame_count;
		out->gltf_index = clip->gltf_index;
		if (!out->name)
			return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
		if (info)
			*info = inf;
		return MLOD_OK;
	}
	double rate = opt && opt->cubic_rate > 0.0 ? opt->cubic_rate : DEFAULT_CUBIC_RATE;
	for (int i = 0; i < clip->channel_count; i++)
		if (clip->channels[i].interp == MLOD_INTERP_CUBICSPLINE)
			inf.cubic_channels++;

	/* The frames: the key times of every channel (mlod_clip_key_times). */
	float *times = NULL, *u = NULL;
	long n = 0;
	int same = 1;
	/* When every channel has the first one's key times (a BVH clip), the
	 * merge of them all is the merge of the first alone: only it is
	 * sorted. */
	unsigned char *use = NULL;
	int all_same = clip->channel_count > 1;
	for (int i = 1; all_same && i < clip->channel_count; i++) {
		const mlod_channel *a = &clip->channels[0], *b = &clip->channels[i];
		all_same = b->key_count == a->key_count &&
		           (a->key_count == 0 || memcmp(b->times, a->times, sizeof(float) * (size_t)a->key_count) == 0);
	}
	if (all_same && (use = calloc((size_t)clip->channel_count, 1)) != NULL)
		use[0] = 1;
	int uk = mlod_clip_key_times(clip, use, 0, &u, &same);
	free(use);
	if (uk < 0)
		return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
	if (same && inf.cubic_channels == 0) {
		/* Every channel has these keys: the clip keeps them. */
		n = uk;
		times = u;
	} else {
		long k = uk;
		/* CUBICSPLINE: evenly spaced frames in intervals longer than 1/rate. */
		double extra = 0.0;
		for (long i = 0; inf.cubic_channels && i + 1 < k; i++)
			extra += ceil(((double)u[i + 1] - u[i]) * rate - 1e-6) - 1.0;
		if (k + extra > MAX_FRAMES) {
			free(u);
			return mlod_fail(err, MLOD_ERR_LIMIT, "clip %s: resampling needs %.0f frames (at most %d)",
			                 mlod_name_text(clip->name, 1, q, sizeof q), k + extra, MAX_FRAMES);
		}
		n = k + (long)extra;
		times = malloc(sizeof(float) * (size_t)n);
		if (!times) {
			free(u);
			return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
		}
		long f = 0;
		for (long i = 0; i < k; i++) {
			times[f++] = u[i];
			if (!inf.cubic_channels || i + 1 == k)
				continue;
			long sub = (long)(ceil(((double)u[i + 1] - u[i]) * rate - 1e-6));
			for (long s = 1; s < sub; s++) {
				float t = (float)((double)u[i] + ((double)u[i + 1] - u[i]) * (double)s / (double)sub);
				if (t > times[f - 1] && t < u[i + 1])
					times[f++] = t;
			}
		}
		n = f;
		free(u);
		inf.resampled = 1;
		for (int i = 0; i < clip->channel_count; i++) {
			const mlod_channel *ch = &clip->channels[i];
			if (ch->key_count != n || memcmp(ch->times, times, sizeof(float) * (size_t)n) != 0)
				inf.mismatched_channels++;
		}
	}
	double values = 0.0;
	for (int i = 0; i < clip->channel_count; i++)
		values += (double)n * (comps_of(&clip->channels[i]) + 1);
	if (n > MAX_FRAMES || values > MAX_VALUES) {
		free(times);
		return mlod_fail(err, MLOD_ERR_LIMIT, "clip %s: %ld frames of %d channels is too much motion",
		                 mlod_name_text(clip->name, 1, q, sizeof q), n, clip->channel_count);
	}
	inf.frames = (int)n;

	/* The channels. */
	out->name = mlod_strdup(clip->name);
	out->channels = calloc((size_t)clip->channel_count, sizeof *out->channels);
	out->channel_count = clip->channel_count;
	out->duration = clip->duration;
	out->frame_time = clip->frame_time;
	out->frame_count = clip->frame_count;
	out->gltf_index = clip->gltf_index;
	int ok = out->name && out->channels;
	for (int i = 0; ok && i < clip->channel_count; i++) {
		const mlod_channel *src = &clip->channels[i];
		mlod_channel *ch = &out->channels[i];
		int comps = comps_of(src);
		ch->joint = src->joint;
		ch->path = src->path;
		ch->interp = src->interp == MLOD_INTERP_STEP ? MLOD_INTERP_STEP : MLOD_INTERP_LINEAR;
		ch->key_count = (int)n;
		ch->times = malloc(sizeof(float) * (size_t)n);
		ch->values = malloc(sizeof(float) * (size_t)n * (size_t)comps);
		if (!ch->times || !ch->values) {
			ok = 0;
			break;
		}
		memcpy(ch->times, times, sizeof(float) * (size_t)n);
		int own = !inf.resampled;
		for (long f = 0; f < n; f++) {
			float *v = ch->values + f * comps;
			if (own)
				memcpy(v, src->values + f * comps, sizeof(float) * (size_t)comps);
			else
				sample_one(clip, src, times[f], v);
			/* Sign-continuous rotations: -q is q. */
			if (comps == 4 && f > 0) {
				const float *p = v - 4;
				if ((double)p[0] * v[0] + (double)p[1] * v[1] + (double)p[2] * v[2] + (double)p[3] * v[3] < 0.0)
					v[0] = -v[0], v[1] = -v[1], v[2] = -v[2], v[3] = -v[3];
			}
		}
	}
	free(times);
	if (!ok) {
		mlod_clip_free(out);
		return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
	}
	if (info)
		*info = inf;
	return MLOD_OK;
}
