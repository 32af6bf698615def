/*
 * pack.c: the one reader of the .mlod pack format (mlod_pack.h, mlod(5)).
 *
 * Everything read from the file is checked before it is used: the header
 * and TOC by mlod_pack_open, each chunk's CRC, stream container, stream
 * sizes, record counts and indices by its decode. Sizes are computed in
 * uint64_t, so no product or sum can wrap. A decode sizes its one
 * allocation (the block) from the stream headers, whose decoded sizes add
 * up to the TOC's raw size, and refuses one above PACK_MAX_BLOCK before
 * allocating. Meshopt-coded streams are decoded into a temporary buffer
 * (freed before the decode returns); raw streams are read in place.
 * Every allocation is the pack's allocator's (mlod_pack_open_alloc; malloc
 * by default), and a block starts with that allocator, for *_free.
 * A MESH level (layout b2, mlod(5)) also decodes the vertex blocks of every
 * coarser MESH chunk, each checked like any chunk, into scratch sized from
 * their TOC raw sizes (freed before the decode returns), then gathers the
 * vertices its indices use; its block is sized from its part records,
 * whose vertex counts the gathering must meet exactly (the runtime's
 * mlod_pack_decode_mesh_reserve, pack_internal.h, is called with those
 * records before the block is allocated).
 *
 * Byte order: the format is little-endian, and so must the host be (the
 * index codec's output and the records are read with memcpy); the
 * preprocessor check below refuses a big-endian target where the compiler
 * tells. Fields are read with memcpy, so the data needs no alignment.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <meshoptimizer.h>
/* ZSTD_createDCtx_advanced (the allocator hooks) is in zstd's advanced
 * API; libzstd exports it. */
#define ZSTD_STATIC_LINKING_ONLY
#include <zstd.h>

#include "mlod_pack.h"
#include "pack_internal.h"
#if MLOD_DRACO
#include "rt_draco.h"
#endif

/* The reader's allocations, all through the pack's allocator: zeroed. */
static void *pk_calloc(const mlod_pack_alloc *a, size_t n, size_t size)
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
static void *pk_malloc(const mlod_pack_alloc *a, size_t n, size_t size)
{
	if (size && n > SIZE_MAX / size)
		return NULL;
	size_t bytes = n * size > 0 ? n * size : 1;
	return a && a->malloc && a->free ? a->malloc(a->user, bytes) : malloc(bytes);
}

static void pk_free(const mlod_pack_alloc *a, void *p)
{
	if (!p)
		return;
	if (a && a->malloc && a->free)
		a->free(a->user, p);
	else
		free(p);
}

#if defined(__BYTE_ORDER__) && defined(__ORDER_LITTLE_ENDIAN__) && __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "mlod's pack reader assumes a little-endian host"
#endif

_Static_assert(sizeof(float) == 4, "f32 is float");
_Static_assert(sizeof(mlod_pack_info_rec) == 80, "INFO record is 80 bytes");
_Static_assert(sizeof(mlod_pack_joint_rec) == 116, "joint record is 116 bytes");
_Static_assert(sizeof(mlod_pack_skin_rec) == 12, "skin record is 12 bytes");
_Static_assert(sizeof(mlod_pack_part_rec) == 200, "part record is 200 bytes");
_Static_assert(sizeof(mlod_pack_channel_rec) == 20, "channel record is 20 bytes");

/* The largest block (and temporary buffer) a decode allocates. */
#define PACK_MAX_BLOCK ((uint64_t)1 << 30)
/* meshopt's codecs decode at most 64 bytes per stored byte (a 16-byte
 * group of zeros costs 2 header bits), plus a little: a stream claiming
 * more is refused before anything is sized from it, and so is a chunk
 * whose TOC raw size is more than this times its container. */
#define PACK_MAX_EXPAND 64
/* A Draco MESH chunk's decoded level against its container (mlod(5)):
 * the part records size every allocation before Draco decodes, so they
 * may not claim more than this many times the container's bytes. The
 * writer's levels measure up to about 16 (tubeman level 0: 22,944 bytes
 * of container, about 365 KB decoded). */
#define PACK_DRACO_MAX_EXPAND 1024

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

static uint16_t rd16(const uint8_t *p)
{
	return (uint16_t)(p[0] | p[1] << 8);
}

static uint32_t rd32(const uint8_t *p)
{
	return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static uint64_t rd64(const uint8_t *p)
{
	return (uint64_t)rd32(p) | (uint64_t)rd32(p + 4) << 32;
}

static float rdf(const uint8_t *p)
{
	uint32_t u = rd32(p);
	float f;
	memcpy(&f, &u, 4);
	return f;
}

static int16_t rdi16(const uint8_t *p)
{
	uint16_t u = rd16(p);
	return u < 0x8000u ? (int16_t)u : (int16_t)((int32_t)u - 65536);
}

static uint64_t pad4(uint64_t n)
{
	return (n + 3) & ~(uint64_t)3;
}

static uint64_t round8(uint64_t n)
{
	return (n + 7) & ~(uint64_t)7;
}

static int all_finite(const float *v, size_t n)
{
	for (size_t i = 0; i < n; i++)
		if (!isfinite(v[i]))
			return 0;
	return 1;
}

/* A fourcc as printable text. */
typedef struct tagname {
	char s[5];
} tagname;

static tagname tagn(uint32_t tag)
{
	tagname t;
	for (int i = 0; i < 4; i++) {
		unsigned char ch = (unsigned char)(tag >> (8 * i));
		t.s[i] = ch >= 0x20 && ch < 0x7f ? (char)ch : '?';
	}
	t.s[4] = 0;
	return t;
}

/* The chunk's name in messages: "MESH level 2", "MOTION level 1 of clip 0". */
static void chunk_label(uint32_t type, unsigned level, unsigned item, char *buf, size_t n)
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
/* The entropy stage's decoder                                         */
/* ------------------------------------------------------------------ */

/* zstd's decoder context, one per opened pack (its set-up costs about as
 * much as decoding a small chunk, so the decodes share it), made with the
 * pack's allocator: a block holding a copy of the allocator (zstd's hooks
 * point to it, so the pack struct may be copied) and the context. */
typedef struct zdec {
	mlod_pack_alloc a;
	ZSTD_DCtx *z;
} zdec;

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
		chunk_label(c->type, c->level, c->item, label, sizeof label);
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
			chunk_label(chunks[i].type, chunks[i].level, chunks[i].item, label, sizeof label);
			r = mlod_fail(err, MLOD_ERR_PARSE, "TOC entry %u (%s): the zstd prefix stage without a SKELETON chunk "
			              "before it for a prefix", i, label);
		}
		if (chunks[i].type != MLOD_CHUNK_MESH)
			continue;
		if (chunks[i].entropy == MLOD_ENTROPY_ZSTD_PREFIX && !coarser) {
			chunk_label(chunks[i].type, chunks[i].level, chunks[i].item, label, sizeof label);
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

/* ------------------------------------------------------------------ */
/* A chunk's stream container                                          */
/* ------------------------------------------------------------------ */

typedef struct stream {
	uint32_t index, tag, count, elsize, codec, stored;
	const uint8_t *src; /* the stored bytes */
} stream;

typedef struct cx {
	const mlod_pack_chunk *c;
	char label[64];
	const uint8_t *base; /* the chunk's stream container: its stored bytes, or
	                      * plain for a chunk with an entropy stage */
	uint64_t size;        /* the container's bytes at base */
	uint8_t *plain;       /* the entropy stage's output (owned) */
	zdec *zd;             /* the pack's zstd decoder */
	const uint8_t *prefix; /* MLOD_ENTROPY_ZSTD_PREFIX: the coarser MESH levels' */
	uint64_t prefix_size;  /* containers, coarsest first (the caller's) */
	uint32_t nstreams, next;
	uint64_t cursor;      /* offset in the chunk of stream next's bytes */
	uint64_t max_decoded; /* the largest meshopt-coded stream, decoded */
	uint8_t *temp;        /* aux bytes, then the decode buffer */
	uint64_t aux;
	mlod_pack_alloc alloc; /* the pack's */
	uint16_t major;       /* the pack's format */
} cx;

/* Checks the chunk's TOC entry (index, type, codec). */
static mlod_result cx_head(const mlod_pack *p, uint32_t index, uint32_t type, cx *x, mlod_error *err)
{
	memset(x, 0, sizeof *x);
	if (index >= p->chunk_count)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "pack decode: chunk %u does not exist (the pack has %u)", index,
		                 p->chunk_count);
	const mlod_pack_chunk *c = &p->chunks[index];
	x->major = p->major;
	x->c = c;
	x->alloc = p->alloc;
	x->zd = p->zstd;
	chunk_label(c->type, c->level, c->item, x->label, sizeof x->label);
	if (c->type != type) {
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "pack decode: chunk %u is %s, not a %s chunk", index, x->label,
		                 mlod_pack_type_name(type));
	}
#if !MLOD_DRACO
	if (c->codec == MLOD_CODEC_DRACO)
		return mlod_fail(err, MLOD_ERR_UNSUPPORTED, "%s: Draco chunks need the Draco decoder, not built in", x->label);
#endif
	if (c->codec == MLOD_CODEC_DRACO && c->type != MLOD_CHUNK_MESH) /* open refuses it; a caller's TOC may not */
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: the Draco codec is for MESH chunks only", x->label);
	if (c->codec != MLOD_CODEC_NONE && c->codec != MLOD_CODEC_MESHOPT && c->codec != MLOD_CODEC_DRACO)
		return mlod_fail(err, MLOD_ERR_UNSUPPORTED, "%s: unknown chunk codec %u", x->label, c->codec);
	if (c->entropy != MLOD_ENTROPY_NONE && c->entropy != MLOD_ENTROPY_ZSTD && c->entropy != MLOD_ENTROPY_ZSTD_PREFIX)
		return mlod_fail(err, MLOD_ERR_UNSUPPORTED, "%s: unknown entropy stage %u", x->label, c->entropy);
	return MLOD_OK;
}

/* What a zstd frame (checked whole by ZSTD_findFrameCompressedSize) can
 * decode to at most, from its blocks rather than the size its header
 * states: raw and RLE blocks give their size, a compressed block at most
 * the frame's block size. 0 for a frame it cannot walk. */
static unsigned long long zstd_bound(const uint8_t *src, size_t n)
{
	ZSTD_frameHeader fh;
	size_t at = ZSTD_frameHeaderSize(src, n);
	if (ZSTD_isError(at) || ZSTD_getFrameHeader(&fh, src, n) != 0 || fh.frameType != ZSTD_frame)
		return 0;
	unsigned long long bound = 0;
	for (;;) {
		if (n - at < 3)
			return 0;
		uint32_t h = (uint32_t)src[at] | (uint32_t)src[at + 1] << 8 | (uint32_t)src[at + 2] << 16;
		uint32_t type = (h >> 1) & 3, size = h >> 3;
		uint64_t used = type == 1 ? 1 : size;
		at += 3;
		if (type == 3 || used > n - at)
			return 0;
		at += (size_t)used;
		bound += type == 2 ? fh.blockSizeMax : size;
		if (h & 1)
			return bound;
	}
}

/* The one place that undoes an entropy stage: the chunk's stored bytes at
 * x->base (CRC checked) become its stream container in x->plain, exactly
 * the TOC's coded size (checked against the raw size at open) and nothing
 * else: the frame must say that size, hold one frame and nothing after
 * it, and decode to exactly that; the output buffer is that size, so no
 * frame can write more. The context is the pack's (zdec, made at open). */
static mlod_result cx_unpack(cx *x, mlod_error *err)
{
	const mlod_pack_chunk *c = x->c;
	uint64_t want = c->coded_size;
	if (want > PACK_MAX_BLOCK)
		return mlod_fail(err, MLOD_ERR_NOMEM, "%s: its container of %llu bytes is more than the reader's limit",
		                 x->label, (unsigned long long)want);
	unsigned long long said = ZSTD_getFrameContentSize(x->base, c->stored_size);
	if (said == ZSTD_CONTENTSIZE_ERROR)
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: not a zstd frame (its %u bytes)", x->label, c->stored_size);
	if (said == ZSTD_CONTENTSIZE_UNKNOWN)
		return mlod_fail(err, MLOD_ERR_PARSE,
		                 "%s: the zstd frame does not state its size (the TOC's coded size is %llu)", x->label,
		                 (unsigned long long)want);
	if (said != want)
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: the zstd frame says %llu bytes, the TOC's coded size is %llu",
		                 x->label, said, (unsigned long long)want);
	size_t frame = ZSTD_findFrameCompressedSize(x->base, c->stored_size);
	if (ZSTD_isError(frame) || frame != c->stored_size)
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: the zstd frame %s its %u bytes", x->label,
		                 ZSTD_isError(frame) ? "is truncated or malformed in" : "does not end at the end of",
		                 c->stored_size);
	unsigned long long bound = zstd_bound(x->base, c->stored_size);
	if (bound < want)
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: the zstd frame's %u bytes cannot decode to its stated %llu",
		                 x->label, c->stored_size, (unsigned long long)want);
	x->plain = pk_malloc(&x->alloc, 1, (size_t)want);
	if (!x->plain)
		return mlod_fail(err, MLOD_ERR_NOMEM, "%s: out of memory for its %llu-byte container", x->label,
		                 (unsigned long long)want);
	if (!x->zd)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "%s: the pack has no zstd decoder (not opened by mlod_pack_open)",
		                 x->label);
	if (c->entropy == MLOD_ENTROPY_ZSTD_PREFIX) {
		/* Only decode_mesh and a skeleton level's decode give a prefix,
		 * and open allowed the stage only on those levels. */
		if (!x->prefix || !x->prefix_size)
			return mlod_fail(err, MLOD_ERR_PARSE, "%s: coded on the containers of the chunks it needs, which were "
			                 "not given", x->label);
		if (x->prefix_size > MLOD_PACK_MAX_PREFIX)
			return mlod_fail(err, MLOD_ERR_PARSE, "%s: its prefix (the containers of the chunks it needs) is %llu "
			                 "bytes, more than the format's %llu", x->label, (unsigned long long)x->prefix_size,
			                 (unsigned long long)MLOD_PACK_MAX_PREFIX);
		size_t pr = ZSTD_DCtx_refPrefix(x->zd->z, x->prefix, (size_t)x->prefix_size);
		if (ZSTD_isError(pr))
			return mlod_fail(err, MLOD_ERR_NOMEM, "%s: zstd prefix: %s", x->label, ZSTD_getErrorName(pr));
	}
	/* ZSTD_decompressDCtx uses a referenced prefix for this frame only,
	 * but keeps the dictionary object it made of it (27,352 bytes on
	 * tubeman's mesh levels) until the next: freed here, so that the
	 * decoder stays the size mlod_pack_decoder_bytes counted at open. */
	size_t got = ZSTD_decompressDCtx(x->zd->z, x->plain, (size_t)want, x->base, c->stored_size);
	if (c->entropy == MLOD_ENTROPY_ZSTD_PREFIX)
		ZSTD_DCtx_reset(x->zd->z, ZSTD_reset_session_and_parameters);
	if (ZSTD_isError(got))
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: zstd: %s", x->label, ZSTD_getErrorName(got));
	if (got != want)
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: zstd gave %zu bytes, the TOC's coded size is %llu", x->label, got,
		                 (unsigned long long)want);
	x->base = x->plain;
	x->size = want;
	return MLOD_OK;
}

static mlod_result cx_container(cx *x, mlod_error *err);

/* Checks the chunk's bytes at x->base (CRC), undoes its entropy stage, and
 * checks its stream container (sizes add up to the container's and the
 * raw size). */
static mlod_result cx_parse(cx *x, mlod_error *err)
{
	const mlod_pack_chunk *c = x->c;
	uint32_t crc = mlod_pack_crc32(0, x->base, c->stored_size);
	if (crc != c->crc)
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: CRC mismatch (stored 0x%08x, computed 0x%08x)", x->label, c->crc,
		                 crc);
	x->size = c->stored_size;
	mlod_result r = c->entropy == MLOD_ENTROPY_NONE ? MLOD_OK : cx_unpack(x, err);
	if (r == MLOD_OK)
		r = cx_container(x, err);
	if (r != MLOD_OK) {
		pk_free(&x->alloc, x->plain);
		x->plain = NULL;
	}
	return r;
}

