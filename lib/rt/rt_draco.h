/*
 * rt_draco.h: the runtime's Draco decode (lib/rt/rt_draco.cpp, the only
 * C++ in lib/rt, built when MLOD_DRACO=1; the reader in pack.c calls it
 * for MESH chunks of codec MLOD_CODEC_DRACO).
 *
 * One call decodes one part's Draco mesh (mlod(5), MESH levels, codec
 * draco) into integer attributes and triangles the caller allocated, sized
 * from the part's record. Everything Draco says is checked: the mesh must
 * have exactly the vertex and face counts expected, exactly the attributes
 * expected (count, component count, data type), and every face index
 * below the vertex count; anything else is a failure with a message, never
 * a write past the caller's buffers. Draco's own allocations (C++ new) are
 * freed before the call returns.
 */
#ifndef MLOD_RT_DRACO_H
#define MLOD_RT_DRACO_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* One attribute: components values of elsize bytes (1: u8, 2: u16) per
 * vertex, written to dst at stride bytes per vertex (>= components *
 * elsize; bytes past them are left as they are). */
typedef struct mlod_rt_draco_attr {
	int components; /* 1..4 */
	int elsize;     /* 1 or 2 */
	uint8_t *dst;
	size_t stride;
} mlod_rt_draco_attr;

/* Decodes size bytes at data: a mesh of exactly vertex_count vertices
 * (>= 1) and index_count / 3 triangles (index_count a positive multiple
 * of 3), with attr_count attributes as attrs says (their order in the
 * Draco mesh). Fills each attrs[a].dst and indices (index_count u32).
 * Returns 0, or -1 with a message in msg (msg_size bytes, NUL-ended). */
int mlod_rt_draco_decode(const void *data, size_t size, uint32_t vertex_count, uint32_t index_count,
                         const mlod_rt_draco_attr *attrs, int attr_count, uint32_t *indices, char *msg,
                         size_t msg_size);

#ifdef __cplusplus
}
#endif

#endif /* MLOD_RT_DRACO_H */
