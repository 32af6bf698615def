/*
 * rt_ctx.c: the runtime context: allocation, levels and the resident-level
 * cache (loading, LRU eviction under the budget, streaming), instances and
 * the fallback rule. The pack source lives in rt_pack.c; views open here.
 */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pack_internal.h"
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

static void *rt_calloc(const mlod_rt_ctx *ctx, size_t n, size_t size)
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
	ctx->budget = config && config->budget_bytes ? config->budget_bytes : SIZE_MAX;
	ctx->max_instances = config && config->max_instances ? config->max_instances : 1024;
	ctx->streamed = 1; /* the first update starts a frame */
	return ctx;
}

rt_unit *rt_unit_get(const mlod_rt_ctx *ctx, mlod_rt_layer layer, uint32_t level, uint32_t item)
{
	if ((unsigned)layer >= MLOD_RT_LAYERS || level >= ctx->levels[layer])
		return NULL;
	if (layer == MLOD_RT_MOTION) {
		if (item >= ctx->clip_count)
			return NULL;
		return &ctx->units[ctx->unit_base[layer] + item * ctx->levels[layer] + level];
	}
	return &ctx->units[ctx->unit_base[layer] + level];
}

/* ---------------------------------------------------------------- */
/* Byte counts                                                       */
/* ---------------------------------------------------------------- */