/* The stream container at x->base, x->size bytes. */
static mlod_result cx_container(cx *x, mlod_error *err)
{
	const mlod_pack_chunk *c = x->c;
	const char *what = c->entropy == MLOD_ENTROPY_NONE ? "" : " decoded";
	uint64_t csize = x->size;
	if (csize < 4)
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: %llu%s bytes, too short for its stream count", x->label,
		                 (unsigned long long)csize, what);
	uint32_t n = rd32(x->base);
	if (n > MLOD_PACK_MAX_STREAMS)
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: %u streams, more than the format's %d", x->label, n,
		                 MLOD_PACK_MAX_STREAMS);
	uint64_t cursor = 4 + 16 * (uint64_t)n, raw = cursor;
	if (cursor > csize)
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: %u stream headers do not fit in its %llu%s bytes", x->label, n,
		                 (unsigned long long)csize, what);
	for (uint32_t i = 0; i < n; i++) {
		const uint8_t *h = x->base + 4 + 16 * (size_t)i;
		uint32_t tag = rd32(h), count = rd32(h + 4), elsize = rd16(h + 8), codec = h[10], stored = rd32(h + 12);
		uint64_t decoded = (uint64_t)count * elsize;
		if (elsize < 1 || elsize > 256)
			return mlod_fail(err, MLOD_ERR_PARSE, "%s: stream %u '%s': element size %u is not 1 to 256", x->label, i,
			                 tagn(tag).s, elsize);
		if (codec > MLOD_SCODEC_SUM255)
			return mlod_fail(err, MLOD_ERR_PARSE, "%s: stream %u '%s': unknown stream codec %u", x->label, i,
			                 tagn(tag).s, codec);
		if (codec >= MLOD_SCODEC_PLANES && x->major < 7)
			return mlod_fail(err, MLOD_ERR_PARSE,
			                 "%s: stream %u '%s': stream codec %u in a %u.x pack (format 7.0 added it)", x->label, i,
			                 tagn(tag).s, codec, x->major);
		if (codec != MLOD_SCODEC_RAW && c->codec == MLOD_CODEC_NONE)
			return mlod_fail(err, MLOD_ERR_PARSE, "%s: stream %u '%s' is %s in a chunk of codec none", x->label, i,
			                 tagn(tag).s,
			                 codec == MLOD_SCODEC_SUM255 ? "stored without its sums"
			                 : codec >= MLOD_SCODEC_PLANES ? "in byte planes"
			                                               : "meshopt-coded");
		if (codec == MLOD_SCODEC_SUM255 && elsize != 4)
			return mlod_fail(err, MLOD_ERR_PARSE,
			                 "%s: stream %u '%s': the sum codec needs an element size of 4, not %u", x->label, i,
			                 tagn(tag).s, elsize);
		if (codec == MLOD_SCODEC_SUM255 && stored != 3 * (uint64_t)count)
			return mlod_fail(err, MLOD_ERR_PARSE, "%s: stream %u '%s': %u bytes stored for %u elements of 3 bytes",
			                 x->label, i, tagn(tag).s, stored, count);
		if (codec == MLOD_SCODEC_MESHOPT_VERTEX && elsize % 4 != 0)
			return mlod_fail(err, MLOD_ERR_PARSE,
			                 "%s: stream %u '%s': the meshopt vertex codec needs an element size that is a multiple of "
			                 "4, not %u",
			                 x->label, i, tagn(tag).s, elsize);
		if (codec == MLOD_SCODEC_MESHOPT_INDEX && elsize != 2 && elsize != 4)
			return mlod_fail(err, MLOD_ERR_PARSE,
			                 "%s: stream %u '%s': the meshopt index codec needs an element size of 2 or 4, not %u",
			                 x->label, i, tagn(tag).s, elsize);
		if (codec == MLOD_SCODEC_MESHOPT_SEQUENCE && elsize != 2 && elsize != 4)
			return mlod_fail(err, MLOD_ERR_PARSE,
			                 "%s: stream %u '%s': the meshopt index sequence codec needs an element size of 2 or 4, "
			                 "not %u",
			                 x->label, i, tagn(tag).s, elsize);
		if (codec == MLOD_SCODEC_MESHOPT_INDEX && count % 3 != 0)
			return mlod_fail(err, MLOD_ERR_PARSE,
			                 "%s: stream %u '%s': the meshopt index codec needs a multiple of 3 elements, not %u",
			                 x->label, i, tagn(tag).s, count);
		if (codec != MLOD_SCODEC_RAW && decoded > (uint64_t)PACK_MAX_EXPAND * stored + PACK_MAX_EXPAND)
			return mlod_fail(err, MLOD_ERR_PARSE,
			                 "%s: stream %u '%s': %u meshopt-coded bytes cannot hold %u elements of %u bytes",
			                 x->label, i, tagn(tag).s, stored, count, elsize);
		if ((codec == MLOD_SCODEC_RAW || codec == MLOD_SCODEC_PLANES || codec == MLOD_SCODEC_PLANES_DELTA) &&
		    stored != decoded)
			return mlod_fail(err, MLOD_ERR_PARSE, "%s: stream %u '%s': %u bytes stored for %u elements of %u bytes",
			                 x->label, i, tagn(tag).s, stored, count, elsize);
		if (pad4(stored) > csize - cursor)
			return mlod_fail(err, MLOD_ERR_PARSE,
			                 "%s: stream %u '%s' (%u bytes at %llu) runs past the chunk's %llu%s bytes", x->label, i,
			                 tagn(tag).s, stored, (unsigned long long)cursor, (unsigned long long)csize, what);
		cursor += pad4(stored);
		raw += pad4(decoded);
		if (codec != MLOD_SCODEC_RAW && decoded > x->max_decoded)
			x->max_decoded = decoded;
	}
	if (cursor != csize)
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: its streams end at byte %llu of its %llu%s", x->label,
		                 (unsigned long long)cursor, (unsigned long long)csize, what);
	if (raw != c->raw_size)
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: raw size %u in the TOC, but its streams decode to %llu bytes",
		                 x->label, c->raw_size, (unsigned long long)raw);
	x->nstreams = n;
	x->next = 0;
	x->cursor = 4 + 16 * (uint64_t)n;
	return MLOD_OK;
}

/* cx_head and cx_parse on the chunk's bytes in data (a file or a prefix);
 * prefix: for MLOD_ENTROPY_ZSTD_PREFIX, or NULL. */
static mlod_result cx_begin_prefix(const mlod_pack *p, uint32_t index, uint32_t type, const void *data, size_t size,
                                   const uint8_t *prefix, uint64_t prefix_size, cx *x, mlod_error *err)
{
	memset(x, 0, sizeof *x);
	if (!p || (!data && size))
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "pack decode: the pack or the data is NULL");
	mlod_result r = cx_head(p, index, type, x, err);
	if (r != MLOD_OK)
		return r;
	const mlod_pack_chunk *c = x->c;
	if (c->offset > size || c->stored_size > size - c->offset)
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: truncated: the chunk ends at byte %llu, the data has %zu", x->label,
		                 (unsigned long long)(c->offset + c->stored_size), size);
	x->base = (const uint8_t *)data + c->offset;
	x->prefix = prefix;
	x->prefix_size = prefix_size;
	return cx_parse(x, err);
}

static mlod_result cx_begin(const mlod_pack *p, uint32_t index, uint32_t type, const void *data, size_t size, cx *x,
                            mlod_error *err)
{
	return cx_begin_prefix(p, index, type, data, size, NULL, 0, x, err);
}

/* cx_begin on a skeleton level: with the prefix stage, the SKELETON
 * chunk in data is read and checked first (its CRC, its own stage, its
 * container), and its container is the prefix; it is freed once the
 * level's frame is undone. */
static mlod_result cx_begin_skel_level(const mlod_pack *p, uint32_t index, const void *data, size_t size, cx *x,
                                       mlod_error *err)
{
	if (!p || index >= p->chunk_count || p->chunks[index].entropy != MLOD_ENTROPY_ZSTD_PREFIX ||
	    p->chunks[index].type != MLOD_CHUNK_SKELETON || p->chunks[index].level == 0)
		return cx_begin(p, index, MLOD_CHUNK_SKELETON, data, size, x, err);
	memset(x, 0, sizeof *x);
	int di = mlod_pack_find(p, MLOD_CHUNK_SKELETON, 0, 0);
	if (di < 0) /* open refuses that; a caller's own TOC may not */
		return mlod_fail(err, MLOD_ERR_PARSE, "SKELETON level %u: coded on the SKELETON chunk's container, which the "
		                 "pack lacks", (unsigned)p->chunks[index].level);
	cx dx;
	mlod_result r = cx_begin(p, (uint32_t)di, MLOD_CHUNK_SKELETON, data, size, &dx, err);
	if (r == MLOD_OK)
		r = cx_begin_prefix(p, index, MLOD_CHUNK_SKELETON, data, size, dx.base, dx.size, x, err);
	pk_free(&dx.alloc, dx.plain);
	if (x->prefix)
		x->prefix = NULL, x->prefix_size = 0;
	return r;
}

static void cx_rewind(cx *x)
{
	x->next = 0;
	x->cursor = 4 + 16 * (uint64_t)x->nstreams;
}

/* The next stream's header; 0 when there is none. */
static int cx_next(cx *x, stream *s)
{
	if (x->next >= x->nstreams)
		return 0;
	const uint8_t *h = x->base + 4 + 16 * (size_t)x->next;
	s->index = x->next;
	s->tag = rd32(h);
	s->count = rd32(h + 4);
	s->elsize = rd16(h + 8);
	s->codec = h[10];
	s->stored = rd32(h + 12);
	s->src = x->base + x->cursor;
	x->cursor += pad4(s->stored);
	x->next++;
	return 1;
}

/* The next stream, which must have this tag, element size and count
 * (count UINT64_MAX: any). what says where ("part 3"), count_what what
 * the count is. */
static mlod_result cx_expect(cx *x, stream *s, uint32_t tag, uint32_t elsize, uint64_t count, const char *what,
                             const char *count_what, mlod_error *err)
{
	const char *sep = *what ? ": " : "";
	if (!cx_next(x, s))
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: %s%smissing stream '%s' (the chunk has %u streams)", x->label, what,
		                 sep, tagn(tag).s, x->nstreams);
	if (s->tag != tag)
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: %s%sstream %u is '%s', expected '%s'", x->label, what, sep, s->index,
		                 tagn(s->tag).s, tagn(tag).s);
	if (s->elsize != elsize)
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: %s%sstream %u '%s' has elements of %u bytes, expected %u", x->label,
		                 what, sep, s->index, tagn(tag).s, s->elsize, elsize);
	if (count != UINT64_MAX && s->count != count)
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: %s%sstream %u '%s' has %u elements, expected %llu (%s)", x->label,
		                 what, sep, s->index, tagn(tag).s, s->count, (unsigned long long)count, count_what);
	return MLOD_OK;
}

static mlod_result cx_end(cx *x, mlod_error *err)
{
	if (x->next != x->nstreams)
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: %u unexpected streams after the last one it needs (stream %u '%s')",
		                 x->label, x->nstreams - x->next, x->next, tagn(rd32(x->base + 4 + 16 * (size_t)x->next)).s);
	return MLOD_OK;
}

/* Allocates the temporary buffer: aux bytes for the decode's own checks,
 * then room for the largest meshopt-coded stream. */
static mlod_result cx_temp(cx *x, uint64_t aux, mlod_error *err)
{
	uint64_t total = round8(aux) + x->max_decoded;
	x->aux = round8(aux);
	if (total == 0)
		return MLOD_OK;
	if (total > PACK_MAX_BLOCK)
		return mlod_fail(err, MLOD_ERR_NOMEM, "%s: decoding needs %llu bytes of scratch, more than the reader's limit",
		                 x->label, (unsigned long long)total);
	x->temp = pk_calloc(&x->alloc, 1, (size_t)total);
	if (!x->temp)
		return mlod_fail(err, MLOD_ERR_NOMEM, "%s: out of memory for %llu bytes of scratch", x->label,
		                 (unsigned long long)total);
	return MLOD_OK;
}

static void cx_done(cx *x)
{
	pk_free(&x->alloc, x->temp);
	x->temp = NULL;
	pk_free(&x->alloc, x->plain);
	x->plain = NULL;
}

/* Index k of a decoded index stream of 16-bit (i16) or 32-bit entries, in
 * the machine's byte order (as the index decoders write them). */
static uint32_t index_at(const uint8_t *src, int i16, uint32_t k)
{
	if (i16) {
		uint16_t v;
		memcpy(&v, src + 2 * (size_t)k, 2);
		return v;
	}
	uint32_t v;
	memcpy(&v, src + 4 * (size_t)k, 4);
	return v;
}

/* The stream's decoded bytes: in place for raw streams, else decoded into
 * the temporary buffer (valid until the next load). */
static mlod_result cx_load_into(cx *x, const stream *s, uint8_t *dst, mlod_error *err);

static mlod_result cx_load(cx *x, const stream *s, const uint8_t **out, mlod_error *err)
{
	if (s->codec == MLOD_SCODEC_RAW) {
		*out = s->src;
		return MLOD_OK;
	}
	static unsigned char dummy[256];
	unsigned char *dst = x->temp && x->max_decoded ? x->temp + x->aux : dummy;
	mlod_result r = cx_load_into(x, s, dst, err);
	if (r == MLOD_OK)
		*out = dst;
	return r;
}

/* The stream's decoded bytes written to dst (count * element size bytes):
 * a copy of a raw stream, or the meshopt decoder's output in place. */
static mlod_result cx_load_into(cx *x, const stream *s, uint8_t *dst, mlod_error *err)
{
	if (s->codec == MLOD_SCODEC_RAW) {
		if (s->count)
			memcpy(dst, s->src, (size_t)s->count * s->elsize);
		return MLOD_OK;
	}
	if (s->codec == MLOD_SCODEC_SUM255) { /* elsize 4, stored == count * 3 (cx_container) */
		for (size_t k = 0; k < s->count; k++) {
			const uint8_t *e = s->src + 3 * k;
			unsigned sum = (unsigned)e[0] + e[1] + e[2];
			if (sum > 255)
				return mlod_fail(err, MLOD_ERR_PARSE, "%s: stream %u '%s': element %zu: its three bytes sum to %u, "
				                 "more than 255", x->label, s->index, tagn(s->tag).s, k, sum);
			memcpy(dst + 4 * k, e, 3);
			dst[4 * k + 3] = (uint8_t)(255 - sum);
		}
		return MLOD_OK;
	}
	if (s->codec >= MLOD_SCODEC_PLANES) { /* stored == count * elsize (cx_container) */
		size_t n = s->count, e = s->elsize;
		for (size_t j = 0; j < e; j++) {
			const uint8_t *plane = s->src + j * n;
			uint8_t acc = 0;
			if (s->codec == MLOD_SCODEC_PLANES_DELTA)
				for (size_t k = 0; k < n; k++)
					dst[k * e + j] = acc = (uint8_t)(acc + plane[k]);
			else
				for (size_t k = 0; k < n; k++)
					dst[k * e + j] = plane[k];
		}
		return MLOD_OK;
	}
	int rc = s->codec == MLOD_SCODEC_MESHOPT_VERTEX
	                 ? meshopt_decodeVertexBuffer(dst, s->count, s->elsize, s->src, s->stored)
	         : s->codec == MLOD_SCODEC_MESHOPT_SEQUENCE
	                 ? meshopt_decodeIndexSequence(dst, s->count, s->elsize, s->src, s->stored)
	                 : meshopt_decodeIndexBuffer(dst, s->count, s->elsize, s->src, s->stored);
	if (rc != 0)
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: stream %u '%s': the meshopt %s codec failed (%d)", x->label,
		                 s->index, tagn(s->tag).s,
		                 s->codec == MLOD_SCODEC_MESHOPT_VERTEX     ? "vertex"
		                 : s->codec == MLOD_SCODEC_MESHOPT_SEQUENCE ? "index sequence"
		                                                            : "index",
		                 rc);
	return MLOD_OK;
}

/* The block: one allocation carved into 8-aligned arrays, after a head
 * that records the allocator that made it (for the *_free calls). */
enum { BLOCK_HEAD = 32, BLOCK_SIZE_AT = 24 };
_Static_assert(sizeof(mlod_pack_alloc) <= BLOCK_SIZE_AT && BLOCK_SIZE_AT + sizeof(uint64_t) <= BLOCK_HEAD,
               "the block's head holds its allocator and its size");

size_t mlod_pack_block_size(const void *block)
{
	uint64_t n = 0;
	if (block)
		memcpy(&n, (const uint8_t *)block + BLOCK_SIZE_AT, sizeof n);
	return (size_t)n;
}

static void block_free(void *block)
{
	if (!block)
		return;
	mlod_pack_alloc a;
	memcpy(&a, block, sizeof a);
	pk_free(&a, block);
}

typedef struct bump {
	uint8_t *base;
	uint64_t used, cap;
} bump;

static mlod_result bump_alloc(bump *b, cx *x, uint64_t total, mlod_error *err)
{
	memset(b, 0, sizeof *b);
	if (total > PACK_MAX_BLOCK)
		return mlod_fail(err, MLOD_ERR_NOMEM, "%s: decoded, it needs %llu bytes, more than the reader's limit",
		                 x->label, (unsigned long long)total);
	b->base = pk_calloc(&x->alloc, 1, (size_t)(BLOCK_HEAD + total));
	if (!b->base)
		return mlod_fail(err, MLOD_ERR_NOMEM, "%s: out of memory for %llu bytes", x->label,
		                 (unsigned long long)total);
	memcpy(b->base, &x->alloc, sizeof x->alloc);
	b->used = BLOCK_HEAD;
	b->cap = BLOCK_HEAD + total;
	memcpy(b->base + BLOCK_SIZE_AT, &b->cap, sizeof b->cap);
	return MLOD_OK;
}

