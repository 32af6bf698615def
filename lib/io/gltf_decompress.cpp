/*
 * gltf_decompress.cpp: compressed glTF made plain before tinygltf reads it
 * (gltf_internal.hpp). The Debian tinygltf knows neither
 * EXT_meshopt_compression / KHR_meshopt_compression (buffer views) nor
 * KHR_draco_mesh_compression (primitives), so the reader rewrites such a
 * document into a plain glb: every buffer view's bytes, decoded where
 * compressed, go into one new buffer (overlapping plain views copied
 * once, views with one meshopt source decoded once, the decoded bytes
 * within a budget of the input's: spend), each Draco primitive's
 * attributes and indices into new buffer views of it, and the extensions
 * leave extensionsUsed / extensionsRequired. Only Draco's core decoder is used
 * (never its glTF I/O, which carries its own tinygltf: deps.md).
 */
#include <tuple>

#include <draco/compression/decode.h>
#include <meshoptimizer.h>

#include "io/gltf_internal.hpp"

namespace mlod_gltf_internal {

static const char *const meshopt_names[] = {"EXT_meshopt_compression", "KHR_meshopt_compression"};
static const char *const draco_name = "KHR_draco_mesh_compression";

/* A meshopt stream never decodes to more than this many times its length
 * plus a little: the vertex codec's densest block spends 2 bits on 16 zero
 * bytes (64x), an index triangle takes at least a byte (12 bytes out), a
 * sequence index a byte (4 out). A declared size past it is hostile, and
 * is refused before anything is allocated. */
const size_t meshopt_max_ratio = 64, meshopt_slack = 4096;

/* The document's buffers, loaded when a view first needs one. */
struct Buffers {
	const json &list;
	const unsigned char *glb_bin; /* the glb's BIN chunk, or null */
	size_t glb_bin_size;
	const char *base_dir;
	std::vector<std::unique_ptr<std::vector<unsigned char>>> loaded;
	uint64_t input; /* the glb's length (0 for JSON), plus each buffer read from a URI */

	Buffers(const json &j, const unsigned char *bin, size_t bin_size, const char *dir, size_t glb_size)
	    : list(j), glb_bin(bin), glb_bin_size(bin_size), base_dir(dir), loaded(j.is_array() ? j.size() : 0),
	      input(glb_size)
	{
	}

