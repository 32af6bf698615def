/*
 * mlod.h: the public interface of libmlod, the bake library of mlod.
 *
 * mlod implements "Multi-Layer Level of Detail for Character Animation"
 * (Savoye & Meyer, VRIPHYS 2008). This header is the whole public API of
 * the bake side; the runtime has its own header (lib/rt/mlodrt.h) and does
 * not include this one.
 *
 * Conventions
 * - Every fallible call returns an mlod_result and, when err is not NULL,
 *   fills *err with the code and a human-readable message. The library
 *   never prints and never exits.
 * - Lengths are in the scene's units (metres for glTF, file units for BVH).
 *   Angles are radians. Matrices are column-major 4x4 (as in glTF):
 *   m[col * 4 + row].
 * - Objects the library allocates are released with the matching *_free
 *   call, which accepts NULL. Plain buffers it returns are released with
 *   mlod_free().
 * - Joints of an mlod_skeleton are ordered so that a parent always comes
 *   before its children (parent index < child index). Readers establish
 *   this; everything else relies on it.
 */
#ifndef MLOD_H
#define MLOD_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define MLOD_VERSION "0.1.0"

/* ------------------------------------------------------------------ */
/* Results                                                             */
/* ------------------------------------------------------------------ */

typedef enum mlod_result {
	MLOD_OK = 0,
	MLOD_ERR_INVALID_ARG,  /* a caller error: NULL where not allowed, bad option value */
	MLOD_ERR_IO,           /* reading or writing a file failed */
	MLOD_ERR_PARSE,        /* malformed input: truncated, bad syntax, out-of-range index */
	MLOD_ERR_UNSUPPORTED,  /* well-formed input using a feature mlod does not handle */
	MLOD_ERR_NOMEM,        /* an allocation failed, or input claims an absurd size */
	MLOD_ERR_LIMIT         /* a request the data cannot satisfy (e.g. an error bound) */
} mlod_result;

#define MLOD_ERROR_MESSAGE_SIZE 512

typedef struct mlod_error {
	mlod_result code;
	char message[MLOD_ERROR_MESSAGE_SIZE]; /* says what went wrong, without a trailing newline */
} mlod_error;

/* A short static description of a result code ("malformed input", ...). */
const char *mlod_strerror(mlod_result code);

/* Fills err (if not NULL) with code and a printf-style message; returns code.
 * Used by the library itself and available to tools. */
mlod_result mlod_fail(mlod_error *err, mlod_result code, const char *fmt, ...)
#if defined(__GNUC__)
	__attribute__((format(printf, 3, 4)))
#endif
	;

/* Releases a buffer returned by the library (glb bytes, JSON text, ...). */
void mlod_free(void *p);

/* ------------------------------------------------------------------ */
/* Math                                                                */
/* ------------------------------------------------------------------ */

typedef struct mlod_v3 { float x, y, z; } mlod_v3;
typedef struct mlod_quat { float x, y, z, w; } mlod_quat;  /* glTF order */
typedef struct mlod_mat4 { float m[16]; } mlod_mat4;         /* column-major */

/* A local transform: translation, rotation, scale (glTF's TRS). */
typedef struct mlod_trs {
	mlod_v3 t;
	mlod_quat r;
	mlod_v3 s;
} mlod_trs;

/* Euler orders. MLOD_EULER_ZXY means the rotation matrix is Rz * Rx * Ry:
 * the order in which BVH lists "Zrotation Xrotation Yrotation". */
typedef enum mlod_euler_order {
	MLOD_EULER_XYZ,
	MLOD_EULER_XZY,
	MLOD_EULER_YXZ,
	MLOD_EULER_YZX,
	MLOD_EULER_ZXY,
	MLOD_EULER_ZYX
} mlod_euler_order;

mlod_v3 mlod_v3_add(mlod_v3 a, mlod_v3 b);
mlod_v3 mlod_v3_sub(mlod_v3 a, mlod_v3 b);
mlod_v3 mlod_v3_scale(mlod_v3 a, float s);
float mlod_v3_dot(mlod_v3 a, mlod_v3 b);
mlod_v3 mlod_v3_cross(mlod_v3 a, mlod_v3 b);
float mlod_v3_length(mlod_v3 a);

mlod_quat mlod_quat_identity(void);
mlod_quat mlod_quat_mul(mlod_quat a, mlod_quat b);         /* a then applied after b: a*b */
mlod_quat mlod_quat_normalize(mlod_quat q);
mlod_quat mlod_quat_conjugate(mlod_quat q);
mlod_v3 mlod_quat_rotate(mlod_quat q, mlod_v3 v);
mlod_quat mlod_quat_axis_angle(mlod_v3 axis, float angle); /* axis need not be unit */
mlod_quat mlod_quat_slerp(mlod_quat a, mlod_quat b, float t); /* shortest path */
mlod_quat mlod_quat_nlerp(mlod_quat a, mlod_quat b, float t); /* shortest path */
/* Angle in [0, pi] between the rotations a and b; q and -q are the same rotation. */
float mlod_quat_angle(mlod_quat a, mlod_quat b);

