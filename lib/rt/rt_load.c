/*
 * rt_load.c: the resident-level cache: byte counts of decoded levels,
 * loading (through the source's load, then rt_prepare.c) and releasing a
 * level, LRU eviction under the budget, the pack reader's reserve
 * callback, and streaming (requests, mlod_rt_stream) with its handling of
 * failed levels.
 */
#include <string.h>

#include "pack_internal.h"
#include "rt_internal.h"

/* ---------------------------------------------------------------- */
/* Byte counts                                                       */
/* ---------------------------------------------------------------- */

/* A skeleton level of these counts (its kept joints; its palette's joints
 * and bind matrices). */
static size_t rt_bytes_skel_counts(uint32_t kept_count, uint32_t palette_size)
{
	return sizeof(mlod_pack_skel_level) + (size_t)kept_count * 4 + (size_t)palette_size * (4 + 64);
}

size_t rt_bytes_skel_level(const mlod_pack_skel_level *l)
{
	return rt_bytes_skel_counts(l->kept_count, l->palette_size);
}

/* rt_bytes_mesh of the level the pack reader decodes from these part
 * records (its arrays follow the records' flags, UV sets and target
 * counts exactly, lib/rt/rd_mesh.c part_dequant): the same count. */
static size_t rt_bytes_mesh_recs(const mlod_pack_part_rec *recs, uint32_t n)
{
	size_t b = sizeof(mlod_pack_mesh);
	for (uint32_t i = 0; i < n; i++) {
		const mlod_pack_part_rec *r = &recs[i];
		size_t v = r->vertex_count, per = 12 + 8 * (size_t)r->uv_sets;
		if (r->flags & MLOD_PART_NORMALS)
			per += 12;
		if (r->flags & MLOD_PART_TANGENTS)
			per += 16;
		if (r->flags & MLOD_PART_COLORS)
			per += 16;
		if (r->flags & MLOD_PART_SKINNED)
			per += 8 + 16;
		b += sizeof(mlod_pack_part) + v * per + (size_t)r->index_count * 4;
		if (r->target_count)
			b += (size_t)r->target_count * (sizeof(float *) + v * 12);
	}
	return b;
}

size_t rt_bytes_mesh(const mlod_pack_mesh *m)
{
	size_t b = sizeof *m;
	for (uint32_t i = 0; i < m->part_count; i++) {
		const mlod_pack_part *p = &m->parts[i];
		size_t v = p->rec.vertex_count, per = 12;
		if (p->normals)
			per += 12;
		if (p->tangents)
			per += 16;
		for (int s = 0; s < MLOD_PACK_MAX_UV; s++)
			if (p->uvs[s])
				per += 8;
		if (p->colors)
			per += 16;
		if (p->joints)
			per += 8;
		if (p->weights)
			per += 16;
		b += sizeof *p + v * per + (size_t)p->rec.index_count * 4;
		if (p->targets)
			b += (size_t)p->rec.target_count * (sizeof(float *) + v * 12);
	}
	return b;
}

size_t rt_bytes_motion(const mlod_pack_motion *m)
{
	/* A decoded level's block is sized exactly from its channel records
	 * (lib/rt/rd_motion.c), its head included: counted as allocated. */
	if (m->block)
		return sizeof *m + mlod_pack_block_size(m->block);
	size_t b = sizeof *m;
	for (uint32_t i = 0; i < m->channel_count; i++) {
		const mlod_pack_channel *c = &m->channels[i];
		size_t comps = c->rec.path == 1 ? 4 : 3;
		if (c->rec.interp == 2)
			comps *= 3;
		b += sizeof *c + (size_t)c->rec.key_count * (4 + 4 * comps);
	}
	return b;
}

/* ---------------------------------------------------------------- */
/* Loading and evicting                                              */
/* ---------------------------------------------------------------- */

