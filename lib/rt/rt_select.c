/*
 * rt_select.c: level selection (the paper's alpha, projected pixels, the
 * TOC's distances), hysteresis and the batch update (mlod_rt.h,
 * "Selection").
 */
#include <float.h>
#include <math.h>
#include <string.h>

#include "rt_internal.h"

void mlod_rt_select_default(mlod_rt_select *sel)
{
	memset(sel, 0, sizeof *sel);
	sel->mode = MLOD_RT_SELECT_ALPHA;
	sel->d_near = 2.0f;
	sel->d_far = 200.0f;
	for (int l = 0; l < MLOD_RT_LAYERS; l++) {
		sel->t_start[l] = 0.0f;
		sel->t_end[l] = 1.0f;
	}
	sel->fov_y = (float)(MLOD_PACK_FOV_Y * 3.14159265358979323846 / 180.0);
	sel->lines = (float)MLOD_PACK_LINES;
	sel->max_pixels = (float)MLOD_PACK_PIXELS;
	sel->hysteresis = 0.1f;
	sel->distance_scale = 1.0f;
	sel->force_level = -1;
}

/* D_l, the distance from which level l (>= 1) is wanted. */
static float switch_distance(const mlod_rt_ctx *ctx, const mlod_rt_select *sel, mlod_rt_layer layer, uint32_t item,
                             uint32_t l)
{
	const uint32_t L = ctx->levels[layer];
	float D;
	switch (sel->mode) {
	case MLOD_RT_SELECT_ALPHA: {
		const float ts = sel->t_start[layer], te = sel->t_end[layer];
		float a = te > ts ? ts + ((float)l - 0.5f) / (float)(L - 1) * (te - ts) : ts;
		if (a <= 0.0f)
			D = 0.0f;
		else if (a > 1.0f)
			D = INFINITY;
		else
			D = sel->d_near + a * (sel->d_far > sel->d_near ? sel->d_far - sel->d_near : 0.0f);
		break;
	}
	case MLOD_RT_SELECT_PIXELS: {
		const rt_unit *u = rt_unit_get(ctx, layer, l, item);
		const float k = 2.0f * tanf(0.5f * sel->fov_y) * sel->max_pixels;
		D = u && k > 0.0f && sel->lines > 0.0f ? u->error * sel->lines / k : INFINITY;
		break;
	}
	default: {
		const rt_unit *u = rt_unit_get(ctx, layer, l, item);
		D = u && u->distance > 0.0f ? u->distance : INFINITY;
		break;
	}
	}
	if (sel->distance_scale > 0.0f)
		D *= sel->distance_scale;
	return isnan(D) ? INFINITY : D;
}

uint32_t mlod_rt_select_level(const mlod_rt_ctx *ctx, const mlod_rt_select *sel, mlod_rt_layer layer,
                              uint32_t item, float d, int prev)
{
	if (!ctx || !sel || (unsigned)layer >= MLOD_RT_LAYERS || ctx->levels[layer] == 0)
		return 0;
	const uint32_t L = ctx->levels[layer];
	if (sel->force_level >= 0)
		return (uint32_t)sel->force_level < L ? (uint32_t)sel->force_level : L - 1;
	if (!(d >= 0.0f))
		d = 0.0f;
	uint32_t raw = 0;
	for (uint32_t l = L - 1; l >= 1; l--)
		if (switch_distance(ctx, sel, layer, item, l) <= d) {
			raw = l;
			break;
		}
	if (prev < 0 || (uint32_t)prev >= L || raw <= (uint32_t)prev)
		return raw; /* finer (or the same) at the threshold */
	const float h = sel->hysteresis > 0.0f ? 1.0f + sel->hysteresis : 1.0f;
	for (uint32_t l = L - 1; l > (uint32_t)prev; l--)
		if (switch_distance(ctx, sel, layer, item, l) * h <= d)
			return l;
	return (uint32_t)prev;
}