/* angles[0..2] are the rotations about x, y, z (radians), whatever the order. */
mlod_quat mlod_quat_from_euler(mlod_euler_order order, const float angles[3]);
void mlod_quat_to_euler(mlod_euler_order order, mlod_quat q, float angles[3]);
/* Parses "XYZ", "zxy", ... ; returns 0 on success, -1 when not an order. */
int mlod_euler_order_parse(const char *s, mlod_euler_order *out);
const char *mlod_euler_order_name(mlod_euler_order order);

mlod_mat4 mlod_mat4_identity(void);
mlod_mat4 mlod_mat4_mul(const mlod_mat4 *a, const mlod_mat4 *b); /* a*b */
mlod_mat4 mlod_mat4_from_trs(const mlod_trs *trs);
/* Decomposes an affine matrix. Returns 0 when it is exactly a TRS (no shear,
 * within tol relative), 1 when it has shear the TRS cannot express (the
 * result is then the closest TRS), -1 when singular. */
int mlod_mat4_to_trs(const mlod_mat4 *m, mlod_trs *out, float tol);
/* General inverse; returns 0 on success, -1 when singular. */
int mlod_mat4_invert(const mlod_mat4 *m, mlod_mat4 *out);
mlod_v3 mlod_mat4_point(const mlod_mat4 *m, mlod_v3 p);  /* m * (p, 1) */
mlod_v3 mlod_mat4_vector(const mlod_mat4 *m, mlod_v3 v); /* m * (v, 0) */
mlod_trs mlod_trs_identity(void);

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
	 * (e.g. "2 joint nodes outside any skin"). May be NULL. */
	char *notes;
} mlod_character;

/* Releases everything the character owns and zeroes it. */
void mlod_character_free(mlod_character *c);

/* Releases a primitive's arrays and zeroes it (NULL is allowed). */
void mlod_primitive_free(mlod_primitive *p);

/* Checks the invariants (parent order, index ranges, finite values,
 * increasing key times, weights in range). Returns MLOD_ERR_PARSE with a
 * message naming the first problem. */
mlod_result mlod_character_validate(const mlod_character *c, mlod_error *err);

/* Height of the skeleton: the extent of the rest-pose joint positions
 * along its largest axis (never 0 for a non-empty skeleton). */
float mlod_skeleton_size(const mlod_skeleton *s);

/* ------------------------------------------------------------------ */
/* Pose evaluation and skinning                                        */
/* ------------------------------------------------------------------ */

/* local[i] = rest transform of joint i. */
void mlod_pose_rest(const mlod_skeleton *s, mlod_trs *local);

/* Samples clip at time t (clamped to [0, duration]) into local, which must
 * hold the pose the clip does not animate (usually the rest pose). */
void mlod_clip_sample(const mlod_clip *clip, float t, mlod_trs *local);

/* world[i] = world transform of joint i for the given local pose
 * (roots are prefixed by their base). */
void mlod_pose_world(const mlod_skeleton *s, const mlod_trs *local, mlod_mat4 *world);

/* out[k] = world[skin->joints[k]] * skin->inverse_bind[k]. */
void mlod_skin_matrices(const mlod_skin *skin, const mlod_mat4 *world, mlod_mat4 *out);

/* Linear blend skinning of a primitive's positions (3 * vertex_count floats
 * into out) and, when out_normals is not NULL and the primitive has
 * normals, of its normals. Vertices whose weights sum to 0 stay at their
 * bind position. */
void mlod_skin_primitive(const mlod_primitive *p, const mlod_mat4 *skin_mats,
                         float *out_positions, float *out_normals);

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
/* glTF (through a C shim over tinygltf)                               */
/* ------------------------------------------------------------------ */

/* An opaque glTF document. Everything mlod does not change (materials,
 * textures, cameras, extras, extensions, names, animations, skins) is kept
 * as read and written back unchanged. */
typedef struct mlod_gltf mlod_gltf;

/* Parses .glb or .gltf bytes. base_dir resolves external URIs of a .gltf
 * (may be NULL: only data: URIs are then allowed). Draco- or
 * meshopt-compressed input is MLOD_ERR_UNSUPPORTED. */
mlod_result mlod_gltf_read(const void *data, size_t size, const char *base_dir,
                           mlod_gltf **out, mlod_error *err);
void mlod_gltf_free(mlod_gltf *doc);

/* Serialises the document: binary != 0 gives .glb, else .gltf JSON with
 * embedded buffers. *data is released with mlod_free. */
