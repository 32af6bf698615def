/*
 * mlod_motion.h: the motion layer (paper 4.3): the common timeline
 * (timeline.c), the point error both methods answer to (pointerror.c), the
 * motion object (motion.c) and its levels (nextlevel.c): the
 * multiresolution motion tree (motiontree.c, the frames method of
 * framesmethod.c) and per-channel key reduction under a hierarchical
 * error bound (keyreduce.c, the keys method of keysmethod.c), their
 * values rounded (precision.c), morph target weight tracks
 * (morphweights.c), the levels of many clips on threads (levels.c), and
 * a character's levels as mlod-motion makes and writes them (bake.c).
 * Files call one way: bake.c calls levels.c and morphweights.c, levels.c
 * calls motion.c and nextlevel.c, which calls the two methods;
 * keysmethod.c calls keyreduce.c; all call pointerror.c and timeline.c.
 * motion_internal.h (internal) maps the files of the levels;
 * motion_eval.h (internal) holds the inline fast forms of sampling,
 * kinematics and the point error check that they and keyreduce.c
 * measure with.
 */
#ifndef MLOD_MOTION_H
#define MLOD_MOTION_H

#include "model/mlod_model.h"
#include "io/mlod_io.h"
#include "measure/mlod_measure.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ------------------------------------------------------------------ */
/* Motion layer: the multiresolution motion tree (paper 4.3)           */
/* ------------------------------------------------------------------ */

/* Levels of one clip. Level 0 is the clip as read; level k + 1 is coarser
 * than level k (fewer keys, a larger bound). Frame distances, thresholds
 * and the tree follow the paper; per-channel key reduction goes beyond it.
 * Error bounds apply to the point error (mlod_motion_point_error) of every
 * joint at every sample of the clip's common timeline (its frames and, by
 * default, the midpoints between them: mlod_motion_options.subdivide),
 * which bounds the world-space joint and End Site position error
 * (mlod_joint_deviation_at) against the clip as read, in scene units. */

/* How far any point within radius of a joint moves between world matrices
 * a and b: |origin(a) - origin(b)| + radius * sigma_max(A - B), A and B
 * their 3x3 parts (for a rotation error of angle t alone, 2 radius sin(t/2),
 * exact for the farthest point). */
double mlod_motion_point_error(const mlod_mat4 *a, const mlod_mat4 *b, double radius);

/* mlod_motion_point_error(w, w0, radius) <= budget, with early exits. */
int mlod_motion_point_within(const mlod_mat4 *w, const mlod_mat4 *w0, double radius, double budget);

typedef enum mlod_motion_method {
	MLOD_MOTION_FRAMES,  /* the paper's multiresolution motion tree: whole frames go */
	MLOD_MOTION_KEYS     /* per-channel key reduction under a hierarchical error bound */
} mlod_motion_method;

/* How the tree merges two neighbouring frames. */
typedef enum mlod_motion_merge {
	MLOD_MOTION_REMOVE,  /* keep one of the two as it is; the other is interpolated at play time */
	MLOD_MOTION_AVERAGE  /* one frame at their mean time with their mean pose (weighted by the frames each stands for) */
} mlod_motion_merge;

/* How a level's size is chosen. */
typedef enum mlod_motion_target {
	MLOD_MOTION_THRESHOLD, /* frames method only: merge neighbours closer than this frame distance */
	MLOD_MOTION_FRACTION,  /* keep at most this fraction (0..1] of the clip's keys */
	MLOD_MOTION_MAX_ERROR  /* the coarsest level whose joint position error is at most this (scene units) */
} mlod_motion_target;

/* How a level stores its key values (plain glTF in every case). */
typedef enum mlod_motion_precision {
	MLOD_MOTION_PRECISION_AUTO,  /* rotations on the lattice of normalised shorts (n / 32767, core
	                                glTF, 8 bytes a key), translations and scales float32 rounded to
	                                power-of-two grids: the coarsest that keep the level within its
	                                bound. First and last keys: translations and scales exact,
	                                rotations on the finest lattice (1/65534 per component). */
	MLOD_MOTION_PRECISION_FLOAT, /* every value float32 rounded to power-of-two grids (the low
	                                mantissa bits become zeros); first and last keys exact */
	MLOD_MOTION_PRECISION_FULL   /* values as read */
} mlod_motion_precision;

