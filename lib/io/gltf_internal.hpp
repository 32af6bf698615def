/*
 * gltf_internal.hpp: internal to lib/io's glTF shim (mlod_io.h is the
 * public API), a C shim over tinygltf 2.7 that implements every mlod_gltf_*
 * function of mlod_io.h. What its files share: the document (struct
 * mlod_gltf), the errors, the stage record's keys, the accessor layout, and
 * the functions one file calls in another (in namespace mlod_gltf_internal;
 * every other function stays static in its file). A function's comment
 * stays at its definition.
 *
 * The files, each calling only files below it (scripts/check-call-cycles):
 *
 *   gltf_api.cpp        the C API: argument checks, then the layers below
 *   gltf_edit.cpp       extras; editing a read document: level meshes in
 *                       place, pruning, dropping and restoring what a pack
 *                       keeps
 *   gltf_read.cpp       reading: tinygltf with mlod's file callbacks, then
 *                       what the reader adds (a scene, unit rotations)
 *   gltf_decompress.cpp meshopt and Draco compression made plain before
 *                       tinygltf reads the document
 *   gltf_model.cpp      glTF -> character (mlod_gltf_to_character), and
 *                       character -> glTF: meshes, skins, animations, nodes
 *   gltf_write.cpp      writing: tinygltf's JSON reconciled with the input's
 *   gltf_check.cpp      the checks of a document: the glb container and the
 *                       JSON before tinygltf, every reference after it
 *   gltf_accessor.cpp   accessors: layouts, checks, decoding
 *   gltf_util.cpp       errors, C allocation, strings, JSON, node transforms
 *
 * Reading. mlod_gltf_read checks what tinygltf does not before handing it
 * the bytes: the glb container's length fields, the JSON syntax and nesting
 * depth, required extensions mlod cannot read, and the URIs of external
 * buffers. A document using EXT_/KHR_meshopt_compression or
 * KHR_draco_mesh_compression is rewritten into a plain glb (one buffer,
 * every compressed buffer view and Draco primitive decoded), since the
 * Debian tinygltf knows neither. tinygltf then parses the document, keeping
 * images as their encoded bytes (no decoding). Finally every cross-reference
 * is checked (node hierarchy, accessors inside buffer views inside buffers),
 * so the rest of the shim can index the model without re-checking, and no
 * two channels of an animation may target the same node and path.
 *
 * Writing. tinygltf 2.7 serialises the model, but it drops data (empty
 * objects inside extras, accessor and buffer extensions, ...) and writes
 * defaults the input left out. The JSON it writes is therefore reconciled
 * with the JSON as read: objects that came from the input keep exactly
 * their keys, plus those mlod adds, and extras come from an exact copy.
 * A glb's BIN chunk holds every buffer (buffers 1.. appended to buffer 0,
 * unless their indices matter beyond the buffer views) and every image
 * that was not in a buffer view (in a view of its own); a .gltf embeds
 * buffers and such images as data: URIs, bytes unchanged.
 *
 * Character model. mlod_gltf_to_character decodes skins, meshes (every
 * accessor layout: normalised integers, strides, sparse) and animations
 * into the structures of mlod.h; mlod_gltf_from_character and the
 * mlod_gltf_add_* functions build glTF from them.
 *
 * No C++ exception crosses into C: errors are thrown as Failure and turned
 * into mlod_result codes by guard(), as are std::bad_alloc and anything
 * tinygltf or nlohmann::json throw.
 *
 * tinygltf is the compiled library (-ltinygltf): no file here defines
 * TINYGLTF_IMPLEMENTATION.
 */
#ifndef MLOD_GLTF_INTERNAL_HPP
#define MLOD_GLTF_INTERNAL_HPP

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <tiny_gltf.h>

#include "io/mlod_io.h"

