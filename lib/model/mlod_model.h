/*
 * mlod_model.h: the character model: skeleton, skins, meshes, instances and
 * clips as every reader produces them and every layer consumes them, with
 * pose evaluation and linear blend skinning (pose.c), lifetime, invariants
 * and the skeleton height (character.c), clip timelines (keytimes.c) and
 * the rule for skin weights glTF does not allow (weights.c).
 *
 * - Objects the library allocates are released with the matching *_free
 *   call, which accepts NULL. Plain buffers it returns are released with
 *   mlod_free().
 * - Joints of an mlod_skeleton are ordered so that a parent always comes
 *   before its children (parent index < child index). Readers establish
 *   this; everything else relies on it.
 */
#ifndef MLOD_MODEL_H
#define MLOD_MODEL_H

#include "mlod_core.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ------------------------------------------------------------------ */
/* Character model                                                     */
/* ------------------------------------------------------------------ */

/* BVH channel codes, in the order a BVH file lists them. */
typedef enum mlod_bvh_channel {
	MLOD_BVH_XPOS, MLOD_BVH_YPOS, MLOD_BVH_ZPOS,
	MLOD_BVH_XROT, MLOD_BVH_YROT, MLOD_BVH_ZROT
} mlod_bvh_channel;

typedef struct mlod_joint {
	char *name;               /* never NULL; may be "" */
	int parent;               /* joint index, or -1 for a root */
	mlod_trs rest;            /* local rest transform (glTF node TRS, or BVH OFFSET) */
	mlod_mat4 base;           /* roots only: world transform of the non-joint ancestors; identity otherwise */
	int node;                 /* glTF node index, or -1 (BVH) */
	/* BVH layout, kept so a BVH round-trips. channel_count is 0 for glTF joints. */
	int channel_count;        /* 0, 3 or 6 */
	unsigned char channels[6];/* mlod_bvh_channel codes in file order */
	mlod_euler_order euler;   /* rotation order implied by the channels (XYZ when none) */
	int has_end_site;         /* BVH "End Site" below this joint */
	mlod_v3 end_site;         /* its OFFSET */
} mlod_joint;

/* A glTF skin: a list of joints with their inverse bind matrices.
 * Vertex joint indices in primitives skinned by it index this list. */
typedef struct mlod_skin {
	char *name;
	int joint_count;
	int *joints;              /* indices into mlod_skeleton.joints */
	mlod_mat4 *inverse_bind;  /* joint_count matrices */
	int gltf_index;           /* glTF skin index, or -1 */
} mlod_skin;

typedef struct mlod_skeleton {
	int joint_count;
	mlod_joint *joints;
	int skin_count;
	mlod_skin *skins;
} mlod_skeleton;

#define MLOD_MAX_SETS 8

typedef struct mlod_morph_target {
	float *positions;  /* 3 * vertex_count deltas, or NULL */
	float *normals;    /* 3 * vertex_count deltas, or NULL */
	float *tangents;   /* 3 * vertex_count deltas, or NULL */
} mlod_morph_target;

/* One glTF primitive with its attributes decoded to floats. */
typedef struct mlod_primitive {
	int vertex_count;
	float *positions;                 /* 3 * vertex_count */
	float *normals;                   /* 3 * vertex_count, or NULL */
	float *tangents;                  /* 4 * vertex_count, or NULL */
	int uv_set_count;
	float *uvs[MLOD_MAX_SETS];        /* 2 * vertex_count each */
	int color_set_count;
	float *colors[MLOD_MAX_SETS];     /* 4 * vertex_count each (RGB gets alpha 1) */
	int weight_set_count;             /* sets of 4 influences (JOINTS_n/WEIGHTS_n) */
	uint16_t *joints[MLOD_MAX_SETS];  /* 4 * vertex_count each; skin-local indices */
	float *weights[MLOD_MAX_SETS];    /* 4 * vertex_count each */
	int index_count;                  /* 0 when not indexed */
	uint32_t *indices;
	int mode;                         /* glTF mode: 4 = triangles */
	int material;                     /* glTF material index, or -1 */
	int target_count;
	mlod_morph_target *targets;
} mlod_primitive;

typedef struct mlod_mesh {
	char *name;
	int primitive_count;
	mlod_primitive *primitives;
	int gltf_index;                   /* glTF mesh index, or -1 */
} mlod_mesh;

/* A mesh placed in the scene by a node. A skinned instance follows its
 * skin; a rigid one follows the joint it hangs under (joint >= 0), with
 * offset its rest transform relative to that joint; otherwise offset is
 * its world transform. */
