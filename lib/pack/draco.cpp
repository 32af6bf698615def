// draco.cpp: the C shim over Draco's core mesh codec (draco.h). Only the
// mesh encoder and decoder: Draco's glTF and scene I/O are never used.
#include <cstdlib>
#include <cstring>
#include <memory>
#include <new>

#include <draco/compression/decode.h>
#include <draco/compression/encode.h>
#include <draco/mesh/mesh.h>

#include "draco.h"

namespace {

draco::GeometryAttribute::Type draco_kind(mlod_draco_kind k)
{
	switch (k) {
	case MLOD_DRACO_POSITION: return draco::GeometryAttribute::POSITION;
	case MLOD_DRACO_NORMAL: return draco::GeometryAttribute::NORMAL;
	case MLOD_DRACO_TEXCOORD: return draco::GeometryAttribute::TEX_COORD;
	case MLOD_DRACO_COLOR: return draco::GeometryAttribute::COLOR;
	default: return draco::GeometryAttribute::GENERIC;
	}
}

draco::DataType draco_type(mlod_draco_type t)
{
	return t == MLOD_DRACO_F32 ? draco::DT_FLOAT32 : t == MLOD_DRACO_U8 ? draco::DT_UINT8 : draco::DT_UINT16;
}

size_t type_size(mlod_draco_type t)
{
	return t == MLOD_DRACO_F32 ? 4 : t == MLOD_DRACO_U8 ? 1 : 2;
}

} // namespace

extern "C" mlod_result mlod_draco_encode(int vertex_count, const mlod_draco_attr *attrs, int attr_count,
                                         const uint32_t *indices, int index_count, int sequential, int speed,
                                         void **out, size_t *size, mlod_error *err)
{
	*out = nullptr;
	*size = 0;
	if (vertex_count <= 0 || index_count <= 0 || index_count % 3 || attr_count <= 0 || speed < 0 || speed > 10)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "draco: bad mesh (%d vertices, %d indices, %d attributes)",
		                 vertex_count, index_count, attr_count);
	try {
		draco::Mesh mesh;
		mesh.set_num_points(static_cast<uint32_t>(vertex_count));
		draco::Encoder enc;
		for (int a = 0; a < attr_count; a++) {
			const mlod_draco_attr &at = attrs[a];
			if (at.components < 1 || at.components > 4 || !at.data)
				return mlod_fail(err, MLOD_ERR_INVALID_ARG, "draco: attribute %d: bad components or data", a);
			size_t stride = type_size(at.type) * static_cast<size_t>(at.components);
			draco::GeometryAttribute ga;
			ga.Init(draco_kind(at.kind), nullptr, static_cast<int8_t>(at.components), draco_type(at.type), false,
			        static_cast<int64_t>(stride), 0);
			int id = mesh.AddAttribute(ga, true, static_cast<uint32_t>(vertex_count));
			if (id < 0)
				return mlod_fail(err, MLOD_ERR_INVALID_ARG, "draco: attribute %d refused", a);
			draco::PointAttribute *pa = mesh.attribute(id);
			const unsigned char *src = static_cast<const unsigned char *>(at.data);
			for (int v = 0; v < vertex_count; v++)
				pa->SetAttributeValue(draco::AttributeValueIndex(v), src + stride * static_cast<size_t>(v));
			if (at.type == MLOD_DRACO_F32 && at.bits > 0)
				enc.SetAttributeQuantization(draco_kind(at.kind), at.bits);
		}
		for (int i = 0; i < index_count; i++)
			if (indices[i] >= static_cast<uint32_t>(vertex_count))
				return mlod_fail(err, MLOD_ERR_INVALID_ARG, "draco: index %d is %u, past %d vertices", i,
				                 indices[i], vertex_count);
		for (int f = 0; f < index_count / 3; f++) {
			draco::Mesh::Face face;
			for (int k = 0; k < 3; k++)
				face[k] = draco::PointIndex(indices[3 * f + k]);
			mesh.AddFace(face);
		}
		enc.SetSpeedOptions(speed, speed);
		enc.SetEncodingMethod(sequential ? draco::MESH_SEQUENTIAL_ENCODING : draco::MESH_EDGEBREAKER_ENCODING);
		draco::EncoderBuffer buf;
		draco::Status st = enc.EncodeMeshToBuffer(mesh, &buf);
		if (!st.ok())
			return mlod_fail(err, MLOD_ERR_UNSUPPORTED, "draco: cannot encode: %s", st.error_msg());
		void *p = std::malloc(buf.size());
		if (!p)
			return mlod_fail(err, MLOD_ERR_NOMEM, "draco: cannot allocate %zu bytes", buf.size());
		std::memcpy(p, buf.data(), buf.size());
		*out = p;
		*size = buf.size();
		return MLOD_OK;
	} catch (const std::bad_alloc &) {
		return mlod_fail(err, MLOD_ERR_NOMEM, "draco: out of memory");
	}
}

