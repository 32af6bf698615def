/*
 * rt_open.c: opening: the common part of every open (the character's
 * tables, the instance pool, the pinned coarse levels, the morph
 * weights), opening views, and closing. The pack source opens in
 * rt_pack.c.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rt_internal.h"

/* ---------------------------------------------------------------- */
/* Opening: the common part                                          */
/* ---------------------------------------------------------------- */

/* A mesh level's data for morph_setup: resident, or (views) the caller's. */
static const mlod_pack_mesh *mesh_of(const mlod_rt_ctx *ctx, const rt_unit *u)
{
	if (!u)
		return NULL;
	if (u->state == RT_UNIT_RESIDENT)
		return u->mesh;
	if (!ctx->load && u->view)
		return ((const mlod_rt_view_level *)u->view)->data;
	return NULL;
}

/* The morph weights' layout and their storage for the whole instance
 * pool, all 0. A pack's levels have the same parts (mlod(5)): the
 * coarsest level, resident at open, gives them. Views are all there:
 * every level counts (the most parts, the most targets per part). */
static mlod_result morph_setup(mlod_rt_ctx *ctx, mlod_error *err)
{
	const uint32_t L = ctx->levels[MLOD_RT_MESH];
	uint32_t parts = 0;
	for (uint32_t l = L ? (ctx->load ? L - 1 : 0) : 0; l < L; l++) {
		const mlod_pack_mesh *m = mesh_of(ctx, rt_unit_get(ctx, MLOD_RT_MESH, l, 0));
		if (m && m->part_count > parts)
			parts = m->part_count;
	}
	ctx->part_count = parts;
	if (!parts)
		return MLOD_OK;
	ctx->morph_offset = rt_calloc(ctx, (size_t)parts + 1, sizeof *ctx->morph_offset);
	if (!ctx->morph_offset)
		return mlod_fail(err, MLOD_ERR_NOMEM, "opening: out of memory for the morph weights");
	/* morph_offset[i + 1]: part i's targets, then summed in place. */
	for (uint32_t l = ctx->load ? L - 1 : 0; l < L; l++) {
		const mlod_pack_mesh *m = mesh_of(ctx, rt_unit_get(ctx, MLOD_RT_MESH, l, 0));
		for (uint32_t i = 0; m && i < m->part_count; i++) {
			const uint32_t k = m->parts[i].targets ? m->parts[i].rec.target_count : 0;
			if (k > ctx->morph_offset[i + 1])
				ctx->morph_offset[i + 1] = k;
		}
	}
	uint64_t total = 0;
	for (uint32_t i = 0; i < parts; i++) {
		total += ctx->morph_offset[i + 1];
		if (total > UINT32_MAX / 4)
			return mlod_fail(err, MLOD_ERR_LIMIT, "too many morph targets");
		ctx->morph_offset[i + 1] = (uint32_t)total;
	}
	if (total == 0)
		return MLOD_OK; /* no weights: morph_parts stays 0 */
	if (total > SIZE_MAX / sizeof(float) / 2 / ctx->max_instances)
		return mlod_fail(err, MLOD_ERR_LIMIT, "%llu morph targets: too many for %u instances",
		                 (unsigned long long)total, ctx->max_instances);
	ctx->morph_weights = rt_calloc(ctx, (size_t)total * ctx->max_instances, sizeof(float));
	if (!ctx->morph_weights)
		return mlod_fail(err, MLOD_ERR_NOMEM, "opening: out of memory for the morph weights");
	ctx->morph_parts = parts;
	ctx->morph_total = (uint32_t)total;
	return MLOD_OK;
}

