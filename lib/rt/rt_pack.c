/*
 * rt_pack.c: the pack source of the runtime: mlod_rt_open_memory, _path
 * and _read, and the loader that decodes one level through the pack reader
 * (lib/rt/rd_*.c) inside mlod_rt_stream. Sources other than memory read a
 * chunk into a staging buffer (allocated at open, the size of the largest
 * chunk) and decode it through a copy of the TOC whose entry for that
 * chunk says offset 0; a MESH level (layout b2) needs the vertex blocks of
 * every coarser MESH level, so its load reads those chunks again through
 * the read callback, coarsest first, each into the staging buffer
 * (mlod_pack_decode_mesh_fetch): nothing is kept between loads, and the
 * coarser blocks live only in the decode's scratch. A skeleton level
 * coded on SKELETON's container (format 6.0's entropy stage 2) is staged
 * after the SKELETON chunk, read again, and the staging buffer is sized
 * for both. The reader allocates through the context's
 * allocator (mlod_pack_open_alloc), so every allocation of a context is
 * its allocator's.
 */
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pack_internal.h"
#include "rt_internal.h"

enum { SRC_VIEWS = 0, SRC_MEMORY = 1, SRC_READ = 2 };

/* Reads chunk k's stored bytes into dst. A read source can misread (a
 * glitch, a file rewritten under it): bytes that fail the chunk's CRC are
 * read once more, and when they fail again though they matched when read
 * before (ctx->verified), the read is blamed, MLOD_ERR_IO, which
 * mlod_rt_stream tries again; else the reader reports the CRC mismatch
 * (MLOD_ERR_PARSE: the level fails for good). */
static mlod_result read_chunk(mlod_rt_ctx *ctx, uint32_t k, void *dst, mlod_error *err)
{
	const mlod_pack_chunk *c = &ctx->pack.chunks[k];
	for (int pass = 0; pass < 2; pass++) {
		if (ctx->read(ctx->read_user, c->offset, c->stored_size, dst) != 0)
			return mlod_fail(err, MLOD_ERR_IO, "chunk %u: reading %u bytes at offset %llu failed", k, c->stored_size,
			                 (unsigned long long)c->offset);
		if (mlod_pack_crc32(0, dst, c->stored_size) == c->crc) {
			if (ctx->verified)
				ctx->verified[k] = 1;
			return MLOD_OK;
		}
	}
	if (ctx->verified && ctx->verified[k])
		return mlod_fail(err, MLOD_ERR_IO,
		                 "chunk %u (%s level %u): read twice, its bytes fail the CRC they matched when read before "
		                 "(a read error, or a source that changed): tried again by the next mlod_rt_stream",
		                 k, mlod_pack_type_name(c->type), (unsigned)c->level);
	return MLOD_OK;
}

/* The chunk's bytes as (data, size) for the reader, and the pack to pass. */
static mlod_result chunk_bytes(mlod_rt_ctx *ctx, uint32_t chunk, const mlod_pack **pack, const void **data,
                               size_t *size, mlod_pack *shadow, mlod_error *err)
{
	const mlod_pack_chunk *c = &ctx->pack.chunks[chunk];
	if (ctx->source == SRC_MEMORY) {
		*pack = &ctx->pack;
		*data = ctx->data;
		*size = ctx->size;
		return MLOD_OK;
	}
	/* A skeleton level with the prefix stage (format 6.0) is coded on
	 * SKELETON's container: that chunk goes first in the staging buffer. */
	int dep = c->type == MLOD_CHUNK_SKELETON && c->level > 0 && c->entropy == MLOD_ENTROPY_ZSTD_PREFIX
	                  ? mlod_pack_find(&ctx->pack, MLOD_CHUNK_SKELETON, 0, 0)
	                  : -1;
	uint64_t at = 0;
	if (dep >= 0) {
		const mlod_pack_chunk *d = &ctx->pack.chunks[dep];
		if (d->stored_size > ctx->staging_size)
			return mlod_fail(err, MLOD_ERR_PARSE, "chunk %d: %u bytes, larger than the staging buffer", dep,
			                 d->stored_size);
		mlod_result r = read_chunk(ctx, (uint32_t)dep, ctx->staging, err);
		if (r)
			return r;
		at = ((uint64_t)d->stored_size + 15) & ~(uint64_t)15;
	}
	if (c->stored_size > ctx->staging_size || at > ctx->staging_size - c->stored_size)
		return mlod_fail(err, MLOD_ERR_PARSE, "chunk %u: %u bytes, larger than the staging buffer", chunk,
		                 c->stored_size);
	mlod_result r = read_chunk(ctx, chunk, ctx->staging + at, err);
	if (r)
		return r;
	*shadow = ctx->pack;
	memcpy(ctx->shadow, ctx->pack.chunks, sizeof *ctx->shadow * ctx->pack.chunk_count);
	ctx->shadow[chunk].offset = at;
	if (dep >= 0)
		ctx->shadow[dep].offset = 0;
	shadow->chunks = ctx->shadow;
	*pack = shadow;
	*data = ctx->staging;
	*size = (size_t)at + c->stored_size;
	return MLOD_OK;
}

