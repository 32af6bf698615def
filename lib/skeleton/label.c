/*
 * label.c: skeleton labeling and joint energy (paper 4.1.1 and 4.1.2).
 *
 * Labels, applied in the paper's order with hub factor f (1.9):
 *   1. depth 0                                           -> root (zeta)
 *   2. no children                                       -> end-effector (chi)
 *   3. neighbours > f * avg(neighbours), depth < avg(depth) -> major (psi)
 *   4. neighbours > f * avg(neighbours), depth > avg(depth) -> extreme (mu)
 *   5. otherwise                                         -> minor (kappa)
 * A hub whose depth equals the average exactly falls through to minor, as
 * the rules are written (mlod-label(1), Labels).
 *
 * Energy. The paper's sum over frames of R(b+1) - R(b) telescopes to the
 * net displacement, so we read it as the total variation of each unwrapped
 * Euler angle, normalised by the axis range Max(R^a) (pi without joint
 * limits), summed over the three axes and multiplied by the weight factor
 * (h - depth) / h, where h is the tree height (max depth + 1). A joint's
 * energy is its maximum over the clips.
 *
 * Euler angles are taken in each joint's own order (the BVH channel order;
 * XYZ for glTF joints). Uniformly sampled clips (BVH) use their frames;
 * glTF clips use their rotation key times when every rotation channel
 * shares them, and otherwise are sampled at ENERGY_RATE frames per second.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "skeleton/mlod_skeleton.h"

#define DEFAULT_HUB_FACTOR MLOD_LABEL_HUB_FACTOR_DEFAULT
#define ENERGY_RATE 30.0

static const char *const label_names[] = {"root", "end-effector", "major", "extreme", "minor"};
static const char *const label_symbols[] = {"\xce\xb6", "\xcf\x87", "\xcf\x88", "\xce\xbc", "\xce\xba"};

const char *mlod_label_name(mlod_label l)
{
	return (unsigned)l < 5 ? label_names[l] : "?";
}

const char *mlod_label_symbol(mlod_label l)
{
	return (unsigned)l < 5 ? label_symbols[l] : "?";
}

int mlod_label_parse(const char *s, mlod_label *out)
{
	for (int i = 0; i < 5; i++) {
		if (strcmp(s, label_names[i]) == 0 || strcmp(s, label_symbols[i]) == 0) {
			*out = (mlod_label)i;
			return 0;
		}
	}
	return -1;
}

/* The times at which a clip is sampled for energy; returns the count and
 * sets *times (malloc'ed), or -1 when out of memory. */
static int energy_times(const mlod_clip *clip, float **times)
{
	*times = NULL;
	/* A sampled clip: its frames. */
	if (clip->frame_time > 0.0f && clip->frame_count > 0)
		return mlod_clip_key_times(clip, NULL, 1, times, NULL);
	/* Rotation channels that share their key times: those. */
	if (clip->frame_time <= 0.0f) {
		unsigned char *rot = malloc((size_t)clip->channel_count + 1);
		if (!rot)
			return -1;
		for (int i = 0; i < clip->channel_count; i++)
			rot[i] = clip->channels[i].path == MLOD_PATH_ROTATION;
		int shared = 0, n = mlod_clip_key_times(clip, rot, 0, times, &shared);
		free(rot);
		if (n < 0 || (n > 0 && shared))
			return n;
		free(*times);
		*times = NULL;
	}
	/* Otherwise ENERGY_RATE frames per second. */
	double frames = floor((double)clip->duration * ENERGY_RATE) + 1.0;
	int n = frames > 1e7 ? 10000000 : frames < 1.0 ? 1 : (int)frames;
	*times = malloc(sizeof(float) * (size_t)n);
	if (!*times)
		return -1;
	for (int i = 0; i < n; i++)
		(*times)[i] = (float)(i / ENERGY_RATE);
	return n;
}

/* Adds each joint's total Euler variation over one clip into variation
 * (joint_count doubles, the sum over the three axes, in radians). */