/* p, a pointer into b's block (else returned as it is), at the same
 * offset of nb, a copy of its used bytes. */
static void *moved(const bump *b, uint8_t *nb, const void *p)
{
	/* compared as integers: the relational operators are only defined
	 * within one object, and p may point elsewhere */
	const uintptr_t at = (uintptr_t)p, base = (uintptr_t)b->base;
	return p && at >= base && at - base < b->used ? nb + (at - base) : (void *)at;
}

static void *bump_take(bump *b, uint64_t bytes)
{
	if (round8(bytes) > b->cap - b->used)
		return NULL;
	void *p = b->base + b->used;
	b->used += round8(bytes);
	return p;
}

/* A string table: the stream's bytes with a NUL after them; every string
 * offset must be inside and the table must end with a NUL. */
static mlod_result load_names(cx *x, bump *b, const stream *s, char **out, mlod_error *err)
{
	const uint8_t *src;
	mlod_result r = cx_load(x, s, &src, err);
	if (r != MLOD_OK)
		return r;
	char *t = bump_take(b, (uint64_t)s->count + 1);
	if (!t)
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: internal block size mismatch", x->label);
	if (s->count)
		memcpy(t, src, s->count);
	t[s->count] = 0;
	if (s->count && t[s->count - 1] != 0)
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: the string table 'NAME' does not end with a NUL", x->label);
	*out = t;
	return MLOD_OK;
}

static mlod_result name_at(cx *x, const char *table, uint32_t table_size, uint32_t off, const char **out,
                           const char *what, mlod_error *err)
{
	if (off >= table_size)
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: %s: name offset %u is outside the string table (%u bytes)", x->label,
		                 what, off, table_size);
	*out = table + off;
	return MLOD_OK;
}

#define TAKE(ptr, bytes)                                                                                        \
	do {                                                                                                    \
		(ptr) = bump_take(&b, (bytes));                                                                  \
		if (!(ptr)) {                                                                                   \
			r = mlod_fail(err, MLOD_ERR_PARSE, "%s: internal block size mismatch", x.label);          \
			goto fail;                                                                              \
		}                                                                                               \
	} while (0)

#define TRY(call)                                                                                               \
	do {                                                                                                    \
		r = (call);                                                                                     \
		if (r != MLOD_OK)                                                                               \
			goto fail;                                                                              \
	} while (0)

#define FAIL(...)                                                                                               \
	do {                                                                                                    \
		r = mlod_fail(err, MLOD_ERR_PARSE, __VA_ARGS__);                                                 \
		goto fail;                                                                                      \
	} while (0)

/* An allocation that failed: MLOD_ERR_NOMEM, so that a caller tells a low
 * memory moment from a corrupt pack. */
#define FAIL_NOMEM(...)                                                                                         \
	do {                                                                                                    \
		r = mlod_fail(err, MLOD_ERR_NOMEM, __VA_ARGS__);                                                 \
		goto fail;                                                                                      \
	} while (0)

/* ------------------------------------------------------------------ */
/* INFO                                                                */
/* ------------------------------------------------------------------ */

mlod_result mlod_pack_decode_info(const mlod_pack *p, const void *data, size_t size, mlod_pack_info *out,
                                  mlod_error *err)
{
	if (!out)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_pack_decode_info: out is NULL");
	memset(out, 0, sizeof *out);
	if (!p)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_pack_decode_info: the pack is NULL");
	int ci = mlod_pack_find(p, MLOD_CHUNK_INFO, 0, 0);
	if (ci < 0)
		return mlod_fail(err, MLOD_ERR_PARSE, "the pack has no INFO chunk");
	cx x;
	bump b = {0};
	stream s_info, s_name;
	const uint8_t *src;
	mlod_result r = cx_begin(p, (uint32_t)ci, MLOD_CHUNK_INFO, data, size, &x, err);
	if (r != MLOD_OK)
		return r;
	TRY(cx_expect(&x, &s_info, MLOD_STREAM_INFO, sizeof(mlod_pack_info_rec), 1, "", "one record", err));
	TRY(cx_expect(&x, &s_name, MLOD_STREAM_NAME, 1, UINT64_MAX, "", "", err));
	TRY(cx_end(&x, err));
	TRY(cx_temp(&x, 0, err));
	TRY(cx_load(&x, &s_info, &src, err));
	mlod_pack_info_rec rec;
	memcpy(&rec, src, sizeof rec);
	if (!all_finite(rec.bounds_min, 3) || !all_finite(rec.bounds_max, 3) || !isfinite(rec.height) ||
	    !isfinite(rec.diagonal))
		FAIL("%s: the bounds, height and diagonal must be finite", x.label);
	if ((rec.mesh_levels == 0) != (rec.instance_count == 0))
		FAIL("%s: %u mesh levels with %u instances (0 mesh levels means no instances)", x.label, rec.mesh_levels,
		     rec.instance_count);
	if ((rec.motion_levels == 0) != (rec.clip_count == 0))
		FAIL("%s: %u motion levels with %u clips (0 motion levels means no clips)", x.label, rec.motion_levels,
		     rec.clip_count);
	if (rec.first_drawable > p->file_size)
		FAIL("%s: first_drawable %u is past the file's end (%llu)", x.label, rec.first_drawable,
		     (unsigned long long)p->file_size);
	/* first_drawable: where the last of INFO, SKELETON and the coarsest
	 * level of each layer (of every clip) ends */
	uint64_t drawable = 0;
	for (uint32_t i = 0; i < p->chunk_count; i++) {
		const mlod_pack_chunk *c = &p->chunks[i];
		const int coarse = c->type == MLOD_CHUNK_INFO ||
		                   (c->type == MLOD_CHUNK_SKELETON && (c->level == 0 || c->level + 1u == rec.skeleton_levels)) ||
		                   (c->type == MLOD_CHUNK_MESH && c->level + 1u == rec.mesh_levels) ||
		                   (c->type == MLOD_CHUNK_MOTION && c->level + 1u == rec.motion_levels);
		if (coarse && c->offset + c->stored_size > drawable)
			drawable = c->offset + c->stored_size;
	}
	if (rec.first_drawable != drawable)
		FAIL("%s: first_drawable %u, but INFO, SKELETON and the coarsest levels end at byte %llu", x.label,
		     rec.first_drawable, (unsigned long long)drawable);
	/* The TOC holds exactly the levels INFO counts (open made them unique). */
	uint64_t nskel = 0, nmesh = 0, nmotion = 0;
	for (uint32_t i = 0; i < p->chunk_count; i++) {
		const mlod_pack_chunk *c = &p->chunks[i];
		char label[64];
		chunk_label(c->type, c->level, c->item, label, sizeof label);
		if (c->type == MLOD_CHUNK_SKELETON) {
			if (c->level >= rec.skeleton_levels)
				FAIL("%s: the TOC has %s, but INFO counts %u skeleton levels", x.label, label, rec.skeleton_levels);
			nskel++;
		} else if (c->type == MLOD_CHUNK_MESH) {
			if (c->level >= rec.mesh_levels)
				FAIL("%s: the TOC has %s, but INFO counts %u mesh levels", x.label, label, rec.mesh_levels);
			nmesh++;
		} else if (c->type == MLOD_CHUNK_MOTION) {
			if (c->level >= rec.motion_levels || c->item >= rec.clip_count)
				FAIL("%s: the TOC has %s, but INFO counts %u motion levels of %u clips", x.label, label,
				     rec.motion_levels, rec.clip_count);
			nmotion++;
		}
	}
	if (nskel != rec.skeleton_levels || nmesh != rec.mesh_levels ||
	    nmotion != (uint64_t)rec.motion_levels * rec.clip_count)
		FAIL("%s: it counts %u skeleton, %u mesh and %u motion levels of %u clips, but the TOC has %llu SKELETON, "
		     "%llu MESH and %llu MOTION chunks",
		     x.label, rec.skeleton_levels, rec.mesh_levels, rec.motion_levels, rec.clip_count,
		     (unsigned long long)nskel, (unsigned long long)nmesh, (unsigned long long)nmotion);
	/* Every clip name takes at least its NUL. */
	if (rec.clip_count > s_name.count)
		FAIL("%s: %u clips, but the string table 'NAME' has only %u bytes", x.label, rec.clip_count, s_name.count);
	TRY(bump_alloc(&b, &x, round8((uint64_t)rec.clip_count * sizeof(char *)) + round8((uint64_t)s_name.count + 1),
	               err));
	const char **clip_names;
	char *names;
	TAKE(clip_names, (uint64_t)rec.clip_count * sizeof(char *));
	TRY(load_names(&x, &b, &s_name, &names, err));
	const char *name = NULL;
	TRY(name_at(&x, names, s_name.count, rec.name, &name, "the character", err));
	/* The clips' names follow the character's, one after the other. */
	size_t pos = (size_t)rec.name + strlen(name) + 1;
	for (uint32_t c = 0; c < rec.clip_count; c++) {
		if (pos >= s_name.count)
			FAIL("%s: the string table 'NAME' ends before clip %u's name", x.label, c);
		clip_names[c] = names + pos;
		pos += strlen(names + pos) + 1;
	}
	cx_done(&x);
	out->rec = rec;
	out->name = name;
	out->clip_names = clip_names;
	out->block = b.base;
	return MLOD_OK;
fail:
	cx_done(&x);
	pk_free(&x.alloc, b.base);
	return r;
}

void mlod_pack_info_free(mlod_pack_info *x)
{
	if (!x)
		return;
	block_free(x->block);
	memset(x, 0, sizeof *x);
}

/* ------------------------------------------------------------------ */
/* SKELETON                                                            */
/* ------------------------------------------------------------------ */

mlod_result mlod_pack_decode_skeleton(const mlod_pack *p, const void *data, size_t size, mlod_pack_skeleton *out,
                                      mlod_error *err)
{
	if (!out)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_pack_decode_skeleton: out is NULL");
	memset(out, 0, sizeof *out);
	if (!p)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_pack_decode_skeleton: the pack is NULL");
	int ci = mlod_pack_find(p, MLOD_CHUNK_SKELETON, 0, 0);
	if (ci < 0)
		return mlod_fail(err, MLOD_ERR_PARSE, "the pack has no SKELETON chunk");
	cx x;
	bump b = {0};
	stream sj, sn, ss, sk, si;
	const uint8_t *src;
	mlod_result r = cx_begin(p, (uint32_t)ci, MLOD_CHUNK_SKELETON, data, size, &x, err);
	if (r != MLOD_OK)
		return r;
	TRY(cx_expect(&x, &sj, MLOD_STREAM_JNTS, sizeof(mlod_pack_joint_rec), UINT64_MAX, "", "", err));
	TRY(cx_expect(&x, &sn, MLOD_STREAM_NAME, 1, UINT64_MAX, "", "", err));
	TRY(cx_expect(&x, &ss, MLOD_STREAM_SKIN, sizeof(mlod_pack_skin_rec), UINT64_MAX, "", "", err));
	TRY(cx_expect(&x, &sk, MLOD_STREAM_SKJT, 4, UINT64_MAX, "", "", err));
	TRY(cx_expect(&x, &si, MLOD_STREAM_IBMS, 64, sk.count, "", "one per skin joint in 'SKJT'", err));
	TRY(cx_end(&x, err));
	uint64_t J = sj.count, N = sn.count, S = ss.count, K = sk.count;
	TRY(cx_temp(&x, 0, err));
	TRY(bump_alloc(&b, &x,
	               round8(J * sizeof(mlod_pack_joint_rec)) + round8(J * sizeof(char *)) + round8(N + 1) +
	                       round8(S * sizeof(mlod_pack_skin_rec)) + 3 * round8(S * sizeof(void *)) + round8(K * 4) +
	                       round8(K * 64),
	               err));
	mlod_pack_joint_rec *joints;
	const char **joint_names, **skin_names;
	mlod_pack_skin_rec *skins;
	const uint32_t **skin_joints;
	const float **inverse_bind;
	uint32_t *skjt;
	float *ibms;
	char *names;
	TAKE(joints, J * sizeof *joints);
	TAKE(joint_names, J * sizeof *joint_names);
	TAKE(skins, S * sizeof *skins);
	TAKE(skin_names, S * sizeof *skin_names);
	TAKE(skin_joints, S * sizeof *skin_joints);
	TAKE(inverse_bind, S * sizeof *inverse_bind);
	TAKE(skjt, K * 4);
	TAKE(ibms, K * 64);
	TRY(cx_load(&x, &sj, &src, err));
	if (J)
		memcpy(joints, src, J * sizeof *joints);
	TRY(load_names(&x, &b, &sn, &names, err));
	for (uint32_t j = 0; j < J; j++) {
		const mlod_pack_joint_rec *jt = &joints[j];
		char what[48];
		snprintf(what, sizeof what, "joint %u", j);
		if (jt->parent < -1 || jt->parent >= (int32_t)j)
			FAIL("%s: joint %u: parent %d is not -1 or an earlier joint", x.label, j, jt->parent);
		if (!all_finite(jt->t, 3) || !all_finite(jt->r, 4) || !all_finite(jt->s, 3) || !all_finite(jt->base, 16))
			FAIL("%s: joint %u: a rest transform or base value is not finite", x.label, j);
		const double len = mlod_quat4_length(jt->r[0], jt->r[1], jt->r[2], jt->r[3]);
		if (!(fabs(len - 1.0) <= MLOD_UNIT_QUAT_TOLERANCE))
			FAIL("%s: joint %u: its rest rotation has length %g, not a unit quaternion (within %g)", x.label, j, len,
			     MLOD_UNIT_QUAT_TOLERANCE);
		if (jt->node < -1)
			FAIL("%s: joint %u: node %d is not -1 or a node", x.label, j, jt->node);
		TRY(name_at(&x, names, sn.count, jt->name, &joint_names[j], what, err));
	}
	TRY(cx_load(&x, &ss, &src, err));
	if (S)
		memcpy(skins, src, S * sizeof *skins);
	uint64_t sum = 0;
	for (uint32_t k = 0; k < S; k++) {
		char what[48];
		snprintf(what, sizeof what, "skin %u", k);
		if (skins[k].gltf_index < -1)
			FAIL("%s: skin %u: glTF skin %d is not -1 or a skin", x.label, k, skins[k].gltf_index);
		TRY(name_at(&x, names, sn.count, skins[k].name, &skin_names[k], what, err));
		skin_joints[k] = skjt + sum;
		inverse_bind[k] = ibms + 16 * sum;
		sum += skins[k].joint_count;
		if (sum > K)
			FAIL("%s: skin %u: its joints run past the %llu in 'SKJT'", x.label, k, (unsigned long long)K);
	}
	if (sum != K)
		FAIL("%s: the skins have %llu joints, but 'SKJT' has %llu", x.label, (unsigned long long)sum,
		     (unsigned long long)K);
	TRY(cx_load(&x, &sk, &src, err));
	if (K)
		memcpy(skjt, src, K * 4);
	for (uint32_t k = 0, i = 0; k < S; k++)
		for (uint32_t m = 0; m < skins[k].joint_count; m++, i++)
			if (skjt[i] >= J)
				FAIL("%s: skin %u: joint %u is %u, not below the joint count %llu", x.label, k, m, skjt[i],
				     (unsigned long long)J);
	TRY(cx_load(&x, &si, &src, err));
	if (K)
		memcpy(ibms, src, K * 64);
	if (!all_finite(ibms, (size_t)K * 16))
		FAIL("%s: an inverse bind matrix is not finite", x.label);
	cx_done(&x);
	out->joint_count = (uint32_t)J;
	out->joints = joints;
	out->joint_names = joint_names;
	out->skin_count = (uint32_t)S;
	out->skins = skins;
	out->skin_names = skin_names;
	out->skin_joints = skin_joints;
	out->inverse_bind = inverse_bind;
	out->block = b.base;
	return MLOD_OK;
fail:
	cx_done(&x);
	pk_free(&x.alloc, b.base);
	return r;
}

void mlod_pack_skeleton_free(mlod_pack_skeleton *x)
{
	if (!x)
		return;
	block_free(x->block);
	memset(x, 0, sizeof *x);
}

/* ------------------------------------------------------------------ */
/* SKELETON level k                                                    */
/* ------------------------------------------------------------------ */