	/* The bytes of buffer i ("what" names who asks). */
	const std::vector<unsigned char> &get(size_t i, const std::string &what);
};

static std::vector<unsigned char> base64_decode(const std::string &s, size_t from, const std::string &what)
{
	static signed char table[256];
	if (!table['B']) {
		memset(table, -1, sizeof table);
		const char *a = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
		for (int k = 0; a[k]; k++)
			table[(unsigned char)a[k]] = (signed char)k;
	}
	std::vector<unsigned char> out;
	out.reserve((s.size() - from) / 4 * 3);
	unsigned acc = 0;
	int bits = 0;
	for (size_t i = from; i < s.size(); i++) {
		unsigned char c = (unsigned char)s[i];
		if (c == '=')
			break;
		if (table[c] < 0)
			fail(MLOD_ERR_PARSE, "%s: the data: URI is not base64 (byte %zu)", what.c_str(), i);
		acc = acc << 6 | unsigned(table[c]);
		bits += 6;
		if (bits >= 8) {
			bits -= 8;
			out.push_back((unsigned char)(acc >> bits & 0xFF));
		}
	}
	return out;
}

static size_t member(const json &e, const char *key, long long def, const std::string &at);

const std::vector<unsigned char> &Buffers::get(size_t i, const std::string &what)
{
	if (i >= loaded.size())
		fail(MLOD_ERR_PARSE, "%s: buffer %zu does not exist (the document has %zu)", what.c_str(), i, loaded.size());
	if (loaded[i])
		return *loaded[i];
	const json &b = list[i];
	std::string at = "buffers[" + std::to_string(i) + "]";
	size_t length = member(b, "byteLength", -1, at);
	std::vector<unsigned char> data;
	if (!b.contains("uri")) {
		for (const char *name : meshopt_names)
			if (b.contains("extensions") && b["extensions"].is_object() && b["extensions"].contains(name))
				fail(MLOD_ERR_PARSE, "%s: %s uses %s's fallback buffer, which has no data", what.c_str(), at.c_str(),
				     name);
		if (i != 0 || !glb_bin)
			fail(MLOD_ERR_PARSE, "%s: %s has neither a URI nor a glb BIN chunk", what.c_str(), at.c_str());
		data.assign(glb_bin, glb_bin + glb_bin_size);
	} else {
		std::string uri = b["uri"].get<std::string>();
		if (uri.compare(0, 5, "data:") == 0) {
			size_t comma = uri.find(',');
			if (comma == std::string::npos || uri.rfind(";base64", comma) == std::string::npos)
				fail(MLOD_ERR_UNSUPPORTED, "%s: a data: URI that is not base64", at.c_str());
			data = base64_decode(uri, comma + 1, at);
			input += data.size();
		} else {
			/* check_buffer_uris allowed it: a file below base_dir */
			if (!base_dir)
				fail(MLOD_ERR_PARSE, "%s: an external file without a directory to read it from", at.c_str());
			std::string why;
			if (!read_file(join_path(base_dir, url_decode(uri)), data, &why))
				fail(MLOD_ERR_IO, "%s: cannot read %s: %s", at.c_str(), mlod_gltf_internal::quoted(uri).c_str(),
				     why.c_str());
			input += data.size();
		}
	}
	if (data.size() < length)
		fail(MLOD_ERR_PARSE, "%s: byteLength %zu, but the data has %zu bytes", at.c_str(), length, data.size());
	data.resize(length);
	loaded[i].reset(new std::vector<unsigned char>(std::move(data)));
	return *loaded[i];
}

/* The extension object of name on o, or null. */
static const json *extension(const json &o, const char *name)
{
	if (!o.is_object() || !o.contains("extensions") || !o["extensions"].is_object())
		return nullptr;
	auto it = o["extensions"].find(name);
	return it == o["extensions"].end() ? nullptr : &*it;
}

static void erase_extension(json &o, const char *name)
{
	o["extensions"].erase(name);
	if (o["extensions"].empty())
		o.erase("extensions");
}

/* A non-negative integer member of an extension object, or def when
 * absent (def < 0: required). */
static size_t member(const json &e, const char *key, long long def, const std::string &at)
{
	if (!e.contains(key)) {
		if (def < 0)
			fail(MLOD_ERR_PARSE, "%s: no %s", at.c_str(), key);
		return size_t(def);
	}
	const json &v = e[key];
	if (!v.is_number_integer() || v.get<long long>() < 0 || v.get<unsigned long long>() > UINT32_MAX)
		fail(MLOD_ERR_PARSE, "%s.%s: not an integer from 0 to 2^32-1", at.c_str(), key);
	return v.get<size_t>();
}

static std::string string_member(const json &e, const char *key, const char *def, const std::string &at)
{
	if (!e.contains(key))
		return def;
	if (!e[key].is_string())
		fail(MLOD_ERR_PARSE, "%s.%s: not a string", at.c_str(), key);
	return e[key].get<std::string>();
}

/* The bytes [offset, offset + length) of buffer "buffer", checked. */
static const unsigned char *slice(Buffers &buffers, size_t buffer, size_t offset, size_t length, const std::string &at)
{
	const std::vector<unsigned char> &b = buffers.get(buffer, at);
	if (offset > b.size() || length > b.size() - offset)
		fail(MLOD_ERR_PARSE, "%s: bytes %zu to %zu lie past the end of buffer %zu (%zu bytes)", at.c_str(), offset,
		     offset + length, buffer, b.size());
	return b.data() + offset;
}

/* Explains a meshopt decoder's refusal: an unknown codec version is
 * unsupported, anything else malformed. header: the high nibble the
 * stream must start with; newest: the last version 0.18 decodes. */
[[noreturn]] static void meshopt_refused(const unsigned char *src, size_t length, unsigned header, unsigned newest,
                                         const char *codec, const std::string &at)
{
	if (length > 0 && (src[0] & 0xF0) == header && (src[0] & 0x0F) > newest)
		fail(MLOD_ERR_UNSUPPORTED, "%s: %s codec version %u: mlod's meshoptimizer 0.18 decodes versions up to %u",
		     at.c_str(), codec, src[0] & 0x0Fu, newest);
	fail(MLOD_ERR_PARSE, "%s: the compressed %s data is malformed or truncated", at.c_str(), codec);
}

/* A meshopt-compressed buffer view's source: what decoding it depends on.
 * Views with equal sources decode to the same bytes, once. */
struct MeshoptSource {
	size_t buffer, offset, length, stride, count;
	std::string mode, filter;
	bool operator<(const MeshoptSource &o) const
	{
		return std::tie(buffer, offset, length, stride, count, mode, filter) <
		       std::tie(o.buffer, o.offset, o.length, o.stride, o.count, o.mode, o.filter);
	}
};

/* Reads and checks the meshopt extension object e of name on a buffer
 * view (view_stride: the view's own byteStride, 0 without one). */
static MeshoptSource meshopt_source(const json &e, const char *name, size_t view_length, size_t view_stride,
                                    const std::string &view_at)
{
	std::string at = view_at + ".extensions." + name;
	if (!e.is_object())
		fail(MLOD_ERR_PARSE, "%s: not an object", at.c_str());
	MeshoptSource s;
	s.buffer = member(e, "buffer", -1, at), s.offset = member(e, "byteOffset", 0, at);
	s.length = member(e, "byteLength", -1, at), s.stride = member(e, "byteStride", -1, at);
	s.count = member(e, "count", -1, at);
	s.mode = string_member(e, "mode", "", at), s.filter = string_member(e, "filter", "NONE", at);
	const std::string &mode = s.mode, &filter = s.filter;
	size_t stride = s.stride, count = s.count, length = s.length;
	if (mode != "ATTRIBUTES" && mode != "TRIANGLES" && mode != "INDICES")
		fail(MLOD_ERR_UNSUPPORTED, "%s: mode %s: mlod decodes ATTRIBUTES, TRIANGLES and INDICES", at.c_str(),
		     mlod_gltf_internal::quoted(mode).c_str());
	if (filter != "NONE" && filter != "OCTAHEDRAL" && filter != "QUATERNION" && filter != "EXPONENTIAL")
		fail(MLOD_ERR_UNSUPPORTED, "%s: filter %s: mlod decodes NONE, OCTAHEDRAL, QUATERNION and EXPONENTIAL",
		     at.c_str(), mlod_gltf_internal::quoted(filter).c_str());
	if (mode != "ATTRIBUTES" && filter != "NONE")
		fail(MLOD_ERR_PARSE, "%s: filter %s on mode %s (filters apply to ATTRIBUTES only)", at.c_str(),
		     filter.c_str(), mode.c_str());
	/* The decoders assert on these: checked first. */
	if (mode == "ATTRIBUTES" ? stride == 0 || stride > 256 || stride % 4 != 0 : stride != 2 && stride != 4)
		fail(MLOD_ERR_PARSE, "%s: byteStride %zu is not valid for mode %s", at.c_str(), stride, mode.c_str());
	/* The decoded elements lie byteStride apart: a view that says
	 * otherwise would read them in another layout. */
	if (view_stride && view_stride != stride)
		fail(MLOD_ERR_PARSE, "%s: byteStride %zu, but the buffer view's byteStride is %zu", at.c_str(), stride,
		     view_stride);
	if (mode == "TRIANGLES" && count % 3 != 0)
		fail(MLOD_ERR_PARSE, "%s: count %zu of mode TRIANGLES is not a multiple of 3", at.c_str(), count);
	if ((filter == "OCTAHEDRAL" && stride != 4 && stride != 8) || (filter == "QUATERNION" && stride != 8))
		fail(MLOD_ERR_PARSE, "%s: byteStride %zu is not valid for filter %s", at.c_str(), stride, filter.c_str());
	uint64_t size = uint64_t(count) * stride;
	if (size != view_length)
		fail(MLOD_ERR_PARSE, "%s: count %zu times byteStride %zu is %llu bytes, but the buffer view has %zu",
		     at.c_str(), count, stride, (unsigned long long)size, view_length);
	if (size > uint64_t(length) * meshopt_max_ratio + meshopt_slack)
		fail(MLOD_ERR_PARSE, "%s: %llu bytes cannot be the decoding of %zu compressed bytes", at.c_str(),
		     (unsigned long long)size, length);
	return s;
}

/* Decodes a meshopt source (checked by meshopt_source) into dst, its
 * count * stride bytes. */
static void decode_meshopt(Buffers &buffers, const MeshoptSource &s, void *dst, const std::string &at)
{
	const unsigned char *src = slice(buffers, s.buffer, s.offset, s.length, at);
	if (s.mode == "ATTRIBUTES") {
		if (meshopt_decodeVertexBuffer(dst, s.count, s.stride, src, s.length) != 0)
			meshopt_refused(src, s.length, 0xA0, 0, "vertex", at);
		if (s.filter == "OCTAHEDRAL")
			meshopt_decodeFilterOct(dst, s.count, s.stride);
		else if (s.filter == "QUATERNION")
			meshopt_decodeFilterQuat(dst, s.count, s.stride);
		else if (s.filter == "EXPONENTIAL")
			meshopt_decodeFilterExp(dst, s.count, s.stride);
	} else if (s.mode == "TRIANGLES") {
		if (meshopt_decodeIndexBuffer(dst, s.count, s.stride, src, s.length) != 0)
			meshopt_refused(src, s.length, 0xE0, 1, "index", at);
	} else {
		if (meshopt_decodeIndexSequence(dst, s.count, s.stride, src, s.length) != 0)
			meshopt_refused(src, s.length, 0xD0, 0, "index sequence", at);
	}
}

/* Appends bytes (null: zeros) to the new buffer on a 4-byte boundary;
 * returns where. */
static size_t append(std::string &bin, const void *data, size_t size)
{
	bin.append((4 - bin.size() % 4) % 4, '\0');
	if (uint64_t(bin.size()) + size > UINT32_MAX - 4096)
		fail(MLOD_ERR_LIMIT, "the decompressed buffers would be larger than 4 GiB");
	size_t at = bin.size();
	if (data)
		bin.append(static_cast<const char *>(data), size);
	else
		bin.append(size, '\0');
	return at;
}

/* Decoded bytes (meshopt's and Draco's, every view and primitive
 * together) may reach this many per byte of input (the glb, and the
 * buffers read from URIs), plus decoded_slack: one meshopt stream never
 * passes 64 to 1 (meshopt_max_ratio), but many streams over the same
 * compressed bytes, or many Draco primitives, could otherwise make a small
 * file allocate gigabytes. Checked before each allocation. */
const uint64_t decoded_per_input_byte = 64, decoded_slack = uint64_t(1) << 20;

static void spend(const Buffers &buffers, uint64_t &total, uint64_t size, const std::string &at)
{
	uint64_t budget = buffers.input * decoded_per_input_byte + decoded_slack;
	if (total + size > budget)
		fail(MLOD_ERR_LIMIT,
		     "%s: the decompressed data would pass %llu bytes: mlod decodes at most %llu times the %llu bytes of "
		     "input and buffers, plus 1 MiB",
		     at.c_str(), (unsigned long long)budget, (unsigned long long)decoded_per_input_byte,
		     (unsigned long long)buffers.input);
	total += size;
}

static int type_components(const std::string &type)
{
	if (type == "SCALAR")
		return 1;
	if (type.size() == 4 && type.compare(0, 3, "VEC") == 0 && type[3] >= '2' && type[3] <= '4')
		return type[3] - '0';
	return 0;
}

/* Writes the values of a Draco attribute, one element per point, as the
 * accessor's component type. */
template <class T>
static void convert_points(const draco::PointAttribute &attr, size_t points, int comps, size_t stride, char *out,
                           const std::string &at)
{
	T v[4];
	for (size_t p = 0; p < points; p++) {
		if (!attr.ConvertValue<T>(attr.mapped_index(draco::PointIndex(uint32_t(p))), int8_t(comps), v))
			fail(MLOD_ERR_PARSE, "%s: Draco cannot convert point %zu's value", at.c_str(), p);
		memcpy(out + p * stride, v, sizeof(T) * size_t(comps));
	}
}

/* The min and max of an accessor decoded from Draco: those of its
 * decoded values, which the dequantisation moved off the file's (a
 * validator compares them exactly). */
static void set_bounds(json &acc, const std::string &data, size_t count, int comps, int ct, size_t stride)
{
	json lo = json::array(), hi = json::array();
	for (int c = 0; c < comps; c++) {
		double mn = 0, mx = 0;
		for (size_t e = 0; e < count; e++) {
			const char *p = data.data() + e * stride + size_t(c) * component_size(ct);
			double v;
			switch (ct) {
			case 5120: v = *reinterpret_cast<const int8_t *>(p); break;
			case 5121: v = *reinterpret_cast<const uint8_t *>(p); break;
			case 5122: { int16_t x; memcpy(&x, p, 2); v = x; } break;
			case 5123: { uint16_t x; memcpy(&x, p, 2); v = x; } break;
			case 5125: { uint32_t x; memcpy(&x, p, 4); v = x; } break;
			default: { float x; memcpy(&x, p, 4); v = x; } break;
			}
			if (e == 0 || v < mn)
				mn = v;
			if (e == 0 || v > mx)
				mx = v;
		}
		if (ct == 5126) {
			lo.push_back(mn);
			hi.push_back(mx);
		} else {
			lo.push_back((long long)mn);
			hi.push_back((long long)mx);
		}
	}
	if (count == 0)
		return;
	acc["min"] = lo;
	acc["max"] = hi;
}

/* Rewrites a Draco primitive: its indices and mapped attributes get new
 * buffer views in bin, decoded from the extension's buffer view (views
 * are the document's views as read; decoded caches their meshes, by view;
 * written maps an accessor to the Draco view it was written from). */
static void decode_draco(json &j, json &prim, const std::string &at, Buffers &buffers, const json &views,
                         std::map<size_t, std::unique_ptr<draco::Mesh>> &decoded, std::map<size_t, size_t> &written, std::string &bin,
                         uint64_t &total)
{
	const json &e = *extension(prim, draco_name);
	std::string eat = at + ".extensions." + draco_name;
	if (!e.is_object())
		fail(MLOD_ERR_PARSE, "%s: not an object", eat.c_str());
	if (prim.contains("mode") && prim["mode"].get<int>() != 4)
		fail(MLOD_ERR_UNSUPPORTED, "%s: mode %d: mlod decodes Draco triangles (mode 4) only", at.c_str(),
		     prim["mode"].get<int>());
	if (!prim.contains("indices"))
		fail(MLOD_ERR_UNSUPPORTED, "%s: a Draco primitive without indices", at.c_str());
	size_t v = member(e, "bufferView", -1, eat);
	if (!views.is_array() || v >= views.size())
		fail(MLOD_ERR_PARSE, "%s.bufferView %zu does not exist", eat.c_str(), v);
	if (!e.contains("attributes") || !e["attributes"].is_object())
		fail(MLOD_ERR_PARSE, "%s: no attributes object", eat.c_str());
	json &accessors = j["accessors"];
	size_t n_acc = accessors.is_array() ? accessors.size() : 0;
	/* The accessors are checked before Draco decodes anything: their
	 * counts bound what mlod writes (below max_values each, and within
	 * the decoded budget: spend). What Draco's decoder allocates for its
	 * own mesh only its own checks against its input bound. */
	auto accessor = [&](size_t a, const std::string &what) -> json & {
		if (a >= n_acc)
			fail(MLOD_ERR_PARSE, "%s: accessor %zu does not exist", what.c_str(), a);
		json &acc = accessors[a];
		if (!acc.contains("count") || !acc.contains("componentType") || !acc.contains("type"))
			fail(MLOD_ERR_PARSE, "%s: accessor %zu lacks count, componentType or type", what.c_str(), a);
		if (acc.contains("sparse"))
			fail(MLOD_ERR_UNSUPPORTED, "%s: accessor %zu is sparse", what.c_str(), a);
		return acc;
	};
	size_t ia = prim["indices"].get<size_t>();
	json &iacc = accessor(ia, at + ".indices");
	{
		int ct = iacc["componentType"].get<int>();
		if (iacc["type"] != "SCALAR" || (ct != 5121 && ct != 5123 && ct != 5125))
			fail(MLOD_ERR_PARSE, "%s: indices accessor %zu is not SCALAR of unsigned integers", at.c_str(), ia);
		if (iacc["count"].get<size_t>() > max_values)
			fail(MLOD_ERR_LIMIT, "%s: indices accessor %zu has %zu elements, more than mlod decodes", at.c_str(), ia,
			     iacc["count"].get<size_t>());
	}
	const json &attrs = prim["attributes"];
	for (auto it = e["attributes"].begin(); it != e["attributes"].end(); ++it) {
		std::string what = eat + ".attributes." + it.key();
		if (!it->is_number_integer() || it->get<long long>() < 0 || it->get<long long>() > INT32_MAX)
			fail(MLOD_ERR_PARSE, "%s: not a Draco attribute id", what.c_str());
		if (!attrs.contains(it.key()))
			fail(MLOD_ERR_PARSE, "%s: the primitive has no attribute %s", what.c_str(), it.key().c_str());
		size_t a = attrs[it.key()].get<size_t>();
		json &acc = accessor(a, what);
		size_t count = acc["count"].get<size_t>();
		int ct = acc["componentType"].get<int>(), comps = type_components(acc["type"].get<std::string>());
		if (!comps)
			fail(MLOD_ERR_UNSUPPORTED, "%s: accessor %zu of type %s from Draco", what.c_str(), a,
			     acc["type"].get<std::string>().c_str());
		if (!component_size(ct))
			fail(MLOD_ERR_PARSE, "%s: accessor %zu has component type %d", what.c_str(), a, ct);
		if (count > max_values / size_t(comps))
			fail(MLOD_ERR_LIMIT, "%s: accessor %zu has %zu elements, more than mlod decodes", what.c_str(), a, count);
	}
	auto found = decoded.find(v);
	if (found == decoded.end()) {
		const json &view = views[v];
		std::string vat = "bufferViews[" + std::to_string(v) + "]";
		size_t buffer = member(view, "buffer", -1, vat), offset = member(view, "byteOffset", 0, vat);
		size_t length = member(view, "byteLength", -1, vat);
		if (extension(view, meshopt_names[0]) || extension(view, meshopt_names[1]))
			fail(MLOD_ERR_UNSUPPORTED, "%s: Draco data in a meshopt-compressed buffer view", vat.c_str());
		const unsigned char *src = slice(buffers, buffer, offset, length, vat);
		draco::DecoderBuffer db;
		db.Init(reinterpret_cast<const char *>(src), length);
		auto type = draco::Decoder::GetEncodedGeometryType(&db);
		if (!type.ok())
			fail(MLOD_ERR_PARSE, "%s: not Draco data (%s)", vat.c_str(), printable(type.status().error_msg()).c_str());
		if (type.value() != draco::TRIANGULAR_MESH)
			fail(MLOD_ERR_UNSUPPORTED, "%s: a Draco point cloud, not a triangle mesh", vat.c_str());
		draco::Decoder decoder;
		auto mesh = decoder.DecodeMeshFromBuffer(&db);
		if (!mesh.ok())
			fail(MLOD_ERR_PARSE, "%s: Draco cannot decode it: %s", vat.c_str(),
			     printable(mesh.status().error_msg()).c_str());
		found = decoded.emplace(v, std::move(mesh).value()).first;
	}
	const draco::Mesh &mesh = *found->second;
	size_t points = mesh.num_points(), faces = mesh.num_faces();
	auto claim = [&](size_t a, const std::string &what) {
		auto w = written.find(a);
		if (w != written.end()) {
			if (w->second != v)
				fail(MLOD_ERR_PARSE, "%s: accessor %zu is decoded from two Draco buffer views (%zu and %zu)",
				     what.c_str(), a, w->second, v);
			return false;
		}
		written[a] = v;
		return true;
	};
	auto set_view = [&](json &acc, size_t offset, size_t length, size_t stride, int target) {
		json nv = json::object({{"buffer", 0}, {"byteOffset", offset}, {"byteLength", length}, {"target", target}});
		if (stride)
			nv["byteStride"] = stride;
		j["bufferViews"].push_back(nv);
		acc["bufferView"] = j["bufferViews"].size() - 1;
		acc.erase("byteOffset");
	};
	/* Indices: three per face, as the accessor's component type. */
	if (claim(ia, at + ".indices")) {
		size_t count = iacc["count"].get<size_t>();
		int ct = iacc["componentType"].get<int>();
		if (count != faces * 3)
			fail(MLOD_ERR_PARSE, "%s: indices accessor %zu has count %zu, the Draco mesh %zu faces (%zu indices)",
			     at.c_str(), ia, count, faces, faces * 3);
		size_t cs = component_size(ct), limit = ct == 5121 ? 0xFF : ct == 5123 ? 0xFFFF : 0xFFFFFFFF;
		spend(buffers, total, uint64_t(count) * cs, at + ".indices");
		std::string out(count * cs, '\0');
		for (draco::FaceIndex f(0); f < mesh.num_faces(); ++f)
			for (int k = 0; k < 3; k++) {
				uint32_t idx = mesh.face(f)[k].value();
				if (idx >= points || idx > limit)
					fail(MLOD_ERR_PARSE, "%s: Draco index %u does not fit %zu points and accessor %zu", at.c_str(),
					     idx, points, ia);
				memcpy(&out[(size_t(f.value()) * 3 + size_t(k)) * cs], &idx, cs); /* little-endian */
			}
		size_t off = append(bin, out.data(), out.size());
		set_view(iacc, off, out.size(), 0, 34963);
	}
	for (auto it = e["attributes"].begin(); it != e["attributes"].end(); ++it) {
		std::string what = eat + ".attributes." + it.key();
		size_t a = attrs[it.key()].get<size_t>();
		json &acc = accessors[a]; /* checked above */
		const draco::PointAttribute *attr = mesh.GetAttributeByUniqueId(it->get<uint32_t>());
		if (!attr)
			fail(MLOD_ERR_PARSE, "%s: the Draco mesh has no attribute %lld", what.c_str(), it->get<long long>());
		if (!claim(a, what))
			continue;
		size_t count = acc["count"].get<size_t>();
		int ct = acc["componentType"].get<int>(), comps = type_components(acc["type"].get<std::string>());
		if (count != points)
			fail(MLOD_ERR_PARSE, "%s: accessor %zu has count %zu, the Draco mesh %zu points", what.c_str(), a, count,
			     points);
		if (attr->num_components() != comps)
			fail(MLOD_ERR_PARSE, "%s: accessor %zu has %d components, the Draco attribute %d", what.c_str(), a, comps,
			     int(attr->num_components()));
		size_t cs = component_size(ct);
		size_t element = cs * size_t(comps), stride = (element + 3) / 4 * 4;
		spend(buffers, total, uint64_t(count) * stride, what);
		std::string out(count * stride, '\0');
		switch (ct) {
		case 5120: convert_points<int8_t>(*attr, count, comps, stride, &out[0], what); break;
		case 5121: convert_points<uint8_t>(*attr, count, comps, stride, &out[0], what); break;
		case 5122: convert_points<int16_t>(*attr, count, comps, stride, &out[0], what); break;
		case 5123: convert_points<uint16_t>(*attr, count, comps, stride, &out[0], what); break;
		case 5125: convert_points<uint32_t>(*attr, count, comps, stride, &out[0], what); break;
		default: convert_points<float>(*attr, count, comps, stride, &out[0], what); break;
		}
		size_t off = append(bin, out.data(), out.size());
		set_view(acc, off, out.size(), stride == element ? 0 : stride, 34962);
		if (acc.contains("min") || acc.contains("max"))
			set_bounds(acc, out, count, comps, ct, stride);
	}
	erase_extension(prim, draco_name);
}

/* Renumbers the buffer views j refers to after views were removed: those
 * of accessors (sparse too) and images, and, as extension_refs finds
 * them, any "bufferView" inside an extension; never inside extras. */
static void remap_views(json &j, bool inside, const std::vector<long long> &map)
{
	if (j.is_object()) {
		for (auto it = j.begin(); it != j.end(); ++it) {
			if (it.key() == "extras")
				continue;
			if (inside && it.key() == "bufferView" && it->is_number_unsigned() && it->get<size_t>() < map.size())
				*it = map[it->get<size_t>()];
			else
				remap_views(*it, inside || it.key() == "extensions" || it.key() == "accessors" ||
				                     it.key() == "images",
				            map);
		}
	} else if (j.is_array()) {
		for (json &e : j)
			remap_views(e, inside, map);
	}
}

/* Marks the buffer views that accessors (sparse too), images and
 * extensions name. */
static void mark_view_users(const json &j, std::vector<bool> &used)
{
	std::vector<bool> ignored(j.contains("buffers") && j["buffers"].is_array() ? j["buffers"].size() : 0, false);
	extension_refs(j, false, used, ignored);
	auto use = [&](const json &o) {
		if (o.is_object() && o.contains("bufferView") && o["bufferView"].is_number_unsigned() &&
		    o["bufferView"].get<size_t>() < used.size())
			used[o["bufferView"].get<size_t>()] = true;
	};
	for (const char *list : {"accessors", "images"})
		if (j.contains(list) && j[list].is_array())
			for (const json &o : j[list]) {
				use(o);
				if (o.is_object() && o.contains("sparse") && o["sparse"].is_object())
					for (const char *part : {"indices", "values"})
						if (o["sparse"].contains(part))
							use(o["sparse"][part]);
			}
}

static bool names_compression(const json &j)
{
	for (const char *list : {"extensionsUsed", "extensionsRequired"})
		if (j.contains(list))
			for (const json &e : j[list])
				for (const char *n : {meshopt_names[0], meshopt_names[1], draco_name})
					if (e == n)
						return true;
	return false;
}

/* If the document j (read from data; binary: a glb) uses meshopt
 * or Draco compression, rewrites j into a plain document whose one buffer
 * is the glb's BIN chunk, and returns that glb in out; else returns
 * false and leaves j alone. */
bool decompress(json &j, const unsigned char *data, bool binary, const char *base_dir, std::string &out)
{
	if (!names_compression(j))
		return false;
	/* The BIN chunk (glb_json checked the container). */
	const unsigned char *bin_chunk = nullptr;
	size_t bin_size = 0;
	if (binary) {
		size_t at = 20 + size_t(le32(data + 12)), length = le32(data + 8);
		if (at + 8 <= length && le32(data + at + 4) == chunk_bin) {
			bin_chunk = data + at + 8;
			bin_size = le32(data + at);
		}
	}
	static const json none = json::array();
	const json &buffer_list = j.contains("buffers") ? j["buffers"] : none;
	Buffers buffers(buffer_list, bin_chunk, bin_size, base_dir, binary ? le32(data + 8) : 0);
	json views = j.contains("bufferViews") ? j["bufferViews"] : json::array();
	std::string bin;
	uint64_t spent = 0; /* decoded bytes so far (spend) */

	/* Draco's data is read from the views as they are; a view that only
	 * Draco extensions name then carries nothing and stays empty (one an
	 * accessor, an image or another extension also names keeps its bytes). */
	std::vector<bool> draco_view(views.size(), false), other_use(views.size(), false);
	std::vector<json *> draco_exts;
	if (j.contains("meshes"))
		for (json &mesh : j["meshes"])
			if (mesh.contains("primitives"))
				for (json &p : mesh["primitives"])
					if (extension(p, draco_name)) {
						json &e = p["extensions"][draco_name];
						draco_exts.push_back(&e);
						if (e.is_object() && e.contains("bufferView") && e["bufferView"].is_number_unsigned() &&
						    e["bufferView"].get<size_t>() < views.size())
							draco_view[e["bufferView"].get<size_t>()] = true;
					}
	if (!draco_exts.empty()) {
		/* The Draco extensions step aside (null) while the others are read. */
		std::vector<json> held(draco_exts.size());
		for (size_t k = 0; k < draco_exts.size(); k++)
			std::swap(held[k], *draco_exts[k]);
		mark_view_users(j, other_use);
		for (size_t k = 0; k < draco_exts.size(); k++)
			std::swap(held[k], *draco_exts[k]);
	}

	/* Plain views: each run of overlapping views in a buffer is copied
	 * once, from its first view's 4-byte boundary, and the views rebased
	 * onto the copy; meshopt views with the same source share one
	 * decoding. So no byte is copied or decoded twice. */
	struct Plain {
		size_t buffer, begin, end, view;
		bool operator<(const Plain &o) const { return std::tie(buffer, begin, end) < std::tie(o.buffer, o.begin, o.end); }
	};
	std::vector<Plain> plain;
	std::vector<const char *> codec(views.size(), nullptr);
	for (size_t v = 0; v < views.size(); v++) {
		json &view = j["bufferViews"][v];
		std::string at = "bufferViews[" + std::to_string(v) + "]";
		size_t length = member(view, "byteLength", -1, at), offset = member(view, "byteOffset", 0, at);
		for (const char *name : meshopt_names)
			if (extension(view, name))
				codec[v] = name;
		if (!codec[v] && !(draco_view[v] && !other_use[v])) {
			size_t buffer = member(view, "buffer", -1, at);
			slice(buffers, buffer, offset, length, at);
			plain.push_back(Plain{buffer, offset, offset + length, v});
		}
	}
	/* run[v]: the first (lowest) member of v's run, in plain's order. */
	std::sort(plain.begin(), plain.end());
	std::vector<size_t> run(views.size(), SIZE_MAX), run_end(plain.size());
	for (size_t k = 0, first = 0; k < plain.size(); k++) {
		if (k == 0 || plain[k].buffer != plain[first].buffer || plain[k].begin >= run_end[first])
			first = k, run_end[k] = plain[k].end;
		else
			run_end[first] = std::max(run_end[first], plain[k].end);
		run[plain[k].view] = first;
	}
	std::vector<size_t> run_at(plain.size(), SIZE_MAX); /* where a run's copy starts in bin */
	std::map<MeshoptSource, size_t> meshopt_at;
	for (size_t v = 0; v < views.size(); v++) {
		json &view = j["bufferViews"][v];
		std::string at = "bufferViews[" + std::to_string(v) + "]";
		size_t length = member(view, "byteLength", -1, at), offset = member(view, "byteOffset", 0, at);
		size_t placed;
		if (codec[v]) {
			std::string eat = at + ".extensions." + codec[v];
			size_t view_stride = view.contains("byteStride") ? member(view, "byteStride", 0, at) : 0;
			MeshoptSource s = meshopt_source(*extension(view, codec[v]), codec[v], length, view_stride, at);
			auto found = meshopt_at.find(s);
			if (found != meshopt_at.end()) {
				placed = found->second;
			} else {
				slice(buffers, s.buffer, s.offset, s.length, eat); /* loads the buffer for spend's count */
				spend(buffers, spent, length, eat);
				placed = append(bin, nullptr, length);
				decode_meshopt(buffers, s, &bin[placed], eat);
				meshopt_at.emplace(s, placed);
			}
			erase_extension(view, codec[v]);
		} else if (run[v] == SIZE_MAX) {
			/* a view only Draco names: emptied, removed below */
			length = 0;
			placed = append(bin, nullptr, 0);
		} else {
			const Plain &first = plain[run[v]];
			size_t from = first.begin / 4 * 4;
			if (run_at[run[v]] == SIZE_MAX)
				run_at[run[v]] =
				    append(bin, slice(buffers, first.buffer, from, run_end[run[v]] - from, at), run_end[run[v]] - from);
			placed = run_at[run[v]] + (offset - from);
		}
		view["buffer"] = 0;
		view["byteOffset"] = placed;
		view["byteLength"] = length;
	}

	std::map<size_t, std::unique_ptr<draco::Mesh>> decoded;
	std::map<size_t, size_t> written;
	if (j.contains("meshes"))
		for (size_t m = 0; m < j["meshes"].size(); m++) {
			json &mesh = j["meshes"][m];
			if (mesh.contains("primitives"))
				for (size_t p = 0; p < mesh["primitives"].size(); p++)
					if (extension(mesh["primitives"][p], draco_name))
						decode_draco(j, mesh["primitives"][p],
						             "meshes[" + std::to_string(m) + "].primitives[" + std::to_string(p) + "]",
						             buffers, views, decoded, written, bin, spent);
		}
	/* Empty Draco views (glTF wants byteLength >= 1) go, and the indices
	 * of the views after them follow. */
	if (std::find(draco_view.begin(), draco_view.end(), true) != draco_view.end()) {
		std::vector<bool> used(j["bufferViews"].size(), false);
		mark_view_users(j, used);
		std::vector<long long> map(used.size(), -1);
		json kept = json::array();
		for (size_t v = 0; v < used.size(); v++) {
			if (v < draco_view.size() && draco_view[v] && !used[v])
				continue;
			map[v] = (long long)kept.size();
			kept.push_back(j["bufferViews"][v]);
		}
		j["bufferViews"] = kept;
		remap_views(j, false, map);
	}

	/* One buffer now: the BIN chunk. An extension that names a buffer
	 * would name the wrong one. It keeps buffer 0's name, extras and
	 * other extensions; the other buffers' go (documented in
	 * mlod-label(1): keeping them would take keeping their buffers). */
	std::vector<bool> ignored(j["bufferViews"].size(), false), named(buffer_list.size(), false);
	extension_refs(j, false, ignored, named);
	if (std::find(named.begin(), named.end(), true) != named.end())
		fail(MLOD_ERR_UNSUPPORTED, "an extension refers to a buffer directly: mlod cannot decompress this file");
	json buffer = buffer_list.size() ? buffer_list[0] : json::object();
	buffer.erase("uri");
	for (const char *name : meshopt_names)
		if (extension(buffer, name))
			erase_extension(buffer, name);
	buffer["byteLength"] = bin.size();
	if (bin.empty())
		j.erase("buffers");
	else
		j["buffers"] = json::array({buffer});
	if (j["bufferViews"].empty())
		j.erase("bufferViews");
	for (const char *list : {"extensionsUsed", "extensionsRequired"})
		if (j.contains(list)) {
			json kept = json::array();
			for (const json &e : j[list])
				if (e != meshopt_names[0] && e != meshopt_names[1] && e != draco_name)
					kept.push_back(e);
			if (kept.empty())
				j.erase(list);
			else
				j[list] = kept;
		}

	std::string chunk;
	if (!bin.empty()) {
		bin.append((4 - bin.size() % 4) % 4, '\0');
		for (uint32_t v : {uint32_t(bin.size()), chunk_bin})
			for (int k = 0; k < 4; k++)
				chunk += char(v >> (8 * k) & 0xFF);
		chunk += bin;
		std::string().swap(bin);
	}
	out = glb_bytes(j, chunk);
	return true;
}

} /* namespace mlod_gltf_internal */
