/*
 * rd_open.c: the pack reader's header and TOC (mlod_pack_open), its
 * allocations, the CRC and the names of types, codecs and layers.
 * The reader is the rd_*.c files; pack_internal.h says what they share.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ZSTD_createDCtx_advanced (the allocator hooks) is in zstd's advanced
 * API; libzstd exports it. */
#define ZSTD_STATIC_LINKING_ONLY
#include <zstd.h>

#define MLOD_PACK_READER /* pack_internal.h: the reader's own part */
#include "pack_internal.h"

/* The reader's allocations, all through the pack's allocator: zeroed. */
void *pk_calloc(const mlod_pack_alloc *a, size_t n, size_t size)
{
	if (size && n > SIZE_MAX / size)
		return NULL;
	size_t bytes = n * size > 0 ? n * size : 1;
	void *p = a && a->malloc && a->free ? a->malloc(a->user, bytes) : malloc(bytes);
	if (p)
		memset(p, 0, bytes);
	return p;
}

/* As pk_calloc, not zeroed: for scratch written before it is read. */
void *pk_malloc(const mlod_pack_alloc *a, size_t n, size_t size)
{
	if (size && n > SIZE_MAX / size)
		return NULL;
	size_t bytes = n * size > 0 ? n * size : 1;
	return a && a->malloc && a->free ? a->malloc(a->user, bytes) : malloc(bytes);
}

void pk_free(const mlod_pack_alloc *a, void *p)
{
	if (!p)
		return;
	if (a && a->malloc && a->free)
		a->free(a->user, p);
	else
		free(p);
}


_Static_assert(sizeof(float) == 4, "f32 is float");
_Static_assert(sizeof(mlod_pack_info_rec) == 80, "INFO record is 80 bytes");
_Static_assert(sizeof(mlod_pack_joint_rec) == 116, "joint record is 116 bytes");
_Static_assert(sizeof(mlod_pack_skin_rec) == 12, "skin record is 12 bytes");
_Static_assert(sizeof(mlod_pack_part_rec) == 200, "part record is 200 bytes");
_Static_assert(sizeof(mlod_pack_channel_rec) == 20, "channel record is 20 bytes");