mlod_result mlod_pack_decode_skel_level(const mlod_pack *p, uint32_t chunk, const void *data, size_t size,
                                        const mlod_pack_skeleton *skel, mlod_pack_skel_level *out, mlod_error *err)
{
	if (!out)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_pack_decode_skel_level: out is NULL");
	memset(out, 0, sizeof *out);
	if (!skel)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_pack_decode_skel_level: the full skeleton is NULL");
	cx x;
	bump b = {0};
	stream sk, sj, sb;
	const uint8_t *src;
	int refs = p->major >= 7; /* 'PALR' and 'PALX'; 'PALJ' derived (format 7.0) */
	mlod_result r = cx_begin_skel_level(p, chunk, data, size, &x, err);
	if (r != MLOD_OK)
		return r;
	if (x.c->level == 0)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG,
		                 "pack decode: chunk %u is the full SKELETON: use mlod_pack_decode_skeleton", chunk);
	uint64_t J = skel->joint_count, P = 0;
	for (uint32_t k = 0; k < skel->skin_count; k++)
		P += skel->skins[k].joint_count;
	TRY(cx_expect(&x, &sk, MLOD_STREAM_KEPT, 4, UINT64_MAX, "", "", err));
	if (refs) {
		TRY(cx_expect(&x, &sj, MLOD_STREAM_PALR, 4, P, "", "the skins' joints", err));
		TRY(cx_expect(&x, &sb, MLOD_STREAM_PALX, 64, UINT64_MAX, "", "", err));
		if (sb.count > P)
			FAIL("%s: %u bind matrices in 'PALX', more than the %llu skin joints", x.label, sb.count,
			     (unsigned long long)P);
	} else {
		TRY(cx_expect(&x, &sj, MLOD_STREAM_PALJ, 4, P, "", "the skins' joints", err));
		TRY(cx_expect(&x, &sb, MLOD_STREAM_PALB, 64, P, "", "the skins' joints", err));
	}
	TRY(cx_end(&x, err));
	uint64_t Kc = sk.count;
	if (Kc > J)
		FAIL("%s: %llu kept joints of a skeleton of %llu", x.label, (unsigned long long)Kc, (unsigned long long)J);
	/* aux: each joint's nearest kept ancestor (or itself); from 7.0 also
	 * 'PALR' and each skin joint's 'IBMS' entry. */
	TRY(cx_temp(&x, refs ? round8(J * 4) + round8(P * 4) + P * sizeof(float *) : J * 4, err));
	TRY(bump_alloc(&b, &x, round8(Kc * 4) + round8(P * 4) + round8(P * 64), err));
	uint32_t *kept, *palj, *nearest = (uint32_t *)x.temp;
	uint32_t *palr = refs ? (uint32_t *)(x.temp + round8(J * 4)) : NULL;
	const float **ibm = refs ? (const float **)(void *)(x.temp + round8(J * 4) + round8(P * 4)) : NULL;
	float *palb;
	TAKE(kept, Kc * 4);
	TAKE(palj, P * 4);
	TAKE(palb, P * 64);
	TRY(cx_load(&x, &sk, &src, err));
	if (Kc)
		memcpy(kept, src, Kc * 4);
	for (uint64_t i = 0; i < Kc; i++) {
		if (kept[i] >= J)
			FAIL("%s: kept joint %llu is %u, not below the joint count %llu", x.label, (unsigned long long)i, kept[i],
			     (unsigned long long)J);
		if (i > 0 && kept[i] <= kept[i - 1])
			FAIL("%s: kept joints are not increasing (%u after %u)", x.label, kept[i], kept[i - 1]);
	}
	for (uint32_t j = 0, ki = 0; j < J; j++) {
		int is_kept = ki < Kc && kept[ki] == j;
		if (is_kept)
			ki++;
		int32_t parent = skel->joints[j].parent;
		if (parent >= (int32_t)j)
			FAIL("%s: the given skeleton's joint %u has parent %d, not an earlier joint", x.label, j, parent);
		if (parent < 0 && !is_kept)
			FAIL("%s: root joint %u is not kept (every root is)", x.label, j);
		nearest[j] = is_kept ? j : nearest[parent];
	}
	if (!refs) {
		TRY(cx_load(&x, &sj, &src, err));
		if (P)
			memcpy(palj, src, P * 4);
	}
	for (uint32_t k = 0, i = 0; k < skel->skin_count; k++)
		for (uint32_t m = 0; m < skel->skins[k].joint_count; m++, i++) {
			uint32_t joint = skel->skin_joints[k][m];
			if (joint >= J)
				FAIL("%s: the given skeleton's skin %u joint %u is %u, not below its joint count", x.label, k, m,
				     joint);
			if (refs) {
				palj[i] = nearest[joint];
				ibm[i] = skel->inverse_bind[k] + 16 * (size_t)m;
				continue;
			}
			uint32_t v = palj[i];
			if (v >= J || nearest[v] != v)
				FAIL("%s: palette entry %u (skin %u joint %u): joint %u is not a kept joint", x.label, i, k, m, v);
			if (v != nearest[joint])
				FAIL("%s: palette entry %u (skin %u joint %u): joint %u, but the nearest kept ancestor of joint %u "
				     "is %u",
				     x.label, i, k, m, v, joint, nearest[joint]);
		}
	if (refs) {
		/* 0: the own IBMS entry; 1..P: IBMS entry v - 1; then 'PALX'. */
		if (P)
			TRY(cx_load_into(&x, &sj, (uint8_t *)palr, err));
		TRY(cx_load(&x, &sb, &src, err));
		for (uint64_t i = 0; i < P; i++) {
			uint64_t v = palr[i];
			const void *from = v == 0 ? (const void *)ibm[i] : v <= P ? (const void *)ibm[v - 1] : NULL;
			if (!from && v - P - 1 >= sb.count)
				FAIL("%s: palette entry %llu refers to bind matrix %llu, beyond the %llu skin joints and %u in "
				     "'PALX'",
				     x.label, (unsigned long long)i, (unsigned long long)v, (unsigned long long)P, sb.count);
			memcpy(palb + 16 * i, from ? from : (const void *)(src + 64 * (v - P - 1)), 64);
		}
	} else {
		TRY(cx_load(&x, &sb, &src, err));
		if (P)
			memcpy(palb, src, P * 64);
	}
	if (!all_finite(palb, (size_t)P * 16))
		FAIL("%s: a palette bind matrix is not finite", x.label);
	cx_done(&x);
	out->kept_count = (uint32_t)Kc;
	out->kept = kept;
	out->palette_size = (uint32_t)P;
	out->palette_joint = palj;
	out->palette_bind = palb;
	out->block = b.base;
	return MLOD_OK;
fail:
	cx_done(&x);
	pk_free(&x.alloc, b.base);
	return r;
}

void mlod_pack_skel_level_free(mlod_pack_skel_level *x)
{
	if (!x)
		return;
	block_free(x->block);
	memset(x, 0, sizeof *x);
}

/* ------------------------------------------------------------------ */
/* MESH level k                                                        */
/* ------------------------------------------------------------------ */

/* Octahedral unit vector from two snorm16 values, normalised. */
static void oct_decode(int16_t qx, int16_t qy, float *out)
{
	float x = qx / 32767.0f, y = qy / 32767.0f;
	x = x < -1.0f ? -1.0f : x;
	y = y < -1.0f ? -1.0f : y;
	float z = 1.0f - fabsf(x) - fabsf(y);
	if (z < 0) {
		float ox = x;
		x = (1.0f - fabsf(y)) * (ox >= 0 ? 1.0f : -1.0f);
		y = (1.0f - fabsf(ox)) * (y >= 0 ? 1.0f : -1.0f);
	}
	float len = sqrtf(x * x + y * y + z * z); /* >= 1/sqrt(3): |x|+|y|+|z| = 1 */
	out[0] = x / len;
	out[1] = y / len;
	out[2] = z / len;
}

#define PART_KNOWN_FLAGS                                                                                        \
	(MLOD_PART_NORMALS | MLOD_PART_TANGENTS | MLOD_PART_COLORS | MLOD_PART_SKINNED | MLOD_PART_JOINTS16 |    \
	 MLOD_PART_INDEX16 | MLOD_PART_LOCAL | MLOD_PART_NEWBITS)

/* A part's vertex streams in a MESH chunk, in order, with their element
 * sizes (the targets' 'MTPQ' last, after 'IDX ' and 'MTSC'); the count. */
static int part_vstreams(const mlod_pack_part_rec *rc, uint32_t *tag, uint32_t *size)
{
	int n = 0;
	uint32_t f = rc->flags;
	tag[n] = MLOD_STREAM_POSQ, size[n++] = 8;
	if (f & MLOD_PART_NORMALS)
		tag[n] = MLOD_STREAM_NRMQ, size[n++] = 4;
	if (f & MLOD_PART_TANGENTS)
		tag[n] = MLOD_STREAM_TANQ, size[n++] = 8;
	for (uint32_t t = 0; t < rc->uv_sets && t < MLOD_PACK_MAX_UV; t++)
		tag[n] = MLOD_STREAM_UVQ0 + (t << 24), size[n++] = 4;
	if (f & MLOD_PART_COLORS)
		tag[n] = MLOD_STREAM_COLQ, size[n++] = 4;
	if (f & MLOD_PART_SKINNED) {
		int j16 = (f & MLOD_PART_JOINTS16) != 0;
		tag[n] = j16 ? MLOD_STREAM_JN16 : MLOD_STREAM_JNT8, size[n++] = j16 ? 8 : 4;
		tag[n] = MLOD_STREAM_WGT8, size[n++] = 4;
	}
	return n;
}

enum { VSTREAMS_MAX = 4 + MLOD_PACK_MAX_UV + 2 };

/* Checks a part record (as layout a's reader did). */
static mlod_result check_part_rec(const cx *x, uint32_t i, const mlod_pack_part_rec *rc, uint32_t J, uint32_t S,
                                  mlod_error *err)
{
	uint32_t f = rc->flags;
	if (f & ~PART_KNOWN_FLAGS)
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: part %u: unknown flags 0x%x", x->label, i, f & ~PART_KNOWN_FLAGS);
	if ((f & MLOD_PART_NEWBITS) && !(f & MLOD_PART_LOCAL))
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: part %u: NEWBITS without LOCAL", x->label, i);
	if ((f & MLOD_PART_JOINTS16) && !(f & MLOD_PART_SKINNED))
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: part %u: JOINTS16 without SKINNED", x->label, i);
	if (rc->index_count % 3 != 0)
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: part %u: index count %u is not a multiple of 3", x->label, i,
		                 rc->index_count);
	if (rc->uv_sets > MLOD_PACK_MAX_UV)
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: part %u: %u UV sets, more than %d", x->label, i, rc->uv_sets,
		                 MLOD_PACK_MAX_UV);
	if (rc->skin < -1 || rc->skin >= (int64_t)S)
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: part %u: skin %d is not -1 or below the skeleton's %u skins",
		                 x->label, i, rc->skin, S);
	if ((f & MLOD_PART_SKINNED) && rc->skin < 0)
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: part %u: skinned, but without a skin", x->label, i);
	if (rc->joint < -1 || rc->joint >= (int64_t)J)
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: part %u: joint %d is not -1 or below the skeleton's %u joints",
		                 x->label, i, rc->joint, J);
	if (rc->node < -1 || rc->mesh < -1 || rc->material < -1)
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: part %u: node %d, mesh %d, material %d: each must be -1 or an index",
		                 x->label, i, rc->node, rc->mesh, rc->material);
	if (!all_finite(rc->offset, 16))
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: part %u: its offset matrix is not finite", x->label, i);
	for (int a = 0; a < 3; a++)
		if (!isfinite(rc->pos_min[a]) || !(rc->pos_scale[a] >= 0) ||
		    !isfinite(rc->pos_min[a] + 65535.0f * rc->pos_scale[a]))
			return mlod_fail(err, MLOD_ERR_PARSE, "%s: part %u: position range %g + q * %g is not finite and increasing",
			                 x->label, i, (double)rc->pos_min[a], (double)rc->pos_scale[a]);
	for (uint32_t t = 0; t < rc->uv_sets; t++)
		for (int a = 0; a < 2; a++)
			if (!isfinite(rc->uv_min[t][a]) || !isfinite(rc->uv_scale[t][a]) ||
			    !isfinite(rc->uv_min[t][a] + 65535.0f * rc->uv_scale[t][a]))
				return mlod_fail(err, MLOD_ERR_PARSE, "%s: part %u: UV set %u range %g + q * %g is not finite", x->label,
				                 i, t, (double)rc->uv_min[t][a], (double)rc->uv_scale[t][a]);
	if (rc->vertex_count > rc->index_count)
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: part %u: %u vertices, more than its %u indices can use", x->label, i,
		                 rc->vertex_count, rc->index_count);
	return MLOD_OK;
}

/* Two levels' records of one part agree on everything but the counts and
 * the 16-bit index flag. */
static int same_part(const mlod_pack_part_rec *a, const mlod_pack_part_rec *b)
{
	mlod_pack_part_rec x = *a, y = *b;
	x.vertex_count = y.vertex_count = 0;
	x.index_count = y.index_count = 0;
	x.flags &= ~(MLOD_PART_INDEX16 | MLOD_PART_LOCAL | MLOD_PART_NEWBITS);
	y.flags &= ~(MLOD_PART_INDEX16 | MLOD_PART_LOCAL | MLOD_PART_NEWBITS);
	return memcmp(&x, &y, sizeof x) == 0;
}

/* The levels' blocks of one part: level l (0 the coarsest read) holds the
 * part's vertices first[l] .. first[l] + count[l] - 1, each attribute's
 * count[l] elements one after the other from base[l]. */
typedef struct mblock {
	uint8_t *base;
	uint64_t first;
	uint32_t count;
} mblock;

/* The chunk's bytes for a mesh decode: fetch gives it by TOC index. */
typedef struct mesh_src {
	const mlod_pack *p;
	const void *data; /* whole file or prefix */
	size_t size;
	mlod_pack_fetch_fn fetch;
	void *user;
	mlod_pack_reserve_fn reserve; /* or NULL (pack_internal.h) */
	void *reserve_user;
} mesh_src;

/* cx_begin on a MESH chunk from m; prefix: the coarser levels' containers
 * (for MLOD_ENTROPY_ZSTD_PREFIX), or NULL. */
static mlod_result mesh_begin(const mesh_src *m, uint32_t index, const uint8_t *prefix, uint64_t prefix_size, cx *x,
                              mlod_error *err)
{
	mlod_result r = cx_head(m->p, index, MLOD_CHUNK_MESH, x, err);
	if (r != MLOD_OK)
		return r;
	const void *bytes = NULL;
	if (!m->fetch) {
		const mlod_pack_chunk *c = x->c;
		if (c->offset > m->size || c->stored_size > m->size - c->offset)
			return mlod_fail(err, MLOD_ERR_PARSE, "%s: truncated: the chunk ends at byte %llu, the data has %zu",
			                 x->label, (unsigned long long)(c->offset + c->stored_size), m->size);
		bytes = (const uint8_t *)m->data + c->offset;
	} else {
		if ((r = m->fetch(m->user, index, &bytes, err)) != MLOD_OK)
			return r;
		if (!bytes && x->c->stored_size)
			return mlod_fail(err, MLOD_ERR_INVALID_ARG, "%s: the fetch gave no bytes", x->label);
	}
	x->base = bytes;
	x->prefix = prefix;
	x->prefix_size = prefix_size;
	return cx_parse(x, err);
}

/* A part's MTSC stream s (its target count, checked): pt->targets and
 * *scales taken from the level's block, the scales copied and checked. */
static mlod_result morph_scales(cx *x, bump *bp, const stream *s, mlod_pack_part *pt, uint32_t i, float **scales,
                                mlod_error *err)
{
	const uint8_t *src;
	const uint32_t T = pt->rec.target_count;
	mlod_result r = cx_load(x, s, &src, err);
	if (r != MLOD_OK)
		return r;
	pt->targets = bump_take(bp, (uint64_t)T * sizeof(float *));
	*scales = bump_take(bp, (uint64_t)T * 4);
	if (!pt->targets || !*scales)
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: internal block size mismatch", x->label);
	memcpy(*scales, src, (size_t)T * 4);
	for (uint32_t t = 0; t < T; t++)
		if (!((*scales)[t] >= 0) || !isfinite((*scales)[t] * 32768.0f))
			return mlod_fail(err, MLOD_ERR_PARSE, "%s: part %u: morph target %u: scale %g is not finite and >= 0",
			                 x->label, i, t, (double)(*scales)[t]);
	return MLOD_OK;
}

/* Dequantises a decoded part: gather holds its vertex attributes (as
 * part_vstreams lists them) one after the other, each vertex_count
 * elements, then its targets' 'MTPQ' elements the same way; scales the
 * targets' (pt->targets allocated). Takes the arrays from *bp. */
