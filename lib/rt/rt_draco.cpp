// rt_draco.cpp: the runtime's Draco decode (rt_draco.h), the only C++ in
// lib/rt. Only Draco's core mesh decoder is used (never its glTF or scene
// I/O, whose copy of tinygltf clashes with the bake side's). Every C++
// exception stays inside: the C caller sees a result and a message.
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <memory>
#include <new>

#include <draco/compression/decode.h>
#include <draco/mesh/mesh.h>

#include "rt_draco.h"

namespace {

int fail(char *msg, size_t n, const char *fmt, ...)
{
	if (msg && n) {
		va_list ap;
		va_start(ap, fmt);
		std::vsnprintf(msg, n, fmt, ap);
		va_end(ap);
	}
	return -1;
}

} // namespace

extern "C" int mlod_rt_draco_decode(const void *data, size_t size, uint32_t vertex_count, uint32_t index_count,
                                    const mlod_rt_draco_attr *attrs, int attr_count, uint32_t *indices, char *msg,
                                    size_t msg_size)
{
	if (!data || !size || !vertex_count || !index_count || index_count % 3 || attr_count < 1 || !attrs || !indices)
		return fail(msg, msg_size, "draco: bad arguments (%zu bytes, %u vertices, %u indices, %d attributes)", size,
		            vertex_count, index_count, attr_count);
	try {
		draco::DecoderBuffer db;
		db.Init(static_cast<const char *>(data), size);
		auto geom = draco::Decoder::GetEncodedGeometryType(&db);
		if (!geom.ok())
			return fail(msg, msg_size, "draco: not a Draco stream: %s", geom.status().error_msg());
		if (geom.value() != draco::TRIANGULAR_MESH)
			return fail(msg, msg_size, "draco: not a triangle mesh (geometry type %d)", (int)geom.value());
		draco::Decoder dec;
		auto so = dec.DecodeMeshFromBuffer(&db);
		if (!so.ok())
			return fail(msg, msg_size, "draco: cannot decode: %s", so.status().error_msg());
		std::unique_ptr<draco::Mesh> m = std::move(so).value();
		if (!m)
			return fail(msg, msg_size, "draco: no mesh");
		if (m->num_points() != vertex_count || (uint64_t)m->num_faces() * 3 != index_count)
			return fail(msg, msg_size, "draco: %u vertices and %u triangles, the part's record says %u and %u",
			            m->num_points(), m->num_faces(), vertex_count, index_count / 3);
		if (m->num_attributes() != attr_count)
			return fail(msg, msg_size, "draco: %d attributes, expected %d", m->num_attributes(), attr_count);
		for (int a = 0; a < attr_count; a++) {
			const draco::PointAttribute *pa = m->attribute(a);
			const mlod_rt_draco_attr &at = attrs[a];
			draco::DataType want = at.elsize == 1 ? draco::DT_UINT8 : draco::DT_UINT16;
			if (!pa || pa->num_components() != at.components || pa->data_type() != want ||
			    (at.elsize != 1 && at.elsize != 2) || at.stride < (size_t)at.components * at.elsize || !at.dst)
				return fail(msg, msg_size, "draco: attribute %d is not %d components of %d bytes", a, at.components,
				            at.elsize);
			if (pa->size() == 0)
				return fail(msg, msg_size, "draco: attribute %d has no values", a);
			for (uint32_t p = 0; p < vertex_count; p++) {
				draco::AttributeValueIndex avi = pa->mapped_index(draco::PointIndex(p));
				if (avi.value() >= pa->size())
					return fail(msg, msg_size, "draco: attribute %d: vertex %u maps to value %u of %zu", a, p,
					            avi.value(), pa->size());
				uint8_t *d = at.dst + at.stride * p;
				bool ok = at.elsize == 1 ? pa->ConvertValue<uint8_t>(avi, at.components, d)
				                         : pa->ConvertValue<uint16_t>(avi, at.components,
				                                                      reinterpret_cast<uint16_t *>(d));
				if (!ok)
					return fail(msg, msg_size, "draco: attribute %d: vertex %u does not convert", a, p);
			}
		}
		for (uint32_t f = 0; f < index_count / 3; f++) {
			const draco::Mesh::Face &face = m->face(draco::FaceIndex(f));
			for (int k = 0; k < 3; k++) {
				uint32_t v = face[k].value();
				if (v >= vertex_count)
					return fail(msg, msg_size, "draco: triangle %u refers to vertex %u of %u", f, v, vertex_count);
				indices[3 * f + k] = v;
			}
		}
		return 0;
	} catch (const std::bad_alloc &) {
		return fail(msg, msg_size, "draco: out of memory");
	} catch (...) {
		return fail(msg, msg_size, "draco: the decoder failed");
	}
}
