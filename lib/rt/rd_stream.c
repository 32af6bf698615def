/*
 * rd_stream.c: a chunk's bytes to its streams: the CRC, the entropy
 * stage (zstd, with the pack's decoder made in rd_open.c), the stream
 * container and its streams' codecs, and the block a decode carves its
 * arrays from.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <meshoptimizer.h>

/* ZSTD_DCtx_refPrefix is in zstd's advanced API; libzstd exports it. */
#define ZSTD_STATIC_LINKING_ONLY
#include <zstd.h>

#define MLOD_PACK_READER /* pack_internal.h: the reader's own part */
#include "pack_internal.h"

/* ------------------------------------------------------------------ */
/* A chunk's stream container                                          */
/* ------------------------------------------------------------------ */

/* Checks the chunk's TOC entry (index, type, codec). */
mlod_result pk_cx_head(const mlod_pack *p, uint32_t index, uint32_t type, cx *x, mlod_error *err)
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
	pk_chunk_label(c->type, c->level, c->item, x->label, sizeof x->label);
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
mlod_result pk_cx_parse(cx *x, mlod_error *err)
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

/* pk_cx_head and pk_cx_parse on the chunk's bytes in data (a file or a prefix);
 * prefix: for MLOD_ENTROPY_ZSTD_PREFIX, or NULL. */
mlod_result pk_cx_begin_prefix(const mlod_pack *p, uint32_t index, uint32_t type, const void *data, size_t size,
                               const uint8_t *prefix, uint64_t prefix_size, cx *x, mlod_error *err)
{
	memset(x, 0, sizeof *x);
	if (!p || (!data && size))
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "pack decode: the pack or the data is NULL");
	mlod_result r = pk_cx_head(p, index, type, x, err);
	if (r != MLOD_OK)
		return r;
	const mlod_pack_chunk *c = x->c;
	if (c->offset > size || c->stored_size > size - c->offset)
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: truncated: the chunk ends at byte %llu, the data has %zu", x->label,
		                 (unsigned long long)(c->offset + c->stored_size), size);
	x->base = (const uint8_t *)data + c->offset;
	x->prefix = prefix;
	x->prefix_size = prefix_size;
	return pk_cx_parse(x, err);
}

mlod_result pk_cx_begin(const mlod_pack *p, uint32_t index, uint32_t type, const void *data, size_t size, cx *x,
                        mlod_error *err)
{
	return pk_cx_begin_prefix(p, index, type, data, size, NULL, 0, x, err);
}

/* pk_cx_begin on a skeleton level: with the prefix stage, the SKELETON
 * chunk in data is read and checked first (its CRC, its own stage, its
 * container), and its container is the prefix; it is freed once the
 * level's frame is undone. */
mlod_result pk_cx_begin_skel_level(const mlod_pack *p, uint32_t index, const void *data, size_t size, cx *x,
                                   mlod_error *err)
{
	if (!p || index >= p->chunk_count || p->chunks[index].entropy != MLOD_ENTROPY_ZSTD_PREFIX ||
	    p->chunks[index].type != MLOD_CHUNK_SKELETON || p->chunks[index].level == 0)
		return pk_cx_begin(p, index, MLOD_CHUNK_SKELETON, data, size, x, err);
	memset(x, 0, sizeof *x);
	int di = mlod_pack_find(p, MLOD_CHUNK_SKELETON, 0, 0);
	if (di < 0) /* open refuses that; a caller's own TOC may not */
		return mlod_fail(err, MLOD_ERR_PARSE, "SKELETON level %u: coded on the SKELETON chunk's container, which the "
		                 "pack lacks", (unsigned)p->chunks[index].level);
	cx dx;
	mlod_result r = pk_cx_begin(p, (uint32_t)di, MLOD_CHUNK_SKELETON, data, size, &dx, err);
	if (r == MLOD_OK)
		r = pk_cx_begin_prefix(p, index, MLOD_CHUNK_SKELETON, data, size, dx.base, dx.size, x, err);
	pk_free(&dx.alloc, dx.plain);
	if (x->prefix)
		x->prefix = NULL, x->prefix_size = 0;
	return r;
}

/* The next stream, which must have this tag, element size and count
 * (count UINT64_MAX: any). what says where ("part 3"), count_what what
 * the count is. */
mlod_result pk_cx_expect(cx *x, stream *s, uint32_t tag, uint32_t elsize, uint64_t count, const char *what,
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

mlod_result pk_cx_end(cx *x, mlod_error *err)
{
	if (x->next != x->nstreams)
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: %u unexpected streams after the last one it needs (stream %u '%s')",
		                 x->label, x->nstreams - x->next, x->next, tagn(rd32(x->base + 4 + 16 * (size_t)x->next)).s);
	return MLOD_OK;
}

/* Allocates the temporary buffer: aux bytes for the decode's own checks,
 * then room for the largest meshopt-coded stream. */
mlod_result pk_cx_temp(cx *x, uint64_t aux, mlod_error *err)
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

void pk_cx_done(cx *x)
{
	pk_free(&x->alloc, x->temp);
	x->temp = NULL;
	pk_free(&x->alloc, x->plain);
	x->plain = NULL;
}

/* The stream's decoded bytes: in place for raw streams, else decoded into
 * the temporary buffer (valid until the next load). */

mlod_result pk_cx_load(cx *x, const stream *s, const uint8_t **out, mlod_error *err)
{
	if (s->codec == MLOD_SCODEC_RAW) {
		*out = s->src;
		return MLOD_OK;
	}
	static unsigned char dummy[256];
	unsigned char *dst = x->temp && x->max_decoded ? x->temp + x->aux : dummy;
	mlod_result r = pk_cx_load_into(x, s, dst, err);
	if (r == MLOD_OK)
		*out = dst;
	return r;
}

/* The stream's decoded bytes written to dst (count * element size bytes):
 * a copy of a raw stream, or the meshopt decoder's output in place. */
mlod_result pk_cx_load_into(cx *x, const stream *s, uint8_t *dst, mlod_error *err)
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

size_t mlod_pack_block_size(const void *block)
{
	uint64_t n = 0;
	if (block)
		memcpy(&n, (const uint8_t *)block + BLOCK_SIZE_AT, sizeof n);
	return (size_t)n;
}

/* A block freed by the allocator its head records. */
static void block_free(void *block)
{
	if (!block)
		return;
	mlod_pack_alloc a;
	memcpy(&a, block, sizeof a);
	pk_free(&a, block);
}

void pk_block_release(void *block, void *owner, size_t owner_size)
{
	block_free(block);
	memset(owner, 0, owner_size);
}

mlod_result pk_undo(cx *x, bump *b, mlod_result r)
{
	pk_cx_done(x);
	pk_free(&x->alloc, b->base);
	return r;
}

mlod_result pk_bump_alloc(bump *b, cx *x, uint64_t total, mlod_error *err)
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

/* A string table: the stream's bytes with a NUL after them; every string
 * offset must be inside and the table must end with a NUL. */
mlod_result pk_load_names(cx *x, bump *b, const stream *s, char **out, mlod_error *err)
{
	const uint8_t *src;
	mlod_result r = pk_cx_load(x, s, &src, err);
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

mlod_result pk_name_at(cx *x, const char *table, uint32_t table_size, uint32_t off, const char **out,
                       const char *what, mlod_error *err)
{
	if (off >= table_size)
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: %s: name offset %u is outside the string table (%u bytes)", x->label,
		                 what, off, table_size);
	*out = table + off;
	return MLOD_OK;
}