/* A selection the header allows: one of the three modes, every float
 * finite, hysteresis >= 0 (MLOD_ERR_INVALID_ARG naming the member). */
static mlod_result select_check(const mlod_rt_select *sel, const char *fn, mlod_error *err)
{
	if ((unsigned)sel->mode > MLOD_RT_SELECT_TOC)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "%s: selection mode %d is not alpha, pixels or toc", fn,
		                 (int)sel->mode);
	const struct { const char *name; float v; } f[] = {
		{"d_near", sel->d_near}, {"d_far", sel->d_far}, {"fov_y", sel->fov_y}, {"lines", sel->lines},
		{"max_pixels", sel->max_pixels}, {"hysteresis", sel->hysteresis}, {"distance_scale", sel->distance_scale},
	};
	for (size_t i = 0; i < sizeof f / sizeof *f; i++)
		if (!isfinite(f[i].v))
			return mlod_fail(err, MLOD_ERR_INVALID_ARG, "%s: selection %s %g is not finite", fn, f[i].name,
			                 (double)f[i].v);
	for (int l = 0; l < MLOD_RT_LAYERS; l++)
		if (!isfinite(sel->t_start[l]) || !isfinite(sel->t_end[l]))
			return mlod_fail(err, MLOD_ERR_INVALID_ARG, "%s: selection interval [%g, %g] of layer %d is not finite",
			                 fn, (double)sel->t_start[l], (double)sel->t_end[l], l);
	if (sel->hysteresis < 0.0f)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "%s: selection hysteresis %g is negative", fn,
		                 (double)sel->hysteresis);
	/* Settings that would put every layer at level 0 at any distance, or
	 * turn the alpha ramp around, are refused rather than obeyed. */
	if (sel->d_near < 0.0f || sel->d_far < sel->d_near)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "%s: selection d_near %g, d_far %g: need 0 <= d_near <= d_far",
		                 fn, (double)sel->d_near, (double)sel->d_far);
	if (!(sel->fov_y > 0.0f && sel->fov_y < 3.14159265f))
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "%s: selection fov_y %g is not between 0 and pi radians", fn,
		                 (double)sel->fov_y);
	if (sel->lines <= 0.0f || sel->max_pixels <= 0.0f)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "%s: selection lines %g, max_pixels %g: both must be > 0", fn,
		                 (double)sel->lines, (double)sel->max_pixels);
	if (sel->distance_scale < 0.0f)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "%s: selection distance_scale %g is negative", fn,
		                 (double)sel->distance_scale);
	return MLOD_OK;
}

static void update_one(mlod_rt_ctx *ctx, const mlod_rt_select *sel, uint32_t id, float d, float dt)
{
	rt_instance *in = rt_live(ctx, id);
	if (!in)
		return;
	mlod_rt_state *st = &in->st;
	/* time stays finite: when the float sum overflows, it is made in
	 * double, where a looping instance's wraps and another's saturates at
	 * +-FLT_MAX (below, in float, as it always was) */
	const float dur = ctx->clip_count ? ctx->clip_duration[st->clip] : 0.0f;
	const int loop = (st->flags & MLOD_RT_LOOP) && dur > 0.0f;
	if (isfinite(st->time + dt)) {
		st->time += dt;
	} else {
		double t = (double)st->time + dt;
		if (loop)
			t = fmod(t, dur);
		st->time = (float)(t > FLT_MAX ? FLT_MAX : t < -FLT_MAX ? -FLT_MAX : t);
	}
	if (loop && (st->time >= dur || st->time < 0.0f)) {
		st->time = fmodf(st->time, dur);
		if (st->time < 0.0f)
			st->time += dur;
	}
	st->distance = d; /* finite and >= 0: checked by the caller */
	const float span = sel->d_far - sel->d_near;
	float a = span > 0.0f ? (d - sel->d_near) / span : (d >= sel->d_near ? 1.0f : 0.0f);
	st->alpha = a < 0.0f ? 0.0f : a > 1.0f ? 1.0f : a;
	for (int layer = 0; layer < MLOD_RT_LAYERS; layer++) {
		if (!ctx->levels[layer])
			continue;
		const uint32_t item = layer == MLOD_RT_MOTION ? st->clip : 0;
		uint32_t w = mlod_rt_select_level(ctx, sel, (mlod_rt_layer)layer, item, d,
		                                  in->selected ? (int)st->wanted[layer] : -1);
		st->wanted[layer] = (uint16_t)w;
		/* a failed level's want goes to its fallback, which then loads */
		rt_unit *u = rt_unit_get(ctx, (mlod_rt_layer)layer, w, item);
		if (u && u->state == RT_UNIT_FAILED) {
			/* one to try again keeps the want too (mlod_rt_stream) */
			if (u->retry)
				rt_want(ctx, u, 1);
			u = rt_unit_get(ctx, (mlod_rt_layer)layer, rt_want_target(ctx, (mlod_rt_layer)layer, item, w), item);
		}
		if (u)
			rt_want(ctx, u, 1);
	}
	in->selected = 1;
	rt_resolve(ctx, in);
}