size_t rt_bytes_skel_level(const mlod_pack_skel_level *l)
{
	return sizeof *l + (size_t)l->kept_count * 4 + (size_t)l->palette_size * (4 + 64);
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
	/* A decoded level's block is sized by an upper bound from its stream
	 * headers (lib/rt/rd_motion.c): what it holds is counted when it is all. */
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
/* Checking and preparing a loaded unit                              */
/* ---------------------------------------------------------------- */

static mlod_result check_mesh(const mlod_rt_ctx *ctx, const mlod_pack_mesh *m, uint32_t level, uint32_t *vertices,
                              mlod_error *err)
{
	uint64_t total = 0;
	if (m->part_count && !m->parts)
		return mlod_fail(err, MLOD_ERR_PARSE, "mesh level %u: no parts", level);
	for (uint32_t i = 0; i < m->part_count; i++) {
		const mlod_pack_part *p = &m->parts[i];
		const uint32_t n = p->rec.vertex_count;
		if (n && !p->positions)
			return mlod_fail(err, MLOD_ERR_PARSE, "mesh level %u part %u: no positions", level, i);
		if (p->rec.joint >= 0 && (uint32_t)p->rec.joint >= ctx->joint_count)
			return mlod_fail(err, MLOD_ERR_PARSE, "mesh level %u part %u: joint %d out of range", level, i,
			                 (int)p->rec.joint);
		if (p->rec.skin >= 0) {
			if ((uint32_t)p->rec.skin >= ctx->skin_count)
				return mlod_fail(err, MLOD_ERR_PARSE, "mesh level %u part %u: skin %d out of range", level, i,
				                 (int)p->rec.skin);
			if (n && (!p->joints || !p->weights))
				return mlod_fail(err, MLOD_ERR_PARSE, "mesh level %u part %u: skinned without weights", level,
				                 i);
			const uint32_t sj = ctx->skel->skins[p->rec.skin].joint_count;
			for (size_t k = 0; k < 4 * (size_t)n; k++)
				if (p->joints[k] >= sj)
					return mlod_fail(err, MLOD_ERR_PARSE,
					                 "mesh level %u part %u: vertex joint %u outside its skin of %u", level, i,
					                 (unsigned)p->joints[k], sj);
		}
		if (p->rec.index_count % 3 || (p->rec.index_count && !p->indices))
			return mlod_fail(err, MLOD_ERR_PARSE, "mesh level %u part %u: %u indices", level, i, p->rec.index_count);
		for (uint32_t k = 0; k < p->rec.index_count; k++)
			if (p->indices[k] >= n)
				return mlod_fail(err, MLOD_ERR_PARSE, "mesh level %u part %u: index %u of %u vertices", level, i,
				                 p->indices[k], n);
		total += n;
		if (total > UINT32_MAX / 2)
			return mlod_fail(err, MLOD_ERR_PARSE, "mesh level %u: too many vertices", level);
	}
	*vertices = (uint32_t)total;
	return MLOD_OK;
}

static mlod_result check_motion(const mlod_rt_ctx *ctx, const mlod_pack_motion *m, uint32_t level, uint32_t clip,
                                mlod_error *err)
{
	if (m->channel_count && !m->channels)
		return mlod_fail(err, MLOD_ERR_PARSE, "motion level %u of clip %u: no channels", level, clip);
	for (uint32_t i = 0; i < m->channel_count; i++) {
		const mlod_pack_channel_rec *c = &m->channels[i].rec;
		if (c->joint >= ctx->joint_count || c->path > 2 || c->interp > 2 ||
		    (c->key_count && (!m->channels[i].times || !m->channels[i].values)))
			return mlod_fail(err, MLOD_ERR_PARSE, "motion level %u of clip %u: channel %u is malformed", level,
			                 clip, i);
	}
	return MLOD_OK;
}

static void mat_identity(float *m)
{
	memset(m, 0, 16 * sizeof *m);
	m[0] = m[5] = m[10] = m[15] = 1.0f;
}

/* The runtime's tables of a motion level (prepare_motion): a fixed-matrix
 * index per joint, the A channels of its animated joints, and the
 * matrices of its S joints with one-key channels only: 4 bytes per joint
 * and per such channel, 64 per such joint. */
static size_t motion_plan_bytes(uint32_t J, uint32_t A, uint32_t S)
{
	return ((size_t)J + A) * sizeof(uint32_t) + 16 * sizeof(float) * (size_t)S;
}

/* Checks a motion level and sets its channel bits (ctx->chan_bits). A
 * level the runtime decoded (owned) has the keys of a non-cubic rotation
 * replaced by their normalisation when each of those is its own: sampling
 * normalises every key it reads (mlod_quat_slerp, and sample_one after
 * a key or STEP), so the samples stay the same floats, and the keys need
 * no normalising per frame. The caller's views are only read. */
static mlod_result prepare_motion(mlod_rt_ctx *ctx, rt_unit *u, const mlod_pack_motion *m, mlod_error *err)
{
	mlod_result r = check_motion(ctx, m, u->level, u->item, err);
	if (r)
		return r;
	/* The joints' fixed local matrices and the animated joints' channels. */
	const uint32_t J = ctx->joint_count, C = m->channel_count;
	/* [j]: has a channel; [J + j]: one with more than one key */
	uint8_t *mark = rt_calloc(ctx, (size_t)J + 1, 2);
	mlod_trs *l = rt_calloc(ctx, (size_t)J + 1, sizeof *l);
	if (!mark || !l) {
		rt_free(ctx, mark), rt_free(ctx, l);
		return mlod_fail(err, MLOD_ERR_NOMEM, "motion level %u of clip %u: out of memory", u->level, u->item);
	}
	for (uint32_t i = 0; i < C; i++) {
		mark[m->channels[i].rec.joint] = 1;
		if (m->channels[i].rec.key_count > 1)
			mark[J + m->channels[i].rec.joint] = 1;
	}
	uint32_t S = 0, A = 0;
	for (uint32_t j = 0; j < J; j++)
		S += mark[j] && !mark[J + j];
	for (uint32_t i = 0; i < C; i++)
		A += mark[J + m->channels[i].rec.joint];
	const size_t cbytes = motion_plan_bytes(J, A, S);
	uint32_t *cblock = rt_alloc(ctx, cbytes ? cbytes : 4);
	if (!cblock) {
		rt_free(ctx, mark), rt_free(ctx, l);
		return mlod_fail(err, MLOD_ERR_NOMEM, "motion level %u of clip %u: out of memory", u->level, u->item);
	}
	u->plan_block = cblock;
	u->bytes += cbytes;
	u->fixed = cblock, u->anim = cblock + J, u->anim_count = A;
	u->static_mat = (float *)(u->anim + A);
	uint32_t k = 0;
	for (uint32_t j = 0; j < J; j++) {
		u->fixed[j] = mark[J + j] ? 0 : mark[j] ? 2 + k++ : 1;
		l[j] = ctx->rest_local[j];
	}
	A = 0;
	for (uint32_t i = 0; i < C; i++) {
		const mlod_pack_channel *ch = &m->channels[i];
		const uint32_t j = ch->rec.joint;
		if (!u->fixed[j]) {
			u->anim[A++] = i;
			continue;
		}
		if (ch->rec.key_count != 1)
			continue;
		/* sample_one's copy of a lone key (normalised if a rotation) */
		const int rot = ch->rec.path == 1, cubic = ch->rec.interp == 2;
		const float *q = ch->values + (cubic ? (rot ? 4 : 3) : 0);
		if (rot)
			l[j].r = mlod_quat_normalize((mlod_quat){ q[0], q[1], q[2], q[3] });
		else if (ch->rec.path == 0)
			l[j].t.x = q[0], l[j].t.y = q[1], l[j].t.z = q[2];
		else
			l[j].s.x = q[0], l[j].s.y = q[1], l[j].s.z = q[2];
	}
	for (uint32_t j = 0; j < J; j++)
		if (u->fixed[j] >= 2)
			rt_trs_cols(&l[j], u->static_mat + 16 * (size_t)(u->fixed[j] - 2));
	rt_free(ctx, mark), rt_free(ctx, l);
	if (!ctx->chan_bits)
		return MLOD_OK;
	uint8_t *bits = ctx->chan_bits + (size_t)(u - &ctx->units[ctx->unit_base[MLOD_RT_MOTION]]) * ctx->chan_bytes;
	memset(bits, 0, ctx->chan_bytes);
	for (uint32_t i = 0; i < m->channel_count && i < 8 * ctx->chan_bytes; i++) {
		const mlod_pack_channel *ch = &m->channels[i];
		if (ch->rec.path != 1 || ch->rec.interp == 2)
			continue;
		/* unit: every key its own normalisation; norm: every key's
		 * normalisation its own (then an owned level takes them). */
		int unit = 1, norm = u->owned;
		for (uint32_t k = 0; k < ch->rec.key_count && (unit || norm); k++) {
			const float *q = ch->values + 4 * (size_t)k;
			mlod_quat a = { q[0], q[1], q[2], q[3] };
			mlod_quat b = mlod_quat_normalize(a), c = mlod_quat_normalize(b);
			unit &= memcmp(&a, &b, sizeof a) == 0;
			norm &= memcmp(&b, &c, sizeof b) == 0;
		}
		if (!unit && norm) {
			for (uint32_t k = 0; k < ch->rec.key_count; k++) {
				float *q = ch->values + 4 * (size_t)k;
				mlod_quat b = mlod_quat_normalize((mlod_quat){ q[0], q[1], q[2], q[3] });
				q[0] = b.x, q[1] = b.y, q[2] = b.z, q[3] = b.w;
			}
			unit = 1;
		}
		if (unit)
			bits[i >> 3] |= (uint8_t)(1u << (i & 7));
	}
	u->chan_flags = bits;
	return MLOD_OK;
}

/* Palette sources (rt_internal.h): the entries sorted by joint, then by
 * their bind matrix's bytes, then by index, so that equal entries stand
 * together with their first one leading: O(n log n), a hostile palette
 * included. */
typedef struct pal_key {
	uint32_t joint, index;
	const float *bind;
} pal_key;

static int pal_key_cmp(const void *a, const void *b)
{
	const pal_key *x = a, *y = b;
	if (x->joint != y->joint)
		return x->joint < y->joint ? -1 : 1;
	int c = memcmp(x->bind, y->bind, 16 * sizeof(float));
	if (c)
		return c;
	return x->index < y->index ? -1 : x->index > y->index;
}

mlod_result rt_palette_sources(const mlod_rt_ctx *ctx, uint32_t n, const uint32_t *joint,
                               const float *const *bind, uint32_t *src, mlod_error *err)
{
	if (n == 0)
		return MLOD_OK;
	pal_key *k = rt_alloc(ctx, (size_t)n * sizeof *k);
	if (!k)
		return mlod_fail(err, MLOD_ERR_NOMEM, "palette: out of memory");
	for (uint32_t e = 0; e < n; e++)
		k[e] = (pal_key){ joint[e], e, bind[e] };
	qsort(k, n, sizeof *k, pal_key_cmp);
	for (uint32_t i = 0, first = 0; i < n; i++) {
		if (i && (k[i].joint != k[i - 1].joint || memcmp(k[i].bind, k[i - 1].bind, 16 * sizeof(float))))
			first = i;
		src[k[i].index] = k[first].index;
	}
	rt_free(ctx, k);
	return MLOD_OK;
}

/* Builds the plan of a skeleton level (level >= 1) into one block. */
static mlod_result prepare_skel(mlod_rt_ctx *ctx, rt_unit *u, const mlod_pack_skel_level *l, mlod_error *err)
{
	const uint32_t J = ctx->joint_count;
	if (l->kept_count == 0 || l->kept_count > J || !l->kept)
		return mlod_fail(err, MLOD_ERR_PARSE, "skeleton level %u: %u kept joints of %u", u->level, l->kept_count,
		                 J);
	if (l->palette_size != ctx->palette_size || (l->palette_size && (!l->palette_joint || !l->palette_bind)))
		return mlod_fail(err, MLOD_ERR_PARSE, "skeleton level %u: palette of %u entries, the skins have %u",
		                 u->level, l->palette_size, ctx->palette_size);
	const size_t P = l->palette_size;
	size_t bytes = (size_t)J * (4 + 1 + 4 + 64) + P * 4;
	uint8_t *block = rt_alloc(ctx, bytes);
	if (!block)
		return mlod_fail(err, MLOD_ERR_NOMEM, "skeleton level %u: out of memory", u->level);
	rt_skel_plan *p = &u->plan;
	p->rel = (float *)block;
	p->stand = (int32_t *)(block + (size_t)J * 64);
	p->posed = (uint32_t *)(block + (size_t)J * 68);
	p->palette_src = (uint32_t *)(block + (size_t)J * 72);
	p->needed = block + (size_t)J * 72 + P * 4;
	memset(p->needed, 0, J);
	mlod_result r = MLOD_OK;
	for (uint32_t i = 0; i < l->kept_count; i++) {
		if (l->kept[i] >= J || (i && l->kept[i] <= l->kept[i - 1])) {
			r = mlod_fail(err, MLOD_ERR_PARSE, "skeleton level %u: kept joints not increasing inside %u",
			              u->level, J);
			goto fail;
		}
		p->needed[l->kept[i]] = 2; /* 2: kept */
	}
	for (uint32_t j = 0; j < J; j++) {
		int32_t par = ctx->skel->joints[j].parent;
		if (par < 0 && p->needed[j] != 2) {
			r = mlod_fail(err, MLOD_ERR_PARSE, "skeleton level %u: root joint %u is not kept", u->level, j);
			goto fail;
		}
		p->stand[j] = p->needed[j] == 2 ? (int32_t)j : p->stand[par];
	}
	/* Removed ancestors of kept joints are posed too (folded at run time). */
	for (uint32_t i = l->kept_count; i-- > 0;) {
		for (int32_t a = ctx->skel->joints[l->kept[i]].parent; a >= 0 && !p->needed[a]; a = ctx->skel->joints[a].parent)
			p->needed[a] = 1;
	}
	p->posed_count = 0;
	for (uint32_t j = 0; j < J; j++)
		if (p->needed[j])
			p->posed[p->posed_count++] = j;
	for (uint32_t i = 0; i < l->palette_size; i++)
		if (l->palette_joint[i] >= J || p->needed[l->palette_joint[i]] != 2) {
			r = mlod_fail(err, MLOD_ERR_PARSE, "skeleton level %u: palette entry %u follows joint %u, not kept",
			              u->level, i, l->palette_joint[i]);
			goto fail;
		}
	for (uint32_t j = 0; j < J; j++) {
		float *rel = p->rel + 16 * (size_t)j;
		if (p->stand[j] == (int32_t)j) {
			mat_identity(rel);
			continue;
		}
		mlod_mat4 sw, inv;
		memcpy(sw.m, ctx->rest_world + 16 * (size_t)p->stand[j], sizeof sw.m);
		if (mlod_mat4_invert(&sw, &inv) != 0) {
			mat_identity(rel);
			continue;
		}
		rt_mat_mul(inv.m, ctx->rest_world + 16 * (size_t)j, rel);
	}
	if (P) {
		const float **bind = rt_alloc(ctx, P * sizeof *bind);
		if (!bind) {
			r = mlod_fail(err, MLOD_ERR_NOMEM, "skeleton level %u: out of memory", u->level);
			goto fail;
		}
		for (size_t e = 0; e < P; e++)
			bind[e] = l->palette_bind + 16 * e;
		r = rt_palette_sources(ctx, (uint32_t)P, l->palette_joint, bind, p->palette_src, err);
		rt_free(ctx, bind);
		if (r != MLOD_OK)
			goto fail;
	}
	p->kept_count = l->kept_count;
	p->kept = l->kept;
	p->palette_joint = l->palette_joint;
	p->palette_bind = l->palette_bind;
	u->plan_block = block;
	u->bytes += bytes;
	return MLOD_OK;
fail:
	rt_free(ctx, block);
	memset(p, 0, sizeof *p);
	return r;
}

/* 1 when n normals (3 floats each) all have unit length to within
 * RT_UNIT_TOL (| |n|^2 - 1 | <= 2 RT_UNIT_TOL), else 0 (none: 0). */
static uint32_t rt_unit_normals(const float *nrm, size_t n)
{
	if (!nrm)
		return 0;
	for (size_t v = 0; v < n; v++) {
		const double x = nrm[3 * v], y = nrm[3 * v + 1], z = nrm[3 * v + 2];
		if (!(fabs(x * x + y * y + z * z - 1.0) <= 2.0 * RT_UNIT_TOL))
			return 0;
	}
	return 1;
}

/* The bytes of a mesh level's bucket tables (prepare_mesh): an offset per
 * part and each skinned part's RT_SKIN_ORDER_BYTES. */
static size_t skin_order_bytes(const mlod_pack_mesh *m)
{
	size_t b = 4 * (size_t)m->part_count;
	for (uint32_t i = 0; i < m->part_count; i++)
		if (m->parts[i].rec.skin >= 0)
			b += RT_SKIN_ORDER_BYTES(m->parts[i].rec.vertex_count);
	return b;
}

/* The bytes of a mesh level's bound tables (prepare_bounds): 13 floats
 * per palette entry, 7 per part, one per morph target and an offset per
 * part and one more. */
static size_t bound_bytes(uint32_t palette_size, uint32_t parts, size_t targets)
{
	return 4 * (13 * (size_t)palette_size + 7 * (size_t)parts + targets + parts + 1);
}

/* The bytes prepare_mesh allocates for a decoded level. */
static size_t mesh_tables_bytes(const mlod_rt_ctx *ctx, const mlod_pack_mesh *m)
{
	size_t T = 0;
	for (uint32_t i = 0; i < m->part_count; i++)
		T += m->parts[i].rec.target_count;
	return 4 * ((size_t)ctx->palette_size + ctx->joint_count) + skin_order_bytes(m) +
	       bound_bytes(ctx->palette_size, m->part_count, T);
}

/* The bytes prepare_mesh allocates for a level of these part records. */
static size_t mesh_plan_bytes(const mlod_rt_ctx *ctx, const mlod_pack_part_rec *recs, uint32_t n)
{
	size_t b = 4 * ((size_t)ctx->palette_size + ctx->joint_count) + 4 * (size_t)n, t = 0;
	for (uint32_t i = 0; i < n; i++) {
		if (recs[i].skin >= 0)
			b += RT_SKIN_ORDER_BYTES(recs[i].vertex_count);
		t += recs[i].target_count;
	}
	return b + bound_bytes(ctx->palette_size, n, t);
}

/* x rounded up to a float; sqrt(x) rounded up. */
static float float_up(double x)
{
	float f = (float)x;
	if ((double)f < x)
		f = nextafterf(f, INFINITY);
	return f;
}

static float sqrt_up(double x) { return float_up(sqrt(x)); }

/* Bounds accumulate per set of points: its box, then the largest squared
 * distance from the box's middle. */
typedef struct bound_acc {
	double lo[3], hi[3], r2;
	float c[3];
	size_t n;
} bound_acc;

static inline double dmin(double a, double b) { return a < b ? a : b; }
static inline double dmax(double a, double b) { return a > b ? a : b; }

static void acc_init(bound_acc *a)
{
	for (int k = 0; k < 3; k++)
		a->lo[k] = INFINITY, a->hi[k] = -INFINITY;
	a->r2 = 0;
	a->n = 0;
}

static void acc_box(bound_acc *a, const double *x)
{
	a->n++;
	for (int k = 0; k < 3; k++)
		a->lo[k] = dmin(a->lo[k], x[k]), a->hi[k] = dmax(a->hi[k], x[k]);
}

/* Rounds the centre to floats (after the first pass). */
static int acc_centre(bound_acc *a)
{
	if (!a->n)
		return 0;
	for (int k = 0; k < 3; k++)
		a->c[k] = (float)(0.5 * (a->lo[k] + a->hi[k]));
	return 1;
}

static void acc_ball(bound_acc *a, const double *x)
{
	const double dx = x[0] - a->c[0], dy = x[1] - a->c[1], dz = x[2] - a->c[2];
	a->r2 = dmax(a->r2, dx * dx + dy * dy + dz * dz);
}

/* out: centre, half extents (each the larger distance from the float
 * centre to the box's sides, rounded up) and, with ball, the radius. No
 * point: half extent x (and radius) -1. A coordinate not finite (hostile
 * views, or a huge inverse bind): with ball, centre 0 and half extents
 * and radius FLT_MAX, a box that holds anything; without, half extent x
 * -1 (not used). */
static void acc_write(const bound_acc *a, int ball, float *out)
{
	int ok = 1;
	for (int k = 0; k < 3 && ok; k++) {
		out[k] = a->c[k];
		out[3 + k] = float_up(dmax(a->hi[k] - a->c[k], a->c[k] - a->lo[k]));
		ok = isfinite(out[k]) && isfinite(out[3 + k]);
	}
	if (ball) {
		out[6] = sqrt_up(a->r2);
		ok = ok && isfinite(out[6]);
	}
	if (a->n && ok)
		return;
	for (int k = 0; k < 3; k++)
		out[k] = 0.0f, out[3 + k] = a->n && ball ? FLT_MAX : 0.0f;
	if (!a->n || !ball)
		out[3] = -1.0f;
	if (ball)
		out[6] = a->n ? FLT_MAX : -1.0f;
}

/* q = B x for the affine B (column-major), in double. */
static void affine_d(const float *B, const float *x, double *q)
{
	for (int k = 0; k < 3; k++)
		q[k] = (double)B[k] * x[0] + (double)B[4 + k] * x[1] + (double)B[8 + k] * x[2] + B[12 + k];
}

/* A mesh level's bound tables (rt_internal.h, bound_entry and the
 * others) in area (bound_bytes): two passes over the vertices, the boxes
 * (for the centres), then the balls; acc holds 2 per palette entry. */
static void prepare_bounds(const mlod_rt_ctx *ctx, rt_unit *u, const mlod_pack_mesh *m, float *area, bound_acc *acc)
{
	const uint32_t P = ctx->palette_size, n = m->part_count;
	u->bound_entry = area;
	u->bound_part = area + 13 * (size_t)P;
	u->bound_morph = u->bound_part + 7 * (size_t)n;
	size_t T = 0;
	for (uint32_t i = 0; i < n; i++)
		T += m->parts[i].rec.target_count;
	u->bound_morph_at = (uint32_t *)(u->bound_morph + T);
	for (size_t e = 0; e < 2 * (size_t)P; e++)
		acc_init(&acc[e]);
	for (int pass = 0; pass < 2; pass++) {
		for (uint32_t i = 0; i < n; i++) {
			const mlod_pack_part *p = &m->parts[i];
			if (p->rec.skin < 0)
				continue;
			const uint32_t off = ctx->skin_offset[p->rec.skin];
			for (size_t v = 0; v < p->rec.vertex_count; v++) {
				const float *x = p->positions + 3 * v;
				const double xd[3] = { x[0], x[1], x[2] };
				for (int q = 0; q < 4; q++) {
					if (!(p->weights[4 * v + q] > 0.0f))
						continue;
					const size_t e = off + p->joints[4 * v + q];
					if (pass == 0) {
						double jq[3];
						affine_d(ctx->pal_bind0[e], x, jq);
						acc_box(&acc[2 * e], xd);
						acc_box(&acc[2 * e + 1], jq);
					} else {
						acc_ball(&acc[2 * e], xd);
					}
				}
			}
		}
		for (uint32_t e = 0; e < P && pass == 0; e++)
			acc_centre(&acc[2 * (size_t)e]), acc_centre(&acc[2 * (size_t)e + 1]);
	}
	for (uint32_t e = 0; e < P; e++) {
		float *b = u->bound_entry + 13 * (size_t)e;
		acc_write(&acc[2 * (size_t)e], 1, b);
		acc_write(&acc[2 * (size_t)e + 1], 0, b + 7);
		if (ctx->pal_bind_inv[16 * (size_t)e + 15] == 0.0f)
			b[10] = -1.0f;
	}
	size_t at = 0;
	for (uint32_t i = 0; i < n; i++) {
		const mlod_pack_part *p = &m->parts[i];
		bound_acc a;
		acc_init(&a);
		for (int pass = 0; pass < 2 && p->rec.skin < 0; pass++) {
			for (size_t v = 0; v < p->rec.vertex_count; v++) {
				const double xd[3] = { p->positions[3 * v], p->positions[3 * v + 1], p->positions[3 * v + 2] };
				if (pass == 0)
					acc_box(&a, xd);
				else
					acc_ball(&a, xd);
			}
			if (pass == 0)
				acc_centre(&a);
		}
		acc_write(&a, 1, u->bound_part + 7 * (size_t)i);
		u->bound_morph_at[i] = (uint32_t)at;
		for (uint32_t t = 0; t < p->rec.target_count; t++) {
			double d2 = 0;
			const float *d = p->targets ? p->targets[t] : NULL;
			for (size_t v = 0; d && v < p->rec.vertex_count; v++)
				d2 = dmax(d2, (double)d[3 * v] * d[3 * v] + (double)d[3 * v + 1] * d[3 * v + 1] +
				                  (double)d[3 * v + 2] * d[3 * v + 2]);
			u->bound_morph[at++] = sqrt_up(d2);
		}
	}
	u->bound_morph_at[n] = (uint32_t)at;
}

/* Checks a mesh level and lists what skinning it reads (u->pal_used, the
 * palette entries, and u->rigid, the joints of its rigid parts), so that
 * mlod_rt_skin poses and multiplies only those. The kernel reads a
 * vertex's influences up to its last non-zero weight (at least the
 * first), zero weights before it too: each is listed, so the entries
 * left out are never read. */
static mlod_result prepare_mesh(mlod_rt_ctx *ctx, rt_unit *u, const mlod_pack_mesh *m, mlod_error *err)
{
	mlod_result r = check_mesh(ctx, m, u->level, &u->vertex_count, err);
	if (r)
		return r;
	const uint32_t P = ctx->palette_size, J = ctx->joint_count;
	size_t T = 0;
	for (uint32_t i = 0; i < m->part_count; i++)
		T += m->parts[i].rec.target_count;
	const size_t bbytes = bound_bytes(P, m->part_count, T);
	const size_t bytes = mesh_tables_bytes(ctx, m);
	uint32_t *block = rt_alloc(ctx, bytes);
	uint8_t *mark = rt_alloc(ctx, (P > J ? P : J) + 1);
	bound_acc *tmp = rt_alloc(ctx, 2 * sizeof(bound_acc) * (size_t)P + 8);
	if (!block || !mark || !tmp) {
		rt_free(ctx, block);
		rt_free(ctx, mark);
		rt_free(ctx, tmp);
		return mlod_fail(err, MLOD_ERR_NOMEM, "mesh level %u: out of memory", u->level);
	}
	memset(mark, 0, (P > J ? P : J) + 1);
	for (uint32_t i = 0; i < m->part_count; i++) {
		const mlod_pack_part *p = &m->parts[i];
		if (p->rec.skin < 0)
			continue;
		const uint32_t off = ctx->skin_offset[p->rec.skin];
		for (size_t v = 0; v < p->rec.vertex_count; v++) {
			const float *w = p->weights + 4 * v;
			const int k = w[3] != 0.0f ? 4 : w[2] != 0.0f ? 3 : w[1] != 0.0f ? 2 : 1;
			for (int q = 0; q < k; q++)
				mark[off + p->joints[4 * v + q]] = 1;
		}
	}
	u->pal_used = block;
	u->pal_used_count = 0;
	for (uint32_t e = 0; e < P; e++)
		if (mark[e])
			block[u->pal_used_count++] = e;
	memset(mark, 0, (P > J ? P : J) + 1);
	u->rigid = block + P;
	u->rigid_count = 0;
	for (uint32_t i = 0; i < m->part_count; i++) {
		const mlod_pack_part *p = &m->parts[i];
		if (p->rec.skin < 0 && p->rec.joint >= 0 && !mark[p->rec.joint]) {
			mark[p->rec.joint] = 1;
			u->rigid[u->rigid_count++] = (uint32_t)p->rec.joint;
		}
	}
	rt_free(ctx, mark);
	/* The skinned parts' influence-count buckets, once (rt_skin_order). */
	u->skin_order_at = block + P + J;
	prepare_bounds(ctx, u, m, (float *)(u->skin_order_at + m->part_count), tmp);
	rt_free(ctx, tmp);
	u->skin_order = (uint8_t *)(u->skin_order_at + m->part_count) + bbytes;
	size_t at = 0;
	for (uint32_t i = 0; i < m->part_count; i++) {
		const mlod_pack_part *p = &m->parts[i];
		u->skin_order_at[i] = (uint32_t)at;
		if (p->rec.skin < 0) {
			u->skin_order_at[i] = rt_unit_normals(p->normals, p->rec.vertex_count);
			continue;
		}
		rt_skin_order(p->rec.vertex_count, p->weights, u->skin_order + at);
		at += RT_SKIN_ORDER_BYTES(p->rec.vertex_count);
	}
	u->plan_block = block;
	u->bytes += bytes;
	return MLOD_OK;
}

/* ---------------------------------------------------------------- */
/* Loading and evicting                                              */
/* ---------------------------------------------------------------- */

static void unit_release(mlod_rt_ctx *ctx, rt_unit *u)
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
static mlod_result unit_load(mlod_rt_ctx *ctx, rt_unit *u, mlod_error *err)
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
	u->state = RT_UNIT_RESIDENT; /* for unit_release on failure below */
	switch (u->layer) {
	case MLOD_RT_SKELETON: r = prepare_skel(ctx, u, u->skel, err); break;
	case MLOD_RT_MESH: r = prepare_mesh(ctx, u, u->mesh, err); break;
	default: r = prepare_motion(ctx, u, u->motion, err); break;
	}
	ctx->resident_bytes += u->bytes;
	if (r) {
		unit_release(ctx, u);
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
		unit_release(ctx, v);
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
	u->need = rt_bytes_mesh_recs(parts, part_count) + mesh_plan_bytes(ctx, parts, part_count);
	if (!ctx->streaming || make_room(ctx, u->need) == 0)
		return MLOD_OK;
	ctx->refused = 1;
	return mlod_fail(err, MLOD_ERR_LIMIT, "mesh level %u: its %zu decoded bytes do not fit the budget", u->level,
	                 u->need);
}

/* motion_plan_bytes of a motion level's views, bounding its joints with
 * one-key channels only by the joints and by its one-key channels. */
static size_t motion_plan_hint(const mlod_rt_ctx *ctx, const mlod_pack_motion *m)
{
	const uint32_t J = ctx->joint_count, C = m->channel_count;
	uint32_t S = 0;
	for (uint32_t i = 0; i < C; i++)
		S += m->channels[i].rec.key_count == 1;
	return motion_plan_bytes(J, C, S < J ? S : J);
}

/* An upper bound of a unit's resident size before loading it, so that
 * room is made before decoding and resident bytes never pass the budget,
 * not even while a level decodes. Views know their size. A pack's mesh
 * level: its exact size once a load has read its part records (u->need),
 * else 0, as the reader calls rt_mesh_reserve with those records before
 * it allocates the decoded level, and room is made then. Other levels of
 * packs: dequantising at most quadruples a stream (unorm8 weights and
 * colours become floats; positions and normals grow less), the decoded
 * structs at most double their records, and the alignment of each stream
 * costs less than 4 times its 16-byte header; plus the skeleton level's
 * tables or the motion level's. */
static size_t size_hint(const mlod_rt_ctx *ctx, const rt_unit *u)
{
	size_t plan = u->layer == MLOD_RT_SKELETON ? (size_t)ctx->joint_count * (4 + 1 + 4 + 64)
	              : u->layer == MLOD_RT_MESH   ? 4 * ((size_t)ctx->palette_size + ctx->joint_count)
	                                           : 0;
	if (!ctx->load) {
		const mlod_rt_view_level *v = u->view;
		if (v && v->bytes && u->layer == MLOD_RT_MOTION)
			return v->bytes + (v->data ? motion_plan_hint(ctx, v->data) : 0);
		if (v && v->bytes)
			return v->bytes + (u->layer == MLOD_RT_MESH && v->data ? mesh_tables_bytes(ctx, v->data) : plan);
		if (v && v->data)
			switch (u->layer) {
			case MLOD_RT_SKELETON: return rt_bytes_skel_level(v->data) + plan;
			case MLOD_RT_MESH: return rt_bytes_mesh(v->data) + mesh_tables_bytes(ctx, v->data);
			default:
				return rt_bytes_motion(v->data) + motion_plan_hint(ctx, v->data);
			}
		return 0;
	}
	if (u->layer == MLOD_RT_MESH)
		return u->need;
	size_t hint = 4 * (size_t)u->raw_size + 256 + plan;
	/* A nested motion level decodes the coarser ones it builds on (rt_pack.c
	 * motion_load), each freed before it returns; at most two at a time,
	 * counted here as all of them. */
	for (const rt_unit *v = u; v && v->chunk >= 0 && (ctx->pack.chunks[v->chunk].flags & MLOD_PACK_CHUNK_NESTED);) {
		if (!(v = rt_unit_get(ctx, MLOD_RT_MOTION, (uint32_t)v->level + 1, v->item)))
			break;
		hint += 4 * (size_t)v->raw_size + 256;
	}
	/* A motion level's tables: its channels (decoded, counted in the hint
	 * so far at sizeof(mlod_pack_channel) each) are at most hint / that. */
	if (u->layer == MLOD_RT_MOTION)
		hint += motion_plan_bytes(ctx->joint_count, 0, ctx->joint_count) + 4 * (hint / sizeof(mlod_pack_channel));
	return hint;
}

/* ---------------------------------------------------------------- */
/* Fallback                                                          */
/* ---------------------------------------------------------------- */

static uint16_t resolve_layer(const mlod_rt_ctx *ctx, mlod_rt_layer layer, uint32_t item, uint16_t wanted)
{
	const uint32_t L = ctx->levels[layer];
	for (uint32_t l = wanted; l < L; l++) {
		const rt_unit *u = rt_unit_get(ctx, layer, l, item);
		if (u && u->state == RT_UNIT_RESIDENT)
			return (uint16_t)l;
	}
	/* Unreachable while the coarsest stays resident; any resident one. */
	for (uint32_t l = wanted; l-- > 0;) {
		const rt_unit *u = rt_unit_get(ctx, layer, l, item);
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
		rt_unit *old = rt_unit_get(ctx, (mlod_rt_layer)layer, st->level[layer], item);
		uint16_t l = resolve_layer(ctx, (mlod_rt_layer)layer, item, st->wanted[layer]);
		rt_unit *now = rt_unit_get(ctx, (mlod_rt_layer)layer, l, item);
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
		rt_unit *u = rt_unit_get(ctx, (mlod_rt_layer)layer, in->st.level[layer],
		                         layer == MLOD_RT_MOTION ? in->st.clip : 0);
		if (u && u->users)
			u->users--;
	}
}

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
		mlod_result r = unit_load(ctx, u, err);
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
	ctx->levels[MLOD_RT_SKELETON] = v->skel_levels;
	ctx->levels[MLOD_RT_MESH] = v->mesh_levels;
	ctx->clip_count = v->motion_levels ? v->clip_count : 0;
	ctx->levels[MLOD_RT_MOTION] = ctx->clip_count ? v->motion_levels : 0;
	ctx->unit_count = ctx->levels[0] + ctx->levels[1] + ctx->clip_count * ctx->levels[2];
	ctx->unit_base[0] = 0;
	ctx->unit_base[1] = ctx->levels[0];
	ctx->unit_base[2] = ctx->levels[0] + ctx->levels[1];
	ctx->units = rt_calloc(ctx, ctx->unit_count, sizeof *ctx->units);
	if (!ctx->units) {
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
			unit_release(ctx, &ctx->units[i]);
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
	out->loads = ctx->loads;
	out->evictions = ctx->evictions;
	out->failures = ctx->failures;
	for (uint32_t i = 0; i < ctx->unit_count; i++) {
		const rt_unit *u = &ctx->units[i];
		out->resident_levels += u->state == RT_UNIT_RESIDENT;
		out->pending_levels += u->state == RT_UNIT_ABSENT && u->want_count > 0;
	}
}

/* ---------------------------------------------------------------- */
/* Streaming                                                         */
/* ---------------------------------------------------------------- */

mlod_result mlod_rt_request(mlod_rt_ctx *ctx, mlod_rt_layer layer, uint32_t level, uint32_t item, mlod_error *err)
{
	rt_unit *u = ctx ? rt_unit_get(ctx, layer, level, item) : NULL;
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
	for (uint32_t l = (uint32_t)u->level + 1; w && l < ctx->levels[u->layer]; l++) {
		rt_unit *t = rt_unit_get(ctx, (mlod_rt_layer)u->layer, l, u->item);
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
		const rt_unit *v = rt_unit_get(ctx, MLOD_RT_MOTION, l, u->item);
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
		rt_unit *d = rt_unit_get(ctx, (mlod_rt_layer)u->layer, l, u->item);
		if (!d || !unit_needs(ctx, u, d) || d->state == RT_UNIT_RESIDENT || !chunk_corrupt(ctx, d->chunk))
			continue;
		for (uint32_t k = 0; k <= l; k++) {
			rt_unit *f = rt_unit_get(ctx, (mlod_rt_layer)u->layer, k, u->item);
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
		const rt_unit *u = rt_unit_get(ctx, layer, l, item);
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
		rt_unit *t = rt_unit_get(ctx, (mlod_rt_layer)u->layer,
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
	for (uint32_t i = 0; i < ctx->unit_count; i++)
		if (ctx->units[i].state == RT_UNIT_FAILED && ctx->units[i].retry)
			ctx->units[i].state = RT_UNIT_ABSENT, ctx->units[i].retry = 0;
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
			unit_release(ctx, v);
			ctx->evictions++;
			changed = 1;
		}
		mlod_error e;
		ctx->streaming = 1, ctx->refused = 0;
		mlod_result r = unit_load(ctx, u, &e);
		ctx->streaming = 0;
		if (r && ctx->refused) { /* its part records say it cannot fit: it waits */
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
			unit_release(ctx, v);
			ctx->evictions++;
		}
		if (ctx->resident_bytes > ctx->budget) { /* larger than its hint: give it back */
			unit_release(ctx, u);
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
		rt_unit *u = ctx->levels[layer] ? rt_unit_get(ctx, (mlod_rt_layer)layer, c,
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
		rt_unit *u = ctx->levels[layer] ? rt_unit_get(ctx, (mlod_rt_layer)layer, in->st.level[layer],
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