mlod_result mlod_gltf_write(const mlod_gltf *doc, int binary, void **data,
                            size_t *size, mlod_error *err);

/* Builds the character model from the document's skins, meshes and
 * animations. Joint nodes are the union of all skins' joints plus the nodes
 * that connect them; a document without skins (such as a BVH converted by
 * mlod_gltf_from_character) uses its animated nodes instead of skin joints.
 * Instances are the nodes with a mesh that the default scene shows (every
 * node when there is no scene). What is skipped is listed in out->notes. */
mlod_result mlod_gltf_to_character(const mlod_gltf *doc, mlod_character *out,
                                   mlod_error *err);

/* Builds a new document from a character: nodes for joints (joint i is
 * node i; End Sites become child nodes marked extras.mlod.end_site),
 * meshes, skins, instances and one animation per clip. A BVH read this way gives a glb. */
mlod_result mlod_gltf_from_character(const mlod_character *c, mlod_gltf **out,
                                     mlod_error *err);

typedef enum mlod_gltf_kind {
	MLOD_GLTF_NODE,
	MLOD_GLTF_SKIN,
	MLOD_GLTF_SCENE,  /* index -1: the default scene */
	MLOD_GLTF_MESH,
	MLOD_GLTF_ANIMATION,
	MLOD_GLTF_ASSET   /* index ignored */
} mlod_gltf_kind;

int mlod_gltf_count(const mlod_gltf *doc, mlod_gltf_kind kind);

/* Sets extras[key] of an object to the JSON value in json (an object,
 * array, string, number, ...), replacing any previous value of that key
 * and keeping the other keys. */
mlod_result mlod_gltf_set_extra(mlod_gltf *doc, mlod_gltf_kind kind, int index,
                                const char *key, const char *json, mlod_error *err);

/* Reads extras[key] as JSON text into *json (release with mlod_free).
 * Returns MLOD_OK with *json = NULL when the key is absent. */
mlod_result mlod_gltf_get_extra(const mlod_gltf *doc, mlod_gltf_kind kind, int index,
                                const char *key, char **json, mlod_error *err);

/* Appends a mesh built from m's primitives (new accessors in a new buffer
 * view range of buffer 0; material indices kept). */
mlod_result mlod_gltf_add_mesh(mlod_gltf *doc, const mlod_mesh *m, int *out_index,
                               mlod_error *err);

#define MLOD_GLTF_DETACHED (-2)

/* Appends a node. parent -1 puts it in the default scene's roots;
 * MLOD_GLTF_DETACHED leaves it out of every scene (e.g. an MSFT_lod level).
 * mesh and skin may be -1. */
mlod_result mlod_gltf_add_node(mlod_gltf *doc, const char *name, int parent,
                               int mesh, int skin, const mlod_trs *trs,
                               int *out_index, mlod_error *err);

/* Appends a skin whose joints are the glTF nodes of the given skeleton
 * joints (skin->joints index s->joints; each must have a node). */
mlod_result mlod_gltf_add_skin(mlod_gltf *doc, const mlod_skeleton *s,
                               const mlod_skin *skin, int *out_index, mlod_error *err);

/* Appends an animation with the clip's channels, targeting the joints'
 * nodes. */
mlod_result mlod_gltf_add_animation(mlod_gltf *doc, const mlod_skeleton *s,
                                    const mlod_clip *clip, int *out_index,
                                    mlod_error *err);

/* Appends a copy of glTF mesh `mesh` whose JOINTS_n and WEIGHTS_n come
 * from m (same primitives and vertex counts, as made by
 * mlod_skel_level_apply); every other attribute, the indices and the morph
 * targets share the original accessors. */
mlod_result mlod_gltf_add_mesh_reskinned(mlod_gltf *doc, int mesh, const mlod_mesh *m, int *out_index,
                                         mlod_error *err);

/* Adds MSFT_lod to node (lod_nodes are its coarser levels, finest first)
 * and MSFT_screencoverage to its extras (lod_count + 1 values, decreasing),
 * and declares MSFT_lod in extensionsUsed. */
mlod_result mlod_gltf_set_lod(mlod_gltf *doc, int node, const int *lod_nodes,
                              int lod_count, const float *coverage, mlod_error *err);

/* Editing a document that was read: these keep everything else as it
 * was (materials, textures, names, extras, animations, skins). */

/* A deep copy of doc (release it with mlod_gltf_free). */
mlod_result mlod_gltf_copy(const mlod_gltf *doc, mlod_gltf **out, mlod_error *err);

/* Appends a mesh built from m's primitives, like mlod_gltf_add_mesh, that
 * takes the name, default morph weights (when every primitive keeps that
 * many targets), extensions and extras of glTF mesh `like`, and those of
 * its primitives by position. */
