/*
 * gltf.cpp: the glTF half of libmlod, a C shim over tinygltf 2.7 (the only
 * C++ in the library). It implements every mlod_gltf_* function of mlod.h.
 *
 * Reading. mlod_gltf_read checks what tinygltf does not before handing it
 * the bytes: the glb container's length fields, the JSON syntax and nesting
 * depth, required extensions mlod cannot decode (Draco, meshopt), and the
 * URIs of external buffers. tinygltf then parses the document, keeping
 * images as their encoded bytes (no decoding). Finally every cross-reference
 * is checked (node hierarchy, accessors inside buffer views inside buffers),
 * so the rest of this file can index the model without re-checking, and no
 * two channels of an animation may target the same node and path.
 *
 * Writing. tinygltf 2.7 serialises the model, but it drops data (empty
 * objects inside extras, accessor and buffer extensions, ...) and writes
 * defaults the input left out. The JSON it writes is therefore reconciled
 * with the JSON as read: objects that came from the input keep exactly
 * their keys, plus those mlod adds, and extras come from an exact copy.
 * Buffer 0 becomes the glb's BIN chunk; other buffers and images that were
 * not in a buffer view are embedded as data: URIs, bytes unchanged.
 *
 * Character model. mlod_gltf_to_character decodes skins, meshes (every
 * accessor layout: normalised integers, strides, sparse) and animations
 * into the structures of mlod.h; mlod_gltf_from_character and the
 * mlod_gltf_add_* functions build glTF from them.
 *
 * No C++ exception crosses into C: errors are thrown as Failure and turned
 * into mlod_result codes by guard(), as are std::bad_alloc and anything
 * tinygltf or nlohmann::json throw.
 */
#include <sys/stat.h>

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

using json = nlohmann::json;
using tinygltf::Model;
using tinygltf::Value;

struct mlod_gltf {
	Model model;
	/* The JSON as read (without URIs), to write back what tinygltf drops;
	 * null for documents mlod built. */
	json original;
	/* Exact extras by JSON pointer ("/nodes/3/extras"): those read from
	 * the input and those set through mlod_gltf_set_extra. They win over
	 * the tinygltf::Value of the object, which cannot hold all of JSON. */
	std::map<std::string, json> extras;
	/* The roots of the scene the reader added to a document without one
	 * (0: none added). */
	int scene_added = 0;
	/* Node rotations the reader normalised (not unit within
	 * MLOD_UNIT_QUAT_TOLERANCE), the first of them and its length. */
	int rotations_normalised = 0;
	int rotation_node = -1;
	double rotation_length = 0.0;
	/* mlod_gltf_keep_indices: what goes, goes from the end of its array
	 * only (prune, drop_animation), so that no index an unknown extension
	 * may hold changes. */
	bool keep_indices = false;
};