static mlod_result part_dequant(const char *label, bump *bp, mlod_pack_part *pt, uint32_t i, const uint8_t *gather,
                                const float *scales, const mlod_pack_skeleton *skel, mlod_error *err)
{
	bump b = *bp;
	struct {
		const char *label;
	} x = {label};
	mlod_result r = MLOD_OK;
	const mlod_pack_part_rec *rc = &pt->rec;
	uint32_t V = rc->vertex_count, T = rc->target_count;
	uint32_t size[VSTREAMS_MAX], tag[VSTREAMS_MAX];
	int nvs = part_vstreams(rc, tag, size);
	const uint8_t *g[VSTREAMS_MAX] = {0};
	(void)tag;
	{
		size_t off = 0;
		for (int c = 0; c < nvs; c++)
			g[c] = gather + off, off += (size_t)V * size[c];
	}
	/* Dequantise. */
	int a = 0;
	const uint8_t *q = g[a++];
	TAKE(pt->positions, (uint64_t)V * 12);
	for (uint32_t v = 0; v < V; v++)
		for (int c = 0; c < 3; c++)
			pt->positions[3 * v + c] = rc->pos_min[c] + rd16(q + 8 * (size_t)v + 2 * c) * rc->pos_scale[c];
	if (rc->flags & MLOD_PART_NORMALS) {
		q = g[a++];
		TAKE(pt->normals, (uint64_t)V * 12);
		for (uint32_t v = 0; v < V; v++)
			oct_decode(rdi16(q + 4 * (size_t)v), rdi16(q + 4 * (size_t)v + 2), pt->normals + 3 * (size_t)v);
	}
	if (rc->flags & MLOD_PART_TANGENTS) {
		q = g[a++];
		TAKE(pt->tangents, (uint64_t)V * 16);
		for (uint32_t v = 0; v < V; v++) {
			const uint8_t *e = q + 8 * (size_t)v;
			int16_t w = rdi16(e + 4);
			if (w != 32767 && w != -32767)
				FAIL("%s: part %u: vertex %u: tangent handedness %d is not -32767 or 32767", x.label, i, v, w);
			oct_decode(rdi16(e), rdi16(e + 2), pt->tangents + 4 * (size_t)v);
			pt->tangents[4 * (size_t)v + 3] = w > 0 ? 1.0f : -1.0f;
		}
	}
	for (uint32_t t = 0; t < rc->uv_sets; t++) {
		q = g[a++];
		TAKE(pt->uvs[t], (uint64_t)V * 8);
		for (uint32_t v = 0; v < V; v++)
			for (int c = 0; c < 2; c++)
				pt->uvs[t][2 * (size_t)v + c] =
				        rc->uv_min[t][c] + rd16(q + 4 * (size_t)v + 2 * c) * rc->uv_scale[t][c];
	}
	if (rc->flags & MLOD_PART_COLORS) {
		q = g[a++];
		TAKE(pt->colors, (uint64_t)V * 16);
		for (size_t k = 0; k < (size_t)V * 4; k++)
			pt->colors[k] = q[k] / 255.0f;
	}
	if (rc->flags & MLOD_PART_SKINNED) {
		int j16 = (rc->flags & MLOD_PART_JOINTS16) != 0;
		uint32_t skin_joints = skel->skins[rc->skin].joint_count;
		q = g[a++];
		TAKE(pt->joints, (uint64_t)V * 8);
		for (size_t k = 0; k < (size_t)V * 4; k++) {
			uint16_t jv = j16 ? rd16(q + 2 * k) : q[k];
			if (jv >= skin_joints)
				FAIL("%s: part %u: vertex %zu: joint %u is not below skin %d's %u joints", x.label, i, k / 4,
				     jv, rc->skin, skin_joints);
			pt->joints[k] = jv;
		}
		q = g[a++];
		TAKE(pt->weights, (uint64_t)V * 16);
		for (uint32_t v = 0; v < V; v++) {
			const uint8_t *e = q + 4 * (size_t)v;
			unsigned sum = (unsigned)e[0] + e[1] + e[2] + e[3];
			if (sum != 255)
				FAIL("%s: part %u: vertex %u: weights sum to %u, not 255", x.label, i, v, sum);
			for (int c = 0; c < 4; c++)
				pt->weights[4 * (size_t)v + c] = e[c] / 255.0f;
		}
	}
	q = gather;
	for (int c = 0; c < nvs; c++)
		q += (size_t)V * size[c];
	for (uint32_t t = 0; t < T; t++) {
		TAKE(pt->targets[t], (uint64_t)V * 12);
		const uint8_t *e = q + (size_t)t * V * 8;
		for (uint32_t v = 0; v < V; v++)
			for (int c = 0; c < 3; c++)
				pt->targets[t][3 * (size_t)v + c] = rdi16(e + 8 * (size_t)v + 2 * c) * scales[t];
	}
fail:
	*bp = b;
	return r;
}

/* The bytes a decoded mesh level's part takes (its mlod_pack_part arrays,
 * each rounded to 8), from its record alone. */
static uint64_t decoded_part_bytes(const mlod_pack_part_rec *rc)
{
	const uint64_t V = rc->vertex_count, T = rc->target_count;
	const uint32_t f = rc->flags;
	uint64_t total = round8(V * 12);
	total += (f & MLOD_PART_NORMALS) ? round8(V * 12) : 0;
	total += (f & MLOD_PART_TANGENTS) ? round8(V * 16) : 0;
	total += (uint64_t)rc->uv_sets * round8(V * 8);
	total += (f & MLOD_PART_COLORS) ? round8(V * 16) : 0;
	total += (f & MLOD_PART_SKINNED) ? round8(V * 8) + round8(V * 16) : 0;
	total += round8((uint64_t)rc->index_count * 4);
	if (T)
		total += round8(T * sizeof(float *)) + round8(T * 4) + T * round8(V * 12);
	return total;
}

#if MLOD_DRACO
/* A part's attribute in a Draco mesh (mlod(5), codec draco): the stream's
 * element as components of 1 or 2 bytes; 'POSQ' and 'MTPQ' drop their
 * fourth (zero) component. */
static void draco_comp(uint32_t tag, uint32_t elsize, int *components, int *bytes)
{
	if (elsize == 8) {
		*bytes = 2;
		*components = tag == MLOD_STREAM_POSQ || tag == MLOD_STREAM_MTPQ ? 3 : 4;
	} else if (tag == MLOD_STREAM_COLQ || tag == MLOD_STREAM_JNT8 || tag == MLOD_STREAM_WGT8) {
		*bytes = 1, *components = 4;
	} else {
		*bytes = 2, *components = 2;
	}
}

/* A MESH level of codec draco: stands alone (no coarser chunk is read).
 * 'PART', then per part 'DRCO' (its level as one Draco mesh) and, with
 * morph targets, 'MTSC'. */
static mlod_result decode_mesh_draco(const mesh_src *m, uint32_t chunk, const mlod_pack_skeleton *skel,
                                     mlod_pack_mesh *out, mlod_error *err)
{
	const mlod_pack *p = m->p;
	const mlod_pack_alloc *al = &p->alloc;
	cx x;
	memset(&x, 0, sizeof x);
	bump b = {0};
	stream s, sp;
	const uint8_t *src;
	mlod_pack_part_rec *recs = NULL;
	uint8_t *gather = NULL;
	uint32_t J = skel ? skel->joint_count : 0, S = skel ? skel->skin_count : 0;
	mlod_result r = mesh_begin(m, chunk, NULL, 0, &x, err);
	if (r != MLOD_OK) {
		cx_done(&x);
		return r;
	}
	TRY(cx_expect(&x, &sp, MLOD_STREAM_PART, sizeof(mlod_pack_part_rec), UINT64_MAX, "", "", err));
	if (sp.codec != MLOD_SCODEC_RAW)
		FAIL("%s: 'PART' is not stored raw in a Draco chunk", x.label);
	uint64_t P = sp.count; /* raw: its bytes are inside the chunk */
	TRY(cx_load(&x, &sp, &src, err));
	if (!(recs = pk_calloc(al, P + 1, sizeof *recs)))
		FAIL_NOMEM("%s: out of memory for %llu parts", x.label, (unsigned long long)P);
	for (uint64_t i = 0; i < P; i++)
		memcpy(&recs[i], src + i * sizeof *recs, sizeof *recs);
	/* The records bound every allocation before Draco decodes anything. */
	uint64_t total = round8(P * sizeof(mlod_pack_part)), big = 8;
	for (uint32_t i = 0; i < P; i++) {
		const mlod_pack_part_rec *rc = &recs[i];
		TRY(check_part_rec(&x, i, rc, J, S, err));
		if (rc->flags & (MLOD_PART_INDEX16 | MLOD_PART_LOCAL | MLOD_PART_NEWBITS))
			FAIL("%s: part %u: flags 0x%x: INDEX16, LOCAL and NEWBITS are not for a Draco chunk", x.label, i,
			     rc->flags);
		if ((rc->vertex_count == 0) != (rc->index_count == 0))
			FAIL("%s: part %u: %u vertices and %u indices: a Draco part has triangles or neither", x.label, i,
			     rc->vertex_count, rc->index_count);
		uint64_t V = rc->vertex_count, T = rc->target_count;
		uint32_t tag[VSTREAMS_MAX], size[VSTREAMS_MAX];
		int nv = part_vstreams(rc, tag, size);
		uint64_t stride = 8 * T;
		for (int a = 0; a < nv; a++)
			stride += size[a];
		total += decoded_part_bytes(rc);
		big = V * stride > big ? V * stride : big;
		if (total > PACK_MAX_BLOCK || big > PACK_MAX_BLOCK)
			FAIL("%s: decoded, its parts need more than the reader's limit", x.label);
	}
	if (total > (uint64_t)PACK_DRACO_MAX_EXPAND * x.size)
		FAIL("%s: its part records say %llu decoded bytes, more than %d times its %llu-byte container (Draco "
		     "levels expand no more)",
		     x.label, (unsigned long long)total, PACK_DRACO_MAX_EXPAND, (unsigned long long)x.size);
	if (m->reserve)
		TRY(m->reserve(m->reserve_user, recs, (uint32_t)P, err));
	TRY(bump_alloc(&b, &x, total, err));
	if (!(gather = pk_malloc(al, 1, (size_t)big)))
		FAIL_NOMEM("%s: out of memory", x.label);
	mlod_pack_part *parts = bump_take(&b, P * sizeof *parts);
	if (!parts)
		FAIL("%s: internal block size mismatch", x.label);
	for (uint32_t i = 0; i < P; i++) {
		mlod_pack_part *pt = &parts[i];
		pt->rec = recs[i];
		const mlod_pack_part_rec *rc = &pt->rec;
		uint32_t V = rc->vertex_count, T = rc->target_count, tag[VSTREAMS_MAX], size[VSTREAMS_MAX];
		int nv = part_vstreams(rc, tag, size);
		char what[32];
		snprintf(what, sizeof what, "part %u", i);
		TRY(cx_expect(&x, &s, MLOD_STREAM_DRCO, 1, UINT64_MAX, what, "", err));
		if (s.codec != MLOD_SCODEC_RAW)
			FAIL("%s: part %u: 'DRCO' is not stored raw", x.label, i);
		stream dr = s;
		mlod_rt_draco_attr at[VSTREAMS_MAX + 256];
		if (T > 256)
			FAIL("%s: part %u: %u morph targets, more than a Draco part's 256", x.label, i, T);
		size_t off = 0;
		for (int a = 0; a < nv + (int)T; a++) {
			uint32_t es = a < nv ? size[a] : 8, tg = a < nv ? tag[a] : MLOD_STREAM_MTPQ;
			draco_comp(tg, es, &at[a].components, &at[a].elsize);
			at[a].dst = gather + off;
			at[a].stride = es;
			off += (size_t)V * es;
		}
		memset(gather, 0, off); /* the dropped fourth components */
		TAKE(pt->indices, (uint64_t)rc->index_count * 4);
		char msg[160];
		if (V == 0 && dr.stored != 0) /* a part without triangles (mlod(5)) */
			FAIL("%s: part %u: no vertices, but a %llu-byte 'DRCO'", x.label, i, (unsigned long long)dr.stored);
		if (V > 0 && mlod_rt_draco_decode(dr.src, dr.stored, V, rc->index_count, at, nv + (int)T, pt->indices, msg,
		                                  sizeof msg) != 0)
			FAIL("%s: part %u: %s", x.label, i, msg);
		float *scales = NULL;
		if (T) {
			TRY(cx_expect(&x, &s, MLOD_STREAM_MTSC, 4, T, what, "target count", err));
			TRY(morph_scales(&x, &b, &s, pt, i, &scales, err));
		}
		TRY(part_dequant(x.label, &b, pt, i, gather, scales, skel, err));
	}
	TRY(cx_end(&x, err));
	out->part_count = (uint32_t)P;
	out->parts = parts;
	out->block = b.base;
	b.base = NULL;
	r = MLOD_OK;
fail:
	cx_done(&x);
	pk_free(al, b.base);
	pk_free(al, recs);
	pk_free(al, gather);
	return r;
}
#endif

static mlod_result decode_mesh(const mesh_src *m, uint32_t chunk, const mlod_pack_skeleton *skel, mlod_pack_mesh *out,
                               mlod_error *err)
{
	if (!out)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_pack_decode_mesh: out is NULL");
	memset(out, 0, sizeof *out);
	const mlod_pack *p = m->p;
	if (!p || (!m->fetch && !m->data && m->size))
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "pack decode: the pack or the data is NULL");
	cx x;
	mlod_result r = cx_head(p, chunk, MLOD_CHUNK_MESH, &x, err);
	if (r != MLOD_OK)
		return r;
#if MLOD_DRACO
	if (p->chunks[chunk].codec == MLOD_CODEC_DRACO)
		return decode_mesh_draco(m, chunk, skel, out, err);
