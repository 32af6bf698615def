/*
 * rt_ctx.c: the context's groundwork: allocation through the caller's
 * allocator, an empty context, and a unit by layer, level and item
 * (rt_unit_get; rt_unit_at, inline in rt_internal.h). The rest of the
 * context: rt_prepare.c (checking and preparing a loaded level),
 * rt_load.c (the resident-level cache), rt_instance.c (instances and the
 * fallback rule), rt_open.c (opening views, the common part of every
 * open, closing) and rt_query.c; the pack source is rt_pack.c.
 */
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "rt_internal.h"

static void *default_malloc(void *user, size_t size)
{
	(void)user;
	return malloc(size);
}

static void default_free(void *user, void *p)
{
	(void)user;
	free(p);
}

void *rt_alloc(const mlod_rt_ctx *ctx, size_t size)
{
	return ctx->alloc.malloc(ctx->alloc.user, size ? size : 1);
}

void rt_free(const mlod_rt_ctx *ctx, void *p)
{
	if (p)
		ctx->alloc.free(ctx->alloc.user, p);
}

void *rt_calloc(const mlod_rt_ctx *ctx, size_t n, size_t size)
{
	if (size && n > SIZE_MAX / size)
		return NULL;
	void *p = rt_alloc(ctx, n * size);
	if (p)
		memset(p, 0, n * size);
	return p;
}

int rt_config_bad(const mlod_rt_config *config)
{
	return config && config->allocator && !config->allocator->malloc != !config->allocator->free;
}

/* The contexts opened in the process so far: each takes the next count
 * as its open_tag, so a record of mlod_rt_skin_stale written by another
 * context (another pack, or another open of the same one, which may
 * reuse the same memory) never passes for this one's. */
static _Atomic uint64_t rt_opened;

mlod_rt_ctx *rt_ctx_new(const mlod_rt_config *config)
{
	mlod_rt_allocator a = { default_malloc, default_free, NULL };
	if (config && config->allocator && config->allocator->malloc && config->allocator->free)
		a = *config->allocator;
	mlod_rt_ctx *ctx = a.malloc(a.user, sizeof *ctx);
	if (!ctx)
		return NULL;
	memset(ctx, 0, sizeof *ctx);
	ctx->alloc = a;
	ctx->open_tag = atomic_fetch_add(&rt_opened, 1) + 1;
	ctx->budget = config && config->budget_bytes ? config->budget_bytes : SIZE_MAX;
	ctx->max_instances = config && config->max_instances ? config->max_instances : 1024;
	ctx->streamed = 1; /* the first update starts a frame */
	return ctx;
}

int rt_units_make(mlod_rt_ctx *ctx, uint32_t skel_levels, uint32_t mesh_levels, uint32_t clip_count,
                  uint32_t motion_levels)
{
	ctx->levels[MLOD_RT_SKELETON] = skel_levels;
	ctx->levels[MLOD_RT_MESH] = mesh_levels;
	ctx->clip_count = motion_levels ? clip_count : 0;
	ctx->levels[MLOD_RT_MOTION] = ctx->clip_count ? motion_levels : 0;
	ctx->unit_count = ctx->levels[0] + ctx->levels[1] + ctx->clip_count * ctx->levels[2];
	ctx->unit_base[0] = 0;
	ctx->unit_base[1] = ctx->levels[0];
	ctx->unit_base[2] = ctx->levels[0] + ctx->levels[1];
	ctx->units = rt_calloc(ctx, ctx->unit_count, sizeof *ctx->units);
	return ctx->units ? 0 : -1;
}

rt_unit *rt_unit_get(const mlod_rt_ctx *ctx, mlod_rt_layer layer, uint32_t level, uint32_t item)
{
	return rt_unit_at(ctx, layer, level, item);
}