/* The default point distance: 10 cm in metres (glTF's unit) when metres
 * is set; otherwise, for a file in units of its own such as BVH, the
 * skeleton height / 18 (10 cm on a person 1.8 units tall; 1/18 for a
 * skeleton without joints). mlod-motion's default, and the benchmarks'. */
#define MLOD_POINT_DISTANCE_METRES 0.1
double mlod_motion_point_distance(const mlod_skeleton *s, int metres);

/* Zero-initialised options are the defaults. */
typedef struct mlod_motion_options {
	mlod_motion_merge merge;  /* frames method; MLOD_MOTION_REMOVE (the default) measured better */
	double cubic_rate;        /* CUBICSPLINE clips are resampled at least this often (1/s); 0 means 60 */
	double point_distance;    /* radius of the points carried by each joint for the point error
	                             (scene units); 0 means mlod_motion_point_distance(s, 0): the
	                             skeleton height / 18 */
	mlod_motion_precision precision; /* how a level's key values are stored (default auto) */
	double precision_share;   /* auto precision: the share of a max-error bound left to rounding,
	                             (0, 1); 0 means the default */
	int subdivide;            /* errors are checked at the frames of the common timeline and at
	                             subdivide - 1 evenly spaced times inside each interval between
	                             them (1: frames only; 0 means the default, 2: midpoints too) */
} mlod_motion_options;

#define MLOD_DEFAULT_SUBDIVIDE 2
#define MLOD_MAX_SUBDIVIDE 64

/* The sample times of a timeline of `frames` increasing times: frame f is
 * sample f * subdivide, with subdivide - 1 evenly spaced times after it
 * (before the next frame). out holds (frames - 1) * subdivide + 1 floats. */
void mlod_motion_sample_times(const float *times, int frames, int subdivide, float *out);

/* How a clip was put on a common timeline: every channel keyed at every
 * frame. A clip whose channels share their key times and are LINEAR or
 * STEP keeps its keys; otherwise the frames are the union of all key
 * times, and intervals longer than 1/cubic_rate get evenly spaced frames
 * when a channel is CUBICSPLINE (which becomes LINEAR). */
typedef struct mlod_motion_timeline {
	int frames;               /* frames of the common timeline */
	int resampled;            /* 0 when the clip's own keys were kept */
	int cubic_channels;       /* CUBICSPLINE channels, sampled as LINEAR */
	int mismatched_channels;  /* channels whose key times were not the common ones */
} mlod_motion_timeline;

/* Frame distance (paper 4.3): the energy to move every joint from local
 * pose a to local pose b, each joint weighted by the energy weight
 * (h - depth) / h of 4.1.2: the sum over joints of the weight times
 * (|change of each Euler angle| / pi, in the joint's Euler order, wrapped
 * into (-pi, pi], taking the nearer of the two Euler triples that give
 * the rotation, so q and -q and 179 -> -179 degrees are no motion) plus,
 * beyond the paper, |change of translation| / skeleton height and
 * |change of scale|, so root motion counts. */
double mlod_motion_frame_distance(const mlod_skeleton *s, const mlod_trs *a, const mlod_trs *b);

/* Puts clip on its common timeline (see mlod_motion_timeline): out gets
 * one channel per channel of clip, every one keyed at every frame, LINEAR
 * or STEP, rotations normalised and sign-continuous. A clip without
 * channels (an animation of no joint: a camera's, morph weights alone)
 * has a timeline of 0 frames; a motion of it (mlod_motion_create) has
 * nothing to reduce, and every level of it is the clip without channels,
 * no keys and no error. Release out with mlod_clip_free. Bad clips (no
 * keys, times not finite or negative or not increasing, values not
 * finite, zero quaternions) are MLOD_ERR_PARSE; too many frames is
 * MLOD_ERR_LIMIT. info may be NULL. */
mlod_result mlod_motion_common_clip(const mlod_clip *clip, const mlod_motion_options *opt,
                                    mlod_clip *out, mlod_motion_timeline *info, mlod_error *err);

/* Releases what a clip made by the library owns and zeroes it. */
void mlod_clip_free(mlod_clip *clip);

