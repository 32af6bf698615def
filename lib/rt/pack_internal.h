/*
 * pack_internal.h: what the runtime (lib/rt) uses of the pack reader
 * beyond mlod_pack.h.
 */
#ifndef MLOD_PACK_INTERNAL_H
#define MLOD_PACK_INTERNAL_H

#include "mlod_pack.h"

/* Called by mlod_pack_decode_mesh_reserve once the level's part records
 * are read and checked (after the coarser levels' blocks are decoded into
 * the reader's scratch), before the decoded level's one block is
 * allocated: the records (vertex and index counts, flags, UV sets, target
 * counts) give the decoded level's arrays exactly. A result other than
 * MLOD_OK stops the decode with that result, before that allocation. */
typedef mlod_result (*mlod_pack_reserve_fn)(void *user, const mlod_pack_part_rec *parts, uint32_t part_count,
                                            mlod_error *err);

/* mlod_pack_decode_mesh (fetch NULL: the chunks from data, size) or
 * mlod_pack_decode_mesh_fetch (fetch not NULL), calling reserve (may be
 * NULL) as above; Draco-coded levels too. */
mlod_result mlod_pack_decode_mesh_reserve(const mlod_pack *p, uint32_t chunk, const void *data, size_t size,
                                          mlod_pack_fetch_fn fetch, void *fetch_user, mlod_pack_reserve_fn reserve,
                                          void *reserve_user, const mlod_pack_skeleton *skel, mlod_pack_mesh *out,
                                          mlod_error *err);

/* Called by mlod_pack_decode_motion_reserve once the level's channel
 * records are read and checked (a nested level's base already decoded:
 * the caller's), before the decoded level's one block is allocated: the
 * records (key counts, paths, interpolations, time arrays) give its
 * arrays exactly, and block_bytes is that block's size, its head included
 * (mlod_pack_block_size of the level once decoded). A result other than
 * MLOD_OK stops the decode with that result, before that allocation. */
typedef mlod_result (*mlod_pack_motion_reserve_fn)(void *user, const mlod_pack_channel_rec *channels,
                                                   uint32_t channel_count, uint64_t block_bytes, mlod_error *err);

/* mlod_pack_decode_motion_on, calling reserve (may be NULL) as above. */
mlod_result mlod_pack_decode_motion_reserve(const mlod_pack *p, uint32_t chunk, const void *data, size_t size,
                                            const mlod_pack_skeleton *skel, const mlod_pack_motion *base,
                                            mlod_pack_motion_reserve_fn reserve, void *reserve_user,
                                            mlod_pack_motion *out, mlod_error *err);

/* Called by mlod_pack_decode_skel_level_reserve once the level's records
 * are read and checked (its kept joints; its palette's joints, or from
 * format 7.0 its bind matrix references), before the decoded level's one
 * block is allocated: kept_count and palette_size give its arrays exactly
 * (mlod_pack_skel_level), and block_bytes is that block's size, its head
 * included (mlod_pack_block_size of the level once decoded). A result
 * other than MLOD_OK stops the decode with that result, before that
 * allocation. */
typedef mlod_result (*mlod_pack_skel_reserve_fn)(void *user, uint32_t kept_count, uint32_t palette_size,
                                                 uint64_t block_bytes, mlod_error *err);

/* mlod_pack_decode_skel_level, calling reserve (may be NULL) as above. */
mlod_result mlod_pack_decode_skel_level_reserve(const mlod_pack *p, uint32_t chunk, const void *data, size_t size,
                                                const mlod_pack_skeleton *skel, mlod_pack_skel_reserve_fn reserve,
                                                void *reserve_user, mlod_pack_skel_level *out, mlod_error *err);

/* INFO's counts against what the chunks hold (MLOD_ERR_PARSE naming
 * INFO): its joint and skin counts against SKELETON's, its instance count
 * against a decoded MESH level's parts (every level has the same parts)
 * and its max_vertex_count against the level's vertices.
 * mlod_pack_check runs them; the runtime's open too. */
mlod_result mlod_pack_info_check_skeleton(const mlod_pack_info *info, const mlod_pack_skeleton *skel,
                                          mlod_error *err);
mlod_result mlod_pack_info_check_mesh(const mlod_pack_info *info, const mlod_pack_mesh *mesh, unsigned level,
                                      mlod_error *err);
/* A MESH level's vertices (the sum of its part records' vertex counts)
 * against INFO's max_vertex_count (format 8.1; nothing to check before):
 * MLOD_ERR_PARSE naming the level when they are more. The runtime runs it
 * with the part records before it allocates the level;
 * mlod_pack_info_check_mesh with the decoded level. */
mlod_result mlod_pack_info_check_vertices(const mlod_pack_info *info, uint64_t vertices, unsigned level,
                                          mlod_error *err);

/* The bytes allocated for a decoded level's block (mlod_pack_motion.block
 * and the others: one allocation each), 0 for NULL. */
size_t mlod_pack_block_size(const void *block);

/* ------------------------------------------------------------------ */
/* Between the reader's own files                                      */
/* ------------------------------------------------------------------ */

