/*
 * rt_query.c: what a context tells: level and clip counts, durations,
 * level info, mesh parts, the stats; names, the hierarchy and the
 * character.
 */
#include <string.h>

#include "pack_internal.h"
#include "rt_internal.h"

/* ---------------------------------------------------------------- */
/* Queries                                                           */
/* ---------------------------------------------------------------- */

uint32_t mlod_rt_level_count(const mlod_rt_ctx *ctx, mlod_rt_layer layer)
{
	return ctx && (unsigned)layer < MLOD_RT_LAYERS ? ctx->levels[layer] : 0;
}

uint32_t mlod_rt_clip_count(const mlod_rt_ctx *ctx) { return ctx ? ctx->clip_count : 0; }
uint32_t mlod_rt_joint_count(const mlod_rt_ctx *ctx) { return ctx ? ctx->joint_count : 0; }
uint32_t mlod_rt_palette_size(const mlod_rt_ctx *ctx) { return ctx ? ctx->palette_size : 0; }
uint32_t mlod_rt_max_vertex_count(const mlod_rt_ctx *ctx) { return ctx ? ctx->max_vertices : 0; }

float mlod_rt_clip_duration(const mlod_rt_ctx *ctx, uint32_t clip)
{
	return ctx && clip < ctx->clip_count ? ctx->clip_duration[clip] : 0.0f;
}

/* ---------------------------------------------------------------- */
/* Names, hierarchy and the character                                */
/* ---------------------------------------------------------------- */

mlod_result mlod_rt_character_get(const mlod_rt_ctx *ctx, mlod_rt_character *out, mlod_error *err)
{
	if (!ctx || !out)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_rt_character_get: NULL argument");
	memset(out, 0, sizeof *out);
	out->name = "";
	if (!ctx->info_owned)
		return MLOD_OK; /* views: no INFO */
	const mlod_pack_info_rec *r = &ctx->info.rec;
	out->name = ctx->info.name ? ctx->info.name : "";
	for (int k = 0; k < 3; k++)
		out->bounds_min[k] = r->bounds_min[k], out->bounds_max[k] = r->bounds_max[k];
	out->height = r->height;
	out->diagonal = r->diagonal;
	return MLOD_OK;
}

const char *mlod_rt_clip_name(const mlod_rt_ctx *ctx, uint32_t clip)
{
	if (!ctx || clip >= ctx->clip_count)
		return NULL;
	return ctx->info_owned && ctx->info.clip_names && ctx->info.clip_names[clip] ? ctx->info.clip_names[clip] : "";
}

mlod_result mlod_rt_clip_find(const mlod_rt_ctx *ctx, const char *name, uint32_t *clip, mlod_error *err)
{
	if (!ctx || !name || !clip)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_rt_clip_find: NULL argument");
	for (uint32_t k = 0; k < ctx->clip_count; k++)
		if (strcmp(mlod_rt_clip_name(ctx, k), name) == 0) {
			*clip = k;
			return MLOD_OK;
		}
	return mlod_fail(err, MLOD_ERR_INVALID_ARG, "no clip named \"%.200s\" (of %u clips)", name, ctx->clip_count);
}

const char *mlod_rt_joint_name(const mlod_rt_ctx *ctx, uint32_t joint)
{
	if (!ctx || joint >= ctx->joint_count)
		return NULL;
	return ctx->skel->joint_names && ctx->skel->joint_names[joint] ? ctx->skel->joint_names[joint] : "";
}

int32_t mlod_rt_joint_parent(const mlod_rt_ctx *ctx, uint32_t joint)
{
	return ctx && joint < ctx->joint_count ? ctx->skel->joints[joint].parent : -1;
}

mlod_result mlod_rt_joint_find(const mlod_rt_ctx *ctx, const char *name, uint32_t *joint, mlod_error *err)
{
	if (!ctx || !name || !joint)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_rt_joint_find: NULL argument");
	for (uint32_t j = 0; j < ctx->joint_count; j++)
		if (strcmp(mlod_rt_joint_name(ctx, j), name) == 0) {
			*joint = j;
			return MLOD_OK;
		}
	return mlod_fail(err, MLOD_ERR_INVALID_ARG, "no joint named \"%.200s\" (of %u joints)", name,
	                 ctx->joint_count);
}

static const float rt_identity[16] = { 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1 };