void rt_unit_release(mlod_rt_ctx *ctx, rt_unit *u)
{
	if (u->state != RT_UNIT_RESIDENT)
		return;
	if (u->owned && ctx->unload)
		ctx->unload(ctx, u);
	rt_free(ctx, u->plan_block);
	u->plan_block = NULL;
	memset(&u->plan, 0, sizeof u->plan);
	u->pal_used = u->rigid = NULL;
	u->pal_used_count = u->rigid_count = 0;
	u->skin_order_at = NULL, u->skin_order = NULL;
	u->bound_entry = u->bound_part = u->bound_morph = NULL, u->bound_morph_at = NULL;
	ctx->unit_gen++;
	u->chan_flags = NULL;
	u->fixed = u->anim = NULL, u->anim_count = 0, u->static_mat = NULL;
	u->skel = NULL, u->mesh = NULL, u->motion = NULL;
	ctx->resident_bytes -= u->bytes;
	u->bytes = 0;
	u->owned = 0;
	u->state = RT_UNIT_ABSENT;
}

/* Loads u (not resident); on success it is resident and counted. */
mlod_result rt_unit_load(mlod_rt_ctx *ctx, rt_unit *u, mlod_error *err)
{
	mlod_result r;
	u->bytes = 0;
	if (u->layer == MLOD_RT_SKELETON && u->level == 0) {
		/* The full skeleton: resident with the context. */
		u->state = RT_UNIT_RESIDENT;
		return MLOD_OK;
	}
	if (ctx->load) {
		r = ctx->load(ctx, u, err);
		if (r)
			return r;
		u->owned = 1;
		switch (u->layer) {
		case MLOD_RT_SKELETON: u->skel = &u->dec.skel, u->bytes = rt_bytes_skel_level(u->skel); break;
		case MLOD_RT_MESH: u->mesh = &u->dec.mesh, u->bytes = rt_bytes_mesh(u->mesh); break;
		default: u->motion = &u->dec.motion, u->bytes = rt_bytes_motion(u->motion); break;
		}
	} else {
		const mlod_rt_view_level *v = u->view;
		if (!v || !v->data)
			return mlod_fail(err, MLOD_ERR_INVALID_ARG, "%s level %u: no data in the views",
			                 u->layer == MLOD_RT_SKELETON ? "skeleton" : u->layer == MLOD_RT_MESH ? "mesh" : "motion",
			                 u->level);
		switch (u->layer) {
		case MLOD_RT_SKELETON: u->skel = v->data, u->bytes = v->bytes ? v->bytes : rt_bytes_skel_level(u->skel); break;
		case MLOD_RT_MESH: u->mesh = v->data, u->bytes = v->bytes ? v->bytes : rt_bytes_mesh(u->mesh); break;
		default: u->motion = v->data, u->bytes = v->bytes ? v->bytes : rt_bytes_motion(u->motion); break;
		}
	}
	u->state = RT_UNIT_RESIDENT; /* for rt_unit_release on failure below */
	switch (u->layer) {
	case MLOD_RT_SKELETON: r = rt_prepare_skel(ctx, u, u->skel, err); break;
	case MLOD_RT_MESH: r = rt_prepare_mesh(ctx, u, u->mesh, err); break;
	default: r = rt_prepare_motion(ctx, u, u->motion, err); break;
	}
	ctx->resident_bytes += u->bytes;
	if (r) {
		rt_unit_release(ctx, u);
		return r;
	}
	if (u->layer == MLOD_RT_MESH && u->vertex_count > ctx->max_vertices)
		ctx->max_vertices = u->vertex_count;
	if (ctx->resident_bytes > ctx->peak_bytes)
		ctx->peak_bytes = ctx->resident_bytes;
	ctx->loads++;
	ctx->unit_gen++;
	return MLOD_OK;
}

/* The least recently wanted evictable unit, or NULL. */
static rt_unit *lru_victim(mlod_rt_ctx *ctx)
{
	rt_unit *best = NULL;
	for (uint32_t i = 0; i < ctx->unit_count; i++) {
		rt_unit *u = &ctx->units[i];
		if (u->state != RT_UNIT_RESIDENT || u->coarse || (u->layer == MLOD_RT_SKELETON && u->level == 0) ||
		    u->want_count > 0)
			continue;
		if (!best || u->last_wanted < best->last_wanted)
			best = u;
	}
	return best;
}

