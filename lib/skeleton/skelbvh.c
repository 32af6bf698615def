/*
 * skelbvh.c: what a BVH of a character cannot hold. BVH has no scale
 * channel. mlod_bvh_write puts every joint where the character does (a
 * joint's BVH frame is the rigid part of its world transform, and a joint
 * whose offset changes gets position channels), but an End Site is a
 * fixed OFFSET in its joint's frame, written from the rest pose: under a
 * scale that changes (a glTF scale channel), or a non-uniform one above a
 * joint that turns, it is not where the character places it.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "skeleton/mlod_skeleton.h"

/* The rigid frame (rotation, origin) of world matrix m: as mlod_bvh_write
 * takes it; 0 when m is singular. */
static int rigid_frame(const mlod_mat4 *m, mlod_quat *r, mlod_v3 *p)
{
	mlod_trs trs;
	if (mlod_mat4_to_trs(m, &trs, 1e-4f) < 0)
		return 0;
	*r = mlod_quat_normalize(trs.r);
	*p = (mlod_v3){ m->m[12], m->m[13], m->m[14] };
	return 1;
}

/* End Site e of a joint at world m, placed by its rigid frame at offset
 * off, against m * e. */
static double end_site_distance(const mlod_mat4 *m, mlod_v3 e, mlod_v3 off)
{
	mlod_quat r;
	mlod_v3 p;
	if (!rigid_frame(m, &r, &p))
		return 0.0;
	mlod_v3 bvh = mlod_v3_add(p, mlod_quat_rotate(r, off));
	return mlod_v3_length(mlod_v3_sub(bvh, mlod_mat4_point(m, e)));
}

/* Whether v is (1, 1, 1) to 1e-6. */
static int unit(mlod_v3 v)
{
	return fabs(v.x - 1.0) <= 1e-6 && fabs(v.y - 1.0) <= 1e-6 && fabs(v.z - 1.0) <= 1e-6;
}

/* Whether any scale is not 1: a joint's rest scale, a root's base (its
 * columns' lengths), or a scale channel of the clip. Without one every
 * End Site is where the BVH puts it, by construction. */
static int scaled(const mlod_character *c, int clip)
{
	const mlod_skeleton *s = &c->skeleton;
	for (int j = 0; j < s->joint_count; j++) {
		const mlod_joint *jt = &s->joints[j];
		const float *m = jt->base.m;
		mlod_v3 cols = { (float)sqrt((double)m[0] * m[0] + (double)m[1] * m[1] + (double)m[2] * m[2]),
		                 (float)sqrt((double)m[4] * m[4] + (double)m[5] * m[5] + (double)m[6] * m[6]),
		                 (float)sqrt((double)m[8] * m[8] + (double)m[9] * m[9] + (double)m[10] * m[10]) };
		if (!unit(jt->rest.s) || (jt->parent < 0 && !unit(cols)))
			return 1;
	}
	const mlod_clip *cl = &c->clips[clip];
	for (int i = 0; i < cl->channel_count; i++)
		if (cl->channels[i].path == MLOD_PATH_SCALE)
			return 1;
	return 0;
}

mlod_result mlod_skel_bvh_end_sites(const mlod_character *c, int clip, double *max, int *joint, char *note,
                                    size_t note_size, mlod_error *err)
{
	if (!c || !max || !joint || (note && note_size == 0))
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_skel_bvh_end_sites: bad arguments");
	*max = 0.0;
	*joint = -1;
	if (note)
		note[0] = '\0';
	const mlod_skeleton *s = &c->skeleton;
	int n = s->joint_count, any = 0;
	for (int j = 0; j < n; j++)
		any |= s->joints[j].has_end_site;
	if (!any || clip < 0 || clip >= c->clip_count || !scaled(c, clip))
		return MLOD_OK; /* the rest pose (the OFFSETs are its places), or no scale */
	mlod_trs *local = malloc(sizeof *local * (size_t)n);
	mlod_mat4 *world = malloc(sizeof *world * (size_t)n);
	mlod_v3 *off = malloc(sizeof *off * (size_t)n);
	float *times = NULL;
	int count = mlod_clip_times(&c->clips[clip], 0, &times);
	if (!local || !world || !off || count < 0) {
		free(local);
		free(world);
		free(off);
		mlod_free(times);
		return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
	}
	/* The OFFSETs written: each End Site's place in the rest pose's rigid frame. */
	mlod_pose_rest(s, local);
	mlod_pose_world(s, local, world);
	for (int j = 0; j < n; j++) {
		mlod_quat r;
		mlod_v3 p;
		off[j] = s->joints[j].end_site;
		if (s->joints[j].has_end_site && rigid_frame(&world[j], &r, &p))
			off[j] = mlod_quat_rotate(mlod_quat_conjugate(r), mlod_v3_sub(mlod_mat4_point(&world[j], off[j]), p));
	}
	for (int f = 0; f < (count > 0 ? count : 1); f++) {
		mlod_pose_rest(s, local);
		mlod_clip_sample(&c->clips[clip], times ? times[f] : 0.0f, local);
		mlod_pose_world(s, local, world);
		for (int j = 0; j < n; j++) {
			if (!s->joints[j].has_end_site)
				continue;
			double d = end_site_distance(&world[j], s->joints[j].end_site, off[j]);
			if (d > *max)
				*max = d, *joint = j;
		}
	}
	free(local);
	free(world);
	free(off);
	mlod_free(times);
	/* Beyond float rounding (mlod_bvh_write's tolerance is 1e-6 of it). */
	double extent = mlod_skeleton_extent(s), height = mlod_skeleton_height(s);
	if (note && *joint >= 0 && *max > 1e-5 * extent)
		snprintf(note, note_size,
		         "clip %s: BVH has no scale channel: the joints keep their places, but End Sites under a scale do "
		         "not follow it (joint %s's End Site is off by up to %.4g, %.3g%% of the height)",
		         MLOD_QUOTED(c->clips[clip].name), MLOD_QUOTED(s->joints[*joint].name), *max,
		         height > 0.0 ? 100.0 * *max / height : 0.0);
	return MLOD_OK;
}