mlod_result mlod_rt_joint_level_get(const mlod_rt_ctx *ctx, uint32_t level, uint32_t joint, mlod_rt_joint_level *out,
                                    mlod_error *err)
{
	if (!ctx || !out)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_rt_joint_level_get: NULL argument");
	if (joint >= ctx->joint_count)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "joint %u out of range (%u joints)", joint, ctx->joint_count);
	const rt_unit *u = rt_unit_get(ctx, MLOD_RT_SKELETON, level, 0);
	if (!u)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "skeleton level %u out of range (%u levels)", level,
		                 ctx->levels[MLOD_RT_SKELETON]);
	const mlod_pack_joint_rec *jr = ctx->skel->joints;
	if (level == 0) {
		out->kept = out->posed = 1;
		out->stand_in = joint;
		out->parent = jr[joint].parent;
		out->rest_from_stand_in = rt_identity;
		return MLOD_OK;
	}
	if (u->state != RT_UNIT_RESIDENT)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "skeleton level %u is not resident", level);
	const rt_skel_plan *p = &u->plan;
	out->kept = p->needed[joint] == 2;
	out->posed = p->needed[joint] != 0;
	out->stand_in = (uint32_t)p->stand[joint];
	int32_t a = jr[joint].parent;
	while (a >= 0 && p->needed[a] != 2)
		a = jr[a].parent;
	out->parent = a;
	out->rest_from_stand_in = p->rel + 16 * (size_t)joint;
	return MLOD_OK;
}

mlod_result mlod_rt_level_info_get(const mlod_rt_ctx *ctx, mlod_rt_layer layer, uint32_t level, uint32_t item,
                                   mlod_rt_level_info *out, mlod_error *err)
{
	if (!ctx || !out)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_rt_level_info_get: NULL argument");
	const rt_unit *u = rt_unit_get(ctx, layer, level, item);
	if (!u)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "no such level");
	out->error = u->error;
	out->distance = u->distance;
	out->stored_size = u->stored_size;
	out->bytes = u->state == RT_UNIT_RESIDENT ? u->bytes : 0;
	out->resident = u->state == RT_UNIT_RESIDENT;
	out->failed = u->state == RT_UNIT_FAILED;
	out->users = u->users;
	out->no_room = u->no_room;
	return MLOD_OK;
}

uint32_t mlod_rt_mesh_vertex_count(const mlod_rt_ctx *ctx, uint32_t level)
{
	const rt_unit *u = ctx ? rt_unit_get(ctx, MLOD_RT_MESH, level, 0) : NULL;
	return u && u->state == RT_UNIT_RESIDENT ? u->vertex_count : 0;
}

uint32_t mlod_rt_mesh_part_count(const mlod_rt_ctx *ctx, uint32_t level)
{
	const rt_unit *u = ctx ? rt_unit_get(ctx, MLOD_RT_MESH, level, 0) : NULL;
	return u && u->state == RT_UNIT_RESIDENT ? u->mesh->part_count : 0;
}

mlod_result mlod_rt_mesh_part(const mlod_rt_ctx *ctx, uint32_t level, uint32_t part, mlod_rt_part_info *out,
                              mlod_error *err)
{
	const rt_unit *u = ctx && out ? rt_unit_get(ctx, MLOD_RT_MESH, level, 0) : NULL;
	if (!u || u->state != RT_UNIT_RESIDENT || part >= u->mesh->part_count)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mesh level %u part %u: not resident or out of range", level,
		                 part);
	uint32_t first = 0;
	for (uint32_t i = 0; i < part; i++)
		first += u->mesh->parts[i].rec.vertex_count;
	const mlod_pack_part *p = &u->mesh->parts[part];
	out->first_vertex = first;
	out->vertex_count = p->rec.vertex_count;
	out->index_count = p->indices ? p->rec.index_count : 0;
	out->indices = p->indices;
	out->material = p->rec.material;
	out->skin = p->rec.skin;
	out->joint = p->rec.joint;
	out->instance = p->rec.instance;
	out->node = p->rec.node;
	out->target_count = mlod_rt_morph_target_count(ctx, part);
	out->attributes = p;
	out->palette_first = p->rec.skin >= 0 ? ctx->skin_offset[p->rec.skin] : 0;
	return MLOD_OK;
}

void mlod_rt_stats_get(const mlod_rt_ctx *ctx, mlod_rt_stats *out)
{
	if (!out)
		return;
	memset(out, 0, sizeof *out);
	if (!ctx)
		return;
	out->resident_bytes = ctx->resident_bytes;
	out->budget_bytes = ctx->budget == SIZE_MAX ? 0 : ctx->budget; /* 0: no limit, as configured */
	out->peak_resident_bytes = ctx->peak_bytes;
	out->open_bytes = ctx->open_bytes;
	out->loads = ctx->loads;
	out->evictions = ctx->evictions;
	out->failures = ctx->failures;
	for (uint32_t i = 0; i < ctx->unit_count; i++) {
		const rt_unit *u = &ctx->units[i];
		out->resident_levels += u->state == RT_UNIT_RESIDENT;
		out->pending_levels += u->state == RT_UNIT_ABSENT && u->want_count > 0;
	}
}
