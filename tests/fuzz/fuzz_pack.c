/*
 * fuzz_pack.c: libFuzzer target for the pack reader (make fuzz; not part of
 * make test). Each input is opened and every chunk decoded, as the runtime
 * would: INFO, SKELETON, then each skeleton level, mesh level and motion
 * level against the decoded skeleton (or without one), and DOC.
 *
 * The custom mutator re-stamps every CRC after libFuzzer's mutation on
 * half of the runs, so that mutations reach the structural checks behind
 * the CRCs instead of stopping at them.
 */
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "mlod_pack.h"

size_t LLVMFuzzerMutate(uint8_t *data, size_t size, size_t max_size);
size_t LLVMFuzzerCustomMutator(uint8_t *data, size_t size, size_t max_size, unsigned int seed);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static uint32_t get32(const uint8_t *p)
{
	return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static void put32(uint8_t *p, uint32_t v)
{
	p[0] = (uint8_t)v, p[1] = (uint8_t)(v >> 8), p[2] = (uint8_t)(v >> 16), p[3] = (uint8_t)(v >> 24);
}

static void restamp(uint8_t *d, size_t n)
{
	if (n < 32)
		return;
	uint64_t count = get32(d + 12), toc_end = 32 + 48 * count;
	if (toc_end <= n) {
		for (uint64_t i = 0; i < count; i++) {
			uint8_t *e = d + 32 + 48 * i;
			uint64_t off = get32(e + 16) | (uint64_t)get32(e + 20) << 32, sz = get32(e + 24);
			if (off <= n && sz <= n - off)
				put32(e + 32, mlod_pack_crc32(0, d + off, (size_t)sz));
		}
		put32(d + 24, mlod_pack_crc32(0, d + 32, (size_t)(toc_end - 32)));
	}
	put32(d + 28, mlod_pack_crc32(0, d, 28));
}

size_t LLVMFuzzerCustomMutator(uint8_t *data, size_t size, size_t max_size, unsigned int seed)
{
	size = LLVMFuzzerMutate(data, size, max_size);
	if (seed & 1)
		restamp(data, size);
	return size;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	mlod_pack p;
	mlod_error e;
	if (mlod_pack_open(data, size, &p, &e) != MLOD_OK)
		return 0;
	mlod_pack_info info;
	mlod_pack_decode_info(&p, data, size, &info, &e);
	mlod_pack_info_free(&info);
	mlod_pack_skeleton skel;
	int have_skel = mlod_pack_decode_skeleton(&p, data, size, &skel, &e) == MLOD_OK;
	for (uint32_t i = 0; i < p.chunk_count; i++) {
		const mlod_pack_chunk *c = &p.chunks[i];
		if (c->type == MLOD_CHUNK_SKELETON && c->level > 0 && have_skel) {
			mlod_pack_skel_level l;
			mlod_pack_decode_skel_level(&p, i, data, size, &skel, &l, &e);
			mlod_pack_skel_level_free(&l);
		} else if (c->type == MLOD_CHUNK_MESH) {
			mlod_pack_mesh m;
			mlod_pack_decode_mesh(&p, i, data, size, have_skel ? &skel : NULL, &m, &e);
			mlod_pack_mesh_free(&m);
		} else if (c->type == MLOD_CHUNK_MOTION) {
			mlod_pack_motion m;
			mlod_pack_decode_motion(&p, i, data, size, have_skel ? &skel : NULL, &m, &e);
			mlod_pack_motion_free(&m);
		}
	}
	const void *glb;
	size_t glb_size;
	mlod_pack_doc(&p, data, size, &glb, &glb_size, &e);
	mlod_pack_doc_bytes doc;
	mlod_pack_decode_doc(&p, data, size, &doc, &e); /* also with the entropy stage */
	mlod_pack_doc_free(&doc);
	mlod_pack_skeleton_free(&skel);
	mlod_pack_close(&p);
	return 0;
}