mlod_result rt_ctx_finish_open(mlod_rt_ctx *ctx, mlod_error *err)
{
	const mlod_pack_skeleton *s = ctx->skel;
	const uint32_t J = s->joint_count;
	ctx->joint_count = J;
	ctx->skin_count = s->skin_count;
	/* A static prop (no skin, no animation) has no joints: its instances
	 * pose nothing and its static parts are written by their offsets. */
	if (J && !s->joints)
		return mlod_fail(err, MLOD_ERR_PARSE, "the skeleton's joints are missing");
	if (s->skin_count && (!s->skins || !s->skin_joints || !s->inverse_bind))
		return mlod_fail(err, MLOD_ERR_PARSE, "the skeleton's skins are incomplete");
	for (uint32_t j = 0; j < J; j++)
		if (s->joints[j].parent >= (int32_t)j)
			return mlod_fail(err, MLOD_ERR_PARSE, "joint %u: parent %d does not come first", j,
			                 (int)s->joints[j].parent);
	ctx->skin_offset = rt_calloc(ctx, s->skin_count + 1, sizeof *ctx->skin_offset);
	ctx->rest_world = rt_calloc(ctx, J, 16 * sizeof(float));
	ctx->rest_mat = rt_calloc(ctx, J, 16 * sizeof(float));
	ctx->rest_local = rt_calloc(ctx, J, sizeof *ctx->rest_local);
	ctx->all_joints = rt_calloc(ctx, J, sizeof *ctx->all_joints);
	ctx->all_needed = rt_calloc(ctx, J, 1);
	ctx->clip_duration = rt_calloc(ctx, ctx->clip_count + 1, sizeof(float));
	ctx->inst = rt_calloc(ctx, ctx->max_instances, sizeof *ctx->inst);
	const size_t motion_units = (size_t)ctx->levels[MLOD_RT_MOTION] * ctx->clip_count;
	ctx->chan_bytes = (3 * J + 7) / 8;
	ctx->chan_bits = motion_units ? rt_calloc(ctx, motion_units, ctx->chan_bytes) : NULL;
	if ((motion_units && !ctx->chan_bits) || !ctx->skin_offset || !ctx->rest_world || !ctx->rest_mat || !ctx->rest_local || !ctx->all_joints || !ctx->all_needed ||
	    !ctx->clip_duration || !ctx->inst)
		return mlod_fail(err, MLOD_ERR_NOMEM, "opening: out of memory");
	uint64_t pal = 0;
	for (uint32_t k = 0; k < s->skin_count; k++) {
		ctx->skin_offset[k] = (uint32_t)pal;
		if (s->skins[k].joint_count && (!s->skin_joints[k] || !s->inverse_bind[k]))
			return mlod_fail(err, MLOD_ERR_PARSE, "skin %u: no joints", k);
		for (uint32_t i = 0; i < s->skins[k].joint_count; i++)
			if (s->skin_joints[k][i] >= J)
				return mlod_fail(err, MLOD_ERR_PARSE, "skin %u: joint %u out of range", k, s->skin_joints[k][i]);
		pal += s->skins[k].joint_count;
		if (pal > UINT32_MAX / 64)
			return mlod_fail(err, MLOD_ERR_PARSE, "the skins have too many joints");
	}
	ctx->palette_size = (uint32_t)pal;
	ctx->pal_joint0 = rt_calloc(ctx, (size_t)pal + 1, sizeof *ctx->pal_joint0);
	ctx->pal_bind0 = rt_calloc(ctx, (size_t)pal + 1, sizeof *ctx->pal_bind0);
	ctx->pal_src0 = rt_calloc(ctx, (size_t)pal + 1, sizeof *ctx->pal_src0);
	if (!ctx->pal_joint0 || !ctx->pal_bind0 || !ctx->pal_src0)
		return mlod_fail(err, MLOD_ERR_NOMEM, "opening: out of memory");
	for (uint32_t k = 0; k < s->skin_count; k++)
		for (uint32_t i = 0; i < s->skins[k].joint_count; i++) {
			ctx->pal_joint0[ctx->skin_offset[k] + i] = s->skin_joints[k][i];
			ctx->pal_bind0[ctx->skin_offset[k] + i] = s->inverse_bind[k] + 16 * (size_t)i;
		}
	mlod_result pr = rt_palette_sources(ctx, (uint32_t)pal, ctx->pal_joint0, ctx->pal_bind0, ctx->pal_src0, err);
	if (pr != MLOD_OK)
		return pr;
	ctx->pal_bind_inv = rt_calloc(ctx, 16 * (size_t)pal + 1, sizeof *ctx->pal_bind_inv);
	if (!ctx->pal_bind_inv)
		return mlod_fail(err, MLOD_ERR_NOMEM, "opening: out of memory");
	for (uint32_t e = 0; e < pal; e++) {
		mlod_mat4 b, inv;
		memcpy(b.m, ctx->pal_bind0[e], sizeof b.m);
		/* affine (as skinning uses it), invertible, finite */
		int ok = b.m[3] == 0.0f && b.m[7] == 0.0f && b.m[11] == 0.0f && b.m[15] == 1.0f &&
		         mlod_mat4_invert(&b, &inv) == 0;
		inv.m[3] = inv.m[7] = inv.m[11] = 0.0f, inv.m[15] = 1.0f;
		for (int k = 0; k < 16 && ok; k++)
			ok = isfinite(inv.m[k]) && fabsf(inv.m[k]) < 1e18f;
		if (ok)
			memcpy(ctx->pal_bind_inv + 16 * (size_t)e, inv.m, sizeof inv.m);
	}
	for (uint32_t j = 0; j < J; j++) {
		const mlod_pack_joint_rec *jr = &s->joints[j];
		mlod_trs t = { { jr->t[0], jr->t[1], jr->t[2] },
		               { jr->r[0], jr->r[1], jr->r[2], jr->r[3] },
		               { jr->s[0], jr->s[1], jr->s[2] } };
		ctx->rest_local[j] = t;
		float *l = ctx->rest_mat + 16 * (size_t)j;
		rt_mat_trs(&t, l);
		rt_mat_mul(jr->parent < 0 ? jr->base : ctx->rest_world + 16 * (size_t)jr->parent, l,
		           ctx->rest_world + 16 * (size_t)j);
		ctx->all_joints[j] = j;
		ctx->all_needed[j] = 2;
	}
	for (uint32_t i = 0; i < ctx->max_instances; i++)
		ctx->inst[i].next_free = i + 1;
	ctx->free_head = 0;
	ctx->slot_bits = 1;
	while (ctx->slot_bits < 32 && (ctx->max_instances - 1) >> ctx->slot_bits)
		ctx->slot_bits++;

	/* The coarse levels, pinned. */
	for (uint32_t i = 0; i < ctx->unit_count; i++) {
		rt_unit *u = &ctx->units[i];
		u->coarse = u->level + 1u == ctx->levels[u->layer];
		if (!u->coarse && !(u->layer == MLOD_RT_SKELETON && u->level == 0))
			continue;
		mlod_result r = rt_unit_load(ctx, u, err);
		if (r)
			return r;
	}
	for (uint32_t c = 0; c < ctx->clip_count; c++) {
		const rt_unit *u = rt_unit_get(ctx, MLOD_RT_MOTION, ctx->levels[MLOD_RT_MOTION] - 1, c);
		float d = u && u->motion ? u->motion->duration : 0.0f;
		if (u && u->motion && !(d > 0.0f)) /* views may leave it 0: the largest key time */
			for (uint32_t k = 0; k < u->motion->channel_count; k++) {
				const mlod_pack_channel *ch = &u->motion->channels[k];
				if (ch->rec.key_count && ch->times[ch->rec.key_count - 1] > d)
					d = ch->times[ch->rec.key_count - 1];
			}
		ctx->clip_duration[c] = isfinite(d) && d > 0.0f ? d : 0.0f;
	}
	mlod_result mr = morph_setup(ctx, err);
	if (mr)
		return mr;
	ctx->open_bytes = ctx->resident_bytes; /* mlod_rt_stats.open_bytes, mlod_rt_open_*_bytes */
	if (ctx->resident_bytes > ctx->budget)
		return mlod_fail(err, MLOD_ERR_LIMIT,
		                 "the coarse levels need %zu bytes, more than the budget of %zu bytes",
		                 ctx->resident_bytes, ctx->budget);
	ctx->peak_bytes = ctx->resident_bytes;
	return MLOD_OK;
}