typedef struct mlod_instance {
	int mesh;                 /* index into mlod_character.meshes */
	int node;                 /* glTF node index, or -1 */
	int skin;                 /* index into skeleton.skins, or -1 */
	int joint;                /* rigid attachment joint, or -1 */
	mlod_mat4 offset;
} mlod_instance;

typedef enum mlod_path { MLOD_PATH_TRANSLATION, MLOD_PATH_ROTATION, MLOD_PATH_SCALE } mlod_path;
typedef enum mlod_interp { MLOD_INTERP_LINEAR, MLOD_INTERP_STEP, MLOD_INTERP_CUBICSPLINE } mlod_interp;

/* One animated property of one joint. values holds comps floats per key
 * (3 for translation and scale, 4 for a rotation quaternion); for
 * CUBICSPLINE it holds 3 * comps per key: in-tangent, value, out-tangent. */
typedef struct mlod_channel {
	int joint;
	mlod_path path;
	mlod_interp interp;
	int key_count;
	float *times;     /* key_count, strictly increasing, seconds */
	float *values;
	int short_values; /* rotation, not CUBICSPLINE: every value is n / 32767 for an integer n
	                     (|n| <= 32767), so glTF writes them as normalised shorts; 0: floats */
} mlod_channel;

typedef struct mlod_clip {
	char *name;
	float duration;   /* seconds: the largest key time */
	float frame_time; /* > 0 for uniformly sampled clips (BVH); 0 otherwise */
	int frame_count;  /* frames of a uniformly sampled clip, else 0 */
	int channel_count;
	mlod_channel *channels;
	int gltf_index;   /* glTF animation index, or -1 */
} mlod_clip;

typedef struct mlod_character {
	mlod_skeleton skeleton;
	int mesh_count;
	mlod_mesh *meshes;
	int instance_count;
	mlod_instance *instances;
	int clip_count;
	mlod_clip *clips;
	/* What a reader could not represent and skipped, for the report
	 * (e.g. "2 joint nodes outside any skin"), one note per line. May be
	 * NULL. */
	char *notes;
	/* The notes of notes that a user must hear of even without a report,
	 * because the reader changed, approximated or dropped something of
	 * the input (a rotation normalised, an attribute not decoded, a BVH
	 * frame ignored), one per line; the tools print them on stderr. May be
	 * NULL. */
	char *warnings;
} mlod_character;

/* Releases everything the character owns and zeroes it. */
void mlod_character_free(mlod_character *c);

/* Releases a primitive's arrays and zeroes it (NULL is allowed). */
void mlod_primitive_free(mlod_primitive *p);

/* Checks the invariants (parent order, index ranges, finite values,
 * increasing key times, weights in range). Returns MLOD_ERR_PARSE with a
 * message naming the first problem. */
mlod_result mlod_character_validate(const mlod_character *c, mlod_error *err);

/* Height of the skeleton, the scale of every "% of the height" mlod reads
 * or reports (motion bounds, skeleton level errors, the stage record): the
 * extent along +Y, glTF's up axis (BVH files such as CMU's are Y-up too),
 * of the rest-pose joint origins in world space, roots with their base
 * transforms. Joints only: the mesh above the head joint is not counted.
 * The rule for degenerate skeletons: when the Y extent is under
 * MLOD_HEIGHT_MIN_UP of the largest extent (a character lying down or
 * modelled Z-up, a snake, a single joint), the height is the largest
 * extent (mlod_skeleton_extent). Never 0 for a non-empty skeleton; 0 for
 * NULL or no joints. */
#define MLOD_HEIGHT_MIN_UP 0.25f
float mlod_skeleton_height(const mlod_skeleton *s);

/* The largest extent of the rest-pose joint origins along x, y or z (1 for
 * a single point; 0 for NULL or no joints). Not a height (on a T-posed
 * character it is the arm span): a scale for numeric tolerances and for
 * the test character's proportions, never shown as a percentage. */
float mlod_skeleton_extent(const mlod_skeleton *s);

/* Skin weights glTF does not allow (weights.c). glTF wants every skinned
 * vertex's weights to sum to 1, and the Khronos validator fails a file
 * whose sum is off by more than 2e-7 per non-zero weight
 * (ACCESSOR_WEIGHTS_NON_NORMALIZED), all-zero weights included. The one
 * rule of mlod for them, which the glTF reader applies to the primitives
 * of every mesh a skinned node uses (so every level a tool writes has
 * valid weights, and every measure moves the vertices as the pack and
 * the runtime do), with a warning per primitive:
 * - a vertex whose weights are all 0 gets weight 1 on the skin's root
 *   joint (mlod_skin_root), which it then follows; its other influences
 *   become joint 0 at weight 0;
 * - a vertex whose weights sum to something else is scaled to sum to 1
 *   (which changes no pose: skinning divides by the sum);
 * - a vertex that names one joint in two influences or more, each with a
 *   non-zero weight, keeps the first of them with their summed weight,
 *   the others becoming joint 0 at weight 0 (which changes no pose either;
 *   merged first, so the sum is then checked as above).
 * A vertex with a negative or non-finite weight is left as it is (the
 * character then fails mlod_character_validate). */
