/*
 * gltf_read.cpp: reading: tinygltf with mlod's file and image callbacks,
 * then what the reader adds (the exact extras, a scene, unit rotations);
 * a pack's DOC chunk (gltf_internal.hpp).
 */
#include <sys/stat.h>
#include <fstream>

#include "io/gltf_internal.hpp"

namespace mlod_gltf_internal {

/* ------------------------------------------------------------------ */
/* Reading: tinygltf callbacks                                         */
/* ------------------------------------------------------------------ */

/* Where external files may be read from: nowhere when there is no base
 * directory. */
struct FileAccess {
	bool allowed;
	std::string prefix; /* the base directory, ending in '/' unless empty */
};

static bool file_exists(const std::string &path, void *user)
{
	const FileAccess *fa = static_cast<const FileAccess *>(user);
	if (!fa->allowed || path.compare(0, fa->prefix.size(), fa->prefix) != 0 ||
	    !stays_inside(path.substr(fa->prefix.size())))
		return false;
	struct stat st;
	return stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

/* tinygltf's default runs wordexp() on the path; mlod takes it as it is. */
static std::string expand_path(const std::string &path, void *)
{
	return path;
}

static bool read_whole_file(std::vector<unsigned char> *out, std::string *err, const std::string &path, void *user)
{
	if (!file_exists(path, user)) {
		*err = "not readable";
		return false;
	}
	return read_file(path, *out, err);
}

static bool refuse_write(std::string *err, const std::string &, const std::vector<unsigned char> &, void *)
{
	*err = "mlod does not write files through tinygltf";
	return false;
}

/* tinygltf's image loader: keeps the encoded bytes instead of decoding
 * them. Bytes of a bufferView image stay in the buffer; tinygltf computes
 * their address without checking the view against the buffer, so that is
 * checked here (user is the model being loaded). */
static bool keep_image_bytes(tinygltf::Image *image, const int index, std::string *err, std::string *, int, int,
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

/* The external images tinygltf could not read (it keeps their URIs and
 * no bytes): named in doc.unread_images, for a warning. */
static void note_unread_images(mlod_gltf &doc, const char *base_dir)
{
	const std::vector<tinygltf::Image> &images = doc.model.images;
	for (size_t i = 0; i < images.size(); i++) {
		const tinygltf::Image &im = images[i];
		if (im.bufferView >= 0 || !im.image.empty() || im.uri.empty() || im.uri.compare(0, 5, "data:") == 0)
			continue;
		std::string why;
		if (!base_dir) {
			why = "is an external file, and standard input has no directory to find it in";
		} else {
			struct stat st;
			std::string path = join_path(base_dir, url_decode(im.uri));
			why = stat(path.c_str(), &st) != 0 ? std::string("cannot be read: ") + strerror(errno)
			                                    : std::string("could not be read");
		}
		doc.unread_images.push_back("image " + std::to_string(i) + ": " + quoted(im.uri) + " " + why);
	}
}

/* ------------------------------------------------------------------ */
/* Reading: the document                                               */
/* ------------------------------------------------------------------ */

/* Records every "extras" of the JSON by pointer, outside other extras. */
static void collect_extras(const json &j, const std::string &at, std::map<std::string, json> &out)
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

/* A document without a scene (valid glTF: a library of nodes) gets one,
 * the default, with every root node but MSFT_lod levels: what a viewer
 * shows of it. The stages need it: the stage record lives in the scene's
 * extras, and the nodes they add for levels stay out of every scene. */
static void add_scene_if_none(mlod_gltf &doc)
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
static void normalise_node_rotations(mlod_gltf &doc)
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
static void restore_nodeless_channels(Model &m, const json &j)
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
	/* Compressed meshes: tinygltf reads the plain glb made of them. */
	std::string plain;
	if (decompress(j, data, binary, base_dir, plain)) {
		data = reinterpret_cast<const unsigned char *>(plain.data());
		size = plain.size();
		binary = true;
	}

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
	note_unread_images(doc, base_dir);

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

/* A pack's DOC chunk (mlod_gltf_read_doc): a glb read as read_document
 * without a base directory, once the buffers stripping emptied are gone. */
void read_pack_document(mlod_gltf &doc, const unsigned char *d, size_t size)
{
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
	std::string glb = glb_bytes(j, bin);
	read_document(doc, reinterpret_cast<const unsigned char *>(glb.data()), glb.size(), nullptr);
}

} /* namespace mlod_gltf_internal */