/* Bytes the victims could free. */
static size_t evictable_bytes(const mlod_rt_ctx *ctx)
{
	size_t b = 0;
	for (uint32_t i = 0; i < ctx->unit_count; i++) {
		const rt_unit *u = &ctx->units[i];
		if (u->state == RT_UNIT_RESIDENT && !u->coarse && !(u->layer == MLOD_RT_SKELETON && u->level == 0) &&
		    u->want_count == 0)
			b += u->bytes;
	}
	return b;
}

/* Evicts least recently wanted levels until need more bytes fit the
 * budget; 0 when they do, -1 when they cannot (nothing is evicted then). */
static int make_room(mlod_rt_ctx *ctx, size_t need)
{
	if (need > ctx->budget || ctx->resident_bytes - evictable_bytes(ctx) > ctx->budget - need)
		return -1;
	while (ctx->resident_bytes > ctx->budget - need) {
		rt_unit *v = lru_victim(ctx);
		if (!v)
			return -1; /* unreachable: evictable_bytes counted the victims */
		rt_unit_release(ctx, v);
		ctx->evictions++;
	}
	return 0;
}

mlod_result rt_mesh_reserve(void *user, const mlod_pack_part_rec *parts, uint32_t part_count, mlod_error *err)
{
	mlod_rt_ctx *ctx = user;
	rt_unit *u = ctx->loading;
	if (!u)
		return MLOD_OK;
	/* A level of more vertices than INFO says the largest has would
	 * overflow the buffers callers sized from mlod_rt_max_vertex_count:
	 * the pack is corrupt (checked before the level is allocated). */
	uint64_t vertices = 0;
	for (uint32_t i = 0; i < part_count; i++)
		vertices += parts[i].vertex_count;
	mlod_result r = mlod_pack_info_check_vertices(&ctx->info, vertices, u->level, err);
	if (r != MLOD_OK)
		return r;
	u->need = rt_bytes_mesh_recs(parts, part_count) + rt_mesh_plan_bytes(ctx, parts, part_count);
	if (!ctx->streaming || make_room(ctx, u->need) == 0)
		return MLOD_OK;
	ctx->refused = 1;
	return mlod_fail(err, MLOD_ERR_LIMIT, "mesh level %u: its %zu decoded bytes do not fit the budget", u->level,
	                 u->need);
}

/* rt_prepare_motion's tables for a level of these channel records
 * (checked by the reader: joints below the skeleton's), counted as it
 * counts them: A, the channels of joints with a channel of more than one
 * key, and S, the joints whose channels all have one key. SIZE_MAX when
 * its flags cannot be allocated. */
static size_t motion_plan_recs(mlod_rt_ctx *ctx, const mlod_pack_channel_rec *c, uint32_t n)
{
	const uint32_t J = ctx->joint_count;
	/* [j]: has a channel (2 once counted); [J + j]: one of more than one key */
	uint8_t *mark = rt_calloc(ctx, (size_t)J + 1, 2);
	if (!mark)
		return SIZE_MAX;
	uint32_t A = 0, S = 0;
	for (uint32_t i = 0; i < n; i++)
		if (c[i].joint < J) {
			mark[c[i].joint] = 1;
			if (c[i].key_count > 1)
				mark[J + c[i].joint] = 1;
		}
	for (uint32_t i = 0; i < n; i++)
		if (c[i].joint < J) {
			A += mark[J + c[i].joint];
			if (mark[c[i].joint] == 1)
				S += !mark[J + c[i].joint], mark[c[i].joint] = 2;
		}
	rt_free(ctx, mark);
	return rt_motion_plan_bytes(J, A, S);
}