/* mlod_pack_fetch_fn for a read source: reads the chunk into the
 * staging buffer again (a MESH level re-reads the coarser levels' chunks,
 * whose vertex blocks it needs, one after the other). */
static mlod_result fetch_chunk(void *user, uint32_t chunk, const void **bytes, mlod_error *err)
{
	mlod_rt_ctx *ctx = user;
	const mlod_pack_chunk *c = &ctx->pack.chunks[chunk];
	if (c->stored_size > ctx->staging_size)
		return mlod_fail(err, MLOD_ERR_PARSE, "chunk %u: %u bytes, larger than the staging buffer", chunk,
		                 c->stored_size);
	mlod_result r = read_chunk(ctx, chunk, ctx->staging, err);
	if (r)
		return r;
	*bytes = ctx->staging;
	return MLOD_OK;
}

/* A MOTION chunk decoded into out. A nested one (MLOD_PACK_CHUNK_NESTED)
 * builds on the clip's next coarser level, as the reader returns it: the
 * chain of levels it builds on is decoded here, from the first that is
 * not nested, and freed again (a resident level's keys may have been
 * normalised: rt_prepare_motion). The level itself is decoded last, with
 * rt_motion_reserve, which makes room for it before its block is
 * allocated. */
static mlod_result motion_load(mlod_rt_ctx *ctx, uint32_t chunk, mlod_pack_motion *out, mlod_error *err)
{
	const mlod_pack_chunk *c = &ctx->pack.chunks[chunk];
	const mlod_pack_motion *base = NULL;
	unsigned top = c->level; /* the coarsest level of the chain decoded here */
	int ci = (int)chunk;
	while (ci >= 0 && (ctx->pack.chunks[ci].flags & MLOD_PACK_CHUNK_NESTED)) {
		if (top - c->level >= MLOD_PACK_MAX_NESTING)
			return mlod_fail(err, MLOD_ERR_PARSE, "MOTION level %u of clip %u: more than %d nested levels in a row",
			                 (unsigned)c->level, (unsigned)c->item, MLOD_PACK_MAX_NESTING);
		if (top == 65535 || (ci = mlod_pack_find(&ctx->pack, MLOD_CHUNK_MOTION, top + 1, c->item)) < 0)
			return mlod_fail(err, MLOD_ERR_PARSE, "MOTION level %u of clip %u: builds on level %u, which the pack lacks",
			                 top, (unsigned)c->item, top + 1);
		top++;
	}
	mlod_pack_motion tmp[2];
	memset(tmp, 0, sizeof tmp);
	mlod_result r = MLOD_OK;
	for (unsigned l = top + 1; r == MLOD_OK && l-- > c->level;) {
		int k = l == c->level ? (int)chunk : mlod_pack_find(&ctx->pack, MLOD_CHUNK_MOTION, l, c->item);
		const mlod_pack *p;
		const void *data;
		size_t size;
		mlod_pack shadow;
		mlod_pack_motion *dst = l == c->level ? out : &tmp[l & 1];
		if ((r = chunk_bytes(ctx, (uint32_t)k, &p, &data, &size, &shadow, err)) == MLOD_OK)
			r = mlod_pack_decode_motion_reserve(p, (uint32_t)k, data, size, ctx->skel, base,
			                                    l == c->level ? rt_motion_reserve : NULL, ctx, dst, err);
		mlod_pack_motion_free(&tmp[!(l & 1)]);
		base = dst;
	}
	mlod_pack_motion_free(&tmp[0]);
	mlod_pack_motion_free(&tmp[1]);
	return r;
}

