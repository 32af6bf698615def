/*
 * packwrite.c: gathers the levels of every layer and writes the .mlod
 * pack (mlod_pack_write.h; the layout is rt/mlod_pack.h's).
 */
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <meshoptimizer.h>
#include <zstd.h>

#include "pack/draco.h"
#include "pack/mlod_pack_write.h"
#include "record/mlod_record.h"

/* ------------------------------------------------------------------ */
/* Bytes                                                               */
/* ------------------------------------------------------------------ */

typedef struct buf {
	uint8_t *p;
	size_t n, cap;
	int fail;
} buf;

static void buf_reserve(buf *b, size_t extra)
{
	if (b->fail || b->n + extra <= b->cap)
		return;
	size_t cap = b->cap ? b->cap : 256;
	while (cap < b->n + extra)
		cap *= 2;
	uint8_t *p = realloc(b->p, cap);
	if (!p) {
		b->fail = 1;
		return;
	}
	b->p = p;
	b->cap = cap;
}

static void buf_put(buf *b, const void *d, size_t n)
{
	buf_reserve(b, n);
	if (b->fail || n == 0)
		return;
	memcpy(b->p + b->n, d, n);
	b->n += n;
}

static void buf_zeros(buf *b, size_t n)
{
	buf_reserve(b, n);
	if (b->fail)
		return;
	memset(b->p + b->n, 0, n);
	b->n += n;
}

static void buf_pad(buf *b, size_t align)
{
	if (b->n % align)
		buf_zeros(b, align - b->n % align);
}

static void put_u16(uint8_t *p, uint16_t v)
{
	p[0] = (uint8_t)v;
	p[1] = (uint8_t)(v >> 8);
}

static void put_u32(uint8_t *p, uint32_t v)
{
	for (int i = 0; i < 4; i++)
		p[i] = (uint8_t)(v >> (8 * i));
}

static void put_u64(uint8_t *p, uint64_t v)
{
	for (int i = 0; i < 8; i++)
		p[i] = (uint8_t)(v >> (8 * i));
}

static void put_f32(uint8_t *p, float f)
{
	uint32_t u;
	memcpy(&u, &f, 4);
	put_u32(p, u);
}