mlod_result rt_motion_reserve(void *user, const mlod_pack_channel_rec *channels, uint32_t channel_count,
                              uint64_t block_bytes, mlod_error *err)
{
	mlod_rt_ctx *ctx = user;
	rt_unit *u = ctx->loading;
	if (!u)
		return MLOD_OK;
	const size_t plan = motion_plan_recs(ctx, channels, channel_count);
	if (plan == SIZE_MAX || block_bytes > SIZE_MAX - sizeof(mlod_pack_motion) - plan)
		return mlod_fail(err, MLOD_ERR_NOMEM, "motion level %u of clip %u: out of memory", u->level, u->item);
	u->need = sizeof(mlod_pack_motion) + (size_t)block_bytes + plan;
	if (!ctx->streaming || make_room(ctx, u->need) == 0)
		return MLOD_OK;
	ctx->refused = 1;
	return mlod_fail(err, MLOD_ERR_LIMIT, "motion level %u of clip %u: its %zu decoded bytes do not fit the budget",
	                 u->level, u->item, u->need);
}

mlod_result rt_skel_reserve(void *user, uint32_t kept_count, uint32_t palette_size, uint64_t block_bytes,
                            mlod_error *err)
{
	mlod_rt_ctx *ctx = user;
	rt_unit *u = ctx->loading;
	(void)block_bytes; /* counted from its arrays, as a mesh level is (rt_bytes_skel_level) */
	if (!u)
		return MLOD_OK;
	u->need = rt_bytes_skel_counts(kept_count, palette_size) + rt_skel_plan_bytes(ctx->joint_count, palette_size);
	if (!ctx->streaming || make_room(ctx, u->need) == 0)
		return MLOD_OK;
	ctx->refused = 1;
	return mlod_fail(err, MLOD_ERR_LIMIT, "skeleton level %u: its %zu decoded bytes do not fit the budget", u->level,
	                 u->need);
}

/* rt_motion_plan_bytes of a motion level's views, bounding its joints with
 * one-key channels only by the joints and by its one-key channels. */
static size_t motion_plan_hint(const mlod_rt_ctx *ctx, const mlod_pack_motion *m)
{
	const uint32_t J = ctx->joint_count, C = m->channel_count;
	uint32_t S = 0;
	for (uint32_t i = 0; i < C; i++)
		S += m->channels[i].rec.key_count == 1;
	return rt_motion_plan_bytes(J, C, S < J ? S : J);
}

/* A unit's resident size before loading it, so that room is made before
 * decoding and resident bytes never pass the budget, not even while a
 * level decodes. Views know their size. A pack's level: its exact size
 * once a load has read its part, channel or kept-joint records (u->need),
 * else 0, as the reader calls rt_mesh_reserve, rt_motion_reserve or
 * rt_skel_reserve with those records before it allocates the decoded
 * level, and room is made then (a nested motion level's coarser levels,
 * decoded and freed inside its load, are the reader's scratch, not
 * counted, as a mesh level's coarser vertex blocks are). */
static size_t size_hint(const mlod_rt_ctx *ctx, const rt_unit *u)
{
	size_t plan = u->layer == MLOD_RT_SKELETON ? rt_skel_plan_bytes(ctx->joint_count, ctx->palette_size)
	              : u->layer == MLOD_RT_MESH   ? 4 * ((size_t)ctx->palette_size + ctx->joint_count)
	                                           : 0;
	if (!ctx->load) {
		const mlod_rt_view_level *v = u->view;
		if (v && v->bytes && u->layer == MLOD_RT_MOTION)
			return v->bytes + (v->data ? motion_plan_hint(ctx, v->data) : 0);
		if (v && v->bytes)
			return v->bytes + (u->layer == MLOD_RT_MESH && v->data ? rt_mesh_tables_bytes(ctx, v->data) : plan);
		if (v && v->data)
			switch (u->layer) {
			case MLOD_RT_SKELETON: return rt_bytes_skel_level(v->data) + plan;
			case MLOD_RT_MESH: return rt_bytes_mesh(v->data) + rt_mesh_tables_bytes(ctx, v->data);
			default:
				return rt_bytes_motion(v->data) + motion_plan_hint(ctx, v->data);
			}
		return 0;
	}
	return u->need;
}

/* ---------------------------------------------------------------- */
/* Streaming                                                         */
/* ---------------------------------------------------------------- */