static mlod_result pack_load(mlod_rt_ctx *ctx, rt_unit *u, mlod_error *err)
{
	if (u->layer == MLOD_RT_MESH) {
		/* The reader calls rt_mesh_reserve with the level's part records
		 * before it allocates the decoded level: room is made for its
		 * exact size then. */
		memset(&u->dec, 0, sizeof u->dec);
		ctx->loading = u;
		mlod_result r = mlod_pack_decode_mesh_reserve(&ctx->pack, (uint32_t)u->chunk, ctx->data, ctx->size,
		                                              ctx->source == SRC_MEMORY ? NULL : fetch_chunk, ctx,
		                                              rt_mesh_reserve, ctx, ctx->skel, &u->dec.mesh, err);
		ctx->loading = NULL;
		return r;
	}
	if (u->layer == MLOD_RT_MOTION) {
		/* The same for a motion level's channel records (the coarser
		 * levels it builds on, decoded first, are scratch). */
		memset(&u->dec, 0, sizeof u->dec);
		ctx->loading = u;
		mlod_result r = motion_load(ctx, (uint32_t)u->chunk, &u->dec.motion, err);
		ctx->loading = NULL;
		return r;
	}
	/* And a skeleton level's kept joints and palette (rt_skel_reserve). */
	const mlod_pack *p;
	const void *data;
	size_t size;
	mlod_pack shadow;
	mlod_result r = chunk_bytes(ctx, (uint32_t)u->chunk, &p, &data, &size, &shadow, err);
	if (r)
		return r;
	memset(&u->dec, 0, sizeof u->dec);
	ctx->loading = u;
	r = mlod_pack_decode_skel_level_reserve(p, (uint32_t)u->chunk, data, size, ctx->skel, rt_skel_reserve, ctx,
	                                        &u->dec.skel, err);
	ctx->loading = NULL;
	return r;
}

static void pack_unload(mlod_rt_ctx *ctx, rt_unit *u)
{
	(void)ctx;
	switch (u->layer) {
	case MLOD_RT_SKELETON: mlod_pack_skel_level_free(&u->dec.skel); break;
	case MLOD_RT_MESH: mlod_pack_mesh_free(&u->dec.mesh); break;
	default: mlod_pack_motion_free(&u->dec.motion); break;
	}
}

static void pack_close(mlod_rt_ctx *ctx)
{
	if (ctx->skel_owned)
		mlod_pack_skeleton_free(&ctx->skel_dec);
	if (ctx->info_owned)
		mlod_pack_info_free(&ctx->info);
	if (ctx->pack_open)
		mlod_pack_close(&ctx->pack);
	rt_free(ctx, ctx->shadow);
	rt_free(ctx, ctx->verified);
	rt_free(ctx, ctx->staging);
	if (ctx->file)
		fclose(ctx->file);
	ctx->file = NULL;
}

static size_t skeleton_bytes(const mlod_pack_skeleton *s)
{
	size_t b = sizeof *s + (size_t)s->joint_count * (sizeof *s->joints + sizeof(char *) + 16);
	for (uint32_t k = 0; k < s->skin_count; k++)
		b += sizeof *s->skins + 2 * sizeof(void *) + (size_t)s->skins[k].joint_count * (4 + 64);
	return b;
}

