/*
 * packbuf.c: the pack writer's chunks: a chunk's streams and their
 * container (meshopt codecs, built in an mlod_buf), the entropy stage
 * (zstd) and a stream's form chosen by its zstd bytes, the string table
 * (packwrite_internal.h).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <meshoptimizer.h>
#include <zstd.h>

#include "pack/packwrite_internal.h"

/* ------------------------------------------------------------------ */
/* Chunks and their streams                                            */
/* ------------------------------------------------------------------ */

void pack_cb_add(chunkb *cb, uint32_t tag, uint32_t count, uint16_t size, const void *data, int index)
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

void pack_cb_free(chunkb *cb)
{
	for (int i = 0; i < cb->n; i++)
		free(cb->s[i].data);
	free(cb->s);
	memset(cb, 0, sizeof *cb);
}

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
size_t pack_stream_coded_bytes(const stream *s)
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
size_t pack_cb_coded_bytes(const chunkb *cb, int from)
{
	size_t total = 0;
	for (int i = from; i < cb->n; i++)
		total += pack_stream_coded_bytes(&cb->s[i]);
	return total;
}

/* Encodes the streams of cb into a chunk (the stream container). */
mlod_result pack_cb_finish(chunkb *cb, mlod_pack_codec codec, chunks *out, uint32_t type, int layer, int level,
                           int item, float error, mlod_error *err)
{
	mlod_buf b = MLOD_BUF_INIT;
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
		pack_cb_free(cb);
		if (!isfinite(stored_error) || !(stored_error >= 0.0f))
			return mlod_fail(err, MLOD_ERR_PARSE, "%s: error %g is not finite and >= 0 (are the input's "
			                 "coordinates too large?)", label, (double)stored_error);
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: error %g gives a switch distance that is not finite (are the "
		                 "input's coordinates too large?)", label, (double)stored_error);
	}
	put_u32(word, (uint32_t)cb->n);
	mlod_buf_append(&b, word, 4);
	size_t headers = b.size;
	mlod_buf_append_zeros(&b, 16 * (size_t)cb->n);
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
		if (b.status == MLOD_OK)
			memcpy(b.data + headers + 16 * (size_t)i, h, 16);
		mlod_buf_append(&b, data, stored);
		buf_pad(&b, 4);
		free(enc);
	}
	if (b.status != MLOD_OK)
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
	c->data = b.data;
	c->size = b.size;
	c->raw = raw;
	pack_cb_free(cb);
	return MLOD_OK;
nomem:
	mlod_buf_free(&b);
	pack_cb_free(cb);
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

mlod_result pack_chunk_entropy(chunk *c, const uint8_t *prefix, size_t prefix_size, mlod_error *err)
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
mlod_result pack_chunk_stream_choice(chunk *c, mlod_error *err)
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
	mlod_buf b = MLOD_BUF_INIT;
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
	mlod_buf_append(&b, c->data, 4 + 16 * (size_t)ns);
	for (uint32_t i = 0, at = 4 + 16 * ns; i < ns; i++) {
		uint8_t *h = c->data + 4 + 16 * (size_t)i;
		size_t stored = (size_t)h[12] | (size_t)h[13] << 8 | (size_t)h[14] << 16 | (size_t)h[15] << 24;
		if (pick[i]) {
			mlod_buf_append(&b, pick[i], pick_size[i]);
			if (b.status == MLOD_OK) {
				b.data[4 + 16 * (size_t)i + 10] = pick_codec[i];
				put_u32(b.data + 4 + 16 * (size_t)i + 12, (uint32_t)pick_size[i]);
			}
		} else {
			mlod_buf_append(&b, c->data + at, stored);
		}
		buf_pad(&b, 4);
		at += (uint32_t)((stored + 3) & ~(size_t)3);
	}
	if (b.status != MLOD_OK)
		goto nomem;
	if (b.size <= c->raw) { /* always: no form is larger than the raw bytes */
		free(c->data);
		c->data = b.data, c->size = b.size;
		b = (mlod_buf)MLOD_BUF_INIT;
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
	mlod_buf_free(&b);
	ZSTD_freeCCtx(cc);
	return r;
}

uint32_t pack_str_add(mlod_buf *t, const char *s)
{
	uint32_t off = (uint32_t)t->size;
	mlod_buf_append(t, s ? s : "", strlen(s ? s : "") + 1);
	return off;
}