mlod_result mlod_rt_update(mlod_rt_ctx *ctx, const mlod_rt_select *sel, const uint32_t *ids,
                           const float *distances, size_t n, float dt, mlod_error *err)
{
	if (!ctx || !sel || (n && (!ids || !distances)))
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_rt_update: NULL argument");
	/* Everything is checked before any state changes: no partial update. */
	if (select_check(sel, "mlod_rt_update", err) != MLOD_OK)
		return MLOD_ERR_INVALID_ARG;
	if (!isfinite(dt))
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_rt_update: dt %g is not finite", (double)dt);
	for (size_t i = 0; i < n; i++)
		if (!(distances[i] >= 0.0f && distances[i] <= FLT_MAX)) /* NaN fails both */
			return mlod_fail(err, MLOD_ERR_INVALID_ARG,
			                 "mlod_rt_update: instance index %zu: distance %g, not finite and >= 0", i,
			                 (double)distances[i]);
	rt_begin_frame(ctx);
	for (size_t i = 0; i < n; i++)
		update_one(ctx, sel, ids[i], distances[i], dt);
	return MLOD_OK;
}

mlod_result mlod_rt_update_positions(mlod_rt_ctx *ctx, const mlod_rt_select *sel, const float camera[3],
                                     const uint32_t *ids, const float *positions, size_t n, float dt,
                                     mlod_error *err)
{
	if (!ctx || !sel || !camera || (n && (!ids || !positions)))
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_rt_update_positions: NULL argument");
	/* Checked before any state changes, as mlod_rt_update. */
	if (select_check(sel, "mlod_rt_update_positions", err) != MLOD_OK)
		return MLOD_ERR_INVALID_ARG;
	if (!isfinite(dt))
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_rt_update_positions: dt %g is not finite", (double)dt);
	for (size_t i = 0; i < n; i++) {
		const float *p = positions + 3 * i;
		const float x = p[0] - camera[0], y = p[1] - camera[1], z = p[2] - camera[2];
		const float d = sqrtf(x * x + y * y + z * z);
		if (!isfinite(d))
			return mlod_fail(err, MLOD_ERR_INVALID_ARG,
			                 "mlod_rt_update_positions: instance index %zu: distance %g, not finite", i,
			                 (double)d);
	}
	rt_begin_frame(ctx);
	for (size_t i = 0; i < n; i++) {
		const float *p = positions + 3 * i;
		const float x = p[0] - camera[0], y = p[1] - camera[1], z = p[2] - camera[2];
		update_one(ctx, sel, ids[i], sqrtf(x * x + y * y + z * z), dt);
	}
	return MLOD_OK;
}