namespace {

/* ------------------------------------------------------------------ */
/* Errors                                                              */
/* ------------------------------------------------------------------ */

struct Failure {
	mlod_result code;
	std::string message;
};

[[noreturn]] void fail(mlod_result code, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

void fail(mlod_result code, const char *fmt, ...)
{
	char message[MLOD_ERROR_MESSAGE_SIZE];
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(message, sizeof message, fmt, ap);
	va_end(ap);
	throw Failure{code, message};
}

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

char *c_string(const std::string &s)
{
	char *p = static_cast<char *>(malloc(s.size() + 1));
	if (!p)
		throw std::bad_alloc();
	memcpy(p, s.c_str(), s.size() + 1);
	return p;
}

/* s in double quotes as in JSON (quote, backslash and control characters
 * escaped), for a name from the file in a one-line message. */
std::string quoted(const std::string &s)
{
	std::string out = "\"";
	for (unsigned char ch : s) {
		if (ch == '"' || ch == '\\') {
			out += '\\';
			out += char(ch);
		} else if (ch < 0x20 || ch == 0x7f) {
			char buf[8];
			snprintf(buf, sizeof buf, "\\u%04x", ch);
			out += buf;
		} else {
			out += char(ch);
		}
	}
	return out + "\"";
}

/* One of the four paths glTF 2.0 defines for an animation channel. */
bool known_path(const std::string &p)
{
	return p == "translation" || p == "rotation" || p == "scale" || p == "weights";
}

/* s with invalid UTF-8 replaced by U+FFFD: JSON text must be UTF-8, and
 * names from BVH files or callers may be Latin-1. */
std::string utf8(const char *s)
{
	std::string out;
	for (const char *p = s ? s : ""; *p;) {
		int n = mlod_utf8_length(p);
		if (n > 0)
			out.append(p, size_t(n)), p += n;
		else
			out += "\xEF\xBF\xBD", p++;
	}
	return out;
}

/* The double whose shortest decimal form reads back as f: 0.1f is written
 * 0.1 rather than 0.10000000149011612. */
double tidy(float f)
{
	char buf[32];
	for (int digits = 6; digits < 9; digits++) {
		snprintf(buf, sizeof buf, "%.*g", digits, double(f));
		double d = strtod(buf, nullptr);
		if (float(d) == f)
			return d;
	}
	return double(f);
}

/* The glTF reader's own keys of the stage record (mlod-record(5)): a BVH
 * turned into glTF marks its End Site nodes extras.mlod.end_site = true,
 * keeps each joint's channel layout in extras.mlod_bvh.channels and its
 * clip's frame time in extras.mlod_bvh.frame_time of the animation. The
 * reader below (is_end_site, bvh_layout, bvh_frames) is their one reader
 * and build_document (mlod_load, load.c, for the frame time) their one
 * writer; the rest of extras.mlod belongs to lib/record, above this
 * file. */
const char *const record_key = "mlod", *const record_end_site = "end_site";
const char *const bvh_key = "mlod_bvh", *const bvh_channels = "channels", *const bvh_frame_time = "frame_time";

/* Deeper JSON is refused: tinygltf converts it recursively. */
const int max_json_depth = 100;

/* nlohmann's DOM builder with the depth limit, as a SAX handler. The limit
 * used to be a json::parse callback, but nlohmann 3.11's callback parser
 * rescans the enclosing array at every closing object, which made reading
 * quadratic in array lengths: 40,000 empty nodes took 3.9 s, 300,000 did
 * not finish in 120 s. The depth is the one the callback saw (the number of
 * open arrays and objects around a key or value, or around the bracket
 * that opens one), so the same documents are refused, at the same point. */
struct depth_limited_dom : nlohmann::detail::json_sax_dom_parser<json> {
	using base = nlohmann::detail::json_sax_dom_parser<json>;
	int depth = 0;
	explicit depth_limited_dom(json &j) : base(j) {}
	void check() const
	{
		if (depth > max_json_depth)
			fail(MLOD_ERR_PARSE, "JSON nested deeper than %d levels", max_json_depth);
	}
	bool null() { check(); return base::null(); }
	bool boolean(bool v) { check(); return base::boolean(v); }
	bool number_integer(json::number_integer_t v) { check(); return base::number_integer(v); }
	bool number_unsigned(json::number_unsigned_t v) { check(); return base::number_unsigned(v); }
	bool number_float(json::number_float_t v, const json::string_t &s) { check(); return base::number_float(v, s); }
	bool string(json::string_t &v) { check(); return base::string(v); }
	bool binary(json::binary_t &v) { check(); return base::binary(v); }
	bool key(json::string_t &v) { check(); return base::key(v); }
	bool start_object(std::size_t n) { check(); depth++; return base::start_object(n); }
	bool start_array(std::size_t n) { check(); depth++; return base::start_array(n); }
	bool end_object() { depth--; return base::end_object(); }
	bool end_array() { depth--; return base::end_array(); }
};

json parse_json(const char *text, size_t size)
{
	json j;
	depth_limited_dom dom(j);
	json::sax_parse(text, text + size, &dom);
	return j;
}

std::string pointer_token(const std::string &key)
{
	std::string t;
	for (char ch : key)
		t += ch == '~' ? "~0" : ch == '/' ? "~1" : std::string(1, ch);
	return t;
}

json to_json(const Value &v)
{
	switch (v.Type()) {
	case tinygltf::BOOL_TYPE:
		return v.Get<bool>();
	case tinygltf::INT_TYPE:
		return v.Get<int>();
	case tinygltf::REAL_TYPE:
		return v.Get<double>();
	case tinygltf::STRING_TYPE:
		return v.Get<std::string>();
	case tinygltf::ARRAY_TYPE: {
		json a = json::array();
		for (size_t i = 0; i < v.ArrayLen(); i++)
			a.push_back(to_json(v.Get(int(i))));
		return a;
	}
	case tinygltf::OBJECT_TYPE: {
		json o = json::object();
		for (const auto &kv : v.Get<Value::Object>())
			o[kv.first] = to_json(kv.second);
		return o;
	}
	default:
		return nullptr;
	}
}

Value to_value(const json &j)
{
	switch (j.type()) {
	case json::value_t::boolean:
		return Value(j.get<bool>());
	case json::value_t::number_integer: {
		int64_t i = j.get<int64_t>();
		return i >= INT_MIN && i <= INT_MAX ? Value(int(i)) : Value(double(i));
	}
	case json::value_t::number_unsigned: {
		uint64_t u = j.get<uint64_t>();
		return u <= uint64_t(INT_MAX) ? Value(int(u)) : Value(double(u));
	}
	case json::value_t::number_float:
		return Value(j.get<double>());
	case json::value_t::string:
		return Value(j.get<std::string>());
	case json::value_t::array: {
		Value::Array a;
		for (const auto &e : j)
			a.push_back(to_value(e));
		return Value(std::move(a));
	}
	case json::value_t::object: {
		Value::Object o;
		for (auto it = j.begin(); it != j.end(); ++it)
			o[it.key()] = to_value(*it);
		return Value(std::move(o));
	}
	default:
		return Value();
	}
}

/* The extras of an object: the exact copy at pointer if there is one,
 * else its Value. */
json current_extras(const mlod_gltf &doc, const std::string &pointer, const Value &value)
{
	auto it = doc.extras.find(pointer);
	return it != doc.extras.end() ? it->second : to_json(value);
}

/* ------------------------------------------------------------------ */
/* Reading: checks before tinygltf                                     */
/* ------------------------------------------------------------------ */

const uint32_t glb_magic = 0x46546C67, chunk_json = 0x4E4F534A, chunk_bin = 0x004E4942;

uint32_t le32(const unsigned char *p)
{
	return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}

/* Checks the glb container (tinygltf reads 8 bytes past a BIN chunk that
 * claims to end at the end of the file) and returns its JSON chunk. */
std::string glb_json(const unsigned char *d, size_t size)
{
	if (size < 20)
		fail(MLOD_ERR_PARSE, "glb: truncated: %zu bytes, less than a header and a chunk header", size);
	uint32_t version = le32(d + 4), length = le32(d + 8);
	if (version != 2)
		fail(MLOD_ERR_UNSUPPORTED, "glb: container version %u (only 2 is supported)", version);
	if (length > size)
		fail(MLOD_ERR_PARSE, "glb: truncated: the header says %u bytes, the input has %zu", length, size);
	if (length < 20)
		fail(MLOD_ERR_PARSE, "glb: the header says %u bytes, too short for a JSON chunk", length);
	uint32_t json_length = le32(d + 12);
	if (le32(d + 16) != chunk_json)
		fail(MLOD_ERR_PARSE, "glb: the first chunk is not JSON");
	if (json_length > length - 20)
		fail(MLOD_ERR_PARSE, "glb: the JSON chunk (%u bytes) extends past the end of the file (%u bytes)",
		     json_length, length);
	size_t at = 20 + size_t(json_length);
	if (at < length) {
		if (length - at < 8)
			fail(MLOD_ERR_PARSE, "glb: truncated chunk header at byte %zu", at);
		uint32_t bin_length = le32(d + at);
		if (le32(d + at + 4) == chunk_bin && bin_length > length - at - 8)
			fail(MLOD_ERR_PARSE, "glb: the BIN chunk (%u bytes) extends past the end of the file (%u bytes)",
			     bin_length, length);
	}
	return std::string(reinterpret_cast<const char *>(d) + 20, json_length);
}

/* Required extensions that only touch what mlod passes through unchanged
 * (materials, textures, lights) or that the accessor decoder handles. */
bool extension_supported(const std::string &name)
{
	static const char *const prefixes[] = {"KHR_materials_", "KHR_texture_", "EXT_texture_", "KHR_lights_punctual",
	                                       "KHR_mesh_quantization", "MSFT_texture_dds"};
	for (const char *p : prefixes)
		if (name.compare(0, strlen(p), p) == 0)
			return true;
	return false;
}

/* The glTF 2.0 schema's types and ranges of the properties mlod or
 * tinygltf reads, which tinygltf leniently skips or reads as 0 (a
 * primitives object, a byteOffset of -8): each a message naming the
 * object ("meshes[0].primitives: not an array"). */
struct TypeCheck {
	enum Kind { Index, Uint, Number, String, Bool, Object, Numbers, Indices, Strings, Array, Any };
	struct Prop {
		const char *name;
		Kind kind;
		const Prop *members; /* Object: its properties; Array: its elements' (objects) */
	};

	[[noreturn]] static void bad(const std::string &at, const char *what)
	{
		fail(MLOD_ERR_PARSE, "%s: %s", at.c_str(), what);
	}
	static bool is_uint(const json &v)
	{
		if (v.is_number_unsigned())
			return true;
		if (v.is_number_integer())
			return v.get<long long>() >= 0;
		if (v.is_number_float()) {
			double d = v.get<double>();
			return d >= 0 && d <= 4294967295.0 && d == std::floor(d);
		}
		return false;
	}
	static void value(const json &v, Kind kind, const Prop *members, const std::string &at)
	{
		switch (kind) {
		case Index:
			if (!is_uint(v))
				bad(at, "not an index (a non-negative integer)");
			break;
		case Uint:
			if (!is_uint(v))
				bad(at, "not a non-negative integer");
			break;
		case Number:
			if (!v.is_number())
				bad(at, "not a number");
			break;
		case String:
			if (!v.is_string())
				bad(at, "not a string");
			break;
		case Bool:
			if (!v.is_boolean())
				bad(at, "not a boolean");
			break;
		case Object:
			object(v, members, at);
			break;
		case Numbers:
		case Indices:
		case Strings:
		case Array:
			if (!v.is_array())
				bad(at, "not an array");
			for (size_t i = 0; i < v.size(); i++)
				value(v[i], kind == Numbers ? Number : kind == Indices ? Index : kind == Strings ? String : Object,
				      members, at + "[" + std::to_string(i) + "]");
			break;
		case Any:
			break;
		}
	}
	static void object(const json &v, const Prop *members, const std::string &at)
	{
		if (!v.is_object())
			bad(at, "not an object");
		if (v.contains("name") && !v["name"].is_string())
			bad(at + ".name", "not a string");
		if (v.contains("extensions")) {
			const json &e = v["extensions"];
			if (!e.is_object())
				bad(at + ".extensions", "not an object");
			for (auto it = e.begin(); it != e.end(); ++it)
				if (!it->is_object())
					bad(at + ".extensions." + it.key(), "not an object");
		}
		for (const Prop *p = members; p && p->name; p++)
			if (v.contains(p->name))
				value(v[p->name], p->kind, p->members, at + "." + p->name);
	}
};

void check_types(const json &j)
{
	using P = TypeCheck::Prop;
	using K = TypeCheck;
	static const P texture_info[] = {{"index", K::Index, nullptr}, {"texCoord", K::Uint, nullptr},
	                                 {"scale", K::Number, nullptr}, {"strength", K::Number, nullptr}, {}};
	static const P pbr[] = {{"baseColorFactor", K::Numbers, nullptr}, {"baseColorTexture", K::Object, texture_info},
	                        {"metallicFactor", K::Number, nullptr}, {"roughnessFactor", K::Number, nullptr},
	                        {"metallicRoughnessTexture", K::Object, texture_info}, {}};
	static const P material[] = {{"pbrMetallicRoughness", K::Object, pbr}, {"normalTexture", K::Object, texture_info},
	                             {"occlusionTexture", K::Object, texture_info},
	                             {"emissiveTexture", K::Object, texture_info}, {"emissiveFactor", K::Numbers, nullptr},
	                             {"alphaMode", K::String, nullptr}, {"alphaCutoff", K::Number, nullptr},
	                             {"doubleSided", K::Bool, nullptr}, {}};
	static const P none[] = {{}};
	static const P primitive[] = {{"attributes", K::Object, none}, {"indices", K::Index, nullptr},
	                              {"material", K::Index, nullptr}, {"mode", K::Uint, nullptr},
	                              {"targets", K::Array, none}, {}};
	static const P mesh[] = {{"primitives", K::Array, primitive}, {"weights", K::Numbers, nullptr}, {}};
	static const P sparse_indices[] = {{"bufferView", K::Index, nullptr}, {"byteOffset", K::Uint, nullptr},
	                                   {"componentType", K::Uint, nullptr}, {}};
	static const P sparse_values[] = {{"bufferView", K::Index, nullptr}, {"byteOffset", K::Uint, nullptr}, {}};
	static const P sparse[] = {{"count", K::Uint, nullptr}, {"indices", K::Object, sparse_indices},
	                           {"values", K::Object, sparse_values}, {}};
	static const P accessor[] = {{"bufferView", K::Index, nullptr}, {"byteOffset", K::Uint, nullptr},
	                             {"componentType", K::Uint, nullptr}, {"normalized", K::Bool, nullptr},
	                             {"count", K::Uint, nullptr}, {"type", K::String, nullptr},
	                             {"max", K::Numbers, nullptr}, {"min", K::Numbers, nullptr},
	                             {"sparse", K::Object, sparse}, {}};
	static const P target[] = {{"node", K::Index, nullptr}, {"path", K::String, nullptr}, {}};
	static const P channel[] = {{"sampler", K::Index, nullptr}, {"target", K::Object, target}, {}};
	static const P anim_sampler[] = {{"input", K::Index, nullptr}, {"interpolation", K::String, nullptr},
	                                 {"output", K::Index, nullptr}, {}};
	static const P animation[] = {{"channels", K::Array, channel}, {"samplers", K::Array, anim_sampler}, {}};
	static const P asset[] = {{"version", K::String, nullptr}, {"minVersion", K::String, nullptr},
	                          {"generator", K::String, nullptr}, {"copyright", K::String, nullptr}, {}};
	static const P buffer[] = {{"uri", K::String, nullptr}, {"byteLength", K::Uint, nullptr}, {}};
	static const P view[] = {{"buffer", K::Index, nullptr}, {"byteOffset", K::Uint, nullptr},
	                         {"byteLength", K::Uint, nullptr}, {"byteStride", K::Uint, nullptr},
	                         {"target", K::Uint, nullptr}, {}};
	static const P camera[] = {{"type", K::String, nullptr}, {"orthographic", K::Object, none},
	                           {"perspective", K::Object, none}, {}};
	static const P image[] = {{"uri", K::String, nullptr}, {"mimeType", K::String, nullptr},
	                          {"bufferView", K::Index, nullptr}, {}};
	static const P node[] = {{"camera", K::Index, nullptr}, {"children", K::Indices, nullptr},
	                         {"skin", K::Index, nullptr}, {"matrix", K::Numbers, nullptr},
	                         {"mesh", K::Index, nullptr}, {"rotation", K::Numbers, nullptr},
	                         {"scale", K::Numbers, nullptr}, {"translation", K::Numbers, nullptr},
	                         {"weights", K::Numbers, nullptr}, {}};
	static const P sampler[] = {{"magFilter", K::Uint, nullptr}, {"minFilter", K::Uint, nullptr},
	                            {"wrapS", K::Uint, nullptr}, {"wrapT", K::Uint, nullptr}, {}};
	static const P scene[] = {{"nodes", K::Indices, nullptr}, {}};
	static const P skin[] = {{"inverseBindMatrices", K::Index, nullptr}, {"skeleton", K::Index, nullptr},
	                         {"joints", K::Indices, nullptr}, {}};
	static const P texture[] = {{"sampler", K::Index, nullptr}, {"source", K::Index, nullptr}, {}};
	static const P root[] = {{"extensionsUsed", K::Strings, nullptr}, {"extensionsRequired", K::Strings, nullptr},
	                         {"accessors", K::Array, accessor}, {"animations", K::Array, animation},
	                         {"asset", K::Object, asset}, {"buffers", K::Array, buffer},
	                         {"bufferViews", K::Array, view}, {"cameras", K::Array, camera},
	                         {"images", K::Array, image}, {"materials", K::Array, material},
	                         {"meshes", K::Array, mesh}, {"nodes", K::Array, node},
	                         {"samplers", K::Array, sampler}, {"scene", K::Index, nullptr},
	                         {"scenes", K::Array, scene}, {"skins", K::Array, skin},
	                         {"textures", K::Array, texture}, {}};
	for (const P *p = root; p->name; p++)
		if (j.contains(p->name))
			TypeCheck::value(j[p->name], p->kind, p->members, p->name);
	if (j.contains("extensions"))
		TypeCheck::object(json::object({{"extensions", j["extensions"]}}), none, "the document");
	/* Each primitive's attributes and morph targets: accessor indices. */
	if (j.contains("meshes"))
		for (size_t m = 0; m < j["meshes"].size(); m++) {
			const json &mesh_j = j["meshes"][m];
			if (!mesh_j.contains("primitives"))
				continue;
			for (size_t p = 0; p < mesh_j["primitives"].size(); p++) {
				const json &pr = mesh_j["primitives"][p];
				std::string at = "meshes[" + std::to_string(m) + "].primitives[" + std::to_string(p) + "]";
				if (!pr.contains("attributes"))
					TypeCheck::bad(at, "no attributes");
				if (pr.contains("mode") && pr["mode"].get<double>() > 6)
					TypeCheck::bad(at + ".mode", "not a primitive mode (0 to 6)");
				for (auto it = pr["attributes"].begin(); it != pr["attributes"].end(); ++it)
					TypeCheck::value(*it, K::Index, nullptr, at + ".attributes." + it.key());
				if (pr.contains("targets"))
					for (size_t t = 0; t < pr["targets"].size(); t++)
						for (auto it = pr["targets"][t].begin(); it != pr["targets"][t].end(); ++it)
							TypeCheck::value(*it, K::Index, nullptr,
							                 at + ".targets[" + std::to_string(t) + "]." + it.key());
			}
		}
}

void check_required_extensions(const json &doc)
{
	auto it = doc.find("extensionsRequired");
	if (it == doc.end() || !it->is_array())
		return;
	for (const auto &e : *it) {
		if (!e.is_string())
			continue;
		std::string name = e.get<std::string>();
		if (name == "KHR_draco_mesh_compression")
			fail(MLOD_ERR_UNSUPPORTED, "the file requires KHR_draco_mesh_compression: Draco-compressed meshes "
			                           "cannot be decoded (decompress it first, e.g. with gltf-transform)");
		if (name == "EXT_meshopt_compression" || name == "KHR_meshopt_compression")
			fail(MLOD_ERR_UNSUPPORTED, "the file requires %s: meshopt-compressed buffers cannot be decoded "
			                           "(decompress it first, e.g. with gltf-transform)", name.c_str());
		if (!extension_supported(name))
			fail(MLOD_ERR_UNSUPPORTED, "the file requires the extension %s, which mlod does not support", name.c_str());
	}
}

/* %XX decoding, as tinygltf does before opening a URI. */
std::string url_decode(const std::string &s)
{
	std::string out;
	for (size_t i = 0; i < s.size(); i++) {
		if (s[i] == '%' && i + 2 < s.size() && isxdigit((unsigned char)s[i + 1]) && isxdigit((unsigned char)s[i + 2])) {
			out += char(std::stoi(s.substr(i + 1, 2), nullptr, 16));
			i += 2;
		} else {
			out += s[i];
		}
	}
	return out;
}

/* text with every byte outside printable ASCII as \xNN: a JSON parser's
 * message quotes what it last read, which may be any bytes of the file. */
std::string printable(const char *text)
{
	std::string out;
	for (const unsigned char *c = reinterpret_cast<const unsigned char *>(text); *c; c++) {
		if (*c >= 0x20 && *c < 0x7f) {
			out += char(*c);
		} else {
			char hex[8];
			snprintf(hex, sizeof hex, "\\x%02x", unsigned(*c));
			out += hex;
		}
	}
	return out;
}

/* Is path a plain relative path that stays below the base directory (no
 * scheme, not absolute, no ".." segment)? Other URIs are not opened, so a
 * hostile file cannot make mlod embed arbitrary local files. */
bool stays_inside(const std::string &path)
{
	if (path.empty() || path[0] == '/' || path[0] == '\\' || path.find(':') != std::string::npos)
		return false;
	size_t start = 0;
	for (;;) {
		size_t end = path.find_first_of("/\\", start);
		if (path.compare(start, end == std::string::npos ? std::string::npos : end - start, "..") == 0)
			return false;
		if (end == std::string::npos)
			return true;
		start = end + 1;
	}
}

std::string join_path(const std::string &dir, const std::string &file)
{
	if (dir.empty())
		return file;
	return dir.back() == '/' ? dir + file : dir + "/" + file;
}

/* External buffers must be readable files under base_dir; data: URIs must
 * be of a type tinygltf decodes. Images are not checked: one that cannot
 * be read keeps its URI. */
void check_buffer_uris(const json &doc, const char *base_dir)
{
	auto buffers = doc.find("buffers");
	if (buffers == doc.end() || !buffers->is_array())
		return;
	for (size_t i = 0; i < buffers->size(); i++) {
		const json &b = (*buffers)[i];
		if (!b.is_object() || !b.contains("uri") || !b["uri"].is_string())
			continue;
		std::string uri = b["uri"].get<std::string>();
		if (uri.compare(0, 5, "data:") == 0) {
			if (!tinygltf::IsDataURI(uri))
				fail(MLOD_ERR_UNSUPPORTED, "buffer %zu: unsupported data URI \"%.40s...\"", i, uri.c_str());
			continue;
		}
		if (!base_dir)
			fail(MLOD_ERR_IO, "buffer %zu: external file \"%s\" but no base directory to find it in", i, uri.c_str());
		std::string rel = url_decode(uri);
		if (!stays_inside(rel))
			fail(MLOD_ERR_UNSUPPORTED, "buffer %zu: URI \"%s\" is not a file below the base directory", i, uri.c_str());
		std::string path = join_path(base_dir, rel);
		struct stat st;
		if (stat(path.c_str(), &st) != 0)
			fail(MLOD_ERR_IO, "buffer %zu: cannot read \"%s\": %s", i, path.c_str(), strerror(errno));
	}
}

/* An external image is embedded in what mlod writes, so it must be read
 * as a buffer is: from below base_dir. One elsewhere would leave the
 * written glb a relative URI that no longer points at it: refused, as
 * such a buffer is. Without a base directory (standard input, a pack's
 * DOC chunk), or when the file is missing, an image keeps its URI. */
void check_image_uris(const json &doc, const char *base_dir)
{
	auto images = doc.find("images");
	if (images == doc.end() || !images->is_array())
		return;
	for (size_t i = 0; i < images->size(); i++) {
		const json &im = (*images)[i];
		if (!im.is_object() || !im.contains("uri") || !im["uri"].is_string())
			continue;
		std::string uri = im["uri"].get<std::string>();
		if (uri.compare(0, 5, "data:") == 0)
			continue;
		if (base_dir && !stays_inside(url_decode(uri)))
			fail(MLOD_ERR_UNSUPPORTED, "image %zu: URI \"%s\" is not a file below the base directory", i,
			     uri.c_str());
	}
}

/* ------------------------------------------------------------------ */
/* Reading: tinygltf callbacks                                         */
/* ------------------------------------------------------------------ */

/* Where external files may be read from: nowhere when there is no base
 * directory. */
struct FileAccess {
	bool allowed;
	std::string prefix; /* the base directory, ending in '/' unless empty */
};

bool file_exists(const std::string &path, void *user)
{
	const FileAccess *fa = static_cast<const FileAccess *>(user);
	if (!fa->allowed || path.compare(0, fa->prefix.size(), fa->prefix) != 0 ||
	    !stays_inside(path.substr(fa->prefix.size())))
		return false;
	struct stat st;
	return stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

/* tinygltf's default runs wordexp() on the path; mlod takes it as it is. */
std::string expand_path(const std::string &path, void *)
{
	return path;
}

bool read_whole_file(std::vector<unsigned char> *out, std::string *err, const std::string &path, void *user)
{
	if (!file_exists(path, user)) {
		*err = "not readable";
		return false;
	}
	std::ifstream f(path, std::ios::binary | std::ios::ate);
	std::streamoff size = f.tellg();
	if (!f || size < 0 || uint64_t(size) > UINT32_MAX) {
		*err = f ? "larger than 4 GiB" : "cannot open";
		return false;
	}
	out->resize(size_t(size));
	f.seekg(0);
	if (size > 0 && !f.read(reinterpret_cast<char *>(out->data()), size)) {
		*err = "read error";
		return false;
	}
	return true;
}

bool refuse_write(std::string *err, const std::string &, const std::vector<unsigned char> &, void *)
{
	*err = "mlod does not write files through tinygltf";
	return false;
}

/* tinygltf's image loader: keeps the encoded bytes instead of decoding
 * them. Bytes of a bufferView image stay in the buffer; tinygltf computes
 * their address without checking the view against the buffer, so that is
 * checked here (user is the model being loaded). */
bool keep_image_bytes(tinygltf::Image *image, const int index, std::string *err, std::string *, int, int,
                      const unsigned char *bytes, int size, void *user)
{
	if (image->bufferView >= 0) {
		const Model &m = *static_cast<const Model *>(user);
		const tinygltf::BufferView &v = m.bufferViews[size_t(image->bufferView)];
		size_t have = m.buffers[size_t(v.buffer)].data.size();
		if (v.byteOffset > have || v.byteLength > have - v.byteOffset) {
			*err += "image " + std::to_string(index) + ": buffer view " + std::to_string(image->bufferView) +
			        " extends past the end of buffer " + std::to_string(v.buffer);
			return false;
		}
		return true;
	}
	image->image.assign(bytes, bytes + size);
	image->as_is = true;
	return true;
}

/* ------------------------------------------------------------------ */
/* Accessors                                                           */
/* ------------------------------------------------------------------ */

size_t component_size(int component_type)
{
	switch (component_type) {
	case TINYGLTF_COMPONENT_TYPE_BYTE:
	case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
		return 1;
	case TINYGLTF_COMPONENT_TYPE_SHORT:
	case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
		return 2;
	case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
	case TINYGLTF_COMPONENT_TYPE_FLOAT:
		return 4;
	default:
		return 0;
	}
}

const char *type_name(int type)
{
	switch (type) {
	case TINYGLTF_TYPE_SCALAR: return "SCALAR";
	case TINYGLTF_TYPE_VEC2: return "VEC2";
	case TINYGLTF_TYPE_VEC3: return "VEC3";
	case TINYGLTF_TYPE_VEC4: return "VEC4";
	case TINYGLTF_TYPE_MAT2: return "MAT2";
	case TINYGLTF_TYPE_MAT3: return "MAT3";
	case TINYGLTF_TYPE_MAT4: return "MAT4";
	default: return "unknown";
	}
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

Layout layout_of(const tinygltf::Accessor &a)
{
	Layout l{0, 0, component_size(a.componentType), 0, 0};
	switch (a.type) {
	case TINYGLTF_TYPE_SCALAR: l.components = 1; break;
	case TINYGLTF_TYPE_VEC2: l.components = 2; break;
	case TINYGLTF_TYPE_VEC3: l.components = 3; break;
	case TINYGLTF_TYPE_VEC4: l.components = 4; break;
	case TINYGLTF_TYPE_MAT2: l.rows = 2; break;
	case TINYGLTF_TYPE_MAT3: l.rows = 3; break;
	case TINYGLTF_TYPE_MAT4: l.rows = 4; break;
	default: break;
	}
	if (l.rows) {
		l.components = l.rows * l.rows;
		l.column_bytes = (size_t(l.rows) * l.size + 3) / 4 * 4;
		l.element = size_t(l.rows) * l.column_bytes;
	} else {
		l.element = size_t(l.components) * l.size;
	}
	return l;
}

/* Do count elements of elem bytes, stride bytes apart from offset, fit in
 * length bytes? (Overflow-safe; stride >= elem > 0.) */
bool fits(size_t offset, size_t stride, size_t count, size_t elem, size_t length)
{
	if (count == 0)
		return offset <= length;
	if (offset > length || elem > length - offset)
		return false;
	return count - 1 <= (length - offset - elem) / stride;
}

/* Decoded arrays are limited to this many values: a hostile count cannot
 * make mlod allocate without bound. */
const size_t max_values = size_t(1) << 28;

void check_view(const Model &m, size_t v)
{
	const tinygltf::BufferView &bv = m.bufferViews[v];
	if (bv.buffer < 0 || size_t(bv.buffer) >= m.buffers.size())
		fail(MLOD_ERR_PARSE, "buffer view %zu: buffer %d does not exist", v, bv.buffer);
	size_t have = m.buffers[size_t(bv.buffer)].data.size();
	if (!fits(bv.byteOffset, 1, bv.byteLength, 1, have))
		fail(MLOD_ERR_PARSE, "buffer view %zu: extends past the end of buffer %d (%zu bytes at offset %zu, the buffer has %zu)",
		     v, bv.buffer, bv.byteLength, bv.byteOffset, have);
}

/* The sparse index k of accessor a (after check_accessor). */
uint32_t sparse_index(const Model &m, const tinygltf::Accessor &a, size_t k)
{
	const auto &s = a.sparse.indices;
	const tinygltf::BufferView &v = m.bufferViews[size_t(s.bufferView)];
	size_t cs = component_size(s.componentType);
	const unsigned char *p = m.buffers[size_t(v.buffer)].data.data() + v.byteOffset + size_t(s.byteOffset) + k * cs;
	return cs == 1 ? p[0] : cs == 2 ? uint32_t(p[0] | p[1] << 8) : le32(p);
}

/* Checks that accessor i is readable: known types, inside its buffer view
 * (checked against its buffer before), sparse parts likewise, sparse
 * indices increasing and in range. */
void check_accessor(const Model &m, size_t i)
{
	const tinygltf::Accessor &a = m.accessors[i];
	Layout l = layout_of(a);
	if (!l.size)
		fail(MLOD_ERR_PARSE, "accessor %zu: unsupported component type %d", i, a.componentType);
	if (!l.components)
		fail(MLOD_ERR_PARSE, "accessor %zu: unsupported type %d", i, a.type);
	if (a.count > max_values / size_t(l.components))
		fail(MLOD_ERR_NOMEM, "accessor %zu: %zu elements is more than mlod handles", i, a.count);
	if (a.bufferView >= 0) {
		if (size_t(a.bufferView) >= m.bufferViews.size())
			fail(MLOD_ERR_PARSE, "accessor %zu: buffer view %d does not exist", i, a.bufferView);
		const tinygltf::BufferView &v = m.bufferViews[size_t(a.bufferView)];
		size_t stride = v.byteStride ? v.byteStride : l.element;
		if (stride < l.element)
			fail(MLOD_ERR_PARSE, "accessor %zu: buffer view %d has a stride of %zu bytes, less than an element (%zu)",
			     i, a.bufferView, stride, l.element);
		if (!fits(a.byteOffset, stride, a.count, l.element, v.byteLength))
			fail(MLOD_ERR_PARSE, "accessor %zu: extends past the end of buffer view %d", i, a.bufferView);
	} else if (a.bufferView != -1) {
		fail(MLOD_ERR_PARSE, "accessor %zu: buffer view %d does not exist", i, a.bufferView);
	}
	if (!a.sparse.isSparse)
		return;
	const auto &s = a.sparse;
	if (s.count < 1 || size_t(s.count) > a.count)
		fail(MLOD_ERR_PARSE, "accessor %zu: sparse count %d out of range (the accessor has %zu elements)", i, s.count, a.count);
	size_t cs = component_size(s.indices.componentType);
	if (s.indices.componentType == TINYGLTF_COMPONENT_TYPE_BYTE || s.indices.componentType == TINYGLTF_COMPONENT_TYPE_SHORT ||
	    s.indices.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT || !cs)
		fail(MLOD_ERR_PARSE, "accessor %zu: sparse indices of component type %d", i, s.indices.componentType);
	struct Part {
		const char *what;
		int view, offset;
		size_t elem;
	} parts[2] = {{"indices", s.indices.bufferView, s.indices.byteOffset, cs},
	              {"values", s.values.bufferView, s.values.byteOffset, l.element}};
	for (const Part &p : parts) {
		if (p.view < 0 || size_t(p.view) >= m.bufferViews.size())
			fail(MLOD_ERR_PARSE, "accessor %zu: sparse %s buffer view %d does not exist", i, p.what, p.view);
		if (p.offset < 0 || !fits(size_t(p.offset), p.elem, size_t(s.count), p.elem, m.bufferViews[size_t(p.view)].byteLength))
			fail(MLOD_ERR_PARSE, "accessor %zu: sparse %s extend past the end of buffer view %d", i, p.what, p.view);
	}
	for (size_t k = 0; k < size_t(s.count); k++) {
		uint32_t index = sparse_index(m, a, k);
		if (index >= a.count || (k > 0 && index <= sparse_index(m, a, k - 1)))
			fail(MLOD_ERR_PARSE, "accessor %zu: sparse index %zu is %u: out of range or not increasing", i, k, index);
	}
}

/* One component at p, as glTF defines its value (normalised integers map
 * to [0, 1] or [-1, 1]). */
double component(const unsigned char *p, int type, bool normalized)
{
	switch (type) {
	case TINYGLTF_COMPONENT_TYPE_BYTE: {
		double v = int8_t(p[0]);
		return normalized ? std::max(v / 127.0, -1.0) : v;
	}
	case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
		return normalized ? p[0] / 255.0 : p[0];
	case TINYGLTF_COMPONENT_TYPE_SHORT: {
		double v = int16_t(uint16_t(p[0] | p[1] << 8));
		return normalized ? std::max(v / 32767.0, -1.0) : v;
	}
	case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
		double v = uint16_t(p[0] | p[1] << 8);
		return normalized ? v / 65535.0 : v;
	}
	case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
		return le32(p);
	default: {
		uint32_t bits = le32(p);
		float f;
		memcpy(&f, &bits, 4);
		return f;
	}
	}
}

/* All values of accessor i (count * components), the sparse substitution
 * applied; an accessor without buffer view starts from zeros. */
template <class T> std::vector<T> decode(const Model &m, int i)
{
	const tinygltf::Accessor &a = m.accessors[size_t(i)];
	Layout l = layout_of(a);
	size_t n = size_t(l.components);
	std::vector<T> out(a.count * n);
	auto read_element = [&](const unsigned char *p, size_t e) {
		for (size_t c = 0; c < n; c++)
			out[e * n + c] = T(component(p + l.offset(int(c)), a.componentType, a.normalized));
	};
	if (a.bufferView >= 0) {
		const tinygltf::BufferView &v = m.bufferViews[size_t(a.bufferView)];
		const unsigned char *base = m.buffers[size_t(v.buffer)].data.data() + v.byteOffset + a.byteOffset;
		size_t stride = v.byteStride ? v.byteStride : l.element;
		for (size_t e = 0; e < a.count; e++)
			read_element(base + e * stride, e);
	}
	if (a.sparse.isSparse) {
		const tinygltf::BufferView &v = m.bufferViews[size_t(a.sparse.values.bufferView)];
		const unsigned char *base = m.buffers[size_t(v.buffer)].data.data() + v.byteOffset + size_t(a.sparse.values.byteOffset);
		for (size_t k = 0; k < size_t(a.sparse.count); k++)
			read_element(base + k * l.element, sparse_index(m, a, k));
	}
	return out;
}

/* Accessor i, which must exist and have one of the given types, as floats.
 * what names its use in messages ("mesh 2 primitive 0 NORMAL"). */
std::vector<float> read_floats(const Model &m, int i, const std::string &what, int type, int other_type = -1)
{
	if (i < 0 || size_t(i) >= m.accessors.size())
		fail(MLOD_ERR_PARSE, "%s: accessor %d does not exist", what.c_str(), i);
	int t = m.accessors[size_t(i)].type;
	if (t != type && t != other_type)
		fail(MLOD_ERR_PARSE, "%s: accessor %d is %s, not %s", what.c_str(), i, type_name(t), type_name(type));
	return decode<float>(m, i);
}

/* Accessor i as unsigned integers: it must have an unsigned integer type. */
std::vector<uint32_t> read_uints(const Model &m, int i, const std::string &what, int type)
{
	if (i < 0 || size_t(i) >= m.accessors.size())
		fail(MLOD_ERR_PARSE, "%s: accessor %d does not exist", what.c_str(), i);
	const tinygltf::Accessor &a = m.accessors[size_t(i)];
	if (a.type != type)
		fail(MLOD_ERR_PARSE, "%s: accessor %d is %s, not %s", what.c_str(), i, type_name(a.type), type_name(type));
	if (a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
	    a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
		fail(MLOD_ERR_PARSE, "%s: accessor %d has component type %d, not an unsigned integer", what.c_str(), i, a.componentType);
	return decode<uint32_t>(m, i);
}

/* ------------------------------------------------------------------ */
/* Document checks                                                     */
/* ------------------------------------------------------------------ */

void check_ref(int index, size_t count, const char *fmt_owner, size_t owner, const char *what)
{
	if (index < -1 || (index >= 0 && size_t(index) >= count)) {
		char who[96];
		snprintf(who, sizeof who, fmt_owner, owner);
		fail(MLOD_ERR_PARSE, "%s: %s %d does not exist", who, what, index);
	}
}

/* parent[n] of every node, or -1. A node listed as the child of two nodes
 * (or twice), a child that does not exist, or a cycle is an error. */
std::vector<int> node_parents(const Model &m)
{
	size_t n = m.nodes.size();
	std::vector<int> parent(n, -1);
	for (size_t p = 0; p < n; p++) {
		for (int c : m.nodes[p].children) {
			if (c < 0 || size_t(c) >= n)
				fail(MLOD_ERR_PARSE, "node %zu: child node %d does not exist", p, c);
			if (parent[size_t(c)] == int(p))
				fail(MLOD_ERR_PARSE, "node %zu: lists child node %d twice", p, c);
			if (parent[size_t(c)] >= 0)
				fail(MLOD_ERR_PARSE, "node %d has two parents (nodes %d and %zu)", c, parent[size_t(c)], p);
			parent[size_t(c)] = int(p);
		}
	}
	/* With one parent each, a cycle is a parent chain that never ends. */
	std::vector<char> state(n, 0); /* 0 unseen, 1 on the current chain, 2 ends at a root */
	for (size_t start = 0; start < n; start++) {
		int k = int(start);
		while (k >= 0 && state[size_t(k)] == 0) {
			state[size_t(k)] = 1;
			k = parent[size_t(k)];
		}
		if (k >= 0 && state[size_t(k)] == 1)
			fail(MLOD_ERR_PARSE, "the node hierarchy has a cycle through node %d", k);
		for (k = int(start); k >= 0 && state[size_t(k)] == 1; k = parent[size_t(k)])
			state[size_t(k)] = 2;
	}
	return parent;
}

/* Values of accessors without a buffer view (zeros, or a sparse
 * substitution on zeros) cost the input nothing: together they may hold at
 * most this many values per byte of the input and its buffers, so that a
 * few bytes cannot make mlod allocate gigabytes. (Sparse morph targets
 * without buffer views, one per target as exporters write them, stay far
 * below it: their meshes' positions cost 12 bytes a vertex.) */
const size_t dataless_values_per_byte = 16;

/* Each mesh primitive and morph target decodes its accessors again, and
 * each animation channel its sampler's: elements many references share
 * cost the input once. Together the references may reach at most this
 * many elements per byte of the input and its buffers, so that a long list
 * of references to one large accessor cannot make mlod allocate gigabytes.
 * (mlod's own levels share accessors a few times over: skeleton levels
 * share all but the skinning of their mesh.) */
const size_t referenced_elements_per_byte = 4;

void check_references(const Model &m, size_t bytes)
{
	size_t budget = bytes > SIZE_MAX / referenced_elements_per_byte ? SIZE_MAX : bytes * referenced_elements_per_byte;
	size_t total = 0;
	auto count = [&](int accessor) -> size_t {
		return accessor >= 0 && size_t(accessor) < m.accessors.size() ? m.accessors[size_t(accessor)].count : 0;
	};
	auto add = [&](size_t n, const char *what, size_t i) {
		total += n; /* each n is below max_values * (targets + 1): no overflow before the check */
		if (total > budget)
			fail(MLOD_ERR_NOMEM,
			     "%s %zu: the document refers to more than %zu accessor elements (%zu bytes of input and buffers, "
			     "accessors counted once per reference)",
			     what, i, budget, bytes);
	};
	for (size_t i = 0; i < m.meshes.size(); i++)
		for (const tinygltf::Primitive &p : m.meshes[i].primitives) {
			auto it = p.attributes.find("POSITION");
			add(it == p.attributes.end() ? 0 : count(it->second) * (p.targets.size() + 1), "mesh", i);
		}
	for (size_t i = 0; i < m.animations.size(); i++) {
		const tinygltf::Animation &a = m.animations[i];
		for (const tinygltf::AnimationChannel &ch : a.channels)
			if (ch.sampler >= 0 && size_t(ch.sampler) < a.samplers.size())
				add(count(a.samplers[size_t(ch.sampler)].input) + count(a.samplers[size_t(ch.sampler)].output),
				    "animation", i);
	}
}

/* Checks every reference mlod may follow, so later code can index freely.
 * input_size: the bytes the document was read from. */
void check_document(const Model &m, size_t input_size)
{
	for (size_t v = 0; v < m.bufferViews.size(); v++)
		check_view(m, v);
	for (size_t a = 0; a < m.accessors.size(); a++)
		check_accessor(m, a);
	size_t bytes = input_size;
	for (const tinygltf::Buffer &b : m.buffers)
		bytes += std::min(b.data.size(), max_values);
	size_t budget = std::min(max_values, bytes * dataless_values_per_byte), dataless = 0;
	for (size_t a = 0; a < m.accessors.size(); a++) {
		const tinygltf::Accessor &acc = m.accessors[a];
		if (acc.bufferView >= 0)
			continue;
		/* check_accessor bounded each below max_values. */
		dataless += acc.count * size_t(layout_of(acc).components);
		if (dataless > budget)
			fail(MLOD_ERR_NOMEM,
			     "accessor %zu: %zu elements without a buffer view: accessors without one may hold %zu values "
			     "together in %zu bytes of input and buffers",
			     a, acc.count, budget, bytes);
	}
	check_references(m, bytes);
	size_t accessors = m.accessors.size();
	for (size_t i = 0; i < m.meshes.size(); i++) {
		for (const tinygltf::Primitive &p : m.meshes[i].primitives) {
			for (const auto &kv : p.attributes)
				check_ref(kv.second, accessors, "mesh %zu", i, ("attribute " + kv.first + " accessor").c_str());
			for (const auto &target : p.targets)
				for (const auto &kv : target)
					check_ref(kv.second, accessors, "mesh %zu", i, ("morph target " + kv.first + " accessor").c_str());
			check_ref(p.indices, accessors, "mesh %zu", i, "indices accessor");
			check_ref(p.material, m.materials.size(), "mesh %zu", i, "material");
		}
	}
	for (size_t i = 0; i < m.nodes.size(); i++) {
		const tinygltf::Node &n = m.nodes[i];
		check_ref(n.mesh, m.meshes.size(), "node %zu", i, "mesh");
		check_ref(n.skin, m.skins.size(), "node %zu", i, "skin");
		check_ref(n.camera, m.cameras.size(), "node %zu", i, "camera");
		if ((!n.translation.empty() && n.translation.size() != 3) || (!n.rotation.empty() && n.rotation.size() != 4) ||
		    (!n.scale.empty() && n.scale.size() != 3) || (!n.matrix.empty() && n.matrix.size() != 16))
			fail(MLOD_ERR_PARSE, "node %zu: a transform property has the wrong number of values", i);
	}
	node_parents(m);
	for (size_t i = 0; i < m.skins.size(); i++) {
		/* A node listed twice (the validator's DUPLICATE_ELEMENTS) would
		 * make two joints of one node, each skinning with its own bind. */
		std::map<int, size_t> listed;
		for (size_t k = 0; k < m.skins[i].joints.size(); k++) {
			const int j = m.skins[i].joints[k];
			if (j < 0)
				fail(MLOD_ERR_PARSE, "skin %zu: joint node %d does not exist", i, j);
			check_ref(j, m.nodes.size(), "skin %zu", i, "joint node");
			auto seen = listed.emplace(j, k);
			if (!seen.second)
				fail(MLOD_ERR_PARSE, "skin %zu %s: joints %zu and %zu are both node %d", i,
				     quoted(m.skins[i].name).c_str(), seen.first->second, k, j);
		}
		check_ref(m.skins[i].skeleton, m.nodes.size(), "skin %zu", i, "skeleton node");
		check_ref(m.skins[i].inverseBindMatrices, accessors, "skin %zu", i, "inverseBindMatrices accessor");
	}
	for (size_t i = 0; i < m.scenes.size(); i++)
		for (int n : m.scenes[i].nodes) {
			if (n < 0)
				fail(MLOD_ERR_PARSE, "scene %zu: node %d does not exist", i, n);
			check_ref(n, m.nodes.size(), "scene %zu", i, "node");
		}
	if (m.defaultScene >= int(m.scenes.size()))
		fail(MLOD_ERR_PARSE, "the default scene %d does not exist", m.defaultScene);
	for (size_t i = 0; i < m.animations.size(); i++) {
		const tinygltf::Animation &a = m.animations[i];
		/* Two channels of one animation may not target the same node and
		 * path (the validator's ANIMATION_DUPLICATE_TARGETS): which one
		 * moves the node would be up to the reader, and a pack's reader
		 * refuses a joint with two (mlod(5)). */
		std::map<std::pair<int, std::string>, size_t> targets;
		for (size_t k = 0; k < a.channels.size(); k++) {
			const tinygltf::AnimationChannel &c = a.channels[k];
			if (c.sampler < 0)
				fail(MLOD_ERR_PARSE, "animation %zu: sampler %d does not exist", i, c.sampler);
			check_ref(c.sampler, a.samplers.size(), "animation %zu", i, "sampler");
			check_ref(c.target_node, m.nodes.size(), "animation %zu", i, "target node");
			if (c.target_node < 0)
				continue;
			auto seen = targets.emplace(std::make_pair(c.target_node, c.target_path), k);
			if (!seen.second)
				fail(MLOD_ERR_PARSE, "animation %zu %s: channels %zu and %zu both target node %d's %s", i,
				     quoted(a.name).c_str(), seen.first->second, k, c.target_node,
				     known_path(c.target_path) ? c.target_path.c_str() : quoted(c.target_path).c_str());
		}
		for (const tinygltf::AnimationSampler &s : a.samplers) {
			if (s.input < 0 || s.output < 0)
				fail(MLOD_ERR_PARSE, "animation %zu: a sampler has no input or output accessor", i);
			check_ref(s.input, accessors, "animation %zu", i, "sampler input accessor");
			check_ref(s.output, accessors, "animation %zu", i, "sampler output accessor");
		}
	}
}

/* Records every "extras" of the JSON by pointer, outside other extras. */
void collect_extras(const json &j, const std::string &at, std::map<std::string, json> &out)
{
	if (j.is_object()) {
		for (auto it = j.begin(); it != j.end(); ++it) {
			std::string p = at + "/" + pointer_token(it.key());
			if (it.key() == "extras")
				out[p] = *it;
			else
				collect_extras(*it, p, out);
		}
	} else if (j.is_array()) {
		for (size_t i = 0; i < j.size(); i++)
			collect_extras(j[i], at + "/" + std::to_string(i), out);
	}
}

/* The nodes another node's MSFT_lod names as its levels (1), as far as
 * its ids are well formed (mlod_gltf_node_lod checks them). */
std::vector<char> lod_level_nodes(const Model &m)
{
	std::vector<char> level(m.nodes.size(), 0);
	for (const tinygltf::Node &nd : m.nodes) {
		auto it = nd.extensions.find("MSFT_lod");
		if (it == nd.extensions.end() || !it->second.IsObject() || !it->second.Has("ids") ||
		    !it->second.Get("ids").IsArray())
			continue;
		const tinygltf::Value &ids = it->second.Get("ids");
		for (size_t i = 0; i < ids.ArrayLen(); i++) {
			const tinygltf::Value &e = ids.Get(int(i));
			int id = e.IsInt() ? e.Get<int>() : e.IsNumber() ? int(e.GetNumberAsDouble()) : -1;
			if (id >= 0 && size_t(id) < m.nodes.size())
				level[size_t(id)] = 1;
		}
	}
	return level;
}

tinygltf::Scene &default_scene(Model &m);

/* A document without a scene (valid glTF: a library of nodes) gets one,
 * the default, with every root node but MSFT_lod levels: what a viewer
 * shows of it. The stages need it: the stage record lives in the scene's
 * extras, and the nodes they add for levels stay out of every scene. */
void add_scene_if_none(mlod_gltf &doc)
{
	Model &m = doc.model;
	if (!m.scenes.empty() || m.nodes.empty())
		return;
	std::vector<int> parent = node_parents(m);
	std::vector<char> level = lod_level_nodes(m);
	tinygltf::Scene &scene = default_scene(m);
	for (size_t k = 0; k < m.nodes.size(); k++)
		if (parent[k] < 0 && !level[k])
			scene.nodes.push_back(int(k));
	doc.scene_added = int(scene.nodes.size());
}

/* A node rotation further from unit length than the validator takes is
 * normalised: the rest pose a viewer shows, and a document the tools can
 * write valid. A rotation of length 0 has no direction: refused. */
void normalise_node_rotations(mlod_gltf &doc)
{
	for (size_t i = 0; i < doc.model.nodes.size(); i++) {
		std::vector<double> &r = doc.model.nodes[i].rotation;
		if (r.size() != 4)
			continue;
		const double len = mlod_quat4_length(r[0], r[1], r[2], r[3]);
		if (std::fabs(len - 1.0) <= MLOD_UNIT_QUAT_TOLERANCE)
			continue;
		if (!(len > 0.0))
			fail(MLOD_ERR_PARSE, "node %zu: rotation (%g, %g, %g, %g) is not a quaternion of any direction", i, r[0],
			     r[1], r[2], r[3]);
		double m = 0.0;
		for (double v : r)
			m = std::max(m, std::fabs(v));
		const double scaled = len / m; /* finite where len overflows */
		for (double &v : r)
			v = v / m / scaled;
		if (doc.rotations_normalised++ == 0)
			doc.rotation_node = int(i), doc.rotation_length = len;
	}
}

/* tinygltf 2.x drops an animation channel whose target has no node
 * (KHR_animation_pointer's, which targets a JSON pointer instead): each
 * comes back at its place, target_node -1 (the JSON as read, kept in
 * step, gives back its target's extensions when written). */
void restore_nodeless_channels(Model &m, const json &j)
{
	if (!j.contains("animations") || !j["animations"].is_array())
		return;
	const json &anims = j["animations"];
	for (size_t a = 0; a < anims.size() && a < m.animations.size(); a++) {
		const json &oa = anims[a];
		if (!oa.is_object() || !oa.contains("channels") || !oa["channels"].is_array() ||
		    oa["channels"].size() == m.animations[a].channels.size())
			continue;
		std::vector<tinygltf::AnimationChannel> &channels = m.animations[a].channels;
		const json &oc = oa["channels"];
		for (size_t c = 0; c < oc.size(); c++) {
			const json &ch = oc[c];
			if (!ch.is_object() || !ch.contains("target") || !ch["target"].is_object() ||
			    ch["target"].contains("node") || !ch.contains("sampler") || !ch["sampler"].is_number_integer() ||
			    !ch["target"].contains("path") || !ch["target"]["path"].is_string() || c > channels.size())
				continue;
			tinygltf::AnimationChannel nc;
			nc.sampler = ch["sampler"].get<int>();
			nc.target_node = -1;
			nc.target_path = ch["target"]["path"].get<std::string>();
			if (ch["target"].contains("extensions") && ch["target"]["extensions"].is_object())
				for (auto it = ch["target"]["extensions"].begin(); it != ch["target"]["extensions"].end(); ++it)
					nc.target_extensions[it.key()] = to_value(*it);
			channels.insert(channels.begin() + long(c), nc);
		}
	}
}

void read_document(mlod_gltf &doc, const unsigned char *data, size_t size, const char *base_dir)
{
	if (size == 0)
		fail(MLOD_ERR_PARSE, "empty input: not glTF");
	if (size > UINT32_MAX)
		fail(MLOD_ERR_NOMEM, "input of %zu bytes: glTF is limited to 4 GiB", size);
	bool binary = size >= 4 && le32(data) == glb_magic;
	json j;
	try {
		if (binary) {
			std::string text = glb_json(data, size);
			j = parse_json(text.data(), text.size());
		} else {
			j = parse_json(reinterpret_cast<const char *>(data), size);
		}
	} catch (const json::exception &e) {
		fail(MLOD_ERR_PARSE, "%s: %s", binary ? "glb JSON chunk" : "not glTF (neither glb nor JSON)",
		     printable(e.what()).c_str());
	}
	if (!j.is_object())
		fail(MLOD_ERR_PARSE, "not glTF: the JSON is not an object");
	check_types(j);
	check_required_extensions(j);
	check_buffer_uris(j, base_dir);
	check_image_uris(j, base_dir);

	tinygltf::TinyGLTF loader;
	FileAccess access{base_dir != nullptr, base_dir ? join_path(base_dir, "") : ""};
	loader.SetFsCallbacks(tinygltf::FsCallbacks{&file_exists, &expand_path, &read_whole_file, &refuse_write, &access});
	loader.SetImageLoader(&keep_image_bytes, &doc.model);
	std::string error, warning;
	std::string base = base_dir ? base_dir : "";
	bool ok = binary ? loader.LoadBinaryFromMemory(&doc.model, &error, &warning, data, unsigned(size), base)
	                 : loader.LoadASCIIFromString(&doc.model, &error, &warning, reinterpret_cast<const char *>(data),
	                                              unsigned(size), base);
	if (!ok) {
		while (!error.empty() && (error.back() == '\n' || error.back() == ' '))
			error.pop_back();
		for (char &ch : error)
			if (ch == '\n')
				ch = ';';
		fail(MLOD_ERR_PARSE, "glTF: %s", error.empty() ? "tinygltf could not load the document" : error.c_str());
	}
	restore_nodeless_channels(doc.model, j);
	const tinygltf::Asset &asset = doc.model.asset;
	if (asset.version.compare(0, 2, "2.") != 0 || (!asset.minVersion.empty() && asset.minVersion != "2.0"))
		fail(MLOD_ERR_UNSUPPORTED, "glTF version %s (minimum %s) is not supported: mlod reads glTF 2.0",
		     asset.version.c_str(), asset.minVersion.empty() ? "none" : asset.minVersion.c_str());
	check_document(doc.model, size);

	/* The data is in memory now: the document no longer refers to files. */
	for (tinygltf::Buffer &b : doc.model.buffers)
		b.uri.clear();
	for (const char *list : {"buffers", "images"})
		if (j.contains(list) && j[list].is_array())
			for (json &o : j[list])
				if (o.is_object())
					o.erase("uri");
	collect_extras(j, "", doc.extras);
	doc.original = std::move(j);
	add_scene_if_none(doc);
	normalise_node_rotations(doc);
}

/* ------------------------------------------------------------------ */
/* Writing                                                             */
/* ------------------------------------------------------------------ */

std::string base64(const std::vector<unsigned char> &in)
{
	static const char digits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
	std::string out;
	out.reserve((in.size() + 2) / 3 * 4);
	for (size_t i = 0; i < in.size(); i += 3) {
		uint32_t v = uint32_t(in[i]) << 16;
		if (i + 1 < in.size()) v |= uint32_t(in[i + 1]) << 8;
		if (i + 2 < in.size()) v |= in[i + 2];
		out += digits[v >> 18 & 63];
		out += digits[v >> 12 & 63];
		out += i + 1 < in.size() ? digits[v >> 6 & 63] : '=';
		out += i + 2 < in.size() ? digits[v & 63] : '=';
	}
	return out;
}

/* The media type of encoded image bytes, "" when unknown. */
std::string sniff_image_type(const std::vector<unsigned char> &b)
{
	auto starts = [&](const char *magic, size_t n, size_t at) { return b.size() >= at + n && memcmp(b.data() + at, magic, n) == 0; };
	if (starts("\x89PNG", 4, 0)) return "image/png";
	if (starts("\xFF\xD8\xFF", 3, 0)) return "image/jpeg";
	if (starts("RIFF", 4, 0) && starts("WEBP", 4, 8)) return "image/webp";
	if (starts("\xABKTX 20\xBB", 8, 0)) return "image/ktx2";
	return "";
}

/* tinygltf's image writer: embeds the bytes as they were read in a data:
 * URI. Images that were never loaded (an external file that was missing)
 * keep their URI. Not called for images in a buffer view. */
bool embed_image(const std::string *, const std::string *, const tinygltf::Image *image, bool, std::string *uri, void *)
{
	if (image->image.empty())
		return false;
	std::string type = image->mimeType.empty() ? sniff_image_type(image->image) : image->mimeType;
	if (type.empty())
		return false;
	*uri = "data:" + type + ";base64," + base64(image->image);
	return true;
}

/* tinygltf 2.7 writes an object with only default properties (a scene
 * without nodes, an unnamed node at the origin, {} inside extras) as
 * null, which it never means: such nulls become {}. */
void fill_empty_objects(json &j)
{
	if (j.is_null())
		j = json::object();
	else if (j.is_structured())
		for (json &e : j)
			fill_empty_objects(e);
}

/* Keys mlod may add to an object that came from the input. */
bool added_by_mlod(const std::string &key)
{
	return key == "children" || key == "nodes" || key == "extensions" || key == "extras" || key == "uri";
}

/* Makes out (written by tinygltf) hold what orig (read) held: keys tinygltf
 * dropped come back, keys it added (defaults, buffer view targets) go,
 * except those mlod adds. Arrays are matched element by element; mlod only
 * appends to them, so a shorter one is one tinygltf dropped elements of and
 * is left alone. Extras are restored separately, from the exact copies. */
void reconcile(json &out, const json &orig, bool root, bool in_extension)
{
	if (out.is_object() && orig.is_object()) {
		for (auto it = orig.begin(); it != orig.end(); ++it)
			if (it.key() != "uri" && it.key() != "extras" && !out.contains(it.key()))
				out[it.key()] = *it;
		if (!root && !in_extension)
			for (auto it = out.begin(); it != out.end();)
				it = orig.contains(it.key()) || added_by_mlod(it.key()) ? std::next(it) : out.erase(it);
		for (auto it = out.begin(); it != out.end(); ++it)
			if (it.key() != "extras" && orig.contains(it.key()))
				reconcile(*it, orig[it.key()], false, in_extension || it.key() == "extensions");
	} else if (out.is_array() && orig.is_array() && out.size() >= orig.size()) {
		for (size_t i = 0; i < orig.size(); i++)
			reconcile(out[i], orig[i], false, in_extension);
	}
}

/* The document as .glb or pretty-printed .gltf bytes. */
std::string serialize(const mlod_gltf &doc, bool binary)
{
	/* A glb holds the images read from files or data: URIs in its BIN
	 * chunk, each in a buffer view of its own (a data: URI in a glb is
	 * what the validator warns of): on a copy of the model. */
	const Model *model = &doc.model;
	Model with_views;
	std::vector<std::pair<size_t, int>> moved; /* image, its new view */
	for (size_t i = 0; binary && i < doc.model.images.size(); i++) {
		const tinygltf::Image &im = doc.model.images[i];
		if (im.bufferView >= 0 || im.image.empty() ||
		    (im.mimeType.empty() ? sniff_image_type(im.image) : im.mimeType).empty())
			continue;
		if (moved.empty()) {
			with_views = doc.model;
			if (with_views.buffers.empty())
				with_views.buffers.emplace_back();
			model = &with_views;
		}
		tinygltf::Image &out = with_views.images[i];
		std::vector<unsigned char> &b = with_views.buffers[0].data;
		b.resize((b.size() + 3) / 4 * 4, 0);
		tinygltf::BufferView v;
		v.buffer = 0;
		v.byteOffset = b.size();
		v.byteLength = out.image.size();
		b.insert(b.end(), out.image.begin(), out.image.end());
		with_views.bufferViews.push_back(v);
		if (out.mimeType.empty())
			out.mimeType = sniff_image_type(out.image);
		out.bufferView = int(with_views.bufferViews.size() - 1);
		out.uri.clear();
		out.image.clear();
		moved.emplace_back(i, out.bufferView);
	}
	tinygltf::TinyGLTF writer;
	writer.SetImageWriter(&embed_image, nullptr);
	std::ostringstream stream;
	if (!writer.WriteGltfSceneToStream(model, stream, !binary, binary) || !stream)
		fail(MLOD_ERR_IO, "tinygltf could not serialise the document");
	std::string written = stream.str();
	json j;
	std::string bin_chunk; /* with its chunk header and padding */
	if (binary) {
		size_t json_length = le32(reinterpret_cast<const unsigned char *>(written.data()) + 12);
		j = json::parse(written.begin() + 20, written.begin() + 20 + long(json_length));
		bin_chunk = written.substr(20 + json_length);
	} else {
		j = json::parse(written);
	}
	fill_empty_objects(j);
	if (!doc.original.is_null())
		reconcile(j, doc.original, true, false);
	for (const auto &iv : moved)
		if (j.contains("images") && j["images"].is_array() && iv.first < j["images"].size() &&
		    j["images"][iv.first].is_object()) {
			json &im = j["images"][iv.first];
			im.erase("uri");
			im["bufferView"] = iv.second;
			im["mimeType"] = model->images[iv.first].mimeType;
		}
	/* tinygltf skips animations without channels, which shifts indices. */
	bool animations_shifted = j.contains("animations") && j["animations"].size() != doc.model.animations.size();
	for (const auto &kv : doc.extras) {
		json::json_pointer p(kv.first);
		if (animations_shifted && kv.first.compare(0, 12, "/animations/") == 0)
			continue;
		if (j.contains(p.parent_pointer()) && j[p.parent_pointer()].is_object())
			j[p] = kv.second;
	}
	if (!binary)
		return j.dump(2) + "\n";

	std::string text = j.dump();
	text.append((4 - text.size() % 4) % 4, ' ');
	uint64_t total = 20 + uint64_t(text.size()) + bin_chunk.size();
	if (total > UINT32_MAX)
		fail(MLOD_ERR_LIMIT, "the glb would be larger than 4 GiB");
	std::string out;
	out.reserve(size_t(total));
	for (uint32_t v : {glb_magic, uint32_t(2), uint32_t(total), uint32_t(text.size()), chunk_json})
		for (int k = 0; k < 4; k++)
			out += char(v >> (8 * k) & 0xFF);
	out += text;
	out += bin_chunk;
	return out;
}

/* ------------------------------------------------------------------ */
/* Transforms                                                          */
/* ------------------------------------------------------------------ */

mlod_trs node_trs(const tinygltf::Node &n)
{
	mlod_trs t = mlod_trs_identity();
	if (n.translation.size() == 3)
		t.t = mlod_v3{float(n.translation[0]), float(n.translation[1]), float(n.translation[2])};
	if (n.rotation.size() == 4)
		t.r = mlod_quat{float(n.rotation[0]), float(n.rotation[1]), float(n.rotation[2]), float(n.rotation[3])};
	if (n.scale.size() == 3)
		t.s = mlod_v3{float(n.scale[0]), float(n.scale[1]), float(n.scale[2])};
	return t;
}

mlod_mat4 node_matrix(const tinygltf::Node &n)
{
	if (n.matrix.size() == 16) {
		mlod_mat4 m;
		for (int i = 0; i < 16; i++)
			m.m[i] = float(n.matrix[size_t(i)]);
		return m;
	}
	mlod_trs t = node_trs(n);
	return mlod_mat4_from_trs(&t);
}

bool is_identity(const mlod_mat4 &m)
{
	mlod_mat4 id = mlod_mat4_identity();
	return memcmp(&m, &id, sizeof m) == 0;
}

/* Sets a node's TRS, leaving out identity parts; rotations are normalised
 * (the validator wants unit quaternions). */
void set_trs(tinygltf::Node &n, const mlod_trs &t)
{
	n.translation.clear();
	n.rotation.clear();
	n.scale.clear();
	n.matrix.clear();
	mlod_quat q = mlod_quat_normalize(t.r);
	if (t.t.x != 0 || t.t.y != 0 || t.t.z != 0)
		n.translation = {tidy(t.t.x), tidy(t.t.y), tidy(t.t.z)};
	if (q.x != 0 || q.y != 0 || q.z != 0 || q.w != 1)
		n.rotation = {tidy(q.x), tidy(q.y), tidy(q.z), tidy(q.w)};
	if (t.s.x != 1 || t.s.y != 1 || t.s.z != 1)
		n.scale = {tidy(t.s.x), tidy(t.s.y), tidy(t.s.z)};
}

/* Sets a node's transform from a matrix: TRS when it is one, else the matrix. */
void set_transform(tinygltf::Node &n, const mlod_mat4 &m)
{
	mlod_trs t;
	if (mlod_mat4_to_trs(&m, &t, 1e-5f) == 0) {
		set_trs(n, t);
	} else {
		set_trs(n, mlod_trs_identity());
		n.matrix.assign(m.m, m.m + 16);
	}
}

/* ------------------------------------------------------------------ */
/* glTF -> character                                                   */
/* ------------------------------------------------------------------ */

/* Builds an mlod_character from a document; every method may throw. */
class CharacterReader {
public:
	CharacterReader(const mlod_gltf &doc, mlod_character &c) : doc_(doc), m_(doc.model), c_(c) {}

	void read()
	{
		if (doc_.scene_added)
			note("the input has no scene: scene 0 added with its %d root node%s, for the stage record", doc_.scene_added,
			     doc_.scene_added == 1 ? "" : "s");
		if (doc_.rotations_normalised) {
			const tinygltf::Node &n = m_.nodes[size_t(doc_.rotation_node)];
			warn("%d node rotation%s normalised (not unit quaternions: node %d%s%s has length %g)",
			     doc_.rotations_normalised, doc_.rotations_normalised == 1 ? "" : "s", doc_.rotation_node,
			     n.name.empty() ? "" : " ", n.name.empty() ? "" : quoted(n.name).c_str(), doc_.rotation_length);
		}
		graph();
		skeleton();
		skins();
		meshes();
		instances();
		clips();
		notes();
	}

private:
	const mlod_gltf &doc_;
	const Model &m_;
	mlod_character &c_;
	std::vector<int> parent_;       /* per node */
	std::vector<int> order_;        /* nodes, parents first */
	std::vector<mlod_mat4> local_;  /* per node */
	std::vector<mlod_mat4> world_;  /* per node, at rest */
	std::vector<int> joint_of_;     /* per node: joint index or -1 */
	std::vector<char> in_skin_;     /* per node */
	std::vector<char> animated_;    /* per node: a TRS channel targets it */
	std::vector<char> shown_;       /* per node: in the default scene */
	std::vector<std::string> notes_;
	std::vector<std::string> warnings_; /* the notes of what was changed or dropped */

	void vnote(bool warning, const char *fmt, va_list ap)
	{
		char buf[MLOD_ERROR_MESSAGE_SIZE];
		vsnprintf(buf, sizeof buf, fmt, ap);
		notes_.push_back(buf);
		if (warning)
			warnings_.push_back(buf);
	}

	/* A note for the report: what the reader read in its own way. */
	void note(const char *fmt, ...) __attribute__((format(printf, 2, 3)))
	{
		va_list ap;
		va_start(ap, fmt);
		vnote(false, fmt, ap);
		va_end(ap);
	}

	/* A note the tools also print on stderr: the reader changed,
	 * approximated or dropped something of the input. */
	void warn(const char *fmt, ...) __attribute__((format(printf, 2, 3)))
	{
		va_list ap;
		va_start(ap, fmt);
		vnote(true, fmt, ap);
		va_end(ap);
	}

	/* Parents, a parents-first order (depth-first from the roots, in file
	 * order), rest transforms, the nodes the default scene shows (without
	 * scenes, every node but the MSFT_lod levels other nodes name, and
	 * their children) and the nodes TRS channels animate. */
	void graph()
	{
		size_t n = m_.nodes.size();
		parent_ = node_parents(m_);
		std::vector<int> stack;
		for (size_t i = n; i-- > 0;)
			if (parent_[i] < 0)
				stack.push_back(int(i));
		while (!stack.empty()) {
			int k = stack.back();
			stack.pop_back();
			order_.push_back(k);
			const std::vector<int> &ch = m_.nodes[size_t(k)].children;
			for (size_t i = ch.size(); i-- > 0;)
				stack.push_back(ch[i]);
		}
		local_.resize(n);
		world_.resize(n);
		for (int k : order_) {
			local_[size_t(k)] = node_matrix(m_.nodes[size_t(k)]);
			world_[size_t(k)] = parent_[size_t(k)] < 0 ? local_[size_t(k)]
			                                           : mlod_mat4_mul(&world_[size_t(parent_[size_t(k)])], &local_[size_t(k)]);
		}
		shown_.assign(n, 0);
		if (!m_.scenes.empty()) {
			for (int root : m_.scenes[size_t(std::max(m_.defaultScene, 0))].nodes)
				shown_[size_t(root)] = 1;
		} else { /* a document mlod built without a scene: every root but MSFT_lod levels */
			std::vector<char> level = lod_level_nodes(m_);
			for (size_t k = 0; k < n; k++)
				shown_[k] = parent_[k] < 0 && !level[k];
		}
		for (int k : order_)
			if (parent_[size_t(k)] >= 0 && shown_[size_t(parent_[size_t(k)])])
				shown_[size_t(k)] = 1;
		animated_.assign(n, 0);
		for (const tinygltf::Animation &a : m_.animations)
			for (const tinygltf::AnimationChannel &ch : a.channels)
				if (ch.target_node >= 0 && is_trs(ch.target_path))
					animated_[size_t(ch.target_node)] = 1;
	}

	static bool is_trs(const std::string &path)
	{
		return path == "translation" || path == "rotation" || path == "scale";
	}

	/* Is node n marked extras.mlod.end_site = true? */
	bool is_end_site(int n) const
	{
		const json e = current_extras(doc_, "/nodes/" + std::to_string(n) + "/extras", m_.nodes[size_t(n)].extras);
		const json none;
		const json &mlod = e.is_object() && e.contains(record_key) ? e[record_key] : none;
		return mlod.is_object() && mlod.contains(record_end_site) && mlod[record_end_site] == true;
	}

	/* A joint read from a BVH keeps its channel layout in
	 * extras.mlod_bvh.channels, so that its Euler order survives the glb. */
	void bvh_layout(int n, mlod_joint &j) const
	{
		static const char *const names[6] = {"Xposition", "Yposition", "Zposition",
		                                     "Xrotation", "Yrotation", "Zrotation"};
		const json e = current_extras(doc_, "/nodes/" + std::to_string(n) + "/extras", m_.nodes[size_t(n)].extras);
		if (!e.is_object() || !e.contains(bvh_key) || !e[bvh_key].is_object())
			return;
		const json &ch = e[bvh_key].contains(bvh_channels) ? e[bvh_key][bvh_channels] : json();
		if (!ch.is_array() || (ch.size() != 3 && ch.size() != 6))
			return;
		unsigned char codes[6];
		char axes[4] = {0};
		int rotations = 0;
		for (size_t i = 0; i < ch.size(); i++) {
			int code = -1;
			for (int k = 0; k < 6 && ch[i].is_string(); k++)
				if (ch[i].get<std::string>() == names[k])
					code = k;
			if (code < 0)
				return; /* not ours: ignore it */
			codes[i] = (unsigned char)code;
			if (code >= MLOD_BVH_XROT && rotations < 3)
				axes[rotations++] = char('X' + (code - MLOD_BVH_XROT));
		}
		mlod_euler_order order;
		if (rotations != 3 || mlod_euler_order_parse(axes, &order) != 0)
			return;
		j.channel_count = int(ch.size());
		memcpy(j.channels, codes, ch.size());
		j.euler = order;
	}

	/* Joints: skin joints and the nodes between a joint and its nearest
	 * joint ancestor, in parents-first order. A document without skins (a
	 * BVH converted to glTF, a node-animated rig) has its animated nodes
	 * instead of skin joints. Leaves marked as End Sites below a joint
	 * become that joint's End Site. */
	void skeleton()
	{
		size_t n = m_.nodes.size();
		in_skin_.assign(n, 0);
		for (const tinygltf::Skin &s : m_.skins)
			for (int j : s.joints)
				in_skin_[size_t(j)] = 1;
		const std::vector<char> &seeds = m_.skins.empty() ? animated_ : in_skin_;
		std::vector<char> is_joint(seeds);
		for (size_t j = 0; j < n; j++) {
			if (!seeds[j])
				continue;
			std::vector<int> between;
			int k = parent_[j];
			while (k >= 0 && !is_joint[size_t(k)]) {
				between.push_back(k);
				k = parent_[size_t(k)];
			}
			if (k >= 0)
				for (int b : between)
					is_joint[size_t(b)] = 1;
		}
		joint_of_.assign(n, -1);
		int count = 0;
		for (int k : order_)
			if (is_joint[size_t(k)])
				joint_of_[size_t(k)] = count++;
		mlod_skeleton &s = c_.skeleton;
		s.joints = c_array<mlod_joint>(size_t(count));
		s.joint_count = count;
		int sheared = 0;
		for (int k : order_) {
			int i = joint_of_[size_t(k)];
			if (i < 0)
				continue;
			mlod_joint &j = s.joints[i];
			const tinygltf::Node &node = m_.nodes[size_t(k)];
			j.name = c_string(node.name);
			j.node = k;
			j.euler = MLOD_EULER_XYZ;
			bvh_layout(k, j);
			int p = parent_[size_t(k)];
			j.parent = p >= 0 ? joint_of_[size_t(p)] : -1;
			j.base = j.parent < 0 && p >= 0 ? world_[size_t(p)] : mlod_mat4_identity();
			if (node.matrix.size() == 16)
				sheared += mlod_mat4_to_trs(&local_[size_t(k)], &j.rest, 1e-4f) != 0;
			else
				j.rest = node_trs(node);
		}
		if (m_.skins.empty() && count > 0)
			note("the document has no skins: its %d joints are the animated nodes and the nodes between them", count);
		if (sheared)
			warn("%d joint nodes have a matrix that is not a TRS (shear or singular); their rest pose is approximated",
			     sheared);
		for (size_t k = 0; k < n; k++) {
			int p = parent_[k];
			if (is_joint[k] || p < 0 || !is_joint[size_t(p)] || !m_.nodes[k].children.empty() || !is_end_site(int(k)))
				continue;
			mlod_joint &j = s.joints[joint_of_[size_t(p)]];
			if (j.has_end_site) {
				warn("joint %s has more than one End Site node; node %zu is ignored", quoted(j.name).c_str(), k);
				continue;
			}
			j.has_end_site = 1;
			j.end_site = node_trs(m_.nodes[k]).t;
		}
	}

	void skins()
	{
		mlod_skeleton &s = c_.skeleton;
		s.skins = c_array<mlod_skin>(m_.skins.size());
		s.skin_count = int(m_.skins.size());
		for (size_t i = 0; i < m_.skins.size(); i++) {
			const tinygltf::Skin &src = m_.skins[i];
			mlod_skin &k = s.skins[i];
			size_t n = src.joints.size();
			k.name = c_string(src.name);
			k.gltf_index = int(i);
			k.joints = c_array<int>(n);
			k.inverse_bind = c_array<mlod_mat4>(n);
			k.joint_count = int(n);
			std::vector<float> ibm;
			if (src.inverseBindMatrices >= 0) {
				ibm = read_floats(m_, src.inverseBindMatrices, "skin " + std::to_string(i) + " inverseBindMatrices",
				                  TINYGLTF_TYPE_MAT4);
				if (ibm.size() < 16 * n)
					fail(MLOD_ERR_PARSE, "skin %zu: %zu inverse bind matrices for %zu joints", i, ibm.size() / 16, n);
			}
			std::vector<int> roots;
			for (size_t j = 0; j < n; j++) {
				k.joints[j] = joint_of_[size_t(src.joints[j])];
				k.inverse_bind[j] = mlod_mat4_identity();
				if (!ibm.empty())
					memcpy(k.inverse_bind[j].m, &ibm[16 * j], sizeof(float[16]));
				int r = k.joints[j];
				while (s.joints[r].parent >= 0)
					r = s.joints[r].parent;
				if (std::find(roots.begin(), roots.end(), r) == roots.end())
					roots.push_back(r);
			}
			if (roots.size() > 1)
				note("skin %zu \"%s\": its joints have no common root (%zu separate hierarchies)", i, k.name, roots.size());
		}
	}

	/* Index of set n in an attribute name like "TEXCOORD_3", or -1. */
	static int set_index(const std::string &name, const char *prefix)
	{
		size_t len = strlen(prefix);
		if (name.compare(0, len, prefix) != 0 || name.size() == len || name.size() > len + 3)
			return -1;
		for (size_t i = len; i < name.size(); i++)
			if (!isdigit((unsigned char)name[i]))
				return -1;
		return atoi(name.c_str() + len);
	}

	void primitive(size_t mi, size_t pi, mlod_primitive &out)
	{
		const tinygltf::Primitive &p = m_.meshes[mi].primitives[pi];
		std::string who = "mesh " + std::to_string(mi) + " primitive " + std::to_string(pi);
		auto find = [&](const std::map<std::string, int> &attrs, const std::string &name) {
			auto it = attrs.find(name);
			return it == attrs.end() ? -1 : it->second;
		};
		int position = find(p.attributes, "POSITION");
		if (position < 0)
			fail(MLOD_ERR_PARSE, "%s: no POSITION attribute", who.c_str());
		std::vector<float> pos = read_floats(m_, position, who + " POSITION", TINYGLTF_TYPE_VEC3);
		size_t n = pos.size() / 3;
		if (n > size_t(INT_MAX))
			fail(MLOD_ERR_NOMEM, "%s: too many vertices", who.c_str());
		out.vertex_count = int(n);
		out.positions = c_copy(pos);
		out.mode = p.mode < 0 ? TINYGLTF_MODE_TRIANGLES : p.mode;
		out.material = p.material;

		/* Reads an attribute with n elements as floats with comps
		 * components (an RGB color, other_type VEC3, gets alpha 1). */
		auto floats = [&](int accessor, const std::string &name, int type, int comps, int other_type = -1) {
			std::vector<float> v = read_floats(m_, accessor, who + " " + name, type, other_type);
			size_t have = size_t(layout_of(m_.accessors[size_t(accessor)]).components);
			if (v.size() / have != n)
				fail(MLOD_ERR_PARSE, "%s: %s has %zu elements, POSITION has %zu", who.c_str(), name.c_str(), v.size() / have, n);
			if (have < size_t(comps)) {
				std::vector<float> rgba(4 * n, 1.0f);
				for (size_t i = 0; i < n; i++)
					memcpy(&rgba[4 * i], &v[3 * i], 3 * sizeof(float));
				v.swap(rgba);
			}
			return c_copy(v);
		};
		int normal = find(p.attributes, "NORMAL"), tangent = find(p.attributes, "TANGENT");
		if (normal >= 0)
			out.normals = floats(normal, "NORMAL", TINYGLTF_TYPE_VEC3, 3);
		if (tangent >= 0)
			out.tangents = floats(tangent, "TANGENT", TINYGLTF_TYPE_VEC4, 4);
		for (int k = 0; k < MLOD_MAX_SETS; k++) {
			int a = find(p.attributes, "TEXCOORD_" + std::to_string(k));
			if (a < 0)
				break;
			out.uvs[k] = floats(a, "TEXCOORD_" + std::to_string(k), TINYGLTF_TYPE_VEC2, 2);
			out.uv_set_count = k + 1;
		}
		for (int k = 0; k < MLOD_MAX_SETS; k++) {
			int a = find(p.attributes, "COLOR_" + std::to_string(k));
			if (a < 0)
				break;
			out.colors[k] = floats(a, "COLOR_" + std::to_string(k), TINYGLTF_TYPE_VEC4, 4, TINYGLTF_TYPE_VEC3);
			out.color_set_count = k + 1;
		}
		for (int k = 0; k < MLOD_MAX_SETS; k++) {
			std::string jn = "JOINTS_" + std::to_string(k), wn = "WEIGHTS_" + std::to_string(k);
			int ja = find(p.attributes, jn), wa = find(p.attributes, wn);
			if (ja < 0 || wa < 0)
				break;
			std::vector<uint32_t> joints = read_uints(m_, ja, who + " " + jn, TINYGLTF_TYPE_VEC4);
			if (joints.size() / 4 != n)
				fail(MLOD_ERR_PARSE, "%s: %s has %zu elements, POSITION has %zu", who.c_str(), jn.c_str(), joints.size() / 4, n);
			std::vector<uint16_t> narrow(joints.size());
			for (size_t i = 0; i < joints.size(); i++) {
				if (joints[i] > 0xFFFF)
					fail(MLOD_ERR_PARSE, "%s: %s of vertex %zu is %u, out of range", who.c_str(), jn.c_str(), i / 4, joints[i]);
				narrow[i] = uint16_t(joints[i]);
			}
			out.joints[k] = c_copy(narrow);
			out.weights[k] = floats(wa, wn, TINYGLTF_TYPE_VEC4, 4);
			out.weight_set_count = k + 1;
		}
		static const char *const prefixes[] = {"TEXCOORD_", "COLOR_", "JOINTS_", "WEIGHTS_"};
		const int used[] = {out.uv_set_count, out.color_set_count, out.weight_set_count, out.weight_set_count};
		for (const auto &kv : p.attributes)
			for (int s = 0; s < 4; s++)
				if (set_index(kv.first, prefixes[s]) >= used[s])
					warn("%s: attribute %s is not decoded (sets are numbered from 0, JOINTS_n with WEIGHTS_n, "
					     "at most %d)", who.c_str(), quoted(kv.first).c_str(), MLOD_MAX_SETS);
		if (p.indices >= 0) {
			std::vector<uint32_t> idx = read_uints(m_, p.indices, who + " indices", TINYGLTF_TYPE_SCALAR);
			for (size_t i = 0; i < idx.size(); i++)
				if (idx[i] >= n)
					fail(MLOD_ERR_PARSE, "%s: index %zu is %u, out of range (%zu vertices)", who.c_str(), i, idx[i], n);
			if (idx.size() > size_t(INT_MAX))
				fail(MLOD_ERR_NOMEM, "%s: too many indices", who.c_str());
			out.indices = c_copy(idx);
			out.index_count = int(idx.size());
		}
		out.targets = c_array<mlod_morph_target>(p.targets.size());
		out.target_count = int(p.targets.size());
		for (size_t t = 0; t < p.targets.size(); t++) {
			std::string tn = "morph target " + std::to_string(t) + " ";
			int a;
			if ((a = find(p.targets[t], "POSITION")) >= 0)
				out.targets[t].positions = floats(a, tn + "POSITION", TINYGLTF_TYPE_VEC3, 3);
			if ((a = find(p.targets[t], "NORMAL")) >= 0)
				out.targets[t].normals = floats(a, tn + "NORMAL", TINYGLTF_TYPE_VEC3, 3);
			if ((a = find(p.targets[t], "TANGENT")) >= 0)
				out.targets[t].tangents = floats(a, tn + "TANGENT", TINYGLTF_TYPE_VEC3, 3);
		}
	}

	void meshes()
	{
		c_.meshes = c_array<mlod_mesh>(m_.meshes.size());
		c_.mesh_count = int(m_.meshes.size());
		for (size_t i = 0; i < m_.meshes.size(); i++) {
			mlod_mesh &mesh = c_.meshes[i];
			mesh.name = c_string(m_.meshes[i].name);
			mesh.gltf_index = int(i);
			mesh.primitives = c_array<mlod_primitive>(m_.meshes[i].primitives.size());
			mesh.primitive_count = int(m_.meshes[i].primitives.size());
			for (size_t p = 0; p < m_.meshes[i].primitives.size(); p++)
				primitive(i, p, mesh.primitives[p]);
		}
	}

	/* Skinned vertices must name joints of the skin (where they have weight). */
	void check_skinning(size_t node, const mlod_mesh &mesh, const mlod_skin &skin) const
	{
		for (int p = 0; p < mesh.primitive_count; p++) {
			const mlod_primitive &pr = mesh.primitives[p];
			for (int s = 0; s < pr.weight_set_count; s++)
				for (size_t i = 0; i < 4 * size_t(pr.vertex_count); i++)
					if (pr.weights[s][i] > 0 && pr.joints[s][i] >= skin.joint_count)
						fail(MLOD_ERR_PARSE, "node %zu: mesh %d primitive %d vertex %zu uses joint %u, but skin %d has %d joints",
						     node, mesh.gltf_index, p, i / 4, pr.joints[s][i], skin.gltf_index, skin.joint_count);
		}
	}

	/* One instance per node with a mesh that the default scene shows, in
	 * node order. Nodes outside it (MSFT_lod levels, say) are not drawn. */
	void instances()
	{
		std::vector<mlod_instance> list;
		int hidden = 0;
		for (size_t k = 0; k < m_.nodes.size(); k++) {
			const tinygltf::Node &node = m_.nodes[k];
			if (node.mesh < 0)
				continue;
			if (!shown_[k]) {
				hidden++;
				continue;
			}
			mlod_instance in;
			in.mesh = node.mesh;
			in.node = int(k);
			in.skin = node.skin;
			in.joint = -1;
			in.offset = mlod_mat4_identity();
			if (in.skin >= 0) {
				check_skinning(k, c_.meshes[in.mesh], c_.skeleton.skins[in.skin]);
			} else {
				/* Hang it under its nearest joint, or place it in the world. */
				mlod_mat4 offset = mlod_mat4_identity();
				int a = int(k);
				while (a >= 0 && joint_of_[size_t(a)] < 0) {
					offset = mlod_mat4_mul(&local_[size_t(a)], &offset);
					a = parent_[size_t(a)];
				}
				in.joint = a >= 0 ? joint_of_[size_t(a)] : -1;
				in.offset = offset;
			}
			list.push_back(in);
		}
		c_.instances = c_copy(list);
		c_.instance_count = int(list.size());
		if (hidden)
			note("%d nodes with a mesh are not in the default scene (MSFT_lod levels, say): they are not instances",
			     hidden);
	}

	/* A clip per animation with joint channels: one that animates morph
	 * weights or other nodes only (a mesh without joints) has no joint
	 * motion and stays in the document alone (a pack's DOC keeps its
	 * morph weights channels, mlod(5)). */
	void clips()
	{
		int not_joint = 0, weights = 0, outside = 0;
		auto joint_channel = [&](const tinygltf::AnimationChannel &ch) {
			return ch.target_path != "weights" && is_trs(ch.target_path) && ch.target_node >= 0 &&
			       joint_of_[size_t(ch.target_node)] >= 0;
		};
		std::vector<size_t> with_joints;
		for (size_t a = 0; a < m_.animations.size(); a++) {
			bool any = false;
			for (const tinygltf::AnimationChannel &ch : m_.animations[a].channels)
				any = any || joint_channel(ch);
			if (any || c_.skeleton.joint_count > 0)
				with_joints.push_back(a);
			else
				outside++;
		}
		c_.clips = c_array<mlod_clip>(with_joints.size());
		c_.clip_count = int(with_joints.size());
		for (size_t q = 0; q < with_joints.size(); q++) {
			size_t a = with_joints[q];
			const tinygltf::Animation &anim = m_.animations[a];
			mlod_clip &clip = c_.clips[q];
			clip.name = c_string(anim.name);
			clip.gltf_index = int(a);
			std::vector<const tinygltf::AnimationChannel *> kept;
			for (const tinygltf::AnimationChannel &ch : anim.channels) {
				if (ch.target_path == "weights")
					weights++;
				else if (!joint_channel(ch))
					not_joint++;
				else
					kept.push_back(&ch);
			}
			clip.channels = c_array<mlod_channel>(kept.size());
			clip.channel_count = int(kept.size());
			for (size_t i = 0; i < kept.size(); i++) {
				channel(a, *kept[i], clip.channels[i]);
				clip.duration = std::max(clip.duration, clip.channels[i].times[clip.channels[i].key_count - 1]);
			}
			bvh_frames(a, clip);
		}
		if (not_joint)
			note("%d animation channels target nodes that are not joints (kept in the document, not in the clips)",
			     not_joint);
		if (weights)
			note("%d animation channels animate morph target weights (kept in the document, outside the joint clips)",
			     weights);
		if (outside)
			note("%d animations without joints to animate (morph target weights, say) are kept in the document, "
			     "not as clips: no joint motion to reduce",
			     outside);
	}

	/* A BVH's clip keeps its frame time in extras.mlod_bvh.frame_time of
	 * its animation (mlod_load writes it), so that its frames survive the
	 * glb: the clip is sampled again (frame_time, frame_count) when every
	 * joint channel is linear with the same key times, one key per frame
	 * (within half a frame of k times the frame time). Else the mark is
	 * stale (the animation was edited) and the clip is read as keys. */
	void bvh_frames(size_t a, mlod_clip &clip) const
	{
		const json e = current_extras(doc_, "/animations/" + std::to_string(a) + "/extras",
		                              m_.animations[a].extras);
		if (!e.is_object() || !e.contains(bvh_key) || !e[bvh_key].is_object() || clip.channel_count == 0)
			return;
		const json &ft = e[bvh_key].contains(bvh_frame_time) ? e[bvh_key][bvh_frame_time] : json();
		if (!ft.is_number())
			return;
		const float f = float(ft.get<double>());
		const mlod_channel &first = clip.channels[0];
		const int n = first.key_count;
		if (!(f > 0.0f) || !std::isfinite(f) || n < 1)
			return;
		for (int i = 0; i < clip.channel_count; i++) {
			const mlod_channel &ch = clip.channels[i];
			if (ch.interp != MLOD_INTERP_LINEAR || ch.key_count != n ||
			    std::memcmp(ch.times, first.times, sizeof(float) * size_t(n)) != 0)
				return;
		}
		for (int k = 0; k < n; k++)
			if (!(std::fabs(double(first.times[k]) - double(k) * f) <= 0.5 * f))
				return;
		clip.frame_time = f;
		clip.frame_count = n;
	}

	void channel(size_t a, const tinygltf::AnimationChannel &src, mlod_channel &ch)
	{
		const tinygltf::AnimationSampler &s = m_.animations[a].samplers[size_t(src.sampler)];
		std::string who = "animation " + std::to_string(a) + " sampler " + std::to_string(src.sampler);
		ch.joint = joint_of_[size_t(src.target_node)];
		ch.path = src.target_path == "translation" ? MLOD_PATH_TRANSLATION
		          : src.target_path == "rotation"  ? MLOD_PATH_ROTATION
		                                           : MLOD_PATH_SCALE;
		if (s.interpolation.empty() || s.interpolation == "LINEAR")
			ch.interp = MLOD_INTERP_LINEAR;
		else if (s.interpolation == "STEP")
			ch.interp = MLOD_INTERP_STEP;
		else if (s.interpolation == "CUBICSPLINE")
			ch.interp = MLOD_INTERP_CUBICSPLINE;
		else
			fail(MLOD_ERR_PARSE, "%s: unknown interpolation \"%s\"", who.c_str(), s.interpolation.c_str());
		std::vector<float> times = read_floats(m_, s.input, who + " input", TINYGLTF_TYPE_SCALAR);
		if (times.empty())
			fail(MLOD_ERR_PARSE, "%s: no keys", who.c_str());
		if (times.size() > size_t(INT_MAX))
			fail(MLOD_ERR_NOMEM, "%s: too many keys", who.c_str());
		for (size_t k = 1; k < times.size(); k++)
			if (!(times[k] > times[k - 1]))
				fail(MLOD_ERR_PARSE, "%s: key times do not increase (key %zu at %g s follows %g s)", who.c_str(), k,
				     double(times[k]), double(times[k - 1]));
		int comps = ch.path == MLOD_PATH_ROTATION ? 4 : 3;
		std::vector<float> values =
		    read_floats(m_, s.output, who + " output", ch.path == MLOD_PATH_ROTATION ? TINYGLTF_TYPE_VEC4 : TINYGLTF_TYPE_VEC3);
		size_t per_key = size_t(comps) * (ch.interp == MLOD_INTERP_CUBICSPLINE ? 3 : 1);
		if (values.size() != per_key * times.size())
			fail(MLOD_ERR_PARSE, "%s: output has %zu elements for %zu keys, not %zu (%s)", who.c_str(),
			     values.size() / size_t(comps), times.size(), per_key / size_t(comps) * times.size(),
			     ch.interp == MLOD_INTERP_CUBICSPLINE ? "in-tangent, value and out-tangent per key" : "one per key");
		ch.times = c_copy(times);
		ch.values = c_copy(values);
		ch.key_count = int(times.size());
	}

	static std::string lines(const std::vector<std::string> &v)
	{
		std::string all;
		for (const std::string &n : v)
			all += (all.empty() ? "" : "\n") + n;
		return all;
	}

	void notes()
	{
		std::string outside;
		int count = 0, moving = 0;
		for (size_t k = 0; k < m_.nodes.size() && !m_.skins.empty(); k++) {
			if (joint_of_[k] < 0 || in_skin_[k])
				continue;
			if (count++ < 8)
				outside += std::string(count > 1 ? ", " : "") + "\"" + m_.nodes[k].name + "\"";
			moving += animated_[k];
		}
		if (count)
			note("%d joint nodes are in no skin (they connect skin joints: %s%s), %d of them animated", count,
			     outside.c_str(), count > 8 ? ", ..." : "", moving);
		if (notes_.empty())
			return;
		c_.notes = c_string(lines(notes_));
		if (!warnings_.empty())
			c_.warnings = c_string(lines(warnings_));
	}
};

/* ------------------------------------------------------------------ */
/* Character -> glTF                                                   */
/* ------------------------------------------------------------------ */

/* Appends bytes to buffer 0 (made if there is none) at a 4-byte aligned
 * offset, as a new buffer view; returns the view. */
int append_view(Model &m, const void *data, size_t size, int target)
{
	if (m.buffers.empty())
		m.buffers.emplace_back();
	std::vector<unsigned char> &b = m.buffers[0].data;
	b.resize((b.size() + 3) / 4 * 4, 0);
	tinygltf::BufferView v;
	v.buffer = 0;
	v.byteOffset = b.size();
	v.byteLength = size;
	v.target = target;
	const unsigned char *p = static_cast<const unsigned char *>(data);
	b.insert(b.end(), p, p + size);
	m.bufferViews.push_back(v);
	return int(m.bufferViews.size() - 1);
}

/* Appends an accessor over count elements of comps components at data.
 * With min_max, records the per-component bounds (floats only). */
int append_accessor(Model &m, const void *data, size_t count, int component_type, int type, int comps, int target,
                    bool min_max)
{
	size_t bytes = count * size_t(comps) * component_size(component_type);
	tinygltf::Accessor a;
	a.bufferView = append_view(m, data, bytes, target);
	a.byteOffset = 0;
	a.componentType = component_type;
	a.count = count;
	a.type = type;
	a.normalized = false;
	if (min_max) {
		const float *v = static_cast<const float *>(data);
		a.minValues.assign(size_t(comps), INFINITY);
		a.maxValues.assign(size_t(comps), -INFINITY);
		for (size_t i = 0; i < count; i++)
			for (size_t c = 0; c < size_t(comps); c++) {
				a.minValues[c] = std::min(a.minValues[c], double(v[i * size_t(comps) + c]));
				a.maxValues[c] = std::max(a.maxValues[c], double(v[i * size_t(comps) + c]));
			}
	}
	m.accessors.push_back(a);
	return int(m.accessors.size() - 1);
}

/* append_accessor for floats: comps 1 to 4 are SCALAR to VEC4, 16 is MAT4. */
int append_floats(Model &m, const float *v, size_t count, int comps, int target, bool min_max = false)
{
	static const int types[] = {0, TINYGLTF_TYPE_SCALAR, TINYGLTF_TYPE_VEC2, TINYGLTF_TYPE_VEC3, TINYGLTF_TYPE_VEC4};
	int type = comps == 16 ? TINYGLTF_TYPE_MAT4 : types[comps];
	return append_accessor(m, v, count, TINYGLTF_COMPONENT_TYPE_FLOAT, type, comps, target, min_max);
}

/* Callers' data must be finite: JSON cannot hold NaN in min/max. */
void check_finite(const float *v, size_t n, const char *what)
{
	for (size_t i = 0; i < n; i++)
		if (!std::isfinite(v[i]))
			fail(MLOD_ERR_INVALID_ARG, "%s: value %zu is not finite", what, i);
}

/* Adds JOINTS_n (unsigned short) and WEIGHTS_n (float) of p to attributes. */
void add_skinning(Model &m, const mlod_primitive &p, std::map<std::string, int> &attributes)
{
	size_t n = size_t(p.vertex_count);
	for (int k = 0; k < p.weight_set_count && k < MLOD_MAX_SETS; k++) {
		if (!p.joints[k] || !p.weights[k])
			continue;
		check_finite(p.weights[k], 4 * n, "weights");
		attributes["JOINTS_" + std::to_string(k)] = append_accessor(
		    m, p.joints[k], n, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, TINYGLTF_TYPE_VEC4, 4, TINYGLTF_TARGET_ARRAY_BUFFER, false);
		attributes["WEIGHTS_" + std::to_string(k)] = append_floats(m, p.weights[k], n, 4, TINYGLTF_TARGET_ARRAY_BUFFER);
	}
}

/* A glTF primitive with new accessors for every attribute of p (POSITION
 * with min and max, 16-bit indices when the vertices allow). */
tinygltf::Primitive make_primitive(Model &m, const mlod_primitive &p, int mesh_index, int index)
{
	char who[64];
	snprintf(who, sizeof who, "mesh %d primitive %d", mesh_index, index);
	if (p.vertex_count <= 0 || !p.positions)
		fail(MLOD_ERR_INVALID_ARG, "%s: no vertices", who);
	if (p.material < -1 || p.material >= int(m.materials.size()))
		fail(MLOD_ERR_INVALID_ARG, "%s: material %d does not exist in the document", who, p.material);
	size_t n = size_t(p.vertex_count);
	check_finite(p.positions, 3 * n, who);
	tinygltf::Primitive out;
	out.mode = p.mode;
	out.material = p.material;
	auto attribute = [&](const char *name, int k, const float *v, int comps, bool min_max = false) {
		if (v)
			out.attributes[k < 0 ? name : name + std::to_string(k)] =
			    append_floats(m, v, n, comps, TINYGLTF_TARGET_ARRAY_BUFFER, min_max);
	};
	attribute("POSITION", -1, p.positions, 3, true);
	attribute("NORMAL", -1, p.normals, 3);
	attribute("TANGENT", -1, p.tangents, 4);
	for (int k = 0; k < p.uv_set_count && k < MLOD_MAX_SETS; k++)
		attribute("TEXCOORD_", k, p.uvs[k], 2);
	for (int k = 0; k < p.color_set_count && k < MLOD_MAX_SETS; k++)
		attribute("COLOR_", k, p.colors[k], 4);
	add_skinning(m, p, out.attributes);
	if (p.index_count > 0 && p.indices) {
		size_t count = size_t(p.index_count);
		for (size_t i = 0; i < count; i++)
			if (p.indices[i] >= n)
				fail(MLOD_ERR_INVALID_ARG, "%s: index %zu is %u, out of range (%zu vertices)", who, i, p.indices[i], n);
		if (n <= 0xFFFF) { /* 65535 is the primitive restart value */
			std::vector<uint16_t> narrow(p.indices, p.indices + count);
			out.indices = append_accessor(m, narrow.data(), count, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT,
			                              TINYGLTF_TYPE_SCALAR, 1, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER, false);
		} else {
			out.indices = append_accessor(m, p.indices, count, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR,
			                              1, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER, false);
		}
	}
	for (int t = 0; t < p.target_count && p.targets; t++) {
		std::map<std::string, int> target;
		const mlod_morph_target &mt = p.targets[t];
		const float *parts[] = {mt.positions, mt.normals, mt.tangents};
		const char *names[] = {"POSITION", "NORMAL", "TANGENT"};
		for (int k = 0; k < 3; k++)
			if (parts[k])
				target[names[k]] = append_floats(m, parts[k], n, 3, TINYGLTF_TARGET_ARRAY_BUFFER, k == 0);
		out.targets.push_back(target);
	}
	return out;
}

/* Appends a mesh with mesh's primitives; returns its index. */
int add_mesh(Model &m, const mlod_mesh &mesh)
{
	if (mesh.primitive_count <= 0 || !mesh.primitives)
		fail(MLOD_ERR_INVALID_ARG, "mesh \"%s\": no primitives", mesh.name ? mesh.name : "");
	tinygltf::Mesh out;
	out.name = utf8(mesh.name);
	int index = int(m.meshes.size());
	for (int p = 0; p < mesh.primitive_count; p++)
		out.primitives.push_back(make_primitive(m, mesh.primitives[p], index, p));
	m.meshes.push_back(std::move(out));
	return index;
}

/* Appends a copy of mesh `mesh` with JOINTS_n/WEIGHTS_n from m; the rest
 * shares the original accessors, and extras are copied exactly. */
int add_mesh_reskinned(mlod_gltf &doc, int mesh, const mlod_mesh &m)
{
	Model &model = doc.model;
	if (mesh < 0 || size_t(mesh) >= model.meshes.size())
		fail(MLOD_ERR_INVALID_ARG, "mesh %d does not exist", mesh);
	tinygltf::Mesh copy = model.meshes[size_t(mesh)];
	if (m.primitive_count != int(copy.primitives.size()) || !m.primitives)
		fail(MLOD_ERR_INVALID_ARG, "mesh %d has %zu primitives, the new skinning %d", mesh, copy.primitives.size(),
		     m.primitive_count);
	for (size_t p = 0; p < copy.primitives.size(); p++) {
		std::map<std::string, int> &attributes = copy.primitives[p].attributes;
		auto position = attributes.find("POSITION");
		const mlod_primitive &mp = m.primitives[p];
		if (position == attributes.end() || model.accessors[size_t(position->second)].count != size_t(mp.vertex_count))
			fail(MLOD_ERR_INVALID_ARG, "mesh %d primitive %zu: the new skinning has %d vertices, not as many as POSITION",
			     mesh, p, mp.vertex_count);
		for (auto it = attributes.begin(); it != attributes.end();)
			it = it->first.compare(0, 7, "JOINTS_") == 0 || it->first.compare(0, 8, "WEIGHTS_") == 0 ? attributes.erase(it)
			                                                                                       : std::next(it);
		add_skinning(model, mp, attributes);
	}
	int index = int(model.meshes.size());
	model.meshes.push_back(std::move(copy));
	std::string from = "/meshes/" + std::to_string(mesh) + "/", to = "/meshes/" + std::to_string(index) + "/";
	std::map<std::string, json> copied;
	for (auto it = doc.extras.lower_bound(from); it != doc.extras.end() && it->first.compare(0, from.size(), from) == 0; ++it)
		copied[to + it->first.substr(from.size())] = it->second;
	doc.extras.insert(copied.begin(), copied.end());
	return index;
}

/* Appends a skin whose joint k is node nodes[skin.joints[k]]. */
int add_skin(Model &m, const mlod_skin &skin, const std::vector<int> &nodes)
{
	if (skin.joint_count <= 0 || !skin.joints)
		fail(MLOD_ERR_INVALID_ARG, "skin \"%s\": no joints", skin.name ? skin.name : "");
	tinygltf::Skin out;
	out.name = utf8(skin.name);
	for (int k = 0; k < skin.joint_count; k++) {
		int j = skin.joints[k];
		if (j < 0 || size_t(j) >= nodes.size() || nodes[size_t(j)] < 0 || size_t(nodes[size_t(j)]) >= m.nodes.size())
			fail(MLOD_ERR_INVALID_ARG, "skin \"%s\": joint %d (%d) has no node in the document", out.name.c_str(), k, j);
		out.joints.push_back(nodes[size_t(j)]);
	}
	std::vector<float> ibm(16 * size_t(skin.joint_count));
	for (int k = 0; k < skin.joint_count; k++) {
		mlod_mat4 id = mlod_mat4_identity();
		memcpy(&ibm[16 * size_t(k)], skin.inverse_bind ? skin.inverse_bind[k].m : id.m, sizeof(float[16]));
	}
	check_finite(ibm.data(), ibm.size(), "inverse bind matrices");
	out.inverseBindMatrices = append_floats(m, ibm.data(), size_t(skin.joint_count), 16, 0);
	m.skins.push_back(std::move(out));
	return int(m.skins.size() - 1);
}

/* Appends an animation whose channels target nodes[channel.joint]; key
 * times shared by several channels are stored once. */
int add_animation(Model &m, const mlod_clip &clip, const std::vector<int> &nodes)
{
	if (clip.channel_count <= 0 || !clip.channels)
		fail(MLOD_ERR_INVALID_ARG, "clip \"%s\": no channels (a glTF animation needs one)", clip.name ? clip.name : "");
	tinygltf::Animation out;
	out.name = utf8(clip.name);
	std::map<std::vector<float>, int> inputs;
	static const char *const paths[] = {"translation", "rotation", "scale"};
	static const char *const interps[] = {"LINEAR", "STEP", "CUBICSPLINE"};
	for (int i = 0; i < clip.channel_count; i++) {
		const mlod_channel &ch = clip.channels[i];
		if (ch.joint < 0 || size_t(ch.joint) >= nodes.size() || nodes[size_t(ch.joint)] < 0 ||
		    size_t(nodes[size_t(ch.joint)]) >= m.nodes.size())
			fail(MLOD_ERR_INVALID_ARG, "clip \"%s\" channel %d: joint %d has no node in the document", out.name.c_str(), i, ch.joint);
		if (ch.key_count <= 0 || !ch.times || !ch.values || unsigned(ch.path) > MLOD_PATH_SCALE ||
		    unsigned(ch.interp) > MLOD_INTERP_CUBICSPLINE)
			fail(MLOD_ERR_INVALID_ARG, "clip \"%s\" channel %d: no keys, or a bad path or interpolation", out.name.c_str(), i);
		size_t keys = size_t(ch.key_count), comps = ch.path == MLOD_PATH_ROTATION ? 4 : 3;
		size_t per_key = comps * (ch.interp == MLOD_INTERP_CUBICSPLINE ? 3 : 1);
		std::vector<float> times(ch.times, ch.times + keys), values(ch.values, ch.values + keys * per_key);
		check_finite(times.data(), keys, "key times");
		check_finite(values.data(), values.size(), "key values");
		for (size_t k = 1; k < keys; k++)
			if (!(times[k] > times[k - 1]))
				fail(MLOD_ERR_INVALID_ARG, "clip \"%s\" channel %d: key times do not increase", out.name.c_str(), i);
		/* Unit quaternions; cubic tangents stay as they are. A key unit to
		 * single precision (its squared length within 1e-6 of 1, as
		 * mlod_quat_normalize's are) is written as given: normalising it
		 * again moves some keys by a last bit, and not to a fixed point
		 * (31 of the walk's 16,244 keys cycle), so the keys read back
		 * would depend on how many times they were written (a BVH read
		 * directly against the glb a stage makes of it:
		 * cli/pack_bvh_stages; the BVH reader normalises once more). */
		if (ch.path == MLOD_PATH_ROTATION) {
			size_t first = ch.interp == MLOD_INTERP_CUBICSPLINE ? 4 : 0;
			for (size_t k = 0; k < keys; k++) {
				float *q = &values[k * per_key + first];
				double n2 = double(q[0]) * q[0] + double(q[1]) * q[1] + double(q[2]) * q[2] + double(q[3]) * q[3];
				if (std::fabs(n2 - 1.0) <= 1e-6)
					continue;
				mlod_quat n = mlod_quat_normalize(mlod_quat{q[0], q[1], q[2], q[3]});
				q[0] = n.x, q[1] = n.y, q[2] = n.z, q[3] = n.w;
			}
		}
		/* Rotations on the lattice of normalised shorts are written as such
		 * (as given: the lattice is as unit as it gets). */
		std::vector<int16_t> shorts;
		if (ch.short_values && ch.path == MLOD_PATH_ROTATION && ch.interp != MLOD_INTERP_CUBICSPLINE)
			for (size_t k = 0; k < keys * per_key; k++) {
				long n = lrint(double(ch.values[k]) * 32767.0);
				if (n < -32767 || n > 32767 || float(n / 32767.0) != ch.values[k]) {
					shorts.clear();
					break;
				}
				shorts.push_back(int16_t(n));
			}
		auto in = inputs.find(times);
		if (in == inputs.end())
			in = inputs.emplace(times, append_floats(m, times.data(), keys, 1, 0, true)).first;
		tinygltf::AnimationSampler s;
		s.input = in->second;
		if (!shorts.empty()) {
			s.output = append_accessor(m, shorts.data(), keys, TINYGLTF_COMPONENT_TYPE_SHORT, TINYGLTF_TYPE_VEC4, 4, 0,
			                           false);
			m.accessors.back().normalized = true;
		} else {
			s.output = append_floats(m, values.data(), values.size() / comps, int(comps), 0);
		}
		s.interpolation = interps[ch.interp];
		out.samplers.push_back(s);
		tinygltf::AnimationChannel c;
		c.sampler = int(out.samplers.size() - 1);
		c.target_node = nodes[size_t(ch.joint)];
		c.target_path = paths[ch.path];
		out.channels.push_back(c);
	}
	m.animations.push_back(std::move(out));
	return int(m.animations.size() - 1);
}

/* The scene parentless nodes join: the default one, made if needed. */
tinygltf::Scene &default_scene(Model &m)
{
	if (m.scenes.empty())
		m.scenes.emplace_back();
	if (m.defaultScene < 0)
		m.defaultScene = 0;
	return m.scenes[size_t(m.defaultScene)];
}

/* Fills an empty model from a character: joint nodes first (node i is
 * joint i), a node above each root whose base is not the identity, End
 * Site nodes, meshes, skins, instance nodes (rigid ones under their joint)
 * and one animation per clip with channels. */
void build_document(Model &m, const mlod_character &c)
{
	m.asset.version = "2.0";
	m.asset.generator = "mlod";
	const mlod_skeleton &s = c.skeleton;
	std::vector<int> roots, node_of_joint; /* joint i is node i */
	m.nodes.resize(size_t(s.joint_count));
	for (int i = 0; i < s.joint_count; i++) {
		const mlod_joint &j = s.joints[i];
		node_of_joint.push_back(i);
		m.nodes[size_t(i)].name = utf8(j.name);
		set_trs(m.nodes[size_t(i)], j.rest);
		if (j.channel_count > 0) {
			static const char *const names[6] = {"Xposition", "Yposition", "Zposition",
			                                     "Xrotation", "Yrotation", "Zrotation"};
			Value::Array channels;
			for (int k = 0; k < j.channel_count && k < 6; k++)
				if (j.channels[k] < 6)
					channels.push_back(Value(std::string(names[j.channels[k]])));
			m.nodes[size_t(i)].extras =
				Value(Value::Object{{bvh_key, Value(Value::Object{{bvh_channels, Value(channels)}})}});
		}
	}
	for (int i = 0; i < s.joint_count; i++) {
		const mlod_joint &j = s.joints[i];
		if (j.parent >= 0) {
			m.nodes[size_t(j.parent)].children.push_back(i);
		} else if (is_identity(j.base)) {
			roots.push_back(i);
		} else { /* the world transform above a root: a node of its own */
			tinygltf::Node base;
			base.name = utf8(j.name) + "_base";
			set_transform(base, j.base);
			base.children.push_back(i);
			m.nodes.push_back(base);
			roots.push_back(int(m.nodes.size() - 1));
		}
		if (j.has_end_site) {
			tinygltf::Node end;
			end.name = utf8(j.name) + "_end";
			set_trs(end, mlod_trs{j.end_site, mlod_quat_identity(), mlod_v3{1, 1, 1}});
			end.extras = Value(Value::Object{{record_key, Value(Value::Object{{record_end_site, Value(true)}})}});
			m.nodes.push_back(end);
			m.nodes[size_t(i)].children.push_back(int(m.nodes.size() - 1));
		}
	}
	for (int i = 0; i < c.mesh_count; i++) {
		mlod_mesh mesh = c.meshes[i];
		/* A new document has no materials. */
		std::vector<mlod_primitive> prims(mesh.primitives, mesh.primitives + mesh.primitive_count);
		for (mlod_primitive &p : prims)
			p.material = -1;
		mesh.primitives = prims.data();
		add_mesh(m, mesh);
	}
	for (int i = 0; i < s.skin_count; i++)
		add_skin(m, s.skins[i], node_of_joint);
	for (int i = 0; i < c.instance_count; i++) {
		const mlod_instance &in = c.instances[i];
		tinygltf::Node node;
		node.name = utf8(c.meshes[in.mesh].name);
		node.mesh = in.mesh;
		node.skin = in.skin;
		if (in.skin < 0)
			set_transform(node, in.offset);
		m.nodes.push_back(node);
		int k = int(m.nodes.size() - 1);
		if (in.skin < 0 && in.joint >= 0)
			m.nodes[size_t(in.joint)].children.push_back(k);
		else
			roots.push_back(k);
	}
	for (int i = 0; i < c.clip_count; i++)
		if (c.clips[i].channel_count > 0)
			add_animation(m, c.clips[i], node_of_joint);
	default_scene(m).nodes = roots;
}

/* ------------------------------------------------------------------ */
/* Extras                                                              */
/* ------------------------------------------------------------------ */

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

/* Sets extras[key] of an object, keeping its other keys. */
void set_extra(mlod_gltf &doc, mlod_gltf_kind kind, int index, const std::string &key, const json &v)
{
	std::string pointer;
	Value *value = extras_slot(doc, kind, index, &pointer);
	json e = current_extras(doc, pointer, *value);
	if (e.is_null())
		e = json::object();
	if (!e.is_object())
		fail(MLOD_ERR_UNSUPPORTED, "%s is not a JSON object: mlod does not add keys to it", pointer.c_str());
	e[key] = v;
	*value = to_value(e);
	doc.extras[pointer] = std::move(e);
}

/* The glTF node of every joint of s (-1 when it has none). */
std::vector<int> joint_nodes(const mlod_skeleton *s)
{
	std::vector<int> nodes;
	for (int i = 0; i < s->joint_count; i++)
		nodes.push_back(s->joints[i].node);
	return nodes;
}

/* ------------------------------------------------------------------ */
/* Editing a read document: level meshes in place, pruning             */
/* ------------------------------------------------------------------ */

/* Appends a mesh with mesh's primitives that takes the name, default
 * morph weights, extensions and extras of glTF mesh `like` (and of its
 * primitives, by position); returns its index. */
int add_mesh_like(mlod_gltf &doc, int like, const mlod_mesh &mesh)
{
	Model &m = doc.model;
	if (like < 0 || size_t(like) >= m.meshes.size())
		fail(MLOD_ERR_INVALID_ARG, "mesh %d does not exist", like);
	int index = add_mesh(m, mesh);
	const tinygltf::Mesh &src = m.meshes[size_t(like)];
	tinygltf::Mesh &dst = m.meshes[size_t(index)];
	size_t prims = std::min(src.primitives.size(), dst.primitives.size());
	bool same_targets = true;
	for (size_t p = 0; p < dst.primitives.size(); p++)
		same_targets = same_targets && dst.primitives[p].targets.size() == src.weights.size();
	dst.name = src.name;
	if (same_targets)
		dst.weights = src.weights;
	dst.extensions = src.extensions;
	dst.extras = src.extras;
	for (size_t p = 0; p < prims; p++) {
		/* Not Draco's: it points at the full mesh's compressed data (a
		 * file that lists Draco as used but not required gets here). */
		dst.primitives[p].extensions = src.primitives[p].extensions;
		dst.primitives[p].extensions.erase("KHR_draco_mesh_compression");
		dst.primitives[p].extras = src.primitives[p].extras;
	}
	std::string from = "/meshes/" + std::to_string(like) + "/", to = "/meshes/" + std::to_string(index) + "/";
	std::map<std::string, json> copied;
	for (auto it = doc.extras.lower_bound(from); it != doc.extras.end() && it->first.compare(0, from.size(), from) == 0;
	     ++it) {
		std::string rest = it->first.substr(from.size());
		unsigned long p = 0;
		if (rest == "extras" || (sscanf(rest.c_str(), "primitives/%lu/extras", &p) == 1 && p < prims &&
		                         rest == "primitives/" + std::to_string(p) + "/extras"))
			copied[to + rest] = it->second;
	}
	doc.extras.insert(copied.begin(), copied.end());
	return index;
}

/* Extensions that refer to no mesh, accessor or buffer view, so that
 * pruning (which renumbers those) leaves them right. */
bool prune_safe(const std::string &name)
{
	static const char *const prefixes[] = {"KHR_materials_", "KHR_texture_", "KHR_lights_punctual",
	                                       "KHR_mesh_quantization", "KHR_xmp", "EXT_texture_", "MSFT_lod",
	                                       "MSFT_texture_dds"};
	for (const char *p : prefixes)
		if (name.compare(0, strlen(p), p) == 0)
			return true;
	return false;
}

/* Drops the elements of array `name` that keep says go, from the JSON as
 * read and from the exact extras (later ones renumbered). Returns the
 * old -> new index map (-1: dropped). The caller drops them from the model. */
std::vector<int> renumber(mlod_gltf &doc, const std::string &name, const std::vector<bool> &keep)
{
	std::vector<int> map(keep.size(), -1);
	int n = 0;
	for (size_t i = 0; i < keep.size(); i++)
		if (keep[i])
			map[i] = n++;
	if (doc.original.is_object() && doc.original.contains(name) && doc.original[name].is_array()) {
		json kept = json::array();
		const json &a = doc.original[name];
		for (size_t i = 0; i < a.size(); i++)
			if (i >= keep.size() || keep[i])
				kept.push_back(a[i]);
		doc.original[name] = std::move(kept);
	}
	std::string prefix = "/" + name + "/";
	std::map<std::string, json> moved;
	for (auto it = doc.extras.lower_bound(prefix);
	     it != doc.extras.end() && it->first.compare(0, prefix.size(), prefix) == 0;) {
		size_t slash = it->first.find('/', prefix.size());
		size_t i = size_t(std::stoul(it->first.substr(prefix.size(), slash - prefix.size())));
		if (i < map.size() && map[i] >= 0)
			moved[prefix + std::to_string(map[i]) + it->first.substr(slash)] = std::move(it->second);
		it = doc.extras.erase(it);
	}
	doc.extras.insert(moved.begin(), moved.end());
	return map;
}

template <class T> void keep_only(std::vector<T> &v, const std::vector<bool> &keep)
{
	size_t n = 0;
	for (size_t i = 0; i < v.size(); i++)
		if (keep[i]) {
			if (n != i) /* never move an element onto itself */
				v[n] = std::move(v[i]);
			n++;
		}
	v.resize(n);
}

/* The buffer views and buffers that an extension's JSON names (a
 * "bufferView" or "buffer" member anywhere inside an "extensions"
 * object), which prune_tail keeps whole. */
void extension_refs(const json &j, bool inside, std::vector<bool> &views, std::vector<bool> &buffers)
{
	if (j.is_object()) {
		for (auto it = j.begin(); it != j.end(); ++it) {
			if (inside && it->is_number_integer() && it->get<long long>() >= 0) {
				size_t i = size_t(it->get<long long>());
				if (it.key() == "bufferView" && i < views.size())
					views[i] = true;
				if (it.key() == "buffer" && i < buffers.size())
					buffers[i] = true;
			}
			extension_refs(*it, inside || it.key() == "extensions", views, buffers);
		}
	} else if (j.is_array()) {
		for (const json &e : j)
			extension_refs(e, inside, views, buffers);
	}
}

/* Flags index i in used (an index out of range or -1: none). */
void mark_used(std::vector<bool> &used, int i)
{
	if (i >= 0 && size_t(i) < used.size())
		used[size_t(i)] = true;
}

/* The accessors the meshes, skins and animations of m use. */
std::vector<bool> used_accessors(const Model &m)
{
	std::vector<bool> used(m.accessors.size(), false);
	for (const tinygltf::Mesh &mesh : m.meshes)
		for (const tinygltf::Primitive &p : mesh.primitives) {
			mark_used(used, p.indices);
			for (const auto &kv : p.attributes)
				mark_used(used, kv.second);
			for (const auto &t : p.targets)
				for (const auto &kv : t)
					mark_used(used, kv.second);
		}
	for (const tinygltf::Skin &sk : m.skins)
		mark_used(used, sk.inverseBindMatrices);
	for (const tinygltf::Animation &a : m.animations)
		for (const tinygltf::AnimationSampler &sa : a.samplers) {
			mark_used(used, sa.input);
			mark_used(used, sa.output);
		}
	return used;
}

/* Flags in used the buffer views the accessors (their sparse parts too)
 * and images of m use. */
void mark_used_views(const Model &m, std::vector<bool> &used)
{
	for (const tinygltf::Accessor &a : m.accessors) {
		mark_used(used, a.bufferView);
		if (a.sparse.isSparse) {
			mark_used(used, a.sparse.indices.bufferView);
			mark_used(used, a.sparse.values.bufferView);
		}
	}
	for (const tinygltf::Image &i : m.images)
		mark_used(used, i.bufferView);
}

/* prune for a document whose indices must hold (keep_indices): the
 * accessors and buffer views after the last one in use go, and each
 * buffer's bytes after its last kept view (a buffer an extension names
 * stays whole); nothing else moves. */
void prune_tail(mlod_gltf &doc)
{
	Model &m = doc.model;
	auto tail = [](std::vector<bool> &used) {
		size_t n = used.size();
		while (n > 0 && !used[n - 1])
			n--;
		for (size_t i = 0; i < used.size(); i++)
			used[i] = i < n;
	};
	std::vector<bool> used = used_accessors(m);
	tail(used);
	renumber(doc, "accessors", used);
	keep_only(m.accessors, used);

	used.assign(m.bufferViews.size(), false);
	std::vector<bool> named(m.buffers.size(), false);
	extension_refs(doc.original, false, used, named);
	mark_used_views(m, used);
	tail(used);
	renumber(doc, "bufferViews", used);
	keep_only(m.bufferViews, used);
	for (size_t b = 0; b < m.buffers.size(); b++) {
		size_t end = 0;
		bool any = false;
		for (const tinygltf::BufferView &v : m.bufferViews)
			if (v.buffer == int(b))
				any = true, end = std::max(end, size_t(v.byteOffset + v.byteLength));
		if (any && !named[b] && end < m.buffers[b].data.size())
			m.buffers[b].data.resize(end);
	}
}

/* Drops the meshes no node uses, then the accessors and buffer views
 * nothing uses, and packs the buffers' bytes again. */
void prune(mlod_gltf &doc, bool meshes = true)
{
	Model &m = doc.model;
	if (doc.keep_indices) {
		prune_tail(doc);
		return;
	}
	for (const std::string &e : m.extensionsUsed)
		if (!prune_safe(e))
			fail(MLOD_ERR_UNSUPPORTED, "extension %s may refer to meshes or accessors: the document is not pruned",
			     e.c_str());
	auto apply = [](const std::vector<int> &map, int &i) {
		if (i >= 0)
			i = size_t(i) < map.size() ? map[size_t(i)] : -1;
	};

	std::vector<bool> used(m.meshes.size(), true);
	std::vector<int> map;
	if (meshes) {
		used.assign(m.meshes.size(), false);
		for (const tinygltf::Node &n : m.nodes)
			mark_used(used, n.mesh);
		map = renumber(doc, "meshes", used);
		keep_only(m.meshes, used);
		for (tinygltf::Node &n : m.nodes)
			apply(map, n.mesh);
	}

	used = used_accessors(m);
	map = renumber(doc, "accessors", used);
	keep_only(m.accessors, used);
	for (tinygltf::Mesh &mesh : m.meshes)
		for (tinygltf::Primitive &p : mesh.primitives) {
			apply(map, p.indices);
			for (auto &kv : p.attributes)
				apply(map, kv.second);
			for (auto &t : p.targets)
				for (auto &kv : t)
					apply(map, kv.second);
		}
	for (tinygltf::Skin &s : m.skins)
		apply(map, s.inverseBindMatrices);
	for (tinygltf::Animation &a : m.animations)
		for (tinygltf::AnimationSampler &s : a.samplers) {
			apply(map, s.input);
			apply(map, s.output);
		}

	used.assign(m.bufferViews.size(), false);
	mark_used_views(m, used);
	map = renumber(doc, "bufferViews", used);
	keep_only(m.bufferViews, used);
	for (tinygltf::Accessor &a : m.accessors) {
		apply(map, a.bufferView);
		if (a.sparse.isSparse) {
			apply(map, a.sparse.indices.bufferView);
			apply(map, a.sparse.values.bufferView);
		}
	}
	for (tinygltf::Image &i : m.images)
		apply(map, i.bufferView);

	/* Each buffer keeps its views' bytes only, in view order, 4-byte aligned. */
	for (size_t b = 0; b < m.buffers.size(); b++) {
		std::vector<unsigned char> packed;
		for (tinygltf::BufferView &v : m.bufferViews) {
			if (v.buffer != int(b))
				continue;
			const std::vector<unsigned char> &data = m.buffers[b].data;
			if (v.byteOffset > data.size() || v.byteLength > data.size() - v.byteOffset)
				fail(MLOD_ERR_PARSE, "a buffer view lies outside buffer %zu", b);
			packed.resize((packed.size() + 3) / 4 * 4, 0);
			size_t at = packed.size();
			packed.insert(packed.end(), data.begin() + long(v.byteOffset), data.begin() + long(v.byteOffset + v.byteLength));
			v.byteOffset = at;
		}
		m.buffers[b].data = std::move(packed);
	}
	/* A buffer no view uses any more goes: a kept empty one (byteLength
	 * 0, an empty data: URI) is not glTF and does not read back. */
	used.assign(m.buffers.size(), false);
	for (const tinygltf::BufferView &v : m.bufferViews)
		mark_used(used, v.buffer);
	map = renumber(doc, "buffers", used);
	keep_only(m.buffers, used);
	for (tinygltf::BufferView &v : m.bufferViews)
		apply(map, v.buffer);
	/* The JSON as read follows: it brings back what tinygltf leaves out
	 * (a zero byteOffset) and drops what it lacks. */
	if (doc.original.is_object() && doc.original.contains("bufferViews") && doc.original["bufferViews"].is_array()) {
		json &views = doc.original["bufferViews"];
		for (size_t i = 0; i < views.size() && i < m.bufferViews.size(); i++)
			if (views[i].is_object())
				views[i]["byteOffset"] = m.bufferViews[i].byteOffset;
	}
}

/* Gives node `to` the default morph weights of node `from` and, in every
 * animation, a copy of each channel animating from's weights. Returns the
 * channels added. */
int copy_morph_animation(Model &m, int from, int to)
{
	if (from < 0 || size_t(from) >= m.nodes.size() || to < 0 || size_t(to) >= m.nodes.size())
		fail(MLOD_ERR_INVALID_ARG, "node %d or %d does not exist", from, to);
	m.nodes[size_t(to)].weights = m.nodes[size_t(from)].weights;
	int added = 0;
	for (tinygltf::Animation &a : m.animations) {
		size_t n = a.channels.size();
		for (size_t c = 0; c < n; c++)
			if (a.channels[c].target_node == from && a.channels[c].target_path == "weights") {
				tinygltf::AnimationChannel copy = a.channels[c];
				copy.target_node = to;
				a.channels.push_back(copy);
				added++;
			}
	}
	return added;
}

/* Removes MSFT_lod from node and MSFT_screencoverage from its extras; its
 * former level nodes lose their mesh and skin (they stay, empty, so that
 * node indices hold). MSFT_lod leaves extensionsUsed when no node uses it
 * any more. The JSON as read follows. */
void clear_lod(mlod_gltf &doc, int node)
{
	Model &m = doc.model;
	if (node < 0 || size_t(node) >= m.nodes.size())
		fail(MLOD_ERR_INVALID_ARG, "node %d does not exist", node);
	tinygltf::Node &n = m.nodes[size_t(node)];
	auto lod = n.extensions.find("MSFT_lod");
	if (lod == n.extensions.end())
		return;
	const Value ids = lod->second.Get("ids"); /* a copy: the extension goes below */
	for (size_t i = 0; ids.IsArray() && i < ids.ArrayLen(); i++) {
		int id = ids.Get(int(i)).IsInt() ? ids.Get(int(i)).Get<int>() : -1;
		if (id >= 0 && size_t(id) < m.nodes.size() && id != node) {
			m.nodes[size_t(id)].mesh = -1;
			m.nodes[size_t(id)].skin = -1;
		}
	}
	n.extensions.erase(lod);
	std::string pointer = "/nodes/" + std::to_string(node) + "/extras";
	json e = current_extras(doc, pointer, n.extras);
	if (e.is_object() && e.contains("MSFT_screencoverage")) {
		e.erase("MSFT_screencoverage");
		n.extras = e.empty() ? Value() : to_value(e);
		if (e.empty())
			doc.extras.erase(pointer);
		else
			doc.extras[pointer] = e;
	}
	bool used = false;
	for (const tinygltf::Node &other : m.nodes)
		used = used || other.extensions.count("MSFT_lod") > 0;
	if (!used)
		m.extensionsUsed.erase(std::remove(m.extensionsUsed.begin(), m.extensionsUsed.end(), "MSFT_lod"),
		                       m.extensionsUsed.end());

	json &orig = doc.original;
	if (!orig.is_object())
		return;
	if (orig.contains("nodes") && orig["nodes"].is_array()) {
		json &nodes = orig["nodes"];
		if (ids.IsArray())
			for (size_t i = 0; i < ids.ArrayLen(); i++) {
				int id = ids.Get(int(i)).IsInt() ? ids.Get(int(i)).Get<int>() : -1;
				if (id >= 0 && size_t(id) < nodes.size() && nodes[size_t(id)].is_object()) {
					nodes[size_t(id)].erase("mesh");
					nodes[size_t(id)].erase("skin");
				}
			}
		if (size_t(node) < nodes.size() && nodes[size_t(node)].is_object()) {
			json &o = nodes[size_t(node)];
			if (o.contains("extensions") && o["extensions"].is_object()) {
				o["extensions"].erase("MSFT_lod");
				if (o["extensions"].empty())
					o.erase("extensions");
			}
		}
	}
	if (!used && orig.contains("extensionsUsed") && orig["extensionsUsed"].is_array()) {
		json kept = json::array();
		for (const json &e2 : orig["extensionsUsed"])
			if (e2 != "MSFT_lod")
				kept.push_back(e2);
		if (kept.empty())
			orig.erase("extensionsUsed");
		else
			orig["extensionsUsed"] = kept;
	}
}

/* What a pack's levels hold goes (mlod_gltf_strip_levels): the joint
 * channels are the translation, rotation and scale channels of the nodes
 * in joint_nodes. */
void strip_levels(mlod_gltf &doc, const int *joint_nodes, int joint_count, const unsigned char *strip_mesh)
{
	Model &m = doc.model;
	std::vector<char> joint(m.nodes.size(), 0);
	for (int i = 0; joint_nodes && i < joint_count; i++)
		if (joint_nodes[i] >= 0 && size_t(joint_nodes[i]) < joint.size())
			joint[size_t(joint_nodes[i])] = 1;
	for (const std::string &e : m.extensionsUsed)
		if (!prune_safe(e))
			fail(MLOD_ERR_UNSUPPORTED, "extension %s may refer to meshes or accessors: the document is not stripped",
			     e.c_str());
	json &orig = doc.original;
	auto orig_array = [&](const char *name) -> json * {
		return orig.is_object() && orig.contains(name) && orig[name].is_array() ? &orig[name] : nullptr;
	};
	/* MSFT_lod: the level nodes stay, without mesh or skin. */
	for (size_t n = 0; n < m.nodes.size(); n++)
		if (m.nodes[n].extensions.count("MSFT_lod"))
			clear_lod(doc, int(n));
	/* Every primitive keeps its mode, material, extensions and extras; one
	 * the pack does not hold (points, lines, strips, fans: the levels are
	 * of triangle lists) keeps its data too. */
	json *meshes = orig_array("meshes");
	for (size_t i = 0; i < m.meshes.size(); i++)
		for (size_t p = 0; (!strip_mesh || strip_mesh[i]) && p < m.meshes[i].primitives.size(); p++) {
			tinygltf::Primitive &pr = m.meshes[i].primitives[p];
			if (pr.mode >= 0 && pr.mode != TINYGLTF_MODE_TRIANGLES)
				continue;
			pr.attributes.clear();
			pr.indices = -1;
			pr.targets.clear();
			if (meshes && i < meshes->size() && (*meshes)[i].is_object() && (*meshes)[i].contains("primitives") &&
			    (*meshes)[i]["primitives"].is_array() && p < (*meshes)[i]["primitives"].size() &&
			    (*meshes)[i]["primitives"][p].is_object()) {
				json &o = (*meshes)[i]["primitives"][p];
				o["attributes"] = json::object();
				o.erase("indices");
				o.erase("targets");
			}
		}
	/* Animations keep every channel but the joint ones (the MOTION
	 * chunks hold those): morph weights, other nodes' translation,
	 * rotation and scale, channels without a node (KHR_animation_pointer). */
	json *anims = orig_array("animations");
	std::vector<bool> keep(m.animations.size(), true);
	for (size_t a = 0; a < m.animations.size(); a++) {
		tinygltf::Animation &an = m.animations[a];
		json *oa = anims && a < anims->size() && (*anims)[a].is_object() ? &(*anims)[a] : nullptr;
		std::vector<tinygltf::AnimationChannel> channels;
		std::vector<int> sampler_map(an.samplers.size(), -1);
		std::vector<tinygltf::AnimationSampler> samplers;
		json ochannels = json::array(), osamplers = json::array();
		for (size_t c = 0; c < an.channels.size(); c++) {
			tinygltf::AnimationChannel ch = an.channels[c];
			bool node = ch.target_node >= 0 && size_t(ch.target_node) < m.nodes.size();
			if (ch.sampler < 0 || size_t(ch.sampler) >= an.samplers.size())
				continue;
			if (node && joint[size_t(ch.target_node)] &&
			    (ch.target_path == "translation" || ch.target_path == "rotation" || ch.target_path == "scale"))
				continue;
			/* (weights of a node left without mesh: a level node's copy) */
			if (ch.target_path == "weights" && (!node || m.nodes[size_t(ch.target_node)].mesh < 0))
				continue;
			if (sampler_map[size_t(ch.sampler)] < 0) {
				sampler_map[size_t(ch.sampler)] = int(samplers.size());
				samplers.push_back(an.samplers[size_t(ch.sampler)]);
				if (oa && oa->contains("samplers") && (*oa)["samplers"].is_array() &&
				    size_t(ch.sampler) < (*oa)["samplers"].size())
					osamplers.push_back((*oa)["samplers"][size_t(ch.sampler)]);
			}
			if (oa && oa->contains("channels") && (*oa)["channels"].is_array() && c < (*oa)["channels"].size()) {
				json oc = (*oa)["channels"][c];
				oc["sampler"] = sampler_map[size_t(ch.sampler)];
				ochannels.push_back(oc);
			}
			ch.sampler = sampler_map[size_t(ch.sampler)];
			channels.push_back(ch);
		}
		an.channels = std::move(channels);
		an.samplers = std::move(samplers);
		if (oa) {
			(*oa)["channels"] = std::move(ochannels);
			(*oa)["samplers"] = std::move(osamplers);
		}
		keep[a] = !an.channels.empty();
	}
	renumber(doc, "animations", keep);
	keep_only(m.animations, keep);
	/* The accessors, views and bytes nothing uses any more go. */
	prune(doc, false);
}

/* The JSON object as read of element i of top-level array name (nullptr
 * when there is none). */
json *orig_element(mlod_gltf &doc, const char *name, int i)
{
	json &o = doc.original;
	if (i < 0 || !o.is_object() || !o.contains(name) || !o[name].is_array() || size_t(i) >= o[name].size() ||
	    !o[name][size_t(i)].is_object())
		return nullptr;
	return &o[name][size_t(i)];
}

/* Removes key from an object's extras (the whole extras when it empties),
 * but for member `keep` of an object extras[key] (none when empty). */
void remove_extra(mlod_gltf &doc, mlod_gltf_kind kind, int index, const std::string &key, const std::string &keep)
{
	std::string pointer;
	Value *value = extras_slot(doc, kind, index, &pointer);
	json e = current_extras(doc, pointer, *value);
	if (!e.is_object() || !e.contains(key))
		return;
	json &v = e[key];
	if (!keep.empty() && v.is_object() && v.contains(keep)) {
		if (v.size() == 1)
			return;
		json kept = json::object();
		kept[keep] = v[keep];
		v = std::move(kept);
	} else {
		e.erase(key);
	}
	*value = e.empty() ? Value() : to_value(e);
	if (e.empty())
		doc.extras.erase(pointer);
	else
		doc.extras[pointer] = e;
}

/* Drops nodes from `nodes` on, skins from `skins` on, meshes from `meshes`
 * on, after checking that nothing kept refers to them. */
void drop_tail(mlod_gltf &doc, int nodes, int skins, int meshes)
{
	Model &m = doc.model;
	nodes = std::max(0, std::min(nodes, int(m.nodes.size())));
	skins = std::max(0, std::min(skins, int(m.skins.size())));
	meshes = std::max(0, std::min(meshes, int(m.meshes.size())));
	auto gone = [](int i, int from) { return i >= from; };
	for (int n = 0; n < nodes; n++) {
		const tinygltf::Node &nd = m.nodes[size_t(n)];
		if (gone(nd.mesh, meshes) || gone(nd.skin, skins))
			fail(MLOD_ERR_UNSUPPORTED, "node %d uses a mesh or skin that would go", n);
		for (int c : nd.children)
			if (gone(c, nodes))
				fail(MLOD_ERR_UNSUPPORTED, "node %d has a child that would go", n);
		if (nd.extensions.count("MSFT_lod"))
			fail(MLOD_ERR_UNSUPPORTED, "node %d keeps MSFT_lod", n);
	}
	for (int k = 0; k < skins; k++) {
		const tinygltf::Skin &sk = m.skins[size_t(k)];
		if (gone(sk.skeleton, nodes))
			fail(MLOD_ERR_UNSUPPORTED, "skin %d's skeleton would go", k);
		for (int j : sk.joints)
			if (gone(j, nodes))
				fail(MLOD_ERR_UNSUPPORTED, "skin %d has a joint that would go", k);
	}
	for (const tinygltf::Scene &sc : m.scenes)
		for (int n : sc.nodes)
			if (gone(n, nodes))
				fail(MLOD_ERR_UNSUPPORTED, "a scene lists a node that would go");
	for (const tinygltf::Animation &a : m.animations)
		for (const tinygltf::AnimationChannel &c : a.channels)
			if (gone(c.target_node, nodes))
				fail(MLOD_ERR_UNSUPPORTED, "animation \"%s\" targets a node that would go", a.name.c_str());
	auto tail = [](size_t size, int from) {
		std::vector<bool> keep(size, true);
		for (size_t i = size_t(from); i < size; i++)
			keep[i] = false;
		return keep;
	};
	std::vector<bool> keep = tail(m.nodes.size(), nodes);
	renumber(doc, "nodes", keep);
	keep_only(m.nodes, keep);
	keep = tail(m.skins.size(), skins);
	renumber(doc, "skins", keep);
	keep_only(m.skins, keep);
	keep = tail(m.meshes.size(), meshes);
	renumber(doc, "meshes", keep);
	keep_only(m.meshes, keep);
	prune(doc, false);
}

/* A node's rest TRS parts that hold the default (identity) values. */
bool trs_default(const mlod_trs &t, int part)
{
	if (part == 0)
		return t.t.x == 0.0f && t.t.y == 0.0f && t.t.z == 0.0f;
	if (part == 1)
		return t.r.x == 0.0f && t.r.y == 0.0f && t.r.z == 0.0f && t.r.w == 1.0f;
	return t.s.x == 1.0f && t.s.y == 1.0f && t.s.z == 1.0f;
}

/* The double a node's number is for f32 value f: f itself (mode 0), the
 * shortest decimal that reads as f (mode 1), or f to 15 significant digits
 * (mode 2, as some exporters write). */
double trs_number(float f, int mode)
{
	if (mode == 0 || !std::isfinite(f))
		return f;
	char buf[64];
	if (mode == 2) {
		snprintf(buf, sizeof buf, "%.15g", double(f));
		return strtod(buf, nullptr);
	}
	for (int p = 1; p <= 9; p++) {
		snprintf(buf, sizeof buf, "%.*g", p, double(f));
		double d = strtod(buf, nullptr);
		if (float(d) == f)
			return d;
	}
	return f;
}

void trs_values(const mlod_trs &t, int part, int mode, std::vector<double> &v)
{
	if (part == 0)
		v = {trs_number(t.t.x, mode), trs_number(t.t.y, mode), trs_number(t.t.z, mode)};
	else if (part == 1)
		v = {trs_number(t.r.x, mode), trs_number(t.r.y, mode), trs_number(t.r.z, mode), trs_number(t.r.w, mode)};
	else
		v = {trs_number(t.s.x, mode), trs_number(t.s.y, mode), trs_number(t.s.z, mode)};
}

const char *const trs_keys[3] = {"translation", "rotation", "scale"};

std::vector<double> &trs_member(tinygltf::Node &n, int part)
{
	return part == 0 ? n.translation : part == 1 ? n.rotation : n.scale;
}

/* Drops (with apply; else only counts) the translation, rotation and
 * scale of node `node` that are exactly trs_values of rest in mode and
 * not the default; returns them as bits 1, 2, 4. A node with a matrix
 * keeps it. */
int drop_node_trs(mlod_gltf &doc, int node, const mlod_trs &rest, int mode, bool apply)
{
	Model &m = doc.model;
	if (node < 0 || size_t(node) >= m.nodes.size())
		fail(MLOD_ERR_INVALID_ARG, "node %d does not exist", node);
	tinygltf::Node &n = m.nodes[size_t(node)];
	if (!n.matrix.empty())
		return 0;
	int dropped = 0;
	for (int part = 0; part < 3; part++) {
		std::vector<double> &have = trs_member(n, part), want;
		trs_values(rest, part, mode, want);
		if (have != want || trs_default(rest, part))
			continue;
		dropped |= 1 << part;
		if (!apply)
			continue;
		have.clear();
		if (json *o = orig_element(doc, "nodes", node))
			o->erase(trs_keys[part]);
	}
	return dropped;
}

/* Gives node `node` (without a matrix) each of rest's translation,
 * rotation and scale it lacks that is not the default. */
void fill_node_trs(mlod_gltf &doc, int node, const mlod_trs &rest, int mode)
{
	Model &m = doc.model;
	if (node < 0 || size_t(node) >= m.nodes.size())
		fail(MLOD_ERR_INVALID_ARG, "node %d does not exist", node);
	tinygltf::Node &n = m.nodes[size_t(node)];
	if (!n.matrix.empty())
		return;
	for (int part = 0; part < 3; part++) {
		std::vector<double> &have = trs_member(n, part);
		if (!have.empty() || trs_default(rest, part))
			continue;
		trs_values(rest, part, mode, have);
		if (json *o = orig_element(doc, "nodes", node))
			(*o)[trs_keys[part]] = have;
	}
}

/* Drops animation a. */
void drop_animation(mlod_gltf &doc, int a)
{
	Model &m = doc.model;
	if (a < 0 || size_t(a) >= m.animations.size())
		fail(MLOD_ERR_INVALID_ARG, "animation %d does not exist", a);
	if (doc.keep_indices && size_t(a) + 1 != m.animations.size())
		fail(MLOD_ERR_UNSUPPORTED, "animation %d is not the last: the animations after it would be renumbered", a);
	std::vector<bool> keep(m.animations.size(), true);
	keep[size_t(a)] = false;
	renumber(doc, "animations", keep);
	keep_only(m.animations, keep);
	prune(doc, false);
}

/* Drops skin k's inverse bind matrices (their bytes go). */
void drop_inverse_binds(mlod_gltf &doc, int k)
{
	Model &m = doc.model;
	if (k < 0 || size_t(k) >= m.skins.size())
		fail(MLOD_ERR_INVALID_ARG, "skin %d does not exist", k);
	m.skins[size_t(k)].inverseBindMatrices = -1;
	if (json *o = orig_element(doc, "skins", k))
		o->erase("inverseBindMatrices");
	prune(doc, false);
}

/* Gives skin k the inverse bind matrices (a new accessor). */
void set_inverse_binds(mlod_gltf &doc, int k, const mlod_mat4 *ibm, int count)
{
	Model &m = doc.model;
	if (k < 0 || size_t(k) >= m.skins.size())
		fail(MLOD_ERR_INVALID_ARG, "skin %d does not exist", k);
	if (count != int(m.skins[size_t(k)].joints.size()))
		fail(MLOD_ERR_INVALID_ARG, "skin %d has %zu joints, not %d", k, m.skins[size_t(k)].joints.size(), count);
	std::vector<float> v(16 * size_t(count));
	for (int j = 0; j < count; j++)
		memcpy(&v[16 * size_t(j)], ibm[j].m, sizeof(float[16]));
	check_finite(v.data(), v.size(), "inverse bind matrices");
	int a = append_floats(m, v.data(), size_t(count), 16, 0);
	m.skins[size_t(k)].inverseBindMatrices = a;
	if (json *o = orig_element(doc, "skins", k))
		(*o)["inverseBindMatrices"] = a;
}

/* Checks the arguments common to the calls that take a document. */
void need(bool ok, const char *what)
{
	if (!ok)
		fail(MLOD_ERR_INVALID_ARG, "%s", what);
}

} /* namespace */

/* ------------------------------------------------------------------ */
/* Public API                                                          */
/* ------------------------------------------------------------------ */

mlod_result mlod_gltf_read(const void *data, size_t size, const char *base_dir, mlod_gltf **out, mlod_error *err)
{
	return guard(err, [&] {
		need(out != nullptr, "mlod_gltf_read: out is NULL");
		*out = nullptr;
		need(data != nullptr || size == 0, "mlod_gltf_read: data is NULL");
		std::unique_ptr<mlod_gltf> doc(new mlod_gltf);
		read_document(*doc, static_cast<const unsigned char *>(data), size, base_dir);
		*out = doc.release();
	});
}

mlod_result mlod_gltf_read_doc(const void *data, size_t size, mlod_gltf **out, mlod_error *err)
{
	return guard(err, [&] {
		need(out != nullptr, "mlod_gltf_read_doc: out is NULL");
		*out = nullptr;
		need(data != nullptr || size == 0, "mlod_gltf_read_doc: data is NULL");
		const unsigned char *d = static_cast<const unsigned char *>(data);
		if (size < 4 || le32(d) != glb_magic)
			fail(MLOD_ERR_PARSE, "not a glb");
		std::string text = glb_json(d, size);
		json j;
		try {
			j = parse_json(text.data(), text.size());
		} catch (const json::exception &) {
			fail(MLOD_ERR_PARSE, "the glb's JSON chunk is not JSON");
		}
		/* The BIN chunk, when there is one (glb_json checked its length). */
		uint32_t length = le32(d + 8);
		size_t at = 20 + size_t(le32(d + 12));
		std::string bin;
		if (at + 8 <= length && le32(d + at + 4) == chunk_bin)
			bin.assign(reinterpret_cast<const char *>(d) + at, 8 + size_t(le32(d + at)));
		/* Emptied buffers (byteLength 0, whatever else they hold) go and the
		 * views' buffer numbers follow; the BIN chunk goes with buffer 0. */
		if (j.is_object() && j.contains("buffers") && j["buffers"].is_array()) {
			json &buffers = j["buffers"];
			std::vector<int> map(buffers.size(), -1);
			json kept = json::array();
			for (size_t i = 0; i < buffers.size(); i++) {
				const json &b = buffers[i];
				bool empty = b.is_object() && b.contains("byteLength") && b["byteLength"].is_number() &&
				             b["byteLength"] == 0;
				if (empty) {
					if (i == 0)
						bin.clear();
					continue;
				}
				map[i] = int(kept.size());
				kept.push_back(b);
			}
			if (j.contains("bufferViews") && j["bufferViews"].is_array())
				for (size_t v = 0; v < j["bufferViews"].size(); v++) {
					json &view = j["bufferViews"][v];
					if (!view.is_object() || !view.contains("buffer") || !view["buffer"].is_number_unsigned() ||
					    view["buffer"].get<size_t>() >= map.size())
						continue; /* (the reader names it) */
					int to = map[view["buffer"].get<size_t>()];
					if (to < 0)
						fail(MLOD_ERR_PARSE, "bufferViews[%zu]: its buffer has no bytes", v);
					view["buffer"] = to;
				}
			if (kept.empty())
				j.erase("buffers");
			else
				buffers = std::move(kept);
		}
		std::string js = j.dump();
		js.append((4 - js.size() % 4) % 4, ' ');
		std::string glb;
		uint64_t total = 20 + uint64_t(js.size()) + bin.size();
		if (total > UINT32_MAX)
			fail(MLOD_ERR_LIMIT, "the glb would be larger than 4 GiB");
		for (uint32_t v : {glb_magic, uint32_t(2), uint32_t(total), uint32_t(js.size()), chunk_json})
			for (int k = 0; k < 4; k++)
				glb += char(v >> (8 * k) & 0xFF);
		glb += js;
		glb += bin;
		std::unique_ptr<mlod_gltf> doc(new mlod_gltf);
		read_document(*doc, reinterpret_cast<const unsigned char *>(glb.data()), glb.size(), nullptr);
		*out = doc.release();
	});
}

void mlod_gltf_free(mlod_gltf *doc)
{
	delete doc;
}

mlod_result mlod_gltf_write(const mlod_gltf *doc, int binary, void **data, size_t *size, mlod_error *err)
{
	return guard(err, [&] {
		need(doc && data && size, "mlod_gltf_write: doc, data and size must not be NULL");
		*data = nullptr;
		*size = 0;
		std::string bytes = serialize(*doc, binary != 0);
		void *p = malloc(bytes.size());
		if (!p)
			throw std::bad_alloc();
		memcpy(p, bytes.data(), bytes.size());
		*data = p;
		*size = bytes.size();
	});
}

mlod_result mlod_gltf_to_character(const mlod_gltf *doc, mlod_character *out, mlod_error *err)
{
	return guard(err, [&] {
		need(doc && out, "mlod_gltf_to_character: doc and out must not be NULL");
		memset(out, 0, sizeof *out);
		mlod_character c;
		memset(&c, 0, sizeof c);
		try {
			CharacterReader(*doc, c).read();
		} catch (...) {
			mlod_character_free(&c);
			throw;
		}
		*out = c;
	});
}

mlod_result mlod_gltf_from_character(const mlod_character *c, mlod_gltf **out, mlod_error *err)
{
	return guard(err, [&] {
		need(c && out, "mlod_gltf_from_character: c and out must not be NULL");
		*out = nullptr;
		mlod_error verr;
		if (mlod_character_validate(c, &verr) != MLOD_OK)
			fail(MLOD_ERR_INVALID_ARG, "invalid character: %s", verr.message);
		std::unique_ptr<mlod_gltf> doc(new mlod_gltf);
		build_document(doc->model, *c);
		*out = doc.release();
	});
}

int mlod_gltf_count(const mlod_gltf *doc, mlod_gltf_kind kind)
{
	if (!doc)
		return 0;
	const Model &m = doc->model;
	switch (kind) {
	case MLOD_GLTF_NODE: return int(m.nodes.size());
	case MLOD_GLTF_SKIN: return int(m.skins.size());
	case MLOD_GLTF_SCENE: return int(m.scenes.size());
	case MLOD_GLTF_MESH: return int(m.meshes.size());
	case MLOD_GLTF_ANIMATION: return int(m.animations.size());
	case MLOD_GLTF_ASSET: return 1;
	}
	return 0;
}

mlod_result mlod_gltf_set_extra(mlod_gltf *doc, mlod_gltf_kind kind, int index, const char *key, const char *text,
                                mlod_error *err)
{
	return guard(err, [&] {
		need(doc && key && text, "mlod_gltf_set_extra: doc, key and json must not be NULL");
		need(utf8(key) == key, "mlod_gltf_set_extra: the key is not UTF-8");
		json v;
		try {
			v = parse_json(text, strlen(text));
		} catch (const json::exception &e) {
			fail(MLOD_ERR_INVALID_ARG, "extras \"%s\": not JSON: %s", key, printable(e.what()).c_str());
		} catch (const Failure &f) {
			fail(MLOD_ERR_INVALID_ARG, "extras \"%s\": %s", key, f.message.c_str());
		}
		set_extra(*doc, kind, index, key, v);
	});
}

mlod_result mlod_gltf_get_extra(const mlod_gltf *doc, mlod_gltf_kind kind, int index, const char *key, char **text,
                                mlod_error *err)
{
	return guard(err, [&] {
		need(doc && key && text, "mlod_gltf_get_extra: doc, key and json must not be NULL");
		*text = nullptr;
		std::string pointer;
		const Value *value = extras_slot(*doc, kind, index, &pointer);
		json e = current_extras(*doc, pointer, *value);
		if (e.is_object() && e.contains(key))
			*text = c_string(e[key].dump());
	});
}

mlod_result mlod_gltf_add_mesh(mlod_gltf *doc, const mlod_mesh *m, int *out_index, mlod_error *err)
{
	return guard(err, [&] {
		need(doc && m, "mlod_gltf_add_mesh: doc and mesh must not be NULL");
		int index = add_mesh(doc->model, *m);
		if (out_index)
			*out_index = index;
	});
}

mlod_result mlod_gltf_add_mesh_reskinned(mlod_gltf *doc, int mesh, const mlod_mesh *m, int *out_index,
                                         mlod_error *err)
{
	return guard(err, [&] {
		need(doc && m, "mlod_gltf_add_mesh_reskinned: doc and mesh must not be NULL");
		int index = add_mesh_reskinned(*doc, mesh, *m);
		if (out_index)
			*out_index = index;
	});
}

mlod_result mlod_gltf_add_node(mlod_gltf *doc, const char *name, int parent, int mesh, int skin, const mlod_trs *trs,
                               int *out_index, mlod_error *err)
{
	return guard(err, [&] {
		need(doc != nullptr, "mlod_gltf_add_node: doc is NULL");
		Model &m = doc->model;
		if (parent < MLOD_GLTF_DETACHED || parent >= int(m.nodes.size()))
			fail(MLOD_ERR_INVALID_ARG, "parent node %d does not exist", parent);
		if (mesh < -1 || mesh >= int(m.meshes.size()))
			fail(MLOD_ERR_INVALID_ARG, "mesh %d does not exist", mesh);
		if (skin < -1 || skin >= int(m.skins.size()))
			fail(MLOD_ERR_INVALID_ARG, "skin %d does not exist", skin);
		tinygltf::Node node;
		node.name = utf8(name);
		node.mesh = mesh;
		node.skin = skin;
		if (trs)
			set_trs(node, *trs);
		int index = int(m.nodes.size());
		if (parent >= 0)
			m.nodes[size_t(parent)].children.push_back(index);
		else if (parent == -1)
			default_scene(m).nodes.push_back(index);
		m.nodes.push_back(std::move(node));
		if (out_index)
			*out_index = index;
	});
}

mlod_result mlod_gltf_add_skin(mlod_gltf *doc, const mlod_skeleton *s, const mlod_skin *skin, int *out_index,
                               mlod_error *err)
{
	return guard(err, [&] {
		need(doc && s && skin, "mlod_gltf_add_skin: doc, skeleton and skin must not be NULL");
		int index = add_skin(doc->model, *skin, joint_nodes(s));
		if (out_index)
			*out_index = index;
	});
}

mlod_result mlod_gltf_add_animation(mlod_gltf *doc, const mlod_skeleton *s, const mlod_clip *clip, int *out_index,
                                    mlod_error *err)
{
	return guard(err, [&] {
		need(doc && s && clip, "mlod_gltf_add_animation: doc, skeleton and clip must not be NULL");
		int index = add_animation(doc->model, *clip, joint_nodes(s));
		if (out_index)
			*out_index = index;
	});
}

mlod_result mlod_gltf_set_lod(mlod_gltf *doc, int node, const int *lod_nodes, int lod_count, const float *coverage,
                              mlod_error *err)
{
	return guard(err, [&] {
		need(doc && lod_nodes && coverage && lod_count > 0,
		     "mlod_gltf_set_lod: doc, lod_nodes and coverage must not be NULL, lod_count must be positive");
		Model &m = doc->model;
		if (node < 0 || node >= int(m.nodes.size()))
			fail(MLOD_ERR_INVALID_ARG, "node %d does not exist", node);
		Value::Array ids;
		for (int i = 0; i < lod_count; i++) {
			if (lod_nodes[i] < 0 || lod_nodes[i] >= int(m.nodes.size()) || lod_nodes[i] == node)
				fail(MLOD_ERR_INVALID_ARG, "LOD node %d of node %d does not exist or is the node itself", lod_nodes[i], node);
			ids.push_back(Value(lod_nodes[i]));
		}
		json cov = json::array();
		for (int i = 0; i <= lod_count; i++) {
			if (!std::isfinite(coverage[i]) || coverage[i] < 0 || (i > 0 && coverage[i] > coverage[i - 1]))
				fail(MLOD_ERR_INVALID_ARG, "screen coverage %d (%g) is negative or larger than the one before", i,
				     double(coverage[i]));
			cov.push_back(tidy(coverage[i]));
		}
		set_extra(*doc, MLOD_GLTF_NODE, node, "MSFT_screencoverage", cov);
		m.nodes[size_t(node)].extensions["MSFT_lod"] = Value(Value::Object{{"ids", Value(ids)}});
		if (std::find(m.extensionsUsed.begin(), m.extensionsUsed.end(), "MSFT_lod") == m.extensionsUsed.end())
			m.extensionsUsed.push_back("MSFT_lod");
	});
}

mlod_result mlod_gltf_copy(const mlod_gltf *doc, mlod_gltf **out, mlod_error *err)
{
	return guard(err, [&] {
		need(doc && out, "mlod_gltf_copy: doc and out must not be NULL");
		*out = nullptr;
		*out = new mlod_gltf(*doc);
	});
}

mlod_result mlod_gltf_add_mesh_like(mlod_gltf *doc, int like, const mlod_mesh *m, int *out_index, mlod_error *err)
{
	return guard(err, [&] {
		need(doc && m, "mlod_gltf_add_mesh_like: doc and mesh must not be NULL");
		int index = add_mesh_like(*doc, like, *m);
		if (out_index)
			*out_index = index;
	});
}

mlod_result mlod_gltf_set_node_mesh(mlod_gltf *doc, int node, int mesh, int skin, mlod_error *err)
{
	return guard(err, [&] {
		need(doc != nullptr, "mlod_gltf_set_node_mesh: doc is NULL");
		Model &m = doc->model;
		if (node < 0 || node >= int(m.nodes.size()))
			fail(MLOD_ERR_INVALID_ARG, "node %d does not exist", node);
		if (mesh < -1 || mesh >= int(m.meshes.size()))
			fail(MLOD_ERR_INVALID_ARG, "mesh %d does not exist", mesh);
		if (skin < -1 || skin >= int(m.skins.size()))
			fail(MLOD_ERR_INVALID_ARG, "skin %d does not exist", skin);
		tinygltf::Node &n = m.nodes[size_t(node)];
		n.mesh = mesh;
		n.skin = skin;
		/* The JSON as read follows, so that serialising neither brings back
		 * what the node no longer has nor drops what it gained. */
		json &orig = doc->original;
		if (orig.is_object() && orig.contains("nodes") && orig["nodes"].is_array() && size_t(node) < orig["nodes"].size() &&
		    orig["nodes"][size_t(node)].is_object()) {
			json &o = orig["nodes"][size_t(node)];
			for (auto kv : {std::make_pair("mesh", mesh), std::make_pair("skin", skin)}) {
				if (kv.second < 0)
					o.erase(kv.first);
				else
					o[kv.first] = kv.second;
			}
		}
	});
}

mlod_result mlod_gltf_get_node_trs(const mlod_gltf *doc, int node, mlod_trs *out, mlod_error *err)
{
	return guard(err, [&] {
		need(doc && out, "mlod_gltf_get_node_trs: doc and out must not be NULL");
		const Model &m = doc->model;
		if (node < 0 || node >= int(m.nodes.size()))
			fail(MLOD_ERR_INVALID_ARG, "node %d does not exist", node);
		const tinygltf::Node &n = m.nodes[size_t(node)];
		if (n.matrix.size() == 16) {
			mlod_mat4 mat = node_matrix(n);
			if (mlod_mat4_to_trs(&mat, out, 1e-5f) != 0)
				fail(MLOD_ERR_UNSUPPORTED, "node %d: its matrix is not a translation, rotation and scale", node);
		} else {
			*out = node_trs(n);
		}
	});
}

mlod_result mlod_gltf_strip_levels(mlod_gltf *doc, const int *joint_nodes, int joint_count,
                                   const unsigned char *strip_mesh, mlod_error *err)
{
	return guard(err, [&] {
		need(doc != nullptr && (joint_nodes || joint_count == 0), "mlod_gltf_strip_levels: doc is NULL");
		strip_levels(*doc, joint_nodes, joint_count, strip_mesh);
	});
}

void mlod_gltf_keep_indices(mlod_gltf *doc, int on)
{
	if (doc)
		doc->keep_indices = on != 0;
}

int mlod_gltf_skin_has_inverse_binds(const mlod_gltf *doc, int skin)
{
	return doc && skin >= 0 && size_t(skin) < doc->model.skins.size() &&
	       doc->model.skins[size_t(skin)].inverseBindMatrices >= 0;
}

mlod_result mlod_gltf_remove_extra(mlod_gltf *doc, mlod_gltf_kind kind, int index, const char *key,
                                   const char *keep, mlod_error *err)
{
	return guard(err, [&] {
		need(doc && key, "mlod_gltf_remove_extra: doc and key must not be NULL");
		remove_extra(*doc, kind, index, key, keep ? keep : "");
	});
}

mlod_result mlod_gltf_drop_tail(mlod_gltf *doc, int nodes, int skins, int meshes, mlod_error *err)
{
	return guard(err, [&] {
		need(doc != nullptr, "mlod_gltf_drop_tail: doc is NULL");
		drop_tail(*doc, nodes, skins, meshes);
	});
}

mlod_result mlod_gltf_drop_node_trs(mlod_gltf *doc, int node, const mlod_trs *rest, int mode, int apply,
                                    int *dropped, mlod_error *err)
{
	return guard(err, [&] {
		need(doc && rest, "mlod_gltf_drop_node_trs: doc and rest must not be NULL");
		int d = drop_node_trs(*doc, node, *rest, mode, apply != 0);
		if (dropped)
			*dropped = d;
	});
}

mlod_result mlod_gltf_fill_node_trs(mlod_gltf *doc, int node, const mlod_trs *rest, int mode, mlod_error *err)
{
	return guard(err, [&] {
		need(doc && rest, "mlod_gltf_fill_node_trs: doc and rest must not be NULL");
		fill_node_trs(*doc, node, *rest, mode);
	});
}

mlod_result mlod_gltf_drop_animation(mlod_gltf *doc, int animation, mlod_error *err)
{
	return guard(err, [&] {
		need(doc != nullptr, "mlod_gltf_drop_animation: doc is NULL");
		drop_animation(*doc, animation);
	});
}

mlod_result mlod_gltf_drop_inverse_binds(mlod_gltf *doc, int skin, mlod_error *err)
{
	return guard(err, [&] {
		need(doc != nullptr, "mlod_gltf_drop_inverse_binds: doc is NULL");
		drop_inverse_binds(*doc, skin);
	});
}

mlod_result mlod_gltf_set_inverse_binds(mlod_gltf *doc, int skin, const mlod_mat4 *ibm, int count, mlod_error *err)
{
	return guard(err, [&] {
		need(doc && ibm, "mlod_gltf_set_inverse_binds: doc and ibm must not be NULL");
		set_inverse_binds(*doc, skin, ibm, count);
	});
}

mlod_result mlod_gltf_node_refs(const mlod_gltf *doc, int node, int *mesh, int *skin, mlod_error *err)
{
	return guard(err, [&] {
		need(doc && mesh && skin, "mlod_gltf_node_refs: doc, mesh and skin must not be NULL");
		const Model &m = doc->model;
		if (node < 0 || node >= int(m.nodes.size()))
			fail(MLOD_ERR_INVALID_ARG, "node %d does not exist", node);
		*mesh = m.nodes[size_t(node)].mesh;
		*skin = m.nodes[size_t(node)].skin;
	});
}

mlod_result mlod_gltf_node_lod(const mlod_gltf *doc, int node, int *ids, int max, int *count, mlod_error *err)
{
	return guard(err, [&] {
		need(doc && count && (ids || max == 0), "mlod_gltf_node_lod: doc, ids and count must not be NULL");
		const Model &m = doc->model;
		if (node < 0 || node >= int(m.nodes.size()))
			fail(MLOD_ERR_INVALID_ARG, "node %d does not exist", node);
		*count = 0;
		const tinygltf::Node &n = m.nodes[size_t(node)];
		auto it = n.extensions.find("MSFT_lod");
		if (it == n.extensions.end() || !it->second.IsObject() || !it->second.Has("ids"))
			return;
		const tinygltf::Value &v = it->second.Get("ids");
		if (!v.IsArray())
			fail(MLOD_ERR_PARSE, "node %d: MSFT_lod.ids is not an array", node);
		for (size_t i = 0; i < v.ArrayLen(); i++) {
			const tinygltf::Value &e = v.Get(int(i));
			if (!e.IsNumber() && !e.IsInt())
				fail(MLOD_ERR_PARSE, "node %d: MSFT_lod.ids[%zu] is not a node", node, i);
			int id = e.IsInt() ? e.Get<int>() : int(e.GetNumberAsDouble());
			if (id < 0 || id >= int(m.nodes.size()))
				fail(MLOD_ERR_PARSE, "node %d: MSFT_lod.ids[%zu] = %d is not a node", node, i, id);
			if (*count < max)
				ids[*count] = id;
			++*count;
		}
	});
}

mlod_result mlod_gltf_primitive_attributes(const mlod_gltf *doc, int mesh, int primitive, int *mode, char ***names,
                                           int *count, mlod_error *err)
{
	return guard(err, [&] {
		need(doc && mode && names && count, "mlod_gltf_primitive_attributes: doc, mode, names and count must not be NULL");
		*names = nullptr;
		*count = 0;
		const Model &m = doc->model;
		if (mesh < 0 || mesh >= int(m.meshes.size()) || primitive < 0 ||
		    primitive >= int(m.meshes[size_t(mesh)].primitives.size()))
			fail(MLOD_ERR_INVALID_ARG, "mesh %d primitive %d does not exist", mesh, primitive);
		const tinygltf::Primitive &p = m.meshes[size_t(mesh)].primitives[size_t(primitive)];
		*mode = p.mode < 0 ? TINYGLTF_MODE_TRIANGLES : p.mode;
		size_t bytes = (p.attributes.size() + 1) * sizeof(char *);
		for (const auto &kv : p.attributes)
			bytes += kv.first.size() + 1;
		char **out = static_cast<char **>(malloc(bytes));
		if (!out)
			throw std::bad_alloc();
		char *text = reinterpret_cast<char *>(out + p.attributes.size() + 1);
		int k = 0;
		for (const auto &kv : p.attributes) { /* std::map: sorted by name */
			out[k++] = text;
			memcpy(text, kv.first.c_str(), kv.first.size() + 1);
			text += kv.first.size() + 1;
		}
		out[k] = nullptr;
		*names = out;
		*count = k;
	});
}

mlod_result mlod_gltf_prune(mlod_gltf *doc, mlod_error *err)
{
	return guard(err, [&] {
		need(doc != nullptr, "mlod_gltf_prune: doc is NULL");
		prune(*doc);
	});
}

mlod_result mlod_gltf_copy_morph_animation(mlod_gltf *doc, int from, int to, int *added, mlod_error *err)
{
	return guard(err, [&] {
		need(doc != nullptr, "mlod_gltf_copy_morph_animation: doc is NULL");
		int n = copy_morph_animation(doc->model, from, to);
		if (added)
			*added = n;
	});
}

mlod_result mlod_gltf_weight_tracks(const mlod_gltf *doc, int animation, mlod_weight_track **tracks, int *count,
                                    mlod_error *err)
{
	if (tracks)
		*tracks = nullptr;
	if (count)
		*count = 0;
	std::vector<mlod_weight_track> out;
	mlod_result r = guard(err, [&] {
		need(doc && tracks && count, "mlod_gltf_weight_tracks: doc, tracks and count must not be NULL");
		const Model &m = doc->model;
		if (animation < 0 || size_t(animation) >= m.animations.size())
			fail(MLOD_ERR_INVALID_ARG, "animation %d does not exist", animation);
		const tinygltf::Animation &a = m.animations[size_t(animation)];
		for (const tinygltf::AnimationChannel &ch : a.channels) {
			if (ch.target_path != "weights")
				continue;
			std::string who = "animation " + std::to_string(animation) + " sampler " + std::to_string(ch.sampler);
			if (ch.sampler < 0 || size_t(ch.sampler) >= a.samplers.size())
				fail(MLOD_ERR_PARSE, "%s does not exist", who.c_str());
			const tinygltf::AnimationSampler &s = a.samplers[size_t(ch.sampler)];
			mlod_weight_track t;
			memset(&t, 0, sizeof t);
			t.node = ch.target_node;
			t.interp = s.interpolation == "STEP"          ? MLOD_INTERP_STEP
			           : s.interpolation == "CUBICSPLINE" ? MLOD_INTERP_CUBICSPLINE
			                                              : MLOD_INTERP_LINEAR;
			std::vector<float> times = read_floats(m, s.input, who + " input", TINYGLTF_TYPE_SCALAR);
			std::vector<float> values = read_floats(m, s.output, who + " output", TINYGLTF_TYPE_SCALAR);
			size_t per = t.interp == MLOD_INTERP_CUBICSPLINE ? 3 : 1;
			if (times.empty() || times.size() > size_t(INT_MAX) || values.size() % (per * times.size()) != 0 ||
			    values.empty())
				fail(MLOD_ERR_PARSE, "%s: %zu weights for %zu keys", who.c_str(), values.size(), times.size());
			for (size_t k = 1; k < times.size(); k++)
				if (!(times[k] > times[k - 1]))
					fail(MLOD_ERR_PARSE, "%s: key times do not increase", who.c_str());
			check_finite(times.data(), times.size(), "key times");
			check_finite(values.data(), values.size(), "weights");
			t.targets = int(values.size() / (per * times.size()));
			t.key_count = int(times.size());
			out.push_back(t);
			out.back().times = c_copy(times);
			out.back().values = c_copy(values);
		}
	});
	if (r != MLOD_OK) {
		for (mlod_weight_track &t : out)
			free(t.times), free(t.values);
		return r;
	}
	if (!out.empty()) {
		*tracks = static_cast<mlod_weight_track *>(malloc(sizeof(mlod_weight_track) * out.size()));
		if (!*tracks) {
			for (mlod_weight_track &t : out)
				free(t.times), free(t.values);
			return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
		}
		memcpy(*tracks, out.data(), sizeof(mlod_weight_track) * out.size());
		*count = int(out.size());
	}
	return MLOD_OK;
}

void mlod_weight_tracks_free(mlod_weight_track *tracks, int count)
{
	for (int i = 0; tracks && i < count; i++)
		free(tracks[i].times), free(tracks[i].values);
	free(tracks);
}

mlod_result mlod_gltf_add_weight_tracks(mlod_gltf *doc, int animation, const mlod_weight_track *tracks, int count,
                                        mlod_error *err)
{
	return guard(err, [&] {
		need(doc && (tracks || count == 0), "mlod_gltf_add_weight_tracks: doc and tracks must not be NULL");
		Model &m = doc->model;
		if (animation < 0 || size_t(animation) >= m.animations.size())
			fail(MLOD_ERR_INVALID_ARG, "animation %d does not exist", animation);
		static const char *const interps[] = {"LINEAR", "STEP", "CUBICSPLINE"};
		std::map<std::vector<float>, int> inputs;
		for (int i = 0; i < count; i++) {
			const mlod_weight_track &t = tracks[i];
			size_t per = t.interp == MLOD_INTERP_CUBICSPLINE ? 3 : 1, keys = size_t(t.key_count);
			if (t.node < 0 || size_t(t.node) >= m.nodes.size() || t.key_count <= 0 || t.targets <= 0 || !t.times ||
			    !t.values || unsigned(t.interp) > MLOD_INTERP_CUBICSPLINE)
				fail(MLOD_ERR_INVALID_ARG, "weight track %d: no node, no keys or a bad interpolation", i);
			std::vector<float> times(t.times, t.times + keys);
			check_finite(times.data(), keys, "key times");
			check_finite(t.values, keys * per * size_t(t.targets), "weights");
			for (size_t k = 1; k < keys; k++)
				if (!(times[k] > times[k - 1]))
					fail(MLOD_ERR_INVALID_ARG, "weight track %d: key times do not increase", i);
			auto in = inputs.find(times);
			if (in == inputs.end())
				in = inputs.emplace(times, append_floats(m, times.data(), keys, 1, 0, true)).first;
			tinygltf::AnimationSampler s;
			s.input = in->second;
			s.output = append_floats(m, t.values, keys * per * size_t(t.targets), 1, 0);
			s.interpolation = interps[t.interp];
			tinygltf::Animation &a = m.animations[size_t(animation)];
			a.samplers.push_back(s);
			tinygltf::AnimationChannel c;
			c.sampler = int(a.samplers.size() - 1);
			c.target_node = t.node;
			c.target_path = "weights";
			a.channels.push_back(c);
		}
	});
}

mlod_result mlod_gltf_append_other_primitives(mlod_gltf *doc, int from, int to, int *added, mlod_error *err)
{
	return guard(err, [&] {
		need(doc != nullptr, "mlod_gltf_append_other_primitives: doc is NULL");
		Model &m = doc->model;
		need(from >= 0 && size_t(from) < m.meshes.size() && to >= 0 && size_t(to) < m.meshes.size() && from != to,
		     "mlod_gltf_append_other_primitives: no such meshes");
		int n = 0;
		std::vector<tinygltf::Primitive> src = m.meshes[size_t(from)].primitives;
		for (size_t p = 0; p < src.size(); p++) {
			if (src[p].mode < 0 || src[p].mode == TINYGLTF_MODE_TRIANGLES || src[p].attributes.empty())
				continue;
			size_t at = m.meshes[size_t(to)].primitives.size();
			m.meshes[size_t(to)].primitives.push_back(src[p]);
			auto e = doc->extras.find("/meshes/" + std::to_string(from) + "/primitives/" + std::to_string(p) + "/extras");
			if (e != doc->extras.end()) {
				json v = e->second;
				doc->extras["/meshes/" + std::to_string(to) + "/primitives/" + std::to_string(at) + "/extras"] = v;
			}
			n++;
		}
		if (added)
			*added = n;
	});
}

mlod_result mlod_gltf_clear_lod(mlod_gltf *doc, int node, mlod_error *err)
{
	return guard(err, [&] {
		need(doc != nullptr, "mlod_gltf_clear_lod: doc is NULL");
		clear_lod(*doc, node);
	});
}

int mlod_gltf_find_animation(const mlod_gltf *doc, const char *name, int from)
{
	if (!doc || !name)
		return -1;
	const Model &m = doc->model;
	for (size_t i = size_t(from < 0 ? 0 : from); i < m.animations.size(); i++)
		if (m.animations[i].name == name)
			return int(i);
	return -1;
}

mlod_result mlod_gltf_merge_animation(mlod_gltf *doc, int into, mlod_error *err)
{
	return guard(err, [&] {
		need(doc != nullptr, "mlod_gltf_merge_animation: doc is NULL");
		Model &m = doc->model;
		if (m.animations.empty() || into < 0 || size_t(into) + 1 >= m.animations.size())
			fail(MLOD_ERR_INVALID_ARG, "animation %d is not before the last one", into);
		tinygltf::Animation from = m.animations.back();
		m.animations.pop_back();
		tinygltf::Animation &a = m.animations[size_t(into)];
		int base = int(a.samplers.size());
		for (const tinygltf::AnimationSampler &s : from.samplers)
			a.samplers.push_back(s);
		for (tinygltf::AnimationChannel c : from.channels) {
			c.sampler += base;
			a.channels.push_back(c);
		}
	});
}