/* Keys in a clip (all channels), and the bytes glTF stores for them as
 * floats: values (three per key for CUBICSPLINE) plus key times, where
 * channels with identical times share one input accessor. */
long mlod_clip_key_count(const mlod_clip *clip);
long mlod_clip_key_bytes(const mlod_clip *clip);

/* The levels of one clip under construction; it keeps pointers to c. */
typedef struct mlod_motion mlod_motion;

mlod_result mlod_motion_create(const mlod_character *c, int clip, const mlod_motion_options *opt,
                               mlod_motion **out, mlod_error *err);
/* Another motion of first's clip with first's options (for the other
 * method), its setup (common timeline, the clip as read at every sample)
 * shared, read-only, instead of computed again or copied: the same as
 * mlod_motion_create with them; first may be freed before it (the last
 * of the motions sharing a setup to be freed frees it), and the motions
 * may run on different threads. */
mlod_result mlod_motion_create_like(const mlod_motion *first, mlod_motion **out, mlod_error *err);
void mlod_motion_free(mlod_motion *m);
/* The keys method's choice of keys runs on up to threads threads (default
 * 1, also for a motion made by mlod_motion_create_like); the levels are
 * the same at any count. */
void mlod_motion_set_threads(mlod_motion *m, int threads);
/* The clip's common timeline. */
const mlod_motion_timeline *mlod_motion_timeline_info(const mlod_motion *m);

/* One level of a clip. */
typedef struct mlod_motion_level {
	mlod_clip clip;           /* kept keys only, LINEAR or STEP (STEP where the source was); same
	                             name, duration, first and last key times as the source */
	mlod_motion_method method;
	double threshold;         /* frames: the frame distance threshold; keys: the error budget used */
	long keys;                /* mlod_clip_key_count(&clip) */
	long bytes;               /* mlod_clip_key_bytes(&clip) */
	mlod_deviation error;     /* joint position error against the source clip at the samples
	                             (frames and the times between them), scene units */
	double point_error;       /* the largest point error over joints and samples, scene units */
	double grid;              /* auto precision: the grid translations were rounded to (rotations
	                             and scales finer by their joint's reach), scene units; 0: none */
	int unfinished;           /* mlod_motion_next_level_under only: more bytes than its limit
	                             whatever the rounding; clip holds the kept keys unrounded,
	                             bytes the fewest it could store, errors are not measured; a
	                             frames level whose search stopped early (below) has no clip,
	                             and bytes are those of the line that stopped it */
} mlod_motion_level;

/* Builds the next level of a method: each level is made from the previous
 * level of the same method (nested: the frames method's levels are the
 * lines of the motion tree, the keys method's keep subsets of the previous
 * keys). target and value choose its size; with MLOD_MOTION_MAX_ERROR the
 * point error (so the joint position error too) is at most value, or
 * MLOD_ERR_LIMIT says why not (a resampled clip that already deviates
 * more). With auto precision the values are rounded within value (for
 * the other targets, within the error the level has before rounding) and
 * the errors are those after rounding. Release with mlod_motion_level_free. */
mlod_result mlod_motion_next_level(mlod_motion *m, mlod_motion_method method, mlod_motion_target target,
                                   double value, mlod_motion_level *out, mlod_error *err);
void mlod_motion_level_free(mlod_motion_level *l);

/* mlod_motion_next_level for a caller that keeps a level only if it has
 * fewer bytes than another (max_bytes; < 0: no limit): the keys are
 * chosen as there, and the method's next level builds on them, but a
 * level that would store more than max_bytes however its values are
 * rounded is left unfinished (mlod_motion_level.unfinished), which saves
 * the rounding and measuring. With MLOD_MOTION_MAX_ERROR, the frames
 * method also stops its search on the threshold as soon as a line it
 * rejects (too coarse for the bound) stores more than max_bytes: the
 * level would be a finer line, so larger (the tree's lines grow finer as
 * the threshold goes down). That level is left unfinished without keys,
 * and the method's next level builds on its last finished level. */
mlod_result mlod_motion_next_level_under(mlod_motion *m, mlod_motion_method method, mlod_motion_target target,
                                         double value, long max_bytes, mlod_motion_level *out, mlod_error *err);

