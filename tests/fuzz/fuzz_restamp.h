/*
 * fuzz_restamp.h: the custom mutator of the pack targets (fuzz_pack.c,
 * fuzz_unpack.c). It re-stamps every CRC after libFuzzer's mutation on
 * half of the runs, so that mutations reach the structural checks behind
 * the CRCs instead of stopping at them.
 */
#ifndef MLOD_FUZZ_RESTAMP_H
#define MLOD_FUZZ_RESTAMP_H

#include <stddef.h>
#include <stdint.h>

#include "mlod_pack.h"

size_t LLVMFuzzerMutate(uint8_t *data, size_t size, size_t max_size);
size_t LLVMFuzzerCustomMutator(uint8_t *data, size_t size, size_t max_size, unsigned int seed);

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

#endif