extern "C" mlod_result mlod_draco_decode(const void *data, size_t size, mlod_draco_attr *attrs, int attr_count,
                                         int *vertex_count, uint32_t **indices, int *index_count, mlod_error *err)
{
	*vertex_count = 0;
	*indices = nullptr;
	*index_count = 0;
	for (int a = 0; a < attr_count; a++)
		attrs[a].data = nullptr;
	try {
		draco::DecoderBuffer db;
		db.Init(static_cast<const char *>(data), size);
		draco::Decoder dec;
		auto so = dec.DecodeMeshFromBuffer(&db);
		if (!so.ok())
			return mlod_fail(err, MLOD_ERR_PARSE, "draco: cannot decode: %s", so.status().error_msg());
		std::unique_ptr<draco::Mesh> m = std::move(so).value();
		if (!m || m->num_attributes() != attr_count)
			return mlod_fail(err, MLOD_ERR_PARSE, "draco: %d attributes, expected %d", m ? m->num_attributes() : 0,
			                 attr_count);
		uint32_t n = m->num_points(), nf = m->num_faces();
		if (n == 0 || n > 0x7fffffffu || nf == 0 || nf > 0x7fffffffu / 3)
			return mlod_fail(err, MLOD_ERR_PARSE, "draco: %u points and %u faces", n, nf);
		mlod_result r = MLOD_OK;
		for (int a = 0; a < attr_count && !r; a++) {
			const draco::PointAttribute *pa = m->attribute(a);
			mlod_draco_attr &at = attrs[a];
			if (!pa || pa->num_components() != at.components || pa->attribute_type() != draco_kind(at.kind)) {
				r = mlod_fail(err, MLOD_ERR_PARSE, "draco: attribute %d is not what was encoded", a);
				break;
			}
			size_t es = type_size(at.type), stride = es * static_cast<size_t>(at.components);
			unsigned char *dst = static_cast<unsigned char *>(std::malloc(stride * n));
			if (!dst) {
				r = mlod_fail(err, MLOD_ERR_NOMEM, "draco: cannot allocate attribute %d", a);
				break;
			}
			at.data = dst;
			bool ok = true;
			for (uint32_t p = 0; p < n && ok; p++) {
				draco::AttributeValueIndex avi = pa->mapped_index(draco::PointIndex(p));
				if (at.type == MLOD_DRACO_F32)
					ok = pa->ConvertValue<float>(avi, reinterpret_cast<float *>(dst + stride * p));
				else if (at.type == MLOD_DRACO_U8)
					ok = pa->ConvertValue<uint8_t>(avi, dst + stride * p);
				else
					ok = pa->ConvertValue<uint16_t>(avi, reinterpret_cast<uint16_t *>(dst + stride * p));
			}
			if (!ok)
				r = mlod_fail(err, MLOD_ERR_PARSE, "draco: attribute %d: values do not convert", a);
		}
		uint32_t *ix = r ? nullptr : static_cast<uint32_t *>(std::malloc(sizeof(uint32_t) * 3 * nf));
		if (!r && !ix)
			r = mlod_fail(err, MLOD_ERR_NOMEM, "draco: cannot allocate %u faces", nf);
		for (uint32_t f = 0; !r && f < nf; f++)
			for (int k = 0; k < 3; k++)
				ix[3 * f + k] = m->face(draco::FaceIndex(f))[k].value();
		if (r) {
			std::free(ix);
			for (int a = 0; a < attr_count; a++) {
				std::free(attrs[a].data);
				attrs[a].data = nullptr;
			}
			return r;
		}
		*vertex_count = static_cast<int>(n);
		*indices = ix;
		*index_count = static_cast<int>(3 * nf);
		return MLOD_OK;
	} catch (const std::bad_alloc &) {
		return mlod_fail(err, MLOD_ERR_NOMEM, "draco: out of memory");
	}
}