static const uint32_t crc_table[256] = {
	0x00000000u, 0x77073096u, 0xee0e612cu, 0x990951bau, 0x076dc419u, 0x706af48fu,
	0xe963a535u, 0x9e6495a3u, 0x0edb8832u, 0x79dcb8a4u, 0xe0d5e91eu, 0x97d2d988u,
	0x09b64c2bu, 0x7eb17cbdu, 0xe7b82d07u, 0x90bf1d91u, 0x1db71064u, 0x6ab020f2u,
	0xf3b97148u, 0x84be41deu, 0x1adad47du, 0x6ddde4ebu, 0xf4d4b551u, 0x83d385c7u,
	0x136c9856u, 0x646ba8c0u, 0xfd62f97au, 0x8a65c9ecu, 0x14015c4fu, 0x63066cd9u,
	0xfa0f3d63u, 0x8d080df5u, 0x3b6e20c8u, 0x4c69105eu, 0xd56041e4u, 0xa2677172u,
	0x3c03e4d1u, 0x4b04d447u, 0xd20d85fdu, 0xa50ab56bu, 0x35b5a8fau, 0x42b2986cu,
	0xdbbbc9d6u, 0xacbcf940u, 0x32d86ce3u, 0x45df5c75u, 0xdcd60dcfu, 0xabd13d59u,
	0x26d930acu, 0x51de003au, 0xc8d75180u, 0xbfd06116u, 0x21b4f4b5u, 0x56b3c423u,
	0xcfba9599u, 0xb8bda50fu, 0x2802b89eu, 0x5f058808u, 0xc60cd9b2u, 0xb10be924u,
	0x2f6f7c87u, 0x58684c11u, 0xc1611dabu, 0xb6662d3du, 0x76dc4190u, 0x01db7106u,
	0x98d220bcu, 0xefd5102au, 0x71b18589u, 0x06b6b51fu, 0x9fbfe4a5u, 0xe8b8d433u,
	0x7807c9a2u, 0x0f00f934u, 0x9609a88eu, 0xe10e9818u, 0x7f6a0dbbu, 0x086d3d2du,
	0x91646c97u, 0xe6635c01u, 0x6b6b51f4u, 0x1c6c6162u, 0x856530d8u, 0xf262004eu,
	0x6c0695edu, 0x1b01a57bu, 0x8208f4c1u, 0xf50fc457u, 0x65b0d9c6u, 0x12b7e950u,
	0x8bbeb8eau, 0xfcb9887cu, 0x62dd1ddfu, 0x15da2d49u, 0x8cd37cf3u, 0xfbd44c65u,
	0x4db26158u, 0x3ab551ceu, 0xa3bc0074u, 0xd4bb30e2u, 0x4adfa541u, 0x3dd895d7u,
	0xa4d1c46du, 0xd3d6f4fbu, 0x4369e96au, 0x346ed9fcu, 0xad678846u, 0xda60b8d0u,
	0x44042d73u, 0x33031de5u, 0xaa0a4c5fu, 0xdd0d7cc9u, 0x5005713cu, 0x270241aau,
	0xbe0b1010u, 0xc90c2086u, 0x5768b525u, 0x206f85b3u, 0xb966d409u, 0xce61e49fu,
	0x5edef90eu, 0x29d9c998u, 0xb0d09822u, 0xc7d7a8b4u, 0x59b33d17u, 0x2eb40d81u,
	0xb7bd5c3bu, 0xc0ba6cadu, 0xedb88320u, 0x9abfb3b6u, 0x03b6e20cu, 0x74b1d29au,
	0xead54739u, 0x9dd277afu, 0x04db2615u, 0x73dc1683u, 0xe3630b12u, 0x94643b84u,
	0x0d6d6a3eu, 0x7a6a5aa8u, 0xe40ecf0bu, 0x9309ff9du, 0x0a00ae27u, 0x7d079eb1u,
	0xf00f9344u, 0x8708a3d2u, 0x1e01f268u, 0x6906c2feu, 0xf762575du, 0x806567cbu,
	0x196c3671u, 0x6e6b06e7u, 0xfed41b76u, 0x89d32be0u, 0x10da7a5au, 0x67dd4accu,
	0xf9b9df6fu, 0x8ebeeff9u, 0x17b7be43u, 0x60b08ed5u, 0xd6d6a3e8u, 0xa1d1937eu,
	0x38d8c2c4u, 0x4fdff252u, 0xd1bb67f1u, 0xa6bc5767u, 0x3fb506ddu, 0x48b2364bu,
	0xd80d2bdau, 0xaf0a1b4cu, 0x36034af6u, 0x41047a60u, 0xdf60efc3u, 0xa867df55u,
	0x316e8eefu, 0x4669be79u, 0xcb61b38cu, 0xbc66831au, 0x256fd2a0u, 0x5268e236u,
	0xcc0c7795u, 0xbb0b4703u, 0x220216b9u, 0x5505262fu, 0xc5ba3bbeu, 0xb2bd0b28u,
	0x2bb45a92u, 0x5cb36a04u, 0xc2d7ffa7u, 0xb5d0cf31u, 0x2cd99e8bu, 0x5bdeae1du,
	0x9b64c2b0u, 0xec63f226u, 0x756aa39cu, 0x026d930au, 0x9c0906a9u, 0xeb0e363fu,
	0x72076785u, 0x05005713u, 0x95bf4a82u, 0xe2b87a14u, 0x7bb12baeu, 0x0cb61b38u,
	0x92d28e9bu, 0xe5d5be0du, 0x7cdcefb7u, 0x0bdbdf21u, 0x86d3d2d4u, 0xf1d4e242u,
	0x68ddb3f8u, 0x1fda836eu, 0x81be16cdu, 0xf6b9265bu, 0x6fb077e1u, 0x18b74777u,
	0x88085ae6u, 0xff0f6a70u, 0x66063bcau, 0x11010b5cu, 0x8f659effu, 0xf862ae69u,
	0x616bffd3u, 0x166ccf45u, 0xa00ae278u, 0xd70dd2eeu, 0x4e048354u, 0x3903b3c2u,
	0xa7672661u, 0xd06016f7u, 0x4969474du, 0x3e6e77dbu, 0xaed16a4au, 0xd9d65adcu,
	0x40df0b66u, 0x37d83bf0u, 0xa9bcae53u, 0xdebb9ec5u, 0x47b2cf7fu, 0x30b5ffe9u,
	0xbdbdf21cu, 0xcabac28au, 0x53b39330u, 0x24b4a3a6u, 0xbad03605u, 0xcdd70693u,
	0x54de5729u, 0x23d967bfu, 0xb3667a2eu, 0xc4614ab8u, 0x5d681b02u, 0x2a6f2b94u,
	0xb40bbe37u, 0xc30c8ea1u, 0x5a05df1bu, 0x2d02ef8du,
};

