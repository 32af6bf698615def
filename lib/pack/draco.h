/*
 * draco.h: a C shim over Draco's core mesh codec (lib/pack/draco.cpp, the
 * pack's only C++), for the pack's `--codec draco` and its benchmark.
 *
 * Only Draco's mesh encoder and decoder are used: its glTF and scene I/O
 * carry an older copy of tinygltf that clashes with ours, so they are
 * never called, and -ltinygltf comes before -ldraco on every link line.
 *
 * A mesh goes in as vertex attributes and triangles and comes back the
 * same, except that the edgebreaker method (sequential == 0) reorders the
 * vertices (the triangles follow them; every attribute keeps its
 * vertex) and float attributes come back quantised to their bits.
 */
#ifndef MLOD_PACK_DRACO_H
#define MLOD_PACK_DRACO_H

#include <stddef.h>
#include <stdint.h>

#include "mlod_core.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum mlod_draco_kind {
	MLOD_DRACO_POSITION,
	MLOD_DRACO_NORMAL,
	MLOD_DRACO_TEXCOORD,
	MLOD_DRACO_COLOR,
	MLOD_DRACO_GENERIC
} mlod_draco_kind;

typedef enum mlod_draco_type { MLOD_DRACO_F32, MLOD_DRACO_U8, MLOD_DRACO_U16 } mlod_draco_type;

typedef struct mlod_draco_attr {
	mlod_draco_kind kind;
	mlod_draco_type type;
	int components;           /* 1..4 */
	int bits;                 /* float attributes: quantisation bits (1..30); 0 stores them losslessly */
	void *data;               /* vertex_count * components values; the decoder allocates it (mlod_free) */
} mlod_draco_attr;

/* Encodes a triangle mesh. speed is Draco's 0 (smallest) .. 10 (fastest),
 * for both encoding and decoding. *out is released with mlod_free. */
mlod_result mlod_draco_encode(int vertex_count, const mlod_draco_attr *attrs, int attr_count, const uint32_t *indices,
                              int index_count, int sequential, int speed, void **out, size_t *size,
                              mlod_error *err);

/* Decodes what mlod_draco_encode wrote with the same attribute list
 * (kind, type, components): fills each attrs[i].data and *indices (both
 * released with mlod_free). Malformed data is MLOD_ERR_PARSE. */
mlod_result mlod_draco_decode(const void *data, size_t size, mlod_draco_attr *attrs, int attr_count,
                              int *vertex_count, uint32_t **indices, int *index_count, mlod_error *err);

#ifdef __cplusplus
}
#endif

#endif /* MLOD_PACK_DRACO_H */
