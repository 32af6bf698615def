/*
 * rt_instance.c: instances (the pool, their clips, times and morph
 * weights) and the fallback rule: the level an instance shows is the
 * level it wants when resident, else the nearest resident coarser one.
 */
#include <math.h>
#include <string.h>

#include "rt_internal.h"

/* ---------------------------------------------------------------- */
/* Fallback                                                          */
/* ---------------------------------------------------------------- */

static uint16_t resolve_layer(const mlod_rt_ctx *ctx, mlod_rt_layer layer, uint32_t item, uint16_t wanted)
{
	const uint32_t L = ctx->levels[layer];
	for (uint32_t l = wanted; l < L; l++) {
		const rt_unit *u = rt_unit_at(ctx, layer, l, item);
		if (u && u->state == RT_UNIT_RESIDENT)
			return (uint16_t)l;
	}
	/* Unreachable while the coarsest stays resident; any resident one. */
	for (uint32_t l = wanted; l-- > 0;) {
		const rt_unit *u = rt_unit_at(ctx, layer, l, item);
		if (u && u->state == RT_UNIT_RESIDENT)
			return (uint16_t)l;
	}
	return (uint16_t)(L ? L - 1 : 0);
}

void rt_resolve(mlod_rt_ctx *ctx, rt_instance *in)
{
	mlod_rt_state *st = &in->st;
	st->fallback = 0;
	for (int layer = 0; layer < MLOD_RT_LAYERS; layer++) {
		if (!ctx->levels[layer]) {
			st->level[layer] = st->wanted[layer] = 0;
			continue;
		}
		uint32_t item = layer == MLOD_RT_MOTION ? st->clip : 0;
		rt_unit *old = rt_unit_at(ctx, (mlod_rt_layer)layer, st->level[layer], item);
		uint16_t l = resolve_layer(ctx, (mlod_rt_layer)layer, item, st->wanted[layer]);
		rt_unit *now = rt_unit_at(ctx, (mlod_rt_layer)layer, l, item);
		if (old != now) {
			if (old && old->users)
				old->users--;
			if (now)
				now->users++;
		}
		st->level[layer] = l;
		if (l != st->wanted[layer])
			st->fallback |= 1u << layer;
	}
}

/* Drops the instance's users counts (before destroy or a clip change). */
static void unuse(mlod_rt_ctx *ctx, rt_instance *in)
{
	for (int layer = 0; layer < MLOD_RT_LAYERS; layer++) {
		if (!ctx->levels[layer])
			continue;
		rt_unit *u = rt_unit_at(ctx, (mlod_rt_layer)layer, in->st.level[layer],
		                        layer == MLOD_RT_MOTION ? in->st.clip : 0);
		if (u && u->users)
			u->users--;
	}
}

/* ---------------------------------------------------------------- */
/* Instances                                                         */
/* ---------------------------------------------------------------- */

mlod_result mlod_rt_instance_create(mlod_rt_ctx *ctx, uint32_t clip, float time, uint32_t flags, uint32_t *id,
                                    mlod_error *err)
{
	if (!ctx || !id)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_rt_instance_create: NULL argument");
	if (ctx->clip_count && clip >= ctx->clip_count)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "clip %u out of range (%u clips)", clip, ctx->clip_count);
	if (!isfinite(time))
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_rt_instance_create: time %g is not finite", (double)time);
	if (ctx->free_head >= ctx->max_instances)
		return mlod_fail(err, MLOD_ERR_LIMIT, "the instance pool of %u is full", ctx->max_instances);
	uint32_t i = ctx->free_head;
	rt_instance *in = &ctx->inst[i];
	ctx->free_head = in->next_free;
	memset(&in->st, 0, sizeof in->st);
	in->selected = 0;
	in->st.alive = 1;
	in->st.clip = ctx->clip_count ? clip : 0;
	in->st.time = time;
	in->st.flags = flags;
	if (ctx->morph_total)
		memset(ctx->morph_weights + (size_t)i * ctx->morph_total, 0, sizeof(float) * ctx->morph_total);
	for (int layer = 0; layer < MLOD_RT_LAYERS; layer++) {
		uint16_t c = (uint16_t)(ctx->levels[layer] ? ctx->levels[layer] - 1 : 0);
		in->st.wanted[layer] = c;
		in->st.level[layer] = c;
		rt_unit *u = ctx->levels[layer] ? rt_unit_at(ctx, (mlod_rt_layer)layer, c,
		                                             layer == MLOD_RT_MOTION ? in->st.clip : 0)
		                                : NULL;
		if (u)
			u->users++;
	}
	ctx->live++;
	*id = rt_slot_id(ctx, i);
	return MLOD_OK;
}