/* mlod_motion_next_level with the keys method in two parts, for a caller
 * that rounds and measures a level on another thread while the next
 * level's keys are chosen: mlod_motion_keys_reduce chooses the keys (out
 * gets the clip of the kept keys, method and threshold; *known its
 * largest point error, or < 0 when not measured), on which m's next level
 * builds; mlod_motion_keys_finish then rounds and measures that level
 * with the same target, value and max_bytes as mlod_motion_next_level_under,
 * on m or on any motion of the same clip and options (it reads only their
 * setup), and frees it on a failure. The two give the level
 * mlod_motion_next_level_under gives. */
mlod_result mlod_motion_keys_reduce(mlod_motion *m, mlod_motion_target target, double value, mlod_motion_level *out,
                                    double *known, mlod_error *err);
mlod_result mlod_motion_keys_finish(mlod_motion *m, mlod_motion_target target, double value, long max_bytes,
                                    double known, mlod_motion_level *l, mlod_error *err);

/* The auto method's rule, in one place for mlod_motion_next_level_best
 * and the threaded builder: whether the method applies to the target (not
 * the keys method for MLOD_MOTION_THRESHOLD), and whether a level beats
 * the best so far (have: whether there is one): finished, and fewer bytes
 * or, on a tie, no larger error (the later method is met first, so a tie
 * goes to the earlier one). */
int mlod_motion_method_applies(mlod_motion_method method, mlod_motion_target target);
int mlod_motion_level_wins(const mlod_motion_level *l, const mlod_motion_level *best, int have);

/* The auto method's next level: the next level of each of the n motions
 * (one clip, methods[i] for m[i]; the keys method is skipped for a
 * MLOD_MOTION_THRESHOLD target) for the same target and value; the one
 * with fewer bytes wins, on a tie the smaller error, then the earlier
 * motion. The last runs first, so that the others stop early where they
 * cannot win (mlod_motion_next_level_under). When no method meets the
 * target: MLOD_ERR_LIMIT with the first method's reason. */
mlod_result mlod_motion_next_level_best(mlod_motion *const *m, const mlod_motion_method *methods, int n,
                                        mlod_motion_target target, double value, mlod_motion_level *out,
                                        mlod_error *err);

/* One level asked for: its target and value (as mlod_motion_next_level). */
typedef struct mlod_motion_spec {
	mlod_motion_target target;
	double value;
} mlod_motion_spec;

/* The levels of one clip (mlod_motion_build_levels). */
typedef struct mlod_motion_clip_levels {
	mlod_result result;       /* MLOD_OK, or why the clip's motions could not be made (error) */
	mlod_error error;
	mlod_motion_timeline timeline;
	int level_count;          /* levels tried, in spec order: 0 for a clip of fewer than 3 frames
	                             (nothing to reduce, also a clip without channels: 0 frames); a
	                             failure other than MLOD_ERR_LIMIT ends them */
	mlod_motion_level *levels; /* level_count; those whose result is MLOD_OK are set */
	mlod_result *results;     /* per level: MLOD_OK, MLOD_ERR_LIMIT (no method meets the target) or
	                             the failure that ended the levels */
	mlod_error *errors;       /* per level: why, when not MLOD_OK */
} mlod_motion_clip_levels;

/* The levels of clips[0..clip_count) of c, out[k] for clips[k]: for each
 * clip, mlod_motion_create with opt for each of the method_count (1 or 2)
 * methods, then for each spec in order the level
 * mlod_motion_next_level_best makes. Clips run on up to `threads`
 * threads; with fewer clips than threads, a clip's keys method chooses
 * its keys on threads of its own while another thread rounds and
 * measures them and builds the other method's levels (levels.c); the
 * levels do not depend on the thread count. Returns MLOD_OK (each clip's outcome is in out[k]) or
 * MLOD_ERR_NOMEM / MLOD_ERR_INVALID_ARG. Release out with
 * mlod_motion_clip_levels_free (levels taken over by the caller are to be
 * zeroed, or their results set to other than MLOD_OK). */