#endif
	/* The chunks to read: every MESH level from the coarsest down to this
	 * one (their blocks make the prefix this level's indices refer to). */
	unsigned K = p->chunks[chunk].level, top = K;
	for (uint32_t i = 0; i < p->chunk_count; i++)
		if (p->chunks[i].type == MLOD_CHUNK_MESH && p->chunks[i].level > top)
			top = p->chunks[i].level;
	uint32_t nlev = top - K + 1;
	const mlod_pack_alloc *al = &p->alloc;
	bump b = {0};
	stream s;
	const uint8_t *src;
	uint32_t J = skel ? skel->joint_count : 0, S = skel ? skel->skin_count : 0;
	uint64_t P = 0;
	mlod_pack_part_rec *recs0 = NULL; /* the coarsest level's records */
	mblock *blk = NULL;               /* nlev * P */
	uint8_t *blocks = NULL, *temp = NULL; /* the levels' blocks; meshopt's output of the other streams */
	uint64_t blocks_used = 0, sumraw = 0, maxraw = 0, temp_cap = 0;
	uint32_t *map = NULL, *used = NULL;
	uint8_t *work = NULL, *gather = NULL;
	int lev_open = 0;
	memset(&x, 0, sizeof x);
	/* The chunks' raw sizes bound what their blocks and streams decode to
	 * (cx_parse checks them): two allocations for every level. */
	for (uint32_t l = 0; l < nlev; l++) {
		int ci = mlod_pack_find(p, MLOD_CHUNK_MESH, top - l, 0);
		/* An unknown codec or entropy stage: its raw size means nothing
		 * (cx_head says which; called only then, for its message). */
		if (ci >= 0 && (p->chunks[ci].codec > MLOD_CODEC_DRACO || p->chunks[ci].entropy > MLOD_ENTROPY_ZSTD_PREFIX) &&
		    (r = cx_head(p, (uint32_t)ci, MLOD_CHUNK_MESH, &x, err)) != MLOD_OK)
			return r;
		uint64_t raw = ci >= 0 ? p->chunks[ci].raw_size : 0;
		sumraw += raw;
		maxraw = raw > maxraw ? raw : maxraw;
	}
	if (sumraw > PACK_MAX_BLOCK)
		return mlod_fail(err, MLOD_ERR_NOMEM, "MESH level %u: decoding it and the coarser levels needs %llu bytes, more "
		                 "than the reader's limit", K, (unsigned long long)sumraw);
	/* The prefix of the finest prefix-coded level read (format 6.0): the
	 * containers of the levels above it, coarsest first, kept as they are
	 * read; each container's size is its TOC coded size, or its stored
	 * size without an entropy stage (cx_parse checks both). */
	unsigned pmin = 0; /* that level + 1; 0: no level read is prefix-coded */
	uint64_t pcap = 0, pused = 0;
	uint8_t *pbuf = NULL;
	for (uint32_t l = 0; l < nlev; l++) {
		int ci = mlod_pack_find(p, MLOD_CHUNK_MESH, top - l, 0);
		if (ci >= 0 && p->chunks[ci].entropy == MLOD_ENTROPY_ZSTD_PREFIX)
			pmin = top - l + 1;
	}
	for (unsigned L = top; pmin && L >= pmin; L--) {
		int ci = mlod_pack_find(p, MLOD_CHUNK_MESH, L, 0);
		if (ci >= 0)
			pcap += p->chunks[ci].entropy ? p->chunks[ci].coded_size : p->chunks[ci].stored_size;
		if (L == 0)
			break;
	}
	if (pcap > MLOD_PACK_MAX_PREFIX)
		return mlod_fail(err, MLOD_ERR_PARSE, "MESH level %u: its prefix (MESH levels %u to %u's containers) is %llu "
		                 "bytes, more than the format's %llu", pmin - 1, top, pmin, (unsigned long long)pcap,
		                 (unsigned long long)MLOD_PACK_MAX_PREFIX);
	if (pmin && !(pbuf = pk_malloc(al, 1, (size_t)pcap + 1)))
		return mlod_fail(err, MLOD_ERR_NOMEM, "MESH level %u: out of memory for its %llu-byte prefix", pmin - 1,
		                 (unsigned long long)pcap);
	blocks = pk_malloc(al, 1, (size_t)sumraw + 8);
	if (!blocks) {
		pk_free(al, pbuf);
		return mlod_fail(err, MLOD_ERR_NOMEM, "MESH level %u: out of memory", K);
	}
	for (uint32_t l = 0; l < nlev; l++) {
		unsigned L = top - l;
		int ci = mlod_pack_find(p, MLOD_CHUNK_MESH, L, 0);
		if (ci < 0) {
			r = mlod_fail(err, MLOD_ERR_PARSE, "MESH level %u: MESH level %u is missing (a level needs every coarser "
			              "one)", K, L);
			goto fail;
		}
		if (p->chunks[ci].codec == MLOD_CODEC_DRACO)
			FAIL("MESH level %u: builds on MESH level %u, which is Draco-coded (a Draco level stands alone; layout "
			     "b2 levels cannot use its vertices)", K, L);
		TRY(mesh_begin(m, (uint32_t)ci, pbuf, pused, &x, err));
		lev_open = 1;
		if (pmin && L >= pmin) {
			if (x.size > pcap - pused)
				FAIL("%s: its container of %llu bytes does not fit the prefix's %llu", x.label,
				     (unsigned long long)x.size, (unsigned long long)(pcap - pused));
			memcpy(pbuf + pused, x.base, (size_t)x.size);
			pused += x.size;
		}
		stream sp;
		TRY(cx_expect(&x, &sp, MLOD_STREAM_PART, sizeof(mlod_pack_part_rec), l ? P : UINT64_MAX, "",
		              "the parts of the coarsest level", err));
		if (l == 0) {
			P = sp.count;
			if (P * (2 * sizeof *recs0 + nlev * sizeof *blk + sizeof(mlod_pack_part)) > PACK_MAX_BLOCK) {
				r = mlod_fail(err, MLOD_ERR_NOMEM, "%s: %llu parts: decoding them needs more than the reader's limit",
				              x.label, (unsigned long long)P);
				goto fail;
			}
			recs0 = pk_calloc(al, P + 1, sizeof *recs0);
			blk = pk_calloc(al, (uint64_t)nlev * P + 1, sizeof *blk);
			if (!recs0 || !blk) {
				r = mlod_fail(err, MLOD_ERR_NOMEM, "%s: out of memory for %llu parts", x.label, (unsigned long long)P);
				goto fail;
			}
		}
		/* Size this level's blocks from the stream headers. */
		uint64_t bytes = 0;
		/* meshopt's output of the streams not decoded into a block: 'PART'
		 * (read above), 'IDX ' and 'MTSC' */
		uint64_t need = sp.codec != MLOD_SCODEC_RAW ? (uint64_t)sp.count * sp.elsize : 0;
		{
			stream t;
			while (cx_next(&x, &t))
				if (t.tag != MLOD_STREAM_IDX && t.tag != MLOD_STREAM_INEW && t.tag != MLOD_STREAM_IMAP &&
				    t.tag != MLOD_STREAM_MTSC && t.tag != MLOD_STREAM_PART)
					bytes += round8((uint64_t)t.count * t.elsize);
				else if (t.codec != MLOD_SCODEC_RAW && (uint64_t)t.count * t.elsize > need)
					need = (uint64_t)t.count * t.elsize;
			cx_rewind(&x);
			TRY(cx_expect(&x, &sp, MLOD_STREAM_PART, sizeof(mlod_pack_part_rec), P, "", "", err));
		}
		if (bytes > sumraw - blocks_used || need > maxraw)
			FAIL("%s: internal block size mismatch", x.label);
		if (need > temp_cap) {
			pk_free(al, temp);
			temp_cap = 0;
			if (!(temp = pk_malloc(al, 1, (size_t)need + 8)))
				FAIL_NOMEM("%s: out of memory for %llu bytes of scratch", x.label, (unsigned long long)need);
			temp_cap = need;
		}
		x.temp = temp, x.aux = 0; /* the decode's scratch, shared by the levels (cx_done frees none) */
		uint8_t *at = blocks + blocks_used;
		blocks_used += bytes;
		TRY(cx_load(&x, &sp, &src, err));
		mlod_pack_part_rec *recs = pk_calloc(al, P + 1, sizeof *recs);
		if (!recs) {
			r = mlod_fail(err, MLOD_ERR_NOMEM, "%s: out of memory", x.label);
			goto fail;
		}
		for (uint64_t i = 0; i < P; i++)
			memcpy(&recs[i], src + i * sizeof(mlod_pack_part_rec), sizeof(mlod_pack_part_rec));
		for (uint32_t i = 0; i < P && r == MLOD_OK; i++) {
			r = check_part_rec(&x, i, &recs[i], J, S, err);
			if (r == MLOD_OK && l == 0)
				recs0[i] = recs[i];
			else if (r == MLOD_OK && !same_part(&recs[i], &recs0[i]))
				r = mlod_fail(err, MLOD_ERR_PARSE,
				              "%s: part %u: its record differs from MESH level %u's (a part's levels share its "
				              "node, skin, attributes and grid)",
				              x.label, i, top);
		}
		if (r != MLOD_OK) {
			pk_free(al, recs);
			goto fail;
		}
		for (uint32_t i = 0; i < P && r == MLOD_OK; i++) {
			const mlod_pack_part_rec *rc = &recs[i];
			mblock *mb = &blk[(uint64_t)l * P + i];
			char what[32];
			snprintf(what, sizeof what, "part %u", i);
			uint32_t tag[VSTREAMS_MAX], size[VSTREAMS_MAX];
			int nv = part_vstreams(rc, tag, size);
			mb->first = l ? blk[(uint64_t)(l - 1) * P + i].first + blk[(uint64_t)(l - 1) * P + i].count : 0;
			mb->base = at;
			uint64_t off = 0;
			for (int a = 0; a < nv && r == MLOD_OK; a++) {
				r = cx_expect(&x, &s, tag[a], size[a], a ? mb->count : UINT64_MAX, what, "the block's vertex count",
				              err);
				if (r == MLOD_OK && a == 0)
					mb->count = s.count;
				if (r == MLOD_OK)
					r = cx_load_into(&x, &s, mb->base + off, err);
				off += (uint64_t)s.count * size[a];
			}
			if (r != MLOD_OK)
				break;
			int i16 = (rc->flags & MLOD_PART_INDEX16) != 0;
			if (rc->flags & MLOD_PART_LOCAL) {
				if (rc->flags & MLOD_PART_NEWBITS)
					r = cx_expect(&x, &s, MLOD_STREAM_INEW, 4, ((uint64_t)rc->vertex_count + 31) / 32, what,
					              "a bit per vertex", err);
				if (r == MLOD_OK) /* its count: checked against 'INEW' when decoded */
					r = cx_expect(&x, &s, MLOD_STREAM_IMAP, i16 ? 2 : 4, UINT64_MAX, what, "", err);
			}
			if (r == MLOD_OK)
				r = cx_expect(&x, &s, MLOD_STREAM_IDX, i16 ? 2 : 4, rc->index_count, what, "index count", err);
			if (r == MLOD_OK && rc->target_count > 0)
				r = cx_expect(&x, &s, MLOD_STREAM_MTSC, 4, rc->target_count, what, "target count", err);
			for (uint32_t t = 0; t < rc->target_count && r == MLOD_OK; t++) {
				char twhat[64];
				snprintf(twhat, sizeof twhat, "part %u target %u", i, t);
				r = cx_expect(&x, &s, MLOD_STREAM_MTPQ, 8, mb->count, twhat, "the block's vertex count", err);
				if (r == MLOD_OK)
					r = cx_load_into(&x, &s, mb->base + off, err);
				off += (uint64_t)s.count * 8;
			}
			at += round8(off);
			if (r != MLOD_OK || l + 1 < nlev)
				continue;
			/* This level: gather the vertices its indices use. */
			uint64_t prefix = mb->first + mb->count;
			if (rc->vertex_count > prefix) {
				r = mlod_fail(err, MLOD_ERR_PARSE, "%s: part %u: %u vertices, more than its prefix of %llu (MESH levels %u to %u)",
				              x.label, i, rc->vertex_count, (unsigned long long)prefix, top, K);
				break;
			}
		}
		if (r != MLOD_OK) {
			pk_free(al, recs);
			goto fail;
		}
		if (l + 1 < nlev) {
			TRY(cx_end(&x, err));
			x.temp = NULL;
			cx_done(&x);
			lev_open = 0;
			pk_free(al, recs);
			continue;
		}
		/* The finest level read is the one asked for: its output. */
		uint64_t total = round8(P * sizeof(mlod_pack_part)), big_prefix = 1, big_v = 1;
		for (uint32_t i = 0; i < P; i++) {
			const mlod_pack_part_rec *rc = &recs[i];
			uint64_t V = rc->vertex_count, T = rc->target_count;
			total += decoded_part_bytes(rc);
			const mblock *mb = &blk[(uint64_t)l * P + i];
			uint64_t stride = 0;
			uint32_t tag[VSTREAMS_MAX], size[VSTREAMS_MAX];
			int nv = part_vstreams(rc, tag, size);
			for (int a = 0; a < nv; a++)
				stride += size[a];
			stride += 8 * T;
			big_prefix = mb->first + mb->count > big_prefix ? mb->first + mb->count : big_prefix;
			big_v = V * stride > big_v ? V * stride : big_v;
			if (total > PACK_MAX_BLOCK || big_v > PACK_MAX_BLOCK)
				break;
		}
		if (big_prefix > PACK_MAX_BLOCK / 8 || big_v > PACK_MAX_BLOCK) {
			pk_free(al, recs);
			FAIL("%s: its parts' prefixes (%llu vertices) are larger than the reader's limit", x.label,
			     (unsigned long long)big_prefix);
		}
		if (m->reserve && (r = m->reserve(m->reserve_user, recs, (uint32_t)P, err)) != MLOD_OK) {
			pk_free(al, recs);
			goto fail;
		}
		r = bump_alloc(&b, &x, total, err);
		work = pk_malloc(al, 1, (size_t)(8 * big_prefix + big_v + 8));
		if (work) {
			map = (uint32_t *)work;
			used = map + big_prefix;
			gather = (uint8_t *)(used + big_prefix);
		}
		if (r == MLOD_OK && !work)
			r = mlod_fail(err, MLOD_ERR_NOMEM, "%s: out of memory", x.label);
		if (r != MLOD_OK) {
			pk_free(al, recs);
			goto fail;
		}
		mlod_pack_part *parts = bump_take(&b, P * sizeof *parts);
		if (!parts) {
			pk_free(al, recs);
			FAIL("%s: internal block size mismatch", x.label);
		}
		for (uint64_t i = 0; i < P; i++)
			parts[i].rec = recs[i];
		pk_free(al, recs);
		/* Walk the chunk again for the indices and the targets' scales. */
		cx_rewind(&x);
		TRY(cx_expect(&x, &sp, MLOD_STREAM_PART, sizeof(mlod_pack_part_rec), P, "", "", err));
		for (uint32_t i = 0; i < P; i++) {
			mlod_pack_part *pt = &parts[i];
			const mlod_pack_part_rec *rc = &pt->rec;
			uint32_t tag[VSTREAMS_MAX], size[VSTREAMS_MAX];
			int nvs = part_vstreams(rc, tag, size);
			for (int a = 0; a < nvs; a++)
				cx_next(&x, &s);
			int i16 = (rc->flags & MLOD_PART_INDEX16) != 0, local = (rc->flags & MLOD_PART_LOCAL) != 0;
			const mblock *mb = &blk[(uint64_t)l * P + i];
			uint64_t prefix = mb->first + mb->count;
			uint32_t V = rc->vertex_count, nused = 0;
			if (local) { /* the prefix vertex of each of the level's: 'INEW', 'IMAP' */
				uint32_t nnew = 0, nold = 0, w = 0;
				int bits = (rc->flags & MLOD_PART_NEWBITS) != 0;
				if (bits) {
					cx_next(&x, &s);
					TRY(cx_load(&x, &s, &src, err));
				}
				for (uint32_t v = 0; v < V; v++) {
					if (bits)
						memcpy(&w, src + 4 * (size_t)(v / 32), 4);
					if (!(w >> (v % 32) & 1u)) {
						used[v] = UINT32_MAX, nold++;
						continue;
					}
					if (nnew == mb->count)
						FAIL("%s: part %u: 'INEW' marks more than its block's %u vertices new", x.label, i,
						     mb->count);
					used[v] = (uint32_t)mb->first + nnew++;
				}
				cx_next(&x, &s);
				if (s.count != nold)
					FAIL("%s: part %u: stream %u 'IMAP' has %u elements, expected %u (the vertices 'INEW' leaves)",
					     x.label, i, s.index, s.count, nold);
				TRY(cx_load(&x, &s, &src, err));
				for (uint32_t v = 0, o = 0; v < V; v++) {
					if (used[v] != UINT32_MAX)
						continue;
					const uint32_t iv = index_at(src, i16, o);
					if (iv >= prefix)
						FAIL("%s: part %u: vertex %u maps to %u, past its prefix of %llu vertices (MESH levels %u "
						     "to %u)",
						     x.label, i, v, iv, (unsigned long long)prefix, top, K);
					used[v] = iv, o++;
				}
				nused = V;
			}
			cx_next(&x, &s); /* 'IDX ', checked above */
			TRY(cx_load(&x, &s, &src, err));
			for (uint64_t v = 0; v < prefix && !local; v++)
				map[v] = UINT32_MAX;
			TAKE(pt->indices, (uint64_t)rc->index_count * 4);
			for (uint32_t k = 0; k < rc->index_count && local; k++) {
				const uint32_t iv = index_at(src, i16, k);
				if (iv >= V)
					FAIL("%s: part %u: index %u refers past its %u vertices (at position %u)", x.label, i, iv, V, k);
				pt->indices[k] = iv;
			}
			for (uint32_t k = 0; k < rc->index_count && !local; k++) {
				const uint32_t iv = index_at(src, i16, k);
				if (iv >= prefix)
					FAIL("%s: part %u: index %u refers past its prefix of %llu vertices (MESH levels %u to %u; at "
					     "position %u)",
					     x.label, i, iv, (unsigned long long)prefix, top, K, k);
				if (map[iv] == UINT32_MAX) {
					if (nused == V)
						FAIL("%s: part %u: its indices use more than its %u vertices", x.label, i, V);
					used[nused] = iv;
					map[iv] = nused++;
				}
				pt->indices[k] = map[iv];
			}
			if (nused != V)
				FAIL("%s: part %u: its indices use %u vertices, its record says %u", x.label, i, nused, V);
			float *scales = NULL;
			uint32_t T = rc->target_count;
			if (T) {
				cx_next(&x, &s); /* 'MTSC', checked above */
				TRY(morph_scales(&x, &b, &s, pt, i, &scales, err));
				for (uint32_t t = 0; t < T; t++)
					cx_next(&x, &s);
			}
			/* Gather: each attribute of the level's vertices, one after
			 * the other, from the levels' blocks (coarsest first; map[v]
			 * becomes vertex v's block). */
			for (uint32_t v = 0; v < V; v++) {
				uint32_t lo = 0, hi = nlev - 1;
				while (lo < hi) {
					uint32_t mid = lo + (hi - lo + 1) / 2;
					if (blk[(uint64_t)mid * P + i].first <= used[v])
						lo = mid;
					else
						hi = mid - 1;
				}
				map[v] = lo;
			}
			uint64_t aoff = 0, before = 0;
			for (int a = 0; a < nvs + (int)T; a++) {
				uint32_t es = a < nvs ? size[a] : 8;
				uint8_t *dst = gather + aoff;
				const uint8_t *from[64];
				uint64_t first[64];
				for (uint32_t q = 0; q < nlev && q < 64; q++) { /* attribute a of each level's block */
					const mblock *bb = &blk[(uint64_t)q * P + i];
					from[q] = bb->base + before * bb->count, first[q] = bb->first;
				}
				for (uint32_t v = 0; v < V; v++) {
					const uint8_t *sv;
					if (map[v] < 64) {
						sv = from[map[v]] + (used[v] - first[map[v]]) * es;
					} else {
						const mblock *bb = &blk[(uint64_t)map[v] * P + i];
						sv = bb->base + before * bb->count + (used[v] - bb->first) * es;
					}
					if (es == 4)
						memcpy(dst + (size_t)v * 4, sv, 4);
					else
						memcpy(dst + (size_t)v * 8, sv, 8);
				}
				aoff += (uint64_t)V * es;
				before += es;
			}
			TRY(part_dequant(x.label, &b, pt, i, gather, scales, skel, err));
		}
		TRY(cx_end(&x, err));
		x.temp = NULL;
		cx_done(&x);
		lev_open = 0;
		out->part_count = (uint32_t)P;
		out->parts = parts;
		out->block = b.base;
		b.base = NULL;
	}
	r = MLOD_OK;
