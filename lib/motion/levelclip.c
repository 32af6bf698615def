/*
 * levelclip.c: the clips of motion levels. A level clip has the source
 * clip's name, duration and frame rate and the common clip's channels
 * (timeline.c), keyed at a line of the tree's frames (motiontree.c;
 * exactly constant channels keep one key) or at a key selection (the
 * keys method, keysmethod.c); it always reaches the last frame, so the
 * duration is kept. The rounding (precision.c) works on deep copies.
 */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "motion/motion_internal.h"

/* Starts a level clip like the source: name, duration, frame rate. */
int motion_level_clip_init(const mlod_motion *m, mlod_clip *clip)
{
	memset(clip, 0, sizeof *clip);
	clip->name = mlod_strdup(m->orig->name);
	clip->duration = m->orig->duration;
	clip->frame_time = m->orig->frame_time;
	clip->frame_count = m->orig->frame_count;
	clip->gltf_index = m->orig->gltf_index;
	clip->channel_count = m->common.channel_count;
	clip->channels = clip->channel_count > 0 ? calloc((size_t)clip->channel_count, sizeof *clip->channels) : NULL;
	return clip->name && (clip->channels || clip->channel_count == 0) ? 0 : -1;
}

/* The clip must reach the last frame: a channel with a single key gets a
 * second, equal key there when no channel does. */
static int keep_duration(const mlod_motion *m, mlod_clip *clip)
{
	float end = m->common.channels[0].times[m->frames - 1];
	int single = -1;
	for (int i = 0; i < clip->channel_count; i++) {
		const mlod_channel *ch = &clip->channels[i];
		if (ch->times[ch->key_count - 1] == end)
			return 0;
		if (ch->key_count == 1 && single < 0)
			single = i;
	}
	if (single < 0)
		return 0;
	mlod_channel *ch = &clip->channels[single];
	int comps = motion_comps(ch);
	float *t = realloc(ch->times, 2 * sizeof(float)), *v;
	if (!t)
		return -1;
	ch->times = t;
	v = realloc(ch->values, 2 * (size_t)comps * sizeof(float));
	if (!v)
		return -1;
	ch->values = v;
	t[1] = end;
	memcpy(v + comps, v, (size_t)comps * sizeof(float));
	ch->key_count = 2;
	return 0;
}

/* The level clip of a line of the tree; exactly constant channels keep
 * one key. */
int motion_clip_from_line(const mlod_motion *m, const motion_line *l, mlod_clip *clip)
{
	if (motion_level_clip_init(m, clip) != 0)
		return -1;
	for (int i = 0; i < clip->channel_count; i++) {
		const mlod_channel *src = &m->common.channels[i];
		mlod_channel *ch = &clip->channels[i];
		int comps = motion_comps(src), keys = m->constant[i] ? 1 : l->n;
		ch->joint = src->joint;
		ch->path = src->path;
		ch->interp = src->interp;
		ch->key_count = keys;
		ch->times = malloc(sizeof(float) * (size_t)keys);
		ch->values = malloc(sizeof(float) * (size_t)keys * (size_t)comps);
		if (!ch->times || !ch->values)
			return -1;
		float prev = -FLT_MAX;
		for (int k = 0; k < keys; k++) {
			float t = (float)l->v[k].time;
			if (!(t > prev))
				t = nextafterf(prev, FLT_MAX);
			ch->times[k] = prev = t;
			memcpy(ch->values + (size_t)k * (size_t)comps, l->v[k].values + m->offset[i], sizeof(float) * (size_t)comps);
		}
	}
	return keep_duration(m, clip);
}

/* The level clip of a key selection. */
int motion_clip_from_kept(const mlod_motion *m, const unsigned char *kept, mlod_clip *clip)
{
	if (motion_level_clip_init(m, clip) != 0)
		return -1;
	int F = m->frames;
	for (int i = 0; i < clip->channel_count; i++) {
		const mlod_channel *src = &m->common.channels[i];
		mlod_channel *ch = &clip->channels[i];
		const unsigned char *k = kept + (size_t)i * (size_t)F;
		int comps = motion_comps(src), keys = 0;
		for (int f = 0; f < F; f++)
			keys += k[f] != 0;
		ch->joint = src->joint;
		ch->path = src->path;
		ch->interp = src->interp;
		ch->key_count = keys;
		ch->times = malloc(sizeof(float) * (size_t)(keys > 0 ? keys : 1));
		ch->values = malloc(sizeof(float) * (size_t)(keys > 0 ? keys : 1) * (size_t)comps);
		if (!ch->times || !ch->values || keys == 0)
			return -1;
		for (int f = 0, n = 0; f < F; f++) {
			if (!k[f])
				continue;
			ch->times[n] = src->times[f];
			memcpy(ch->values + (size_t)n * (size_t)comps, src->values + (size_t)f * (size_t)comps,
			       sizeof(float) * (size_t)comps);
			n++;
		}
	}
	return keep_duration(m, clip);
}

/* A deep copy of a level clip, or -1 when out of memory. */
int motion_clip_copy(const mlod_clip *src, mlod_clip *dst)
{
	*dst = *src;
	dst->name = mlod_strdup(src->name);
	dst->channels = calloc((size_t)src->channel_count, sizeof *dst->channels);
	if (!dst->name || !dst->channels) {
		dst->channel_count = 0;
		return -1;
	}
	for (int i = 0; i < src->channel_count; i++) {
		const mlod_channel *a = &src->channels[i];
		mlod_channel *b = &dst->channels[i];
		size_t n = (size_t)a->key_count;
		*b = *a;
		b->values = NULL;
		b->times = malloc(sizeof(float) * n);
		b->values = malloc(sizeof(float) * n * (size_t)motion_comps(a));
		if (!b->times || !b->values)
			return -1;
		memcpy(b->times, a->times, sizeof(float) * n);
		memcpy(b->values, a->values, sizeof(float) * n * (size_t)motion_comps(a));
	}
	return 0;
}

void mlod_motion_level_free(mlod_motion_level *l)
{
	if (!l)
		return;
	mlod_clip_free(&l->clip);
	memset(l, 0, sizeof *l);
}