/*
 * The reader of the .mlod pack format (mlod_pack.h, mlod(5)) is the rd_*.c
 * files: rd_open.c (header and TOC), rd_stream.c (a chunk's CRC, entropy
 * stage, stream container and block), rd_info.c (INFO, DOC, the whole
 * pack's checks), rd_skel.c, rd_mesh.c and rd_motion.c (their chunks).
 * What follows is what they share, seen only by them (they define
 * MLOD_PACK_READER before including this header): the rest of the runtime
 * uses the reader through mlod_pack.h and the declarations above.
 *
 * Everything read from the file is checked before it is used: the header
 * and TOC by mlod_pack_open, each chunk's CRC, stream container, stream
 * sizes, record counts and indices by its decode. Sizes are computed in
 * uint64_t, so no product or sum can wrap. A decode sizes its one
 * allocation (the block) from the stream headers, whose decoded sizes add
 * up to the TOC's raw size, and refuses one above PACK_MAX_BLOCK before
 * allocating (a MOTION level sizes it exactly from its channel records,
 * once they are checked, when they are within that bound, and calls
 * mlod_pack_decode_motion_reserve's reserve with that size first; a
 * skeleton level from its kept count and the skeleton's palette, once its
 * records are checked, calling mlod_pack_decode_skel_level_reserve's
 * reserve first). Meshopt-coded streams are decoded into a temporary buffer
 * (freed before the decode returns); raw streams are read in place.
 * Every allocation is the pack's allocator's (mlod_pack_open_alloc; malloc
 * by default), and a block starts with that allocator, for *_free.
 * A MESH level (layout b2, mlod(5)) also decodes the vertex blocks of every
 * coarser MESH chunk, each checked like any chunk, into scratch sized from
 * their TOC raw sizes (freed before the decode returns), then gathers the
 * vertices its indices use; its block is sized from its part records,
 * whose vertex counts the gathering must meet exactly (the runtime's
 * mlod_pack_decode_mesh_reserve, above, is called with those records
 * before the block is allocated).
 *
 * Byte order: the format is little-endian, and so must the host be (the
 * index codec's output and the records are read with memcpy); the
 * preprocessor check below refuses a big-endian target where the compiler
 * tells. Fields are read with memcpy, so the data needs no alignment.
 * The small helpers are static inline here, as they were static in the
 * one file the reader was: the hot ones (rd32, cx_next, index_at,
 * bump_take) stay inlined in every file.
 */
#ifdef MLOD_PACK_READER

#include <math.h>
#include <stdint.h>
#include <string.h>

#if defined(__BYTE_ORDER__) && defined(__ORDER_LITTLE_ENDIAN__) && __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "mlod's pack reader assumes a little-endian host"
#endif

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

/* The reader's allocations, all through the pack's allocator (malloc by
 * default): zeroed (pk_calloc) or not (pk_malloc, for scratch written
 * before it is read). */
void *pk_calloc(const mlod_pack_alloc *a, size_t n, size_t size);
void *pk_malloc(const mlod_pack_alloc *a, size_t n, size_t size);
void pk_free(const mlod_pack_alloc *a, void *p);

static inline uint16_t rd16(const uint8_t *p)
{
	return (uint16_t)(p[0] | p[1] << 8);
}

