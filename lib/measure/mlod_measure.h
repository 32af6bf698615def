/*
 * mlod_measure.h: measurement: surface deviation between posed meshes, posed error
 * of a level over a pose set, and skinned-vertex and joint deviation of a
 * level against the full character over its clips.
 */
#ifndef MLOD_MEASURE_H
#define MLOD_MEASURE_H

#include "model/mlod_model.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Surface deviation between two posed meshes: each vertex and triangle
 * centroid of either mesh is projected to the nearest point of the other
 * surface. mean and max are percentages of the bounding-box diagonal of a. */
typedef struct mlod_deviation {
	double mean;
	double max;
	double scale; /* the length mean and max are percentages of; 0 when they are in scene units */
} mlod_deviation;

mlod_result mlod_surface_deviation(const mlod_posed *a, const mlod_posed *b,
                                   mlod_deviation *out, mlod_error *err);

/* ------------------------------------------------------------------ */
/* Comparing a level against the full character                       */
/* ------------------------------------------------------------------ */

/* The times at which a clip is measured: every frame of a sampled clip, or
 * the union of its key times, thinned evenly to at most max_samples (0: no
 * limit) and always keeping the first and last. *times is released with
 * mlod_free. Returns the count, or -1 when out of memory. */
int mlod_clip_times(const mlod_clip *clip, int max_samples, float **times);

/* Skinned-vertex deviation: a and b have the same meshes, instances and
 * clips (b is a level of a that changed only skeleton, weights or keys).
 * At each measured time of each clip (up to max_samples per clip), every
 * posed vertex of b is compared with the same vertex of a. mean and max
 * are percentages of the bounding-box diagonal of a in its rest pose. A
 * character without clips is measured in the rest pose. */
mlod_result mlod_vertex_deviation(const mlod_character *a, const mlod_character *b, int max_samples,
                                  mlod_deviation *out, mlod_error *err);

/* Joint position deviation, in scene units: the world position of every
 * joint j of a (and of its End Site) against the same point carried by b.
 * stand_in[j] is the joint of a whose counterpart in b carries j rigidly,
 * with their relative transform from a's rest pose (NULL: j itself);
 * a_to_b[k] is the joint of b that is a's joint k (NULL: the same index).
 * For a skeleton level these are the level's remap and the renumbering. */
mlod_result mlod_joint_deviation(const mlod_character *a, const mlod_character *b, const int *stand_in,
                                 const int *a_to_b, int max_samples, mlod_deviation *out, mlod_error *err);
/* The same (joints matched by index) at the count given times of every
 * clip instead of the clips' own times. */
mlod_result mlod_joint_deviation_at(const mlod_character *a, const mlod_character *b, const float *times, int count,
                                    mlod_deviation *out, mlod_error *err);

/* A set of poses as joint world matrices: count poses of joint_count
 * matrices each (pose k at world + k * joint_count). */
typedef struct mlod_pose_set {
	int count;
	int joint_count;
	mlod_mat4 *world;
} mlod_pose_set;

/* Builds a pose set: the rest pose when bind is set, up to per_clip
 * evenly spaced times of each clip (mlod_clip_times), and `random` poses
 * where each joint's rest rotation is turned about a random axis by a
 * random angle of at most max_angle radians (a fixed generator seeded
 * with seed, so the same arguments give the same poses). */
mlod_result mlod_pose_set_make(const mlod_character *c, int bind, int per_clip, int random, uint64_t seed,
                               float max_angle, mlod_pose_set *out, mlod_error *err);
void mlod_pose_set_free(mlod_pose_set *s);

/* Posed surface error of a level against the full character: at every
 * pose, mlod_surface_deviation of the posed level against the posed full
 * character; mean is the mean over poses of the mean, max the largest max
 * (Hausdorff), both in % of the full character's diagonal in that pose. */
mlod_result mlod_posed_error(const mlod_character *full, const mlod_character *level, const mlod_pose_set *poses,
                             mlod_deviation *out, mlod_error *err);


#ifdef __cplusplus
}
#endif

#endif /* MLOD_MEASURE_H */