struct mlod_gltf {
	tinygltf::Model model;
	/* The JSON as read (without URIs), to write back what tinygltf drops;
	 * null for documents mlod built. */
	nlohmann::json original;
	/* Exact extras by JSON pointer ("/nodes/3/extras"): those read from
	 * the input and those set through mlod_gltf_set_extra. They win over
	 * the tinygltf::Value of the object, which cannot hold all of JSON. */
	std::map<std::string, nlohmann::json> extras;
	/* The roots of the scene the reader added to a document without one
	 * (0: none added). */
	int scene_added = 0;
	/* Node rotations the reader normalised (not unit within
	 * MLOD_UNIT_QUAT_TOLERANCE), the first of them and its length. */
	int rotations_normalised = 0;
	int rotation_node = -1;
	double rotation_length = 0.0;
	/* External images the reader could not read (a missing file, or no
	 * directory to find them in): "image I: \"URI\" ...why", one each. The
	 * output keeps their URIs; the character reader warns of them. */
	std::vector<std::string> unread_images;
	/* mlod_gltf_keep_indices: what goes, goes from the end of its array
	 * only (prune, drop_animation), so that no index an unknown extension
	 * may hold changes. */
	bool keep_indices = false;
};

namespace mlod_gltf_internal {

using json = nlohmann::json;
using tinygltf::Model;
using tinygltf::Value;

/* ------------------------------------------------------------------ */
/* Errors                                                              */
/* ------------------------------------------------------------------ */

struct Failure {
	mlod_result code;
	std::string message;
};

[[noreturn]] void fail(mlod_result code, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* Runs body, turning whatever it throws into a result code and message. */
template <class F> mlod_result guard(mlod_error *err, F &&body)
{
	try {
		body();
		return MLOD_OK;
	} catch (const Failure &f) {
		return mlod_fail(err, f.code, "%s", f.message.c_str());
	} catch (const std::bad_alloc &) {
		return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
	} catch (const std::length_error &) {
		return mlod_fail(err, MLOD_ERR_NOMEM, "glTF data too large");
	} catch (const std::out_of_range &) {
		/* (tinygltf's unchecked indices: never the library's text) */
		return mlod_fail(err, MLOD_ERR_PARSE, "glTF: an index or a length is out of range");
	} catch (const std::exception &) {
		return mlod_fail(err, MLOD_ERR_PARSE, "glTF: the document is malformed");
	} catch (...) {
		return mlod_fail(err, MLOD_ERR_PARSE, "glTF: unknown error");
	}
}

/* ------------------------------------------------------------------ */
/* Small helpers: C allocation, strings, JSON                          */
/* ------------------------------------------------------------------ */

/* A zeroed C array of n elements, released with free(); NULL when n == 0. */
template <class T> T *c_array(size_t n)
{
	if (n == 0)
		return nullptr;
	void *p = calloc(n, sizeof(T));
	if (!p)
		throw std::bad_alloc();
	return static_cast<T *>(p);
}

template <class T> T *c_copy(const std::vector<T> &v)
{
	T *p = c_array<T>(v.size());
	if (p)
		memcpy(p, v.data(), v.size() * sizeof(T));
	return p;
}

/* The glTF reader's own keys of the stage record (mlod-record(5)): a BVH
 * turned into glTF marks its End Site nodes extras.mlod.end_site = true,
 * keeps each joint's channel layout in extras.mlod_bvh.channels and its
 * clip's frame time in extras.mlod_bvh.frame_time of the animation. The
 * character reader (is_end_site, bvh_layout, bvh_frames in
 * gltf_model.cpp) is their one reader and build_document
 * (gltf_model.cpp; mlod_load, load.c, for the frame time) their one
 * writer; the rest of extras.mlod belongs to lib/record, above this
 * shim. */
const char *const record_key = "mlod", *const record_end_site = "end_site";
const char *const bvh_key = "mlod_bvh", *const bvh_channels = "channels", *const bvh_frame_time = "frame_time";

/* The glb container's magic and chunk types. */
const uint32_t glb_magic = 0x46546C67, chunk_json = 0x4E4F534A, chunk_bin = 0x004E4942;

inline uint32_t le32(const unsigned char *p)
{
	return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}

/* How an accessor's elements are laid out. Matrix columns start on 4-byte
 * boundaries, which pads MAT2 and MAT3 of 1- and 2-byte components. */
struct Layout {
	int components;      /* per element */
	int rows;            /* of a matrix column; 0 for scalars and vectors */
	size_t size;         /* bytes per component */
	size_t column_bytes; /* matrices only */
	size_t element;      /* bytes per element */

	size_t offset(int c) const { return rows ? size_t(c / rows) * column_bytes + size_t(c % rows) * size : size_t(c) * size; }
};

/* Decoded arrays are limited to this many values: a hostile count cannot
 * make mlod allocate without bound. */
const size_t max_values = size_t(1) << 28;

/* The extras Value of an object and its JSON pointer. Doc is mlod_gltf or
 * const mlod_gltf. */
template <class Doc> auto extras_slot(Doc &doc, mlod_gltf_kind kind, int index, std::string *pointer)
    -> decltype(&doc.model.asset.extras)
{
	auto &m = doc.model;
	auto pick = [&](auto &list, const char *name, const char *what) {
		if (index < 0 || size_t(index) >= list.size())
			fail(MLOD_ERR_INVALID_ARG, "%s %d does not exist (the document has %zu)", what, index, list.size());
		*pointer = std::string("/") + name + "/" + std::to_string(index) + "/extras";
		return &list[size_t(index)].extras;
	};
	switch (kind) {
	case MLOD_GLTF_NODE: return pick(m.nodes, "nodes", "node");
	case MLOD_GLTF_SKIN: return pick(m.skins, "skins", "skin");
	case MLOD_GLTF_MESH: return pick(m.meshes, "meshes", "mesh");
	case MLOD_GLTF_ANIMATION: return pick(m.animations, "animations", "animation");
	case MLOD_GLTF_SCENE:
		if (index == -1) {
			if (m.scenes.empty())
				fail(MLOD_ERR_INVALID_ARG, "the document has no scene");
			index = m.defaultScene >= 0 ? m.defaultScene : 0;
		}
		return pick(m.scenes, "scenes", "scene");
	case MLOD_GLTF_ASSET:
		*pointer = "/asset/extras";
		return &m.asset.extras;
	}
	fail(MLOD_ERR_INVALID_ARG, "unknown glTF object kind %d", int(kind));
}

/* In gltf_util.cpp */
char *c_string(const std::string &s);
std::string quoted(const std::string &s);
bool known_path(const std::string &p);
std::string utf8(const char *s);
double tidy(float f);
json parse_json(const char *text, size_t size);
json parse_written_json(const char *text, size_t size);
std::string dump_json(const json &j, int indent);
/* A glb of JSON j (compact, padded) and bin_chunk, the BIN chunk with its
 * header and padding (empty: none); MLOD_ERR_LIMIT past 4 GiB. */
std::string glb_bytes(const json &j, const std::string &bin_chunk);
/* The bytes of the file at path into out, or false with why ("cannot
 * open", "larger than 4 GiB", "read error"). */
bool read_file(const std::string &path, std::vector<unsigned char> &out, std::string *why);
std::string pointer_token(const std::string &key);
Value to_value(const json &j);
json current_extras(const mlod_gltf &doc, const std::string &pointer, const Value &value);
void extension_refs(const json &j, bool inside, std::vector<bool> &views, std::vector<bool> &buffers);
mlod_trs node_trs(const tinygltf::Node &n);
mlod_mat4 node_matrix(const tinygltf::Node &n);
bool is_identity(const mlod_mat4 &m);
void set_trs(tinygltf::Node &n, const mlod_trs &t);
void set_transform(tinygltf::Node &n, const mlod_mat4 &m);

/* In gltf_check.cpp */
std::string glb_json(const unsigned char *d, size_t size);
void check_types(const json &j);
void check_required_extensions(const json &doc);
std::string printable(const char *text);
bool stays_inside(const std::string &path);
std::string join_path(const std::string &dir, const std::string &file);
void check_buffer_uris(const json &doc, const char *base_dir);
void check_image_uris(const json &doc, const char *base_dir);
std::string url_decode(const std::string &s);
std::vector<int> node_parents(const Model &m);
void check_document(const Model &m, size_t input_size);
std::vector<char> lod_level_nodes(const Model &m);

/* In gltf_decompress.cpp */
bool decompress(json &j, const unsigned char *data, bool binary, const char *base_dir, std::string &out);

/* In gltf_read.cpp */
void read_document(mlod_gltf &doc, const unsigned char *data, size_t size, const char *base_dir);
void read_pack_document(mlod_gltf &doc, const unsigned char *d, size_t size);

/* In gltf_accessor.cpp */
size_t component_size(int component_type);
Layout layout_of(const tinygltf::Accessor &a);
void check_view(const Model &m, size_t v);
void check_accessor(const Model &m, size_t i);
std::vector<float> read_floats(const Model &m, int i, const std::string &what, int type, int other_type = -1);
std::vector<uint32_t> read_uints(const Model &m, int i, const std::string &what, int type);

/* In gltf_write.cpp */
std::string serialize(const mlod_gltf &doc, bool binary);

/* In gltf_model.cpp: glTF -> character */
void read_character(const mlod_gltf &doc, mlod_character &c, std::vector<std::pair<int, int>> *fixed = nullptr);

/* In gltf_model.cpp: character -> glTF */
int append_accessor(Model &m, const void *data, size_t count, int component_type, int type, int comps, int target,
                    bool min_max);
int append_floats(Model &m, const float *v, size_t count, int comps, int target, bool min_max = false);
void check_finite(const float *v, size_t n, const char *what);
int add_mesh(Model &m, const mlod_mesh &mesh);
int add_mesh_reskinned(mlod_gltf &doc, int mesh, const mlod_mesh &m);
int add_skin(Model &m, const mlod_skin &skin, const std::vector<int> &nodes);
int add_animation(Model &m, const mlod_clip &clip, const std::vector<int> &nodes);
tinygltf::Scene &default_scene(Model &m);
void build_document(Model &m, const mlod_character &c);

/* In gltf_edit.cpp */
void set_extra(mlod_gltf &doc, mlod_gltf_kind kind, int index, const std::string &key, const json &v);
std::vector<int> joint_nodes(const mlod_skeleton *s);
int add_mesh_like(mlod_gltf &doc, int like, const mlod_mesh &mesh);
void prune(mlod_gltf &doc, bool meshes = true);
int copy_morph_animation(Model &m, int from, int to);
void clear_lod(mlod_gltf &doc, int node);
void strip_levels(mlod_gltf &doc, const int *joint_nodes, int joint_count, const unsigned char *strip_mesh);
void remove_extra(mlod_gltf &doc, mlod_gltf_kind kind, int index, const std::string &key, const std::string &keep);
void drop_tail(mlod_gltf &doc, int nodes, int skins, int meshes);
int drop_node_trs(mlod_gltf &doc, int node, const mlod_trs &rest, int mode, bool apply);
void fill_node_trs(mlod_gltf &doc, int node, const mlod_trs &rest, int mode);
void drop_animation(mlod_gltf &doc, int a);
void drop_inverse_binds(mlod_gltf &doc, int k);
void set_inverse_binds(mlod_gltf &doc, int k, const mlod_mat4 *ibm, int count);
void set_skin_weights(mlod_gltf &doc, mlod_character &c, const std::vector<std::pair<int, int>> &fixed);

} /* namespace mlod_gltf_internal */

#endif