/* Reads the header and TOC, decodes INFO and SKELETON, builds the units. */
static mlod_result pack_open(mlod_rt_ctx *ctx, mlod_error *err)
{
	mlod_result r;
	ctx->load = pack_load;
	ctx->unload = pack_unload;
	ctx->close_source = pack_close;
	/* The reader allocates the TOC and every decoded chunk (and its
	 * scratch) with the context's allocator. */
	const mlod_pack_alloc pa = { ctx->alloc.malloc, ctx->alloc.free, ctx->alloc.user };
	if (ctx->source == SRC_MEMORY) {
		r = mlod_pack_open_alloc(ctx->data, ctx->size, &pa, &ctx->pack, err);
	} else {
		uint8_t head[MLOD_PACK_HEADER_SIZE];
		if (ctx->file_size < MLOD_PACK_HEADER_SIZE)
			return mlod_fail(err, MLOD_ERR_PARSE, "the pack has %llu bytes, less than its header",
			                 (unsigned long long)ctx->file_size);
		if (ctx->read(ctx->read_user, 0, sizeof head, head) != 0)
			return mlod_fail(err, MLOD_ERR_IO, "reading the pack's header failed");
		uint32_t n = (uint32_t)head[12] | (uint32_t)head[13] << 8 | (uint32_t)head[14] << 16 |
		             (uint32_t)head[15] << 24;
		if (n > MLOD_PACK_MAX_CHUNKS)
			n = MLOD_PACK_MAX_CHUNKS + 1u; /* the reader says what is wrong */
		uint64_t want = MLOD_PACK_HEADER_SIZE + (uint64_t)MLOD_PACK_TOC_ENTRY_SIZE * n;
		if (want > ctx->file_size)
			want = ctx->file_size;
		uint8_t *toc = rt_alloc(ctx, (size_t)want);
		if (!toc)
			return mlod_fail(err, MLOD_ERR_NOMEM, "opening: out of memory for the TOC");
		if (ctx->read(ctx->read_user, 0, (size_t)want, toc) != 0) {
			rt_free(ctx, toc);
			return mlod_fail(err, MLOD_ERR_IO, "reading the pack's TOC failed");
		}
		r = mlod_pack_open_alloc(toc, (size_t)want, &pa, &ctx->pack, err);
		rt_free(ctx, toc);
	}
	if (r)
		return r;
	ctx->pack_open = 1;
	/* The pack's zstd decoder (format 5.0's entropy stage) lives as long
	 * as the pack: resident, like the staging buffer. */
	ctx->resident_bytes += mlod_pack_decoder_bytes(&ctx->pack);
	if (ctx->pack.file_size != (ctx->source == SRC_MEMORY ? (uint64_t)ctx->size : ctx->file_size))
		return mlod_fail(err, MLOD_ERR_PARSE, "the pack says %llu bytes, the source has %llu",
		                 (unsigned long long)ctx->pack.file_size,
		                 (unsigned long long)(ctx->source == SRC_MEMORY ? (uint64_t)ctx->size : ctx->file_size));
	if (ctx->source != SRC_MEMORY) {
		size_t big = 0;
		int cs0 = mlod_pack_find(&ctx->pack, MLOD_CHUNK_SKELETON, 0, 0);
		size_t skel0 = cs0 >= 0 ? ((size_t)ctx->pack.chunks[cs0].stored_size + 15) & ~(size_t)15 : 0;
		for (uint32_t i = 0; i < ctx->pack.chunk_count; i++) {
			const mlod_pack_chunk *c = &ctx->pack.chunks[i];
			if (c->type != MLOD_CHUNK_DOC && c->stored_size > big)
				big = c->stored_size;
			/* a prefix-coded skeleton level is staged after SKELETON */
			if (c->type == MLOD_CHUNK_SKELETON && c->level > 0 && c->entropy == MLOD_ENTROPY_ZSTD_PREFIX &&
			    skel0 + c->stored_size > big)
				big = skel0 + c->stored_size;
		}
		ctx->staging_size = big;
		ctx->staging = rt_alloc(ctx, big);
		ctx->shadow = rt_alloc(ctx, sizeof *ctx->shadow * (ctx->pack.chunk_count + 1));
		ctx->verified = rt_alloc(ctx, (size_t)ctx->pack.chunk_count + 1);
		if (ctx->verified)
			memset(ctx->verified, 0, (size_t)ctx->pack.chunk_count + 1);
		if (!ctx->staging || !ctx->shadow || !ctx->verified)
			return mlod_fail(err, MLOD_ERR_NOMEM, "opening: out of memory for a %zu-byte staging buffer", big);
		ctx->resident_bytes += big + (sizeof *ctx->shadow + 1) * ctx->pack.chunk_count;
	}
	/* INFO and SKELETON. */
	const mlod_pack *p;
	const void *data;
	size_t size;
	mlod_pack shadow;
	int ci = mlod_pack_find(&ctx->pack, MLOD_CHUNK_INFO, 0, 0);
	int cs = mlod_pack_find(&ctx->pack, MLOD_CHUNK_SKELETON, 0, 0);
	if (ci < 0 || cs < 0)
		return mlod_fail(err, MLOD_ERR_PARSE, "the pack has no %s chunk", ci < 0 ? "INFO" : "SKELETON");
	if ((r = chunk_bytes(ctx, (uint32_t)ci, &p, &data, &size, &shadow, err)) ||
	    (r = mlod_pack_decode_info(p, data, size, &ctx->info, err)))
		return r;
	ctx->info_owned = 1;
	/* Known at open from format 8.1 on (mlod_rt_max_vertex_count); an
	 * older pack's grows as its levels load. */
	ctx->max_vertices = ctx->info.rec.max_vertex_count;
	if ((r = chunk_bytes(ctx, (uint32_t)cs, &p, &data, &size, &shadow, err)) ||
	    (r = mlod_pack_decode_skeleton(p, data, size, &ctx->skel_dec, err)))
		return r;
	ctx->skel_owned = 1;
	ctx->skel = &ctx->skel_dec;
	if ((r = mlod_pack_info_check_skeleton(&ctx->info, ctx->skel, err)))
		return r;
	ctx->resident_bytes += sizeof ctx->info + skeleton_bytes(ctx->skel);
	const mlod_pack_info_rec *rec = &ctx->info.rec;
	if (rec->skeleton_levels < 1 || rec->skeleton_levels > 65535 || rec->mesh_levels > 65535 ||
	    rec->motion_levels > 65535 || rec->clip_count > 65535)
		return mlod_fail(err, MLOD_ERR_PARSE, "INFO: level counts out of range");
	if (rt_units_make(ctx, rec->skeleton_levels, rec->mesh_levels, rec->clip_count, rec->motion_levels))
		return mlod_fail(err, MLOD_ERR_NOMEM, "opening: out of memory");
	for (uint32_t i = 0; i < ctx->unit_count; i++) {
		rt_unit *u = &ctx->units[i];
		uint32_t type;
		if (i < ctx->unit_base[1])
			u->layer = MLOD_RT_SKELETON, u->level = (uint16_t)i, type = MLOD_CHUNK_SKELETON;
		else if (i < ctx->unit_base[2])
			u->layer = MLOD_RT_MESH, u->level = (uint16_t)(i - ctx->unit_base[1]), type = MLOD_CHUNK_MESH;
		else {
			uint32_t k = i - ctx->unit_base[2];
			u->layer = MLOD_RT_MOTION;
			u->item = (uint16_t)(k / ctx->levels[2]);
			u->level = (uint16_t)(k % ctx->levels[2]);
			type = MLOD_CHUNK_MOTION;
		}
		int c = mlod_pack_find(&ctx->pack, type, u->level, u->item);
		if (c < 0)
			return mlod_fail(err, MLOD_ERR_PARSE, "the pack has no %s level %u%s", mlod_pack_type_name(type),
			                 u->level, u->layer == MLOD_RT_MOTION ? " for a clip" : "");
		u->chunk = c;
		u->stored_size = ctx->pack.chunks[c].stored_size;
		u->raw_size = ctx->pack.chunks[c].raw_size;
		u->error = ctx->pack.chunks[c].error;
		u->distance = ctx->pack.chunks[c].distance;
	}
	if ((r = rt_ctx_finish_open(ctx, err)))
		return r;
	/* INFO's instance count against the coarsest mesh level, decoded now */
	const rt_unit *cm = ctx->levels[MLOD_RT_MESH] ? rt_unit_get(ctx, MLOD_RT_MESH, ctx->levels[MLOD_RT_MESH] - 1, 0)
	                                              : NULL;
	if (cm && cm->mesh)
		return mlod_pack_info_check_mesh(&ctx->info, cm->mesh, cm->level, err);
	return MLOD_OK;
}