uint32_t mlod_pack_crc32(uint32_t crc, const void *data, size_t size)
{
	const uint8_t *p = data;
	crc = ~crc;
	for (size_t i = 0; i < size; i++)
		crc = crc_table[(crc ^ p[i]) & 0xffu] ^ (crc >> 8);
	return ~crc;
}

/* ------------------------------------------------------------------ */
/* Small helpers                                                       */
/* ------------------------------------------------------------------ */

/* The chunk's name in messages: "MESH level 2", "MOTION level 1 of clip 0". */
void pk_chunk_label(uint32_t type, unsigned level, unsigned item, char *buf, size_t n)
{
	switch (type) {
	case MLOD_CHUNK_INFO: snprintf(buf, n, "INFO"); break;
	case MLOD_CHUNK_SKELETON:
		if (level == 0)
			snprintf(buf, n, "SKELETON");
		else
			snprintf(buf, n, "SKELETON level %u", level);
		break;
	case MLOD_CHUNK_MESH: snprintf(buf, n, "MESH level %u", level); break;
	case MLOD_CHUNK_MOTION: snprintf(buf, n, "MOTION level %u of clip %u", level, item); break;
	case MLOD_CHUNK_DOC: snprintf(buf, n, "DOC"); break;
	default: snprintf(buf, n, "chunk of unknown type '%s'", tagn(type).s); break;
	}
}

static int known_type(uint32_t type)
{
	return type == MLOD_CHUNK_INFO || type == MLOD_CHUNK_SKELETON || type == MLOD_CHUNK_MESH ||
	       type == MLOD_CHUNK_MOTION || type == MLOD_CHUNK_DOC;
}

/* The position of a known chunk in the format's order (strictly increasing
 * along the TOC): INFO, SKELETON, skeleton levels coarsest first, then per
 * rank from the coarsest the mesh level and the motion levels by clip, DOC.
 * mesh_top and motion_top are the TOC's coarsest MESH and MOTION levels:
 * MESH level L ranks mesh_top - L, MOTION level L motion_top - L (0 the
 * coarsest of each layer). The writers before the coarsest of both layers
 * came first ranked both from 65535 (level L with level L, the coarsest
 * motion level after mesh level 0 when a clip has fewer levels): a TOC
 * may follow either order. */
static uint64_t order_key(const mlod_pack_chunk *c, unsigned mesh_top, unsigned motion_top)
{
	uint64_t inv = 65535u - c->level;
	switch (c->type) {
	case MLOD_CHUNK_INFO: return 0;
	case MLOD_CHUNK_SKELETON: return c->level == 0 ? (uint64_t)1 << 40 : (uint64_t)2 << 40 | inv << 24;
	case MLOD_CHUNK_MESH: return (uint64_t)3 << 40 | (uint64_t)(mesh_top - c->level) << 24;
	case MLOD_CHUNK_MOTION:
		return (uint64_t)3 << 40 | (uint64_t)(motion_top - c->level) << 24 | (uint64_t)1 << 16 | c->item;
	default: return (uint64_t)4 << 40;
	}
}

/* ------------------------------------------------------------------ */
/* The entropy stage's decoder, made at open                           */
/* ------------------------------------------------------------------ */

static void *zs_alloc(void *user, size_t size)
{
	const mlod_pack_alloc *a = user;
	return a->malloc(a->user, size);
}

static void zs_free(void *user, void *p)
{
	const mlod_pack_alloc *a = user;
	if (p)
		a->free(a->user, p);
}

static zdec *zdec_new(const mlod_pack_alloc *alloc)
{
	zdec *d = pk_calloc(alloc, 1, sizeof *d);
	if (!d)
		return NULL;
	if (alloc && alloc->malloc && alloc->free) {
		d->a = *alloc;
		ZSTD_customMem mem = {zs_alloc, zs_free, &d->a};
		d->z = ZSTD_createDCtx_advanced(mem);
	} else {
		d->z = ZSTD_createDCtx();
	}
	if (!d->z) {
		pk_free(alloc, d);
		return NULL;
	}
	return d;
}

static void zdec_free(const mlod_pack_alloc *alloc, zdec *d)
{
	if (!d)
		return;
	ZSTD_freeDCtx(d->z);
	pk_free(alloc, d);
}