mlod_result mlod_gltf_add_mesh_like(mlod_gltf *doc, int like, const mlod_mesh *m, int *out_index,
                                    mlod_error *err);

/* Points node at mesh and skin (either may be -1: none). */
mlod_result mlod_gltf_set_node_mesh(mlod_gltf *doc, int node, int mesh, int skin, mlod_error *err);

/* The node's local transform. A matrix that is not a translation,
 * rotation and scale is MLOD_ERR_UNSUPPORTED. */
mlod_result mlod_gltf_get_node_trs(const mlod_gltf *doc, int node, mlod_trs *out, mlod_error *err);

/* Removes the meshes no node uses, then the accessors and buffer views
 * nothing uses, and packs the buffers again: indices of meshes, accessors
 * and buffer views change, every other index stays. A document using an
 * extension that may refer to those (beyond the KHR_materials_*,
 * KHR_texture_*, KHR_lights_punctual, KHR_mesh_quantization, EXT_texture_*,
 * MSFT_lod family) is MLOD_ERR_UNSUPPORTED and left unchanged. */
mlod_result mlod_gltf_prune(mlod_gltf *doc, mlod_error *err);

/* Removes MSFT_lod from node (and MSFT_screencoverage from its extras):
 * its former level nodes stay, without mesh or skin, so that node indices
 * hold. MSFT_lod leaves extensionsUsed when no node uses it any more. A
 * node without MSFT_lod is left as it is. */
mlod_result mlod_gltf_clear_lod(mlod_gltf *doc, int node, mlod_error *err);

/* Makes node `to` morph like node `from`: it gets from's default morph
 * weights and, in every animation, a channel animating its weights with
 * the sampler of each channel animating from's (to's mesh must keep the
 * number of targets). *added (may be NULL) is the number of channels
 * added. */
mlod_result mlod_gltf_copy_morph_animation(mlod_gltf *doc, int from, int to, int *added, mlod_error *err);

/* A channel animating the morph target weights of a node (not part of the
 * character's clips). */
typedef struct mlod_weight_track {
	int node;            /* glTF node */
	int targets;         /* weights per key */
	mlod_interp interp;
	int key_count;
	float *times;        /* key_count, increasing */
	float *values;       /* targets per key (3 * targets for CUBICSPLINE: in-tangents, values, out-tangents) */
} mlod_weight_track;

/* The weights channels of glTF animation `animation`, in channel order;
 * *tracks is NULL when there are none. Release with mlod_weight_tracks_free. */
mlod_result mlod_gltf_weight_tracks(const mlod_gltf *doc, int animation, mlod_weight_track **tracks, int *count,
                                    mlod_error *err);
void mlod_weight_tracks_free(mlod_weight_track *tracks, int count);

/* Appends the tracks to glTF animation `animation` as weights channels
 * (key times shared by several tracks are stored once). */
mlod_result mlod_gltf_add_weight_tracks(mlod_gltf *doc, int animation, const mlod_weight_track *tracks, int count,
                                        mlod_error *err);

/* ------------------------------------------------------------------ */
/* BVH                                                                 */
/* ------------------------------------------------------------------ */

/* Parses BVH text. Joints get their channel layout, rest = OFFSET (with
 * identity rotation), and one clip "bvh" with a uniformly sampled
 * translation and rotation channel per animated joint. Errors name the line. */
mlod_result mlod_bvh_read(const void *data, size_t size, mlod_character *out,
                          mlod_error *err);

/* Writes the character's skeleton and one clip as BVH text, sampled at
 * frame_time (0: the clip's own frame time, else 1/30 s). Joints without a
 * BVH layout get "Xposition Yposition Zposition" on roots and
 * "Zrotation Xrotation Yrotation" elsewhere. *text is released with mlod_free. */
mlod_result mlod_bvh_write(const mlod_character *c, int clip, float frame_time,
                           char **text, size_t *size, mlod_error *err);

/* ------------------------------------------------------------------ */
/* Input                                                               */
/* ------------------------------------------------------------------ */

typedef enum mlod_format { MLOD_FORMAT_UNKNOWN, MLOD_FORMAT_GLB, MLOD_FORMAT_GLTF, MLOD_FORMAT_BVH } mlod_format;

/* Guesses the format from the first bytes. */
mlod_format mlod_detect_format(const void *data, size_t size);

/* Loads glb, glTF or BVH bytes into a document and a character. BVH gets a
 * document made with mlod_gltf_from_character, so every tool writes glb.
 * doc may be NULL when only the character is wanted. On failure nothing
 * is allocated. */
mlod_result mlod_load(const void *data, size_t size, const char *base_dir,
                      mlod_gltf **doc, mlod_character *c, mlod_format *format,
                      mlod_error *err);

