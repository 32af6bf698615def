/*
 * gltf_check.cpp: the checks of a document: the glb container, the JSON's
 * types and URIs before tinygltf reads it, every reference of the model
 * after (gltf_internal.hpp).
 */
#include <sys/stat.h>

#include "io/gltf_internal.hpp"

namespace mlod_gltf_internal {

/* ------------------------------------------------------------------ */
/* Reading: checks before tinygltf                                     */
/* ------------------------------------------------------------------ */

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
 * (materials, textures, lights), that the accessor decoder handles, or
 * that gltf_decompress.cpp removes before tinygltf reads the document
 * (meshopt and Draco compression). */
static bool extension_supported(const std::string &name)
{
	static const char *const prefixes[] = {"KHR_materials_", "KHR_texture_", "EXT_texture_", "KHR_lights_punctual",
	                                       "KHR_mesh_quantization", "MSFT_texture_dds", "EXT_meshopt_compression",
	                                       "KHR_meshopt_compression", "KHR_draco_mesh_compression"};
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

/* Whether buffer b is a meshopt fallback (extension object with
 * "fallback": true) in a document that names the extension: its data
 * only serves readers without the extension, and mlod decodes it
 * (gltf_decompress.cpp), so the file may well be absent (gltfpack -cf). */
static bool meshopt_fallback(const json &doc, const json &b)
{
	if (!b.contains("extensions") || !b["extensions"].is_object() || !doc.contains("extensionsUsed") ||
	    !doc["extensionsUsed"].is_array())
		return false;
	for (const char *name : {"EXT_meshopt_compression", "KHR_meshopt_compression"}) {
		auto e = b["extensions"].find(name);
		if (e != b["extensions"].end() && e->is_object() && e->contains("fallback") && (*e)["fallback"] == true)
			for (const json &used : doc["extensionsUsed"])
				if (used == name)
					return true;
	}
	return false;
}

/* External buffers must be readable files under base_dir; data: URIs must
 * be of a type tinygltf decodes. A meshopt fallback buffer is not
 * checked, nor are images: one that cannot be read keeps its URI. */
void check_buffer_uris(const json &doc, const char *base_dir)
{
	auto buffers = doc.find("buffers");
	if (buffers == doc.end() || !buffers->is_array())
		return;
	for (size_t i = 0; i < buffers->size(); i++) {
		const json &b = (*buffers)[i];
		if (!b.is_object() || !b.contains("uri") || !b["uri"].is_string() || meshopt_fallback(doc, b))
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
/* Document checks                                                     */
/* ------------------------------------------------------------------ */

static void check_ref(int index, size_t count, const char *fmt_owner, size_t owner, const char *what)
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

static void check_references(const Model &m, size_t bytes)
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

} /* namespace mlod_gltf_internal */
