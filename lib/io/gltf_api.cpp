/*
 * gltf_api.cpp: the C API of mlod_io.h (gltf_internal.hpp): each call
 * checks its arguments and runs the layers below under guard(), so that no
 * exception crosses into C.
 */
#include "io/gltf_internal.hpp"

using namespace mlod_gltf_internal;

/* Checks the arguments common to the calls that take a document. */
static void need(bool ok, const char *what)
{
	if (!ok)
		fail(MLOD_ERR_INVALID_ARG, "%s", what);
}

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
		std::unique_ptr<mlod_gltf> doc(new mlod_gltf);
		read_pack_document(*doc, static_cast<const unsigned char *>(data), size);
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

/* The character of doc into *out (zeroed first, freed on failure); with
 * fix (doc itself), the skin weights the reader made valid are written
 * back into it (mlod_gltf_to_character_fix). */
static void to_character(const mlod_gltf &doc, mlod_gltf *fix, mlod_character *out)
{
	memset(out, 0, sizeof *out);
	mlod_character c;
	memset(&c, 0, sizeof c);
	try {
		std::vector<std::pair<int, int>> fixed;
		read_character(doc, c, fix ? &fixed : nullptr);
		if (fix)
			set_skin_weights(*fix, c, fixed);
	} catch (...) {
		mlod_character_free(&c);
		throw;
	}
	*out = c;
}

mlod_result mlod_gltf_to_character(const mlod_gltf *doc, mlod_character *out, mlod_error *err)
{
	return guard(err, [&] {
		need(doc && out, "mlod_gltf_to_character: doc and out must not be NULL");
		to_character(*doc, nullptr, out);
	});
}

mlod_result mlod_gltf_to_character_fix(mlod_gltf *doc, mlod_character *out, mlod_error *err)
{
	return guard(err, [&] {
		need(doc && out, "mlod_gltf_to_character_fix: doc and out must not be NULL");
		to_character(*doc, doc, out);
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
			*text = c_string(dump_json(e[key], -1));
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
