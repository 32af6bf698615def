/*
 * test_gltf_decompress.c: meshopt-compressed glTF input
 * (lib/io/gltf_decompress.cpp): a triangle whose positions and indices are
 * EXT_meshopt_compression / KHR_meshopt_compression buffer views, encoded
 * here with meshoptimizer's own encoders (indices with the index codec and
 * the sequence codec), reads as the plain triangle; then
 * hostile variants (truncated, garbled, huge counts, bad strides, a stride
 * the view contradicts, unknown modes, filters and codec versions) are
 * refused with the right code.
 * Draco input is covered by the CLI tests (tests/cli/pack_draco_input.sh),
 * which make it with gltf-transform.
 */
#include "test.h"

#include <meshoptimizer.h>

static const float positions[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
static const unsigned indices[3] = {0, 1, 2};

/* The compressed bytes: vertices at 0, indices at index_at (the index
 * codec: mode TRIANGLES) and at sequence_at (the sequence codec: mode
 * INDICES). */
static unsigned char encoded[512];
static size_t vertex_bytes, index_at, index_bytes, sequence_at, sequence_bytes;

static void encode(void)
{
	vertex_bytes = meshopt_encodeVertexBuffer(encoded, sizeof encoded, positions, 3, 12);
	index_at = (vertex_bytes + 3) / 4 * 4;
	index_bytes = meshopt_encodeIndexBuffer(encoded + index_at, sizeof encoded - index_at, indices, 3);
	sequence_at = (index_at + index_bytes + 3) / 4 * 4;
	sequence_bytes = meshopt_encodeIndexSequence(encoded + sequence_at, sizeof encoded - sequence_at, indices, 3);
}

static void base64(const unsigned char *d, size_t n, char *out)
{
	static const char a[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
	size_t o = 0;
	for (size_t i = 0; i < n; i += 3) {
		unsigned v = (unsigned)d[i] << 16 | (i + 1 < n ? (unsigned)d[i + 1] << 8 : 0) | (i + 2 < n ? d[i + 2] : 0);
		out[o++] = a[v >> 18 & 63];
		out[o++] = a[v >> 12 & 63];
		out[o++] = i + 1 < n ? a[v >> 6 & 63] : '=';
		out[o++] = i + 2 < n ? a[v & 63] : '=';
	}
	out[o] = 0;
}

/* The document: ext names the extension; vertex_ext and index_ext are
 * the members of the two views' extension objects after buffer 0's
 * (byteOffset, byteLength, ...; NULL: the defaults). bytes/nbytes:
 * buffer 0's data (NULL: the encoded triangle). */
static mlod_result read_triangle(const char *ext, const char *vertex_ext, const char *index_ext,
                                 const unsigned char *bytes, size_t nbytes, mlod_character *c, mlod_error *err)
{
	static char text[8192], data[1024], vdef[256], idef[256];
	if (!bytes) {
		bytes = encoded;
		nbytes = sequence_at + sequence_bytes;
	}
	base64(bytes, nbytes, data);
	snprintf(vdef, sizeof vdef, "\"byteLength\":%zu,\"byteStride\":12,\"count\":3,\"mode\":\"ATTRIBUTES\"", vertex_bytes);
	snprintf(idef, sizeof idef, "\"byteOffset\":%zu,\"byteLength\":%zu,\"byteStride\":2,\"count\":3,\"mode\":\"TRIANGLES\"",
	         index_at, index_bytes);
	snprintf(text, sizeof text,
	         "{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"%s\"],\"extensionsRequired\":[\"%s\"],"
	         "\"buffers\":[{\"byteLength\":%zu,\"uri\":\"data:application/octet-stream;base64,%s\"},"
	         "{\"byteLength\":44,\"extensions\":{\"%s\":{\"fallback\":true}}}],"
	         "\"bufferViews\":[{\"buffer\":1,\"byteLength\":36,\"byteStride\":12,\"extensions\":{\"%s\":{\"buffer\":0,%s}}},"
	         "{\"buffer\":1,\"byteOffset\":36,\"byteLength\":6,\"extensions\":{\"%s\":{\"buffer\":0,%s}}}],"
	         "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\","
	         "\"min\":[0,0,0],\"max\":[1,1,0]},{\"bufferView\":1,\"componentType\":5123,\"count\":3,\"type\":\"SCALAR\"}],"
	         "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1}]}],"
	         "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}],\"scene\":0}",
	         ext, ext, nbytes, data, ext, ext, vertex_ext ? vertex_ext : vdef, ext, index_ext ? index_ext : idef);
	mlod_gltf *doc = NULL;
	mlod_result r = mlod_gltf_read(text, strlen(text), NULL, &doc, err);
	if (r == MLOD_OK)
		r = mlod_gltf_to_character(doc, c, err);
	mlod_gltf_free(doc);
	return r;
}

TEST(plain_triangle)
{
	char sequence[256];
	snprintf(sequence, sizeof sequence,
	         "\"byteOffset\":%zu,\"byteLength\":%zu,\"byteStride\":2,\"count\":3,\"mode\":\"INDICES\"", sequence_at,
	         sequence_bytes);
	for (int k = 0; k < 3; k++) {
		mlod_character c = {0};
		mlod_error err = {0};
		const char *ext = k == 1 ? "KHR_meshopt_compression" : "EXT_meshopt_compression";
		mlod_result r = read_triangle(ext, NULL, k == 2 ? sequence : NULL, NULL, 0, &c, &err);
		CHECK_MSG(r == MLOD_OK, "%s: %d %s", ext, (int)r, err.message);
		if (r == MLOD_OK) {
			const mlod_primitive *p = c.mesh_count == 1 && c.meshes[0].primitive_count == 1 ? c.meshes[0].primitives : NULL;
			CHECK(p && p->vertex_count == 3 && p->index_count == 3);
			if (p && p->vertex_count == 3 && p->index_count == 3) {
				CHECK(memcmp(p->positions, positions, sizeof positions) == 0);
				CHECK(p->indices[0] == 0 && p->indices[1] == 1 && p->indices[2] == 2);
			}
		}
		mlod_character_free(&c);
	}
}

/* Expects read_triangle's code and a message containing want. */
static void refused(const char *vertex_ext, const char *index_ext, const unsigned char *bytes, size_t n,
                    mlod_result code, const char *want)
{
	mlod_character c = {0};
	mlod_error err = {0};
	mlod_result r = read_triangle("EXT_meshopt_compression", vertex_ext, index_ext, bytes, n, &c, &err);
	mlod_character_free(&c);
	CHECK_MSG(r == code && strstr(err.message, want), "%s / %s: %d \"%s\", not %d \"%s\"",
	          vertex_ext ? vertex_ext : "-", index_ext ? index_ext : "-", (int)r, err.message, (int)code, want);
}

TEST(hostile)
{
	char v[256];
	/* Truncated streams. */
	snprintf(v, sizeof v, "\"byteLength\":%zu,\"byteStride\":12,\"count\":3,\"mode\":\"ATTRIBUTES\"", vertex_bytes / 2);
	refused(v, NULL, NULL, 0, MLOD_ERR_PARSE, "the compressed vertex data is malformed or truncated");
	char ix[256];
	snprintf(ix, sizeof ix, "\"byteOffset\":%zu,\"byteLength\":2,\"byteStride\":2,\"count\":3,\"mode\":\"TRIANGLES\"",
	         index_at);
	refused(NULL, ix, NULL, 0, MLOD_ERR_PARSE, "the compressed index data is malformed or truncated");
	/* Past the end of the buffer. */
	snprintf(v, sizeof v, "\"byteOffset\":8,\"byteLength\":%zu,\"byteStride\":12,\"count\":3,\"mode\":\"ATTRIBUTES\"",
	         sequence_at + sequence_bytes);
	refused(v, NULL, NULL, 0, MLOD_ERR_PARSE, "lie past the end of buffer 0");
	/* Garbled headers: a newer codec version, and no meshopt stream. */
	unsigned char copy[512];
	memcpy(copy, encoded, sizeof copy);
	copy[0] = 0xA1;
	refused(NULL, NULL, copy, sequence_at + sequence_bytes, MLOD_ERR_UNSUPPORTED, "vertex codec version 1");
	copy[0] = 0x17;
	refused(NULL, NULL, copy, sequence_at + sequence_bytes, MLOD_ERR_PARSE, "malformed or truncated");
	/* Sizes: count and stride against the view, a count no stream of
	 * this length decodes to, strides the decoder would assert on. */
	refused("\"byteLength\":8,\"byteStride\":12,\"count\":4,\"mode\":\"ATTRIBUTES\"", NULL, NULL, 0, MLOD_ERR_PARSE,
	        "count 4 times byteStride 12 is 48 bytes, but the buffer view has 36");
	refused("\"byteLength\":8,\"byteStride\":6,\"count\":6,\"mode\":\"ATTRIBUTES\"", NULL, NULL, 0, MLOD_ERR_PARSE,
	        "byteStride 6 is not valid for mode ATTRIBUTES");
	refused("\"byteLength\":8,\"byteStride\":12,\"count\":4000000000,\"mode\":\"ATTRIBUTES\"", NULL, NULL, 0,
	        MLOD_ERR_PARSE, "but the buffer view has 36");
	refused("\"byteLength\":8,\"byteStride\":-4,\"count\":9,\"mode\":\"ATTRIBUTES\"", NULL, NULL, 0, MLOD_ERR_PARSE,
	        "byteStride: not an integer");
	refused("\"byteLength\":8,\"count\":9,\"mode\":\"ATTRIBUTES\"", NULL, NULL, 0, MLOD_ERR_PARSE, "no byteStride");
	/* A stride the view's own byteStride (12) contradicts: the decoded
	 * elements would be read in another layout. */
	refused("\"byteLength\":8,\"byteStride\":4,\"count\":9,\"mode\":\"ATTRIBUTES\"", NULL, NULL, 0, MLOD_ERR_PARSE,
	        "byteStride 4, but the buffer view's byteStride is 12");
	snprintf(ix, sizeof ix, "\"byteOffset\":%zu,\"byteLength\":%zu,\"byteStride\":2,\"count\":2,\"mode\":\"TRIANGLES\"",
	         index_at, index_bytes);
	refused(NULL, ix, NULL, 0, MLOD_ERR_PARSE, "count 2 of mode TRIANGLES is not a multiple of 3");
	/* Unknown modes and filters, and filters where they do not apply. */
	refused("\"byteLength\":8,\"byteStride\":12,\"count\":3,\"mode\":\"POINTS\"", NULL, NULL, 0, MLOD_ERR_UNSUPPORTED,
	        "mode \"POINTS\"");
	refused("\"byteLength\":8,\"byteStride\":12,\"count\":3,\"mode\":\"ATTRIBUTES\",\"filter\":\"COLOR\"", NULL, NULL, 0,
	        MLOD_ERR_UNSUPPORTED, "filter \"COLOR\"");
	refused("\"byteLength\":8,\"byteStride\":12,\"count\":3,\"mode\":\"ATTRIBUTES\",\"filter\":\"QUATERNION\"", NULL,
	        NULL, 0, MLOD_ERR_PARSE, "byteStride 12 is not valid for filter QUATERNION");
	snprintf(ix, sizeof ix,
	         "\"byteOffset\":%zu,\"byteLength\":%zu,\"byteStride\":2,\"count\":3,\"mode\":\"TRIANGLES\","
	         "\"filter\":\"OCTAHEDRAL\"",
	         index_at, index_bytes);
	refused(NULL, ix, NULL, 0, MLOD_ERR_PARSE, "filters apply to ATTRIBUTES only");
	refused("\"byteLength\":8,\"byteStride\":12,\"count\":3,\"mode\":7", NULL, NULL, 0, MLOD_ERR_PARSE,
	        "mode: not a string");
	refused("\"buffer\":1,\"byteLength\":8,\"byteStride\":12,\"count\":3,\"mode\":\"ATTRIBUTES\"", NULL, NULL, 0,
	        MLOD_ERR_PARSE, "fallback buffer, which has no data");
}

/* A document that only lists the extensions, compressing nothing, reads. */
TEST(listed_only)
{
	static const char text[] = "{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"KHR_draco_mesh_compression\","
	                           "\"EXT_meshopt_compression\"],\"extensionsRequired\":[\"KHR_draco_mesh_compression\"]}";
	mlod_gltf *doc = NULL;
	mlod_error err = {0};
	CHECK_MSG(mlod_gltf_read(text, strlen(text), NULL, &doc, &err) == MLOD_OK, "%s", err.message);
	mlod_gltf_free(doc);
}

int main(void)
{
	encode();
	RUN(plain_triangle);
	RUN(hostile);
	RUN(listed_only);
	TEST_EXIT();
}
