/*
 * gltf_write.cpp: writing: tinygltf's JSON reconciled with the input's,
 * as .glb or .gltf bytes (gltf_internal.hpp).
 */
#include <sstream>

#include "io/gltf_internal.hpp"

namespace mlod_gltf_internal {

/* ------------------------------------------------------------------ */
/* Writing                                                             */
/* ------------------------------------------------------------------ */

static std::string base64(const std::vector<unsigned char> &in)
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
static std::string sniff_image_type(const std::vector<unsigned char> &b)
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
static bool embed_image(const std::string *, const std::string *, const tinygltf::Image *image, bool,
                        std::string *uri, void *)
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
static void fill_empty_objects(json &j)
{
	if (j.is_null())
		j = json::object();
	else if (j.is_structured())
		for (json &e : j)
			fill_empty_objects(e);
}

/* Keys mlod may add to an object that came from the input. */
static bool added_by_mlod(const std::string &key)
{
	return key == "children" || key == "nodes" || key == "extensions" || key == "extras" || key == "uri";
}

/* Makes out (written by tinygltf) hold what orig (read) held: keys tinygltf
 * dropped come back, keys it added (defaults, buffer view targets) go,
 * except those mlod adds. Arrays are matched element by element; mlod only
 * appends to them, so a shorter one is one tinygltf dropped elements of and
 * is left alone. Extras are restored separately, from the exact copies. */
static void reconcile(json &out, const json &orig, bool root, bool in_extension)
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

/* Can a glb's BIN chunk hold buffers 1.. too? Only when their indices
 * matter to nothing but the buffer views: no extension names a buffer
 * (EXT_meshopt_compression's views do), and none of them has a URI (mlod
 * embeds what it reads: none has), extensions or extras of its own. */
static bool buffers_mergeable(const mlod_gltf &doc)
{
	const Model &m = doc.model;
	if (m.buffers.size() < 2 || !m.buffers[0].uri.empty())
		return false;
	for (size_t k = 1; k < m.buffers.size(); k++) {
		const tinygltf::Buffer &b = m.buffers[k];
		if (!b.uri.empty() || !b.extensions.empty() || b.extras.Type() != tinygltf::NULL_TYPE ||
		    doc.extras.count("/buffers/" + std::to_string(k) + "/extras"))
			return false;
	}
	const json &o = doc.original;
	if (o.is_object() && o.contains("buffers") && o["buffers"].is_array())
		for (size_t k = 1; k < o["buffers"].size(); k++)
			if (o["buffers"][k].is_object() &&
			    (o["buffers"][k].contains("extensions") || o["buffers"][k].contains("extras")))
				return false;
	std::vector<bool> views(m.bufferViews.size(), false), named(m.buffers.size(), false);
	extension_refs(o, false, views, named);
	return std::find(named.begin(), named.end(), true) == named.end();
}

/* Appends bytes to a glb's BIN buffer at the next 4-byte aligned offset
 * (every component type's alignment), which it returns. */
static size_t append_aligned(std::vector<unsigned char> &bin, const std::vector<unsigned char> &bytes)
{
	bin.resize((bin.size() + 3) / 4 * 4, 0);
	size_t at = bin.size();
	bin.insert(bin.end(), bytes.begin(), bytes.end());
	return at;
}

/* The document as .glb or pretty-printed .gltf bytes. */
std::string serialize(const mlod_gltf &doc, bool binary)
{
	/* A glb has one BIN chunk: buffers 1.. join buffer 0 there
	 * (append_aligned), rather than as base64 data: URIs, a third larger
	 * and slower to load; their views follow them. On a copy of the
	 * model. */
	const Model *model = &doc.model;
	Model copy;
	const bool merged = binary && buffers_mergeable(doc);
	std::vector<size_t> rebased; /* the views of merged buffers */
	if (merged) {
		copy = doc.model;
		model = &copy;
		std::vector<size_t> base(copy.buffers.size(), 0);
		for (size_t k = 1; k < copy.buffers.size(); k++)
			base[k] = append_aligned(copy.buffers[0].data, copy.buffers[k].data);
		copy.buffers.resize(1);
		for (size_t v = 0; v < copy.bufferViews.size(); v++) {
			tinygltf::BufferView &view = copy.bufferViews[v];
			if (view.buffer < 1)
				continue;
			view.byteOffset += base[size_t(view.buffer)];
			view.buffer = 0;
			rebased.push_back(v);
		}
	}
	/* A glb holds the images read from files or data: URIs in its BIN
	 * chunk, each in a buffer view of its own (a data: URI in a glb is
	 * what the validator warns of): on a copy of the model. */
	std::vector<std::pair<size_t, int>> moved; /* image, its new view */
	for (size_t i = 0; binary && i < doc.model.images.size(); i++) {
		const tinygltf::Image &im = doc.model.images[i];
		if (im.bufferView >= 0 || im.image.empty() ||
		    (im.mimeType.empty() ? sniff_image_type(im.image) : im.mimeType).empty())
			continue;
		if (model != &copy) {
			copy = doc.model;
			model = &copy;
		}
		if (copy.buffers.empty())
			copy.buffers.emplace_back();
		tinygltf::Image &out = copy.images[i];
		tinygltf::BufferView v;
		v.buffer = 0;
		v.byteOffset = append_aligned(copy.buffers[0].data, out.image);
		v.byteLength = out.image.size();
		copy.bufferViews.push_back(v);
		if (out.mimeType.empty())
			out.mimeType = sniff_image_type(out.image);
		out.bufferView = int(copy.bufferViews.size() - 1);
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
		j = parse_written_json(written.data() + 20, json_length);
		bin_chunk = written.substr(20 + json_length);
	} else {
		j = parse_written_json(written.data(), written.size());
	}
	fill_empty_objects(j);
	if (!doc.original.is_null())
		reconcile(j, doc.original, true, false);
	if (merged) {
		/* Merged buffers: reconcile passes over an array shorter than the
		 * input's, so buffer 0 is reconciled here, and a view that the
		 * input gave no byteOffset gets its new one back. */
		const json &o = doc.original;
		if (o.is_object() && o.contains("buffers") && o["buffers"].is_array() && !o["buffers"].empty() &&
		    j.contains("buffers") && j["buffers"].is_array() && !j["buffers"].empty())
			reconcile(j["buffers"][0], o["buffers"][0], false, false);
		for (size_t v : rebased) {
			if (!j.contains("bufferViews") || v >= j["bufferViews"].size() || !j["bufferViews"][v].is_object())
				continue;
			json &view = j["bufferViews"][v];
			view["buffer"] = 0;
			if (model->bufferViews[v].byteOffset)
				view["byteOffset"] = model->bufferViews[v].byteOffset;
		}
	}
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
		return dump_json(j, 2) + "\n";

	return glb_bytes(j, bin_chunk);
}

} /* namespace mlod_gltf_internal */