size_t mlod_pack_decoder_bytes(const mlod_pack *p)
{
	const zdec *d = p ? p->zstd : NULL;
	return d ? sizeof *d + ZSTD_sizeof_DCtx(d->z) : 0;
}

/* ------------------------------------------------------------------ */
/* Header and TOC                                                      */
/* ------------------------------------------------------------------ */

mlod_result mlod_pack_open(const void *data, size_t size, mlod_pack *out, mlod_error *err)
{
	return mlod_pack_open_alloc(data, size, NULL, out, err);
}

mlod_result mlod_pack_open_alloc(const void *data, size_t size, const mlod_pack_alloc *alloc, mlod_pack *out,
                                 mlod_error *err)
{
	if (!out)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_pack_open: out is NULL");
	memset(out, 0, sizeof *out);
	if (!data && size)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_pack_open: data is NULL");
	const uint8_t *d = data;
	if (size < 4 || memcmp(d, MLOD_PACK_MAGIC, 4) != 0)
		return mlod_fail(err, MLOD_ERR_PARSE, "not an mlod pack: it does not start with \"MLOD\"");
	if (size < MLOD_PACK_HEADER_SIZE)
		return mlod_fail(err, MLOD_ERR_PARSE, "truncated pack: %zu bytes, shorter than the %d-byte header", size,
		                 MLOD_PACK_HEADER_SIZE);
	unsigned major = rd16(d + 4), minor = rd16(d + 6);
	if (major > MLOD_PACK_MAJOR)
		return mlod_fail(err, MLOD_ERR_UNSUPPORTED, "pack format %u.%u is newer than this reader's %d.x", major,
		                 minor, MLOD_PACK_MAJOR);
	if (major == 0)
		return mlod_fail(err, MLOD_ERR_PARSE, "pack format %u.%u does not exist (the first is 1.0)", major, minor);
	if (major < MLOD_PACK_MAJOR_OLDEST)
		return mlod_fail(err, MLOD_ERR_UNSUPPORTED,
		                 "mlod %u.%u pack: made by an older mlod-pack; pack the input again (this reader reads %d.x "
		                 "to %d.x)",
		                 major, minor, MLOD_PACK_MAJOR_OLDEST, MLOD_PACK_MAJOR);
	uint32_t hcrc = mlod_pack_crc32(0, d, 28);
	if (hcrc != rd32(d + 28))
		return mlod_fail(err, MLOD_ERR_PARSE, "pack header: CRC mismatch (stored 0x%08x, computed 0x%08x)",
		                 rd32(d + 28), hcrc);
	uint32_t flags = rd32(d + 8), n = rd32(d + 12);
	uint64_t file_size = rd64(d + 16);
	if (n > MLOD_PACK_MAX_CHUNKS)
		return mlod_fail(err, MLOD_ERR_PARSE, "pack header: %u chunks, more than the format's %d", n,
		                 MLOD_PACK_MAX_CHUNKS);
	uint64_t toc_end = MLOD_PACK_HEADER_SIZE + (uint64_t)n * MLOD_PACK_TOC_ENTRY_SIZE;
	if (size < toc_end)
		return mlod_fail(err, MLOD_ERR_PARSE, "truncated pack: the TOC of %u chunks ends at byte %llu, the data has %zu",
		                 n, (unsigned long long)toc_end, size);
	uint32_t tcrc = mlod_pack_crc32(0, d + MLOD_PACK_HEADER_SIZE, (size_t)(toc_end - MLOD_PACK_HEADER_SIZE));
	if (tcrc != rd32(d + 24))
		return mlod_fail(err, MLOD_ERR_PARSE, "pack TOC: CRC mismatch (stored 0x%08x, computed 0x%08x)", rd32(d + 24),
		                 tcrc);
	if (file_size < toc_end)
		return mlod_fail(err, MLOD_ERR_PARSE, "pack header: file size %llu is less than the header and TOC (%llu bytes)",
		                 (unsigned long long)file_size, (unsigned long long)toc_end);

	mlod_pack_chunk *chunks = NULL;
	if (n > 0) {
		chunks = pk_calloc(alloc, n, sizeof *chunks);
		if (!chunks)
			return mlod_fail(err, MLOD_ERR_NOMEM, "pack TOC: out of memory for %u entries", n);
	}
	uint64_t prev_end = toc_end, prev_key = 0, prev_key1 = 0;
	int have_prev = 0, ordered = 1, ordered1 = 1; /* in order so far: by rank, by level (the older writers') */
	mlod_result r = MLOD_OK;
	char label[64];
	unsigned mesh_top = 0, motion_top = 0; /* the coarsest level of each layer ranks 0 */
	for (uint32_t i = 0; i < n; i++) {
		const uint8_t *e = d + MLOD_PACK_HEADER_SIZE + (size_t)i * MLOD_PACK_TOC_ENTRY_SIZE;
		unsigned lv = rd16(e + 6);
		if (rd32(e) == MLOD_CHUNK_MESH && lv > mesh_top)
			mesh_top = lv;
		if (rd32(e) == MLOD_CHUNK_MOTION && lv > motion_top)
			motion_top = lv;
	}
	for (uint32_t i = 0; i < n && r == MLOD_OK; i++) {
		const uint8_t *e = d + MLOD_PACK_HEADER_SIZE + (size_t)i * MLOD_PACK_TOC_ENTRY_SIZE;
		mlod_pack_chunk *c = &chunks[i];
		c->type = rd32(e);
		c->layer = e[4];
		c->codec = e[5] & 15u;
		c->entropy = e[5] >> 4;
		c->coded_size = c->entropy ? rd32(e + 12) : 0;
		c->level = rd16(e + 6);
		c->item = rd16(e + 8);
		c->flags = rd16(e + 10);
		c->offset = rd64(e + 16);
		c->stored_size = rd32(e + 24);
		c->raw_size = rd32(e + 28);
		c->crc = rd32(e + 32);
		c->error = rdf(e + 36);
		c->distance = rdf(e + 40);
		pk_chunk_label(c->type, c->level, c->item, label, sizeof label);
		if (c->offset % MLOD_PACK_ALIGN != 0) {
			r = mlod_fail(err, MLOD_ERR_PARSE, "TOC entry %u (%s): offset %llu is not %d-aligned", i, label,
			              (unsigned long long)c->offset, MLOD_PACK_ALIGN);
		} else if (c->offset < prev_end) {
			r = mlod_fail(err, MLOD_ERR_PARSE, "TOC entry %u (%s): offset %llu overlaps the %s, which ends at %llu", i,
			              label, (unsigned long long)c->offset, i == 0 ? "header and TOC" : "previous chunk",
			              (unsigned long long)prev_end);
		} else if (c->offset > file_size || c->stored_size > file_size - c->offset) {
			r = mlod_fail(err, MLOD_ERR_PARSE, "TOC entry %u (%s): bytes %llu to %llu lie outside the file (%llu bytes)",
			              i, label, (unsigned long long)c->offset,
			              (unsigned long long)c->offset + c->stored_size, (unsigned long long)file_size);
		} else if (c->entropy && major < 5) {
			r = mlod_fail(err, MLOD_ERR_PARSE, "TOC entry %u (%s): codec 0x%02x: an entropy stage in a %u.%u pack "
			              "(format 5.0 added them)", i, label, e[5], major, minor);
		} else if (c->entropy == MLOD_ENTROPY_ZSTD_PREFIX && major < 6) {
			r = mlod_fail(err, MLOD_ERR_PARSE, "TOC entry %u (%s): codec 0x%02x: a zstd prefix stage in a %u.%u pack "
			              "(format 6.0 added it)", i, label, e[5], major, minor);
		} else if (c->entropy == MLOD_ENTROPY_ZSTD_PREFIX && c->type != MLOD_CHUNK_MESH &&
		           !(c->type == MLOD_CHUNK_SKELETON && c->level > 0)) {
			r = mlod_fail(err, MLOD_ERR_PARSE, "TOC entry %u (%s): the zstd prefix stage is for MESH and skeleton "
			              "levels only (the chunks they need are its prefix)", i, label);
		} else if (c->entropy == MLOD_ENTROPY_ZSTD_PREFIX && c->codec == MLOD_CODEC_DRACO) {
			r = mlod_fail(err, MLOD_ERR_PARSE, "TOC entry %u (%s): a Draco chunk stands alone: no zstd prefix stage", i,
			              label);
		} else if (c->entropy && c->type == MLOD_CHUNK_INFO) {
			r = mlod_fail(err, MLOD_ERR_PARSE, "TOC entry %u (%s): INFO has no entropy stage", i, label);
		} else if (c->entropy && (c->coded_size < 4 || c->coded_size > c->raw_size)) {
			r = mlod_fail(err, MLOD_ERR_PARSE, "TOC entry %u (%s): coded size %u is not 4 to its raw size %u", i, label,
			              c->coded_size, c->raw_size);
		} else if (c->codec <= MLOD_CODEC_DRACO &&
		           c->raw_size > (uint64_t)PACK_MAX_EXPAND * (c->entropy ? c->coded_size : c->stored_size)) {
			r = mlod_fail(err, MLOD_ERR_PARSE, "TOC entry %u (%s): raw size %u is more than %d times its %u-byte "
			              "container (the stream codecs expand no more)", i, label, c->raw_size, PACK_MAX_EXPAND,
			              c->entropy ? c->coded_size : c->stored_size);
		} else if (!isfinite(c->error) || c->error < 0 || !isfinite(c->distance) || c->distance < 0) {
			r = mlod_fail(err, MLOD_ERR_PARSE, "TOC entry %u (%s): error %g and switch distance %g must be finite and >= 0",
			              i, label, (double)c->error, (double)c->distance);
		} else if (known_type(c->type)) {
			unsigned want_layer = c->type == MLOD_CHUNK_SKELETON ? MLOD_LAYER_SKELETON
			                      : c->type == MLOD_CHUNK_MESH   ? MLOD_LAYER_MESH
			                      : c->type == MLOD_CHUNK_MOTION ? MLOD_LAYER_MOTION
			                                                     : MLOD_LAYER_NONE;
			uint64_t key = order_key(c, mesh_top, motion_top), key1 = order_key(c, 65535u, 65535u);
			ordered = ordered && (!have_prev || key > prev_key);
			ordered1 = ordered1 && (!have_prev || key1 > prev_key1);
			if (c->layer != want_layer)
				r = mlod_fail(err, MLOD_ERR_PARSE, "TOC entry %u (%s): layer %u, expected %u (%s)", i, label,
				              c->layer, want_layer, mlod_pack_layer_name(want_layer));
			else if ((c->type == MLOD_CHUNK_INFO || c->type == MLOD_CHUNK_DOC) && c->level != 0)
				r = mlod_fail(err, MLOD_ERR_PARSE, "TOC entry %u (%s): level %u, expected 0", i, label, c->level);
			else if (c->type != MLOD_CHUNK_MOTION && c->item != 0)
				r = mlod_fail(err, MLOD_ERR_PARSE, "TOC entry %u (%s): item %u, expected 0", i, label, c->item);
			else if (c->codec == MLOD_CODEC_DRACO && c->type != MLOD_CHUNK_MESH)
				r = mlod_fail(err, MLOD_ERR_PARSE, "TOC entry %u (%s): the Draco codec is for MESH chunks only", i,
				              label);
			else if (have_prev && key == prev_key)
				r = mlod_fail(err, MLOD_ERR_PARSE, "TOC entry %u (%s): a second chunk of that type, level and item", i,
				              label);
			else if (!ordered && !ordered1)
				r = mlod_fail(err, MLOD_ERR_PARSE,
				              "TOC entry %u (%s) is out of order: chunks go INFO, SKELETON, skeleton levels, then mesh "
				              "and motion levels coarsest first, DOC last",
				              i, label);
			prev_key = key;
			prev_key1 = key1;
			have_prev = 1;
		}
		prev_end = c->offset + c->stored_size;
	}
	if (r == MLOD_OK && file_size != prev_end)
		r = mlod_fail(err, MLOD_ERR_PARSE, "pack header: file size %llu, but the %s ends at byte %llu",
		              (unsigned long long)file_size, n ? "last chunk" : "TOC", (unsigned long long)prev_end);
	int zstd = 0;
	for (uint32_t i = 0; r == MLOD_OK && i < n; i++)
		zstd |= chunks[i].entropy == MLOD_ENTROPY_ZSTD || chunks[i].entropy == MLOD_ENTROPY_ZSTD_PREFIX;
	/* A prefix-coded MESH level needs a coarser MESH level (its prefix):
	 * the coarsest has none; a skeleton level needs SKELETON. The order
	 * check put them first. */
	for (uint32_t i = 0, coarser = 0, full = 0; r == MLOD_OK && i < n; i++) {
		if (chunks[i].type == MLOD_CHUNK_SKELETON && chunks[i].level == 0)
			full = 1;
		if (chunks[i].type == MLOD_CHUNK_SKELETON && chunks[i].entropy == MLOD_ENTROPY_ZSTD_PREFIX && !full) {
			pk_chunk_label(chunks[i].type, chunks[i].level, chunks[i].item, label, sizeof label);
			r = mlod_fail(err, MLOD_ERR_PARSE, "TOC entry %u (%s): the zstd prefix stage without a SKELETON chunk "
			              "before it for a prefix", i, label);
		}
		if (chunks[i].type != MLOD_CHUNK_MESH)
			continue;
		if (chunks[i].entropy == MLOD_ENTROPY_ZSTD_PREFIX && !coarser) {
			pk_chunk_label(chunks[i].type, chunks[i].level, chunks[i].item, label, sizeof label);
			r = mlod_fail(err, MLOD_ERR_PARSE, "TOC entry %u (%s): the zstd prefix stage on the coarsest MESH level, "
			              "which has no coarser level for a prefix", i, label);
		}
		coarser = 1;
	}
	zdec *zd = NULL;
	if (r == MLOD_OK && zstd && !(zd = zdec_new(alloc)))
		r = mlod_fail(err, MLOD_ERR_NOMEM, "pack TOC: out of memory for the zstd decoder");
	if (r != MLOD_OK) {
		pk_free(alloc, chunks);
		return r;
	}
	out->zstd = zd;
	out->major = (uint16_t)major;
	out->minor = (uint16_t)minor;
	out->flags = flags;
	out->file_size = file_size;
	out->chunk_count = n;
	out->chunks = chunks;
	if (alloc && alloc->malloc && alloc->free)
		out->alloc = *alloc;
	else
		memset(&out->alloc, 0, sizeof out->alloc);
	return MLOD_OK;
}