static mlod_result finish(mlod_rt_ctx *ctx, mlod_rt_ctx **out, mlod_error *err)
{
	mlod_result r = pack_open(ctx, err);
	if (r) {
		mlod_rt_close(ctx);
		return r;
	}
	*out = ctx;
	return MLOD_OK;
}

mlod_result mlod_rt_open_memory(const void *data, size_t size, const mlod_rt_config *config, mlod_rt_ctx **out,
                                mlod_error *err)
{
	if (!out || !data)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_rt_open_memory: NULL argument");
	*out = NULL;
	if (rt_config_bad(config))
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_rt_open_memory: the allocator has one of malloc and free");
	mlod_rt_ctx *ctx = rt_ctx_new(config);
	if (!ctx)
		return mlod_fail(err, MLOD_ERR_NOMEM, "opening: out of memory");
	ctx->source = SRC_MEMORY;
	ctx->data = data;
	ctx->size = size;
	return finish(ctx, out, err);
}

mlod_result mlod_rt_open_read(mlod_rt_read_fn read, void *user, uint64_t file_size, const mlod_rt_config *config,
                              mlod_rt_ctx **out, mlod_error *err)
{
	if (!out || !read)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_rt_open_read: NULL argument");
	*out = NULL;
	if (rt_config_bad(config))
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_rt_open_read: the allocator has one of malloc and free");
	mlod_rt_ctx *ctx = rt_ctx_new(config);
	if (!ctx)
		return mlod_fail(err, MLOD_ERR_NOMEM, "opening: out of memory");
	ctx->source = SRC_READ;
	ctx->read = read;
	ctx->read_user = user;
	ctx->file_size = file_size;
	return finish(ctx, out, err);
}