static mlod_result clip_variation(const mlod_skeleton *s, const mlod_clip *clip,
                                  double *variation, mlod_error *err)
{
	int jn = s->joint_count;
	float *times = NULL;
	int frames = energy_times(clip, &times);
	mlod_trs *pose = malloc(sizeof *pose * (size_t)jn);
	float *prev = malloc(sizeof(float) * 3 * (size_t)jn);
	if (frames < 0 || !pose || !prev) {
		free(times);
		free(pose);
		free(prev);
		return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory sampling clip %s", MLOD_QUOTED(clip->name));
	}
	memset(variation, 0, sizeof(double) * (size_t)jn);
	for (int f = 0; f < frames; f++) {
		mlod_pose_rest(s, pose);
		mlod_clip_sample(clip, times[f], pose);
		for (int j = 0; j < jn; j++) {
			float e[3];
			mlod_quat_to_euler(s->joints[j].euler, pose[j].r, e);
			for (int a = 0; a < 3; a++) {
				if (f > 0)
					variation[j] += fabs(mlod_wrap_angle((double)e[a] - prev[3 * j + a]));
				prev[3 * j + a] = e[a];
			}
		}
	}
	free(times);
	free(pose);
	free(prev);
	return MLOD_OK;
}

mlod_result mlod_label_skeleton(const mlod_character *c, const mlod_label_options *opt,
                                mlod_joint_info *info, mlod_error *err)
{
	if (!c || !info)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_label_skeleton: NULL argument");
	const mlod_skeleton *s = &c->skeleton;
	int n = s->joint_count;
	if (n <= 0)
		return mlod_fail(err, MLOD_ERR_PARSE, "the skeleton has no joints");
	double hub = opt && opt->hub_factor > 0.0 ? opt->hub_factor : DEFAULT_HUB_FACTOR;
	double range = opt && opt->max_angle > 0.0 ? opt->max_angle : MLOD_PI;

	/* Topology: parents come before children, so one pass gives depths. */
	memset(info, 0, sizeof *info * (size_t)n);
	int max_depth = 0;
	for (int j = 0; j < n; j++) {
		int p = s->joints[j].parent;
		if (p >= j)
			return mlod_fail(err, MLOD_ERR_PARSE, "joint %d %s: parent %d does not come before it",
			                 j, MLOD_QUOTED(s->joints[j].name), p);
		if (p >= 0) {
			info[j].depth = info[p].depth + 1;
			info[p].children++;
		}
		if (info[j].depth > max_depth)
			max_depth = info[j].depth;
	}
	double avg_neighbors = 0.0, avg_depth = 0.0;
	for (int j = 0; j < n; j++) {
		info[j].neighbors = info[j].children + (s->joints[j].parent >= 0);
		avg_neighbors += info[j].neighbors;
		avg_depth += info[j].depth;
	}
	avg_neighbors /= n;
	avg_depth /= n;

	double h = max_depth + 1.0;
	for (int j = 0; j < n; j++) {
		mlod_joint_info *ji = &info[j];
		int hubby = ji->neighbors > hub * avg_neighbors;
		if (ji->depth == 0)
			ji->label = MLOD_LABEL_ROOT;
		else if (ji->children == 0)
			ji->label = MLOD_LABEL_END_EFFECTOR;
		else if (hubby && ji->depth < avg_depth)
			ji->label = MLOD_LABEL_MAJOR;
		else if (hubby && ji->depth > avg_depth)
			ji->label = MLOD_LABEL_EXTREME;
		else
			ji->label = MLOD_LABEL_MINOR;
		ji->weight = (h - ji->depth) / h;
	}

	/* Energy: maximum over clips. */
	double *variation = malloc(sizeof(double) * (size_t)n);
	if (!variation)
		return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
	for (int k = 0; k < c->clip_count; k++) {
		mlod_result r = clip_variation(s, &c->clips[k], variation, err);
		if (r != MLOD_OK) {
			free(variation);
			return r;
		}
		for (int j = 0; j < n; j++) {
			double e = info[j].weight * variation[j] / range;
			if (e > info[j].energy)
				info[j].energy = e;
		}
	}
	free(variation);
	return MLOD_OK;
}
