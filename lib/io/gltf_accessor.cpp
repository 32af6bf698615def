/*
 * gltf_accessor.cpp: accessors: layouts, checks and decoding (normalised
 * integers, strides, sparse) (gltf_internal.hpp).
 */
#include "io/gltf_internal.hpp"

namespace mlod_gltf_internal {

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
static bool fits(size_t offset, size_t stride, size_t count, size_t elem, size_t length)
{
	if (count == 0)
		return offset <= length;
	if (offset > length || elem > length - offset)
		return false;
	return count - 1 <= (length - offset - elem) / stride;
}

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
static uint32_t sparse_index(const Model &m, const tinygltf::Accessor &a, size_t k)
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
static double component(const unsigned char *p, int type, bool normalized)
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
template <class T> static std::vector<T> decode(const Model &m, int i)
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
std::vector<float> read_floats(const Model &m, int i, const std::string &what, int type, int other_type)
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

} /* namespace mlod_gltf_internal */