fail:
	if (lev_open) {
		x.temp = NULL;
		cx_done(&x);
	}
	pk_free(al, b.base);
	pk_free(al, blocks);
	pk_free(al, pbuf);
	pk_free(al, temp);
	pk_free(al, recs0);
	pk_free(al, blk);
	pk_free(al, work);
	return r;
}

mlod_result mlod_pack_decode_mesh(const mlod_pack *p, uint32_t chunk, const void *data, size_t size,
                                  const mlod_pack_skeleton *skel, mlod_pack_mesh *out, mlod_error *err)
{
	mesh_src m = {p, data, size, NULL, NULL, NULL, NULL};
	return decode_mesh(&m, chunk, skel, out, err);
}

mlod_result mlod_pack_decode_mesh_reserve(const mlod_pack *p, uint32_t chunk, const void *data, size_t size,
                                          mlod_pack_fetch_fn fetch, void *fetch_user, mlod_pack_reserve_fn reserve,
                                          void *reserve_user, const mlod_pack_skeleton *skel, mlod_pack_mesh *out,
                                          mlod_error *err)
{
	mesh_src m = {p, fetch ? NULL : data, fetch ? 0 : size, fetch, fetch_user, reserve, reserve_user};
	return decode_mesh(&m, chunk, skel, out, err);
}

mlod_result mlod_pack_decode_mesh_fetch(const mlod_pack *p, uint32_t chunk, mlod_pack_fetch_fn fetch, void *user,
                                        const mlod_pack_skeleton *skel, mlod_pack_mesh *out, mlod_error *err)
{
	if (!fetch) {
		if (out)
			memset(out, 0, sizeof *out);
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_pack_decode_mesh_fetch: fetch is NULL");
	}
	mesh_src m = {p, NULL, 0, fetch, user, NULL, NULL};
	return decode_mesh(&m, chunk, skel, out, err);
}

void mlod_pack_mesh_free(mlod_pack_mesh *x)
{
	if (!x)
		return;
	block_free(x->block);
	memset(x, 0, sizeof *x);
}

/* ------------------------------------------------------------------ */
/* MOTION level k of clip c                                            */
/* ------------------------------------------------------------------ */

/* The base channel of a rotation channel: the base's non-cubic rotation
 * of the same joint, or NULL. */
static const mlod_pack_channel *base_channel(const mlod_pack_motion *base, uint32_t joint)
{
	for (uint32_t i = 0; base && i < base->channel_count; i++)
		if (base->channels[i].rec.joint == joint && base->channels[i].rec.path == 1 && base->channels[i].rec.interp != 2)
			return &base->channels[i];
	return NULL;
}

/* The same for a non-cubic translation or scale channel (path). */
static const mlod_pack_channel *base_vec_channel(const mlod_pack_motion *base, const mlod_pack_channel_rec *rc)
{
	for (uint32_t i = 0; base && rc->interp != 2 && i < base->channel_count; i++)
		if (base->channels[i].rec.joint == rc->joint && base->channels[i].rec.path == rc->path &&
		    base->channels[i].rec.interp != 2)
			return &base->channels[i];
	return NULL;
}

/* The index of time t in a base channel's times (increasing), or -1. */
/* The key of base channel bc at time t, or -1. *from: where the search
 * starts, the previous call's key slot on the same channel (0 for the
 * first): a channel's keys are visited in time order, so the search gallops
 * forward from there, and the whole channel costs linear time instead of
 * a binary search per key (the probe's 50,000-frame clip spent 71% of its
 * decoding here). The key found is the same as a search from 0 (when the
 * time before *from is below t; else it searches from 0). */
static int64_t base_key(const mlod_pack_channel *bc, float t, uint32_t *from)
{
	uint32_t n = bc ? bc->rec.key_count : 0, lo = *from < n ? *from : n, hi, step = 1;
	if (lo > 0 && !(bc->times[lo - 1] < t))
		lo = 0;
	/* the key is at lo or after (times[lo - 1] < t); gallop until a time
	 * at hi is not below t, then search [lo, hi) */
	for (hi = lo; hi < n && bc->times[hi] < t; step *= 2)
		lo = hi + 1, hi = n - hi > step ? hi + step : n;
	while (lo < hi) {
		uint32_t mid = lo + (hi - lo) / 2;
		if (bc->times[mid] < t)
			lo = mid + 1;
		else
			hi = mid;
	}
	*from = lo;
	return lo < n && bc->times[lo] == t ? (int64_t)lo : -1;
}

mlod_result mlod_pack_decode_motion(const mlod_pack *p, uint32_t chunk, const void *data, size_t size,
                                    const mlod_pack_skeleton *skel, mlod_pack_motion *out, mlod_error *err)
{
	if (!out)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_pack_decode_motion: out is NULL");
	memset(out, 0, sizeof *out);
	if (!p || chunk >= p->chunk_count || p->chunks[chunk].type != MLOD_CHUNK_MOTION ||
	    !(p->chunks[chunk].flags & MLOD_PACK_CHUNK_NESTED))
		return mlod_pack_decode_motion_on(p, chunk, data, size, skel, NULL, out, err);
	/* The chain of levels it builds on, decoded from the coarsest up. */
	const mlod_pack_chunk *c = &p->chunks[chunk];
	unsigned top = c->level;
	int ci = (int)chunk;
	while (ci >= 0 && (p->chunks[ci].flags & MLOD_PACK_CHUNK_NESTED)) {
		if (top - c->level >= MLOD_PACK_MAX_NESTING)
			return mlod_fail(err, MLOD_ERR_PARSE, "MOTION level %u of clip %u: more than %d nested levels in a row",
			                 (unsigned)c->level, (unsigned)c->item, MLOD_PACK_MAX_NESTING);
		if (top == 65535 || (ci = mlod_pack_find(p, MLOD_CHUNK_MOTION, top + 1, c->item)) < 0)
			return mlod_fail(err, MLOD_ERR_PARSE, "MOTION level %u of clip %u: builds on level %u, which the pack lacks",
			                 top, (unsigned)c->item, top + 1);
		top++;
	}
	mlod_pack_motion base = {0}, next;
	for (unsigned l = top + 1; l-- > c->level;) {
		int k = l == c->level ? (int)chunk : mlod_pack_find(p, MLOD_CHUNK_MOTION, l, c->item);
		mlod_result r = mlod_pack_decode_motion_on(p, (uint32_t)k, data, size, skel, l == top ? NULL : &base,
		                                           l == c->level ? out : &next, err);
		mlod_pack_motion_free(&base);
		if (r != MLOD_OK)
			return r;
		if (l > c->level)
			base = next;
	}
	return MLOD_OK;
}

mlod_result mlod_pack_decode_motion_on(const mlod_pack *p, uint32_t chunk, const void *data, size_t size,
                                       const mlod_pack_skeleton *skel, const mlod_pack_motion *base,
                                       mlod_pack_motion *out, mlod_error *err)
{
	if (!out)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_pack_decode_motion: out is NULL");
	memset(out, 0, sizeof *out);
	cx x;
	bump b = {0};
	stream s;
	const uint8_t *src;
	mlod_result r = cx_begin(p, chunk, MLOD_CHUNK_MOTION, data, size, &x, err);
	if (r != MLOD_OK)
		return r;
	const int nested = (x.c->flags & MLOD_PACK_CHUNK_NESTED) != 0;
	if (!nested)
		base = NULL;
	else if (!base)
		FAIL("%s: builds on level %u, which was not given", x.label, (unsigned)x.c->level + 1);
	uint32_t J = skel ? skel->joint_count : 0;
	stream sc, sstep;
	TRY(cx_expect(&x, &sc, MLOD_STREAM_CHAN, sizeof(mlod_pack_channel_rec), UINT64_MAX, "", "", err));
	TRY(cx_expect(&x, &sstep, MLOD_STREAM_STEP, 8, 1, "", "one step", err));
	/* each channel's values are taken on their own: up to 8 bytes of
	 * rounding each */
	uint64_t C = sc.count, total = round8(C * sizeof(mlod_pack_channel)) + 8 * C;
	while (cx_next(&x, &s)) {
		/* 'TBIT': each key but an array's first takes a bit at least */
		uint64_t per = s.tag == MLOD_STREAM_TBIT                                 ? 4 * 32
		               : s.tag == MLOD_STREAM_TIME || s.tag == MLOD_STREAM_TICK ? 4
		               : s.tag == MLOD_STREAM_ROTQ || s.tag == MLOD_STREAM_ROTD || s.tag == MLOD_STREAM_ROTF ? 16
		               : s.tag == MLOD_STREAM_VEC3 || s.tag == MLOD_STREAM_VECD   ? 12
		                                                                          : 0;
		if (!per)
			FAIL("%s: stream %u is '%s', not a motion stream", x.label, s.index, tagn(s.tag).s);
		total += round8(per * s.count);
	}
	/* the time arrays: a pointer and a count per array, at most one per
	 * channel */
	total += round8(C * sizeof(float *)) + round8(C * 4);
	cx_rewind(&x);
	/* aux: one byte per joint and path, to find a second channel. */
	TRY(cx_temp(&x, (uint64_t)J * 3, err));
	TRY(bump_alloc(&b, &x, total, err));
	uint8_t *seen = x.temp;
	mlod_pack_channel *chans;
	const float **tarr;
	uint32_t *tcount;
	TAKE(chans, C * sizeof *chans);
	TAKE(tarr, C * sizeof *tarr);
	TAKE(tcount, C * sizeof *tcount);
	TRY(cx_expect(&x, &sc, MLOD_STREAM_CHAN, sizeof(mlod_pack_channel_rec), UINT64_MAX, "", "", err));
	TRY(cx_load(&x, &sc, &src, err));
	for (uint64_t i = 0; i < C; i++)
		memcpy(&chans[i].rec, src + i * sizeof(mlod_pack_channel_rec), sizeof(mlod_pack_channel_rec));
	TRY(cx_expect(&x, &sstep, MLOD_STREAM_STEP, 8, 1, "", "one step", err));
	TRY(cx_load(&x, &sstep, &src, err));
	double step;
	{
		uint64_t bits = rd64(src);
		memcpy(&step, &bits, 8);
	}
	if (!isfinite(step) || !(step >= 0))
		FAIL("%s: step %g is not finite and >= 0", x.label, step);
	float duration = 0;
	static const char *const path_names[3] = {"translation", "rotation", "scale"};
	/* The channels; the time arrays' counts, in first-use order. */
	uint64_t T = 0, nt = 0, nq = 0, nf = 0, nv = 0;
	for (uint32_t i = 0; i < C; i++) {
		const mlod_pack_channel_rec *rc = &chans[i].rec;
		uint32_t K = rc->key_count;
		if (rc->joint >= J)
			FAIL("%s: channel %u: joint %u is not below the skeleton's %u joints", x.label, i, rc->joint, J);
		if (rc->path > 2)
			FAIL("%s: channel %u: path %u is not 0, 1 or 2", x.label, i, rc->path);
		if (rc->interp > 2)
			FAIL("%s: channel %u: interpolation %u is not 0, 1 or 2", x.label, i, rc->interp);
		if (K == 0)
			FAIL("%s: channel %u: no keys", x.label, i);
		if (seen[3 * (size_t)rc->joint + rc->path])
			FAIL("%s: channel %u: a second %s channel of joint %u", x.label, i, path_names[rc->path], rc->joint);
		seen[3 * (size_t)rc->joint + rc->path] = 1;
		if (rc->time > T)
			FAIL("%s: channel %u: time array %u is not below %llu (the arrays go in first-use order)", x.label, i,
			     rc->time, (unsigned long long)T + 1);
		if (rc->time == T) {
			tcount[T++] = K;
			nt += K;
		} else if (tcount[rc->time] != K) {
			FAIL("%s: channel %u: %u keys, but time array %u has %u", x.label, i, K, rc->time, tcount[rc->time]);
		}
		uint64_t m = rc->interp == 2 ? 3 : 1;
		if (rc->path == 1 && m == 1)
			nq += K;
		else if (rc->path == 1)
			nf += 3 * (uint64_t)K;
		else
			nv += m * K;
	}
	/* The key times: one stream, the arrays one after the other. */
	if (!cx_next(&x, &s))
		FAIL("%s: missing its key times", x.label);
	if (step > 0 ? s.tag != MLOD_STREAM_TICK && s.tag != MLOD_STREAM_TBIT : s.tag != MLOD_STREAM_TIME)
		FAIL("%s: stream %u is '%s', expected '%s' (step %g)", x.label, s.index, tagn(s.tag).s,
		     step > 0 ? "TICK' or 'TBIT" : "TIME", step);
	if (s.tag == MLOD_STREAM_TICK ? s.elsize != 2 && s.elsize != 4 : s.elsize != 4)
		FAIL("%s: stream %u '%s' has elements of %u bytes, expected %s", x.label, s.index, tagn(s.tag).s, s.elsize,
		     s.tag == MLOD_STREAM_TICK ? "2 or 4" : "4");
	if (s.tag == MLOD_STREAM_TBIT ? s.count < T : s.count != nt)
		FAIL("%s: stream %u '%s' has %u elements, expected %s%llu (the time arrays' %s)", x.label, s.index,
		     tagn(s.tag).s, s.count, s.tag == MLOD_STREAM_TBIT ? "at least " : "",
		     (unsigned long long)(s.tag == MLOD_STREAM_TBIT ? T : nt),
		     s.tag == MLOD_STREAM_TBIT ? "first ticks" : "keys");
	TRY(cx_load(&x, &s, &src, err));
	float *all;
	TAKE(all, nt * 4);
	if (s.tag == MLOD_STREAM_TIME) {
		memcpy(all, src, (size_t)nt * 4);
	} else if (s.tag == MLOD_STREAM_TBIT) { /* each array's first tick, then a bit per tick after it */
		uint64_t nbits = 32 * ((uint64_t)s.count - T), b = 0;
		for (uint64_t t = 0, k = 0; t < T; t++) {
			uint64_t tick = rd32(src + 4 * t);
			for (uint32_t q = 0; q < tcount[t]; q++, k++) {
				while (q > 0) { /* to the next set bit */
					if (b == nbits)
						FAIL("%s: stream %u 'TBIT': time array %u: key %u: the bits run out", x.label, s.index,
						     (unsigned)t, q);
					tick++;
					uint32_t w = rd32(src + 4 * (T + b / 32));
					if (w >> (b++ % 32) & 1u)
						break;
				}
				if (tick > UINT32_MAX)
					FAIL("%s: stream %u 'TBIT': time array %u: key %u: tick %llu is above 2^32 - 1", x.label,
					     s.index, (unsigned)t, q, (unsigned long long)tick);
				all[k] = (float)((double)tick * step);
			}
		}
		if ((b + 31) / 32 != (uint64_t)s.count - T)
			FAIL("%s: stream %u 'TBIT' has %u elements, expected %llu (the arrays' first ticks and bits)", x.label,
			     s.index, s.count, (unsigned long long)(T + (b + 31) / 32));
	} else /* each array's first tick, then each next's difference */
		for (uint64_t t = 0, k = 0; t < T; t++) {
			uint64_t tick = 0;
			for (uint32_t q = 0; q < tcount[t]; q++, k++) {
				tick += s.elsize == 2 ? rd16(src + 2 * k) : rd32(src + 4 * k);
				if (tick > UINT32_MAX)
					FAIL("%s: stream %u '%s': time array %u: key %u: tick %llu is above 2^32 - 1", x.label,
					     s.index, tagn(s.tag).s, (unsigned)t, q, (unsigned long long)tick);
				all[k] = (float)((double)tick * step);
			}
		}
	for (uint64_t t = 0, at = 0; t < T; at += tcount[t++]) {
		const float *times = all + at;
		for (uint32_t k = 0; k < tcount[t]; k++) {
			if (!isfinite(times[k]))
				FAIL("%s: time array %u: key %u: time is not finite", x.label, (unsigned)t, k);
			if (k > 0 && !(times[k] > times[k - 1]))
				FAIL("%s: time array %u: key %u: time %g is not after %g", x.label, (unsigned)t, k,
				     (double)times[k], (double)times[k - 1]);
		}
		tarr[t] = times;
	}
	for (uint32_t i = 0; i < C; i++) {
		mlod_pack_channel *ch = &chans[i];
		const mlod_pack_channel_rec *rc = &ch->rec;
		uint32_t K = rc->key_count;
		const float *times = tarr[rc->time];
		if (times[K - 1] > duration)
			duration = times[K - 1];
		ch->times = times;
	}
	/* The values: 'ROTQ', 'ROTF', 'VEC3', each the keys of its channels
	 * one channel after the other, in channel order. */
	/* 'ROTQ' holds the rotation keys on their own, 'ROTD' those on a key
	 * of the base at the same time (mlod_pack_rotq_key): each element goes
	 * to its key's slot, then every key is decoded in place. */
	uint64_t nd = 0;
	for (uint32_t i = 0; i < C; i++) {
		mlod_pack_channel *ch = &chans[i];
		if (ch->rec.path != 1 || ch->rec.interp == 2)
			continue;
		TAKE(ch->values, (uint64_t)ch->rec.key_count * 16);
		const mlod_pack_channel *bc = base_channel(base, ch->rec.joint);
		uint32_t from = 0;
		for (uint32_t k = 0; bc && k < ch->rec.key_count; k++)
			nd += base_key(bc, ch->times[k], &from) >= 0;
	}
	for (int pass = 0; pass < 2; pass++) {
		if (pass == 0)
			TRY(cx_expect(&x, &s, MLOD_STREAM_ROTQ, 8, nq - nd, "", "rotation keys without a base key", err));
		else
			TRY(cx_expect(&x, &s, MLOD_STREAM_ROTD, 8, nd, "", "rotation keys on a base key", err));
		TRY(cx_load(&x, &s, &src, err));
		for (uint32_t i = 0; i < C; i++) {
			mlod_pack_channel *ch = &chans[i];
			if (ch->rec.path != 1 || ch->rec.interp == 2)
				continue;
			const mlod_pack_channel *bc = base_channel(base, ch->rec.joint);
			uint32_t from = 0;
			for (uint32_t k = 0; k < ch->rec.key_count; k++)
				if ((base_key(bc, ch->times[k], &from) >= 0) == pass) {
					memcpy(ch->values + 4 * (size_t)k, src, 8);
					src += 8;
				}
		}
	}
	for (uint32_t i = 0; i < C; i++) {
		mlod_pack_channel *ch = &chans[i];
		if (ch->rec.path != 1 || ch->rec.interp == 2)
			continue;
		const mlod_pack_channel *bc = base_channel(base, ch->rec.joint);
		int16_t n[4], prev[4], bn[4];
		uint32_t from = 0;
		for (uint32_t k = 0; k < ch->rec.key_count; k++) {
			const uint8_t *e = (const uint8_t *)(ch->values + 4 * (size_t)k);
			int16_t el[4];
			for (int c = 0; c < 4; c++)
				el[c] = rdi16(e + 2 * c);
			int64_t at = base_key(bc, ch->times[k], &from);
			if (at >= 0)
				for (int c = 0; c < 4; c++)
					bn[c] = (int16_t)lrint((double)bc->values[4 * at + c] * 32767.0);
			else if (el[3] < 0 || el[3] > (p->major >= 4 ? 4 * MLOD_PACK_ROTQ_SHIFT_MAX + 3 : 3))
				FAIL("%s: channel %u: rotation key %u: component index and shift %d out of range", x.label, i,
				     k, el[3]);
			else
				for (int c = 0; c < 3; c++)
					if (el[c] > (32767 >> (el[3] >> 2)) || el[c] < -(32767 >> (el[3] >> 2)))
						FAIL("%s: channel %u: rotation key %u: component %d past the lattice", x.label, i,
						     k, el[c]);
			mlod_pack_rotq_key(el, at >= 0 ? bn : NULL, k > 0 ? prev : NULL, n);
			for (int c = 0; c < 4; c++)
				ch->values[4 * (size_t)k + c] = (float)(n[c] / 32767.0);
			memcpy(prev, n, sizeof prev);
		}
	}
	TRY(cx_expect(&x, &s, MLOD_STREAM_ROTF, 16, nf, "", "3 values per key of the cubic rotations", err));
	TRY(cx_load(&x, &s, &src, err));
	for (uint32_t i = 0; i < C; i++) {
		mlod_pack_channel *ch = &chans[i];
		if (ch->rec.path != 1 || ch->rec.interp != 2)
			continue;
		uint64_t values = 3 * (uint64_t)ch->rec.key_count;
		TAKE(ch->values, values * 16);
		memcpy(ch->values, src, values * 16);
		src += values * 16;
		if (!all_finite(ch->values, values * 4))
			FAIL("%s: channel %u: a rotation value is not finite", x.label, i);
	}
	/* 'VEC3' holds the translation and scale keys without a base key,
	 * 'VECD' those with one (non-cubic, the base's channel of the joint
	 * and path keying the same time) as the differences of their f32 bit
	 * patterns, each wrapped to 32 bits. */
	uint64_t nvd = 0;
	for (uint32_t i = 0; i < C; i++) {
		mlod_pack_channel *ch = &chans[i];
		if (ch->rec.path == 1)
			continue;
		const mlod_pack_channel *bc = base_vec_channel(base, &ch->rec);
		uint32_t from = 0;
		for (uint32_t k = 0; bc && k < ch->rec.key_count; k++)
			nvd += base_key(bc, ch->times[k], &from) >= 0;
	}
	TRY(cx_expect(&x, &s, MLOD_STREAM_VEC3, 12, nv - nvd, "", "translation and scale keys without a base key", err));
	TRY(cx_load(&x, &s, &src, err));
	for (uint32_t i = 0; i < C; i++) {
		mlod_pack_channel *ch = &chans[i];
		if (ch->rec.path == 1)
			continue;
		const mlod_pack_channel *bc = base_vec_channel(base, &ch->rec);
		uint32_t per = ch->rec.interp == 2 ? 3 : 1;
		TAKE(ch->values, (uint64_t)per * ch->rec.key_count * 12);
		uint32_t from = 0;
		for (uint32_t k = 0; k < ch->rec.key_count; k++)
			if (base_key(bc, ch->times[k], &from) < 0) {
				memcpy(ch->values + 3 * (size_t)per * k, src, 12 * (size_t)per);
				src += 12 * (size_t)per;
			}
	}
	TRY(cx_expect(&x, &s, MLOD_STREAM_VECD, 12, nvd, "", "translation and scale keys on a base key", err));
	TRY(cx_load(&x, &s, &src, err));
	for (uint32_t i = 0; i < C; i++) {
		mlod_pack_channel *ch = &chans[i];
		if (ch->rec.path == 1)
			continue;
		const mlod_pack_channel *bc = base_vec_channel(base, &ch->rec);
		uint32_t from = 0;
		for (uint32_t k = 0; bc && k < ch->rec.key_count; k++) {
			int64_t at = base_key(bc, ch->times[k], &from);
			if (at < 0)
				continue;
			for (int c = 0; c < 3; c++) {
				uint32_t bb, v;
				memcpy(&bb, bc->values + 3 * at + c, 4);
				v = bb + rd32(src + 4 * c);
				memcpy(ch->values + 3 * (size_t)k + c, &v, 4);
			}
			src += 12;
		}
		uint64_t values = (ch->rec.interp == 2 ? 3 : 1) * (uint64_t)ch->rec.key_count;
		if (!all_finite(ch->values, values * 3))
			FAIL("%s: channel %u: a %s value is not finite", x.label, i, path_names[ch->rec.path]);
	}
	TRY(cx_end(&x, err));
	cx_done(&x);
	/* The block was sized by an upper bound ('TBIT': 32 keys a word): when
	 * more than an eighth of it is unused, the level moves to a block of
	 * its size (tubeman's motion level 1: 109,736 bytes before), its
	 * pointers moved with it; without memory for that it stays. */
	if (b.cap - b.used > b.cap / 8) {
		uint8_t *nb = pk_malloc(&x.alloc, 1, (size_t)b.used);
		if (nb) {
			memcpy(nb, b.base, (size_t)b.used);
			memcpy(nb + BLOCK_SIZE_AT, &b.used, sizeof b.used);
			chans = moved(&b, nb, chans);
			for (uint64_t i = 0; i < C; i++) {
				chans[i].times = moved(&b, nb, chans[i].times);
				chans[i].values = moved(&b, nb, chans[i].values);
			}
			pk_free(&x.alloc, b.base);
			b.base = nb;
		}
	}
	out->channel_count = (uint32_t)C;
	out->channels = chans;
	out->duration = duration;
	out->block = b.base;
	return MLOD_OK;
fail:
	cx_done(&x);
	pk_free(&x.alloc, b.base);
	return r;
}

