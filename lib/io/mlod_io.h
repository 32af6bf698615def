/*
 * mlod_io.h: input and output: glTF through a C shim over tinygltf (C++,
 * lib/io/gltf_*.cpp; the bake side's other C++ is lib/pack's Draco shim),
 * BVH read and write, and format detection.
 */
#ifndef MLOD_IO_H
#define MLOD_IO_H

#include "model/mlod_model.h"

/* The deepest hierarchy the readers take, in levels from a root (the root
 * one): glTF nodes and BVH joints. The later stages walk joints to their
 * roots, so deeper input is MLOD_ERR_UNSUPPORTED (exit 3), with the line
 * (BVH) or node (glTF) too deep in the message. */
#define MLOD_MAX_HIERARCHY_DEPTH 1000

#ifdef __cplusplus
extern "C" {
#endif

/* ------------------------------------------------------------------ */
/* glTF (through a C shim over tinygltf)                               */
/* ------------------------------------------------------------------ */

/* An opaque glTF document. Everything mlod does not change (materials,
 * textures, cameras, extras, extensions, names, animations, skins) is kept
 * as read and written back unchanged; a glb joins the buffers into one
 * (mlod_gltf_write: the names of the buffers past the first go). */
typedef struct mlod_gltf mlod_gltf;

/* Parses .glb or .gltf bytes. base_dir resolves external URIs of a .gltf
 * (may be NULL: only data: URIs are then allowed). Draco- or
 * meshopt-compressed input is MLOD_ERR_UNSUPPORTED. A document that would
 * decode far more than its bytes is MLOD_ERR_NOMEM: accessors without a
 * buffer view may hold 16 values per byte of the input and its buffers
 * together, and the accessors that primitives, morph targets and animation
 * channels name (each counted once per reference) 4 elements per byte.
 * A property of the wrong JSON type or range for the glTF 2.0 schema (an
 * object for an array, a negative byteOffset or index, a non-object
 * extension, a primitive mode past 6) is MLOD_ERR_PARSE naming it ("meshes[0].primitives: not an
 * array"), where tinygltf would skip it or read 0. JSON nested deeper than
 * 100 levels is MLOD_ERR_UNSUPPORTED (valid JSON, beyond what mlod reads). */
mlod_result mlod_gltf_read(const void *data, size_t size, const char *base_dir,
                           mlod_gltf **out, mlod_error *err);
/* Reads a pack's DOC chunk (a glb, mlod(5)): as mlod_gltf_read without a
 * base directory, but a buffer emptied by stripping (byteLength 0,
 * whatever else it holds, as older mlod-pack wrote) is dropped first and
 * the buffer views renumbered; a view on such a buffer is MLOD_ERR_PARSE. */
mlod_result mlod_gltf_read_doc(const void *data, size_t size, mlod_gltf **out, mlod_error *err);
void mlod_gltf_free(mlod_gltf *doc);

/* Serialises the document: binary != 0 gives .glb (images read from
 * files or data: URIs go into its BIN chunk, a buffer view each), else
 * .gltf JSON with embedded buffers and images. *data is released with
 * mlod_free. */
mlod_result mlod_gltf_write(const mlod_gltf *doc, int binary, void **data,
                            size_t *size, mlod_error *err);

/* Builds the character model from the document's skins, meshes and
 * animations. Joint nodes are the union of all skins' joints plus the nodes
 * that connect them; a document without skins (such as a BVH converted by
 * mlod_gltf_from_character) uses its animated nodes instead of skin joints.
 * Instances are the nodes with a mesh that the default scene shows (when
 * there is no scene, every node but the MSFT_lod levels other nodes name,
 * and their children). What is skipped is listed in out->notes, and what
 * was changed, approximated or dropped of the input also in out->warnings. */
mlod_result mlod_gltf_to_character(const mlod_gltf *doc, mlod_character *out,
                                   mlod_error *err);
/* mlod_gltf_to_character for a document that will be written back (what
 * mlod_load does): the reader's rule for skin weights glTF does not allow
 * (mlod_primitive_fix_weights) then holds in the document too. Each
 * JOINTS_n and WEIGHTS_n accessor whose values the rule changed gets the
 * character's values, in its own component type where that can hold
 * them: floats stay floats, bit for bit; normalised unsigned bytes or
 * shorts (every set of the primitive in that one type) keep it, each
 * changed vertex's weights rounded by largest remainder to sum to
 * exactly 255 or 65535, and the character takes the values read back
 * from those; other weight types become floats, and joints stored as
 * unsigned bytes become unsigned shorts when the skin's root joint is
 * past 255. An accessor that only such primitives use and whose bytes
 * are its own (no sparse part, no other accessor or image on them) is
 * overwritten in place, its min and max kept true; otherwise the
 * primitive gets a new accessor, and the old data goes when nothing uses
 * it (as mlod_gltf_prune, but for a document it would refuse). Nothing
 * changes in a document whose weights are valid. On failure doc may be
 * partly changed. */
mlod_result mlod_gltf_to_character_fix(mlod_gltf *doc, mlod_character *out, mlod_error *err);

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

/* Removes what a pack's levels hold (mlod(5), the DOC chunk): every
 * triangle list's attributes, indices and morph targets (each keeps its
 * mode, material, extensions and extras; points, lines, strips and fans,
 * which the levels do not hold, stay whole), the joint channels (the
 * translation, rotation and scale channels of the joint_count nodes
 * joint_nodes lists, which a pack's MOTION chunks hold) and the morph
 * weights channels of nodes left without a mesh (a level node's copy):
 * other channels stay, with their samplers (a non-joint node's motion,
 * morph weights, KHR_animation_pointer); animations left without
 * channels go. MSFT_lod goes (level nodes stay, without mesh or skin),
 * then the accessors, buffer views and
 * bytes nothing uses. Node, mesh, skin, material, texture and image
 * indices hold; animation, accessor and buffer view indices change. The
 * result is not a valid glTF on its own (triangle lists without POSITION):
 * mlod-pack -x puts the levels back. A document using an extension that
 * may refer to accessors (as mlod_gltf_prune) is MLOD_ERR_UNSUPPORTED and
 * may be partly stripped: strip a copy. strip_mesh (NULL: every mesh)
 * holds a flag per mesh of the document: the triangle lists of a mesh
 * whose flag is 0 stay whole (a mesh the levels do not hold: outside the
 * default scene, or used by no node). */
mlod_result mlod_gltf_strip_levels(mlod_gltf *doc, const int *joint_nodes, int joint_count,
                                   const unsigned char *strip_mesh, mlod_error *err);

/* For a pack's DOC chunk (mlod-pack, mlod(5)): */
/* From now on (on != 0) mlod_gltf_drop_tail, mlod_gltf_drop_animation and
 * mlod_gltf_prune change no index that stays: a dropped animation must be
 * the last one (else MLOD_ERR_UNSUPPORTED, the document unchanged), and
 * only the accessors and buffer views after the last one in use go, with
 * each buffer's bytes after its last kept view (but in a buffer an
 * extension names); meshes stay. For a document using an extension mlod
 * does not know, which may hold any index: the DOC chunk that keeps the
 * input whole drops the levels the stages and mlod-pack -x append. */
void mlod_gltf_keep_indices(mlod_gltf *doc, int on);
/* Whether skin `skin` has inverse bind matrices (an accessor). */
int mlod_gltf_skin_has_inverse_binds(const mlod_gltf *doc, int skin);
/* Removes extras[key] of an object (its extras whole when nothing else is
 * left in them), but when extras[key] is an object with a member `keep`
 * (NULL: none), that member stays alone in it; nothing without the key. */
mlod_result mlod_gltf_remove_extra(mlod_gltf *doc, mlod_gltf_kind kind, int index, const char *key,
                                   const char *keep, mlod_error *err);
/* Drops the nodes from index `nodes` on, the skins from `skins` on and
 * the meshes from `meshes` on (a count at or past the end drops none),
 * then the accessors, views and bytes nothing uses. Every other index
 * holds. MLOD_ERR_UNSUPPORTED, the document unchanged, when something
 * kept (a node's mesh, skin or child, a skin's joint, a scene, an
 * animation channel, MSFT_lod) refers to one that would go. */
mlod_result mlod_gltf_drop_tail(mlod_gltf *doc, int nodes, int skins, int meshes, mlod_error *err);
/* Drops the translation, rotation and scale of a node (without a matrix)
 * whose numbers are exactly those of rest in `mode` and that are not the
 * default (identity); *dropped (may be NULL) gets them as bits 1, 2 and 4
 * (apply 0: counted, not dropped). Mode 0: each number is the f32 value
 * itself; mode 1: the shortest decimal that reads as the f32 value; mode
 * 2: the f32 value to 15 significant digits. Then
 * gives a node (without a matrix) each part of rest it lacks that is not
 * the default, in the numbers of `mode`: the two give the node back with
 * the same numbers. */
mlod_result mlod_gltf_drop_node_trs(mlod_gltf *doc, int node, const mlod_trs *rest, int mode, int apply,
                                    int *dropped, mlod_error *err);
mlod_result mlod_gltf_fill_node_trs(mlod_gltf *doc, int node, const mlod_trs *rest, int mode, mlod_error *err);
/* Drops an animation (later ones move down) and the data only it used. */
mlod_result mlod_gltf_drop_animation(mlod_gltf *doc, int animation, mlod_error *err);
/* Drops a skin's inverse bind matrices (the skin then has none, which
 * glTF reads as identities) and their bytes; and gives a skin count
 * matrices (one per joint) as a new accessor. */
mlod_result mlod_gltf_drop_inverse_binds(mlod_gltf *doc, int skin, mlod_error *err);
mlod_result mlod_gltf_set_inverse_binds(mlod_gltf *doc, int skin, const mlod_mat4 *ibm, int count, mlod_error *err);

/* The glTF mesh and skin a node points at (-1: none). */
mlod_result mlod_gltf_node_refs(const mlod_gltf *doc, int node, int *mesh, int *skin, mlod_error *err);

/* The nodes a node's MSFT_lod lists (its coarser levels, finest first):
 * the first max into ids, their number into *count (0 without MSFT_lod).
 * An ids entry that is not a node is MLOD_ERR_PARSE. */
mlod_result mlod_gltf_node_lod(const mlod_gltf *doc, int node, int *ids, int max, int *count, mlod_error *err);

/* Removes the meshes no node uses, then the accessors and buffer views
 * nothing uses, and packs the buffers again: indices of meshes, accessors
 * and buffer views change, every other index stays. A document using an
 * extension that may refer to those (beyond the KHR_materials_*,
 * KHR_texture_*, KHR_lights_punctual, KHR_mesh_quantization, KHR_xmp*,
 * EXT_texture_*, MSFT_lod, MSFT_texture_dds family, KHR_node_visibility and
 * EXT_materials_bump; KHR_animation_pointer is known when every pointer
 * names a node, material, camera or KHR_lights_punctual light) is
 * MLOD_ERR_UNSUPPORTED and left unchanged. */
mlod_result mlod_gltf_prune(mlod_gltf *doc, mlod_error *err);

/* Appends to mesh `to` a copy of each primitive of mesh `from` that is
 * not a triangle list (points, lines, strips, fans) and has attributes,
 * sharing its accessors, with its extras; *added (may be NULL) gets their
 * number. mlod-pack -x puts them after the level-0 parts (the pack holds
 * triangle lists only; the DOC keeps the others whole). */
mlod_result mlod_gltf_append_other_primitives(mlod_gltf *doc, int from, int to, int *added, mlod_error *err);

/* The names of the vertex attributes of primitive `primitive` of mesh
 * `mesh`, sorted, and its mode (4 when the file gives none): *names is an
 * array of *count strings and a NULL, in one block to release with
 * mlod_free. */
mlod_result mlod_gltf_primitive_attributes(const mlod_gltf *doc, int mesh, int primitive, int *mode, char ***names,
                                           int *count, mlod_error *err);

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

/* The first animation at index from or later named name, or -1. */
int mlod_gltf_find_animation(const mlod_gltf *doc, const char *name, int from);

/* Moves the last animation's samplers and channels to the end of
 * animation `into` (an earlier one, which keeps its name, extras and
 * extensions) and removes the last animation: mlod-pack -x puts a clip's
 * joint channels back beside the morph weights channels the DOC kept. */
mlod_result mlod_gltf_merge_animation(mlod_gltf *doc, int into, mlod_error *err);

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
 * A glTF document is read with mlod_gltf_to_character_fix: it holds the
 * skin weights the reader made valid, as the character does.
 * doc may be NULL when only the character is wanted. On failure nothing
 * is allocated. */
mlod_result mlod_load(const void *data, size_t size, const char *base_dir,
                      mlod_gltf **doc, mlod_character *c, mlod_format *format,
                      mlod_error *err);


#ifdef __cplusplus
}
#endif

#endif /* MLOD_IO_H */