mlod_result mlod_rt_open_views(const mlod_rt_views *v, const mlod_rt_config *config, mlod_rt_ctx **out,
                               mlod_error *err)
{
	if (!out)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_rt_open_views: NULL argument");
	*out = NULL;
	if (rt_config_bad(config))
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_rt_open_views: the allocator has one of malloc and free");
	if (!v || !v->skeleton || v->skel_levels < 1 || !v->skel || (v->mesh_levels && !v->mesh) ||
	    (v->clip_count && v->motion_levels && !v->motion) || v->skel_levels > 65535 || v->mesh_levels > 65535 ||
	    v->motion_levels > 65535 || v->clip_count > 65535)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_rt_open_views: missing or oversized views");
	mlod_rt_ctx *ctx = rt_ctx_new(config);
	if (!ctx)
		return mlod_fail(err, MLOD_ERR_NOMEM, "opening: out of memory");
	ctx->skel = v->skeleton;
	if (rt_units_make(ctx, v->skel_levels, v->mesh_levels, v->clip_count, v->motion_levels)) {
		mlod_rt_close(ctx);
		return mlod_fail(err, MLOD_ERR_NOMEM, "opening: out of memory");
	}
	for (uint32_t i = 0; i < ctx->unit_count; i++) {
		rt_unit *u = &ctx->units[i];
		const mlod_rt_view_level *vl;
		if (i < ctx->unit_base[1])
			u->layer = MLOD_RT_SKELETON, u->level = (uint16_t)i, vl = &v->skel[i];
		else if (i < ctx->unit_base[2])
			u->layer = MLOD_RT_MESH, u->level = (uint16_t)(i - ctx->unit_base[1]), vl = &v->mesh[u->level];
		else {
			uint32_t k = i - ctx->unit_base[2];
			u->layer = MLOD_RT_MOTION;
			u->item = (uint16_t)(k / ctx->levels[2]);
			u->level = (uint16_t)(k % ctx->levels[2]);
			vl = &v->motion[k];
		}
		u->chunk = -1;
		u->view = vl;
		u->error = u->level ? vl->error : 0.0f;
		u->distance = u->level ? vl->distance : 0.0f;
		/* Views hold every level from open on: mlod_rt_max_vertex_count
		 * is their largest (a level check_mesh would refuse counts none) */
		const mlod_pack_mesh *m = u->layer == MLOD_RT_MESH ? vl->data : NULL;
		uint64_t nv = 0;
		for (uint32_t k = 0; m && m->parts && k < m->part_count; k++)
			nv += m->parts[k].rec.vertex_count;
		if (nv > ctx->max_vertices && nv <= UINT32_MAX / 2)
			ctx->max_vertices = (uint32_t)nv;
	}
	mlod_result r = rt_ctx_finish_open(ctx, err);
	if (r) {
		mlod_rt_close(ctx);
		return r;
	}
	*out = ctx;
	return MLOD_OK;
}

void mlod_rt_close(mlod_rt_ctx *ctx)
{
	if (!ctx)
		return;
	if (ctx->units)
		for (uint32_t i = 0; i < ctx->unit_count; i++)
			rt_unit_release(ctx, &ctx->units[i]);
	if (ctx->close_source)
		ctx->close_source(ctx);
	rt_free(ctx, ctx->units);
	rt_free(ctx, ctx->skin_offset);
	rt_free(ctx, ctx->rest_world);
	rt_free(ctx, ctx->rest_mat);
	rt_free(ctx, ctx->rest_local);
	rt_free(ctx, ctx->all_joints);
	rt_free(ctx, ctx->all_needed);
	rt_free(ctx, ctx->pal_joint0);
	rt_free(ctx, ctx->pal_bind0);
	rt_free(ctx, ctx->pal_bind_inv);
	rt_free(ctx, ctx->pal_src0);
	rt_free(ctx, ctx->clip_duration);
	rt_free(ctx, ctx->chan_bits);
	rt_free(ctx, ctx->inst);
	rt_free(ctx, ctx->morph_offset);
	rt_free(ctx, ctx->morph_weights);
	mlod_rt_allocator a = ctx->alloc;
	a.free(a.user, ctx);
}