/* ------------------------------------------------------------------ */
/* Skeleton labeling and joint energy (paper 4.1.1, 4.1.2)             */
/* ------------------------------------------------------------------ */

typedef enum mlod_label {
	MLOD_LABEL_ROOT,         /* zeta */
	MLOD_LABEL_END_EFFECTOR, /* chi */
	MLOD_LABEL_MAJOR,        /* psi */
	MLOD_LABEL_EXTREME,      /* mu */
	MLOD_LABEL_MINOR         /* kappa: the only removable joints */
} mlod_label;

const char *mlod_label_name(mlod_label l);   /* "root", "end-effector", ... */
const char *mlod_label_symbol(mlod_label l); /* UTF-8 Greek letter */
/* Parses a label name; returns 0 on success, -1 otherwise. */
int mlod_label_parse(const char *s, mlod_label *out);

typedef struct mlod_label_options {
	double hub_factor;   /* 0 means 1.9, the paper's value */
	double max_angle;    /* rotation range per Euler axis for energy normalisation; 0 means pi */
} mlod_label_options;

typedef struct mlod_joint_info {
	int depth;           /* edges to the joint's root */
	int children;
	int neighbors;       /* children + 1 if the joint has a parent */
	mlod_label label;
	double weight;       /* (h - depth) / h, h = tree height (max depth + 1) */
	double energy;       /* max over clips of the joint energy */
} mlod_joint_info;

/* Labels every joint and computes its energy from the character's clips
 * (0 when there are none). info holds skeleton.joint_count entries. */
mlod_result mlod_label_skeleton(const mlod_character *c, const mlod_label_options *opt,
                                mlod_joint_info *info, mlod_error *err);


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

/* ------------------------------------------------------------------ */
/* Multiresolution Skeletal Graph and skeleton levels (paper 4.1.3)    */
/* ------------------------------------------------------------------ */

/* An edge of the transitive closure of a kinematic sub-chain: from an
 * ancestor a to a descendant b, weighted by the bone length along the
 * chain between them. */
typedef struct mlod_skelgraph_edge {
	int a, b;
	float length;
} mlod_skelgraph_edge;

/* The graph: each kinematic sub-chain is a connected set of joints whose
 * interior joints are minor and whose ends are non-minor; chains meet only
 * at non-minor joints. A chain may branch where a minor joint has several
 * children. */
typedef struct mlod_skelgraph {
	int joint_count;
	int *joint_parent;            /* joint_count: the skeleton's parents */
	int chain_count;
	int *chain_start;             /* chain_count + 1 offsets into chain_joints */
	int *chain_joints;            /* each chain's joints, its top joint first, parents before children */
	int edge_count;
	mlod_skelgraph_edge *edges;   /* the closure of every chain, sorted by (length, a, b) */
} mlod_skelgraph;

/* Builds the graph from the skeleton and its labels. A skeleton whose
 * closure would exceed a few million edges is MLOD_ERR_LIMIT. */
mlod_result mlod_skelgraph_build(const mlod_skeleton *s, const mlod_joint_info *info,
                                 mlod_skelgraph *out, mlod_error *err);
void mlod_skelgraph_free(mlod_skelgraph *g);

/* One skeleton level. */
typedef struct mlod_skel_level {
	double threshold;        /* minor joints with energy below it are removed */
	int joint_count;         /* of the full skeleton */
	int kept_count;
	unsigned char *kept;     /* joint_count flags */
	int *parent;             /* joint_count: a kept joint's parent in the level (-1 for a root or a removed joint) */
	int *remap;              /* joint_count: the kept joint that stands in for each joint (itself when kept) */
} mlod_skel_level;

/* Extracts the level at threshold: disables the minor joints whose energy
 * is below it, then takes the minimum spanning tree of the enabled joints
 * over the closure edges, oriented from the roots. Levels extracted at
 * increasing thresholds are nested. */
mlod_result mlod_skelgraph_extract(const mlod_skelgraph *g, const mlod_joint_info *info,
                                   double threshold, mlod_skel_level *out, mlod_error *err);
void mlod_skel_level_free(mlod_skel_level *l);

/* The paper's decimation order: the minor joints sorted by energy, lowest
 * first; equal energies (joints that never move relative to their parent)
 * go deepest first, then by index. Writes the minor joints to order
 * (joint_count entries suffice) and returns how many there are. */
int mlod_skel_removal_order(const mlod_skeleton *s, const mlod_joint_info *info, int *order);

/* Extracts the level that removes the first `removed` joints of order, as
 * mlod_skelgraph_extract does for a threshold. Levels with increasing
 * counts are nested. out->threshold is the energy of the last removed
 * joint (0 when none). */