mlod_result mlod_motion_build_levels(const mlod_character *c, const int *clips, int clip_count,
                                     const mlod_motion_options *opt, const mlod_motion_method *methods,
                                     int method_count, const mlod_motion_spec *specs, int spec_count, int threads,
                                     mlod_motion_clip_levels *out, mlod_error *err);
void mlod_motion_clip_levels_free(mlod_motion_clip_levels *out, int count);

/* A character's motion levels as mlod-motion(1) makes them (bake.c). */

/* One level of a clip, with its measures and morph weights channels. */
typedef struct mlod_motion_bake_level {
	mlod_motion_target target;
	double value;             /* as asked (scene units for a max error) */
	double bound;             /* a max-error level's bound, else -1 */
	int ok;                   /* 0: no method made it (a note says why) */
	mlod_motion_level l;
	int has_vertex;           /* the character has meshes: vertex is set */
	mlod_deviation vertex;    /* skinned-vertex error (mlod_vertex_deviation): % of the diagonal */
	mlod_weight_track *w;     /* the level's morph weights channels (w_count) */
	int w_count;
	int w_copied;             /* tracks kept as they are (CUBICSPLINE, or no mesh to measure) */
	double w_bound;           /* scene units: the level's bound, or its joint error without one */
	double w_error;           /* the largest vertex displacement bound of the reduced tracks */
	long w_keys, w_bytes;
} mlod_motion_bake_level;

typedef struct mlod_motion_bake_clip {
	int index;                /* the character's clip */
	int frames;               /* of its common timeline */
	mlod_motion_timeline timeline;
	long keys, bytes;         /* as read: joint channels and morph weights */
	mlod_weight_track *w;     /* its morph weights channels as read (glTF input) */
	int w_count;
	long w_keys;
	int level_count;
	mlod_motion_bake_level *levels;
} mlod_motion_bake_clip;

typedef struct mlod_motion_bake {
	int clip_count;
	mlod_motion_bake_clip *clips;
	int note_count;
	char **notes;             /* what to tell the user, in order: clips with nothing to reduce
	                             (fewer than 3 frames, or no joint channels: kept as they are),
	                             levels no method makes (the caller prints them); names in them
	                             are quoted and escaped (mlod_name_text) */
} mlod_motion_bake;

typedef struct mlod_motion_bake_options {
	mlod_motion_options motion;
	const mlod_motion_method *methods; /* 1 or 2 (mlod_motion_build_levels) */
	int method_count;
	const mlod_motion_spec *specs;     /* the levels, finer first */
	int spec_count;
	int threads;
	int vertex_samples;       /* times per clip for the skinned-vertex error */
} mlod_motion_bake_options;

/* The levels of clips[0..clip_count) of c (mlod_motion_build_levels),
 * each level's skinned-vertex error (when c has meshes) and, with doc
 * (the glTF c was read from, or NULL), its morph weights channels reduced
 * within the level's bound (mlod_weight_track_reduce). Threads as there;
 * the result does not depend on their number. Returns MLOD_OK, or the
 * failure a run one clip and level after another meets first, with the
 * notes before it in out. Release out with mlod_motion_bake_free, in
 * either case. */
mlod_result mlod_motion_bake_run(const mlod_character *c, const mlod_gltf *doc, const int *clips, int clip_count,
                                 const mlod_motion_bake_options *o, mlod_motion_bake *out, mlod_error *err);
void mlod_motion_bake_free(mlod_motion_bake *b);

/* What the reports say besides the levels. */
typedef struct mlod_motion_report_info {
	const char *input;        /* the input's name */
	double height;            /* the skeleton height */
	double point_distance;
	int subdivide;
	mlod_motion_precision precision;
} mlod_motion_report_info;

/* The report of a bake of c as a table or as JSON: *text, released with
 * free(). Names (info->input, the clips') in the table with
 * mlod_name_text's C escapes; in the JSON as JSON strings, a byte that
 * is not UTF-8 as U+FFFD. */
mlod_result mlod_motion_bake_table(const mlod_motion_bake *b, const mlod_character *c,
                                   const mlod_motion_report_info *info, char **text, mlod_error *err);
mlod_result mlod_motion_bake_json(const mlod_motion_bake *b, const mlod_character *c,
                                  const mlod_motion_report_info *info, char **text, mlod_error *err);

