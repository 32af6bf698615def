/*
 * gltf_util.cpp: errors, C allocation, strings, JSON (the depth-limited
 * parser, tinygltf Values) and node transforms (gltf_internal.hpp).
 */
#include <cstdarg>

#include "io/gltf_internal.hpp"

namespace mlod_gltf_internal {

/* ------------------------------------------------------------------ */
/* Errors                                                              */
/* ------------------------------------------------------------------ */

void fail(mlod_result code, const char *fmt, ...)
{
	char message[MLOD_ERROR_MESSAGE_SIZE];
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(message, sizeof message, fmt, ap);
	va_end(ap);
	throw Failure{code, message};
}

/* ------------------------------------------------------------------ */
/* Small helpers: C allocation, strings, JSON                          */
/* ------------------------------------------------------------------ */

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

/* Deeper JSON is refused: tinygltf converts it recursively. It is valid
 * JSON that mlod does not handle, so MLOD_ERR_UNSUPPORTED (exit 3). */
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
			fail(MLOD_ERR_UNSUPPORTED, "JSON nested deeper than %d levels", max_json_depth);
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

/* JSON that tinygltf wrote, read back without the depth limit. nlohmann's
 * parser and serialiser are instantiated here alone (each file that uses
 * them compiles its own copy, seconds of build time each). */
json parse_written_json(const char *text, size_t size)
{
	return json::parse(text, text + size);
}

/* j as JSON text: compact (indent -1) or pretty-printed. */
std::string dump_json(const json &j, int indent)
{
	return j.dump(indent);
}

std::string glb_bytes(const json &j, const std::string &bin_chunk)
{
	std::string text = dump_json(j, -1);
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

bool read_file(const std::string &path, std::vector<unsigned char> &out, std::string *why)
{
	std::ifstream f(path, std::ios::binary | std::ios::ate);
	std::streamoff size = f.tellg();
	if (!f || size < 0 || uint64_t(size) > UINT32_MAX) {
		*why = f ? "larger than 4 GiB" : "cannot open";
		return false;
	}
	out.resize(size_t(size));
	f.seekg(0);
	if (size > 0 && !f.read(reinterpret_cast<char *>(out.data()), size)) {
		*why = "read error";
		return false;
	}
	return true;
}

std::string pointer_token(const std::string &key)
{
	std::string t;
	for (char ch : key)
		t += ch == '~' ? "~0" : ch == '/' ? "~1" : std::string(1, ch);
	return t;
}

static json to_json(const Value &v)
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

/* The buffer views and buffers that an extension's JSON names (a
 * "bufferView" or "buffer" member anywhere inside an "extensions"
 * object), which prune_tail keeps whole and a glb
 * does not merge. */
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

/* The extras of an object: the exact copy at pointer if there is one,
 * else its Value. */
json current_extras(const mlod_gltf &doc, const std::string &pointer, const Value &value)
{
	auto it = doc.extras.find(pointer);
	return it != doc.extras.end() ? it->second : to_json(value);
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

} /* namespace mlod_gltf_internal */