void mlod_rt_instance_destroy(mlod_rt_ctx *ctx, uint32_t id)
{
	rt_instance *in = ctx ? rt_live(ctx, id) : NULL;
	if (!in)
		return;
	unuse(ctx, in);
	in->st.alive = 0;
	/* The slot's next id differs from every id it gave before, until the
	 * generation wraps (2^(32 - slot_bits) destroys of this slot). */
	if (ctx->slot_bits < 32)
		in->gen = (in->gen + 1) & ((1u << (32 - ctx->slot_bits)) - 1u);
	in->next_free = ctx->free_head;
	ctx->free_head = (uint32_t)(in - ctx->inst);
	ctx->live--;
}

mlod_result mlod_rt_instance_set(mlod_rt_ctx *ctx, uint32_t id, uint32_t clip, float time, uint32_t flags,
                                 mlod_error *err)
{
	rt_instance *in = ctx ? rt_live(ctx, id) : NULL;
	if (!in)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "instance %u is not alive", id);
	if (ctx->clip_count && clip >= ctx->clip_count)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "clip %u out of range (%u clips)", clip, ctx->clip_count);
	if (!isfinite(time))
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "instance %u: time %g is not finite", id, (double)time);
	unuse(ctx, in);
	in->st.clip = ctx->clip_count ? clip : 0;
	in->st.time = time;
	in->st.flags = flags;
	/* The shown motion level now counts for the new clip. */
	for (int layer = 0; layer < MLOD_RT_LAYERS; layer++) {
		rt_unit *u = ctx->levels[layer] ? rt_unit_at(ctx, (mlod_rt_layer)layer, in->st.level[layer],
		                                             layer == MLOD_RT_MOTION ? in->st.clip : 0)
		                                : NULL;
		if (u)
			u->users++;
	}
	rt_resolve(ctx, in);
	return MLOD_OK;
}

uint32_t mlod_rt_morph_target_count(const mlod_rt_ctx *ctx, uint32_t part)
{
	if (!ctx || part >= ctx->morph_parts)
		return 0;
	return ctx->morph_offset[part + 1] - ctx->morph_offset[part];
}

mlod_result mlod_rt_instance_set_morph_weights(mlod_rt_ctx *ctx, uint32_t id, uint32_t part, const float *weights,
                                               uint32_t count, mlod_error *err)
{
	if (!ctx || (!weights && count))
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_rt_instance_set_morph_weights: NULL argument");
	const rt_instance *in = rt_live(ctx, id);
	if (!in)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "instance %u is not alive", id);
	if (part >= ctx->part_count)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "part %u out of range (%u parts)", part, ctx->part_count);
	const uint32_t targets = mlod_rt_morph_target_count(ctx, part);
	if (count > targets)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "part %u has %u morph targets, %u weights given", part, targets,
		                 count);
	for (uint32_t t = 0; t < count; t++)
		if (!isfinite(weights[t]))
			return mlod_fail(err, MLOD_ERR_INVALID_ARG, "part %u: morph weight %u is not finite", part, t);
	if (!targets)
		return MLOD_OK;
	float *w = ctx->morph_weights + (size_t)(in - ctx->inst) * ctx->morph_total + ctx->morph_offset[part];
	for (uint32_t t = 0; t < targets; t++)
		w[t] = t < count ? weights[t] : 0.0f;
	return MLOD_OK;
}

const mlod_rt_state *mlod_rt_instance_state(const mlod_rt_ctx *ctx, uint32_t id)
{
	const rt_instance *in = ctx ? rt_live(ctx, id) : NULL;
	return in ? &in->st : NULL;
}