/* For a resampled clip (b->clips[k]): 1 and how, into buf; else 0. */
int mlod_motion_bake_timeline_note(const mlod_motion_bake *b, int k, char *buf, size_t size);

/* Adds each level to doc as an animation "<clip>@lod<k>" (the level's
 * clip takes that name) with its morph weights channels and its stage
 * record (mlod_record_write_motion; height and subdivide as the bake's). */
mlod_result mlod_motion_bake_to_gltf(mlod_motion_bake *b, const mlod_character *c, mlod_gltf *doc, double height,
                                     int subdivide, mlod_error *err);

/* A BVH of c's clip `clip` with the keys of use (NULL: the clip itself),
 * at the clip's own frame time, else at the mean spacing of its `frames`
 * common frames (0: of its key times). *text released with mlod_free. */
mlod_result mlod_motion_bvh(const mlod_character *c, int clip, const mlod_clip *use, int frames, char **text,
                            size_t *size, mlod_error *err);

/* Morph target weights of a level (beyond the paper). A weight error dw on
 * a target moves a vertex by dw times that target's offset there, so a
 * track's error at a time is the sum over its targets of |dw| times the
 * target's reach: its largest vertex offset, in scene units, on the node's
 * mesh as placed (rigidly or skinned) in the rest pose. */

/* The reach of each of the `targets` morph targets of the mesh instance on
 * glTF node `node` into out. MLOD_ERR_INVALID_ARG when no instance of c is
 * on that node or its mesh has another number of targets. */
mlod_result mlod_morph_target_reach(const mlod_character *c, int node, int targets, double *out, mlod_error *err);

/* Reduces a LINEAR or STEP weight track: out gets the keys it needs so
 * that, at every key time of in and subdivide - 1 evenly spaced times
 * between each two, the error (above) is at most bound; the first and last
 * keys stay (one key for a track that comes down to a constant), and kept
 * keys keep their values. *error gets the largest
 * error at those times. CUBICSPLINE tracks are MLOD_ERR_UNSUPPORTED.
 * out's times and values are released with free(). */
mlod_result mlod_weight_track_reduce(const mlod_weight_track *in, const double *reach, double bound, int subdivide,
                                     mlod_weight_track *out, double *error, mlod_error *err);

/* Keys and glTF bytes of weight tracks: each key stores targets floats
 * (three times as many for CUBICSPLINE) and a time, which tracks with
 * identical times share. */
long mlod_weight_tracks_keys(const mlod_weight_track *tracks, int count);
long mlod_weight_tracks_bytes(const mlod_weight_track *tracks, int count);

/* Per-channel key reduction under a hierarchical error bound (beyond the
 * paper; the metric of ozz-animation's optimizer and ACL's virtual
 * vertices). common is original on its common timeline
 * (mlod_motion_common_clip). kept holds channel_count * frames flags
 * (channel-major): on entry the keys that may stay (each channel keeps its
 * first frame, and its last unless it is a single key), on return those
 * kept. A key goes only if, at every sample (mlod_motion_sample_times:
 * the frames and subdivide - 1 times between each two, 1 to
 * MLOD_MAX_SUBDIVIDE), every joint's world origin stays within bound of
 * the original, and so does every point within point_distance of it (and
 * its End Site); tracks that then fit a constant collapse to one key. */
mlod_result mlod_keyreduce(const mlod_skeleton *s, const mlod_clip *original, const mlod_clip *common,
                           double bound, double point_distance, int subdivide, unsigned char *kept,
                           mlod_error *err);

/* Whether the keys method (mlod_keyreduce) takes a clip of frames frames on
 * its common timeline, named name, over joint_count joints at subdivide
 * samples per interval: its caches hold every sample of every joint
 * (about 230 bytes each), at most MLOD_KEYREDUCE_MAX_SAMPLES of them.
 * MLOD_OK, or MLOD_ERR_LIMIT with why in err ("split the clip"); past it
 * a clip's levels come from the frames method alone, larger. */
#define MLOD_KEYREDUCE_MAX_SAMPLES 1000000L
mlod_result mlod_motion_keys_fit(int joint_count, int frames, int subdivide, const char *name, mlod_error *err);


#ifdef __cplusplus
}
#endif

#endif /* MLOD_MOTION_H */