void mlod_pack_close(mlod_pack *p)
{
	if (!p)
		return;
	pk_free(&p->alloc, p->chunks);
	zdec_free(&p->alloc, p->zstd);
	memset(p, 0, sizeof *p);
}

int mlod_pack_find(const mlod_pack *p, uint32_t type, unsigned level, unsigned item)
{
	if (!p)
		return -1;
	for (uint32_t i = 0; i < p->chunk_count; i++) {
		const mlod_pack_chunk *c = &p->chunks[i];
		if (c->type == type && c->level == level && c->item == item)
			return (int)i;
	}
	return -1;
}

mlod_result pk_find_one(const mlod_pack *p, uint32_t type, void *out, size_t out_size, const char *fn, int *ci,
                        mlod_error *err)
{
	if (!out)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "%s: out is NULL", fn);
	memset(out, 0, out_size);
	if (!p)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "%s: the pack is NULL", fn);
	*ci = mlod_pack_find(p, type, 0, 0);
	if (*ci < 0) {
		char label[64];
		pk_chunk_label(type, 0, 0, label, sizeof label);
		return mlod_fail(err, MLOD_ERR_PARSE, "the pack has no %s chunk", label);
	}
	return MLOD_OK;
}

const char *mlod_pack_type_name(uint32_t type)
{
	switch (type) {
	case MLOD_CHUNK_INFO: return "INFO";
	case MLOD_CHUNK_SKELETON: return "SKEL";
	case MLOD_CHUNK_MESH: return "MESH";
	case MLOD_CHUNK_MOTION: return "ANIM";
	case MLOD_CHUNK_DOC: return "DOC";
	}
	return "unknown";
}

const char *mlod_pack_codec_name(unsigned codec)
{
	switch (codec) {
	case MLOD_CODEC_NONE: return "none";
	case MLOD_CODEC_MESHOPT: return "meshopt";
	case MLOD_CODEC_DRACO: return "draco";
	}
	return "unknown";
}

const char *mlod_pack_entropy_name(unsigned entropy)
{
	switch (entropy) {
	case MLOD_ENTROPY_NONE: return "none";
	case MLOD_ENTROPY_ZSTD: return "zstd";
	case MLOD_ENTROPY_ZSTD_PREFIX: return "zstd-prefix";
	}
	return "unknown";
}

const char *mlod_pack_layer_name(unsigned layer)
{
	switch (layer) {
	case MLOD_LAYER_NONE: return "none";
	case MLOD_LAYER_SKELETON: return "skeleton";
	case MLOD_LAYER_MESH: return "mesh";
	case MLOD_LAYER_MOTION: return "motion";
	}
	return "unknown";
}