mlod_result mlod_skelgraph_extract_first(const mlod_skelgraph *g, const mlod_joint_info *info,
                                         const int *order, int removed, mlod_skel_level *out,
                                         mlod_error *err);

/* A level as measured, for mlod_gltf_add_skel_levels. */
typedef struct mlod_skel_level_record {
	const mlod_skel_level *level;
	const mlod_character *character; /* the level applied to the full character */
	mlod_deviation vertex;           /* skinned-vertex error, % of diagonal; scale 0 without meshes */
	mlod_deviation joint;            /* joint position error, scene units */
	double size;                     /* the skeleton height, for the joint error */
} mlod_skel_level_record;

/* The largest screen coverage (fraction of the screen height covered by
 * the character) at which an error of error_percent of the character's
 * size stays within pixel_budget pixels on a screen screen_pixels high;
 * at most 1, and 0 for no error. */
double mlod_error_coverage(double error_percent, double screen_pixels, double pixel_budget);

typedef struct mlod_fold_stats {
	int shear_samples;       /* composed transforms that had shear TRS cannot express */
	int weight_merges;       /* vertices whose influences were merged */
} mlod_fold_stats;

/* Applies a level to a character, giving a standalone character whose
 * skeleton holds only the kept joints (in the same relative order):
 * - motion folding: a kept joint whose parent was removed gets the local
 *   transform L'_c = L_j ... L_c composed over its removed ancestors, at
 *   the union of their key times (or every frame of a sampled clip), so
 *   every kept joint's world transform is unchanged there;
 * - skin transfer: each vertex's weight on a removed joint moves to its
 *   stand-in; duplicates merge and the weights are renormalised;
 * - skins list the kept joints they used plus any stand-in they need, with
 *   inverse bind matrices from the full skeleton;
 * - rigid instances on a removed joint follow its stand-in.
 * out->joints[k].node keeps the original node index. stats may be NULL. */
mlod_result mlod_skel_level_apply(const mlod_character *c, const mlod_skel_level *l,
                                  mlod_character *out, mlod_fold_stats *stats, mlod_error *err);

/* Records levels (coarser in order) in the document that full was read
 * from: per level a glTF skin for each skin, over the kept joints; a copy
 * of each skinned mesh with the transferred weights, on a node outside the
 * scene listed in the original node's MSFT_lod (coverage from the
 * errors); and extras.mlod on the scene (the levels: threshold, kept
 * nodes, remap as node -> stand-in node, skins, errors) and on each skin
 * (the skins of its levels). */
mlod_result mlod_gltf_add_skel_levels(mlod_gltf *doc, const mlod_character *full,
                                      const mlod_skel_level_record *levels, int count, mlod_error *err);

/* ------------------------------------------------------------------ */
/* Mesh layer: BindGraphMesh, triangle collapse, Power Skinning (4.2)  */
/* ------------------------------------------------------------------ */

/* The mesh layer simplifies each triangle primitive of a character on its
 * own. A BindGraphMesh (BGM) holds one primitive welded by position (the
 * topology) with one attribute "wedge" per seam side (each glTF vertex),
 * its dual graph (face adjacency) and each node's joint influences. Rigid
 * meshes hanging under a joint are skinned to it with weight 1. Triangle
 * (the paper) or edge collapses into a new vertex v-bar are recorded in
 * order, so that every prefix of the sequence is a valid mesh: a level is
 * a prefix. */

/* Up to this many joint influences per vertex (every weight set). */
#define MLOD_MAX_INFLUENCES (4 * MLOD_MAX_SETS)

/* A vertex's joint influences: joints are skin-local indices (or the one
 * joint of a rigid mesh, index 0), weights are positive. */
typedef struct mlod_influences {
	int count;
	uint16_t joints[MLOD_MAX_INFLUENCES];
	float weights[MLOD_MAX_INFLUENCES];
} mlod_influences;

/* Power Skinning (4.2.4), the weights of k collapsed vertices v[0..k-1]
 * for the new vertex vbar: with d_i = |vbar - v_i| and D = sum d_i,
 * W[i] = (D - d_i) / ((k - 1) D); 1/k each when D = 0 (or k = 1). The W
 * sum to 1. */
void mlod_power_weights(const mlod_v3 *v, int k, mlod_v3 vbar, double *W);

/* The influences of vbar: w(j) = sum_i W[i] w(j, v_i), with W from
 * mlod_power_weights. When more than 4 remain, the largest 4 are kept
 * (ties: lower joint first); out is then renormalised to sum 1, sorted
 * by weight, largest first. Returns 1 when influences were dropped (a
 * "cap event"), else 0. */
int mlod_power_skin(const mlod_v3 *v, const mlod_influences *in, int k, mlod_v3 vbar, mlod_influences *out);