void mlod_pack_motion_free(mlod_pack_motion *x)
{
	if (!x)
		return;
	block_free(x->block);
	memset(x, 0, sizeof *x);
}

/* ------------------------------------------------------------------ */
/* DOC                                                                 */
/* ------------------------------------------------------------------ */

/* The DOC chunk's 'GLB ' stream, checked; x is left open (cx_done). */
static mlod_result doc_begin(const mlod_pack *p, const void *data, size_t size, cx *x, stream *s, mlod_error *err)
{
	if (!p)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_pack_doc: the pack is NULL");
	int ci = mlod_pack_find(p, MLOD_CHUNK_DOC, 0, 0);
	if (ci < 0)
		return mlod_fail(err, MLOD_ERR_PARSE, "the pack has no DOC chunk");
	mlod_result r = cx_begin(p, (uint32_t)ci, MLOD_CHUNK_DOC, data, size, x, err);
	if (r != MLOD_OK)
		return r;
	r = cx_expect(x, s, MLOD_STREAM_GLB, 1, UINT64_MAX, "", "", err);
	if (r == MLOD_OK)
		r = cx_end(x, err);
	if (r == MLOD_OK && s->codec != MLOD_SCODEC_RAW)
		r = mlod_fail(err, MLOD_ERR_PARSE, "DOC: the 'GLB ' stream must be stored raw");
	if (r != MLOD_OK)
		cx_done(x);
	return r;
}

mlod_result mlod_pack_doc(const mlod_pack *p, const void *data, size_t size, const void **glb, size_t *glb_size,
                          mlod_error *err)
{
	if (!glb || !glb_size)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_pack_doc: glb or glb_size is NULL");
	*glb = NULL;
	*glb_size = 0;
	int ci = p ? mlod_pack_find(p, MLOD_CHUNK_DOC, 0, 0) : -1;
	if (ci >= 0 && p->chunks[ci].entropy != MLOD_ENTROPY_NONE)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG,
		                 "DOC: stored with the %s entropy stage, so its bytes are not in the file: use "
		                 "mlod_pack_decode_doc",
		                 mlod_pack_entropy_name(p->chunks[ci].entropy));
	cx x;
	stream s;
	mlod_result r = doc_begin(p, data, size, &x, &s, err);
	if (r != MLOD_OK)
		return r;
	*glb = s.src;
	*glb_size = s.count;
	cx_done(&x);
	return MLOD_OK;
}

mlod_result mlod_pack_decode_doc(const mlod_pack *p, const void *data, size_t size, mlod_pack_doc_bytes *out,
                                 mlod_error *err)
{
	if (!out)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_pack_decode_doc: out is NULL");
	memset(out, 0, sizeof *out);
	cx x;
	stream s;
	mlod_result r = doc_begin(p, data, size, &x, &s, err);
	if (r != MLOD_OK)
		return r;
	bump b = {0};
	r = bump_alloc(&b, &x, round8((uint64_t)s.count), err);
	if (r == MLOD_OK) {
		uint8_t *g = bump_take(&b, s.count);
		if (s.count)
			memcpy(g, s.src, s.count);
		out->glb = g;
		out->size = s.count;
		out->block = b.base;
	}
	cx_done(&x);
	return r;
}

void mlod_pack_doc_free(mlod_pack_doc_bytes *x)
{
	if (!x)
		return;
	block_free(x->block);
	memset(x, 0, sizeof *x);
}

/* Every chunk decoded in TOC order and released, stopping at the first
 * failure (whose message names the chunk); unknown types are skipped. */
mlod_result mlod_pack_check_padding(const mlod_pack *p, const void *data, size_t size, mlod_error *err)
{
	if (!p || (!data && size))
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_pack_check_padding: NULL argument");
	/* no CRC covers it: a whole file has no other bytes than the header,
	 * the TOC, the chunks and the zero padding before each chunk */
	const uint8_t *d = data;
	uint64_t at = MLOD_PACK_HEADER_SIZE + (uint64_t)p->chunk_count * MLOD_PACK_TOC_ENTRY_SIZE;
	for (uint32_t i = 0; i < p->chunk_count; i++) {
		const mlod_pack_chunk *c = &p->chunks[i];
		for (uint64_t b = at; b < c->offset && b < size; b++)
			if (d[b]) {
				char label[48];
				chunk_label(c->type, c->level, c->item, label, sizeof label);
				return mlod_fail(err, MLOD_ERR_PARSE, "%s: padding byte %llu before the chunk is not zero", label,
				                 (unsigned long long)b);
			}
		at = c->offset + c->stored_size;
	}
	if (size > p->file_size)
		return mlod_fail(err, MLOD_ERR_PARSE, "%llu bytes after the pack's end (byte %llu), which no CRC covers",
		                 (unsigned long long)(size - p->file_size), (unsigned long long)p->file_size);
	return MLOD_OK;
}

mlod_result mlod_pack_info_check_skeleton(const mlod_pack_info *info, const mlod_pack_skeleton *skel,
                                          mlod_error *err)
{
	if (info->rec.joint_count != skel->joint_count || info->rec.skin_count != skel->skin_count)
		return mlod_fail(err, MLOD_ERR_PARSE, "INFO: %u joints and %u skins, but SKELETON has %u and %u",
		                 info->rec.joint_count, info->rec.skin_count, skel->joint_count, skel->skin_count);
	return MLOD_OK;
}

mlod_result mlod_pack_info_check_mesh(const mlod_pack_info *info, const mlod_pack_mesh *mesh, unsigned level,
                                      mlod_error *err)
{
	if (info->rec.instance_count != mesh->part_count)
		return mlod_fail(err, MLOD_ERR_PARSE, "INFO: %u instances, but MESH level %u has %u parts",
		                 info->rec.instance_count, level, mesh->part_count);
	return MLOD_OK;
}

mlod_result mlod_pack_check(const mlod_pack *p, const void *data, size_t size, mlod_error *err)
{
	if (!p || (!data && size))
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_pack_check: NULL argument");
	mlod_pack_skeleton skel;
	memset(&skel, 0, sizeof skel);
	mlod_pack_info info; /* INFO stands first (mlod_pack_open checks the order) */
	memset(&info, 0, sizeof info);
	int have_skel = 0, have_info = 0;
	mlod_result r = MLOD_OK;
	if ((r = mlod_pack_check_padding(p, data, size, err)) != MLOD_OK)
		return r;
	for (uint32_t i = 0; r == MLOD_OK && i < p->chunk_count; i++) {
		const mlod_pack_chunk *c = &p->chunks[i];
		const mlod_pack_skeleton *s = have_skel ? &skel : NULL;
		if (c->type == MLOD_CHUNK_INFO) {
			r = mlod_pack_decode_info(p, data, size, &info, err);
			have_info = r == MLOD_OK;
		} else if (c->type == MLOD_CHUNK_SKELETON && c->level == 0) {
			r = mlod_pack_decode_skeleton(p, data, size, &skel, err);
			have_skel = r == MLOD_OK;
			/* INFO's counts against what the chunks hold */
			if (have_skel && have_info)
				r = mlod_pack_info_check_skeleton(&info, &skel, err);
		} else if (c->type == MLOD_CHUNK_SKELETON) {
			mlod_pack_skel_level x;
			memset(&x, 0, sizeof x);
			r = mlod_pack_decode_skel_level(p, i, data, size, s, &x, err);
			mlod_pack_skel_level_free(&x);
		} else if (c->type == MLOD_CHUNK_MESH) {
			mlod_pack_mesh x;
			memset(&x, 0, sizeof x);
			r = mlod_pack_decode_mesh(p, i, data, size, s, &x, err);
			if (r == MLOD_OK && have_info)
				r = mlod_pack_info_check_mesh(&info, &x, c->level, err);
			mlod_pack_mesh_free(&x);
		} else if (c->type == MLOD_CHUNK_MOTION) {
			mlod_pack_motion x;
			memset(&x, 0, sizeof x);
			r = mlod_pack_decode_motion(p, i, data, size, s, &x, err);
			mlod_pack_motion_free(&x);
		} else if (c->type == MLOD_CHUNK_DOC) {
			mlod_pack_doc_bytes x;
			memset(&x, 0, sizeof x);
			r = mlod_pack_decode_doc(p, data, size, &x, err);
			mlod_pack_doc_free(&x);
		}
	}
	mlod_pack_skeleton_free(&skel);
	mlod_pack_info_free(&info);
	return r;
}