static double now_seconds(void)
{
	struct timespec ts;
	timespec_get(&ts, TIME_UTC);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ------------------------------------------------------------------ */
/* Chunks and their streams                                            */
/* ------------------------------------------------------------------ */

typedef struct stream {
	uint32_t tag, count;
	uint16_t size;
	int index;       /* an index stream (the index codec may apply) */
	uint8_t *data;   /* count * size bytes, owned */
} stream;

typedef struct chunkb {
	stream *s;
	int n, cap;
	int fail;
} chunkb;

static void cb_add(chunkb *cb, uint32_t tag, uint32_t count, uint16_t size, const void *data, int index)
{
	if (cb->fail)
		return;
	if (cb->n == cb->cap) {
		int cap = cb->cap ? 2 * cb->cap : 16;
		stream *s = realloc(cb->s, sizeof *s * (size_t)cap);
		if (!s) {
			cb->fail = 1;
			return;
		}
		cb->s = s;
		cb->cap = cap;
	}
	size_t bytes = (size_t)count * size;
	uint8_t *copy = malloc(bytes ? bytes : 1);
	if (!copy) {
		cb->fail = 1;
		return;
	}
	if (bytes)
		memcpy(copy, data, bytes);
	cb->s[cb->n++] = (stream){tag, count, size, index, copy};
}

static void cb_free(chunkb *cb)
{
	for (int i = 0; i < cb->n; i++)
		free(cb->s[i].data);
	free(cb->s);
	memset(cb, 0, sizeof *cb);
}

typedef struct chunk {
	uint32_t type;
	uint8_t layer, codec, entropy;
	uint16_t level, item, flags;
	float error, distance;
	uint8_t *data;
	size_t size;
	uint32_t raw, coded; /* coded: with an entropy stage, the container's size */
	uint64_t offset;
} chunk;

typedef struct chunks {
	chunk *c;
	int n, cap;
} chunks;

/* The u32 copy of an index stream's elements (2 or 4 bytes each), and
 * their largest; NULL when out of memory. */
static unsigned int *stream_u32(const stream *s, unsigned int *maxv)
{
	unsigned int *idx = malloc(sizeof *idx * ((size_t)s->count + 1));
	*maxv = 0;
	if (!idx)
		return NULL;
	for (uint32_t k = 0; k < s->count; k++) {
		if (s->size == 2) {
			uint16_t v;
			memcpy(&v, s->data + 2 * k, 2);
			idx[k] = v;
		} else {
			memcpy(&idx[k], s->data + 4 * k, 4);
		}
		*maxv = idx[k] > *maxv ? idx[k] : *maxv;
	}
	return idx;
}

/* A stream's meshopt coding as cb_finish makes it: the stream codec and
 * the coded bytes in *enc (malloc'd; NULL and MLOD_SCODEC_RAW when it
 * stays raw). Returns 0 when out of memory. */
static int stream_encode(const stream *s, uint8_t *scodec, unsigned char **enc, size_t *enc_size)
{
	size_t bytes = (size_t)s->count * s->size;
	*scodec = MLOD_SCODEC_RAW, *enc = NULL, *enc_size = 0;
	if (s->count == 0)
		return 1;
	if (s->index && (s->size == 2 || s->size == 4) && (s->index == 2 || s->count % 3 == 0)) {
		unsigned int maxv, *idx = stream_u32(s, &maxv);
		if (!idx)
			return 0;
		size_t bound = s->index == 2 ? meshopt_encodeIndexSequenceBound(s->count, (size_t)maxv + 1)
		                             : meshopt_encodeIndexBufferBound(s->count, (size_t)maxv + 1);
		if (!(*enc = malloc(bound))) {
			free(idx);
			return 0;
		}
		*enc_size = s->index == 2 ? meshopt_encodeIndexSequence(*enc, bound, idx, s->count)
		                          : meshopt_encodeIndexBuffer(*enc, bound, idx, s->count);
		free(idx);
		if (*enc_size > 0)
			*scodec = s->index == 2 ? MLOD_SCODEC_MESHOPT_SEQUENCE : MLOD_SCODEC_MESHOPT_INDEX;
	} else if (!s->index && s->size % 4 == 0 && s->size <= 256) {
		size_t bound = meshopt_encodeVertexBufferBound(s->count, s->size);
		if (!(*enc = malloc(bound)))
			return 0;
		*enc_size = meshopt_encodeVertexBuffer(*enc, bound, s->data, s->count, s->size);
		if (*enc_size > 0 && *enc_size < bytes)
			*scodec = MLOD_SCODEC_MESHOPT_VERTEX;
	}
	if (*scodec == MLOD_SCODEC_RAW) {
		free(*enc);
		*enc = NULL, *enc_size = 0;
	}
	return 1;
}

/* The stored bytes of one stream with the meshopt codecs (padded to 4). */
static size_t stream_coded_bytes(const stream *s)
{
	uint8_t scodec;
	unsigned char *enc;
	size_t enc_size;
	size_t got = (size_t)s->count * s->size;
	if (stream_encode(s, &scodec, &enc, &enc_size) && scodec != MLOD_SCODEC_RAW)
		got = enc_size;
	free(enc);
	return (got + 3) & ~(size_t)3;
}

/* The meshopt-coded bytes of the streams from `from` on. */
static size_t cb_coded_bytes(const chunkb *cb, int from)
{
	size_t total = 0;
	for (int i = from; i < cb->n; i++)
		total += stream_coded_bytes(&cb->s[i]);
	return total;
}

/* Encodes the streams of cb into a chunk (the stream container). */
static mlod_result cb_finish(chunkb *cb, mlod_pack_codec codec, chunks *out, uint32_t type, int layer, int level,
                             int item, float error, mlod_error *err)
{
	buf b = {0};
	uint8_t word[4];
	uint32_t raw = 4 + 16 * (uint32_t)cb->n;
	if (cb->fail)
		goto nomem;
	/* The reader refuses a TOC error or switch distance that is not finite
	 * and >= 0 (mlod_pack_open): coordinates near FLT_MAX (a BVH offset of
	 * 1e25) give a motion level's error of inf. */
	float stored_error = level > 0 || type == MLOD_CHUNK_MOTION ? error : 0.0f;
	float distance = level > 0 ? mlod_pack_switch_distance(error) : 0.0f;
	if (!isfinite(stored_error) || !(stored_error >= 0.0f) || !isfinite(distance)) {
		char label[64];
		if (type == MLOD_CHUNK_MOTION)
			snprintf(label, sizeof label, "MOTION level %d of clip %d", level, item);
		else
			snprintf(label, sizeof label, "%s level %d", type == MLOD_CHUNK_MESH ? "MESH" : "SKELETON", level);
		cb_free(cb);
		if (!isfinite(stored_error) || !(stored_error >= 0.0f))
			return mlod_fail(err, MLOD_ERR_PARSE, "%s: error %g is not finite and >= 0 (are the input's "
			                 "coordinates too large?)", label, (double)stored_error);
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: error %g gives a switch distance that is not finite (are the "
		                 "input's coordinates too large?)", label, (double)stored_error);
	}
	put_u32(word, (uint32_t)cb->n);
	buf_put(&b, word, 4);
	size_t headers = b.n;
	buf_zeros(&b, 16 * (size_t)cb->n);
	for (int i = 0; i < cb->n; i++) {
		stream *s = &cb->s[i];
		size_t bytes = (size_t)s->count * s->size;
		uint8_t scodec = MLOD_SCODEC_RAW;
		uint8_t *enc = NULL;
		size_t enc_size = 0;
		raw += (uint32_t)((bytes + 3) & ~(size_t)3);
		if (codec == MLOD_CODEC_MESHOPT && !stream_encode(s, &scodec, &enc, &enc_size))
			goto nomem;
		const uint8_t *data = scodec == MLOD_SCODEC_RAW ? s->data : enc;
		size_t stored = scodec == MLOD_SCODEC_RAW ? bytes : enc_size;
		uint8_t h[16] = {0};
		put_u32(h, s->tag);
		put_u32(h + 4, s->count);
		put_u16(h + 8, s->size);
		h[10] = scodec;
		put_u32(h + 12, (uint32_t)stored);
		if (!b.fail)
			memcpy(b.p + headers + 16 * (size_t)i, h, 16);
		buf_put(&b, data, stored);
		buf_pad(&b, 4);
		free(enc);
	}
	if (b.fail)
		goto nomem;
	if (out->n == out->cap) {
		int cap = out->cap ? 2 * out->cap : 32;
		chunk *c = realloc(out->c, sizeof *c * (size_t)cap);
		if (!c)
			goto nomem;
		out->c = c;
		out->cap = cap;
	}
	chunk *c = &out->c[out->n++];
	memset(c, 0, sizeof *c);
	c->type = type;
	c->layer = (uint8_t)layer;
	c->codec = type == MLOD_CHUNK_INFO || type == MLOD_CHUNK_DOC ? MLOD_CODEC_NONE : (uint8_t)codec;
	c->level = (uint16_t)level;
	c->item = (uint16_t)item;
	c->error = stored_error; /* ANIM level 0: against the input clip */
	c->distance = distance;
	c->data = b.p;
	c->size = b.n;
	c->raw = raw;
	cb_free(cb);
	return MLOD_OK;
nomem:
	free(b.p);
	cb_free(cb);
	return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory writing the pack");
}

/* The entropy stage (mlod(5), format 5.0): zstd at this level over the
 * chunk's whole container, kept when it stores fewer bytes and the
 * container is at most the raw size (the reader's bound). Deterministic:
 * one-shot compression, one thread, the frame with its content size. */
#define PACK_ZSTD_LEVEL 19
/* chunk_stream_choice compares a stream's forms by their zstd frames at
 * this level (level 19 there costs 4 times the instructions for 0.1-0.6%
 * of the four inputs' bytes, bench/RESULTS.md), on at most
 * PACK_CHOICE_SAMPLE of its bytes (whole elements from its first). */
#ifndef PACK_CHOICE_LEVEL
#define PACK_CHOICE_LEVEL 12
#endif
#ifndef PACK_CHOICE_SAMPLE
#define PACK_CHOICE_SAMPLE ((size_t)1 << 14)
#endif
/* The block run's threshold (zstd_frame): a zstd block ends at a stream's
 * end once this many container bytes are pending (chunk_entropy compares
 * both runs at PACK_ZSTD_TRIAL_LEVEL). */
#ifndef PACK_ZSTD_FLUSH
#define PACK_ZSTD_FLUSH 512
#endif
#define PACK_ZSTD_TRIAL_LEVEL 3
/* Draco's speed option (0 smallest .. 10 fastest), for encoding and decoding. */
#ifndef MLOD_PACK_DRACO_SPEED
#define MLOD_PACK_DRACO_SPEED 0
#endif

/* prefix (format 6.0): a MESH level's (but the coarsest's), the coarser
 * MESH levels' containers, coarsest first; a skeleton level's, SKELETON's
 * container. Such a chunk is always coded on its prefix
 * (MLOD_ENTROPY_ZSTD_PREFIX, chunk_entropy): no frame coded alone is
 * tried. */
/* One zstd frame of the container d (n bytes) at the pack's level, with
 * its content size, into out (cap bytes): on prefix when prefix_size > 0.
 * With flush > 0, a zstd block ends at the end of each stream that ends
 * at least flush bytes after the last block's end (each block has its
 * own literal and sequence statistics: a stream's own may code it in
 * fewer bytes than those of a block mixing it with others). */
static size_t zstd_frame(ZSTD_CCtx *cc, int level, uint8_t *out, size_t cap, const uint8_t *d, size_t n,
                         const uint8_t *prefix, size_t prefix_size, size_t flush)
{
	ZSTD_CCtx_reset(cc, ZSTD_reset_session_and_parameters);
	size_t z = ZSTD_CCtx_setParameter(cc, ZSTD_c_compressionLevel, level);
	if (!ZSTD_isError(z))
		z = ZSTD_CCtx_setPledgedSrcSize(cc, n);
	if (!ZSTD_isError(z) && prefix_size)
		z = ZSTD_CCtx_refPrefix(cc, prefix, prefix_size);
	if (ZSTD_isError(z))
		return z;
	if (!flush || n < 4)
		return ZSTD_compress2(cc, out, cap, d, n);
	uint32_t ns = (uint32_t)d[0] | (uint32_t)d[1] << 8 | (uint32_t)d[2] << 16 | (uint32_t)d[3] << 24;
	ZSTD_outBuffer o = {out, cap, 0};
	size_t from = 0, to = 4 + 16 * (size_t)ns;
	for (uint32_t i = 0; i <= ns; i++) {
		if (i < ns) {
			const uint8_t *h = d + 4 + 16 * (size_t)i;
			to += (((size_t)h[12] | (size_t)h[13] << 8 | (size_t)h[14] << 16 | (size_t)h[15] << 24) + 3) & ~(size_t)3;
		}
		if (to > n)
			to = n;
		if (i < ns && to - from < flush)
			continue;
		ZSTD_inBuffer in = {d + from, to - from, 0};
		ZSTD_EndDirective how = i == ns ? ZSTD_e_end : ZSTD_e_flush;
		do {
			z = ZSTD_compressStream2(cc, &o, &in, how);
			if (ZSTD_isError(z))
				return z;
		} while (z != 0 || in.pos < in.size);
		from = to;
	}
	return o.pos;
}

static mlod_result chunk_entropy(chunk *c, const uint8_t *prefix, size_t prefix_size, mlod_error *err)
{
	if (c->type == MLOD_CHUNK_INFO || c->size < 4 || c->size > c->raw)
		return MLOD_OK;
	size_t cap = ZSTD_compressBound(c->size);
	uint8_t *z = malloc(cap), *zt = malloc(cap);
	ZSTD_CCtx *cc = ZSTD_createCCtx();
	mlod_result r = MLOD_OK;
	if (!z || !zt || !cc) {
		r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory writing the pack");
		goto done;
	}
	/* The block run (one as zstd splits them, or a block per stream run of
	 * PACK_ZSTD_FLUSH bytes) that codes the container alone smaller at
	 * PACK_ZSTD_TRIAL_LEVEL; then one frame at the pack's level with it:
	 * on the prefix where there is one, else alone. */
	int has_prefix = prefix_size && prefix_size <= MLOD_PACK_MAX_PREFIX;
	size_t t0 = zstd_frame(cc, PACK_ZSTD_TRIAL_LEVEL, zt, cap, c->data, c->size, NULL, 0, 0);
	size_t t1 = ZSTD_isError(t0) ? t0 : zstd_frame(cc, PACK_ZSTD_TRIAL_LEVEL, zt, cap, c->data, c->size, NULL, 0,
	                                               PACK_ZSTD_FLUSH);
	size_t t = ZSTD_isError(t1) ? t1
	                            : zstd_frame(cc, PACK_ZSTD_LEVEL, z, cap, c->data, c->size, has_prefix ? prefix : NULL,
	                                         has_prefix ? prefix_size : 0, t1 < t0 ? PACK_ZSTD_FLUSH : 0);
	if (ZSTD_isError(t)) {
		r = mlod_fail(err, MLOD_ERR_INVALID_ARG, "zstd%s: %s", has_prefix ? " with a prefix" : "",
		              ZSTD_getErrorName(t));
		goto done;
	}
	if (t < c->size) { /* else the container stays as it is */
		free(c->data);
		c->coded = (uint32_t)c->size;
		c->data = z;
		c->size = t;
		c->entropy = has_prefix ? MLOD_ENTROPY_ZSTD_PREFIX : MLOD_ENTROPY_ZSTD;
		z = NULL;
	}
done:
	free(z);
	free(zt);
	ZSTD_freeCCtx(cc);
	return r;
}

/* The bytes of d's zstd frame alone at PACK_CHOICE_LEVEL, at most n (the
 * estimate chunk_stream_choice compares forms by). cc: a reused context;
 * scratch grows to the bound. 0 when zstd fails or out of memory. */
static size_t zstd_bytes(ZSTD_CCtx *cc, uint8_t **scratch, size_t *cap, const uint8_t *d, size_t n)
{
	size_t need = ZSTD_compressBound(n);
	if (need > *cap) {
		uint8_t *p = realloc(*scratch, need);
		if (!p)
			return 0;
		*scratch = p, *cap = need;
	}
	size_t z = ZSTD_compressCCtx(cc, *scratch, *cap, d, n, PACK_CHOICE_LEVEL);
	return ZSTD_isError(z) ? 0 : z < n ? z : n;
}

/* Byte planes (MLOD_SCODEC_PLANES, _DELTA; format 7.0) of n elements of
 * e bytes: byte j of element k at j * n + k, with delta each minus the
 * same byte of element k - 1. */
static void to_planes(const uint8_t *src, size_t n, size_t e, int delta, uint8_t *out)
{
	for (size_t j = 0; j < e; j++)
		for (size_t k = 0; k < n; k++)
			out[j * n + k] = (uint8_t)(src[k * e + j] - (delta && k ? src[(k - 1) * e + j] : 0));
}

/* The stream codecs by the entropy stage's bytes: cb_finish codes a
 * stream with meshopt wherever that is smaller than the raw bytes, but
 * zstd after it may store the raw bytes in fewer (unorm8 joints and
 * weights, whose meshopt deltas look random to it), or the bytes in
 * planes (format 7.0: UVs, normals, positions), or weights without their
 * sums. Per stream of a meshopt chunk but index buffers, the form whose
 * zstd frame alone (PACK_CHOICE_LEVEL, on the first PACK_CHOICE_SAMPLE
 * bytes) is the smallest: as cb_finish made it, raw, in byte planes, in
 * planes of deltas, or (elements of 4 bytes each summing to 255) without
 * their sums (ties in that order). The decoded values are the same. */
static mlod_result chunk_stream_choice(chunk *c, mlod_error *err)
{
	if (c->type == MLOD_CHUNK_INFO || c->codec != MLOD_CODEC_MESHOPT || c->size < 4)
		return MLOD_OK;
	uint32_t ns = (uint32_t)c->data[0] | (uint32_t)c->data[1] << 8 | (uint32_t)c->data[2] << 16 |
	              (uint32_t)c->data[3] << 24;
	mlod_result r = MLOD_OK;
	size_t cap = 0;
	uint8_t *scratch = NULL, *raw = NULL, *form = NULL;
	uint8_t **pick = calloc((size_t)ns + 1, sizeof *pick); /* the chosen form's bytes, NULL: as it is */
	uint8_t *pick_codec = calloc((size_t)ns + 1, 1);
	size_t *pick_size = calloc((size_t)ns + 1, sizeof *pick_size);
	ZSTD_CCtx *cc = ZSTD_createCCtx();
	buf b = {0};
	if (!pick || !pick_codec || !pick_size || !cc)
		goto nomem;
	for (uint32_t i = 0, at = 4 + 16 * ns; i < ns; i++) {
		const uint8_t *h = c->data + 4 + 16 * (size_t)i;
		uint8_t scodec = h[10];
		uint32_t count = (uint32_t)h[4] | (uint32_t)h[5] << 8 | (uint32_t)h[6] << 16 | (uint32_t)h[7] << 24;
		size_t el = (size_t)h[8] | (size_t)h[9] << 8, bytes = (size_t)count * el;
		size_t stored = (size_t)h[12] | (size_t)h[13] << 8 | (size_t)h[14] << 16 | (size_t)h[15] << 24;
		const uint8_t *src = c->data + at;
		at += (uint32_t)((stored + 3) & ~(size_t)3);
		pick_codec[i] = scodec;
		/* index buffers stay with meshopt's index codec (raw or planes
		 * of them never came near it) */
		if (!count || scodec == MLOD_SCODEC_MESHOPT_INDEX)
			continue;
		if (!(raw = malloc(bytes)) || !(form = malloc(bytes)))
			goto nomem;
		int rc = scodec == MLOD_SCODEC_RAW                ? (memcpy(raw, src, bytes), 0)
		         : scodec == MLOD_SCODEC_MESHOPT_VERTEX   ? meshopt_decodeVertexBuffer(raw, count, el, src, stored)
		         : scodec == MLOD_SCODEC_MESHOPT_SEQUENCE ? meshopt_decodeIndexSequence(raw, count, el, src, stored)
		                                                  : meshopt_decodeIndexBuffer(raw, count, el, src, stored);
		if (rc != 0) { /* never: the writer's own coding */
			r = mlod_fail(err, MLOD_ERR_INVALID_ARG, "meshopt decode of the writer's own stream failed (%d)", rc);
			goto done;
		}
		int sums = el == 4; /* every element's bytes sum to 255 (unorm8 weights) */
		for (size_t k = 0; sums && k < count; k++)
			sums = raw[4 * k] + raw[4 * k + 1] + raw[4 * k + 2] + raw[4 * k + 3] == 255;
		/* The forms compared on the stream's first PACK_CHOICE_SAMPLE bytes
		 * of elements (the whole of a sequence-coded one), the codec's form
		 * coded again on them. */
		uint32_t en = scodec == MLOD_SCODEC_MESHOPT_SEQUENCE || bytes <= PACK_CHOICE_SAMPLE
		                      ? count
		                      : (uint32_t)(PACK_CHOICE_SAMPLE / el > 0 ? PACK_CHOICE_SAMPLE / el : 1);
		size_t best;
		if (en == count) {
			best = zstd_bytes(cc, &scratch, &cap, src, stored);
		} else if (scodec == MLOD_SCODEC_MESHOPT_VERTEX) {
			size_t bound = meshopt_encodeVertexBufferBound(en, el);
			uint8_t *sub = malloc(bound);
			if (!sub)
				goto nomem;
			size_t sn = meshopt_encodeVertexBuffer(sub, bound, raw, en, el);
			best = sn ? zstd_bytes(cc, &scratch, &cap, sub, sn) : 0;
			free(sub);
		} else {
			best = zstd_bytes(cc, &scratch, &cap, raw, (size_t)en * el);
		}
		for (int f = 0; best && f < 4; f++) {
			static const uint8_t codecs[4] = {MLOD_SCODEC_RAW, MLOD_SCODEC_PLANES, MLOD_SCODEC_PLANES_DELTA,
			                                  MLOD_SCODEC_SUM255};
			uint8_t codec = codecs[f];
			size_t fb = f == 3 ? 3 * (size_t)count : bytes;
			if ((f == 0 && scodec == MLOD_SCODEC_RAW) || (f == 1 && el == 1) || (f == 3 && !sums))
				continue;
			size_t z = 0;
			for (int whole = en == count; whole < 2; whole++) { /* the sample, then the stream */
				uint32_t m = whole ? count : en;
				if (f == 0)
					memcpy(form, raw, (size_t)m * el);
				else if (f == 3)
					for (size_t k = 0; k < m; k++)
						memcpy(form + 3 * k, raw + 4 * k, 3);
				else
					to_planes(raw, m, el, f == 2, form);
				if (!whole)
					z = zstd_bytes(cc, &scratch, &cap, form, f == 3 ? 3 * (size_t)m : (size_t)m * el);
				else if (en == count)
					z = zstd_bytes(cc, &scratch, &cap, form, fb);
				if (!whole && !(z && z < best))
					break; /* the sample lost: no whole form */
			}
			if (z && z < best) {
				best = z;
				free(pick[i]);
				pick[i] = form, pick_codec[i] = codec, pick_size[i] = fb;
				if (!(form = malloc(bytes)))
					goto nomem;
			}
		}
		free(raw), free(form);
		raw = form = NULL;
	}
	/* the container with the chosen forms */
	buf_put(&b, c->data, 4 + 16 * (size_t)ns);
	for (uint32_t i = 0, at = 4 + 16 * ns; i < ns; i++) {
		uint8_t *h = c->data + 4 + 16 * (size_t)i;
		size_t stored = (size_t)h[12] | (size_t)h[13] << 8 | (size_t)h[14] << 16 | (size_t)h[15] << 24;
		if (pick[i]) {
			buf_put(&b, pick[i], pick_size[i]);
			if (!b.fail) {
				b.p[4 + 16 * (size_t)i + 10] = pick_codec[i];
				put_u32(b.p + 4 + 16 * (size_t)i + 12, (uint32_t)pick_size[i]);
			}
		} else {
			buf_put(&b, c->data + at, stored);
		}
		buf_pad(&b, 4);
		at += (uint32_t)((stored + 3) & ~(size_t)3);
	}
	if (b.fail)
		goto nomem;
	if (b.n <= c->raw) { /* always: no form is larger than the raw bytes */
		free(c->data);
		c->data = b.p, c->size = b.n;
		b.p = NULL;
	}
	goto done;
nomem:
	r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory writing the pack");
done:
	for (uint32_t i = 0; pick && i < ns; i++)
		free(pick[i]);
	free(pick);
	free(pick_codec);
	free(pick_size);
	free(raw);
	free(form);
	free(scratch);
	free(b.p);
	ZSTD_freeCCtx(cc);
	return r;
}

/* A string table. */
typedef struct strtab {
	buf b;
} strtab;

static uint32_t str_add(strtab *t, const char *s)
{
	uint32_t off = (uint32_t)t->b.n;
	buf_put(&t->b, s ? s : "", strlen(s ? s : "") + 1);
	return off;
}

/* ------------------------------------------------------------------ */
/* The character as packed                                             */
/* ------------------------------------------------------------------ */

struct clip_levels {
	const mlod_clip *level0;   /* the input clip, or its reduction (motion_level0) */
	float error0;              /* level 0's joint position error against the input clip */
	int count;                 /* levels >= 1 */
	int no_shifts;             /* its rotation keys all at shift 0 (motion_shift_choice) */
	int packed;                /* a pack's level 0 (extras.mlod.motion_level0): kept as read */
	const mlod_clip *clip[MLOD_PACK_MAX_MOTION_LEVELS];
	float error[MLOD_PACK_MAX_MOTION_LEVELS];
	float toc[MLOD_PACK_MAX_MOTION_LEVELS + 1]; /* per level, 0 first: its TOC error (the chunk loop) */
	/* The bounds the levels hold as read back (motion_hold), scene units;
	 * 0: none (the clip as read, a pack's levels, an input's without). */
	double bound0, bound[MLOD_PACK_MAX_MOTION_LEVELS];
	mlod_motion_level remade[MLOD_PACK_MAX_MOTION_LEVELS + 1]; /* 0 first: the levels made again */
	int chain_remade;          /* levels 1 to count are remade[1] to remade[count] */
	/* rotq_shifts' last answer (the shifts follow the clip and emin only) */
	int *shift, *tgrid, has_shift;
	double shift_emin;
	/* img_error's samples: the times and the clip as read posed there */
	float *at;
	mlod_mat4 *world;
	int samples;
};

/* The root of skin `skin` as a skin joint index: its joint nearest the
 * skeleton's root (the first of them). */
static int skin_root(const mlod_skeleton *s, int skin)
{
	const mlod_skin *sk = &s->skins[skin];
	int best = 0, best_depth = -1;
	for (int q = 0; q < sk->joint_count; q++) {
		int depth = 0, j = sk->joints[q];
		while (j >= 0 && j < s->joint_count && depth <= s->joint_count)
			j = s->joints[j].parent, depth++;
		if (best_depth < 0 || depth < best_depth)
			best = q, best_depth = depth;
	}
	return best;
}

struct ctx {
	const mlod_gltf *doc;
	const mlod_character *in;
	mlod_format format;
	const mlod_pack_options *opt; /* codec draco: opt's copy with codec meshopt (the other chunks') */
	int draco;                    /* --codec draco: MESH chunks are Draco meshes (draco_level) */
	mlod_result draco_fail;       /* draco_level's failure (its message in err) */
	mlod_pack_stats *st;
	mlod_error *err;
	mlod_record rec;
	/* The view: the full skins and clips of in. */
	mlod_character v;
	int *view_skin;            /* input skin -> view skin, -1 for a level's */
	mlod_mat4 *world;          /* rest world matrices */
	float bmin[3], bmax[3], diag, height;
	/* skeleton levels >= 1, finest first */
	int skel_count;
	unsigned char *kept[MLOD_SKEL_MAX_LEVELS];
	int *remap[MLOD_SKEL_MAX_LEVELS];
	float skel_error[MLOD_SKEL_MAX_LEVELS];
	/* mesh levels >= 1 */
	int mesh_count;
	const mlod_mesh *level_mesh[MLOD_MESH_MAX_LEVELS]; /* per instance (computed) */
	int *level_node[MLOD_MESH_MAX_LEVELS];             /* per instance (from input), -1 none */
	float mesh_error[MLOD_MESH_MAX_LEVELS];
	mlod_mesh_levels ML;
	int has_ML;
	struct mpart *mp;          /* the parts of layout b2 (mesh_parts) */
	uint32_t degenerate[MLOD_MESH_MAX_LEVELS + 1]; /* per MESH level: triangles quantisation made degenerate */
	int emptied[MLOD_MESH_MAX_LEVELS + 1];         /* per MESH level: parts left without a triangle */
	int mp_count, mp_ready;
	int **lmaps;               /* per level and instance: level_joint_map, or NULL */
	int lmap_count;
	/* motion */
	struct clip_levels *clips;
	mlod_motion_level *owned_levels;
	int owned_count;
	mlod_motion_level *level0_owned; /* per clip; clip.channels NULL where level 0 is the input's */
	struct motion_img *motion_imgs;  /* per clip, two: the last MOTION chunk written and the one before */
	int motion_count;          /* levels >= 1, over all clips */
};

static void note(struct ctx *x, const char *text)
{
	char *n = x->st->notes;
	size_t len = strlen(n);
	if (len + strlen(text) + 3 < sizeof x->st->notes)
		snprintf(n + len, sizeof x->st->notes - len, "%s%s", len ? "; " : "", text);
}

/* A note that is also a warning (mlod_pack_stats.warnings). */
static void warn(struct ctx *x, const char *text)
{
	note(x, text);
	char *w = x->st->warnings;
	size_t len = strlen(w);
	if (len + strlen(text) + 2 < sizeof x->st->warnings)
		snprintf(w + len, sizeof x->st->warnings - len, "%s%s", len ? "\n" : "", text);
}

static int joint_of_node(const mlod_skeleton *s, int node)
{
	for (int j = 0; j < s->joint_count; j++)
		if (s->joints[j].node == node)
			return j;
	return -1;
}

static int skin_of_gltf(const mlod_skeleton *s, int g)
{
	for (int i = 0; g >= 0 && i < s->skin_count; i++)
		if (s->skins[i].gltf_index == g)
			return i;
	return -1;
}

static int mesh_of_gltf(const mlod_character *c, int g)
{
	for (int i = 0; g >= 0 && i < c->mesh_count; i++)
		if (c->meshes[i].gltf_index == g)
			return i;
	return -1;
}

/* The level nodes of instance node `node`, by mesh level (1-based) into
 * nodes[]; returns the largest level found. errors (may be NULL) gets the
 * largest error_percent.max of each level's nodes, pack_errors the largest
 * pack_error (-1 where none has one), and *no_error 1 when a node has
 * neither. */
static mlod_result level_nodes(struct ctx *x, int node, int *nodes, int *max_level, double *errors,
                               double *pack_errors, int *no_error)
{
	int ids[64], count = 0;
	*max_level = 0;
	if (node < 0 || !x->doc)
		return MLOD_OK;
	mlod_result r = mlod_gltf_node_lod(x->doc, node, ids, 64, &count, x->err);
	for (int i = 0; r == MLOD_OK && i < count && i < 64; i++) {
		mlod_record_mesh_node mn;
		int found = 0;
		if ((r = mlod_record_read_mesh_node(x->doc, ids[i], &mn, &found, x->err)) != MLOD_OK || !found)
			continue;
		if (mn.level >= 1 && mn.level <= MLOD_MESH_MAX_LEVELS) {
			nodes[mn.level - 1] = ids[i];
			if (errors && mn.error.max > errors[mn.level - 1])
				errors[mn.level - 1] = mn.error.max;
			if (pack_errors && mn.has_pack_error && mn.pack_error > pack_errors[mn.level - 1])
				pack_errors[mn.level - 1] = mn.pack_error;
			if (no_error && mn.missing_error && !mn.has_pack_error)
				*no_error = 1;
			*max_level = mn.level > *max_level ? mn.level : *max_level;
		}
	}
	return r;
}

/* Builds the view: skins that are not a level's, clips that are not a
 * motion level. */
static mlod_result make_view(struct ctx *x)
{
	const mlod_character *c = x->in;
	const mlod_skeleton *s = &c->skeleton;
	mlod_result r;
	unsigned char *level_skin = calloc((size_t)s->skin_count + 1, 1);
	x->view_skin = malloc(sizeof(int) * ((size_t)s->skin_count + 1));
	if (!level_skin || !x->view_skin) {
		free(level_skin);
		return mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
	}
	for (int i = 0; i < x->rec.skin_count; i++)
		for (int k = 0; k < x->rec.skins[i].level_count; k++) {
			int sk = skin_of_gltf(s, x->rec.skins[i].levels[k]);
			if (sk >= 0)
				level_skin[sk] = 1;
		}
	for (int k = 0; k < x->rec.skel_level_count; k++)
		for (int i = 0; i < x->rec.skel_levels[k].skin_count; i++) {
			int sk = skin_of_gltf(s, x->rec.skel_levels[k].skins[i]);
			if (sk >= 0)
				level_skin[sk] = 1;
		}
	for (int i = 0; i < c->instance_count; i++) {
		int nodes[MLOD_MESH_MAX_LEVELS], max = 0;
		if ((r = level_nodes(x, c->instances[i].node, nodes, &max, NULL, NULL, NULL)) != MLOD_OK) {
			free(level_skin);
			return r;
		}
		for (int k = 0; k < max; k++) {
			int mesh = -1, skin = -1;
			mlod_error ignored;
			if (mlod_gltf_node_refs(x->doc, nodes[k], &mesh, &skin, &ignored) == MLOD_OK && skin >= 0) {
				int sk = skin_of_gltf(s, skin);
				if (sk >= 0 && sk != c->instances[i].skin)
					level_skin[sk] = 1;
			}
		}
	}
	x->v = *c;
	x->v.notes = NULL;
	x->v.skeleton.skins = malloc(sizeof(mlod_skin) * ((size_t)s->skin_count + 1));
	x->v.instances = malloc(sizeof(mlod_instance) * ((size_t)c->instance_count + 1));
	x->v.clips = malloc(sizeof(mlod_clip) * ((size_t)c->clip_count + 1));
	if (!x->v.skeleton.skins || !x->v.instances || !x->v.clips) {
		free(level_skin);
		return mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
	}
	x->v.skeleton.skin_count = 0;
	for (int i = 0; i < s->skin_count; i++) {
		x->view_skin[i] = level_skin[i] ? -1 : x->v.skeleton.skin_count;
		if (!level_skin[i])
			x->v.skeleton.skins[x->v.skeleton.skin_count++] = s->skins[i];
	}
	free(level_skin);
	for (int i = 0; i < c->instance_count; i++) {
		x->v.instances[i] = c->instances[i];
		if (c->instances[i].skin >= 0)
			x->v.instances[i].skin = x->view_skin[c->instances[i].skin];
	}
	x->v.clip_count = 0;
	for (int i = 0; i < c->clip_count; i++) {
		int found = 0;
		mlod_record_motion_level ml;
		if (x->doc && c->clips[i].gltf_index >= 0 &&
		    (r = mlod_record_read_motion(x->doc, c->clips[i].gltf_index, &ml, &found, x->err)) != MLOD_OK)
			return r;
		if (!found)
			x->v.clips[x->v.clip_count++] = c->clips[i];
	}
	if (x->v.skeleton.skin_count < s->skin_count || x->v.clip_count < c->clip_count) {
		char text[160];
		snprintf(text, sizeof text, "the input's level skins (%d) and level animations (%d) are packed as levels",
		         s->skin_count - x->v.skeleton.skin_count, c->clip_count - x->v.clip_count);
		note(x, text);
	}
	return MLOD_OK;
}

/* Rest world matrices, bounds, height and diagonal. */
static mlod_result measure(struct ctx *x)
{
	const mlod_skeleton *s = &x->v.skeleton;
	x->world = malloc(sizeof(mlod_mat4) * ((size_t)s->joint_count + 1));
	mlod_trs *local = malloc(sizeof(mlod_trs) * ((size_t)s->joint_count + 1));
	if (!x->world || !local) {
		free(local);
		return mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
	}
	mlod_pose_rest(s, local);
	mlod_pose_world(s, local, x->world);
	free(local);
	int any = 0;
	for (int a = 0; a < 3; a++) {
		x->bmin[a] = 0.0f;
		x->bmax[a] = 0.0f;
	}
	mlod_posed posed = {0};
	if (x->v.instance_count > 0) {
		mlod_result r = mlod_pose_character(&x->v, x->world, &posed, x->err);
		if (r != MLOD_OK) {
			mlod_posed_free(&posed);
			return r;
		}
	}
	for (int i = 0; i < posed.vertex_count; i++)
		for (int a = 0; a < 3; a++) {
			float p = posed.positions[3 * i + a];
			if (!any || p < x->bmin[a])
				x->bmin[a] = p;
			if (!any || p > x->bmax[a])
				x->bmax[a] = p;
			any |= a == 2;
		}
	mlod_posed_free(&posed);
	if (!any)
		for (int j = 0; j < s->joint_count; j++) {
			float p[3] = {x->world[j].m[12], x->world[j].m[13], x->world[j].m[14]};
			for (int a = 0; a < 3; a++) {
				if (!any || p[a] < x->bmin[a])
					x->bmin[a] = p[a];
				if (!any || p[a] > x->bmax[a])
					x->bmax[a] = p[a];
			}
			any = 1;
		}
	/* An input unpacked from a pack (extras.mlod.pack): that pack's bounds,
	 * which its level 0 posed again after quantisation gives back only to
	 * within the quantisation steps (and its diagonal is the one its
	 * errors in percent were of). */
	if (x->rec.has_pack)
		for (int a = 0; a < 3; a++) {
			x->bmin[a] = (float)x->rec.pack_bounds_min[a];
			x->bmax[a] = (float)x->rec.pack_bounds_max[a];
		}
	float d[3] = {x->bmax[0] - x->bmin[0], x->bmax[1] - x->bmin[1], x->bmax[2] - x->bmin[2]};
	x->diag = sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
	x->height = s->joint_count > 0 ? mlod_skeleton_height(s) : 0.0f;
	return MLOD_OK;
}

/* ------------------------------------------------------------------ */
/* Skeleton                                                            */
/* ------------------------------------------------------------------ */

static mlod_result skeleton_levels(struct ctx *x)
{
	const mlod_skeleton *s = &x->v.skeleton;
	int n = s->joint_count;
	mlod_result r = MLOD_OK;
	if (n == 0 || x->opt->no_skeleton_levels)
		return MLOD_OK;
	/* An empty list: an unpacked pack that had level 0 alone. */
	if (x->rec.has_skel_levels && x->rec.skel_level_count == 0 && x->rec.has_pack) {
		x->st->skeleton.from_input = 1;
		return MLOD_OK;
	}
	if (x->rec.skel_level_count > 0) {
		x->st->skeleton.from_input = 1;
		for (int k = 0; k < x->rec.skel_level_count && k < MLOD_SKEL_MAX_LEVELS; k++) {
			const mlod_record_skel_level *l = &x->rec.skel_levels[k];
			unsigned char *kept = calloc((size_t)n, 1);
			int *remap = malloc(sizeof(int) * (size_t)n);
			if (!kept || !remap) {
				free(kept);
				free(remap);
				return mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
			}
			x->kept[k] = kept;
			x->remap[k] = remap;
			x->skel_count = k + 1;
			for (int i = 0; i < l->kept_count; i++) {
				int j = joint_of_node(s, l->kept[i]);
				if (j < 0)
					return mlod_fail(x->err, MLOD_ERR_PARSE,
					                 "skeleton level %d: kept node %d is not a joint", k + 1, l->kept[i]);
				kept[j] = 1;
			}
			for (int j = 0; j < n; j++)
				if (s->joints[j].parent < 0)
					kept[j] = 1; /* every root is kept */
			for (int j = 0; j < n; j++)
				remap[j] = kept[j] ? j : -1;
			for (int i = 0; i < l->remap_count; i++) {
				int a = joint_of_node(s, l->remap_from[i]), b = joint_of_node(s, l->remap_to[i]);
				if (a < 0 || b < 0 || !kept[b])
					return mlod_fail(x->err, MLOD_ERR_PARSE, "skeleton level %d: remap %d -> %d is not a kept joint",
					                 k + 1, l->remap_from[i], l->remap_to[i]);
				if (!kept[a])
					remap[a] = b;
			}
			for (int j = 0; j < n; j++) /* parents first: the nearest kept ancestor */
				if (remap[j] < 0)
					remap[j] = remap[s->joints[j].parent];
			/* The pack error a record from mlod-pack -x gives, else the
			 * measured errors (version 3 may have neither). */
			if (!l->has_pack_error && !l->has_vertex_error && l->missing_joint_error)
				return mlod_fail(x->err, MLOD_ERR_PARSE,
				                 "the scene's extras.mlod.skeleton_levels[%d]: no error (pack_error, "
				                 "vertex_error_percent or joint_error)",
				                 k);
			x->skel_error[k] = (float)(l->has_pack_error     ? l->pack_error
			                           : l->has_vertex_error ? l->vertex_error.max * x->diag / 100.0
			                                                 : l->joint_error.max);
		}
		return MLOD_OK;
	}
	/* Computed: labels (the record's when there), then the default chain. */
	mlod_joint_info *info = calloc((size_t)n, sizeof *info);
	mlod_skel_levels L;
	int found = 0;
	memset(&L, 0, sizeof L);
	if (!info)
		return mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
	r = mlod_label_skeleton(&x->v, &x->opt->label, info, x->err);
	if (r == MLOD_OK && x->doc)
		r = mlod_record_read_joints(x->doc, &x->v, info, &found, x->err);
	if (r == MLOD_OK)
		r = mlod_skel_levels_init(&L, &x->v, info, x->err);
	if (r == MLOD_OK)
		r = mlod_skel_levels_default(&L, x->opt->skel_max_error, x->err);
	for (int k = 0; r == MLOD_OK && k < L.count; k++) {
		const mlod_skel_built *b = &L.levels[k];
		x->kept[k] = malloc((size_t)n);
		x->remap[k] = malloc(sizeof(int) * (size_t)n);
		x->skel_count = k + 1;
		if (!x->kept[k] || !x->remap[k]) {
			r = mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
			break;
		}
		memcpy(x->kept[k], b->skel.kept, (size_t)n);
		memcpy(x->remap[k], b->skel.remap, sizeof(int) * (size_t)n);
		x->skel_error[k] = (float)(b->has_mesh_error ? b->vertex.max * x->diag / 100.0 : b->joint.max);
	}
	if (r == MLOD_OK && L.count == 0 && L.minor_count > 0)
		note(x, "no skeleton level within the skeleton's max error");
	mlod_skel_levels_free(&L);
	free(info);
	return r;
}

static mlod_result skeleton_chunk(struct ctx *x, chunks *out)
{
	const mlod_skeleton *s = &x->v.skeleton;
	chunkb cb = {0};
	strtab names = {0};
	int n = s->joint_count;
	mlod_pack_joint_rec *j = calloc((size_t)n + 1, sizeof *j);
	mlod_pack_skin_rec *sk = calloc((size_t)s->skin_count + 1, sizeof *sk);
	size_t pal = 0;
	for (int i = 0; i < s->skin_count; i++)
		pal += (size_t)s->skins[i].joint_count;
	uint32_t *skjt = malloc(sizeof(uint32_t) * (pal + 1));
	float *ibms = malloc(sizeof(float) * 16 * (pal + 1));
	mlod_result r = MLOD_OK;
	if (!j || !sk || !skjt || !ibms) {
		r = mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
		goto done;
	}
	for (int i = 0; i < n; i++) {
		const mlod_joint *q = &s->joints[i];
		j[i].parent = q->parent;
		j[i].name = str_add(&names, q->name);
		j[i].t[0] = q->rest.t.x, j[i].t[1] = q->rest.t.y, j[i].t[2] = q->rest.t.z;
		j[i].r[0] = q->rest.r.x, j[i].r[1] = q->rest.r.y, j[i].r[2] = q->rest.r.z, j[i].r[3] = q->rest.r.w;
		j[i].s[0] = q->rest.s.x, j[i].s[1] = q->rest.s.y, j[i].s[2] = q->rest.s.z;
		memcpy(j[i].base, q->base.m, sizeof j[i].base);
		j[i].node = q->node;
	}
	size_t e = 0;
	for (int i = 0; i < s->skin_count; i++) {
		const mlod_skin *k = &s->skins[i];
		sk[i].joint_count = (uint32_t)k->joint_count;
		sk[i].name = str_add(&names, k->name);
		sk[i].gltf_index = k->gltf_index;
		for (int q = 0; q < k->joint_count; q++, e++) {
			skjt[e] = (uint32_t)k->joints[q];
			memcpy(ibms + 16 * e, k->inverse_bind[q].m, 64);
		}
	}
	if (names.b.fail) {
		r = mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
		goto done;
	}
	cb_add(&cb, MLOD_STREAM_JNTS, (uint32_t)n, sizeof *j, j, 0);
	cb_add(&cb, MLOD_STREAM_NAME, (uint32_t)names.b.n, 1, names.b.p, 0);
	cb_add(&cb, MLOD_STREAM_SKIN, (uint32_t)s->skin_count, sizeof *sk, sk, 0);
	cb_add(&cb, MLOD_STREAM_SKJT, (uint32_t)pal, 4, skjt, 0);
	cb_add(&cb, MLOD_STREAM_IBMS, (uint32_t)pal, 64, ibms, 0);
	r = cb_finish(&cb, x->opt->codec, out, MLOD_CHUNK_SKELETON, MLOD_LAYER_SKELETON, 0, 0, 0.0f, x->err);
done:
	cb_free(&cb);
	free(names.b.p);
	free(j);
	free(sk);
	free(skjt);
	free(ibms);
	return r;
}

/* Skeleton level k (1-based): KEPT, and the palette binds (as PALR and
 * PALX, format 7.0; the palette joints the reader derives) as fold.c's skin
 * transfer makes it (reduce_skin): a kept skin joint keeps its bind; a
 * removed one uses its stand-in's entry in the level skin: the stand-in's
 * own bind when the skin has it, else R(stand-in -> joint) * IBM(joint)
 * of the first removed joint of the skin that brought it in. */
static mlod_result skel_level_chunk(struct ctx *x, int k, chunks *out)
{
	const mlod_skeleton *s = &x->v.skeleton;
	const unsigned char *kept = x->kept[k - 1];
	const int *remap = x->remap[k - 1];
	int n = s->joint_count;
	size_t pal = 0, e = 0;
	int maxsk = 0;
	for (int i = 0; i < s->skin_count; i++) {
		pal += (size_t)s->skins[i].joint_count;
		maxsk = s->skins[i].joint_count > maxsk ? s->skins[i].joint_count : maxsk;
	}
	uint32_t *keptv = malloc(sizeof(uint32_t) * ((size_t)n + 1)), kc = 0;
	uint32_t *palr = malloc(sizeof(uint32_t) * (pal + 1));
	float *palb = malloc(sizeof(float) * 16 * (pal + 1));
	float *palx = malloc(sizeof(float) * 16 * (pal + 1));
	float *ibmf = malloc(sizeof(float) * 16 * (pal + 1)); /* SKELETON's 'IBMS' */
	size_t nx = 0;
	int *lj = malloc(sizeof(int) * ((size_t)maxsk + 1));          /* the level skin's joints */
	mlod_mat4 *lb = malloc(sizeof(mlod_mat4) * ((size_t)maxsk + 1)); /* and binds */
	chunkb cb = {0};
	mlod_result r = MLOD_OK;
	if (!keptv || !palr || !palb || !palx || !ibmf || !lj || !lb) {
		r = mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
		goto done;
	}
	for (int j = 0; j < n; j++)
		if (kept[j])
			keptv[kc++] = (uint32_t)j;
	for (int i = 0; i < s->skin_count; i++) {
		const mlod_skin *sk = &s->skins[i];
		int ln = 0;
		for (int q = 0; q < sk->joint_count; q++)
			if (kept[sk->joints[q]]) {
				lj[ln] = sk->joints[q];
				lb[ln++] = sk->inverse_bind[q];
			}
		for (int q = 0; q < sk->joint_count; q++, e++) {
			int j = sk->joints[q];
			mlod_mat4 bind = sk->inverse_bind[q];
			if (!kept[j]) { /* its palette joint, the stand-in, the reader derives */
				int stand = remap[j], at = -1;
				for (int t = 0; t < ln; t++)
					if (lj[t] == stand)
						at = t;
				if (at < 0) {
					mlod_mat4 inv, rel;
					if (mlod_mat4_invert(&x->world[stand], &inv) != 0) {
						r = mlod_fail(x->err, MLOD_ERR_PARSE, "joint \"%s\" has a singular rest transform",
						              s->joints[stand].name);
						goto done;
					}
					rel = mlod_mat4_mul(&inv, &x->world[j]);
					lj[ln] = stand;
					lb[ln] = mlod_mat4_mul(&rel, &sk->inverse_bind[q]);
					at = ln++;
				}
				bind = lb[at];
			}
			memcpy(palb + 16 * e, bind.m, 64);
			memcpy(ibmf + 16 * e, sk->inverse_bind[q].m, 64);
		}
	}
	/* Format 7.0: each bind matrix as a reference (palr, mlod(5)): 0 for
	 * the joint's own IBMS entry, 1 + the first IBMS entry over all skins
	 * that holds the same bytes, else P + 1 + its index in PALX (each
	 * matrix once, in first-use order). */
	for (size_t i = 0, xe = 0, g = 0; i < pal; i++) {
		const float *m = palb + 16 * i;
		if (memcmp(m, ibmf + 16 * i, 64) == 0) {
			palr[i] = 0;
			continue;
		}
		for (g = 0; g < pal && memcmp(m, ibmf + 16 * g, 64) != 0; g++)
			;
		if (g < pal) {
			palr[i] = (uint32_t)(g + 1);
			continue;
		}
		for (g = 0; g < xe && memcmp(m, palx + 16 * g, 64) != 0; g++)
			;
		if (g == xe)
			memcpy(palx + 16 * xe++, m, 64);
		palr[i] = (uint32_t)(pal + 1 + g);
		nx = xe;
	}
	cb_add(&cb, MLOD_STREAM_KEPT, kc, 4, keptv, 0);
	cb_add(&cb, MLOD_STREAM_PALR, (uint32_t)pal, 4, palr, 0);
	cb_add(&cb, MLOD_STREAM_PALX, (uint32_t)nx, 64, palx, 0);
	r = cb_finish(&cb, x->opt->codec, out, MLOD_CHUNK_SKELETON, MLOD_LAYER_SKELETON, k, 0, x->skel_error[k - 1],
	              x->err);
done:
	cb_free(&cb);
	free(keptv);
	free(palr);
	free(palb);
	free(palx);
	free(ibmf);
	free(lj);
	free(lb);
	return r;
}

/* ------------------------------------------------------------------ */
/* Mesh                                                                */
/* ------------------------------------------------------------------ */

static int *level_joint_map(const mlod_skeleton *s, const mlod_skin *lsk, const mlod_skin *fsk);

/* ------------------------------------------------------------------ */
/* Input mesh levels bound to skeleton levels (issue 11)               */
/* ------------------------------------------------------------------ */

/* The input's mesh level k (0-based) of instance i and its skin: *mesh
 * the input character's mesh (NULL: the instance has no level node
 * there), *skin the input skin of the level node (-1: none). */
static mlod_result input_level(struct ctx *x, int k, int i, const mlod_mesh **mesh, int *skin)
{
	int gm = -1, gs = -1;
	*mesh = NULL;
	*skin = -1;
	if (!x->level_node[k] || x->level_node[k][i] < 0)
		return MLOD_OK;
	mlod_result r = mlod_gltf_node_refs(x->doc, x->level_node[k][i], &gm, &gs, x->err);
	if (r != MLOD_OK)
		return r;
	int mi = mesh_of_gltf(x->in, gm);
	if (mi < 0)
		return mlod_fail(x->err, MLOD_ERR_PARSE, "mesh level %d of node %d: its mesh %d was not read", k + 1,
		                 x->v.instances[i].node, gm);
	*mesh = &x->in->meshes[mi];
	*skin = skin_of_gltf(&x->in->skeleton, gs);
	return MLOD_OK;
}

/* Whether the input's mesh level k of skinned instance i is skinned with
 * another skin than the instance's: a skeleton level's, on which
 * mlod-bgm after mlod-skelgraph (or mlod-pack -x) wrote it, moving each
 * influence of a joint that level removes to the joint's stand-in. Its
 * weights on the full skin are lost. */
static mlod_result level_bound(struct ctx *x, int k, int i, int *bound)
{
	const mlod_mesh *m;
	int ls;
	*bound = 0;
	mlod_result r = input_level(x, k, i, &m, &ls);
	if (r == MLOD_OK && m && x->v.instances[i].skin >= 0 && ls >= 0)
		*bound = x->view_skin[ls] != x->v.instances[i].skin;
	return r;
}

static int same_floats(const float *a, const float *b, long n)
{
	return (!a && !b) || (a && b && memcmp(a, b, sizeof *a * (size_t)n) == 0);
}

/* Whether the levels of L have the input's triangles: each level node's
 * primitives the same positions and indices, and no simplified primitive
 * where the input has no level node. */
static mlod_result same_triangles(struct ctx *x, const mlod_mesh_levels *L, int *same)
{
	const mlod_character *c = &x->v;
	*same = L->count == x->mesh_count;
	for (int k = 0; *same && k < L->count; k++)
		for (int i = 0; *same && i < c->instance_count; i++) {
			const mlod_mesh *im, *lm = &L->levels[k].meshes[i];
			int ls;
			mlod_result r = input_level(x, k, i, &im, &ls);
			if (r != MLOD_OK)
				return r;
			if (!im) {
				for (int p = 0; *same && p < lm->primitive_count; p++)
					*same = !L->levels[k].owned[i][p];
				continue;
			}
			*same = im->primitive_count == lm->primitive_count;
			for (int p = 0; *same && p < lm->primitive_count; p++) {
				const mlod_primitive *a = &im->primitives[p], *b = &lm->primitives[p];
				*same = a->mode == b->mode && a->vertex_count == b->vertex_count &&
				        a->index_count == b->index_count &&
				        same_floats(a->positions, b->positions, 3L * a->vertex_count) &&
				        ((!a->indices && !b->indices) ||
				         (a->indices && b->indices &&
				          memcmp(a->indices, b->indices, sizeof *a->indices * (size_t)a->index_count) == 0));
			}
		}
	return MLOD_OK;
}

/* The input's levels rebuilt on the full skin from level 0: mlod-bgm's
 * levels do not depend on the skeleton levels (it binds them to those
 * only after measuring them), so the same ratios (the stage record's)
 * and options (mlod-pack's own: the record holds no other) give the
 * same triangles, with their weights on the full skin and their posed
 * errors. *rebuilt 0 (and nothing kept) when the record has no ratio for
 * every level (mlod-pack -x writes none), the rebuild gives other
 * triangles (mlod-bgm ran with options the record does not hold) or
 * fails but for memory. */
static mlod_result rebuild_levels(struct ctx *x, int *rebuilt)
{
	double ratios[MLOD_MESH_MAX_LEVELS];
	int n = x->mesh_count, same = 0;
	*rebuilt = 0;
	if (x->rec.mesh_level_count != n)
		return MLOD_OK;
	for (int k = 0; k < n; k++) {
		const mlod_record_mesh_level *l = &x->rec.mesh_levels[k];
		if (l->level != k + 1 || l->missing_ratio || !(l->ratio > 0.0 && l->ratio < 1.0) ||
		    (k > 0 && !(l->ratio < ratios[k - 1])))
			return MLOD_OK;
		ratios[k] = l->ratio;
	}
	mlod_bgm_options bo = x->opt->bgm;
	mlod_mesh_budget budget = x->opt->budget;
	mlod_mesh_resolve(&bo, &budget);
	mlod_result r = mlod_mesh_levels_init(&x->ML, &x->v, &bo, budget, ratios[n - 1], x->err);
	x->has_ML = 1;
	if (r == MLOD_OK)
		r = mlod_mesh_levels_by_ratio(&x->ML, ratios, n, x->err);
	if (r == MLOD_OK)
		r = same_triangles(x, &x->ML, &same);
	if (r != MLOD_OK || !same) {
		mlod_mesh_levels_free(&x->ML);
		x->has_ML = 0;
		/* levels that cannot be made again are measured instead */
		return r == MLOD_ERR_NOMEM ? r : MLOD_OK;
	}
	for (int k = 0; k < n; k++) {
		x->level_mesh[k] = x->ML.levels[k].meshes;
		x->mesh_error[k] = (float)(x->ML.levels[k].error.max * x->diag / 100.0);
	}
	*rebuilt = 1;
	return MLOD_OK;
}

/* The character at input mesh level k as the pack stores it: each
 * instance's level mesh (level 0's where it has none), the weights of a
 * level bound to a skeleton level's skin mapped to the full skin as
 * mesh_parts maps them (level_joint_map). view->instances must hold the
 * instances, meshes one mesh per instance; the primitives of bound
 * levels go to prims from *nprim on and their joint arrays to own from
 * *nown on (the caller's to free). */
static mlod_result stored_level(struct ctx *x, int k, mlod_character *view, mlod_mesh *meshes,
                                mlod_primitive *prims, int *nprim, uint16_t **own, int *nown)
{
	const mlod_character *c = &x->v;
	mlod_instance *inst = view->instances;
	*view = *c;
	view->instances = inst;
	view->meshes = meshes;
	view->mesh_count = c->instance_count;
	for (int i = 0; i < c->instance_count; i++) {
		const mlod_instance *in = &c->instances[i];
		const mlod_mesh *m;
		int ls;
		mlod_result r = input_level(x, k, i, &m, &ls);
		if (r != MLOD_OK)
			return r;
		meshes[i] = m ? *m : c->meshes[in->mesh];
		inst[i] = *in;
		inst[i].mesh = i;
		if (!m || in->skin < 0 || ls < 0 || x->view_skin[ls] == in->skin)
			continue;
		const mlod_skin *lsk = &x->in->skeleton.skins[ls];
		int *map = level_joint_map(&c->skeleton, lsk, &c->skeleton.skins[in->skin]);
		if (!map)
			return mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
		mlod_primitive *q = prims + *nprim;
		*nprim += m->primitive_count;
		for (int p = 0; p < m->primitive_count; p++) {
			q[p] = m->primitives[p];
			for (int s = 0; s < q[p].weight_set_count && s < MLOD_MAX_SETS; s++) {
				if (!q[p].joints[s])
					continue;
				uint16_t *j = malloc(sizeof *j * 4 * ((size_t)q[p].vertex_count + 1));
				if (!j) {
					free(map);
					return mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
				}
				own[(*nown)++] = j;
				for (long v = 0; v < 4L * q[p].vertex_count; v++) {
					int a = m->primitives[p].joints[s][v];
					j[v] = (uint16_t)(a < lsk->joint_count ? map[a] : 0);
				}
				q[p].joints[s] = j;
			}
		}
		meshes[i].primitives = q;
		free(map);
	}
	return MLOD_OK;
}

/* The input's levels that are bound to skeleton levels measured again as
 * the pack stores them: posed under the full skeleton with their stored
 * weights, against level 0, at mlod-bgm's measuring poses (rest pose, up
 * to 4 times per clip, 8 random poses: meshlevels.c make_poses). Each
 * such level's error becomes the larger of that and the input's. */
static mlod_result measure_bound_levels(struct ctx *x, const int *bound)
{
	const mlod_character *c = &x->v;
	int n = x->mesh_count, nprim = 0, nown = 0, count = 0;
	for (int i = 0; i < c->instance_count; i++)
		for (int k = 0; k < n; k++) {
			const mlod_mesh *m;
			int ls;
			mlod_result r = input_level(x, k, i, &m, &ls);
			if (r != MLOD_OK)
				return r;
			nprim += m ? m->primitive_count : 0;
		}
	mlod_character *views = calloc((size_t)n + 1, sizeof *views);
	const mlod_character **lv = calloc((size_t)n + 1, sizeof *lv);
	mlod_mesh *meshes = calloc((size_t)n * (size_t)c->instance_count + 1, sizeof *meshes);
	mlod_instance *inst = calloc((size_t)n * (size_t)c->instance_count + 1, sizeof *inst);
	mlod_primitive *prims = calloc((size_t)nprim + 1, sizeof *prims);
	uint16_t **own = calloc((size_t)nprim * MLOD_MAX_SETS + 1, sizeof *own);
	mlod_deviation *dev = calloc((size_t)n + 1, sizeof *dev);
	int *which = calloc((size_t)n + 1, sizeof *which);
	mlod_pose_set poses = {0};
	mlod_result r = MLOD_OK;
	if (!views || !lv || !meshes || !inst || !prims || !own || !dev || !which)
		r = mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
	for (int k = 0, used = 0; r == MLOD_OK && k < n; k++) {
		if (!bound[k])
			continue;
		views[count].instances = inst + (size_t)count * (size_t)c->instance_count;
		r = stored_level(x, k, &views[count], meshes + (size_t)count * (size_t)c->instance_count, prims, &used, own,
		                 &nown);
		lv[count] = &views[count];
		which[count++] = k;
	}
	if (r == MLOD_OK && count > 0) {
		int clips = c->clip_count > 0 ? c->clip_count : 1, per = 16 / clips;
		mlod_bgm_options bo = x->opt->bgm;
		mlod_mesh_budget budget = x->opt->budget;
		mlod_mesh_resolve(&bo, &budget);
		per = per < 2 ? 2 : per > 4 ? 4 : per;
		r = mlod_pose_set_make(c, 1, per, MLOD_MESH_RANDOM_POSES, MLOD_MESH_MEASURE_SEED, MLOD_MESH_RANDOM_ANGLE,
		                       &poses, x->err);
		poses.threads = bo.threads;
		if (r == MLOD_OK) {
			mlod_pose_set_bound_mean(&poses, 1);
			r = mlod_posed_errors(c, lv, count, &poses, dev, x->err);
		}
	}
	for (int q = 0; r == MLOD_OK && q < count; q++) {
		float e = (float)(dev[q].max * x->diag / 100.0);
		if (e > x->mesh_error[which[q]])
			x->mesh_error[which[q]] = e;
	}
	mlod_pose_set_free(&poses);
	for (int i = 0; i < nown; i++)
		free(own[i]);
	free(views);
	free(lv);
	free(meshes);
	free(inst);
	free(prims);
	free(own);
	free(dev);
	free(which);
	return r;
}

/* Input mesh levels bound to skeleton levels lose their weights on the
 * joints those levels remove, and the runtime shows a mesh level at any
 * skeleton level: at a finer one than the level's own, the removed joints
 * no longer move it, and its error as measured before the binding does
 * not hold (tubeman after mlod-skelgraph | mlod-bgm: mesh level 2 0.2323
 * through the runtime at one clip time, stated 0.174). Such levels are
 * rebuilt on the full skin when that gives the input's triangles
 * (rebuild_levels), else measured again as stored (measure_bound_levels),
 * with a warning either way. */
static mlod_result bound_levels(struct ctx *x)
{
	const mlod_character *c = &x->v;
	int bound[MLOD_MESH_MAX_LEVELS] = {0}, count = 0, rebuilt = 0;
	char list[96] = "";
	for (int k = 0; k < x->mesh_count; k++) {
		for (int i = 0; i < c->instance_count && !bound[k]; i++) {
			mlod_result r = level_bound(x, k, i, &bound[k]);
			if (r != MLOD_OK)
				return r;
		}
		if (bound[k]) {
			size_t n = strlen(list);
			snprintf(list + n, sizeof list - n, "%s%d", count++ ? ", " : "", k + 1);
		}
	}
	if (!count)
		return MLOD_OK;
	mlod_result r = rebuild_levels(x, &rebuilt);
	if (r == MLOD_OK && !rebuilt)
		r = measure_bound_levels(x, bound);
	if (r != MLOD_OK)
		return r;
	int ratios = x->rec.mesh_level_count == x->mesh_count;
	for (int k = 0; ratios && k < x->mesh_count; k++)
		ratios = !x->rec.mesh_levels[k].missing_ratio;
	char text[400];
	snprintf(text, sizeof text,
	         "mesh level%s %s of the input %s on skeleton levels' skins (the weights of the joints those levels "
	         "remove moved to their stand-ins): %s",
	         count > 1 ? "s" : "", list, count > 1 ? "are" : "is",
	         rebuilt ? "the mesh levels are made again on the full skin from level 0 with the stage record's "
	                   "ratios (the same triangles)"
	         : ratios ? "made again with the stage record's ratios and these mesh options they have other triangles "
	                    "(mlod-bgm's options differ: the same -p and --influence-budget may give them): "
	                    "their posed error measured again under the full skeleton with the weights as stored"
	                  : "the stage record has no ratios to make them again with: their posed error measured "
	                    "again under the full skeleton with the weights as stored");
	warn(x, text);
	return MLOD_OK;
}

static int ratio_desc(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return (x < y) - (x > y);
}

static mlod_result mesh_levels(struct ctx *x)
{
	const mlod_character *c = &x->v;
	mlod_result r = MLOD_OK;
	if (x->opt->no_mesh_levels || mlod_mesh_triangle_primitives(c) == 0)
		return MLOD_OK;
	/* The input's levels: MSFT_lod level nodes with a mesh level record. */
	int max = 0;
	int *nodes = malloc(sizeof(int) * MLOD_MESH_MAX_LEVELS * ((size_t)c->instance_count + 1));
	if (!nodes)
		return mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
	for (size_t i = 0; i < MLOD_MESH_MAX_LEVELS * ((size_t)c->instance_count + 1); i++)
		nodes[i] = -1;
	double node_error[MLOD_MESH_MAX_LEVELS] = {0}, node_pack_error[MLOD_MESH_MAX_LEVELS];
	int no_error = 0;
	for (int k = 0; k < MLOD_MESH_MAX_LEVELS; k++)
		node_pack_error[k] = -1.0;
	for (int i = 0; r == MLOD_OK && i < c->instance_count; i++) {
		int m = 0;
		r = level_nodes(x, c->instances[i].node, nodes + MLOD_MESH_MAX_LEVELS * i, &m, node_error, node_pack_error,
		                &no_error);
		max = m > max ? m : max;
	}
	if (r == MLOD_OK && max > 0) {
		x->st->mesh.from_input = 1;
		for (int k = 0; k < max; k++) {
			x->level_node[k] = malloc(sizeof(int) * ((size_t)c->instance_count + 1));
			if (!x->level_node[k]) {
				r = mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
				break;
			}
			x->mesh_count = k + 1;
			for (int i = 0; i < c->instance_count; i++)
				x->level_node[k][i] = nodes[MLOD_MESH_MAX_LEVELS * i + k];
			/* The scene's record, else the largest of the level nodes';
			 * the pack error of a record from mlod-pack -x before the
			 * measured error in percent. */
			int scene = 0;
			x->mesh_error[k] = (float)(node_pack_error[k] >= 0.0 ? node_pack_error[k] : node_error[k] * x->diag / 100.0);
			for (int q = 0; q < x->rec.mesh_level_count; q++) {
				const mlod_record_mesh_level *l = &x->rec.mesh_levels[q];
				if (l->level != k + 1 || (l->missing_error && !l->has_pack_error))
					continue;
				x->mesh_error[k] = (float)(l->has_pack_error ? l->pack_error : l->error.max * x->diag / 100.0);
				scene = 1;
			}
			if (!scene && no_error) {
				r = mlod_fail(x->err, MLOD_ERR_PARSE,
				              "mesh level %d: no error (pack_error or error_percent) in the level nodes' "
				              "or the scene's extras.mlod",
				              k + 1);
				break;
			}
		}
		free(nodes);
		return r == MLOD_OK ? bound_levels(x) : r;
	}
	free(nodes);
	if (r != MLOD_OK)
		return r;
	/* An empty list: an unpacked pack that had level 0 alone. */
	if (x->rec.has_mesh_levels && x->rec.mesh_level_count == 0 && x->rec.has_pack) {
		x->st->mesh.from_input = 1;
		return MLOD_OK;
	}
	/* Computed, as mlod-bgm does with the same options. */
	double ratios[MLOD_MESH_MAX_LEVELS];
	int n = x->opt->ratio_count;
	memcpy(ratios, x->opt->ratios, sizeof ratios);
	qsort(ratios, (size_t)n, sizeof *ratios, ratio_desc);
	mlod_bgm_options bo = x->opt->bgm;
	mlod_mesh_budget budget = x->opt->budget;
	mlod_mesh_resolve(&bo, &budget);
	int by_error = x->opt->mesh_max_error >= 0.0;
	r = mlod_mesh_levels_init(&x->ML, c, &bo, budget, by_error || n == 0 ? 0.0 : ratios[n - 1], x->err);
	x->has_ML = 1;
	if (r == MLOD_OK)
		r = by_error ? mlod_mesh_levels_by_error(&x->ML, x->opt->mesh_max_error, x->err)
		             : mlod_mesh_levels_by_ratio(&x->ML, ratios, n, x->err);
	if (r != MLOD_OK)
		return r;
	if (by_error && x->ML.count == 0)
		note(x, "no mesh level within the mesh's max error");
	for (int k = 0; k < x->ML.count; k++) {
		x->level_mesh[k] = x->ML.levels[k].meshes;
		x->mesh_error[k] = (float)(x->ML.levels[k].error.max * x->diag / 100.0);
	}
	x->mesh_count = x->ML.count;
	return MLOD_OK;
}

/* ------------------------------------------------------------------ */
/* Layout b2 (mlod(5) MESH levels): per part one buffer of quantised     */
/* vertices on one grid, each vertex placed by the coarsest level that   */
/* has it; MESH level k carries its block of new vertices and its        */
/* indices into the buffer's prefix. The chunks are made coarsest first. */
/* ------------------------------------------------------------------ */

/* A part's vertex attribute in the interleaved working buffer. */
typedef struct mattr {
	uint32_t tag;
	uint16_t size;
	int off;
} mattr;

/* One part: a triangle primitive of an instance, at every level. jmap
 * maps a level primitive's joint indices to the full skin's (NULL: as
 * they are). */
struct mpart {
	mlod_pack_part_rec rec; /* the level-independent fields and the grid */
	const mlod_primitive *lv[MLOD_MESH_MAX_LEVELS + 1];
	const int *jmap[MLOD_MESH_MAX_LEVELS + 1];
	int jmap_count[MLOD_MESH_MAX_LEVELS + 1];
	float *tscale;          /* per morph target */
	mattr *attr;
	int nattr, ntargets, stride, skinned, wide;
	uint8_t *G;             /* the buffer, interleaved */
	uint32_t count;
	uint32_t *slot;         /* hash set of G's vertices: id + 1, 0 empty */
	size_t slot_cap;
	/* Coarse levels' own steps (part_coarse; mlod(5) QUANTISATION): per
	 * level and vertex, the finest level that has the vertex as level 0's
	 * steps quantise it (NULL: every vertex on level 0's steps); per
	 * level f >= 1, the position and UV shifts of a vertex whose finest
	 * level is f. */
	uint8_t *fin[MLOD_MESH_MAX_LEVELS + 1];
	int pos_shift[MLOD_MESH_MAX_LEVELS + 1];
	int uv_shift[MLOD_MESH_MAX_LEVELS + 1][MLOD_PACK_MAX_UV];
};

/* The attributes a level primitive has (the part's skin, -1 none). */
static uint32_t prim_signature(const mlod_primitive *p, int skin)
{
	int sets = p->uv_set_count < MLOD_PACK_MAX_UV ? p->uv_set_count : MLOD_PACK_MAX_UV;
	return (p->normals ? 1u : 0u) | (p->tangents ? 2u : 0u) | (p->color_set_count > 0 ? 4u : 0u) |
	       (skin >= 0 && p->weight_set_count > 0 ? 8u : 0u) | (uint32_t)sets << 4 | (uint32_t)p->target_count << 8;
}

/* The grid of every level of a part: the union of the levels' boxes,
 * level 0's steps (positions_bits and uv_bits of level 0's box); a union
 * wider than 65535 such steps takes the union's 16-bit steps. Morph
 * deltas: the largest |delta| of any level. bench/bench_layout makes the
 * same grid (mlod_pack_b2_grid). */
static void part_grid(struct ctx *x, struct mpart *m, int M)
{
	const mlod_primitive *p0 = m->lv[0];
	float mn[3], mx[3], mn0[3], mx0[3];
	for (int k = 0; k < M; k++) {
		const mlod_primitive *p = m->lv[k];
		for (int v = 0; v < p->vertex_count; v++)
			for (int a = 0; a < 3; a++) {
				float f = p->positions[3 * v + a];
				int first = k == 0 && v == 0;
				if (first || f < mn[a])
					mn[a] = f;
				if (first || f > mx[a])
					mx[a] = f;
				if (k == 0)
					mn0[a] = first || f < mn0[a] ? f : mn0[a], mx0[a] = first || f > mx0[a] ? f : mx0[a];
			}
	}
	for (int a = 0; a < 3; a++) {
		float s0 = mlod_pack_range_scale_bits(mn0[a], mx0[a], x->opt->position_bits);
		float s16 = mlod_pack_range_scale_bits(mn[a], mx[a], 16);
		m->rec.pos_min[a] = mn[a];
		m->rec.pos_scale[a] = s0 > s16 ? s0 : s16;
	}
	for (int s = 0; s < (int)m->rec.uv_sets; s++) {
		float umn[2], umx[2], umn0[2], umx0[2];
		for (int k = 0; k < M; k++) {
			const mlod_primitive *p = m->lv[k];
			for (int v = 0; v < p->vertex_count; v++)
				for (int a = 0; a < 2; a++) {
					float f = p->uvs[s][2 * v + a];
					int first = k == 0 && v == 0;
					if (first || f < umn[a])
						umn[a] = f;
					if (first || f > umx[a])
						umx[a] = f;
					if (k == 0)
						umn0[a] = first || f < umn0[a] ? f : umn0[a],
						umx0[a] = first || f > umx0[a] ? f : umx0[a];
				}
		}
		for (int a = 0; a < 2; a++) {
			float s0 = mlod_pack_range_scale_bits(umn0[a], umx0[a], x->opt->uv_bits);
			float s16 = mlod_pack_range_scale_bits(umn[a], umx[a], 16);
			m->rec.uv_min[s][a] = umn[a];
			m->rec.uv_scale[s][a] = s0 > s16 ? s0 : s16;
		}
	}
	for (int t = 0; t < m->ntargets; t++) {
		float mt = 0.0f;
		for (int k = 0; k < M; k++) {
			const float *d = m->lv[k]->targets[t].positions;
			for (int i = 0; d && i < 3 * m->lv[k]->vertex_count; i++)
				mt = fabsf(d[i]) > mt ? fabsf(d[i]) : mt;
		}
		m->tscale[t] = mt > 0.0f ? (float)(mt / (ldexp(1.0, x->opt->position_bits - 1) - 1.0)) : 0.0f;
	}
	(void)p0;
}

/* Level k's vertices quantised on the part's grid into V (interleaved). */
static void part_quantise(struct ctx *x, const struct mpart *m, int k, uint8_t *V)
{
	const mlod_primitive *p = m->lv[k];
	const mlod_pack_part_rec *rec = &m->rec;
	int nv = p->vertex_count;
	memset(V, 0, (size_t)nv * (size_t)m->stride);
	for (int v = 0; v < nv; v++) {
		uint8_t *o = V + (size_t)v * (size_t)m->stride;
		int a = 0;
		uint16_t q[4] = {0, 0, 0, 0};
		int f = m->fin[k] ? m->fin[k][v] : 0; /* the vertex's finest level: its steps */
		for (int c = 0; c < 3; c++)
			q[c] = f ? mlod_pack_qu16_shift(p->positions[3 * v + c], rec->pos_min[c], rec->pos_scale[c],
			                                m->pos_shift[f])
			         : mlod_pack_qu16(p->positions[3 * v + c], rec->pos_min[c], rec->pos_scale[c]);
		memcpy(o + m->attr[a++].off, q, 8);
		if (p->normals) {
			int16_t s[2];
			mlod_pack_oct_encode_bits(p->normals + 3 * v, x->opt->normal_bits, s);
			memcpy(o + m->attr[a++].off, s, 4);
		}
		if (p->tangents) {
			int16_t s[4] = {0, 0, 0, 0};
			mlod_pack_oct_encode_bits(p->tangents + 4 * v, x->opt->normal_bits, s);
			s[2] = p->tangents[4 * v + 3] < 0.0f ? -32767 : 32767;
			memcpy(o + m->attr[a++].off, s, 8);
		}
		for (uint32_t s = 0; s < rec->uv_sets; s++) {
			uint16_t u[2];
			for (int c = 0; c < 2; c++)
				u[c] = f ? mlod_pack_qu16_shift(p->uvs[s][2 * v + c], rec->uv_min[s][c], rec->uv_scale[s][c],
				                                m->uv_shift[f][s])
				         : mlod_pack_qu16(p->uvs[s][2 * v + c], rec->uv_min[s][c], rec->uv_scale[s][c]);
			memcpy(o + m->attr[a++].off, u, 4);
		}
		if (p->color_set_count > 0) {
			uint8_t *u8 = o + m->attr[a++].off;
			for (int c = 0; c < 4; c++) {
				float f = p->colors[0][4 * v + c];
				f = f > 0.0f ? (f < 1.0f ? f : 1.0f) : 0.0f;
				u8[c] = (uint8_t)lrintf(f * 255.0f);
			}
		}
		if (m->skinned) {
			int joints = x->v.skeleton.skins[rec->skin].joint_count;
			int bj[4];
			float bw[4];
			mlod_pack_top4(p, (uint32_t)v, m->jmap[k], m->jmap_count[k], bj, bw);
			uint8_t w8[4], j8[4];
			uint16_t j16[4];
			mlod_pack_weights8(bw, w8);
			if (w8[0] + w8[1] + w8[2] + w8[3] == 0) { /* no weight: the skin's root (note_unweighted) */
				w8[0] = 255;
				bj[0] = skin_root(&x->v.skeleton, rec->skin);
			}
			for (int t = 0; t < 4; t++) {
				int jt = w8[t] ? bj[t] : 0;
				if (jt < 0 || jt >= joints)
					jt = 0;
				j16[t] = (uint16_t)jt, j8[t] = (uint8_t)jt;
			}
			if (m->wide)
				memcpy(o + m->attr[a++].off, j16, 8);
			else
				memcpy(o + m->attr[a++].off, j8, 4);
			memcpy(o + m->attr[a++].off, w8, 4);
		}
		for (int t = 0; t < m->ntargets; t++) {
			const float *d = p->targets[t].positions;
			int16_t s[4] = {0, 0, 0, 0};
			for (int c = 0; c < 3; c++) {
				float f = d && m->tscale[t] > 0.0f ? d[3 * v + c] / m->tscale[t] : 0.0f;
				f = f > 32767.0f ? 32767.0f : f < -32767.0f ? -32767.0f : f;
				s[c] = (int16_t)lrintf(f);
			}
			memcpy(o + m->attr[a++].off, s, 8);
		}
	}
}

static uint64_t vhash(const uint8_t *p, int n)
{
	uint64_t h = 1469598103934665603ull;
	for (int i = 0; i < n; i++)
		h = (h ^ p[i]) * 1099511628211ull;
	return h;
}

static double sigma_bound3(const mlod_mat4 *w);

static int dbl_asc(const void *a, const void *b)
{
	double p = *(const double *)a, q = *(const double *)b;
	return p < q ? -1 : p > q;
}

/* The part's skinning scale at the rest pose: the largest singular value
 * bound (sigma_bound3) of its skin's matrices (joint world times inverse
 * bind), or of its rigid matrix (joint world times offset, or offset). */
static double part_sigma(const struct ctx *x, const struct mpart *m)
{
	const mlod_pack_part_rec *rec = &m->rec;
	const mlod_character *c = &x->v;
	if (m->skinned) {
		const mlod_skin *sk = &c->skeleton.skins[rec->skin];
		double s = 0.0;
		for (int j = 0; j < sk->joint_count; j++) {
			mlod_mat4 J = mlod_mat4_mul(&x->world[sk->joints[j]], &sk->inverse_bind[j]);
			double g = sigma_bound3(&J);
			s = g > s ? g : s;
		}
		return s;
	}
	const mlod_instance *in = &c->instances[rec->instance];
	mlod_mat4 R = in->joint >= 0 ? mlod_mat4_mul(&x->world[in->joint], &in->offset) : in->offset;
	return sigma_bound3(&R);
}

/* The q-th quantile (0 to 1, the lower of two) of n values, sorted in
 * place; 0 when n is 0. */
static double quantile(double *v, size_t n, double q)
{
	if (n == 0)
		return 0.0;
	qsort(v, n, sizeof *v, dbl_asc);
	size_t i = (size_t)(q * (double)(n - 1));
	return v[i];
}

/* The texture's density in UV units per mesh unit: the
 * MLOD_PACK_COARSE_UV_QUANTILE quantile over the primitive's edges of UV
 * length over length (those with both above 0). */
static double coarse_density(const mlod_primitive *p, int set, double *work)
{
	uint32_t ni = p->index_count > 0 ? (uint32_t)p->index_count : (uint32_t)p->vertex_count;
	size_t n = 0;
	for (uint32_t t = 0; t + 3 <= ni; t += 3)
		for (int e = 0; e < 3; e++) {
			uint32_t a = p->index_count > 0 ? p->indices[t + e] : t + e;
			uint32_t b = p->index_count > 0 ? p->indices[t + (e + 1) % 3] : t + (e + 1) % 3;
			double d = 0.0, u = 0.0;
			for (int c = 0; c < 3; c++) {
				double w = (double)p->positions[3 * a + c] - p->positions[3 * b + c];
				d += w * w;
			}
			for (int c = 0; c < 2; c++) {
				double w = (double)p->uvs[set][2 * a + c] - p->uvs[set][2 * b + c];
				u += w * w;
			}
			if (d > 0.0 && u > 0.0)
				work[n++] = sqrt(u / d);
		}
	return quantile(work, n, MLOD_PACK_COARSE_UV_QUANTILE);
}

/* The largest shift (0 to 15) whose steps, scale * 2^shift per axis of
 * n, stay within bound as a half-step vector, with every code of the
 * range [0, qmax] still rounding within 0 .. 65535. */
static int coarse_shift(const float *scale, const uint32_t *qmax, int n, double bound)
{
	int best = 0;
	for (int sh = 1; sh <= 15; sh++) {
		double h = 0.0;
		int fits = 1;
		for (int a = 0; a < n; a++) {
			double st = ldexp((double)scale[a], sh);
			h += st * st;
			fits &= qmax[a] + ldexp(1.0, sh - 1) + 1.0 <= 65535.0;
		}
		if (!fits || !(sqrt(h) / 2.0 <= bound))
			break;
		best = sh;
	}
	return best;
}

/* Per vertex of every level, the finest level that has it on level 0's
 * steps (the same quantised attributes), and per level f >= 1 the
 * position and UV shifts of the vertices whose finest level is f: within
 * the writer's share of the smallest TOC error of the levels f and
 * coarser, as mlod(5) QUANTISATION states. Nothing (every vertex on level
 * 0's steps) with a share of 0 or one level. 0, or -1
 * out of memory. */
static int part_coarse(struct ctx *x, struct mpart *m, int M)
{
	double share = x->opt->coarse_share;
	if (!(share > 0.0) || M < 2)
		return 0;
	size_t total = 0, most = 0;
	for (int k = 0; k < M; k++) {
		size_t nv = (size_t)m->lv[k]->vertex_count, ni = m->lv[k]->index_count > 0 ? (size_t)m->lv[k]->index_count : nv;
		total += nv;
		most = 3 * ni > most ? 3 * ni : most;
	}
	size_t cap = 16;
	while (cap < 2 * total + 2)
		cap *= 2;
	uint8_t *K = malloc(total * (size_t)m->stride + 1);
	uint32_t *slot = calloc(cap, sizeof *slot);
	uint8_t *lev = malloc(total + 1);
	double *work = malloc(sizeof *work * (most + 1));
	int ok = K && slot && lev && work;
	uint32_t count = 0;
	/* Level 0's steps: the finest level of each distinct key. */
	for (int k = 0; ok && k < M; k++) {
		const mlod_primitive *p = m->lv[k];
		uint8_t *V = malloc((size_t)p->vertex_count * (size_t)m->stride + 1);
		uint8_t *fk = malloc((size_t)p->vertex_count + 1);
		if (!V || !fk) {
			free(V), free(fk);
			ok = 0;
			break;
		}
		part_quantise(x, m, k, V); /* level 0's steps: fin[k] is still NULL */
		m->fin[k] = fk;
		for (int v = 0; v < p->vertex_count; v++) {
			const uint8_t *key = V + (size_t)v * (size_t)m->stride;
			size_t i = vhash(key, m->stride) & (cap - 1);
			while (slot[i] && memcmp(K + (size_t)(slot[i] - 1) * (size_t)m->stride, key, (size_t)m->stride) != 0)
				i = (i + 1) & (cap - 1);
			if (!slot[i]) {
				memcpy(K + (size_t)count * (size_t)m->stride, key, (size_t)m->stride);
				lev[count] = (uint8_t)k;
				slot[i] = ++count;
			}
			m->fin[k][v] = lev[slot[i] - 1];
		}
		free(V);
	}
	/* Each level's bounds (mesh units, UV units), then the
	 * smallest of them over it and the coarser levels. */
	double sigma = ok ? part_sigma(x, m) : 0.0;
	double bpos[MLOD_MESH_MAX_LEVELS + 1], buv[MLOD_MESH_MAX_LEVELS + 1][MLOD_PACK_MAX_UV];
	double rho[MLOD_PACK_MAX_UV] = {0};
	for (uint32_t s = 0; ok && s < m->rec.uv_sets; s++)
		rho[s] = coarse_density(m->lv[0], (int)s, work);
	for (int k = M - 1; ok && k >= 1; k--) {
		double e = share * (double)x->mesh_error[k - 1];
		if (!(e > 0.0) || !(sigma > 0.0) || !isfinite(e / sigma))
			e = 0.0;
		bpos[k] = sigma > 0.0 ? e / sigma : 0.0;
		for (uint32_t s = 0; s < m->rec.uv_sets; s++)
			buv[k][s] = e * rho[s] / (sigma > 0.0 ? sigma : 1.0);
		if (k < M - 1) {
			bpos[k] = fmin(bpos[k], bpos[k + 1]);
			for (uint32_t s = 0; s < m->rec.uv_sets; s++)
				buv[k][s] = fmin(buv[k][s], buv[k + 1][s]);
		}
	}
	for (int k = 1; ok && k < M; k++) {
		uint32_t qmax[3];
		for (int a = 0; a < 3; a++) {
			float hi = m->rec.pos_min[a];
			for (int j = 0; j < M; j++)
				for (int v = 0; v < m->lv[j]->vertex_count; v++)
					hi = fmaxf(hi, m->lv[j]->positions[3 * v + a]);
			qmax[a] = mlod_pack_qu16(hi, m->rec.pos_min[a], m->rec.pos_scale[a]);
		}
		m->pos_shift[k] = coarse_shift(m->rec.pos_scale, qmax, 3, bpos[k]);
		for (uint32_t s = 0; s < m->rec.uv_sets; s++) {
			uint32_t umax[2];
			for (int a = 0; a < 2; a++) {
				float hi = m->rec.uv_min[s][a];
				for (int j = 0; j < M; j++)
					for (int v = 0; v < m->lv[j]->vertex_count; v++)
						hi = fmaxf(hi, m->lv[j]->uvs[s][2 * v + a]);
				umax[a] = mlod_pack_qu16(hi, m->rec.uv_min[s][a], m->rec.uv_scale[s][a]);
			}
			m->uv_shift[k][s] = coarse_shift(m->rec.uv_scale[s], umax, 2, buv[k][s]);
		}
	}
	free(K), free(slot), free(lev), free(work);
	return ok ? 0 : -1;
}

/* The id of vertex key in the part's buffer, appending it when new. */
static uint32_t part_vertex(struct mpart *m, const uint8_t *key)
{
	size_t i = vhash(key, m->stride) & (m->slot_cap - 1);
	while (m->slot[i]) {
		uint32_t id = m->slot[i] - 1;
		if (memcmp(m->G + (size_t)id * (size_t)m->stride, key, (size_t)m->stride) == 0)
			return id;
		i = (i + 1) & (m->slot_cap - 1);
	}
	memcpy(m->G + (size_t)m->count * (size_t)m->stride, key, (size_t)m->stride);
	m->slot[i] = ++m->count;
	return m->count - 1;
}

/* Appends level V's vertices not yet in the buffer that its triangles in
 * use, in order o of the triangles (mlod_pack_vertex_order); the level's
 * indices into the buffer, or NULL when out of memory. With cls (each vertex of V: its
 * buffer id as the hash set gave it, or for a vertex the buffer lacked,
 * count + the first of its bit-identical copies in V), the same without
 * the hash set, which it leaves as it was (for trying orders). */
static uint32_t *part_append(struct mpart *m, const uint8_t *V, const uint32_t *in, uint32_t ni, uint32_t nv,
                             const float *positions, int o, mlod_pack_order_memo *memo, const uint32_t *cls)
{
	uint32_t *remap = malloc(sizeof *remap * ((size_t)nv + 1));
	uint32_t *inv = malloc(sizeof *inv * ((size_t)nv + 1));
	uint32_t *out = malloc(sizeof *out * ((size_t)ni + 1));
	uint32_t *gid = malloc(sizeof *gid * ((size_t)nv + 1));
	uint32_t *idx = malloc(sizeof *idx * ((size_t)ni + 1));
	uint8_t *used = calloc((size_t)nv + 1, 1);
	if (!remap || !inv || !out || !gid || !idx || !used ||
	    mlod_pack_vertex_order_memo(o, in, ni, nv, positions, memo, remap, out) != 0) {
		free(remap), free(inv), free(out), free(gid), free(idx), free(used);
		return NULL;
	}
	for (uint32_t v = 0; v < nv; v++)
		inv[remap[v]] = v;
	for (uint32_t t = 0; t < ni; t++) /* a vertex only dropped triangles used: not stored */
		used[in[t]] = 1;
	if (cls) { /* remap becomes each new class's id: UINT32_MAX until placed */
		uint32_t count0 = m->count;
		for (uint32_t v = 0; v < nv; v++)
			remap[v] = UINT32_MAX;
		for (uint32_t j = 0; j < nv; j++) {
			uint32_t c = cls[inv[j]];
			if (!used[inv[j]])
				continue;
			if (c < count0) {
				gid[j] = c;
				continue;
			}
			if (remap[c - count0] == UINT32_MAX) {
				memcpy(m->G + (size_t)m->count * (size_t)m->stride, V + (size_t)inv[j] * (size_t)m->stride,
				       (size_t)m->stride);
				remap[c - count0] = m->count++;
			}
			gid[j] = remap[c - count0];
		}
	} else {
		for (uint32_t j = 0; j < nv; j++)
			if (used[inv[j]])
				gid[j] = part_vertex(m, V + (size_t)inv[j] * (size_t)m->stride);
	}
	for (uint32_t t = 0; t < ni; t++)
		idx[t] = gid[out[t]];
	free(remap), free(inv), free(out), free(gid), free(used);
	return idx;
}

/* The level's own numbering of its indices idx (ni of them, into a prefix
 * of count vertices): its vertices in first-use order into map (the prefix
 * vertex of each; *nused of them) and the renumbered indices into local.
 * seen is count zeroed u32s, left zeroed. */
static void local_form(const uint32_t *idx, uint32_t ni, uint32_t *seen, uint32_t *map, uint32_t *nused,
                       uint32_t *local)
{
	uint32_t n = 0;
	for (uint32_t t = 0; t < ni; t++) {
		if (!seen[idx[t]])
			map[n] = idx[t], seen[idx[t]] = ++n;
		local[t] = seen[idx[t]] - 1;
	}
	for (uint32_t v = 0; v < n; v++)
		seen[map[v]] = 0;
	*nused = n;
}

/* The level's own numbering in the stored form (MLOD_PART_LOCAL): from
 * local_form's map (nused vertices), the words of 'INEW' (bit v set:
 * vertex v is the next of the level's block, which starts at count0) and
 * the prefix vertices of the others ('IMAP', *nold of them). Without
 * split, or when the block's vertices are not in the order the level
 * first uses them, no bit is set and 'IMAP' lists every vertex; returns
 * whether bits were set. */
static int local_split(const uint32_t *map, uint32_t nused, uint32_t count0, int split, uint32_t *words, uint32_t *old,
                       uint32_t *nold)
{
	uint32_t nn = 0, no = 0;
	memset(words, 0, sizeof *words * (((size_t)nused + 31) / 32));
	if (!split)
		count0 = UINT32_MAX;
	for (uint32_t v = 0; v < nused; v++) {
		if (map[v] < count0) {
			old[no++] = map[v];
			continue;
		}
		if (map[v] != count0 + nn) { /* out of order: list them all */
			memset(words, 0, sizeof *words * (((size_t)nused + 31) / 32));
			memcpy(old, map, sizeof *old * nused);
			*nold = nused;
			return 0;
		}
		nn++;
		words[v / 32] |= 1u << (v % 32);
	}
	*nold = no;
	return split;
}

/* Adds an index stream of n u32s as u16 when wide is 0. */
static void add_index_stream(chunkb *cb, uint32_t tag, const uint32_t *v, uint32_t n, int wide, int index)
{
	if (wide) {
		cb_add(cb, tag, n, 4, v, index);
		return;
	}
	uint16_t *i16 = malloc(sizeof *i16 * ((size_t)n + 1));
	if (!i16) {
		cb->fail = 1;
		return;
	}
	for (uint32_t i = 0; i < n; i++)
		i16[i] = (uint16_t)v[i];
	cb_add(cb, tag, n, 2, i16, index);
	free(i16);
}

/* Adds the streams of the part's block (vertices first .. count - 1 of
 * the buffer) and of its level's indices, in the chunk's stream order:
 * with local, 'INEW' (nwords words; none when words is NULL), 'IMAP'
 * (old, nold of them) and 'IDX ' in the level's own numbering (idx then
 * holds those). */
static void part_block_streams(chunkb *cb, const struct mpart *m, uint32_t first, const uint32_t *idx, uint32_t ni,
                               int local, const uint32_t *words, uint32_t nwords, const uint32_t *old, uint32_t nold)
{
	uint32_t n = m->count - first;
	uint8_t *s = malloc((size_t)n * 8 + 8);
	if (!s) {
		cb->fail = 1;
		return;
	}
	int plain = m->nattr - m->ntargets, wide = m->count > 65536;
	for (int a = 0; a <= m->nattr; a++) {
		if (a == plain) { /* the indices, then the targets' scales */
			if (local) {
				if (words)
					cb_add(cb, MLOD_STREAM_INEW, nwords, 4, words, 0);
				add_index_stream(cb, MLOD_STREAM_IMAP, old, nold, wide, 2);
			}
			add_index_stream(cb, MLOD_STREAM_IDX, idx, ni, wide, 1);
			if (m->ntargets)
				cb_add(cb, MLOD_STREAM_MTSC, (uint32_t)m->ntargets, 4, m->tscale, 0);
		}
		if (a == m->nattr)
			break;
		const mattr *at = &m->attr[a];
		for (uint32_t v = 0; v < n; v++)
			memcpy(s + (size_t)v * at->size, m->G + (size_t)(first + v) * (size_t)m->stride + at->off, at->size);
		cb_add(cb, at->tag, n, at->size, s, 0);
	}
	free(s);
}

static void mesh_parts_free(struct ctx *x)
{
	for (int i = 0; i < x->mp_count; i++) {
		struct mpart *m = &x->mp[i];
		free(m->tscale), free(m->attr), free(m->G), free(m->slot);
		for (int k = 0; k <= MLOD_MESH_MAX_LEVELS; k++)
			free(m->fin[k]);
	}
	free(x->mp);
	x->mp = NULL;
	x->mp_count = 0;
	for (int i = 0; i < x->lmap_count; i++)
		free(x->lmaps[i]);
	free(x->lmaps);
	x->lmaps = NULL;
	x->lmap_count = 0;
}

/* Maps the joints of a level skin (input skin `lsk`) to the full skin
 * `fsk`: the same joint, else the first joint of the full skin that the
 * level joint stands in for (its nearest ancestor in the level skin). */
static int *level_joint_map(const mlod_skeleton *s, const mlod_skin *lsk, const mlod_skin *fsk)
{
	int *map = malloc(sizeof(int) * ((size_t)lsk->joint_count + 1));
	if (!map)
		return NULL;
	for (int q = 0; q < lsk->joint_count; q++) {
		int j = lsk->joints[q], at = -1;
		for (int t = 0; t < fsk->joint_count && at < 0; t++)
			if (fsk->joints[t] == j)
				at = t;
		for (int t = 0; t < fsk->joint_count && at < 0; t++) {
			int a = fsk->joints[t];
			int in_level = 0;
			for (int u = 0; u < lsk->joint_count; u++)
				in_level |= lsk->joints[u] == a;
			if (in_level)
				continue;
			while (a >= 0 && a != j) {
				int p = s->joints[a].parent, in = 0;
				for (int u = 0; p >= 0 && u < lsk->joint_count; u++)
					in |= lsk->joints[u] == p;
				a = p;
				if (in && p != j)
					a = -1; /* a nearer level joint stands in for it */
			}
			if (a == j)
				at = t;
		}
		map[q] = at >= 0 ? at : 0;
	}
	return map;
}

/* The parts (level 0's triangle primitives of every instance) with their
 * level primitives, attributes, grids and buffers. Every level of a part
 * must have triangles and the attributes level 0 has. */
static mlod_result mesh_parts(struct ctx *x, int M)
{
	const mlod_character *c = &x->v;
	mlod_result r = MLOD_OK;
	int cap = 0;
	x->lmap_count = c->instance_count * M;
	x->lmaps = calloc((size_t)x->lmap_count + 1, sizeof *x->lmaps);
	if (!x->lmaps)
		return mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
	for (int i = 0; i < c->instance_count; i++) {
		const mlod_instance *in = &c->instances[i];
		const mlod_mesh *m = &c->meshes[in->mesh];
		const mlod_mesh *lm[MLOD_MESH_MAX_LEVELS + 1];
		int lmap_count[MLOD_MESH_MAX_LEVELS + 1] = {0};
		for (int k = 0; k < M; k++) {
			lm[k] = m;
			if (k > 0 && x->level_mesh[k - 1]) {
				lm[k] = &x->level_mesh[k - 1][i];
			} else if (k > 0 && x->level_node[k - 1] && x->level_node[k - 1][i] >= 0) {
				int gm = -1, gs = -1;
				if ((r = mlod_gltf_node_refs(x->doc, x->level_node[k - 1][i], &gm, &gs, x->err)) != MLOD_OK)
					return r;
				int mi = mesh_of_gltf(x->in, gm);
				if (mi < 0)
					return mlod_fail(x->err, MLOD_ERR_PARSE, "mesh level %d of node %d: its mesh %d was not read", k,
					                 in->node, gm);
				lm[k] = &x->in->meshes[mi];
				int ls = skin_of_gltf(&x->in->skeleton, gs);
				if (in->skin >= 0 && ls >= 0 && x->view_skin[ls] != in->skin) {
					int **mp = &x->lmaps[k * c->instance_count + i];
					*mp = level_joint_map(&c->skeleton, &x->in->skeleton.skins[ls], &c->skeleton.skins[in->skin]);
					if (!*mp)
						return mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
					lmap_count[k] = x->in->skeleton.skins[ls].joint_count;
				}
			}
		}
		for (int p = 0; p < m->primitive_count; p++) {
			const mlod_primitive *p0 = &m->primitives[p];
			if (p0->mode != 4 || p0->vertex_count <= 0)
				continue;
			if (x->mp_count == cap) {
				cap = cap ? 2 * cap : 16;
				struct mpart *q = realloc(x->mp, sizeof *q * (size_t)cap);
				if (!q)
					return mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
				x->mp = q;
			}
			struct mpart *pt = &x->mp[x->mp_count++];
			memset(pt, 0, sizeof *pt);
			size_t total = 0;
			for (int k = 0; k < M; k++) {
				const mlod_primitive *pr = p < lm[k]->primitive_count ? &lm[k]->primitives[p] : NULL;
				if (!pr || pr->mode != 4 || pr->vertex_count <= 0)
					return mlod_fail(x->err, MLOD_ERR_UNSUPPORTED,
					                 "mesh level %d of node %d: primitive %d has no triangles (every level of a "
					                 "part needs some)",
					                 k, in->node, p);
				if (prim_signature(pr, in->skin) != prim_signature(p0, in->skin))
					return mlod_fail(x->err, MLOD_ERR_UNSUPPORTED,
					                 "mesh level %d of node %d: primitive %d has other attributes than level 0 "
					                 "(normals, tangents, UV sets, colours, weights or morph targets); the "
					                 "pack stores a part's levels with one set",
					                 k, in->node, p);
				pt->lv[k] = pr;
				pt->jmap[k] = x->lmaps[k * c->instance_count + i];
				pt->jmap_count[k] = lmap_count[k];
				total += (size_t)pr->vertex_count;
			}
			mlod_pack_part_rec *rec = &pt->rec;
			rec->instance = (uint32_t)i;
			rec->node = in->node;
			rec->mesh = m->gltf_index;
			rec->primitive = (uint32_t)p;
			rec->skin = in->skin;
			rec->joint = in->joint;
			rec->material = p0->material;
			memcpy(rec->offset, in->offset.m, sizeof rec->offset);
			rec->uv_sets = (uint32_t)(p0->uv_set_count < MLOD_PACK_MAX_UV ? p0->uv_set_count : MLOD_PACK_MAX_UV);
			rec->target_count = (uint32_t)p0->target_count;
			pt->skinned = in->skin >= 0 && p0->weight_set_count > 0;
			pt->wide = pt->skinned && c->skeleton.skins[in->skin].joint_count > 256;
			pt->ntargets = p0->target_count;
			rec->flags = (p0->normals ? MLOD_PART_NORMALS : 0) | (p0->tangents ? MLOD_PART_TANGENTS : 0) |
			             (p0->color_set_count > 0 ? MLOD_PART_COLORS : 0) | (pt->skinned ? MLOD_PART_SKINNED : 0) |
			             (pt->wide ? MLOD_PART_JOINTS16 : 0);
			pt->attr = malloc(sizeof *pt->attr * (size_t)(8 + MLOD_PACK_MAX_UV + pt->ntargets));
			pt->tscale = malloc(sizeof(float) * ((size_t)pt->ntargets + 1));
			if (!pt->attr || !pt->tscale)
				return mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
#define ATTR(t, s) (pt->attr[pt->nattr++] = (mattr){(t), (s), pt->stride}, pt->stride += (s))
			ATTR(MLOD_STREAM_POSQ, 8);
			if (p0->normals)
				ATTR(MLOD_STREAM_NRMQ, 4);
			if (p0->tangents)
				ATTR(MLOD_STREAM_TANQ, 8);
			for (uint32_t s = 0; s < rec->uv_sets; s++)
				ATTR(MLOD_STREAM_UVQ0 + (s << 24), 4);
			if (p0->color_set_count > 0)
				ATTR(MLOD_STREAM_COLQ, 4);
			if (pt->skinned) {
				if (pt->wide)
					ATTR(MLOD_STREAM_JN16, 8);
				else
					ATTR(MLOD_STREAM_JNT8, 4);
				ATTR(MLOD_STREAM_WGT8, 4);
			}
			for (int t = 0; t < pt->ntargets; t++)
				ATTR(MLOD_STREAM_MTPQ, 8);
#undef ATTR
			part_grid(x, pt, M);
			if (part_coarse(x, pt, M) != 0)
				return mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
			pt->slot_cap = 16;
			while (pt->slot_cap < 2 * total + 2)
				pt->slot_cap *= 2;
			pt->G = malloc(total * (size_t)pt->stride + 1);
			pt->slot = calloc(pt->slot_cap, sizeof *pt->slot);
			if (!pt->G || !pt->slot)
				return mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
		}
	}
	return MLOD_OK;
}

/* A level's index forms (mlod(5) MESH levels): its indices as they are,
 * or in its own numbering (MLOD_PART_LOCAL); the working arrays as
 * local_form and local_split take them. */
typedef struct iforms {
	uint32_t *seen, *map, *lidx, *words, *old;
	uint32_t nused, nold;
	int split; /* the local form has 'INEW' */
} iforms;

/* The coded bytes of a level's indices idx (into a prefix of count
 * vertices, the level's block from count0) in the smaller of the forms,
 * with 16 for each stream beyond 'IDX ' (*stored: without them); *local
 * 1 when that is the level's own numbering (f then holds it). */
static size_t index_bytes(const uint32_t *idx, uint32_t ni, uint32_t count0, uint32_t count, iforms *f, int *local,
                          size_t *stored)
{
	int wide = count > 65536;
	chunkb t = {0};
	add_index_stream(&t, MLOD_STREAM_IDX, idx, ni, wide, 1);
	size_t g = t.fail ? 0 : stream_coded_bytes(&t.s[0]), best[2] = {g, g};
	local_form(idx, ni, f->seen, f->map, &f->nused, f->lidx);
	add_index_stream(&t, MLOD_STREAM_IDX, f->lidx, ni, wide, 1);
	size_t li = t.fail ? 0 : stream_coded_bytes(&t.s[1]);
	for (int split = 1; split >= 0 && !t.fail; split--) { /* with the bits, then without */
		if (!local_split(f->map, f->nused, count0, split, f->words, f->old, &f->nold) && split)
			continue;
		if (split)
			cb_add(&t, MLOD_STREAM_INEW, (f->nused + 31) / 32, 4, f->words, 0);
		add_index_stream(&t, MLOD_STREAM_IMAP, f->old, f->nold, wide, 2);
		/* the streams beyond 'IDX ': their 16-byte headers count */
		best[split] = t.fail ? g : 16 * (size_t)(1 + split) + li + stream_coded_bytes(&t.s[t.n - 1]) +
		                                   (split ? stream_coded_bytes(&t.s[t.n - 2]) : 0);
	}
	cb_free(&t);
	int split = best[1] < best[0];
	size_t l = best[split];
	*local = l < g;
	f->split = *local && split;
	if (*local) /* f holds the form chosen */
		local_split(f->map, f->nused, count0, split, f->words, f->old, &f->nold);
	*stored = *local ? l - 16 * (size_t)(1 + split) : g;
	return l < g ? l : g;
}

size_t mlod_pack_index_cost(const uint32_t *idx, uint32_t ni, uint32_t count0, uint32_t count, size_t *stored)
{
	iforms f = {0};
	size_t cost = 0;
	int local;
	*stored = 0;
	f.seen = calloc((size_t)count + 1, sizeof *f.seen);
	f.map = malloc(sizeof *f.map * ((size_t)ni + 1));
	f.lidx = malloc(sizeof *f.lidx * ((size_t)ni + 1));
	f.words = malloc(sizeof *f.words * ((size_t)ni / 32 + 2));
	f.old = malloc(sizeof *f.old * ((size_t)ni + 1));
	if (f.seen && f.map && f.lidx && f.words && f.old)
		cost = index_bytes(idx, ni, count0, count, &f, &local, stored);
	free(f.seen), free(f.map), free(f.lidx), free(f.words), free(f.old);
	return cost;
}

/* Codec draco (mlod(5)): level k of a part as one Draco mesh of its own
 * (layout a: the nused vertices map[] of the part's buffer, in that
 * numbering, and the triangles lidx), every attribute the stream's
 * quantised integers (lossless), coded by edgebreaker; the sequential
 * coder where edgebreaker does not give back exactly nused vertices and
 * ni / 3 triangles (it splits non-manifold vertices and drops degenerate
 * triangles), which the reader requires. Adds 'DRCO', then 'MTSC' with
 * morph targets. 0 on failure (x->draco_fail and the message set, or out
 * of memory: cb->fail). */
static int draco_level(struct ctx *x, chunkb *cb, const struct mpart *m, const uint32_t *map, uint32_t nused,
                       const uint32_t *lidx, uint32_t ni)
{
	mlod_draco_attr at[8 + MLOD_PACK_MAX_UV + 256];
	int na = m->nattr, ok = 0;
	if (nused == 0 && ni == 0 && m->ntargets <= 256) { /* no triangle left: an empty 'DRCO' */
		cb_add(cb, MLOD_STREAM_DRCO, 0, 1, NULL, 0);
		if (m->ntargets)
			cb_add(cb, MLOD_STREAM_MTSC, (uint32_t)m->ntargets, 4, m->tscale, 0);
		return !cb->fail;
	}
	if (nused == 0 || ni == 0 || na > (int)(sizeof at / sizeof at[0])) {
		x->draco_fail = mlod_fail(x->err, MLOD_ERR_UNSUPPORTED,
		                          "codec draco: a part of %u vertices, %u indices and %d attributes (Draco parts "
		                          "need triangles and at most 256 morph targets)",
		                          nused, ni, m->ntargets);
		return 0;
	}
	memset(at, 0, sizeof at);
	for (int a = 0; a < na; a++) {
		const mattr *ma = &m->attr[a];
		int bytes = 2, comps;
		if (ma->size == 8)
			comps = ma->tag == MLOD_STREAM_POSQ || ma->tag == MLOD_STREAM_MTPQ ? 3 : 4;
		else if (ma->tag == MLOD_STREAM_COLQ || ma->tag == MLOD_STREAM_JNT8 || ma->tag == MLOD_STREAM_WGT8)
			bytes = 1, comps = 4;
		else
			comps = 2;
		at[a].kind = ma->tag == MLOD_STREAM_POSQ ? MLOD_DRACO_POSITION : MLOD_DRACO_GENERIC;
		at[a].type = bytes == 1 ? MLOD_DRACO_U8 : MLOD_DRACO_U16;
		at[a].components = comps;
		uint8_t *d = malloc((size_t)nused * (size_t)(comps * bytes) + 1);
		if (!d)
			goto done;
		for (uint32_t v = 0; v < nused; v++)
			memcpy(d + (size_t)v * (size_t)(comps * bytes), m->G + (size_t)map[v] * (size_t)m->stride + ma->off,
			       (size_t)(comps * bytes));
		at[a].data = d;
	}
	for (int sequential = 0; sequential < 2 && !ok; sequential++) {
		void *enc = NULL;
		size_t size = 0;
		mlod_error e2;
		mlod_result r = mlod_draco_encode((int)nused, at, na, lidx, (int)ni, sequential, MLOD_PACK_DRACO_SPEED, &enc,
		                                  &size, &e2);
		if (r == MLOD_ERR_NOMEM)
			goto done;
		if (r != MLOD_OK)
			continue;
		/* What the reader checks: exactly these counts back. */
		mlod_draco_attr back[8 + MLOD_PACK_MAX_UV + 256];
		memcpy(back, at, sizeof(mlod_draco_attr) * (size_t)na);
		int bv = 0, bi = 0;
		uint32_t *bix = NULL;
		r = mlod_draco_decode(enc, size, back, na, &bv, &bix, &bi, &e2);
		if (r == MLOD_OK) {
			for (int a = 0; a < na; a++)
				mlod_free(back[a].data);
			mlod_free(bix);
		}
		if (r == MLOD_OK && bv == (int)nused && bi == (int)ni) {
			cb_add(cb, MLOD_STREAM_DRCO, (uint32_t)size, 1, enc, 0);
			if (m->ntargets)
				cb_add(cb, MLOD_STREAM_MTSC, (uint32_t)m->ntargets, 4, m->tscale, 0);
			ok = 1;
		}
		mlod_free(enc);
		if (r == MLOD_ERR_NOMEM)
			goto done;
	}
	if (!ok)
		x->draco_fail = mlod_fail(x->err, MLOD_ERR_UNSUPPORTED,
		                          "codec draco: a part of %u vertices and %u triangles does not come back from Draco "
		                          "with those counts, by edgebreaker or the sequential coder",
		                          nused, ni / 3);
done:
	for (int a = 0; a < na; a++)
		free(at[a].data);
	if (!ok && !x->draco_fail)
		cb->fail = 1;
	return ok;
}

/* Level k of one part: appends its new vertices (in the order of the
 * writer's that codes the block and the indices to the fewest bytes; the
 * input order with codec none) and adds their streams, with the indices
 * in the level's own numbering when that codes smaller (MLOD_PART_LOCAL);
 * rec is the part's record at this level. */
static int part_level(struct ctx *x, chunkb *cb, struct mpart *m, int k, mlod_pack_part_rec *rec)
{
	const mlod_primitive *p = m->lv[k];
	uint32_t nv = (uint32_t)p->vertex_count;
	uint32_t ni = p->index_count > 0 ? (uint32_t)p->index_count : nv;
	ni -= ni % 3;
	uint8_t *V = malloc((size_t)nv * (size_t)m->stride + 1);
	uint32_t *in = malloc(sizeof *in * ((size_t)ni + 1));
	uint32_t *saved = malloc(sizeof *saved * m->slot_cap);
	iforms f = {0};
	mlod_pack_order_memo memo = {{NULL, NULL, NULL}}; /* the triangle orders the vertex orders share */
	f.seen = calloc((size_t)m->count + nv + 1, sizeof *f.seen);
	f.map = malloc(sizeof *f.map * ((size_t)ni + 1));
	f.lidx = malloc(sizeof *f.lidx * ((size_t)ni + 1));
	f.words = malloc(sizeof *f.words * ((size_t)ni / 32 + 2));
	f.old = malloc(sizeof *f.old * ((size_t)ni + 1));
	uint32_t *idx = NULL, *cls = NULL;
	int ok = 0, local = 0;
	if (!V || !in || !saved || !f.seen || !f.map || !f.lidx || !f.words || !f.old)
		goto done;
	part_quantise(x, m, k, V);
	uint32_t count0 = m->count;
	int best = 0;
	/* Each vertex's class once (part_append's cls), the hash set then as
	 * it was: the orders tried need no hashing. */
	memcpy(saved, m->slot, sizeof *saved * m->slot_cap);
	if (!(cls = malloc(sizeof *cls * ((size_t)nv + 1))))
		goto done;
	for (uint32_t v = 0; v < nv; v++)
		cls[v] = part_vertex(m, V + (size_t)v * (size_t)m->stride);
	memcpy(m->slot, saved, sizeof *saved * m->slot_cap);
	m->count = count0;
	/* The triangles quantisation leaves: one whose corners are two or
	 * three times one vertex of the buffer (bit-identical quantised
	 * attributes) is dropped; a part may keep none at a level. */
	uint32_t kept = 0;
	for (uint32_t t = 0; t + 3 <= ni; t += 3) {
		uint32_t a = p->index_count > 0 ? p->indices[t] : t, b = p->index_count > 0 ? p->indices[t + 1] : t + 1,
		         c = p->index_count > 0 ? p->indices[t + 2] : t + 2;
		if (cls[a] == cls[b] || cls[b] == cls[c] || cls[a] == cls[c])
			continue;
		in[kept++] = a, in[kept++] = b, in[kept++] = c;
	}
	x->degenerate[k] += (ni - kept) / 3;
	x->emptied[k] += ni > 0 && kept == 0;
	ni = kept;
	if (x->opt->codec == MLOD_CODEC_MESHOPT && !x->draco) {
		size_t best_bytes = 0;
		for (int o = 0; o < MLOD_PACK_ORDERS; o++) {
			uint32_t *ix = part_append(m, V, in, ni, nv, p->positions, o, &memo, cls);
			if (!ix)
				goto done;
			int from = cb->n, loc;
			size_t st;
			part_block_streams(cb, m, count0, ix, 0, 0, NULL, 0, NULL, 0); /* the vertex streams (no indices) */
			size_t b = cb->fail ? 0 : cb_coded_bytes(cb, from) + index_bytes(ix, ni, count0, m->count, &f, &loc, &st);
			while (cb->n > from)
				free(cb->s[--cb->n].data);
			free(ix);
			if (o == 0 || b < best_bytes)
				best = o, best_bytes = b;
			m->count = count0;
		}
	}
	if (!(idx = part_append(m, V, in, ni, nv, p->positions, best, &memo, NULL)))
		goto done;
	/* The vertices the level uses: what a reader gathers from the prefix. */
	size_t st;
	if (x->draco) {
		local_form(idx, ni, f.seen, f.map, &f.nused, f.lidx);
		if (!draco_level(x, cb, m, f.map, f.nused, f.lidx, ni))
			goto done;
		*rec = m->rec;
		rec->vertex_count = f.nused;
		rec->index_count = ni;
		ok = 1;
		goto done;
	}
	if (x->opt->codec == MLOD_CODEC_MESHOPT)
		index_bytes(idx, ni, count0, m->count, &f, &local, &st);
	else
		local_form(idx, ni, f.seen, f.map, &f.nused, f.lidx);
	part_block_streams(cb, m, count0, local ? f.lidx : idx, ni, local, f.split ? f.words : NULL, (f.nused + 31) / 32,
	                   f.old, f.nold);
	*rec = m->rec;
	rec->vertex_count = f.nused;
	rec->index_count = ni;
	if (m->count <= 65536)
		rec->flags |= MLOD_PART_INDEX16;
	if (local)
		rec->flags |= MLOD_PART_LOCAL | (f.split ? MLOD_PART_NEWBITS : 0);
	ok = 1;
done:
	free(V), free(in), free(saved), free(idx), free(f.seen), free(f.map), free(f.lidx), free(f.words), free(f.old);
	mlod_pack_order_memo_free(&memo);
	free(cls);
	return ok;
}

static mlod_result mesh_chunk(struct ctx *x, int k, chunks *out, int *part_count)
{
	chunkb cb = {0};
	mlod_result r = MLOD_OK;
	if (!x->mp_ready) { /* the coarsest level comes first */
		if ((r = mesh_parts(x, k + 1)) != MLOD_OK)
			return r;
		x->mp_ready = 1;
	}
	int np = x->mp_count;
	mlod_pack_part_rec *recs = malloc(sizeof *recs * ((size_t)np + 1));
	if (!recs)
		return mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
	/* PART first: its records are complete once the streams are made. */
	cb_add(&cb, MLOD_STREAM_PART, 0, sizeof(mlod_pack_part_rec), NULL, 0);
	for (int i = 0; i < np && !cb.fail; i++)
		if (!part_level(x, &cb, &x->mp[i], k, &recs[i]))
			cb.fail = 1;
	if (!cb.fail) {
		free(cb.s[0].data);
		cb.s[0].data = (uint8_t *)recs;
		cb.s[0].count = (uint32_t)np;
		recs = NULL;
	}
	free(recs);
	*part_count = np;
	if (!cb.fail && x->degenerate[k]) {
		char text[160], parts[64] = "";
		if (x->emptied[k])
			snprintf(parts, sizeof parts, " (parts left without a triangle: %d)", x->emptied[k]);
		snprintf(text, sizeof text, "mesh level %d: %u triangles quantisation made degenerate dropped%s", k,
		         x->degenerate[k], parts);
		note(x, text);
	}
	if (x->draco && x->draco_fail) {
		cb_free(&cb);
		return x->draco_fail;
	}
	return cb_finish(&cb, x->draco ? MLOD_CODEC_DRACO : x->opt->codec, out, MLOD_CHUNK_MESH, MLOD_LAYER_MESH, k, 0,
	                 k > 0 ? x->mesh_error[k - 1] : 0.0f,
	                 x->err);
}

/* ------------------------------------------------------------------ */
/* Motion                                                              */
/* ------------------------------------------------------------------ */

static int double_asc(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return (x > y) - (x < y);
}

static double motion_point_distance(const struct ctx *x)
{
	/* A BVH, or a glb made from one (its record's source): the BVH rule. */
	return x->opt->point_distance > 0.0
	           ? x->opt->point_distance
	           : mlod_motion_point_distance(&x->v.skeleton, !mlod_record_from_bvh(&x->rec, x->format));
}

/* Level 0 of each clip: the clip as read, or (unless lossless_motion or a
 * zero bound) the level lib/motion builds from it within the level-0
 * bound, methods and precision as for the coarser levels (fewer bytes
 * wins). The same for computed and piped levels, which are made from the
 * clip as read too. A clip keeps its keys as read when it has fewer than 3
 * frames, when no level meets the bound (a resampled cubic clip that
 * deviates more) or when the level would not have fewer key bytes. */
static mlod_result motion_level0(struct ctx *x)
{
	const mlod_character *c = &x->v;
	for (int q = 0; q < c->clip_count; q++)
		x->clips[q].level0 = &c->clips[q];
	double e0 = x->opt->motion_level0_percent ? x->opt->motion_level0_error * x->height / 100.0
	                                          : x->opt->motion_level0_error;
	/* A clip that is a pack's level 0 (mlod-pack -x: motion_level0 in its
	 * record) keeps its keys and that pack's error: reducing it again
	 * would stack a second error on the first. */
	unsigned char *packed = calloc((size_t)c->clip_count + 1, 1);
	if (!packed)
		return mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
	for (int q = 0; x->doc && q < c->clip_count; q++) {
		double pe = 0.0;
		int found = 0;
		mlod_result rr = c->clips[q].gltf_index >= 0
		                     ? mlod_record_read_motion0(x->doc, c->clips[q].gltf_index, &pe, &found, x->err)
		                     : MLOD_OK;
		if (rr != MLOD_OK) {
			free(packed);
			return rr;
		}
		if (found) {
			packed[q] = 1;
			x->clips[q].packed = 1;
			x->clips[q].error0 = (float)pe;
		}
	}
	if (c->clip_count == 0 || x->opt->lossless_motion || !(e0 > 0.0)) {
		free(packed);
		return MLOD_OK;
	}
	x->level0_owned = calloc((size_t)c->clip_count, sizeof *x->level0_owned);
	if (!x->level0_owned) {
		free(packed);
		return mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
	}
	mlod_motion_options mo = {0};
	mo.point_distance = motion_point_distance(x);
	mo.precision = MLOD_MOTION_PRECISION_FULL; /* every level keeps the clip's own values (mlod(5) MOTION levels) */
	mlod_result r = MLOD_OK;
	int kept = 0;
	for (int q = 0; r == MLOD_OK && q < c->clip_count; q++) {
		mlod_motion *m[2] = {NULL, NULL};
		if (packed[q])
			continue;
		for (int i = 0; r == MLOD_OK && i < 2; i++)
			r = i == 0 ? mlod_motion_create(c, q, &mo, &m[i], x->err) : mlod_motion_create_like(m[0], &m[i], x->err);
		if (r == MLOD_OK && mlod_motion_timeline_info(m[0])->frames >= 3) {
			static const mlod_motion_method methods[2] = {MLOD_MOTION_FRAMES, MLOD_MOTION_KEYS};
			mlod_motion_level best;
			mlod_error why = {0};
			mlod_result e = mlod_motion_next_level_best(m, methods, 2, MLOD_MOTION_MAX_ERROR, e0, &best, &why);
			if (e == MLOD_OK && best.keys < mlod_clip_key_count(&c->clips[q])) {
				x->level0_owned[q] = best;
				x->clips[q].level0 = &x->level0_owned[q].clip;
				x->clips[q].error0 = (float)best.error.max;
				x->clips[q].bound0 = e0;
			} else if (e == MLOD_OK || e == MLOD_ERR_LIMIT) {
				if (e == MLOD_OK)
					mlod_motion_level_free(&best);
				kept++;
			} else {
				if (x->err)
					*x->err = why;
				r = e;
			}
		} else if (r == MLOD_OK) {
			kept++;
		}
		for (int i = 0; i < 2; i++)
			mlod_motion_free(m[i]);
	}
	if (r == MLOD_OK && kept) {
		char text[96];
		snprintf(text, sizeof text, "%d clip(s) keep every key at motion level 0", kept);
		note(x, text);
	}
	int npacked = 0;
	for (int q = 0; q < c->clip_count; q++)
		npacked += packed[q];
	if (r == MLOD_OK && npacked) {
		char text[96];
		snprintf(text, sizeof text, "%d clip(s) are a pack's motion level 0: kept as they are", npacked);
		note(x, text);
	}
	free(packed);
	return r;
}

static mlod_result motion_levels(struct ctx *x)
{
	const mlod_character *c = &x->v;
	mlod_result r = MLOD_OK;
	x->clips = calloc((size_t)c->clip_count + 1, sizeof *x->clips);
	if (!x->clips)
		return mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
	if ((r = motion_level0(x)) != MLOD_OK)
		return r;
	if (c->clip_count == 0 || x->opt->no_motion_levels)
		return MLOD_OK;
	/* The input's levels: "<clip>@lod<k>" animations with a record. */
	int from_input = 0;
	for (int i = 0; r == MLOD_OK && x->doc && i < x->in->clip_count; i++) {
		mlod_record_motion_level ml;
		int found = 0;
		if (x->in->clips[i].gltf_index < 0)
			continue;
		if ((r = mlod_record_read_motion(x->doc, x->in->clips[i].gltf_index, &ml, &found, x->err)) != MLOD_OK ||
		    !found)
			continue;
		for (int q = 0; q < c->clip_count; q++)
			if (c->clips[q].gltf_index == ml.source_animation && ml.level >= 1 &&
			    ml.level <= MLOD_PACK_MAX_MOTION_LEVELS) {
				struct clip_levels *cl = &x->clips[q];
				if (!ml.has_pack_error && ml.missing_joint_error)
					return mlod_fail(x->err, MLOD_ERR_PARSE,
					                 "animation %d: extras.mlod: no error (pack_error or joint_error)",
					                 x->in->clips[i].gltf_index);
				cl->clip[ml.level - 1] = &x->in->clips[i];
				cl->error[ml.level - 1] = (float)(ml.has_pack_error ? ml.pack_error : ml.joint_error.max);
				cl->bound[ml.level - 1] = ml.has_bound && !ml.has_pack_error ? ml.bound : 0.0;
				cl->count = ml.level > cl->count ? ml.level : cl->count;
				from_input = 1;
			}
	}
	if (r != MLOD_OK)
		return r;
	for (int q = 0; q < c->clip_count; q++) /* an unpacked pack's clips: its levels, maybe none */
		from_input |= x->clips[q].packed;
	if (from_input) {
		x->st->motion.from_input = 1;
		for (int q = 0; q < c->clip_count; q++) { /* a gap repeats the finer level */
			struct clip_levels *cl = &x->clips[q];
			int gap = 0;
			for (int k = 0; k < cl->count; k++)
				if (!cl->clip[k]) {
					cl->clip[k] = k ? cl->clip[k - 1] : cl->level0;
					cl->error[k] = k ? cl->error[k - 1] : cl->error0;
					gap = 1;
				}
			/* levels held to their bounds (motion_hold) only when every
			 * one has its bound, in increasing order, as mlod-motion's */
			for (int k = 0; k < cl->count; k++)
				gap |= !(cl->bound[k] > (k ? cl->bound[k - 1] : 0.0));
			for (int k = 0; gap && k < cl->count; k++)
				cl->bound[k] = 0.0;
		}
		return MLOD_OK;
	}
	/* Computed: per bound, the frames and keys methods; fewer bytes wins. */
	int nb = x->opt->motion_bound_count;
	double bounds[MLOD_PACK_MAX_MOTION_LEVELS];
	for (int b = 0; b < nb; b++)
		bounds[b] = x->opt->motion_percent[b] ? x->opt->motion_bounds[b] * x->height / 100.0 : x->opt->motion_bounds[b];
	qsort(bounds, (size_t)nb, sizeof *bounds, double_asc);
	mlod_motion_options mo = {0};
	mo.point_distance = motion_point_distance(x);
	mo.precision = MLOD_MOTION_PRECISION_FULL; /* every level keeps the clip's own values (mlod(5) MOTION levels) */
	x->owned_levels = calloc((size_t)c->clip_count * (size_t)(nb > 0 ? nb : 1), sizeof *x->owned_levels);
	if (!x->owned_levels)
		return mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
	int short_clips = 0, missed = 0;
	for (int q = 0; r == MLOD_OK && q < c->clip_count; q++) {
		mlod_motion *m[2] = {NULL, NULL};
		for (int i = 0; r == MLOD_OK && i < 2; i++)
			r = i == 0 ? mlod_motion_create(c, q, &mo, &m[i], x->err) : mlod_motion_create_like(m[0], &m[i], x->err);
		mlod_error fit = {0};
		if (r == MLOD_OK && mlod_motion_timeline_info(m[0])->frames < 3)
			short_clips++;
		else if (r == MLOD_OK && nb > 0 &&
		         mlod_motion_keys_fit(c->skeleton.joint_count, mlod_motion_timeline_info(m[0])->frames,
		                              MLOD_DEFAULT_SUBDIVIDE, c->clips[q].name, &fit) != MLOD_OK) {
			char text[MLOD_ERROR_MESSAGE_SIZE + 80];
			snprintf(text, sizeof text, "the keys method is left out, the levels come from the frames method alone: %s",
			         fit.message);
			warn(x, text);
		}
		if (r == MLOD_OK && mlod_motion_timeline_info(m[0])->frames >= 3)
			for (int b = 0; r == MLOD_OK && b < nb; b++) {
				static const mlod_motion_method methods[2] = {MLOD_MOTION_FRAMES, MLOD_MOTION_KEYS};
				mlod_motion_level best;
				mlod_error why = {0};
				mlod_result e = mlod_motion_next_level_best(m, methods, 2, MLOD_MOTION_MAX_ERROR, bounds[b], &best, &why);
				if (e == MLOD_ERR_LIMIT) {
					missed++;
					continue;
				}
				if (e != MLOD_OK) {
					if (x->err)
						*x->err = why;
					r = e;
					break;
				}
				struct clip_levels *cl = &x->clips[q];
				x->owned_levels[x->owned_count] = best;
				cl->clip[cl->count] = &x->owned_levels[x->owned_count++].clip;
				cl->bound[cl->count] = bounds[b];
				cl->error[cl->count++] = (float)best.error.max;
			}
		for (int i = 0; i < 2; i++)
			mlod_motion_free(m[i]);
	}
	if (short_clips) {
		char text[96];
		snprintf(text, sizeof text, "%d clip(s) with fewer than 3 frames: no motion levels", short_clips);
		note(x, text);
	}
	if (missed) {
		char text[96];
		snprintf(text, sizeof text, "%d motion level(s) met no bound", missed);
		warn(x, text);
	}
	return r;
}

/* 1 when a non-cubic channel's keys all hold one value (bit for bit). */
static int constant_channel(const mlod_channel *ch)
{
	if (ch->interp == MLOD_INTERP_CUBICSPLINE || ch->key_count < 2)
		return 0;
	int comps = ch->path == MLOD_PATH_ROTATION ? 4 : 3;
	for (int k = 1; k < ch->key_count; k++)
		if (memcmp(ch->values + (size_t)comps * k, ch->values, sizeof(float) * (size_t)comps) != 0)
			return 0;
	return 1;
}

/* 1 when every time t of the arrays is within tol * max(|t|, step) of
 * (float)(tick * step) for a tick in 0..UINT32_MAX (tol 0: exactly), and
 * the ticks and their times increase strictly; *max_tick is the largest. */
static int ticks_fit(const float *const *arr, const int *cnt, int n, double step, double tol, uint32_t *max_tick)
{
	uint32_t mx = 0;
	if (!(step > 0) || !isfinite(step))
		return 0;
	for (int a = 0; a < n; a++) {
		float prev = 0;
		for (int k = 0; k < cnt[a]; k++) {
			double q = floor((double)arr[a][k] / step + 0.5);
			if (!(q >= 0 && q <= 4294967295.0))
				return 0;
			float t = (float)(q * step);
			double lim = tol * (fabs((double)arr[a][k]) > step ? fabs((double)arr[a][k]) : step);
			if (tol == 0 ? t != arr[a][k] : !(fabs((double)t - arr[a][k]) <= lim))
				return 0;
			if (k > 0 && !(t > prev))
				return 0;
			prev = t;
			mx = (uint32_t)q > mx ? (uint32_t)q : mx;
		}
	}
	*max_tick = mx;
	return 1;
}

/* The time step of a chunk's key-time arrays, or 0 to keep them f32. The
 * candidates: 1 / the nearest whole frame rate to the smallest key
 * interval d; the smallest positive key time (a clip sampled as
 * (float)(k * step)); the largest time over its whole number of d; d.
 * The first that gives every time back exactly wins; else the first
 * within MLOD_PACK_TICK_TOLERANCE (times summed frame by frame in f32). */
static double time_step(const float *const *arr, const int *cnt, int n, uint32_t *max_tick)
{
	double d = 0, first = 0, last = 0;
	for (int a = 0; a < n; a++)
		for (int k = 0; k < cnt[a]; k++) {
			double t = arr[a][k], e = k > 0 ? t - (double)arr[a][k - 1] : 0;
			if (e > 0 && (d == 0 || e < d))
				d = e;
			if (t > 0 && (first == 0 || t < first))
				first = t;
			last = t > last ? t : last;
		}
	if (d == 0)
		return 0;
	double fps = floor(1.0 / d + 0.5), frames = floor(last / d + 0.5);
	double cand[5] = {fps >= 1 && fps <= 100000 ? 1.0 / fps : 0, first, frames >= 1 ? last / frames : 0,
	                  frames >= 1 ? (double)(float)(last / frames) : 0, d};
	for (int pass = 0; pass < 2; pass++)
		for (int i = 0; i < 5; i++)
			if (cand[i] > 0 && ticks_fit(arr, cnt, n, cand[i], pass ? MLOD_PACK_TICK_TOLERANCE : 0, max_tick))
				return cand[i];
	return 0;
}

/* A rotation key's lattice value the reader rebuilds (mlod(5) ROTQ): the
 * component big from the three others n (big's own entry ignored), as
 * lib/motion rounds onto the lattice of normalised shorts. */
static long rotq_big(const long *n, int big)
{
	double sum = 0.0;
	for (int c = 0; c < 4; c++)
		if (c != big) {
			float f = (float)((double)n[c] / 32767.0);
			sum += (double)f * f;
		}
	return lrint(sqrt(sum < 1.0 ? 1.0 - sum : 0.0) * 32767.0);
}

/* One 'ROTQ' key: the three components other than the one at index big
 * (in index order), then big. When r is a lattice point (n / 32767) whose
 * component big, made non-negative, is what the reader rebuilds from the
 * other three (as lib/motion's levels are), it comes back exactly (up to
 * the sign); else r is normalised, big is its largest component, made
 * non-negative, and the three go to the nearest lattice points. */
static void rotq_encode(const float *r, int16_t *out, int shift)
{
	long n[4], m[4];
	if (shift > 0) { /* the normalised key, its three smaller components on the coarser lattice */
		double len = 0.0, u[4];
		int big = 0;
		for (int c = 0; c < 4; c++)
			len += (double)r[c] * r[c];
		len = len > 0.0 ? sqrt(len) : 1.0;
		for (int c = 0; c < 4; c++) {
			u[c] = r[c] / len;
			big = fabs(u[c]) > fabs(u[big]) ? c : big;
		}
		double sign = u[big] < 0 ? -1.0 : 1.0, step = ldexp(1.0, shift);
		long lim = 32767L >> shift;
		for (int c = 0, i = 0; c < 4; c++)
			if (c != big) {
				long k = lrint(sign * u[c] * 32767.0 / step);
				out[i++] = (int16_t)(k > lim ? lim : k < -lim ? -lim : k);
			}
		out[3] = (int16_t)(big | shift << 2);
		return;
	}
	int order[4] = {0, 1, 2, 3};
	for (int c = 0; c < 4; c++) {
		double e = r[c] > 1 ? 1 : r[c] < -1 ? -1 : r[c];
		n[c] = lrint(e * 32767.0);
	}
	for (int i = 1; i < 4; i++) /* by decreasing |n|, index order on ties */
		for (int j = i; j > 0 && labs(n[order[j]]) > labs(n[order[j - 1]]); j--) {
			int t = order[j];
			order[j] = order[j - 1], order[j - 1] = t;
		}
	int big = -1;
	for (int i = 0; i < 4 && big < 0; i++) {
		int b = order[i];
		long sign = n[b] < 0 ? -1 : 1;
		for (int c = 0; c < 4; c++)
			m[c] = sign * n[c];
		if (rotq_big(m, b) == m[b])
			big = b;
	}
	if (big < 0) {
		double len = 0.0, u[4];
		for (int c = 0; c < 4; c++)
			len += (double)r[c] * r[c];
		len = len > 0.0 ? sqrt(len) : 1.0;
		big = 0;
		for (int c = 0; c < 4; c++) {
			u[c] = r[c] / len;
			big = fabs(u[c]) > fabs(u[big]) ? c : big;
		}
		double sign = u[big] < 0 ? -1.0 : 1.0;
		for (int c = 0; c < 4; c++) {
			double e = sign * u[c];
			m[c] = lrint((e > 1 ? 1 : e < -1 ? -1 : e) * 32767.0);
		}
	}
	for (int c = 0, i = 0; c < 4; c++)
		if (c != big)
			out[i++] = (int16_t)m[c];
	out[3] = (int16_t)big;
}

/* A MOTION chunk as the reader returns it, for the next finer level to
 * build on: per channel its key times and, for non-cubic rotations, its
 * keys as lattice integers (mlod_pack_rotq_key). */
typedef struct motion_img {
	int n;
	struct img_chan {
		uint32_t joint, path, interp, keys;
		float *times;
		int16_t *rot;
		float *vec; /* non-cubic translations and scales: the values */
	} *ch;
} motion_img;

static void motion_img_free(motion_img *m)
{
	for (int i = 0; m && i < m->n; i++)
		free(m->ch[i].times), free(m->ch[i].rot), free(m->ch[i].vec);
	if (m)
		free(m->ch), memset(m, 0, sizeof *m);
}

/* As pack.c's base_channel and base_key. */
static const struct img_chan *img_channel(const motion_img *m, uint32_t joint)
{
	for (int i = 0; m && i < m->n; i++)
		if (m->ch[i].joint == joint && m->ch[i].path == MLOD_PATH_ROTATION &&
		    m->ch[i].interp != MLOD_INTERP_CUBICSPLINE)
			return &m->ch[i];
	return NULL;
}

static long img_key(const struct img_chan *c, float t)
{
	uint32_t lo = 0, hi = c ? c->keys : 0;
	while (lo < hi) {
		uint32_t mid = lo + (hi - lo) / 2;
		if (c->times[mid] < t)
			lo = mid + 1;
		else
			hi = mid;
	}
	return c && lo < c->keys && c->times[lo] == t ? (long)lo : -1;
}

/* A 'ROTQ' key on its base's key bn: the lattice point r is (else the
 * nearest to r normalised), with the sign nearer bn, minus bn, each
 * component wrapped to 16 bits (the reader adds bn back). */
static void rotq_encode_on(const float *r, const int16_t *bn, int16_t *out, int shift)
{
	long t[4];
	int lattice = 1;
	for (int c = 0; c < 4; c++) {
		double e = r[c] > 1 ? 1 : r[c] < -1 ? -1 : r[c];
		t[c] = lrint(e * 32767.0);
		lattice &= (float)((double)t[c] / 32767.0) == r[c];
	}
	if (!lattice) {
		double len = 0.0;
		for (int c = 0; c < 4; c++)
			len += (double)r[c] * r[c];
		len = len > 0.0 ? sqrt(len) : 1.0;
		for (int c = 0; c < 4; c++)
			t[c] = lrint(r[c] / len * 32767.0);
	}
	long dot = 0;
	for (int c = 0; c < 4; c++)
		dot += t[c] * bn[c];
	if (shift > 0) { /* the base key itself when within the shift's angle of r */
		double lr = 0.0, lb = 0.0, d2 = 0.0, sd = 0.0;
		for (int c = 0; c < 4; c++)
			lr += (double)r[c] * r[c], lb += (double)bn[c] * bn[c], sd += (double)r[c] * bn[c];
		lr = sqrt(lr), lb = sqrt(lb);
		for (int c = 0; c < 4; c++) {
			double e = (sd < 0 ? -r[c] : r[c]) / lr - bn[c] / lb;
			d2 += e * e;
		}
		if (lr > 0.0 && lb > 0.0 && 4.0 * asin(fmin(1.0, sqrt(d2) / 2.0)) <= mlod_pack_rotq_angle(shift) * (1.0 - 1e-6)) {
			memset(out, 0, 4 * sizeof *out);
			return;
		}
	}
	for (int c = 0; c < 4; c++)
		out[c] = (int16_t)(uint16_t)((uint16_t)(dot < 0 ? -t[c] : t[c]) - (uint16_t)bn[c]);
}

double mlod_pack_rotq_angle(int shift)
{
	double h = sqrt(19.0) * ldexp(1.0, shift) / 65534.0;
	return 2.0 * asin(h < 1.0 ? h : 1.0) * (1.0 + 1e-9);
}

/* An upper bound of the largest singular value of w's 3x3 part M: the
 * square root of the largest absolute row sum of M^T M (Gershgorin),
 * exact for a rotation times a uniform scale. */
static double sigma_bound3(const mlod_mat4 *w)
{
	double g = 0.0;
	for (int a = 0; a < 3; a++) {
		double row = 0.0;
		for (int b = 0; b < 3; b++) {
			double d = 0.0;
			for (int r = 0; r < 3; r++)
				d += (double)w->m[4 * a + r] * w->m[4 * b + r];
			row += fabs(d);
		}
		g = row > g ? row : g;
	}
	return sqrt(g);
}

/* Per joint, the lattice shift of the rotation keys of a motion level of
 * TOC error `error` whose channels are lvl's (mlod_pack_write.h
 * MLOD_PACK_ROTQ_SHARE): reach[g * nj + j] is the largest, over the
 * original clip's frames and midpoints, of joint j's distance to its
 * ancestor g (or itself) plus its point distance times its world scale;
 * a key of g off by angle a moves j's points by at most a times that. The
 * shifts go up one at a time, leaves first, round after round, while every
 * joint's sum of angle times reach stays within its budget: share *
 * error plus that sum at shift 0. tgrid gets each joint's translation
 * grid exponent (INT_MIN: exact), raised in the same rounds against the
 * same sums. */
/* Joint j's rounding error bound in rotq_shifts: over its ancestors a,
 * j first, ra[a] reach(a, j) where a has a rotation lattice, and ta[a]
 * where its translations are on a grid (0 when exact). */
static double rotq_error(const mlod_skeleton *sk, int j, const double *ra, const double *ta, const unsigned char *rot,
                         const unsigned char *tr, const double *reach)
{
	int nj = sk->joint_count;
	double e = 0.0;
	for (int a = j; a >= 0; a = sk->joints[a].parent) {
		if (rot[a])
			e += ra[a] * reach[(size_t)a * nj + j];
		if (tr[a] && ta[a] > 0.0)
			e += ta[a];
	}
	return e;
}

static mlod_result rotq_shifts(struct ctx *x, const mlod_clip *orig, const mlod_clip *lvl, double error, int *shift,
                               int *tgrid)
{
	const mlod_skeleton *sk = &x->v.skeleton;
	int nj = sk->joint_count;
	for (int j = 0; j < nj; j++)
		shift[j] = 0, tgrid[j] = INT_MIN;
	if (!(error > 0.0) || nj <= 0 || orig->channel_count <= 0)
		return MLOD_OK;
	mlod_motion_options mo = {0};
	mlod_clip common;
	mlod_result r = mlod_motion_common_clip(orig, &mo, &common, NULL, x->err);
	if (r != MLOD_OK)
		return r;
	int frames = common.channel_count > 0 ? common.channels[0].key_count : 0, n = frames > 0 ? 2 * (frames - 1) + 1 : 0;
	double pd = motion_point_distance(x), a0 = mlod_pack_rotq_angle(0);
	float *t = malloc(sizeof *t * ((size_t)n + 1));
	mlod_trs *loc = malloc(sizeof *loc * (size_t)nj);
	mlod_mat4 *w = malloc(sizeof *w * (size_t)nj);
	double *reach = calloc((size_t)nj * nj, sizeof *reach), *budget = calloc((size_t)nj, sizeof *budget);
	double *tmax = calloc((size_t)nj, sizeof *tmax), *ps = calloc((size_t)nj, sizeof *ps);
	unsigned char *rot = calloc((size_t)nj, 1), *tr = calloc((size_t)nj, 1);
	int *tl = calloc((size_t)nj, sizeof *tl), *tbase = calloc((size_t)nj, sizeof *tbase);
	if (!t || !loc || !w || !reach || !budget || !rot || !tmax || !ps || !tr || !tl || !tbase) {
		r = mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
		goto done;
	}
	if (n > 0)
		mlod_motion_sample_times(common.channels[0].times, frames, 2, t);
	for (int i = 0; i < lvl->channel_count; i++)
		if (lvl->channels[i].path == MLOD_PATH_ROTATION && lvl->channels[i].interp != MLOD_INTERP_CUBICSPLINE &&
		    lvl->channels[i].joint >= 0 && lvl->channels[i].joint < nj)
			rot[lvl->channels[i].joint] = 1;
	/* translations: grid 2^(tbase + tl), tbase the exponent of the ulp of
	 * the channel's largest |value| (tl 0: exact) */
	for (int i = 0; i < lvl->channel_count; i++) {
		const mlod_channel *ch = &lvl->channels[i];
		if (ch->path != MLOD_PATH_TRANSLATION || ch->interp == MLOD_INTERP_CUBICSPLINE || ch->joint < 0 ||
		    ch->joint >= nj)
			continue;
		tr[ch->joint] = 1;
		for (int k = 0; k < 3 * ch->key_count; k++)
			tmax[ch->joint] = fabs((double)ch->values[k]) > tmax[ch->joint] ? fabs((double)ch->values[k]) : tmax[ch->joint];
	}
	for (int j = 0; j < nj; j++) {
		int ex = 0;
		frexp(tmax[j], &ex);
		tbase[j] = ex - 24;
		if (!isfinite(tmax[j]) || !(tmax[j] > 0.0))
			tr[j] = 0;
	}
	if (n == 0)
		goto done; /* nothing to measure the reach on: shifts 0 */
	for (int i = 0; i < n; i++) {
		mlod_pose_rest(sk, loc);
		mlod_clip_sample(orig, t[i], loc);
		mlod_pose_world(sk, loc, w);
		for (int j = 0; j < nj; j++) {
			double rad = pd * sigma_bound3(&w[j]);
			int pa = sk->joints[j].parent;
			double sp = sigma_bound3(pa < 0 ? &sk->joints[j].base : &w[pa]);
			if (!(sp <= ps[j]))
				ps[j] = isfinite(sp) ? sp : INFINITY;
			for (int g = j; g >= 0; g = sk->joints[g].parent) {
				double d = 0.0;
				for (int c = 0; c < 3; c++)
					d += ((double)w[j].m[12 + c] - w[g].m[12 + c]) * ((double)w[j].m[12 + c] - w[g].m[12 + c]);
				d = sqrt(d) + rad;
				if (!(d <= reach[(size_t)g * nj + j])) /* NaN too: no coarser lattice */
					reach[(size_t)g * nj + j] = isfinite(d) ? d : INFINITY;
			}
		}
	}
	for (size_t i = 0; i < (size_t)nj * nj; i++)
		if (!isfinite(reach[i]) || (i < (size_t)nj && !isfinite(ps[i])))
			goto done; /* shifts 0 */
	for (int j = 0; j < nj; j++) {
		double b = MLOD_PACK_ROTQ_SHARE * error;
		for (int g = j; g >= 0; g = sk->joints[g].parent)
			if (rot[g])
				b += a0 * reach[(size_t)g * nj + j];
		budget[j] = b;
	}
	/* A translation of g off by the grid's half step per component moves
	 * g and every joint below it by at most sqrt(3) 2^(e - 1) times the
	 * scale of g's parent's world matrix (its base for a root).
	 * Joint j's error is the sum over its ancestors a (j included, from j
	 * up) of a's rotation term ra[a] reach(a, j) and translation term
	 * ta[a]; a coarser lattice of g is kept when every joint below g stays
	 * within its budget. The sums are kept per joint (sum[j]) and moved by
	 * each kept step, and a joint whose moved sum falls within a relative
	 * 1e-9 of its budget is summed again exactly, in the order above, so
	 * that every decision is that of the exact sums (which took time cubic
	 * in a chain's depth: a 500-joint chain 33 s, a scale probe). */
	double *ra = calloc((size_t)nj, sizeof *ra), *ta = calloc((size_t)nj, sizeof *ta);
	double *sum = calloc((size_t)nj, sizeof *sum), *delta = calloc((size_t)nj, sizeof *delta);
	int *below = malloc(sizeof *below * (size_t)nj);
	if (!ra || !ta || !sum || !delta || !below) {
		free(ra), free(ta), free(sum), free(delta), free(below);
		r = mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
		goto done;
	}
	double angle[MLOD_PACK_ROTQ_SHIFT_MAX + 1];
	for (int k = 0; k <= MLOD_PACK_ROTQ_SHIFT_MAX; k++)
		angle[k] = mlod_pack_rotq_angle(k);
	for (int a = 0; a < nj; a++)
		ra[a] = rot[a] ? angle[0] : 0.0;
	for (int j = 0; j < nj; j++)
		sum[j] = rotq_error(sk, j, ra, ta, rot, tr, reach);
	for (int changed = 1; changed;) {
		changed = 0;
		for (int g = nj - 1; g >= 0; g--)
			for (int kind = 0; kind < 2; kind++) {
				if (kind == 0 ? !rot[g] || shift[g] >= MLOD_PACK_ROTQ_SHIFT_MAX : !tr[g] || tl[g] >= 24)
					continue;
				double old = kind == 0 ? ra[g] : ta[g];
				double now = kind == 0 ? angle[shift[g] + 1]
				                       : sqrt(3.0) * ldexp(1.0, tbase[g] + tl[g]) * ps[g] * (1.0 + 1e-9);
				(kind == 0 ? ra : ta)[g] = now;
				int ok = 1, nb = 0;
				for (int j = 0; j < nj && ok; j++) {
					if (!(reach[(size_t)g * nj + j] > 0.0) && j != g)
						continue; /* not below g */
					delta[j] = kind == 0 ? (now - old) * reach[(size_t)g * nj + j] : now - old;
					double e = sum[j] + delta[j];
					if (fabs(e - budget[j]) <= 1e-9 * budget[j])
						e = rotq_error(sk, j, ra, ta, rot, tr, reach);
					ok = e <= budget[j];
					below[nb++] = j;
				}
				if (ok) {
					changed = 1;
					(kind == 0 ? shift : tl)[g]++;
					for (int i = 0; i < nb; i++)
						sum[below[i]] += delta[below[i]];
				} else {
					(kind == 0 ? ra : ta)[g] = old;
				}
			}
	}
	free(ra), free(ta), free(sum), free(delta), free(below);
	for (int j = 0; j < nj; j++)
		tgrid[j] = tr[j] && tl[j] > 0 ? tbase[j] + tl[j] : INT_MIN;
done:
	free(t), free(loc), free(w), free(reach), free(budget), free(rot), free(tmax), free(ps), free(tr), free(tl),
	    free(tbase);
	mlod_clip_free(&common);
	return r;
}

/* One MOTION chunk of level k of clip item. base: the clip's level k + 1
 * as the reader returns it (NULL: none, level k is the coarsest); its
 * rotation keys then build on it (MLOD_PACK_CHUNK_NESTED). img gets this
 * chunk as the reader returns it. */
static mlod_result motion_chunk(struct ctx *x, const mlod_clip *clip, int k, int item, float error,
                                const motion_img *base, motion_img *img, chunks *out)
{
	chunkb cb = {0};
	int n = clip->channel_count;
	mlod_pack_channel_rec *recs = calloc((size_t)n + 1, sizeof *recs);
	const float **arr = calloc((size_t)n + 1, sizeof *arr);
	int *cnt = calloc((size_t)n + 1, sizeof *cnt), na = 0;
	if (!recs || !arr || !cnt) {
		free(recs), free(arr), free(cnt);
		return mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
	}
	/* The distinct time arrays, in first-use order. */
	for (int i = 0; i < n; i++) {
		const mlod_channel *ch = &clip->channels[i];
		int konst = constant_channel(ch), keys = konst ? 1 : ch->key_count;
		const float *t = konst ? ch->times + ch->key_count - 1 : ch->times;
		int a = 0;
		while (a < na && !(cnt[a] == keys && memcmp(arr[a], t, sizeof(float) * (size_t)keys) == 0))
			a++;
		if (a == na)
			arr[na] = t, cnt[na++] = keys;
		recs[i] = (mlod_pack_channel_rec){(uint32_t)ch->joint, (uint32_t)ch->path, (uint32_t)ch->interp,
		                                  (uint32_t)keys, (uint32_t)a};
	}
	cb_add(&cb, MLOD_STREAM_CHAN, (uint32_t)n, sizeof *recs, recs, 0);
	/* the rotation keys' lattice per joint: level 0 the finest */
	int nj = x->v.skeleton.joint_count, *shift = calloc((size_t)nj + 1, sizeof *shift);
	int *tgrid = malloc(sizeof *tgrid * ((size_t)nj + 1));
	for (int j = 0; tgrid && j < nj; j++)
		tgrid[j] = INT_MIN;
	if (!shift || !tgrid) {
		cb.fail = 1;
	} else if (item < x->v.clip_count && !x->clips[item].no_shifts) {
		/* one set of shifts for every level of the clip, from the
		 * smallest TOC error, level 0's included: a finer level's key on
		 * its base's then mostly stores zeros (below); per-level shifts
		 * cost more (mlod(5)) */
		double emin = error;
		const struct clip_levels *cl = &x->clips[item];
		emin = cl->error0 < emin ? cl->error0 : emin;
		for (int l = 0; l < cl->count; l++)
			emin = cl->error[l] < emin ? cl->error[l] : emin;
		struct clip_levels *cw = &x->clips[item];
		if (!(cw->has_shift && cw->shift_emin == emin)) {
			mlod_result sr = rotq_shifts(x, &x->v.clips[item], &x->v.clips[item], emin, shift, tgrid);
			if (sr != MLOD_OK) {
				free(shift), free(tgrid), free(recs), free(arr), free(cnt), cb_free(&cb);
				return sr;
			}
			if (!cw->shift)
				cw->shift = malloc(sizeof *shift * ((size_t)nj + 1));
			if (!cw->tgrid)
				cw->tgrid = malloc(sizeof *tgrid * ((size_t)nj + 1));
			if (cw->shift && cw->tgrid) {
				memcpy(cw->shift, shift, sizeof *shift * (size_t)nj);
				memcpy(cw->tgrid, tgrid, sizeof *tgrid * (size_t)nj);
				cw->has_shift = 1, cw->shift_emin = emin;
			}
		} else {
			memcpy(shift, cw->shift, sizeof *shift * (size_t)nj);
			memcpy(tgrid, cw->tgrid, sizeof *tgrid * (size_t)nj);
		}
	}
	/* this chunk as the reader returns it: the channels */
	motion_img_free(img);
	img->ch = calloc((size_t)n + 1, sizeof *img->ch);
	if (!img->ch)
		cb.fail = 1;
	else
		img->n = n;
	for (int i = 0; i < img->n; i++)
		img->ch[i] = (struct img_chan){recs[i].joint, recs[i].path, recs[i].interp, recs[i].key_count, NULL, NULL, NULL};
	int *ta = malloc(sizeof *ta * ((size_t)n + 1));
	if (!ta)
		cb.fail = 1;
	for (int i = 0; ta && i < n; i++)
		ta[i] = (int)recs[i].time;
	free(recs);
	uint32_t max_tick = 0;
	double step = time_step(arr, cnt, na, &max_tick);
	cb_add(&cb, MLOD_STREAM_STEP, 1, 8, &step, 0);
	/* The key times: one stream, the arrays one after the other; f32, or
	 * ticks, each array's first then each next minus the one before (the
	 * vertex codec's byte deltas then see second differences: nearly
	 * nothing for evenly sampled arrays); u16 raw, u32 where they do not
	 * fit or the vertex codec (a multiple of 4 bytes) applies. */
	size_t nt = 0;
	for (int a = 0; a < na; a++)
		nt += (size_t)cnt[a];
	int wide = max_tick > 65535 || x->opt->codec == MLOD_CODEC_MESHOPT;
	uint8_t *tk = malloc(4 * (nt + 1));
	float *dt = malloc(sizeof *dt * (nt + 1)); /* the times as the reader returns them */
	size_t *dt_at = malloc(sizeof *dt_at * ((size_t)na + 1));
	if (!tk || !dt || !dt_at) {
		cb.fail = 1;
	} else {
		size_t at = 0;
		for (int a = 0; a < na; a++)
			for (int q = 0; q < cnt[a]; q++, at++) {
				if (q == 0)
					dt_at[a] = at;
				dt[at] = arr[a][q];
				if (step == 0) {
					memcpy(tk + 4 * at, &arr[a][q], 4);
					continue;
				}
				uint32_t v = (uint32_t)floor((double)arr[a][q] / step + 0.5);
				dt[at] = (float)((double)v * step);
				if (q > 0) /* the tick before's difference */
					v -= (uint32_t)floor((double)arr[a][q - 1] / step + 0.5);
				if (wide)
					put_u32(tk + 4 * at, v);
				else
					put_u16(tk + 2 * at, (uint16_t)v);
			}
		if (step == 0)
			cb_add(&cb, MLOD_STREAM_TIME, (uint32_t)nt, 4, tk, 0);
		else
			cb_add(&cb, MLOD_STREAM_TICK, (uint32_t)nt, wide ? 4 : 2, tk, 0);
		/* Or 'TBIT' (format 3.0), each array's first tick then a bit per
		 * tick after it: whichever stores fewer bytes. */
		if (step > 0 && !cb.fail) {
			size_t nbits = 0;
			for (int a = 0; a < na; a++)
				if (cnt[a] > 0)
					nbits += (size_t)((uint32_t)floor((double)arr[a][cnt[a] - 1] / step + 0.5) -
					                  (uint32_t)floor((double)arr[a][0] / step + 0.5));
			size_t nw = (size_t)na + (nbits + 31) / 32;
			uint32_t *w = nw <= UINT32_MAX ? calloc(nw + 1, 4) : NULL;
			if (!w) {
				cb.fail = 1;
			} else {
				size_t b = 0;
				for (int a = 0; a < na; a++) {
					uint32_t first = cnt[a] > 0 ? (uint32_t)floor((double)arr[a][0] / step + 0.5) : 0;
					w[a] = first;
					for (int q = 1; q < cnt[a]; q++) {
						uint32_t tq = (uint32_t)floor((double)arr[a][q] / step + 0.5);
						uint32_t tp = (uint32_t)floor((double)arr[a][q - 1] / step + 0.5);
						b += tq - tp; /* the key's bit: the last of its gap */
						w[(size_t)na + (b - 1) / 32] |= 1u << ((b - 1) % 32);
					}
				}
				stream tb = {MLOD_STREAM_TBIT, (uint32_t)nw, 4, 0, (uint8_t *)w};
				const stream *st = &cb.s[cb.n - 1];
				int coded = x->opt->codec == MLOD_CODEC_MESHOPT;
				size_t bt = coded ? stream_coded_bytes(&tb) : nw * 4;
				size_t bk = coded ? stream_coded_bytes(st) : ((size_t)st->count * st->size + 3) & ~(size_t)3;
				if (bt < bk) {
					free(cb.s[--cb.n].data);
					cb_add(&cb, MLOD_STREAM_TBIT, (uint32_t)nw, 4, w, 0);
				}
				free(w);
			}
		}
	}
	free(tk);
	free(arr);
	free(cnt);
	for (int i = 0; !cb.fail && i < img->n; i++) {
		struct img_chan *ic = &img->ch[i];
		ic->times = malloc(sizeof *ic->times * ic->keys);
		if (!ic->times) {
			cb.fail = 1;
			break;
		}
		memcpy(ic->times, dt + dt_at[ta[i]], sizeof *ic->times * ic->keys);
		if (ic->path == MLOD_PATH_ROTATION && ic->interp != MLOD_INTERP_CUBICSPLINE &&
		    !(ic->rot = malloc(sizeof *ic->rot * 4 * ic->keys)))
			cb.fail = 1;
		if (ic->path != MLOD_PATH_ROTATION && ic->interp != MLOD_INTERP_CUBICSPLINE &&
		    !(ic->vec = malloc(sizeof *ic->vec * 3 * ic->keys)))
			cb.fail = 1;
	}
	free(dt);
	free(dt_at);
	free(ta);
	/* The values: 'ROTQ' (non-cubic rotations), 'ROTF' (cubic rotations),
	 * 'VEC3' (translations and scales), each one stream of its channels'
	 * keys in channel order. */
	size_t nq = 0, nf = 0, nv = 0;
	for (int i = 0; i < n; i++) {
		const mlod_channel *ch = &clip->channels[i];
		size_t keys = constant_channel(ch) ? 1 : (size_t)ch->key_count;
		size_t per = ch->interp == MLOD_INTERP_CUBICSPLINE ? 3 : 1;
		if (ch->path == MLOD_PATH_ROTATION && per == 1)
			nq += keys;
		else if (ch->path == MLOD_PATH_ROTATION)
			nf += 3 * keys;
		else
			nv += per * keys;
	}
	int16_t *q = malloc(sizeof(int16_t) * 4 * (nq + 1)), *qd = malloc(sizeof(int16_t) * 4 * (nq + 1));
	uint32_t *vd = malloc(sizeof *vd * 3 * (nv + 1));
	size_t at_d = 0, at_a = 0, at_vd = 0;
	float *rf = malloc(sizeof(float) * 4 * (nf + 1)), *v3 = malloc(sizeof(float) * 3 * (nv + 1));
	if (!q || !qd || !vd || !rf || !v3)
		cb.fail = 1;
	size_t at_q = 0, at_f = 0, at_v = 0;
	for (int i = 0; i < n && !cb.fail; i++) {
		const mlod_channel *ch = &clip->channels[i];
		int konst = constant_channel(ch);
		uint32_t keys = konst ? 1 : (uint32_t)ch->key_count, per = ch->interp == MLOD_INTERP_CUBICSPLINE ? 3 : 1;
		if (ch->path == MLOD_PATH_ROTATION && per == 1) {
			/* on the base's key at the same time, if any; else on its own */
			struct img_chan *ic = &img->ch[i];
			const struct img_chan *bc = img_channel(base, ic->joint);
			for (uint32_t v = 0; v < keys; v++, at_q++) {
				long b = img_key(bc, ic->times[v]);
				int16_t *e = b >= 0 ? qd + 4 * at_d++ : q + 4 * at_a++;
				int sh = ic->joint < (uint32_t)nj ? shift[ic->joint] : 0;
				if (b >= 0)
					rotq_encode_on(ch->values + 4 * (size_t)v, bc->rot + 4 * b, e, sh);
				else
					rotq_encode(ch->values + 4 * (size_t)v, e, sh);
				mlod_pack_rotq_key(e, b >= 0 ? bc->rot + 4 * b : NULL, v > 0 ? ic->rot + 4 * (v - 1) : NULL,
				                   ic->rot + 4 * v);
			}
		} else if (ch->path == MLOD_PATH_ROTATION) {
			memcpy(rf + 4 * at_f, ch->values, sizeof(float) * 4 * 3 * keys);
			at_f += 3 * (size_t)keys;
		} else if (per == 3) {
			memcpy(v3 + 3 * at_v, ch->values, sizeof(float) * 3 * per * keys);
			at_v += (size_t)per * keys;
		} else {
			/* on the base's key at the same time, if any: the bit
			 * patterns' differences ('VECD'); else as they are */
			struct img_chan *ic = &img->ch[i];
			const struct img_chan *bc = NULL;
			for (int j = 0; base && j < base->n; j++)
				if (base->ch[j].joint == ic->joint && base->ch[j].path == ic->path &&
				    base->ch[j].interp != MLOD_INTERP_CUBICSPLINE)
					bc = &base->ch[j];
			/* a translation on its joint's grid (rotq_shifts), if any */
			int e = ch->path == MLOD_PATH_TRANSLATION && ic->joint < (uint32_t)nj ? tgrid[ic->joint] : INT_MIN;
			for (size_t c = 0; c < 3 * (size_t)keys; c++)
				ic->vec[c] = e == INT_MIN ? ch->values[c] : (float)ldexp(rint(ldexp((double)ch->values[c], -e)), e);
			for (uint32_t v = 0; v < keys; v++) {
				long b = img_key(bc, ic->times[v]);
				for (int c = 0; c < 3; c++) {
					uint32_t a, bb;
					memcpy(&a, ic->vec + 3 * (size_t)v + c, 4);
					if (b >= 0) {
						memcpy(&bb, bc->vec + 3 * b + c, 4);
						vd[3 * at_vd + c] = a - bb;
					} else {
						v3[3 * at_v + c] = ic->vec[3 * (size_t)v + c];
					}
				}
				if (b >= 0)
					at_vd++;
				else
					at_v++;
			}
		}
	}
	free(shift);
	free(tgrid);
	cb_add(&cb, MLOD_STREAM_ROTQ, (uint32_t)at_a, 8, q, 0);
	cb_add(&cb, MLOD_STREAM_ROTD, (uint32_t)at_d, 8, qd, 0);
	cb_add(&cb, MLOD_STREAM_ROTF, (uint32_t)nf, 16, rf, 0);
	cb_add(&cb, MLOD_STREAM_VEC3, (uint32_t)at_v, 12, v3, 0);
	cb_add(&cb, MLOD_STREAM_VECD, (uint32_t)at_vd, 12, vd, 0);
	free(q);
	free(qd);
	free(vd);
	free(rf);
	free(v3);
	mlod_result r = cb_finish(&cb, x->opt->codec, out, MLOD_CHUNK_MOTION, MLOD_LAYER_MOTION, k, item, error, x->err);
	if (r == MLOD_OK && base)
		out->c[out->n - 1].flags = MLOD_PACK_CHUNK_NESTED;
	return r;
}

/* Per clip, whether its MOTION chunks (levels A - 1 to 0) store fewer
 * bytes with the rotation lattice shifts or without (the shifts change
 * the keys' bases and their sign choices, which can cost more than they
 * save). Sets no_shifts where they do not pay. */
static int img_as_read(const motion_img *img, const mlod_clip *clip);
static double img_error(struct ctx *x, int q, const mlod_clip *clip, const motion_img *img, mlod_error *err);

/* Encodes clip q's MOTION chunks (levels A - 1 to 0) as the pack will:
 * *bytes gets their stored bytes, and toc (not NULL) each level's TOC
 * error as the chunk loop of mlod_pack_write states it (0 first). */
static mlod_result motion_trial(struct ctx *x, int A, int q, size_t *bytes, double *toc)
{
	motion_img img[2] = {{0, NULL}, {0, NULL}};
	mlod_result r = MLOD_OK;
	*bytes = 0;
	for (int k = A - 1; r == MLOD_OK && k >= 0; k--) {
		chunks c = {0};
		const mlod_clip *cl = k == 0 ? x->clips[q].level0 : x->clips[q].clip[k - 1];
		float e = k == 0 ? x->clips[q].error0 : x->clips[q].error[k - 1];
		r = motion_chunk(x, cl, k, q, e, k + 1 < A ? &img[!(k & 1)] : NULL, &img[k & 1], &c);
		for (int i = 0; i < c.n; i++)
			*bytes += c.c[i].size, free(c.c[i].data);
		free(c.c);
		if (r == MLOD_OK && toc) {
			double me = e > 0.0f ? img_error(x, q, cl, &img[k & 1], x->err) : 0.0;
			if (me < 0)
				r = MLOD_ERR_NOMEM;
			toc[k] = (float)me > e ? (double)(float)me : (double)e;
		}
	}
	motion_img_free(&img[0]), motion_img_free(&img[1]);
	return r;
}

/* Clip q's levels made again (motion_hold) as motion_level0 and
 * motion_levels make them: with chains bit 0, level 0 within b0 (0: the
 * clip as read), or the clip as read where the level would not have fewer
 * keys; with bit 1, levels 1 to count within b[0] to b[count - 1], each
 * from the one before (the nested levels of lib/motion); a level that
 * meets no bound repeats the finer one. The levels from count to A - 2
 * repeat the coarsest. */
static mlod_result levels_remake(struct ctx *x, int q, int A, int chains, double b0, const double *b)
{
	const mlod_character *c = &x->v;
	struct clip_levels *cl = &x->clips[q];
	mlod_motion_level lv[MLOD_PACK_MAX_MOTION_LEVELS + 1];
	memset(lv, 0, sizeof lv);
	mlod_motion_options mo = {0};
	mo.point_distance = motion_point_distance(x);
	mo.precision = MLOD_MOTION_PRECISION_FULL;
	static const mlod_motion_method methods[2] = {MLOD_MOTION_FRAMES, MLOD_MOTION_KEYS};
	mlod_result r = MLOD_OK;
	for (int chain = 0; r == MLOD_OK && chain < 2; chain++) {
		int n = !(chains >> chain & 1) ? 0 : chain == 0 ? b0 > 0.0 : cl->count;
		mlod_motion *m[2] = {NULL, NULL};
		for (int i = 0; r == MLOD_OK && n > 0 && i < 2; i++)
			r = i == 0 ? mlod_motion_create(c, q, &mo, &m[i], x->err) : mlod_motion_create_like(m[0], &m[i], x->err);
		for (int k = 0; r == MLOD_OK && k < n; k++) {
			mlod_motion_level *l = &lv[chain == 0 ? 0 : k + 1];
			mlod_error why = {0};
			mlod_result e = mlod_motion_next_level_best(m, methods, 2, MLOD_MOTION_MAX_ERROR, chain == 0 ? b0 : b[k], l,
			                                            &why);
			if (e == MLOD_ERR_LIMIT) {
				memset(l, 0, sizeof *l);
			} else if (e != MLOD_OK) {
				if (x->err)
					*x->err = why;
				r = e;
			}
		}
		for (int i = 0; i < 2; i++)
			mlod_motion_free(m[i]);
	}
	if (r == MLOD_OK && lv[0].clip.channels && !(lv[0].keys < mlod_clip_key_count(&c->clips[q])))
		mlod_motion_level_free(&lv[0]);
	for (int k = 0; k <= MLOD_PACK_MAX_MOTION_LEVELS; k++) {
		if (r != MLOD_OK) {
			mlod_motion_level_free(&lv[k]);
		} else if (chains >> (k > 0) & 1) {
			mlod_motion_level_free(&cl->remade[k]);
			cl->remade[k] = lv[k];
		}
	}
	if (r != MLOD_OK)
		return r;
	if (chains & 1) {
		int l0 = cl->remade[0].clip.channels != NULL;
		cl->level0 = l0 ? &cl->remade[0].clip : &c->clips[q];
		cl->error0 = l0 ? (float)cl->remade[0].error.max : 0.0f;
	}
	cl->chain_remade |= (chains & 2) != 0;
	for (int k = 0; k < A - 1; k++) { /* repeats point at the finer level again (it may be new) */
		const mlod_motion_level *l = &cl->remade[k + 1];
		if (k < cl->count && !cl->chain_remade) {
			continue;
		} else if (k < cl->count && l->clip.channels) {
			cl->clip[k] = &l->clip;
			cl->error[k] = (float)l->error.max;
		} else {
			cl->clip[k] = k ? cl->clip[k - 1] : cl->level0;
			cl->error[k] = k ? cl->error[k - 1] : cl->error0;
		}
	}
	return MLOD_OK;
}

/* Chooses clip q's shifts (no_shifts): with them or without, whichever
 * stores fewer bytes; toc (not NULL) gets the levels' TOC errors with
 * that choice (motion_trial). */
static mlod_result motion_shifts_pick(struct ctx *x, int A, int q, double *toc)
{
	size_t bytes[2] = {0, 0};
	for (int pass = 0; pass < 2; pass++) {
		x->clips[q].no_shifts = pass;
		mlod_result r = motion_trial(x, A, q, &bytes[pass], pass == 0 ? toc : NULL);
		if (r != MLOD_OK)
			return r;
	}
	x->clips[q].no_shifts = bytes[1] <= bytes[0];
	if (toc && x->clips[q].no_shifts)
		return motion_trial(x, A, q, &bytes[1], toc);
	return MLOD_OK;
}

/* Every level of clip q with a bound (clip_levels.bound0 and bound)
 * holds it as the reader returns its keys (its TOC error): while one
 * measures above its bound, the levels are made again (levels_remake),
 * that level's within its bound less 1.05 times the excess (twice that
 * each round, at least a quarter of the bound before), and the shifts
 * chosen again (they follow the smallest TOC error). After 8 rounds a
 * level 0 still above its bound is the clip as read (TOC error 0). */
static mlod_result motion_hold(struct ctx *x, int A, int q)
{
	struct clip_levels *cl = &x->clips[q];
	double b0 = cl->bound0, b[MLOD_PACK_MAX_MOTION_LEVELS], toc[MLOD_PACK_MAX_MOTION_LEVELS + 1];
	int hold = b0 > 0.0;
	for (int k = 0; k < MLOD_PACK_MAX_MOTION_LEVELS; k++)
		b[k] = cl->bound[k], hold |= k < cl->count && b[k] > 0.0;
	mlod_result r = motion_shifts_pick(x, A, q, hold ? toc : NULL);
	for (int round = 0; r == MLOD_OK && hold; round++) {
		int over = cl->bound0 > 0.0 && toc[0] > cl->bound0;
		for (int k = 0; k < cl->count && k < A - 1; k++)
			over |= cl->bound[k] > 0.0 && toc[k + 1] > cl->bound[k];
		if (!over)
			break;
		int chains = 0;
		if (round == 8) {
			if (!(cl->bound0 > 0.0 && toc[0] > cl->bound0))
				break;
			b0 = 0.0, hold = 0, chains = 1;
		} else {
			if (cl->bound0 > 0.0 && toc[0] > cl->bound0) {
				double next = b0 - ldexp(1.05, round) * (toc[0] - cl->bound0);
				b0 = next > 0.25 * b0 ? next : 0.25 * b0;
				chains |= 1;
			}
			for (int k = 0; k < cl->count && k < A - 1; k++)
				if (cl->bound[k] > 0.0 && toc[k + 1] > cl->bound[k]) {
					double next = b[k] - ldexp(1.05, round) * (toc[k + 1] - cl->bound[k]);
					b[k] = next > 0.25 * b[k] ? next : 0.25 * b[k];
					chains |= 2;
				}
		}
		if ((r = levels_remake(x, q, A, chains, b0, b)) == MLOD_OK)
			r = motion_shifts_pick(x, A, q, hold ? toc : NULL);
	}
	return r;
}

static mlod_result motion_shift_choice(struct ctx *x, int A)
{
	for (int q = 0; q < x->v.clip_count; q++) {
		/* A pack's level 0 and its levels (an input of mlod-pack -x):
		 * their keys are on that pack's lattices and grids already. The
		 * shifts chosen again are kept where every level's keys go back
		 * exactly as read (the same shifts, or coarser ones the keys
		 * happen to sit on), else none: each level keeps the error that
		 * pack measured, never rounded a second time. */
		if (x->clips[q].packed) {
			motion_img img[2] = {{0, NULL}, {0, NULL}};
			int same = 1;
			x->clips[q].no_shifts = 0;
			for (int k = A - 1; same && k >= 0; k--) {
				chunks c = {0};
				const mlod_clip *cl = k == 0 ? x->clips[q].level0 : x->clips[q].clip[k - 1];
				mlod_result r = motion_chunk(x, cl, k, q, k == 0 ? x->clips[q].error0 : x->clips[q].error[k - 1],
				                             k + 1 < A ? &img[!(k & 1)] : NULL, &img[k & 1], &c);
				for (int i = 0; i < c.n; i++)
					free(c.c[i].data);
				free(c.c);
				if (r != MLOD_OK) {
					motion_img_free(&img[0]), motion_img_free(&img[1]);
					return r;
				}
				same = img_as_read(&img[k & 1], cl);
			}
			motion_img_free(&img[0]), motion_img_free(&img[1]);
			x->clips[q].no_shifts = !same;
			continue;
		}
		mlod_result r = motion_hold(x, A, q);
		if (r != MLOD_OK)
			return r;
	}
	return MLOD_OK;
}

/* The largest point error (mlod_motion_point_error, the point distance's
 * radius) of every joint of clip as the reader returns it (img: its keys
 * as the MOTION chunk holds them) against clip q as read, at its common
 * timeline frames and midpoints, rounded up to 8 significant bits (at
 * most 0.4% more), so that the float noise of an input read two ways
 * gives the same TOC error (cli/pack_bvh_stages; RESULTS Run 85); -1
 * when out of memory. The clip as read is posed once per clip (kept in
 * clip_levels: motion_hold measures each level round after round). */
static double img_error(struct ctx *x, int q, const mlod_clip *clip, const motion_img *img, mlod_error *err)
{
	const mlod_skeleton *sk = &x->v.skeleton;
	const mlod_clip *orig = &x->v.clips[q];
	struct clip_levels *cq = &x->clips[q];
	int nj = sk->joint_count;
	if (nj <= 0 || orig->channel_count <= 0 || img->n != clip->channel_count)
		return 0.0;
	if (!cq->world) {
		mlod_motion_options mo = {0};
		mlod_clip common;
		if (mlod_motion_common_clip(orig, &mo, &common, NULL, err) != MLOD_OK)
			return -1.0;
		int frames = common.channel_count > 0 ? common.channels[0].key_count : 0;
		int n = frames > 0 ? 2 * (frames - 1) + 1 : 0;
		float *t = malloc(sizeof *t * ((size_t)n + 1));
		mlod_mat4 *w = malloc(sizeof *w * ((size_t)n * nj + 1));
		mlod_trs *la = malloc(sizeof *la * (size_t)nj);
		if (!t || !w || !la) {
			free(t), free(w), free(la);
			mlod_clip_free(&common);
			mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
			return -1.0;
		}
		if (n > 0)
			mlod_motion_sample_times(common.channels[0].times, frames, 2, t);
		for (int i = 0; i < n; i++) {
			mlod_pose_rest(sk, la);
			mlod_clip_sample(orig, t[i], la);
			mlod_pose_world(sk, la, w + (size_t)i * nj);
		}
		free(la);
		mlod_clip_free(&common);
		cq->at = t, cq->world = w, cq->samples = n;
	}
	int n = cq->samples;
	const float *t = cq->at;
	mlod_clip dec = *clip;
	dec.channels = calloc((size_t)clip->channel_count + 1, sizeof *dec.channels);
	mlod_trs *lb = malloc(sizeof *lb * (size_t)nj);
	mlod_mat4 *wb = malloc(sizeof *wb * (size_t)nj);
	double worst = -1.0;
	if (!dec.channels || !lb || !wb) {
		mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
		goto done;
	}
	worst = 0.0;
	for (int i = 0; i < clip->channel_count && worst >= 0; i++) {
		const struct img_chan *ic = &img->ch[i];
		mlod_channel *d = &dec.channels[i];
		*d = clip->channels[i];
		d->short_values = 0;
		d->key_count = (int)ic->keys;
		d->times = ic->times;
		if (ic->rot) {
			if (!(d->values = malloc(sizeof *d->values * 4 * ic->keys)))
				worst = -1.0;
			for (size_t v = 0; d->values && v < 4 * (size_t)ic->keys; v++)
				d->values[v] = (float)(ic->rot[v] / 32767.0);
		} else if (ic->vec) {
			d->values = ic->vec;
		}
	}
	if (worst < 0) {
		mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
		goto done;
	}
	double pd = motion_point_distance(x);
	for (int i = 0; i < n; i++) {
		const mlod_mat4 *wa = cq->world + (size_t)i * nj;
		mlod_pose_rest(sk, lb);
		mlod_clip_sample(&dec, t[i], lb);
		mlod_pose_world(sk, lb, wb);
		for (int j = 0; j < nj; j++) {
			double e = mlod_motion_point_error(&wa[j], &wb[j], pd);
			if (!(e <= worst))
				worst = isfinite(e) ? e : INFINITY;
		}
	}
	if (worst > 0.0 && isfinite(worst)) {
		int ex = 0;
		frexp(worst, &ex);
		worst = ldexp(ceil(ldexp(worst, 8 - ex)), ex - 8);
	}
done:
	for (int i = 0; dec.channels && i < clip->channel_count; i++)
		if (img->ch[i].rot)
			free(dec.channels[i].values);
	free(dec.channels), free(lb), free(wb);
	return worst;
}

/* 1 when every non-cubic rotation and translation or scale key of the
 * MOTION chunk img describes is the key of clip as read (a rotation up to
 * its sign). */
static int img_as_read(const motion_img *img, const mlod_clip *clip)
{
	for (int i = 0; i < img->n; i++) {
		const struct img_chan *ic = &img->ch[i];
		const mlod_channel *ch = NULL;
		if (!ic->rot && !ic->vec)
			continue;
		for (int j = 0; !ch && j < clip->channel_count; j++)
			if ((uint32_t)clip->channels[j].joint == ic->joint && (uint32_t)clip->channels[j].path == ic->path &&
			    clip->channels[j].interp != MLOD_INTERP_CUBICSPLINE)
				ch = &clip->channels[j];
		if (!ch || (uint32_t)ch->key_count != ic->keys)
			return 0;
		for (uint32_t v = 0; ic->rot && v < ic->keys; v++) {
			int plus = 1, minus = 1;
			for (int c = 0; c < 4; c++) {
				float r = (float)ic->rot[4 * v + c] / 32767.0f, w = ch->values[4 * (size_t)v + c];
				plus &= r == w;
				minus &= -r == w;
			}
			if (!plus && !minus)
				return 0;
		}
		if (ic->vec && memcmp(ic->vec, ch->values, sizeof(float) * 3 * ic->keys) != 0)
			return 0;
	}
	return 1;
}

/* ------------------------------------------------------------------ */
/* Attributes the pack does not store                                  */
/* ------------------------------------------------------------------ */

/* An attribute name a part stores (mlod(5) MESH levels): POSITION,
 * NORMAL, TANGENT, TEXCOORD_0 to TEXCOORD_3 (MLOD_PACK_MAX_UV), COLOR_0,
 * JOINTS_n and WEIGHTS_n (the influences). */
static int known_attribute(const char *name)
{
	static const char *const sets[] = {"TEXCOORD_", "COLOR_", "JOINTS_", "WEIGHTS_"};
	static const long most[] = {MLOD_PACK_MAX_UV, 1, LONG_MAX, LONG_MAX};
	if (!strcmp(name, "POSITION") || !strcmp(name, "NORMAL") || !strcmp(name, "TANGENT"))
		return 1;
	for (size_t i = 0; i < sizeof sets / sizeof *sets; i++) {
		size_t n = strlen(sets[i]);
		if (!strncmp(name, sets[i], n) && name[n] >= '0' && name[n] <= '9') {
			char *d;
			long k = strtol(name + n, &d, 10);
			return *d == '\0' && k < most[i];
		}
	}
	return 0;
}

/* Notes each attribute of a triangle list that the pack does not store
 * (_ID, any other custom or unknown name, a fifth UV set, a second
 * colour set), from the document's primitives (lib/io lists them; the
 * DOC chunk drops them with the rest of level 0). Points, lines, strips
 * and fans stay whole in the DOC chunk: no note. */
static mlod_result note_unstored_attributes(struct ctx *x, const mlod_gltf *doc)
{
	for (int mesh = 0; doc && mesh < mlod_gltf_count(doc, MLOD_GLTF_MESH); mesh++)
		for (int p = 0;; p++) {
			char **names = NULL;
			int count = 0, mode = 4;
			mlod_error e = {0};
			mlod_result r = mlod_gltf_primitive_attributes(doc, mesh, p, &mode, &names, &count, &e);
			if (r == MLOD_ERR_NOMEM)
				return mlod_fail(x->err, r, "%s", e.message);
			if (r != MLOD_OK) /* past the mesh's last primitive */
				break;
			for (int k = 0; mode == 4 && k < count; k++)
				if (!known_attribute(names[k])) {
					char text[256];
					snprintf(text, sizeof text, "mesh %d primitive %d: attribute %s is not stored in the pack", mesh,
					         p, MLOD_QUOTED(names[k]));
					warn(x, text);
				}
			mlod_free(names);
		}
	return MLOD_OK;
}

/* Notes the skinned vertices whose weights are all 0 (glTF wants them to
 * sum to 1; the validator flags them): a pack's weights sum to 255, so
 * each goes on the skin's root joint (skin_root), which the vertex then
 * follows. */
static void note_unweighted(struct ctx *x)
{
	const mlod_character *c = x->in;
	for (int m = 0; m < c->mesh_count; m++) {
		int skin = -1;
		for (int i = 0; i < c->instance_count && skin < 0; i++)
			if (c->instances[i].mesh == m)
				skin = c->instances[i].skin;
		if (skin < 0 || skin >= c->skeleton.skin_count)
			continue;
		const mlod_mesh *mesh = &c->meshes[m];
		for (int p = 0; p < mesh->primitive_count; p++) {
			const mlod_primitive *pr = &mesh->primitives[p];
			int count = 0, first = -1;
			for (int v = 0; pr->weight_set_count > 0 && v < pr->vertex_count; v++) {
				int any = 0;
				for (int set = 0; set < pr->weight_set_count && !any; set++)
					for (int i = 0; i < 4; i++)
						any |= pr->weights[set][4 * (size_t)v + (size_t)i] > 0.0f;
				if (!any && count++ == 0)
					first = v;
			}
			if (count == 0)
				continue;
			const mlod_skin *sk = &c->skeleton.skins[skin];
			int root = sk->joint_count > 0 ? sk->joints[skin_root(&c->skeleton, skin)] : -1;
			const char *name = root >= 0 && c->skeleton.joints[root].name ? c->skeleton.joints[root].name : "";
			char text[256];
			int g = mesh->gltf_index >= 0 ? mesh->gltf_index : m;
			if (count == 1)
				snprintf(text, sizeof text, "mesh %d primitive %d: vertex %d has no weight: it follows the skin's "
				         "root joint %s", g, p, first, MLOD_QUOTED(name));
			else
				snprintf(text, sizeof text, "mesh %d primitive %d: %d vertices have no weight (vertex %d the first): "
				         "they follow the skin's root joint %s", g, p, count, first, MLOD_QUOTED(name));
			warn(x, text);
		}
	}
}

/* ------------------------------------------------------------------ */
/* The pack                                                            */
/* ------------------------------------------------------------------ */

/* The DOC's asset extras.mlod when joint nodes' TRS went, by mode
 * (mlod_gltf_drop_node_trs); mlod_pack_unpack reads it back. */
static const char *const trs_marks[3] = {"{\"doc_trs\":0}", "{\"doc_trs\":1}", "{\"doc_trs\":2}"};

/* A skin's inverse bind matrices are all identities (glTF's default). */
static int identity_binds(const mlod_skin *sk)
{
	mlod_mat4 id = mlod_mat4_identity();
	for (int j = 0; sk->inverse_bind && j < sk->joint_count; j++)
		if (memcmp(&sk->inverse_bind[j], &id, sizeof id) != 0)
			return 0;
	return 1;
}

/* Whether glTF index g is among the n in list. */
static int listed(const int *list, int n, int g)
{
	for (int i = 0; i < n; i++)
		if (list[i] == g)
			return 1;
	return 0;
}

/* The copy of the document that the DOC chunk strips. A BVH's document,
 * which mlod_load builds in memory, is copied as the glb a stage writes of
 * it is read (written and read back): stripped, a document that was read
 * keeps the top-level arrays its edits empty ("accessors": [] ...), one
 * built writes none, and the walk packed alone and after mlod-label had
 * DOC chunks of 614 and 649 bytes. */
static mlod_result doc_copy(const struct ctx *x, const mlod_gltf *doc, mlod_gltf **copy, mlod_error *err)
{
	if (x->format != MLOD_FORMAT_BVH)
		return mlod_gltf_copy(doc, copy, err);
	void *glb = NULL;
	size_t size = 0;
	mlod_result r = mlod_gltf_write(doc, 1, &glb, &size, err);
	if (r == MLOD_OK)
		r = mlod_gltf_read(glb, size, NULL, copy, err);
	mlod_free(glb);
	return r;
}

/* The stripped DOC without what the other chunks hold (mlod(5) DOC):
 * the inverse bind matrices of the packed skins (SKEL holds them; not
 * identities), the joint nodes' translation, rotation and scale that are
 * SKEL's rest TRS at f32 (not the defaults), the stages' records
 * (extras "mlod", but for a BVH's End Site marks, "end_site", which are
 * the input's), and a piped input's levels: its level animations, and
 * its level nodes (MSFT_lod entries, nodes with a level skin), level
 * skins and level meshes when they are the last of their kind (as the
 * stages append them; else they stay, with a note). */
static mlod_result doc_dedupe(struct ctx *x, mlod_gltf *copy, int whole, mlod_error *err)
{
	const mlod_character *c = x->in;
	const mlod_skeleton *s = &c->skeleton;
	mlod_result r = MLOD_OK;
	for (int i = 0; r == MLOD_OK && !whole && i < x->v.skeleton.skin_count; i++) {
		const mlod_skin *sk = &x->v.skeleton.skins[i];
		if (sk->gltf_index >= 0 && x->v.skeleton.joint_count > 0 && !identity_binds(sk))
			r = mlod_gltf_drop_inverse_binds(copy, sk->gltf_index, err);
	}
	/* The joints' nodes' rest TRS (SKEL's JNTS hold it, as f32) when their
	 * numbers are those of the f32 values (mode 0), their shortest
	 * decimals (1) or their 15 significant digits (2), whichever more
	 * parts use (the asset's extras.mlod.doc_trs says which). */
	int parts[3] = {0, 0, 0}, nodes = mlod_gltf_count(copy, MLOD_GLTF_NODE);
	for (int mode = 0; mode < 3 && !whole; mode++)
		for (int j = 0; r == MLOD_OK && j < x->v.skeleton.joint_count; j++) {
			const mlod_joint *q = &x->v.skeleton.joints[j];
			int d = 0;
			if (q->node >= 0 && q->node < nodes)
				r = mlod_gltf_drop_node_trs(copy, q->node, &q->rest, mode, 0, &d, err);
			parts[mode] += (d & 1) + (d >> 1 & 1) + (d >> 2 & 1);
		}
	int trs_mode = parts[1] > parts[0] ? 1 : 0;
	trs_mode = parts[2] > parts[trs_mode] ? 2 : trs_mode;
	for (int j = 0; r == MLOD_OK && parts[trs_mode] > 0 && j < x->v.skeleton.joint_count; j++) {
		const mlod_joint *q = &x->v.skeleton.joints[j];
		if (q->node >= 0 && q->node < nodes)
			r = mlod_gltf_drop_node_trs(copy, q->node, &q->rest, trs_mode, 1, NULL, err);
	}
	static const mlod_gltf_kind kinds[] = {MLOD_GLTF_NODE, MLOD_GLTF_SKIN, MLOD_GLTF_SCENE, MLOD_GLTF_MESH,
	                                       MLOD_GLTF_ANIMATION};
	for (size_t k = 0; r == MLOD_OK && k < sizeof kinds / sizeof *kinds; k++)
		for (int i = 0; r == MLOD_OK && i < mlod_gltf_count(copy, kinds[k]); i++)
			r = mlod_gltf_remove_extra(copy, kinds[k], i, "mlod", "end_site", err);
	if (r == MLOD_OK)
		r = mlod_gltf_remove_extra(copy, MLOD_GLTF_ASSET, 0, "mlod", "end_site", err);
	if (r == MLOD_OK && parts[trs_mode] > 0)
		r = mlod_gltf_set_extra(copy, MLOD_GLTF_ASSET, 0, "mlod", trs_marks[trs_mode], err);
	/* The level animations (those strip_levels left: morph weights, other
	 * nodes' channels); a document whose indices hold (whole), from the
	 * last animation down while they are levels. */
	int anims = mlod_gltf_count(copy, MLOD_GLTF_ANIMATION), dropped = 0, levels = 0;
	for (int a = anims - 1; r == MLOD_OK && a >= 0; a--) {
		int level = 0;
		for (int i = 0; !level && i < c->clip_count; i++) {
			int in_v = 0;
			for (int q = 0; q < x->v.clip_count; q++)
				in_v |= x->v.clips[q].name == c->clips[i].name;
			level = !in_v && c->clips[i].name && mlod_gltf_find_animation(copy, c->clips[i].name, 0) == a;
		}
		levels += level;
		if (level && (!whole || a + dropped + 1 == anims)) {
			r = mlod_gltf_drop_animation(copy, a, err);
			dropped++;
		}
	}
	if (r == MLOD_OK && dropped < levels)
		note(x, "the document chunk keeps some of the input's level animations: they are not its last animations");
	if (r != MLOD_OK || !x->doc)
		return r;
	/* The level nodes (every MSFT_lod entry), their meshes, level skins. */
	int nn = mlod_gltf_count(x->doc, MLOD_GLTF_NODE), ns = mlod_gltf_count(x->doc, MLOD_GLTF_SKIN),
	    nm = mlod_gltf_count(x->doc, MLOD_GLTF_MESH);
	int *ln = malloc(sizeof(int) * ((size_t)nn + 1)), *lm = malloc(sizeof(int) * ((size_t)nn + 1));
	int *ls = malloc(sizeof(int) * ((size_t)s->skin_count + 1)), nln = 0, nlm = 0, nls = 0;
	if (!ln || !lm || !ls) {
		free(ln), free(lm), free(ls);
		return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
	}
	for (int n = 0; r == MLOD_OK && n < nn; n++) {
		int ids[64], count = 0;
		mlod_error ignored = {0};
		if (mlod_gltf_node_lod(x->doc, n, ids, 64, &count, &ignored) != MLOD_OK)
			continue;
		for (int i = 0; i < count && i < 64; i++) {
			int mesh = -1, skin = -1;
			if (ids[i] == n || listed(ln, nln, ids[i]))
				continue;
			ln[nln++] = ids[i];
			if (mlod_gltf_node_refs(x->doc, ids[i], &mesh, &skin, &ignored) == MLOD_OK && mesh >= 0 &&
			    !listed(lm, nlm, mesh))
				lm[nlm++] = mesh;
		}
	}
	for (int i = 0; i < s->skin_count; i++)
		if (x->view_skin[i] < 0 && s->skins[i].gltf_index >= 0)
			ls[nls++] = s->skins[i].gltf_index;
	/* and the nodes a level skin skins (mlod-skelgraph's skeleton level
	 * nodes), with their meshes */
	for (int n = 0; nls > 0 && n < nn; n++) {
		int mesh = -1, skin = -1;
		mlod_error ignored = {0};
		if (mlod_gltf_node_refs(x->doc, n, &mesh, &skin, &ignored) != MLOD_OK || !listed(ls, nls, skin))
			continue;
		if (!listed(ln, nln, n))
			ln[nln++] = n;
		if (mesh >= 0 && !listed(lm, nlm, mesh))
			lm[nlm++] = mesh;
	}
	/* Each kind from its first level one on, when all of those are. */
	int from[3] = {nn, ns, nm}, *lists[3] = {ln, ls, lm}, counts[3] = {nln, nls, nlm}, totals[3] = {nn, ns, nm};
	for (int k = 0; k < 3; k++) {
		int f = totals[k];
		while (f > 0 && listed(lists[k], counts[k], f - 1))
			f--;
		from[k] = f;
	}
	/* a mesh a kept node still uses stays (drop_tail refuses it) */
	if (from[0] < nn || from[1] < ns || from[2] < nm) {
		mlod_error derr = {0};
		mlod_result dr = mlod_gltf_drop_tail(copy, from[0], from[1], from[2], &derr);
		if (dr == MLOD_ERR_UNSUPPORTED) {
			char text[MLOD_ERROR_MESSAGE_SIZE + 64];
			snprintf(text, sizeof text, "the document chunk keeps the input's level nodes: %s", derr.message);
			note(x, text);
		} else if (dr != MLOD_OK) {
			r = mlod_fail(err, dr, "%s", derr.message);
		}
	}
	if (r == MLOD_OK && (nln > 0 && from[0] > nn - nln))
		note(x, "the document chunk keeps some of the input's level nodes: they are not its last nodes");
	free(ln), free(lm), free(ls);
	return r;
}

void mlod_pack_options_default(mlod_pack_options *opt)
{
	static const double ratios[] = {MLOD_MESH_RATIOS_DEFAULT}, bounds[] = {MLOD_PACK_MOTION_BOUNDS_DEFAULT};
	memset(opt, 0, sizeof *opt);
	opt->codec = MLOD_CODEC_MESHOPT;
	opt->entropy = MLOD_ENTROPY_ZSTD;
	opt->skel_max_error = MLOD_SKEL_MAX_ERROR_DEFAULT;
	opt->ratio_count = (int)(sizeof ratios / sizeof *ratios);
	memcpy(opt->ratios, ratios, sizeof ratios);
	opt->mesh_max_error = -1.0;
	opt->position_bits = MLOD_PACK_POSITION_BITS_DEFAULT;
	opt->normal_bits = MLOD_PACK_NORMAL_BITS_DEFAULT;
	opt->uv_bits = MLOD_PACK_UV_BITS_DEFAULT;
	opt->coarse_share = MLOD_PACK_COARSE_SHARE;
	opt->motion_bound_count = (int)(sizeof bounds / sizeof *bounds);
	opt->motion_level0_error = MLOD_PACK_MOTION_LEVEL0_DEFAULT;
	opt->motion_level0_percent = 1;
	for (int i = 0; i < opt->motion_bound_count; i++) {
		opt->motion_bounds[i] = bounds[i];
		opt->motion_percent[i] = 1;
	}
}

static void ctx_free(struct ctx *x)
{
	mesh_parts_free(x);
	for (int k = 0; k < MLOD_SKEL_MAX_LEVELS; k++) {
		free(x->kept[k]);
		free(x->remap[k]);
	}
	for (int k = 0; k < MLOD_MESH_MAX_LEVELS; k++)
		free(x->level_node[k]);
	if (x->has_ML)
		mlod_mesh_levels_free(&x->ML);
	for (int i = 0; i < x->owned_count; i++)
		mlod_motion_level_free(&x->owned_levels[i]);
	free(x->owned_levels);
	for (int q = 0; x->level0_owned && q < x->v.clip_count; q++)
		mlod_motion_level_free(&x->level0_owned[q]);
	free(x->level0_owned);
	for (int q = 0; x->clips && q < x->v.clip_count; q++) {
		for (int k = 0; k <= MLOD_PACK_MAX_MOTION_LEVELS; k++)
			mlod_motion_level_free(&x->clips[q].remade[k]);
		free(x->clips[q].shift), free(x->clips[q].tgrid), free(x->clips[q].at), free(x->clips[q].world);
	}
	for (int i = 0; x->motion_imgs && i < 2 * x->v.clip_count; i++)
		motion_img_free(&x->motion_imgs[i]);
	free(x->motion_imgs);
	free(x->clips);
	free(x->world);
	free(x->view_skin);
	free(x->v.skeleton.skins);
	free(x->v.instances);
	free(x->v.clips);
	mlod_record_free(&x->rec);
}

static uint64_t layer_bytes(const chunks *ch, int layer, int raw)
{
	uint64_t n = 0;
	for (int i = 0; i < ch->n; i++)
		if (ch->c[i].layer == layer)
			n += raw ? ch->c[i].raw : ch->c[i].size;
	return n;
}

/* Level 0 is the finest motion level: its bound (motion_level0_error)
 * must be below the smallest of the coarser levels' (motion_bounds),
 * each in units or % of the character's height. */
static mlod_result check_level0_bound(const mlod_pack_options *o, const mlod_character *c, mlod_error *err)
{
	if (o->lossless_motion || o->no_motion_levels || c->clip_count == 0 || !(o->motion_level0_error > 0.0))
		return MLOD_OK;
	double h = c->skeleton.joint_count > 0 ? mlod_skeleton_height(&c->skeleton) : 0.0, e1 = 0.0;
	double e0 = o->motion_level0_percent ? o->motion_level0_error * h / 100.0 : o->motion_level0_error;
	int first = -1;
	for (int b = 0; b < o->motion_bound_count; b++) {
		double e = o->motion_percent[b] ? o->motion_bounds[b] * h / 100.0 : o->motion_bounds[b];
		if (first < 0 || e < e1)
			first = b, e1 = e;
	}
	if (!(first >= 0 && e0 >= e1))
		return MLOD_OK;
	return mlod_fail(err, MLOD_ERR_INVALID_ARG,
	                 "motion level 0's bound %g%s (%.4g units) is not below the first motion level's bound, "
	                 "%g%s (%.4g units of a height of %.4g): level 0 is the finest",
	                 o->motion_level0_error, o->motion_level0_percent ? "%" : "", e0, o->motion_bounds[first],
	                 o->motion_percent[first] ? "%" : "", e1, h);
}

mlod_result mlod_pack_write(const mlod_gltf *doc, const mlod_character *c, mlod_format format, const void *input,
                            size_t input_size, const mlod_pack_options *opt, void **out, size_t *out_size,
                            mlod_pack_stats *stats, mlod_error *err)
{
	struct ctx x;
	mlod_pack_stats local_stats;
	chunks body = {0}, head = {0};
	mlod_result r;
	double t0;
	if (!c || !opt || !out || !out_size)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_pack_write: c, opt, out and out_size must not be NULL");
	*out = NULL;
	*out_size = 0;
	if (opt->codec != MLOD_CODEC_NONE && opt->codec != MLOD_CODEC_MESHOPT && opt->codec != MLOD_CODEC_DRACO)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "unknown codec %d", (int)opt->codec);
	if (opt->entropy != MLOD_ENTROPY_NONE && opt->entropy != MLOD_ENTROPY_ZSTD)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "unknown entropy stage %d", opt->entropy);
	if ((r = check_level0_bound(opt, c, err)) != MLOD_OK)
		return r;
	memset(&x, 0, sizeof x);
	x.doc = doc;
	x.in = c;
	x.format = format;
	/* Draco codes the MESH chunks; the other chunks take meshopt. */
	mlod_pack_options mopt = *opt;
	x.draco = opt->codec == MLOD_CODEC_DRACO;
	if (x.draco)
		mopt.codec = MLOD_CODEC_MESHOPT;
	x.opt = &mopt;
	x.st = stats ? stats : &local_stats;
	x.err = err;
	memset(x.st, 0, sizeof *x.st);
	if (c->notes && *c->notes) /* the reader's, first */
		note(&x, c->notes);
	if (doc && (r = mlod_record_read(doc, &x.rec, err)) != MLOD_OK)
		return r;
	if ((r = make_view(&x)) != MLOD_OK || (r = measure(&x)) != MLOD_OK)
		goto done;
	if (mlod_mesh_triangle_primitives(&x.v) > 0 && (r = note_unstored_attributes(&x, doc)) != MLOD_OK)
		goto done;
	note_unweighted(&x);

	/* The levels of each layer. */
	t0 = now_seconds();
	if ((r = skeleton_levels(&x)) != MLOD_OK)
		goto done;
	x.st->skeleton.seconds = now_seconds() - t0;
	t0 = now_seconds();
	if ((r = mesh_levels(&x)) != MLOD_OK)
		goto done;
	x.st->mesh.seconds = now_seconds() - t0;
	t0 = now_seconds();
	if ((r = motion_levels(&x)) != MLOD_OK)
		goto done;
	int A = 0; /* motion levels counting level 0 */
	for (int q = 0; q < x.v.clip_count; q++)
		A = x.clips[q].count + 1 > A ? x.clips[q].count + 1 : A;
	for (int q = 0; q < x.v.clip_count; q++) /* a clip with fewer levels repeats its coarsest */
		for (int k = x.clips[q].count; k < A - 1; k++) {
			x.clips[q].clip[k] = k ? x.clips[q].clip[k - 1] : x.clips[q].level0;
			x.clips[q].error[k] = k ? x.clips[q].error[k - 1] : x.clips[q].error0;
		}
	if ((r = motion_shift_choice(&x, A)) != MLOD_OK)
		goto done;
	x.st->motion.seconds = now_seconds() - t0;
	if (!(x.motion_imgs = calloc(2 * (size_t)x.v.clip_count + 1, sizeof *x.motion_imgs))) {
		r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
		goto done;
	}

	/* The chunks after INFO, in file order. */
	int S = 1 + x.skel_count;
	int M = mlod_mesh_triangle_primitives(&x.v) > 0 ? 1 + x.mesh_count : 0;
	int parts0 = 0;
	t0 = now_seconds();
	if ((r = skeleton_chunk(&x, &body)) != MLOD_OK)
		goto done;
	for (int k = S - 1; k >= 1; k--)
		if ((r = skel_level_chunk(&x, k, &body)) != MLOD_OK)
			goto done;
	x.st->skeleton.seconds += now_seconds() - t0;
	/* Rank i from the coarsest: mesh level M - 1 - i, then motion level
	 * A - 1 - i of every clip, so that the coarsest of both layers come
	 * first however many levels each has (mlod(5) Chunk order). */
	int top = (M > A ? M : A) - 1;
	for (int i = 0; i <= top; i++) {
		int mk = M - 1 - i, k = A - 1 - i;
		t0 = now_seconds();
		if (mk >= 0) {
			int np = 0;
			if ((r = mesh_chunk(&x, mk, &body, &np)) != MLOD_OK)
				goto done;
			if (mk == 0)
				parts0 = np;
		}
		x.st->mesh.seconds += now_seconds() - t0;
		t0 = now_seconds();
		for (int q = 0; k >= 0 && q < x.v.clip_count; q++) {
			const mlod_clip *cl = k == 0 ? x.clips[q].level0 : x.clips[q].clip[k - 1];
			motion_img *mi = &x.motion_imgs[2 * q + (k & 1)], *base = k + 1 < A ? &x.motion_imgs[2 * q + !(k & 1)] : NULL;
			if ((r = motion_chunk(&x, cl, k, q, k == 0 ? x.clips[q].error0 : x.clips[q].error[k - 1], base, mi,
			                      &body)) != MLOD_OK)
				goto done;
			/* The TOC error of a level with one (not the clip as read):
			 * the level's as the reader returns it (its keys on the
			 * lattices and grids), when above that of the values given
			 * (mlod(5) QUANTISATION), and its switch distance with it.
			 * A pack's level 0 and its levels (mlod-pack -x) keep that
			 * pack's errors: their keys come back as read
			 * (motion_shift_choice), measured against its level 0. */
			if (body.c[body.n - 1].error > 0.0f && !x.clips[q].packed) {
				double me = img_error(&x, q, cl, mi, err);
				if (me < 0) {
					r = MLOD_ERR_NOMEM;
					goto done;
				}
				if ((float)me > body.c[body.n - 1].error) {
					body.c[body.n - 1].error = (float)me;
					body.c[body.n - 1].distance = k > 0 ? mlod_pack_switch_distance((float)me) : 0.0f;
					if (!isfinite((float)me) || !isfinite(body.c[body.n - 1].distance)) {
						r = mlod_fail(err, MLOD_ERR_PARSE,
						              "MOTION level %d of clip %d: error %g as read back is not finite or gives a "
						              "switch distance that is not (are the input's coordinates too large?)",
						              k, q, me);
						goto done;
					}
				}
			}
			x.clips[q].toc[k] = body.c[body.n - 1].error;
			/* A reduced level 0 that stores more than the clip as read
			 * gives way to it (error 0). */
			if (k == 0 && cl != &x.v.clips[q]) {
				chunks alt = {0};
				motion_img alt_img = {0};
				r = motion_chunk(&x, &x.v.clips[q], 0, q, 0.0f, base, &alt_img, &alt);
				if (r == MLOD_OK && alt.c[0].size < body.c[body.n - 1].size) {
					x.clips[q].toc[0] = 0.0f;
					free(body.c[body.n - 1].data);
					body.c[body.n - 1] = alt.c[0];
					alt.n = 0;
					x.clips[q].level0 = &x.v.clips[q];
					x.clips[q].error0 = 0.0f;
				}
				for (int i = 0; i < alt.n; i++)
					free(alt.c[i].data);
				free(alt.c);
				motion_img_free(&alt_img);
				if (r != MLOD_OK)
					goto done;
			}
		}
		x.st->motion.seconds += now_seconds() - t0;
	}
	/* DOC: the input without what the levels hold (mlod_gltf_strip_levels),
	 * or as read when it cannot be stripped. */
	{
		chunkb cb = {0};
		void *glb = NULL;
		size_t glb_size = 0;
		mlod_gltf *copy = NULL;
		mlod_error serr = {0};
		mlod_result sr = doc ? doc_copy(&x, doc, &copy, &serr) : MLOD_ERR_INVALID_ARG;
		int *joint_nodes = malloc(sizeof(int) * ((size_t)c->skeleton.joint_count + 1)), jn = 0;
		if (!joint_nodes)
			sr = mlod_fail(&serr, MLOD_ERR_NOMEM, "out of memory");
		for (int j = 0; joint_nodes && j < c->skeleton.joint_count; j++)
			joint_nodes[jn++] = c->skeleton.joints[j].node;
		if (sr == MLOD_OK && !opt->doc_whole)
			sr = mlod_gltf_strip_levels(copy, joint_nodes, jn, &serr);
		free(joint_nodes);
		if (sr == MLOD_OK && !opt->doc_whole)
			sr = doc_dedupe(&x, copy, 0, &serr);
		if (sr == MLOD_OK)
			sr = mlod_gltf_write(copy, 1, &glb, &glb_size, &serr);
		mlod_gltf_free(copy);
		copy = NULL;
		int whole = 0;
		if (sr == MLOD_ERR_UNSUPPORTED && doc && !opt->doc_whole) {
			/* An extension mlod does not know may hold any index: the
			 * document stays whole, but for what goes without moving an
			 * index (mlod_gltf_keep_indices): the stages' records and
			 * MSFT_lod, and the levels the stages and -x append at the
			 * ends of the arrays, so that unpacking and packing again
			 * gives the same document. */
			mlod_error werr = {0};
			mlod_result wr = mlod_gltf_copy(doc, &copy, &werr);
			mlod_free(glb);
			glb = NULL;
			if (wr == MLOD_OK) {
				mlod_gltf_keep_indices(copy, 1);
				for (int n = 0; wr == MLOD_OK && n < mlod_gltf_count(copy, MLOD_GLTF_NODE); n++)
					wr = mlod_gltf_clear_lod(copy, n, &werr);
			}
			if (wr == MLOD_OK)
				wr = doc_dedupe(&x, copy, 1, &werr);
			if (wr == MLOD_OK)
				wr = mlod_gltf_write(copy, 1, &glb, &glb_size, &werr);
			mlod_gltf_free(copy);
			if (wr == MLOD_ERR_NOMEM) {
				mlod_free(glb);
				r = mlod_fail(err, wr, "%s", werr.message);
				goto done;
			}
			whole = wr == MLOD_OK;
		}
		if (sr != MLOD_OK && (whole || (format == MLOD_FORMAT_GLB && input) || doc)) {
			snprintf(x.st->doc_note, sizeof x.st->doc_note, "the document chunk holds the input whole: %s",
			         serr.message);
			note(&x, x.st->doc_note);
		}
		if (sr == MLOD_OK) {
			cb_add(&cb, MLOD_STREAM_GLB, (uint32_t)glb_size, 1, glb, 0);
			x.st->doc_stripped = !opt->doc_whole;
		} else if (whole) {
			cb_add(&cb, MLOD_STREAM_GLB, (uint32_t)glb_size, 1, glb, 0);
		} else if (format == MLOD_FORMAT_GLB && input) {
			cb_add(&cb, MLOD_STREAM_GLB, (uint32_t)input_size, 1, input, 0);
		} else if (doc) {
			mlod_free(glb);
			glb = NULL;
			if ((r = mlod_gltf_write(doc, 1, &glb, &glb_size, err)) != MLOD_OK)
				goto done;
			cb_add(&cb, MLOD_STREAM_GLB, (uint32_t)glb_size, 1, glb, 0);
		} else {
			cb_add(&cb, MLOD_STREAM_GLB, 0, 1, NULL, 0);
		}
		mlod_free(glb);
		if ((r = cb_finish(&cb, MLOD_CODEC_NONE, &body, MLOD_CHUNK_DOC, MLOD_LAYER_NONE, 0, 0, 0.0f, err)) != MLOD_OK)
			goto done;
	}

	/* The stream codecs by the entropy stage's bytes. */
	for (int i = 0; opt->entropy == MLOD_ENTROPY_ZSTD && i < body.n; i++)
		if ((r = chunk_stream_choice(&body.c[i], err)) != MLOD_OK)
			goto done;

	/* The entropy stage, after every choice above was made on the codec's
	 * bytes (INFO has none: its size must not depend on the offsets). */
	/* Finest first, so that the coarser MESH levels, a finer level's
	 * prefix, and SKELETON, a skeleton level's, are still their containers. */
	for (int i = body.n - 1; opt->entropy == MLOD_ENTROPY_ZSTD && i >= 0; i--) {
		size_t np = 0;
		uint8_t *pre = NULL;
		if (body.c[i].type == MLOD_CHUNK_MESH && body.c[i].codec != MLOD_CODEC_DRACO) { /* Draco: standalone */
			for (int j = 0; j < i; j++)
				if (body.c[j].type == MLOD_CHUNK_MESH)
					np += body.c[j].size;
			if (np && !(pre = malloc(np))) {
				r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory writing the pack");
				goto done;
			}
			for (size_t j = 0, o = 0; (int)j < i; j++)
				if (body.c[j].type == MLOD_CHUNK_MESH)
					memcpy(pre + o, body.c[j].data, body.c[j].size), o += body.c[j].size;
		}
		if (body.c[i].type == MLOD_CHUNK_SKELETON && body.c[i].level > 0)
			for (int j = 0; j < i && !np; j++)
				if (body.c[j].type == MLOD_CHUNK_SKELETON && body.c[j].level == 0) {
					if (!(pre = malloc(body.c[j].size))) {
						r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory writing the pack");
						goto done;
					}
					memcpy(pre, body.c[j].data, body.c[j].size);
					np = body.c[j].size;
				}
		r = chunk_entropy(&body.c[i], pre, np, err);
		free(pre);
		if (r != MLOD_OK)
			goto done;
	}

	/* INFO: its size does not depend on its values (its streams are raw). */
	strtab names = {0};
	mlod_pack_info_rec info;
	memset(&info, 0, sizeof info);
	info.name = str_add(&names, opt->name                   ? opt->name
	                            : x.rec.has_pack            ? x.rec.pack_name
	                            : opt->default_name         ? opt->default_name
	                                                        : "");
	for (int q = 0; q < x.v.clip_count; q++)
		str_add(&names, x.v.clips[q].name);
	if (names.b.fail) {
		free(names.b.p);
		r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
		goto done;
	}
	info.joint_count = (uint32_t)x.v.skeleton.joint_count;
	info.skin_count = (uint32_t)x.v.skeleton.skin_count;
	info.skeleton_levels = (uint32_t)S;
	info.mesh_levels = (uint32_t)M;
	info.clip_count = (uint32_t)x.v.clip_count;
	info.motion_levels = (uint32_t)A;
	info.instance_count = (uint32_t)parts0;
	for (int a = 0; a < 3; a++) {
		info.bounds_min[a] = x.bmin[a];
		info.bounds_max[a] = x.bmax[a];
	}
	info.height = x.height;
	info.diagonal = x.diag;
	size_t info_size = 4 + 2 * 16 + ((sizeof info + 3) & ~(size_t)3) + ((names.b.n + 3) & ~(size_t)3);
	/* Offsets. */
	uint64_t off = MLOD_PACK_HEADER_SIZE + (uint64_t)MLOD_PACK_TOC_ENTRY_SIZE * (uint64_t)(body.n + 1);
	off = (off + 15) & ~(uint64_t)15;
	uint64_t info_off = off;
	off += info_size;
	uint64_t first = off;
	for (int i = 0; i < body.n; i++) {
		off = (off + 15) & ~(uint64_t)15;
		body.c[i].offset = off;
		off += body.c[i].size;
		chunk *ch = &body.c[i];
		int needed = ch->type == MLOD_CHUNK_SKELETON ? ch->level == 0 || ch->level == S - 1
		             : ch->type == MLOD_CHUNK_MESH    ? ch->level == M - 1
		             : ch->type == MLOD_CHUNK_MOTION  ? ch->level == A - 1
		                                              : 0;
		if (needed && off > first)
			first = off;
	}
	uint64_t file_size = off;
	if (file_size > UINT32_MAX || body.n + 1 > MLOD_PACK_MAX_CHUNKS) {
		free(names.b.p);
		r = mlod_fail(err, MLOD_ERR_LIMIT, "the pack would be larger than 4 GiB");
		goto done;
	}
	info.first_drawable = (uint32_t)first;
	{
		chunkb cb = {0};
		cb_add(&cb, MLOD_STREAM_INFO, 1, sizeof info, &info, 0);
		cb_add(&cb, MLOD_STREAM_NAME, (uint32_t)names.b.n, 1, names.b.p, 0);
		free(names.b.p);
		if ((r = cb_finish(&cb, MLOD_CODEC_NONE, &head, MLOD_CHUNK_INFO, MLOD_LAYER_NONE, 0, 0, 0.0f, err)) != MLOD_OK)
			goto done;
		head.c[0].offset = info_off;
	}

	/* Header, TOC, chunks. */
	{
		buf f = {0};
		int n = body.n + 1;
		buf_zeros(&f, MLOD_PACK_HEADER_SIZE + (size_t)MLOD_PACK_TOC_ENTRY_SIZE * (size_t)n);
		if (f.fail) {
			r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
			goto done;
		}
		for (int i = 0; i < n; i++) {
			chunk *ch = i == 0 ? &head.c[0] : &body.c[i - 1];
			buf_pad(&f, MLOD_PACK_ALIGN);
			if (f.fail || f.n != ch->offset)
				break;
			uint8_t *e = f.p + MLOD_PACK_HEADER_SIZE + (size_t)MLOD_PACK_TOC_ENTRY_SIZE * (size_t)i;
			put_u32(e, ch->type);
			e[4] = ch->layer;
			e[5] = (uint8_t)(ch->codec | ch->entropy << 4);
			put_u32(e + 12, ch->entropy ? ch->coded : 0);
			put_u16(e + 6, ch->level);
			put_u16(e + 8, ch->item);
			put_u16(e + 10, ch->flags);
			put_u64(e + 16, ch->offset);
			put_u32(e + 24, (uint32_t)ch->size);
			put_u32(e + 28, ch->raw);
			put_u32(e + 32, mlod_pack_crc32(0, ch->data, ch->size));
			put_f32(e + 36, ch->error);
			put_f32(e + 40, ch->distance);
			buf_put(&f, ch->data, ch->size);
		}
		if (f.fail || f.n != file_size) {
			free(f.p);
			r = mlod_fail(err, f.fail ? MLOD_ERR_NOMEM : MLOD_ERR_INVALID_ARG, "writing the pack: layout mismatch");
			goto done;
		}
		memcpy(f.p, MLOD_PACK_MAGIC, 4);
		put_u16(f.p + 4, MLOD_PACK_MAJOR);
		put_u16(f.p + 6, MLOD_PACK_MINOR);
		put_u32(f.p + 8, 0);
		put_u32(f.p + 12, (uint32_t)n);
		put_u64(f.p + 16, file_size);
		put_u32(f.p + 24, mlod_pack_crc32(0, f.p + MLOD_PACK_HEADER_SIZE, (size_t)MLOD_PACK_TOC_ENTRY_SIZE * (size_t)n));
		put_u32(f.p + 28, mlod_pack_crc32(0, f.p, 28));
		/* The pack through its reader's own rules (mlod_pack_open's TOC,
		 * mlod_pack_check's chunks): never a pack the reader refuses. */
		mlod_pack rp;
		mlod_error rerr = {0};
		mlod_result rr = mlod_pack_open(f.p, f.n, &rp, &rerr);
		if (rr == MLOD_OK) {
			rr = mlod_pack_check(&rp, f.p, f.n, &rerr);
			mlod_pack_close(&rp);
		}
		if (rr != MLOD_OK) {
			free(f.p);
			r = mlod_fail(err, rr == MLOD_ERR_NOMEM ? rr : MLOD_ERR_LIMIT,
			              "the pack as written fails its reader's check: %s", rerr.message);
			goto done;
		}
		*out = f.p;
		*out_size = f.n;
	}

	/* Stats. */
	{
		mlod_pack_stats *st = x.st;
		st->skeleton.levels = S;
		st->mesh.levels = M;
		st->motion.levels = A;
		for (int k = 1; k < S; k++)
			st->skeleton.errors[k] = x.skel_error[k - 1];
		for (int k = 1; k < M; k++)
			st->mesh.errors[k] = x.mesh_error[k - 1];
		for (int k = 0; k < A; k++)
			for (int q = 0; q < x.v.clip_count; q++) {
				float e = x.clips[q].toc[k];
				st->motion.errors[k] = e > st->motion.errors[k] ? e : st->motion.errors[k];
			}
		st->skeleton.stored = layer_bytes(&body, MLOD_LAYER_SKELETON, 0);
		st->skeleton.raw = layer_bytes(&body, MLOD_LAYER_SKELETON, 1);
		st->mesh.stored = layer_bytes(&body, MLOD_LAYER_MESH, 0);
		st->mesh.raw = layer_bytes(&body, MLOD_LAYER_MESH, 1);
		st->motion.stored = layer_bytes(&body, MLOD_LAYER_MOTION, 0);
		st->motion.raw = layer_bytes(&body, MLOD_LAYER_MOTION, 1);
		st->info_bytes = head.c[0].size;
		st->doc_bytes = body.c[body.n - 1].size;
		st->total = file_size;
		st->chunks = (uint32_t)(body.n + 1);
		st->first_drawable = info.first_drawable;
		st->joints = x.v.skeleton.joint_count;
		st->skins = x.v.skeleton.skin_count;
		st->parts = parts0;
		st->clips = x.v.clip_count;
		st->height = x.height;
		st->diagonal = x.diag;
	}
	r = MLOD_OK;
done:
	for (int i = 0; i < body.n; i++)
		free(body.c[i].data);
	free(body.c);
	for (int i = 0; i < head.n; i++)
		free(head.c[i].data);
	free(head.c);
	ctx_free(&x);
	return r;
}