mlod_result mlod_rt_request(mlod_rt_ctx *ctx, mlod_rt_layer layer, uint32_t level, uint32_t item, mlod_error *err)
{
	rt_unit *u = ctx ? rt_unit_at(ctx, layer, level, item) : NULL;
	if (!u)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_rt_request: no such level");
	rt_begin_frame(ctx);
	rt_want(ctx, u, 1);
	return MLOD_OK;
}

void rt_begin_frame(mlod_rt_ctx *ctx)
{
	if (!ctx->streamed)
		return;
	ctx->streamed = 0;
	ctx->stamp++;
	for (uint32_t i = 0; i < ctx->unit_count; i++)
		ctx->units[i].want_count = 0;
}

void rt_want(mlod_rt_ctx *ctx, rt_unit *u, uint32_t n)
{
	const uint32_t w = u->want_count & 0x7fffffffu;
	u->want_count = (u->want_count & 0x80000000u) | (n > 0x7fffffffu - w ? 0x7fffffffu : w + n);
	u->last_wanted = ctx->stamp;
}

/* u cannot fit in this mlod_rt_stream call: the high bit of its want
 * count says so (next_wanted skips it), and its wants pass to the finest
 * coarser level of its layer and item that neither failed nor cannot fit
 * either: one absent then loads in this call when it fits, one resident
 * is kept from eviction. So an instance whose level never fits shows the
 * finest level that does, not the coarsest (mlod_rt_stream(3)). */
static void defer_want(mlod_rt_ctx *ctx, rt_unit *u)
{
	const uint32_t w = u->want_count & 0x7fffffffu;
	u->want_count |= 0x80000000u;
	u->no_room = 1; /* until the next mlod_rt_stream: the caller can tell why */
	for (uint32_t l = (uint32_t)u->level + 1; w && l < ctx->levels[u->layer]; l++) {
		rt_unit *t = rt_unit_at(ctx, (mlod_rt_layer)u->layer, l, u->item);
		if (!t || t->state == RT_UNIT_FAILED || (t->state == RT_UNIT_ABSENT && (t->want_count & 0x80000000u)))
			continue;
		rt_want(ctx, t, w); /* stamped now, as u was */
		return;
	}
}

/* The next unit to load: most wanted, then coarser, then lower index. */
static rt_unit *next_wanted(mlod_rt_ctx *ctx)
{
	rt_unit *best = NULL;
	for (uint32_t i = 0; i < ctx->unit_count; i++) {
		rt_unit *u = &ctx->units[i];
		/* the high bit marks a level that cannot fit in this call */
		if (u->state != RT_UNIT_ABSENT || u->want_count == 0 || (u->want_count & 0x80000000u))
			continue;
		if (!best || u->want_count > best->want_count ||
		    (u->want_count == best->want_count && u->level > best->level))
			best = u;
	}
	return best;
}

/* ---------------------------------------------------------------- */
/* Failed levels                                                     */
/* ---------------------------------------------------------------- */

/* 1 when the chunk's stored bytes fail its CRC, 0 when they match or
 * cannot be read (a read error is not blamed on the chunk). Reads into
 * the staging buffer for a read source: no allocation. */
static int chunk_corrupt(const mlod_rt_ctx *ctx, int32_t chunk)
{
	if (chunk < 0 || (uint32_t)chunk >= ctx->pack.chunk_count || (ctx->verified && ctx->verified[chunk]))
		return 0; /* bytes that matched their CRC once were misread since, not corrupt */
	const mlod_pack_chunk *c = &ctx->pack.chunks[chunk];
	const void *bytes;
	if (ctx->data) { /* memory: the TOC was checked against the size at open */
		if (c->offset > ctx->size || c->stored_size > ctx->size - c->offset)
			return 0;
		bytes = ctx->data + c->offset;
	} else {
		if (!ctx->read || !ctx->staging || c->stored_size > ctx->staging_size ||
		    ctx->read(ctx->read_user, c->offset, c->stored_size, ctx->staging) != 0)
			return 0;
		bytes = ctx->staging;
	}
	return mlod_pack_crc32(0, bytes, c->stored_size) != c->crc;
}