typedef struct mlod_weight_fix {
	int unweighted;        /* vertices that had no weight (on root, unless -1) */
	int first_unweighted;  /* the first of them, or -1 */
	int rescaled;          /* vertices whose weights were scaled to sum to 1 */
	int first_rescaled;    /* the first of them, or -1 */
	float first_sum;       /* its weights' sum before */
	int merged;            /* vertices whose repeated joints were merged */
	int first_merged;      /* the first of them, or -1 */
} mlod_weight_fix;

/* The root of skin `skin` as a skin joint index: of its joints, the
 * nearest the skeleton's root (the first of them at that depth); -1 for a
 * skin without joints or out of range. */
int mlod_skin_root(const mlod_skeleton *s, int skin);

/* Applies the rule to p, whose vertices a skin with skin joint `root`
 * (mlod_skin_root; -1: all-zero vertices are counted but left as they
 * are) deforms, and counts what it found into *fix. */
void mlod_primitive_fix_weights(mlod_primitive *p, int root, mlod_weight_fix *fix);

/* A malloc'ed copy of s ("" for NULL), or NULL when out of memory. */
char *mlod_strdup(const char *s);

/* The timeline of a clip (keytimes.c): with frames set and a sampled clip
 * (frame_time > 0, frame_count > 0), its frames i * frame_time; otherwise
 * the key times of the channels that use selects (use[i] != 0 for channel
 * i; every channel when use is NULL), merged, sorted and each once.
 * *times is malloc'ed (NULL when the count is 0). Returns the count, or -1
 * when out of memory. *shared (may be NULL) is set to 1 when the selected
 * channels all have the same key times, else 0. */
int mlod_clip_key_times(const mlod_clip *clip, const unsigned char *use, int frames, float **times, int *shared);

/* ------------------------------------------------------------------ */
/* Pose evaluation and skinning                                        */
/* ------------------------------------------------------------------ */

/* local[i] = rest transform of joint i. */
void mlod_pose_rest(const mlod_skeleton *s, mlod_trs *local);

/* Samples clip at time t (clamped to [0, duration]) into local, which must
 * hold the pose the clip does not animate (usually the rest pose). */
void mlod_clip_sample(const mlod_clip *clip, float t, mlod_trs *local);

/* Sets the path of l that one channel animates to its value at time t
 * (clamped to [0, duration]), as mlod_clip_sample does for each channel. */
void mlod_channel_sample(const mlod_channel *ch, float duration, float t, mlod_trs *l);

/* world[i] = world transform of joint i for the given local pose
 * (roots are prefixed by their base). */
void mlod_pose_world(const mlod_skeleton *s, const mlod_trs *local, mlod_mat4 *world);

/* out[k] = world[skin->joints[k]] * skin->inverse_bind[k]. */
void mlod_skin_matrices(const mlod_skin *skin, const mlod_mat4 *world, mlod_mat4 *out);

/* Linear blend skinning of a primitive's positions (3 * vertex_count floats
 * into out) and, when out_normals is not NULL and the primitive has
 * normals, of its normals. Vertices whose weights sum to 0 stay at their
 * bind position (the glTF reader leaves none: mlod_primitive_fix_weights). */
void mlod_skin_primitive(const mlod_primitive *p, const mlod_mat4 *skin_mats,
                         float *out_positions, float *out_normals);
/* The position mlod_skin_primitive gives vertex v, bit for bit. */
void mlod_skin_vertex(const mlod_primitive *p, int v, const mlod_mat4 *skin_mats, float out[3]);

/* A character posed as one triangle soup, for measuring. */
typedef struct mlod_posed {
	int vertex_count;
	float *positions;     /* 3 * vertex_count */
	int triangle_count;
	uint32_t *indices;    /* 3 * triangle_count */
} mlod_posed;

/* Poses every triangle instance of the character (skinned or rigid) with
 * the world matrices of one pose into out. out is reused between calls:
 * initialise it to {0} and free it with mlod_posed_free. */
mlod_result mlod_pose_character(const mlod_character *c, const mlod_mat4 *world,
                                mlod_posed *out, mlod_error *err);
void mlod_posed_free(mlod_posed *p);

#ifdef __cplusplus
}
#endif

#endif /* MLOD_MODEL_H */