static inline uint32_t rd32(const uint8_t *p)
{
	return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static inline uint64_t rd64(const uint8_t *p)
{
	return (uint64_t)rd32(p) | (uint64_t)rd32(p + 4) << 32;
}

static inline float rdf(const uint8_t *p)
{
	uint32_t u = rd32(p);
	float f;
	memcpy(&f, &u, 4);
	return f;
}

static inline int16_t rdi16(const uint8_t *p)
{
	uint16_t u = rd16(p);
	return u < 0x8000u ? (int16_t)u : (int16_t)((int32_t)u - 65536);
}

static inline uint64_t pad4(uint64_t n)
{
	return (n + 3) & ~(uint64_t)3;
}

static inline uint64_t round8(uint64_t n)
{
	return (n + 7) & ~(uint64_t)7;
}

static inline int all_finite(const float *v, size_t n)
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

static inline tagname tagn(uint32_t tag)
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
void pk_chunk_label(uint32_t type, unsigned level, unsigned item, char *buf, size_t n);

/* The start of a decode of the pack's one chunk of a type (INFO,
 * SKELETON): out (out_size bytes) zeroed, then the pack and the chunk's
 * index (*ci) found; fn names the call in messages (rd_open.c). */
mlod_result pk_find_one(const mlod_pack *p, uint32_t type, void *out, size_t out_size, const char *fn, int *ci,
                        mlod_error *err);

/* zstd's decoder context, one per opened pack (its set-up costs about as
 * much as decoding a small chunk, so the decodes share it), made by open
 * (rd_open.c) with the pack's allocator when a chunk has an entropy stage:
 * a block holding a copy of the allocator (zstd's hooks point to it, so
 * the pack struct may be copied) and the context, which rd_stream.c
 * decodes with (struct ZSTD_DCtx_s: zstd.h's ZSTD_DCtx, not included
 * here). */
typedef struct zdec {
	mlod_pack_alloc a;
	struct ZSTD_DCtx_s *z;
} zdec;

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

/* A chunk's container (rd_stream.c). pk_cx_head checks the chunk's TOC entry
 * (index, type, codec); pk_cx_parse the bytes at x->base (CRC, entropy stage,
 * container); pk_cx_begin both on the chunk's bytes in data (a file or a
 * prefix), pk_cx_begin_prefix with prefix (MLOD_ENTROPY_ZSTD_PREFIX, or NULL),
 * pk_cx_begin_skel_level on a skeleton level (the SKELETON chunk its prefix).
 * pk_cx_expect: the next stream, which must have this tag, element size and
 * count (UINT64_MAX: any); pk_cx_end: no stream left; pk_cx_temp: the temporary
 * buffer (aux bytes, then the largest meshopt-coded stream); pk_cx_done frees
 * what x owns. pk_cx_load: a stream's decoded bytes (in place when raw, else in
 * the temporary buffer); pk_cx_load_into: written to dst. */
mlod_result pk_cx_head(const mlod_pack *p, uint32_t index, uint32_t type, cx *x, mlod_error *err);
mlod_result pk_cx_parse(cx *x, mlod_error *err);
mlod_result pk_cx_begin(const mlod_pack *p, uint32_t index, uint32_t type, const void *data, size_t size, cx *x,
                        mlod_error *err);
mlod_result pk_cx_begin_prefix(const mlod_pack *p, uint32_t index, uint32_t type, const void *data, size_t size,
                               const uint8_t *prefix, uint64_t prefix_size, cx *x, mlod_error *err);
mlod_result pk_cx_begin_skel_level(const mlod_pack *p, uint32_t index, const void *data, size_t size, cx *x,
                                   mlod_error *err);
mlod_result pk_cx_expect(cx *x, stream *s, uint32_t tag, uint32_t elsize, uint64_t count, const char *what,
                         const char *count_what, mlod_error *err);
mlod_result pk_cx_end(cx *x, mlod_error *err);
mlod_result pk_cx_temp(cx *x, uint64_t aux, mlod_error *err);
void pk_cx_done(cx *x);
mlod_result pk_cx_load(cx *x, const stream *s, const uint8_t **out, mlod_error *err);
mlod_result pk_cx_load_into(cx *x, const stream *s, uint8_t *dst, mlod_error *err);

static inline void cx_rewind(cx *x)
{
	x->next = 0;
	x->cursor = 4 + 16 * (uint64_t)x->nstreams;
}

/* The next stream's header; 0 when there is none. */
static inline int cx_next(cx *x, stream *s)
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

/* Index k of a decoded index stream of 16-bit (i16) or 32-bit entries, in
 * the machine's byte order (as the index decoders write them). */
static inline uint32_t index_at(const uint8_t *src, int i16, uint32_t k)
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

/* The block: one allocation carved into 8-aligned arrays, after a head
 * that records the allocator that made it (for the *_free calls). */
enum { BLOCK_HEAD = 32, BLOCK_SIZE_AT = 24 };
_Static_assert(sizeof(mlod_pack_alloc) <= BLOCK_SIZE_AT && BLOCK_SIZE_AT + sizeof(uint64_t) <= BLOCK_HEAD,
               "the block's head holds its allocator and its size");

/* pk_bump_alloc makes a block (total bytes after its head), bump_take
 * carves it; pk_block_release frees it by the allocator its head records
 * and zeroes the struct that held it (the *_free calls); pk_undo is a
 * decode's failure: x done, b's block freed, r returned (rd_stream.c). */
typedef struct bump {
	uint8_t *base;
	uint64_t used, cap;
} bump;

mlod_result pk_bump_alloc(bump *b, cx *x, uint64_t total, mlod_error *err);
void pk_block_release(void *block, void *owner, size_t owner_size);
mlod_result pk_undo(cx *x, bump *b, mlod_result r);

/* p, a pointer into b's block (else returned as it is), at the same
 * offset of nb, a copy of its used bytes. */
static inline void *moved(const bump *b, uint8_t *nb, const void *p)
{
	/* compared as integers: the relational operators are only defined
	 * within one object, and p may point elsewhere */
	const uintptr_t at = (uintptr_t)p, base = (uintptr_t)b->base;
	return p && at >= base && at - base < b->used ? nb + (at - base) : (void *)at;
}

static inline void *bump_take(bump *b, uint64_t bytes)
{
	if (round8(bytes) > b->cap - b->used)
		return NULL;
	void *p = b->base + b->used;
	b->used += round8(bytes);
	return p;
}

/* A string table (pk_load_names): the stream's bytes with a NUL after them,
 * ending with a NUL; pk_name_at: a name in it, its offset checked. */
mlod_result pk_load_names(cx *x, bump *b, const stream *s, char **out, mlod_error *err);
mlod_result pk_name_at(cx *x, const char *table, uint32_t table_size, uint32_t off, const char **out,
                       const char *what, mlod_error *err);

/* The decodes' error paths: each has a bump b, a cx x, a result r and a
 * fail: label that frees what it holds. */
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

#endif /* MLOD_PACK_READER */

#endif