static int file_read(void *user, uint64_t offset, size_t size, void *dst)
{
	FILE *f = user;
	if (offset > (uint64_t)LONG_MAX || fseek(f, (long)offset, SEEK_SET) != 0)
		return -1;
	return fread(dst, 1, size, f) == size ? 0 : -1;
}

mlod_result mlod_rt_open_path(const char *path, const mlod_rt_config *config, mlod_rt_ctx **out, mlod_error *err)
{
	if (!out || !path)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_rt_open_path: NULL argument");
	*out = NULL;
	if (rt_config_bad(config))
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_rt_open_path: the allocator has one of malloc and free");
	FILE *f = fopen(path, "rb");
	if (!f)
		return mlod_fail(err, MLOD_ERR_IO, "%s: cannot open", path);
	long end = -1;
	if (fseek(f, 0, SEEK_END) == 0)
		end = ftell(f);
	if (end < 0) {
		fclose(f);
		return mlod_fail(err, MLOD_ERR_IO, "%s: cannot tell its size", path);
	}
	mlod_rt_ctx *ctx = rt_ctx_new(config);
	if (!ctx) {
		fclose(f);
		return mlod_fail(err, MLOD_ERR_NOMEM, "opening: out of memory");
	}
	ctx->source = SRC_READ;
	ctx->read = file_read;
	ctx->read_user = f;
	ctx->file = f;
	ctx->file_size = (uint64_t)end;
	mlod_result r = pack_open(ctx, err);
	if (r) {
		mlod_rt_close(ctx);
		/* say which file */
		if (err) {
			char m[MLOD_ERROR_MESSAGE_SIZE];
			memcpy(m, err->message, sizeof m);
			m[300] = '\0';
			mlod_fail(err, r, "%.200s: %s", path, m);
		}
		return r;
	}
	*out = ctx;
	return MLOD_OK;
}

/* ---------------------------------------------------------------- */
/* The budget an open needs                                          */
/* ---------------------------------------------------------------- */

/* config with no budget (a copy; the defaults for NULL). */
static mlod_rt_config unlimited(const mlod_rt_config *config)
{
	mlod_rt_config c = { 0, 0, NULL };
	if (config)
		c = *config;
	c.budget_bytes = 0;
	return c;
}

/* The opened ctx's open_bytes into *bytes, and ctx closed (r: the open's
 * result, taken before ctx is read: an argument's order is unspecified). */
static mlod_result open_bytes(mlod_result r, mlod_rt_ctx *ctx, size_t *bytes)
{
	if (r == MLOD_OK) {
		*bytes = ctx->open_bytes;
		mlod_rt_close(ctx);
	}
	return r;
}

mlod_result mlod_rt_open_memory_bytes(const void *data, size_t size, const mlod_rt_config *config, size_t *bytes,
                                      mlod_error *err)
{
	if (!bytes)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_rt_open_memory_bytes: NULL argument");
	*bytes = 0;
	const mlod_rt_config c = unlimited(config);
	mlod_rt_ctx *ctx = NULL;
	const mlod_result r = mlod_rt_open_memory(data, size, &c, &ctx, err);
	return open_bytes(r, ctx, bytes);
}

mlod_result mlod_rt_open_path_bytes(const char *path, const mlod_rt_config *config, size_t *bytes, mlod_error *err)
{
	if (!bytes)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_rt_open_path_bytes: NULL argument");
	*bytes = 0;
	const mlod_rt_config c = unlimited(config);
	mlod_rt_ctx *ctx = NULL;
	const mlod_result r = mlod_rt_open_path(path, &c, &ctx, err);
	return open_bytes(r, ctx, bytes);
}

mlod_result mlod_rt_open_read_bytes(mlod_rt_read_fn read, void *user, uint64_t file_size,
                                    const mlod_rt_config *config, size_t *bytes, mlod_error *err)
{
	if (!bytes)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_rt_open_read_bytes: NULL argument");
	*bytes = 0;
	const mlod_rt_config c = unlimited(config);
	mlod_rt_ctx *ctx = NULL;
	const mlod_result r = mlod_rt_open_read(read, user, file_size, &c, &ctx, err);
	return open_bytes(r, ctx, bytes);
}