/* 1 when loading unit u (level l of its layer and item) reads the chunk
 * of unit d of the same layer and item: a MESH level reads the chunks of
 * every coarser MESH level (layout b2, mlod(5)); a nested MOTION level
 * reads the clip's next coarser level and what that one builds on. */
static int unit_needs(const mlod_rt_ctx *ctx, const rt_unit *u, const rt_unit *d)
{
	if (u == d)
		return 1;
	if (u->layer != d->layer || u->item != d->item || d->level < u->level || u->chunk < 0)
		return 0;
	if (u->layer == MLOD_RT_MESH)
		return 1;
	if (u->layer != MLOD_RT_MOTION)
		return 0;
	for (uint32_t l = u->level; l < d->level; l++) {
		const rt_unit *v = rt_unit_at(ctx, MLOD_RT_MOTION, l, u->item);
		if (!v || v->chunk < 0 || !(ctx->pack.chunks[v->chunk].flags & MLOD_PACK_CHUNK_NESTED))
			return 0;
	}
	return 1;
}

static void fail_unit(mlod_rt_ctx *ctx, rt_unit *u, int retry)
{
	if (u->state == RT_UNIT_FAILED && !retry)
		u->retry = 0; /* a corrupt chunk it reads: never again */
	if (u->state != RT_UNIT_ABSENT)
		return; /* resident levels decoded fine and stay; failed ones stay failed */
	u->state = RT_UNIT_FAILED;
	u->retry = (uint8_t)retry;
	ctx->failures++;
}

/* Loading u failed with r. u fails, to be tried again by the next
 * mlod_rt_stream when r is MLOD_ERR_NOMEM or MLOD_ERR_IO (a transient
 * cause: memory or the source), never again otherwise; and when the load
 * read a chunk whose stored bytes fail its CRC (u's own or a coarser
 * level's it builds on), that chunk's level fails too, with every level
 * that needs it, so that none of them is tried again; the others stay
 * loadable (fallbacks). */
static void load_failed(mlod_rt_ctx *ctx, rt_unit *u, mlod_result r)
{
	const int transient = r == MLOD_ERR_NOMEM || r == MLOD_ERR_IO;
	fail_unit(ctx, u, transient);
	if (!ctx->load || u->chunk < 0 || u->layer == MLOD_RT_SKELETON || transient)
		return; /* a read or memory failure blames no chunk */
	const uint32_t L = ctx->levels[u->layer];
	for (uint32_t l = u->level; l < L; l++) {
		rt_unit *d = rt_unit_at(ctx, (mlod_rt_layer)u->layer, l, u->item);
		if (!d || !unit_needs(ctx, u, d) || d->state == RT_UNIT_RESIDENT || !chunk_corrupt(ctx, d->chunk))
			continue;
		for (uint32_t k = 0; k <= l; k++) {
			rt_unit *f = rt_unit_at(ctx, (mlod_rt_layer)u->layer, k, u->item);
			if (f && unit_needs(ctx, f, d))
				fail_unit(ctx, f, 0);
		}
	}
}

/* The level to load for an instance that wants level w of a layer: w, or
 * when it failed the finest coarser level that has not (the coarsest is
 * resident from open to close and never fails). */
uint32_t rt_want_target(const mlod_rt_ctx *ctx, mlod_rt_layer layer, uint32_t item, uint32_t w)
{
	const uint32_t L = ctx->levels[layer];
	for (uint32_t l = w; l < L; l++) {
		const rt_unit *u = rt_unit_at(ctx, layer, l, item);
		if (u && u->state != RT_UNIT_FAILED)
			return l;
	}
	return w;
}

/* Moves the wants of failed levels to their fallbacks (rt_want_target),
 * so that these load in the same mlod_rt_stream call. */
