/*
 * gltf_edit.cpp: editing a document: extras, level meshes in place,
 * pruning, dropping and restoring what a pack keeps (gltf_internal.hpp).
 */
#include "io/gltf_internal.hpp"

namespace mlod_gltf_internal {

/* ------------------------------------------------------------------ */
/* Extras                                                              */
/* ------------------------------------------------------------------ */

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

/* The node, mesh, ... index a JSON pointer ("/nodes/3/rotation") names
 * in top-level array `array` ("nodes"), or -1. */
static long pointer_index(const std::string &pointer, const char *array)
{
	std::string head = std::string("/") + array + "/";
	if (pointer.compare(0, head.size(), head) != 0)
		return -1;
	const char *digits = pointer.c_str() + head.size();
	char *end = nullptr;
	errno = 0;
	long i = isdigit((unsigned char)*digits) ? strtol(digits, &end, 10) : -1;
	return i >= 0 && errno == 0 && (*end == '/' || *end == '\0') ? i : -1;
}

/* The JSON pointers of the KHR_animation_pointer channels of m. */
static std::vector<std::string> animation_pointers(const Model &m)
{
	std::vector<std::string> pointers;
	for (const tinygltf::Animation &a : m.animations)
		for (const tinygltf::AnimationChannel &c : a.channels) {
			auto it = c.target_extensions.find("KHR_animation_pointer");
			if (it == c.target_extensions.end())
				continue;
			const Value &v = it->second;
			pointers.push_back(v.IsObject() && v.Has("pointer") && v.Get("pointer").IsString()
			                       ? v.Get("pointer").Get<std::string>()
			                       : std::string());
		}
	return pointers;
}

/* Whether the document's extension `name` refers to no mesh, accessor or
 * buffer view, so that pruning and stripping (which renumber those) leave
 * it right. By name: the families
 * that refer to materials, textures, images, samplers or lights only, or
 * to nothing (KHR_node_visibility: a boolean; EXT_materials_bump, which
 * three.js's exporter writes: a factor and a texture). By its content:
 * KHR_animation_pointer, whose channels are core animation channels (their
 * samplers' accessors are renumbered with the others), when each pointer
 * names a property of a node, material, camera or KHR_lights_punctual
 * light, whose indices hold. Not of a mesh: mlod-pack -x puts level 0 in
 * a new mesh and leaves the old one an empty shell that such a pointer
 * would still name. */
static bool prune_safe(const Model &m, const std::string &name)
{
	static const char *const prefixes[] = {"KHR_materials_", "KHR_texture_", "KHR_lights_punctual",
	                                       "KHR_mesh_quantization", "KHR_xmp", "EXT_texture_", "MSFT_lod",
	                                       "MSFT_texture_dds"};
	for (const char *p : prefixes)
		if (name.compare(0, strlen(p), p) == 0)
			return true;
	if (name == "KHR_node_visibility" || name == "EXT_materials_bump")
		return true;
	if (name != "KHR_animation_pointer")
		return false;
	for (const std::string &p : animation_pointers(m))
		if (pointer_index(p, "nodes") < 0 && pointer_index(p, "materials") < 0 && pointer_index(p, "cameras") < 0 &&
		    pointer_index(p, "extensions/KHR_lights_punctual/lights") < 0)
			return false;
	return true;
}

/* Drops the elements of array `name` that keep says go, from the JSON as
 * read and from the exact extras (later ones renumbered). Returns the
 * old -> new index map (-1: dropped). The caller drops them from the model. */
static std::vector<int> renumber(mlod_gltf &doc, const std::string &name, const std::vector<bool> &keep)
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

template <class T> static void keep_only(std::vector<T> &v, const std::vector<bool> &keep)
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

/* Flags index i in used (an index out of range or -1: none). */
static void mark_used(std::vector<bool> &used, int i)
{
	if (i >= 0 && size_t(i) < used.size())
		used[size_t(i)] = true;
}

/* The accessors the meshes, skins and animations of m use. */
static std::vector<bool> used_accessors(const Model &m)
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
static void mark_used_views(const Model &m, std::vector<bool> &used)
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

/* Trims each buffer view that only plain accessors read (no image, no
 * sparse part, no extension names it) to the bytes they read: the ranges
 * of accessors that went (a view holding every clip's keys, as
 * gltf-transform writes them, of which a pack's DOC chunk keeps one morph
 * weights channel) go, and the accessors left move down with their
 * bytes. Each range keeps its offset modulo 4, so every accessor keeps
 * its alignment; a range that overlaps another (interleaved attributes)
 * is merged with it. Views whose accessors read all their bytes are left
 * as they are. */
static void trim_views(mlod_gltf &doc)
{
	Model &m = doc.model;
	const size_t nv = m.bufferViews.size();
	std::vector<bool> fixed(nv, false);
	std::vector<bool> named(m.buffers.size(), false);
	extension_refs(doc.original, false, fixed, named);
	for (const tinygltf::Accessor &a : m.accessors)
		if (a.sparse.isSparse) {
			mark_used(fixed, a.bufferView);
			mark_used(fixed, a.sparse.indices.bufferView);
			mark_used(fixed, a.sparse.values.bufferView);
		}
	for (const tinygltf::Image &i : m.images)
		mark_used(fixed, i.bufferView);
	std::vector<std::vector<std::pair<size_t, size_t>>> ranges(nv);
	for (const tinygltf::Accessor &a : m.accessors) {
		if (a.bufferView < 0 || size_t(a.bufferView) >= nv || fixed[size_t(a.bufferView)])
			continue;
		const tinygltf::BufferView &v = m.bufferViews[size_t(a.bufferView)];
		const Layout l = layout_of(a);
		const size_t stride = v.byteStride ? v.byteStride : l.element;
		size_t end = a.byteOffset;
		if (a.count > 0) {
			/* (the reader checked that every accessor fits its view) */
			end += stride * (a.count - 1) + l.element;
		}
		if (end > v.byteLength) {
			fixed[size_t(a.bufferView)] = true; /* not ours to move */
			continue;
		}
		if (end > a.byteOffset)
			ranges[size_t(a.bufferView)].emplace_back(a.byteOffset, end);
	}
	json *acc = nullptr, *views = nullptr;
	if (doc.original.is_object() && doc.original.contains("accessors") && doc.original["accessors"].is_array())
		acc = &doc.original["accessors"];
	if (doc.original.is_object() && doc.original.contains("bufferViews") && doc.original["bufferViews"].is_array())
		views = &doc.original["bufferViews"];
	for (size_t vi = 0; vi < nv; vi++) {
		auto &r = ranges[vi];
		if (fixed[vi] || r.empty())
			continue;
		tinygltf::BufferView &v = m.bufferViews[vi];
		if (v.buffer < 0 || size_t(v.buffer) >= m.buffers.size() || named[size_t(v.buffer)])
			continue;
		std::vector<unsigned char> &data = m.buffers[size_t(v.buffer)].data;
		if (v.byteOffset > data.size() || v.byteLength > data.size() - v.byteOffset)
			fail(MLOD_ERR_PARSE, "buffer view %zu lies outside buffer %d", vi, v.buffer);
		std::sort(r.begin(), r.end());
		std::vector<std::pair<size_t, size_t>> merged;
		size_t kept = 0;
		for (const auto &x : r)
			if (!merged.empty() && x.first <= merged.back().second)
				merged.back().second = std::max(merged.back().second, x.second);
			else
				merged.push_back(x);
		for (const auto &x : merged)
			kept += x.second - x.first;
		if (kept + 4 * merged.size() >= v.byteLength)
			continue;
		/* Each merged range's new start, congruent to its old one mod 4. */
		std::vector<size_t> to(merged.size());
		std::vector<unsigned char> bytes;
		for (size_t k = 0; k < merged.size(); k++) {
			size_t at = bytes.size();
			at += (merged[k].first - at % 4 + 4) % 4;
			to[k] = at;
			bytes.resize(at, 0);
			bytes.insert(bytes.end(), data.begin() + long(v.byteOffset + merged[k].first),
			             data.begin() + long(v.byteOffset + merged[k].second));
		}
		for (size_t ai = 0; ai < m.accessors.size(); ai++) {
			tinygltf::Accessor &a = m.accessors[ai];
			if (a.bufferView != int(vi))
				continue;
			size_t k = size_t(std::upper_bound(merged.begin(), merged.end(), std::make_pair(a.byteOffset, SIZE_MAX)) -
			                  merged.begin());
			/* an accessor of count 0 may sit past every range: it reads nothing */
			a.byteOffset = k == 0 ? 0 : to[k - 1] + (a.byteOffset - merged[k - 1].first);
			if (a.count == 0 && k > 0 && a.byteOffset > bytes.size())
				a.byteOffset = bytes.size();
			if (acc && ai < acc->size() && (*acc)[ai].is_object())
				(*acc)[ai]["byteOffset"] = a.byteOffset;
		}
		/* The view's bytes now lie at its start; those after stay in the
		 * buffer until prune packs it. */
		std::copy(bytes.begin(), bytes.end(), data.begin() + long(v.byteOffset));
		v.byteLength = bytes.size();
		if (views && vi < views->size() && (*views)[vi].is_object())
			(*views)[vi]["byteLength"] = v.byteLength;
	}
}

/* prune for a document whose indices must hold (keep_indices): the
 * accessors and buffer views after the last one in use go, and each
 * buffer's bytes after its last kept view (a buffer an extension names
 * stays whole); nothing else moves. */
static void prune_tail(mlod_gltf &doc)
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
void prune(mlod_gltf &doc, bool meshes)
{
	Model &m = doc.model;
	if (doc.keep_indices) {
		prune_tail(doc);
		return;
	}
	for (const std::string &e : m.extensionsUsed)
		if (!prune_safe(m, e))
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

	trim_views(doc);
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
		if (!prune_safe(m, e))
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
static json *orig_element(mlod_gltf &doc, const char *name, int i)
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
	for (const std::string &p : animation_pointers(m))
		if (gone(int(std::min(pointer_index(p, "nodes"), long(INT_MAX))), nodes) ||
		    gone(int(std::min(pointer_index(p, "meshes"), long(INT_MAX))), meshes))
			fail(MLOD_ERR_UNSUPPORTED, "an animation pointer (KHR_animation_pointer) names a node or mesh that would go");
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
static bool trs_default(const mlod_trs &t, int part)
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
static double trs_number(float f, int mode)
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

static void trs_values(const mlod_trs &t, int part, int mode, std::vector<double> &v)
{
	if (part == 0)
		v = {trs_number(t.t.x, mode), trs_number(t.t.y, mode), trs_number(t.t.z, mode)};
	else if (part == 1)
		v = {trs_number(t.r.x, mode), trs_number(t.r.y, mode), trs_number(t.r.z, mode), trs_number(t.r.w, mode)};
	else
		v = {trs_number(t.s.x, mode), trs_number(t.s.y, mode), trs_number(t.s.z, mode)};
}

const char *const trs_keys[3] = {"translation", "rotation", "scale"};

static std::vector<double> &trs_member(tinygltf::Node &n, int part)
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

/* ------------------------------------------------------------------ */
/* Skin weights the reader made valid, into the document               */
/* ------------------------------------------------------------------ */

/* How many times m refers to each accessor (as used_accessors). */
static std::vector<int> accessor_refs(const Model &m)
{
	std::vector<int> refs(m.accessors.size(), 0);
	auto count = [&](int i) {
		if (i >= 0 && size_t(i) < refs.size())
			refs[size_t(i)]++;
	};
	for (const tinygltf::Mesh &mesh : m.meshes)
		for (const tinygltf::Primitive &p : mesh.primitives) {
			count(p.indices);
			for (const auto &kv : p.attributes)
				count(kv.second);
			for (const auto &t : p.targets)
				for (const auto &kv : t)
					count(kv.second);
		}
	for (const tinygltf::Skin &sk : m.skins)
		count(sk.inverseBindMatrices);
	for (const tinygltf::Animation &a : m.animations)
		for (const tinygltf::AnimationSampler &sa : a.samplers) {
			count(sa.input);
			count(sa.output);
		}
	return refs;
}

static bool skin_attribute(const std::string &name)
{
	return name.compare(0, 7, "JOINTS_") == 0 || name.compare(0, 8, "WEIGHTS_") == 0;
}

/* Whether the bytes of accessor i's elements are its own, so that writing
 * them changes nothing else: it has a buffer view (that no extension
 * names) and no sparse part, and no other accessor, sparse part or image
 * reads any of them (accessors interleaved in one strided view each read
 * their own bytes of every stride). */
static bool owns_bytes(const mlod_gltf &doc, size_t i)
{
	const Model &m = doc.model;
	const tinygltf::Accessor &a = m.accessors[i];
	if (a.bufferView < 0 || a.sparse.isSparse || a.count == 0)
		return false;
	std::vector<bool> named(m.bufferViews.size(), false), buffers(m.buffers.size(), false);
	extension_refs(doc.original, false, named, buffers);
	const tinygltf::BufferView &v = m.bufferViews[size_t(a.bufferView)];
	if (named[size_t(a.bufferView)] || buffers[size_t(v.buffer)])
		return false;
	const Layout l = layout_of(a);
	const size_t stride = v.byteStride ? v.byteStride : l.element;
	const size_t begin = v.byteOffset + a.byteOffset, end = begin + (a.count - 1) * stride + l.element;
	/* Does [from, to) of view `view` meet [begin, end)? */
	auto meets = [&](int view, size_t from, size_t to) {
		if (view < 0 || size_t(view) >= m.bufferViews.size())
			return false;
		const tinygltf::BufferView &w = m.bufferViews[size_t(view)];
		return w.buffer == v.buffer && w.byteOffset + from < end && begin < w.byteOffset + to;
	};
	for (size_t k = 0; k < m.accessors.size(); k++) {
		const tinygltf::Accessor &b = m.accessors[k];
		if (k == i || b.count == 0)
			continue;
		const Layout lb = layout_of(b);
		if (b.sparse.isSparse) {
			const auto &s = b.sparse;
			size_t n = size_t(std::max(s.count, 0));
			if (meets(s.indices.bufferView, size_t(s.indices.byteOffset),
			          size_t(s.indices.byteOffset) + n * component_size(s.indices.componentType)) ||
			    meets(s.values.bufferView, size_t(s.values.byteOffset), size_t(s.values.byteOffset) + n * lb.element))
				return false;
		}
		if (b.bufferView < 0)
			continue;
		const tinygltf::BufferView &w = m.bufferViews[size_t(b.bufferView)];
		size_t sb = w.byteStride ? w.byteStride : lb.element;
		if (!meets(b.bufferView, b.byteOffset, b.byteOffset + (b.count - 1) * sb + lb.element))
			continue;
		if (b.bufferView == a.bufferView && v.byteStride) {
			/* interleaved: each reads a window of every stride */
			size_t s = v.byteStride, ra = a.byteOffset % s, rb = b.byteOffset % s;
			if ((rb + s - ra) % s >= l.element && (ra + s - rb) % s >= lb.element)
				continue;
		}
		return false;
	}
	for (const tinygltf::Image &im : m.images)
		if (im.bufferView >= 0 && size_t(im.bufferView) < m.bufferViews.size() &&
		    meets(im.bufferView, 0, m.bufferViews[size_t(im.bufferView)].byteLength))
			return false;
	return true;
}

/* One component of type `type` (an unsigned integer or a float) at p,
 * little-endian. */
static void put_component(unsigned char *p, int type, double value)
{
	uint32_t bits;
	size_t size = component_size(type);
	if (type == TINYGLTF_COMPONENT_TYPE_FLOAT) {
		float f = float(value);
		memcpy(&bits, &f, 4);
	} else {
		bits = uint32_t(value);
	}
	for (size_t k = 0; k < size; k++)
		p[k] = uint8_t(bits >> (8 * k));
}

/* Gives attribute `name` of primitive p of mesh `mesh` the VEC4 values
 * raw (stored values: integers, or floats) in component type `type`:
 * in place when the accessor it names has that type, owns its bytes and
 * no one else refers to it (refs and mine: every reference, and those of
 * the primitives being rewritten; written: accessors already rewritten
 * in place), else as a new accessor (normalized as `normalized`). Returns
 * whether the old accessor was left without reference. */
static bool put_attribute(mlod_gltf &doc, int mesh, int p, const std::string &name, const std::vector<double> &raw,
                          int type, bool normalized, std::vector<int> &refs, std::vector<int> &mine,
                          std::vector<char> &written)
{
	Model &m = doc.model;
	int &index = m.meshes[size_t(mesh)].primitives[size_t(p)].attributes.at(name);
	tinygltf::Accessor &a = m.accessors[size_t(index)];
	size_t n = raw.size() / 4;
	if (a.componentType == type && a.type == TINYGLTF_TYPE_VEC4 && a.count == n && !written[size_t(index)] &&
	    refs[size_t(index)] == mine[size_t(index)] && owns_bytes(doc, size_t(index))) {
		Layout l = layout_of(a);
		const tinygltf::BufferView &v = m.bufferViews[size_t(a.bufferView)];
		size_t stride = v.byteStride ? v.byteStride : l.element;
		unsigned char *base = m.buffers[size_t(v.buffer)].data.data() + v.byteOffset + a.byteOffset;
		for (size_t e = 0; e < n; e++)
			for (int c = 0; c < 4; c++)
				put_component(base + e * stride + l.offset(c), type, raw[4 * e + size_t(c)]);
		/* Bounds the input gave stay true (stored values, as glTF's). */
		if (a.minValues.size() == 4 && a.maxValues.size() == 4)
			for (int c = 0; c < 4; c++) {
				a.minValues[size_t(c)] = a.maxValues[size_t(c)] = raw[size_t(c)];
				for (size_t e = 1; e < n; e++) {
					a.minValues[size_t(c)] = std::min(a.minValues[size_t(c)], raw[4 * e + size_t(c)]);
					a.maxValues[size_t(c)] = std::max(a.maxValues[size_t(c)], raw[4 * e + size_t(c)]);
				}
			}
		written[size_t(index)] = 1;
		return false;
	}
	std::vector<unsigned char> bytes(raw.size() * component_size(type));
	for (size_t k = 0; k < raw.size(); k++)
		put_component(&bytes[k * component_size(type)], type, raw[k]);
	int old = index;
	int added = append_accessor(m, bytes.data(), n, type, TINYGLTF_TYPE_VEC4, 4, TINYGLTF_TARGET_ARRAY_BUFFER, false);
	m.accessors[size_t(added)].normalized = normalized;
	/* (`index` and `a` may not outlive append_accessor) */
	m.meshes[size_t(mesh)].primitives[size_t(p)].attributes[name] = added;
	refs.push_back(1);
	mine.push_back(1);
	written.push_back(1);
	json &o = doc.original;
	if (o.is_object() && o.contains("meshes") && o["meshes"].is_array() && size_t(mesh) < o["meshes"].size()) {
		json &om = o["meshes"][size_t(mesh)];
		if (om.is_object() && om.contains("primitives") && om["primitives"].is_array() &&
		    size_t(p) < om["primitives"].size() && om["primitives"][size_t(p)].is_object() &&
		    om["primitives"][size_t(p)].contains("attributes") && om["primitives"][size_t(p)]["attributes"].is_object())
			om["primitives"][size_t(p)]["attributes"][name] = added;
	}
	return --refs[size_t(old)] == 0;
}

/* Writes into the document the skin weights the reader changed by mlod's
 * rule (read_character's fixed: mesh, primitive), so that level 0 of
 * what a tool writes passes the validator as its levels do: each
 * JOINTS_n and WEIGHTS_n accessor whose values the rule changed gets c's
 * values, in its own component type where that can hold them. Float
 * weights take c's floats as they are. Normalised unsigned bytes or
 * shorts (every set of the primitive in one such type) must sum to
 * exactly 255 or 65535: each changed vertex's weights are rounded by
 * largest remainder, over all its sets, and c takes the values the
 * reader reads back from those (less than a step from the rule's);
 * other weight types become floats. Joints keep their type unless the
 * root joint does not fit (unsigned bytes past 255: unsigned shorts).
 * An accessor is written in place (its bytes, bounds kept true) when it
 * owns its bytes, keeps its type and only the primitives rewritten here
 * refer to it; otherwise the primitive gets a new accessor, and the old
 * data goes (prune) when nothing else uses it and the document may be
 * pruned. Valid weights: nothing changes. */
void set_skin_weights(mlod_gltf &doc, mlod_character &c, const std::vector<std::pair<int, int>> &fixed)
{
	if (fixed.empty())
		return;
	Model &m = doc.model;
	std::vector<int> refs = accessor_refs(m), mine(m.accessors.size(), 0);
	for (const auto &mp : fixed)
		for (const auto &kv : m.meshes[size_t(mp.first)].primitives[size_t(mp.second)].attributes)
			if (skin_attribute(kv.first))
				mine[size_t(kv.second)]++;
	std::vector<char> written(m.accessors.size(), 0);
	bool orphans = false;
	for (const auto &mp : fixed) {
		const int mesh = mp.first, p = mp.second;
		mlod_primitive &pr = c.meshes[mesh].primitives[p];
		const size_t n = size_t(pr.vertex_count);
		const int sets = pr.weight_set_count;
		const size_t ns = size_t(sets);
		std::vector<std::string> wn(ns), jn(ns);
		std::vector<std::vector<float>> have_w(ns);
		std::vector<std::vector<uint32_t>> have_j(ns);
		int wtype = -1;
		bool wnorm = false, one_type = true;
		for (int k = 0; k < sets; k++) {
			wn[size_t(k)] = "WEIGHTS_" + std::to_string(k);
			jn[size_t(k)] = "JOINTS_" + std::to_string(k);
			const auto &attrs = m.meshes[size_t(mesh)].primitives[size_t(p)].attributes;
			int wa = attrs.at(wn[size_t(k)]), ja = attrs.at(jn[size_t(k)]);
			have_w[size_t(k)] = read_floats(m, wa, wn[size_t(k)], TINYGLTF_TYPE_VEC4);
			have_j[size_t(k)] = read_uints(m, ja, jn[size_t(k)], TINYGLTF_TYPE_VEC4);
			const tinygltf::Accessor &a = m.accessors[size_t(wa)];
			if (k == 0)
				wtype = a.componentType, wnorm = a.normalized;
			one_type = one_type && a.componentType == wtype && a.normalized == wnorm;
		}
		double scale = 0.0; /* stored value of weight 1; 0: floats */
		if (one_type && wnorm && wtype == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE)
			scale = 255.0;
		else if (one_type && wnorm && wtype == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT)
			scale = 65535.0;
		if (scale > 0.0) {
			/* Largest remainder over the vertex's weights, ties to the
			 * first: the stored values sum to exactly `scale`. */
			std::vector<double> x(4 * size_t(sets));
			std::vector<size_t> order(x.size());
			for (size_t v = 0; v < n; v++) {
				bool changed = false;
				double total = 0.0;
				for (int k = 0; k < sets; k++)
					for (size_t i = 0; i < 4; i++) {
						float w = pr.weights[k][4 * v + i];
						changed = changed || memcmp(&w, &have_w[size_t(k)][4 * v + i], sizeof w) != 0;
						total += w;
					}
				if (!changed || !(total > 0.0))
					continue;
				double left = scale;
				for (size_t i = 0; i < x.size(); i++) {
					x[i] = double(pr.weights[i / 4][4 * v + i % 4]) / total * scale;
					left -= std::floor(x[i]);
					order[i] = i;
				}
				std::stable_sort(order.begin(), order.end(),
				                 [&](size_t a, size_t b) { return x[a] - std::floor(x[a]) > x[b] - std::floor(x[b]); });
				for (size_t r = 0; r < x.size(); r++) {
					double q = std::floor(x[order[r]]) + (double(r) < left ? 1.0 : 0.0);
					/* as the reader reads it (gltf_accessor.cpp) */
					pr.weights[order[r] / 4][4 * v + order[r] % 4] = float(q / scale);
				}
			}
		}
		for (int k = 0; k < sets; k++) {
			if (memcmp(pr.weights[k], have_w[size_t(k)].data(), 4 * n * sizeof(float)) != 0) {
				std::vector<double> raw(4 * n);
				for (size_t i = 0; i < raw.size(); i++)
					raw[i] = scale > 0.0 ? std::round(double(pr.weights[k][i]) * scale) : double(pr.weights[k][i]);
				orphans |= put_attribute(doc, mesh, p, wn[size_t(k)], raw,
				                         scale > 0.0 ? wtype : int(TINYGLTF_COMPONENT_TYPE_FLOAT), scale > 0.0, refs,
				                         mine, written);
			}
			bool same = true;
			uint32_t most = 0;
			std::vector<double> raw(4 * n);
			for (size_t i = 0; i < raw.size(); i++) {
				same = same && pr.joints[k][i] == have_j[size_t(k)][i];
				most = std::max(most, uint32_t(pr.joints[k][i]));
				raw[i] = pr.joints[k][i];
			}
			if (same)
				continue;
			int jtype = m.accessors[size_t(m.meshes[size_t(mesh)].primitives[size_t(p)].attributes.at(jn[size_t(k)]))]
			                .componentType;
			if (jtype == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && most > 0xFF)
				jtype = TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
			orphans |= put_attribute(doc, mesh, p, jn[size_t(k)], raw, jtype, false, refs, mine, written);
		}
	}
	if (!orphans)
		return;
	bool safe = doc.keep_indices;
	if (!safe) {
		safe = true;
		for (const std::string &e : m.extensionsUsed)
			safe = safe && prune_safe(m, e);
	}
	if (safe)
		prune(doc, false);
}

} /* namespace mlod_gltf_internal */
