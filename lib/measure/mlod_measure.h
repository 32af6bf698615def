/*
 * mlod_measure.h: measurement: surface deviation between posed meshes, posed error
 * of a level over a pose set, and skinned-vertex and joint deviation of a
 * level against the full character over its clips; the search for levels
 * within an error bound and the screen coverage an error allows, which the
 * skeleton and mesh layers share.
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
	int threads;      /* mlod_posed_error measures poses on this many threads
	                   * (0 or 1: the caller's only); the same result at any count */
	struct mlod_pose_cache *cache; /* made by mlod_pose_set_make (NULL in a set made
	                   * by hand: nothing is kept); mlod_posed_error keeps the full
	                   * character posed at each pose with its search hierarchy there,
	                   * for later calls with the same full character */
} mlod_pose_set;

/* Builds a pose set: the rest pose when bind is set, up to per_clip
 * evenly spaced times of each clip (mlod_clip_times), and `random` poses
 * where each joint's rest rotation is turned about a random axis by a
 * random angle of at most max_angle radians (a fixed generator seeded
 * with seed, so the same arguments give the same poses). */
mlod_result mlod_pose_set_make(const mlod_character *c, int bind, int per_clip, int random, uint64_t seed,
                               float max_angle, mlod_pose_set *out, mlod_error *err);
void mlod_pose_set_free(mlod_pose_set *s);

/* With on set, mlod_posed_error on a set made by mlod_pose_set_make
 * searches the nearest point at the poses after the first only for the
 * samples that may raise the max: the same max, to the bit, and a mean
 * at least the exact one (see there). Off (as made): every sample
 * searched. Does nothing to a set made by hand. */
void mlod_pose_set_bound_mean(mlod_pose_set *s, int on);

/* Posed surface error of a level against the full character: at every
 * pose, mlod_surface_deviation of the posed level against the posed full
 * character; mean is the mean over poses of the mean, max the largest max
 * (Hausdorff), both in % of the full character's diagonal in that pose.
 * With mlod_pose_set_bound_mean on, the first pose is measured so and records
 * each sample's nearest triangle; at the other poses a sample's distance
 * to that triangle (an upper bound of its distance to the surface) stands
 * for it, and the search runs only when that bound exceeds both the first
 * pose's max (as a fraction of the diagonal) and the largest distance
 * searched so far at that pose: a sample left unsearched cannot raise the
 * max. So max is the same, bit for bit, and mean at least the exact one
 * (and equal where the recorded triangle is still the nearest); both are
 * the same at any thread count.
 * With a pose set from mlod_pose_set_make, the first call keeps the posed
 * full character of each pose and its hierarchy in the set's cache, and
 * later calls whose full character poses to the same bytes there reuse
 * them (the levels of one character): the same results, to the bit. Calls
 * may run at once on one set. */
mlod_result mlod_posed_error(const mlod_character *full, const mlod_character *level, const mlod_pose_set *poses,
                             mlod_deviation *out, mlod_error *err);

/* mlod_posed_error of count levels of one full character, into out[0 ..
 * count): the same results, to the bit, as one call per level, with the
 * work spread over the levels and poses (poses->threads threads: the
 * levels' first poses, then every other pose of every level). On a
 * failure, the first failing level and pose in that order, of those
 * measured, is reported. */
mlod_result mlod_posed_errors(const mlod_character *full, const mlod_character *const *levels, int count,
                              const mlod_pose_set *poses, mlod_deviation *out, mlod_error *err);

/* Keeps full posed at pose k of s (a set from mlod_pose_set_make), with
 * its search hierarchy for pose 0, as the first mlod_posed_error measuring
 * it would; and so declares that full does not change while s lives:
 * mlod_posed_error with this full character (the same pointer) then takes
 * the kept pose without posing it again. Poses may be kept in any order,
 * on several threads at once, and while other work runs (mlod_mesh's
 * levels keep them during the collapses); the results are the same. A
 * pose already kept for another character stays so (and full is then
 * posed at each call). Nothing is kept in a set made by hand. */
mlod_result mlod_pose_set_keep(const mlod_pose_set *s, const mlod_character *full, int k, mlod_error *err);

/* Frees what s keeps (the posed full characters and their hierarchies,
 * those of mlod_pose_set_keep too): a later mlod_posed_error poses and
 * keeps them again, with the same results. Not while another call uses s. */
void mlod_pose_set_forget(const mlod_pose_set *s);


/* ------------------------------------------------------------------ */
/* Levels within an error bound (bound.c)                              */
/* ------------------------------------------------------------------ */

/* Screen coverage: a level shows while its error stays within
 * MLOD_COVERAGE_PIXELS pixels on a screen MLOD_COVERAGE_LINES high. */
#define MLOD_COVERAGE_LINES 1080.0
#define MLOD_COVERAGE_PIXELS 1.0

/* The largest screen coverage (fraction of the screen height covered by
 * the character) at which an error of error_percent of the character's
 * size stays within pixel_budget pixels on a screen screen_pixels high;
 * at most 1, and 0 for no error. */
double mlod_error_coverage(double error_percent, double screen_pixels, double pixel_budget);

/* MSFT_screencoverage for count levels of errors error_percent (finest
 * first): count + 1 values, the full mesh's first, made non-increasing,
 * the last 0. */
void mlod_lod_coverage(const double *error_percent, int count, float *coverage);

/* The search both the skeleton and the mesh layer use for levels within a
 * bound: the candidate parameters are tried in order, coarser and
 * coarser, each level kept while its error stays within the bound; at the
 * first one beyond it, the parameter is bisected between it and the last
 * one kept (at first `start`), and the coarsest level within the bound
 * found there ends the chain. */
typedef struct mlod_level_search {
	const double *candidates;
	int count;
	double start;        /* the parameter of the level before the first (the full one) */
	int whole;           /* bisect over whole numbers until they are neighbours; else `bisections` halvings */
	int bisections;
	double bound;
	void *ctx;
	/* Makes the level at x: MLOD_OK with its error in *error, or an
	 * error. For a candidate of the chain (chain set) it may instead
	 * return 1, without a level, when that brings nothing over the last
	 * level kept: the chain then ends. */
	mlod_result (*make)(void *ctx, double x, int chain, void **level, double *error, mlod_error *err);
	/* Keeps a level: 1, or 0 when it refuses it (and drops it itself);
	 * the chain ends on a refusal. */
	int (*keep)(void *ctx, void *level);
	void (*drop)(void *ctx, void *level);
} mlod_level_search;

mlod_result mlod_level_search_run(const mlod_level_search *s, mlod_error *err);

#ifdef __cplusplus
}
#endif

#endif /* MLOD_MEASURE_H */