static void pass_wants(mlod_rt_ctx *ctx)
{
	for (uint32_t i = 0; i < ctx->unit_count; i++) {
		rt_unit *u = &ctx->units[i];
		const uint32_t w = u->want_count & 0x7fffffffu;
		if (u->state != RT_UNIT_FAILED || !w)
			continue;
		rt_unit *t = rt_unit_at(ctx, (mlod_rt_layer)u->layer,
		                        rt_want_target(ctx, (mlod_rt_layer)u->layer, u->item, u->level), u->item);
		u->want_count = 0;
		if (t && t != u && t->state != RT_UNIT_FAILED) {
			rt_want(ctx, t, w);
			t->last_wanted = u->last_wanted;
		}
	}
}

mlod_result mlod_rt_stream(mlod_rt_ctx *ctx, size_t byte_budget, uint32_t *loaded, mlod_error *err)
{
	if (loaded)
		*loaded = 0;
	if (!ctx)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_rt_stream: NULL context");
	mlod_result first = MLOD_OK;
	size_t spent = 0;
	uint32_t n = 0;
	int changed = 0;
	/* Levels failed by a transient cause are tried again (their wants
	 * stayed on them, mlod_rt_update). */
	for (uint32_t i = 0; i < ctx->unit_count; i++) {
		if (ctx->units[i].state == RT_UNIT_FAILED && ctx->units[i].retry)
			ctx->units[i].state = RT_UNIT_ABSENT, ctx->units[i].retry = 0;
		ctx->units[i].no_room = 0; /* said of the last call only */
	}
	pass_wants(ctx); /* requests of failed levels */
	while (byte_budget > 0 && spent < byte_budget) {
		rt_unit *u = NULL;
		/* Find the best candidate that may fit. */
		for (;;) {
			rt_unit *c = next_wanted(ctx);
			if (!c)
				break;
			size_t hint = size_hint(ctx, c);
			if (ctx->resident_bytes + hint > ctx->budget &&
			    ctx->resident_bytes - evictable_bytes(ctx) + hint > ctx->budget) {
				/* cannot fit even after every eviction: skip it in this call */
				defer_want(ctx, c);
				continue;
			}
			u = c;
			break;
		}
		if (!u)
			break;
		if (spent > 0 && spent + u->stored_size > byte_budget)
			break;
		/* Make room for the hint before decoding. */
		size_t hint = size_hint(ctx, u);
		while (ctx->resident_bytes + hint > ctx->budget) {
			rt_unit *v = lru_victim(ctx);
			if (!v)
				break;
			rt_unit_release(ctx, v);
			ctx->evictions++;
			changed = 1;
		}
		mlod_error e;
		ctx->streaming = 1, ctx->refused = 0;
		mlod_result r = rt_unit_load(ctx, u, &e);
		ctx->streaming = 0;
		if (r && ctx->refused) { /* its records say it cannot fit: it waits */
			ctx->refused = 0;
			defer_want(ctx, u);
			changed = 1;
			continue;
		}
		if (r) { /* not counted in byte_budget: the fallback loads in this call */
			load_failed(ctx, u, r);
			pass_wants(ctx);
			changed = 1;
			if (!first) {
				first = r;
				if (err)
					*err = e;
			}
			continue;
		}
		/* Evict to fit what it really costs. */
		while (ctx->resident_bytes > ctx->budget) {
			rt_unit *v = lru_victim(ctx);
			if (!v)
				break;
			rt_unit_release(ctx, v);
			ctx->evictions++;
		}
		if (ctx->resident_bytes > ctx->budget) { /* larger than its hint: give it back */
			rt_unit_release(ctx, u);
			defer_want(ctx, u);
			changed = 1;
			continue;
		}
		spent += u->stored_size ? u->stored_size : 1;
		n++;
		changed = 1;
	}
	for (uint32_t i = 0; i < ctx->unit_count; i++)
		ctx->units[i].want_count &= 0x7fffffffu;
	ctx->streamed = 1; /* the next update starts the next frame's wants */
	if (changed)
		for (uint32_t i = 0; i < ctx->max_instances; i++)
			if (ctx->inst[i].st.alive)
				rt_resolve(ctx, &ctx->inst[i]);
	if (loaded)
		*loaded = n;
	return first;
}