/* Which vertices may disappear (4.2.2). eta(j) is the average of the
 * non-zero weights joint j has on vertices. */
typedef enum mlod_eligibility {
	MLOD_ELIGIBLE_DEFAULT = 0, /* the measured default: BEND with the compactness cost, ALL with the posed cost */
	MLOD_ELIGIBLE_LITERAL,     /* the paper: v only when w(j, v) < tau * eta(j) for every joint j */
	MLOD_ELIGIBLE_BEND,        /* protects bends: v only when its largest weight w(j, v) >= tau * eta(j) */
	MLOD_ELIGIBLE_ALL          /* every vertex */
} mlod_eligibility;

/* eta for every joint of the character (joint_count values, 0 for a joint
 * without weight): skinned instances count each vertex's weights, rigid
 * instances weight 1 on their joint. */
mlod_result mlod_joint_weight_average(const mlod_character *c, double *eta, mlod_error *err);

/* 1 when a vertex with influences inf may disappear. joint_map turns the
 * influence joints into skeleton joints (eta's index); tau 0 means 1. */
int mlod_vertex_eligible(mlod_eligibility rule, double tau, const mlod_influences *inf, const int *joint_map,
                         const double *eta);

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

/* What orders the collapses. */
typedef enum mlod_mesh_cost {
	MLOD_COST_DEFAULT = 0,  /* the measured default: MLOD_COST_POSED */
	MLOD_COST_COMPACTNESS,  /* the paper (4.2.3): lowest 4 sqrt(3) a / (l1^2 + l2^2 + l3^2) first */
	MLOD_COST_POSED         /* beyond the paper: quadric error summed over poses, compactness as tie-break */
} mlod_mesh_cost;

/* Where v-bar goes. Next to a seam or an allowed border it always snaps
 * to a seam (border) vertex, so that textures neither tear nor smear. */
typedef enum mlod_placement {
	MLOD_PLACE_DEFAULT = 0, /* OPTIMAL with the posed cost (measured), BARYCENTER with compactness (the paper) */
	MLOD_PLACE_BARYCENTER,  /* the paper: the triangle's barycenter */
	MLOD_PLACE_OPTIMAL      /* beyond the paper: the minimum of the posed quadric (or the barycenter when lower) */
} mlod_placement;

/* Which collapses run. */
typedef enum mlod_collapse_op {
	MLOD_OP_DEFAULT = 0,    /* the measured default: EDGE with the posed cost, TRIANGLE with compactness */
	MLOD_OP_TRIANGLE,       /* the paper (4.2.3): triangle collapses only */
	MLOD_OP_EDGE,           /* beyond the paper: edge collapses only (the posed cost only: compactness
	                         * does not rank an edge) */
	MLOD_OP_MIXED           /* triangle and edge collapses in one queue, cheapest first (posed cost only) */
} mlod_collapse_op;

/* Zero-initialised options are the defaults. */
typedef struct mlod_bgm_options {
	mlod_mesh_cost cost;
	mlod_placement placement;
	mlod_collapse_op op;
	mlod_eligibility eligibility;
	double tau;                  /* 0 means 1 */
	int allow_border;            /* let collapses move and remove border vertices */
	const mlod_pose_set *poses;  /* the posed cost's poses; NULL: the bind pose only */
	const double *eta;           /* per joint (mlod_joint_weight_average); NULL: computed */
} mlod_bgm_options;

typedef struct mlod_bgm mlod_bgm;

/* Builds the BGM of primitive `primitive` of the mesh of instance
 * `instance`: welds by position (and equal influences and morph target
 * offsets, so that nothing tears when posed or morphed), builds the dual
 * graph, marks borders, seams, locked nodes (non-manifold edges or fans,
 * inconsistent winding, duplicate faces, skinned vertices without weight)
 * and eligible ones, and the posed quadrics. Degenerate triangles (two
 * corners on one node) are dropped. A primitive that is not triangles is
 * MLOD_ERR_UNSUPPORTED. */
mlod_result mlod_bgm_build(const mlod_character *c, int instance, int primitive, const mlod_bgm_options *opt,
                           mlod_bgm **out, mlod_error *err);
void mlod_bgm_free(mlod_bgm *g);

typedef struct mlod_bgm_info {
	int vertices;          /* glTF vertices (wedges) of the input */
	int nodes;             /* welded positions */
	int triangles;         /* input triangles, degenerate ones dropped */
	int dropped;           /* degenerate input triangles dropped */
	int border_edges;
	int nonmanifold_edges; /* edges with more than two faces */
	int seam_nodes;        /* nodes with more than one wedge */
	int locked_nodes;
	int eligible_nodes;
	int collapses;         /* recorded so far */
	int live_triangles;    /* after all of them */
	int caps;              /* collapses whose v-bar had more than 4 influences */
	int snaps;             /* collapses that snapped v-bar to a seam or border vertex */
	int refused;           /* candidate collapses refused as invalid */
	double build_seconds;
	double collapse_seconds;
} mlod_bgm_info;

