/*
 * keytimes.c: the one place that builds a clip's timeline from its keys:
 * the key times of some of its channels merged, sorted and each once, or
 * the frames of a sampled clip. Every timeline in mlod starts here: the
 * energy times of mlod_label, the folded keys of a skeleton level, the
 * measurement times of mlod_clip_times and the common timeline of the
 * motion layer each add only their own policy.
 */
#include <limits.h>
#include <stdlib.h>
#include <string.h>

#include "model/mlod_model.h"

static int float_order(const void *a, const void *b)
{
	float x = *(const float *)a, y = *(const float *)b;
	return (x > y) - (x < y);
}

int mlod_clip_key_times(const mlod_clip *clip, const unsigned char *use, int frames, float **times, int *shared)
{
	*times = NULL;
	if (shared)
		*shared = 1;
	if (!clip)
		return 0;
	if (frames && clip->frame_time > 0.0f && clip->frame_count > 0) {
		float *t = malloc(sizeof(float) * (size_t)clip->frame_count);
		if (!t)
			return -1;
		for (int i = 0; i < clip->frame_count; i++)
			t[i] = (float)i * clip->frame_time;
		*times = t;
		return clip->frame_count;
	}
	long total = 0;
	const mlod_channel *first = NULL;
	for (int i = 0; i < clip->channel_count; i++) {
		const mlod_channel *ch = &clip->channels[i];
		if (use && !use[i])
			continue;
		total += ch->key_count;
		if (!first)
			first = ch;
		else if (shared && (ch->key_count != first->key_count ||
		                    memcmp(ch->times, first->times, sizeof(float) * (size_t)ch->key_count) != 0))
			*shared = 0;
	}
	if (total == 0)
		return 0;
	if (total > INT_MAX)
		return -1;
	float *t = malloc(sizeof(float) * (size_t)total);
	if (!t)
		return -1;
	long n = 0;
	for (int i = 0; i < clip->channel_count; i++) {
		if (use && !use[i])
			continue;
		memcpy(t + n, clip->channels[i].times, sizeof(float) * (size_t)clip->channels[i].key_count);
		n += clip->channels[i].key_count;
	}
	qsort(t, (size_t)n, sizeof *t, float_order);
	long m = 0;
	for (long i = 0; i < n; i++)
		if (m == 0 || t[i] != t[m - 1])
			t[m++] = t[i];
	*times = t;
	return (int)m;
}