void mlod_bgm_get_info(const mlod_bgm *g, mlod_bgm_info *out);

/* Collapses triangles, cheapest first, until at most target triangles are
 * left (0: as far as validity allows) or max_collapses more (0: no
 * limit); every collapse is appended to the sequence. May be called again
 * to go further. */
mlod_result mlod_bgm_simplify(mlod_bgm *g, int target, int max_collapses, mlod_error *err);

/* One recorded triangle collapse, a vertex-split record: undoing it
 * removes faces added_first .. added_first + added_count - 1 and brings
 * back the faces it removed. */
typedef struct mlod_vsplit {
	int parents[3];     /* the collapsed nodes (parents[2] is -1 for an edge) */
	int parent_count;   /* 3: a triangle collapse; 2: an edge collapse */
	int node;           /* v-bar */
	int snapped;        /* v-bar is at parents[snapped], or -1 */
	int removed_first;  /* into mlod_bgm_removed_faces */
	int removed_count;
	int added_first;    /* face ids */
	int added_count;
	int triangles;      /* live triangles after it */
	int capped;         /* v-bar's influences were capped to 4 */
	double cost;
	double seconds;     /* collapse time spent on this BGM up to and including it */
} mlod_vsplit;

/* The sequence so far (valid until the next mlod_bgm_simplify), and the
 * faces each record removed. */
const mlod_vsplit *mlod_bgm_sequence(const mlod_bgm *g, int *count);
const int *mlod_bgm_removed_faces(const mlod_bgm *g);

/* The shortest prefix of the sequence that leaves at most target
 * triangles, or the whole sequence when none does. */
int mlod_bgm_prefix_for(const mlod_bgm *g, int target);

/* A budget shared by several primitives (beyond the paper): the prefixes
 * of n simplified BGMs (NULL entries are skipped, prefix 0) that bring
 * their live triangles down to at most target in all, taking over every
 * sequence the next collapse of lowest cost first. Meaningful with the
 * posed cost, whose costs are errors in one unit across primitives.
 * Returns the triangles left (more than target when the sequences end). */
long mlod_bgm_share_budget(mlod_bgm *const *bgms, int n, long target, int *prefix);

/* The mesh after the first `prefix` collapses as a primitive (release it
 * with mlod_primitive_free): original vertices keep their attributes;
 * new ones get interpolated attributes (per wedge), morph target offsets,
 * and at most 4 influences in set 0. A rigid mesh gets one weight set with
 * joint 0 weight 1 when rigid_as_skinned is set, none otherwise. Unused
 * vertices are dropped. */
mlod_result mlod_bgm_extract(const mlod_bgm *g, int prefix, int rigid_as_skinned, mlod_primitive *out,
                             mlod_error *err);

/* Triangles live after the first `prefix` collapses (0: the input). */
int mlod_bgm_triangles(const mlod_bgm *g, int prefix);

/* Checks the live mesh's internal consistency (dual graph symmetric,
 * incidence lists, manifold fans at every node that was not locked);
 * MLOD_ERR_PARSE names the first problem. For tests. */
mlod_result mlod_bgm_check(const mlod_bgm *g, mlod_error *err);

/* Maps a primitive's joint indices through map (map_count entries; old
 * joint -> new joint), merging influences that land on the same joint
 * (weights add up, so sums are unchanged) and writing them back into the
 * same weight sets, largest first. Returns MLOD_ERR_INVALID_ARG when a
 * weighted joint is outside map (the vertices before it are already
 * remapped: check first when that matters). */
mlod_result mlod_primitive_remap_joints(mlod_primitive *p, const int *map, int map_count, mlod_error *err);


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

/* Zero-initialised options are the defaults. */
typedef struct mlod_motion_options {
	mlod_motion_merge merge;  /* frames method; MLOD_MOTION_REMOVE (the default) measured better */
	double cubic_rate;        /* CUBICSPLINE clips are resampled at least this often (1/s); 0 means 60 */
	double point_distance;    /* radius of the points carried by each joint for the point error
	                             (scene units); 0 means the skeleton height / 18 (10 cm on a 1.8 m
	                             person) */
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
 * or STEP, rotations normalised and sign-continuous. Release out with
 * mlod_clip_free. Bad clips (no channels, no keys, times not finite or
 * negative or not increasing, values not finite, zero quaternions) are
 * MLOD_ERR_PARSE; too many frames is MLOD_ERR_LIMIT. info may be NULL. */
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
void mlod_motion_free(mlod_motion *m);
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

#ifdef __cplusplus
}
#endif

#endif /* MLOD_H */
