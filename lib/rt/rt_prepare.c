/*
 * rt_prepare.c: checking a level when it loads and building the runtime's
 * tables of it: a skeleton level's plan, a motion level's fixed matrices
 * and channel bits, a mesh level's palette entries, skin buckets and
 * bound tables; the palette sources; and the bytes those tables take
 * (rt_load.c counts them before loading).
 */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pack_internal.h"
#include "rt_internal.h"

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

/* The runtime's tables of a motion level (rt_prepare_motion): a fixed-matrix
 * index per joint, the A channels of its animated joints, and the
 * matrices of its S joints with one-key channels only: 4 bytes per joint
 * and per such channel, 64 per such joint. */
size_t rt_motion_plan_bytes(uint32_t J, uint32_t A, uint32_t S)
{
	return ((size_t)J + A) * sizeof(uint32_t) + 16 * sizeof(float) * (size_t)S;
}

/* Checks a motion level and sets its channel bits (ctx->chan_bits). A
 * level the runtime decoded (owned) has the keys of a non-cubic rotation
 * replaced by their normalisation when each of those is its own: sampling
 * normalises every key it reads (mlod_quat_slerp, and sample_one after
 * a key or STEP), so the samples stay the same floats, and the keys need
 * no normalising per frame. The caller's views are only read. */
mlod_result rt_prepare_motion(mlod_rt_ctx *ctx, rt_unit *u, const mlod_pack_motion *m, mlod_error *err)
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
	const size_t cbytes = rt_motion_plan_bytes(J, A, S);
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

/* The plan of a skeleton level (rt_prepare_skel): per joint a matrix, a
 * stand-in, a posed entry and a flag; per palette entry its source. */
size_t rt_skel_plan_bytes(uint32_t J, uint32_t P)
{
	return (size_t)J * (4 + 1 + 4 + 64) + (size_t)P * 4;
}

/* Builds the plan of a skeleton level (level >= 1) into one block. */
mlod_result rt_prepare_skel(mlod_rt_ctx *ctx, rt_unit *u, const mlod_pack_skel_level *l, mlod_error *err)
{
	const uint32_t J = ctx->joint_count;
	if (l->kept_count == 0 || l->kept_count > J || !l->kept)
		return mlod_fail(err, MLOD_ERR_PARSE, "skeleton level %u: %u kept joints of %u", u->level, l->kept_count,
		                 J);
	if (l->palette_size != ctx->palette_size || (l->palette_size && (!l->palette_joint || !l->palette_bind)))
		return mlod_fail(err, MLOD_ERR_PARSE, "skeleton level %u: palette of %u entries, the skins have %u",
		                 u->level, l->palette_size, ctx->palette_size);
	const size_t P = l->palette_size;
	const size_t bytes = rt_skel_plan_bytes(J, (uint32_t)P);
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

/* The bytes of a mesh level's bucket tables (rt_prepare_mesh): an offset per
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

/* The bytes rt_prepare_mesh allocates for a decoded level. */
size_t rt_mesh_tables_bytes(const mlod_rt_ctx *ctx, const mlod_pack_mesh *m)
{
	size_t T = 0;
	for (uint32_t i = 0; i < m->part_count; i++)
		T += m->parts[i].rec.target_count;
	return 4 * ((size_t)ctx->palette_size + ctx->joint_count) + skin_order_bytes(m) +
	       bound_bytes(ctx->palette_size, m->part_count, T);
}

/* The bytes rt_prepare_mesh allocates for a level of these part records. */
size_t rt_mesh_plan_bytes(const mlod_rt_ctx *ctx, const mlod_pack_part_rec *recs, uint32_t n)
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
mlod_result rt_prepare_mesh(mlod_rt_ctx *ctx, rt_unit *u, const mlod_pack_mesh *m, mlod_error *err)
{
	mlod_result r = check_mesh(ctx, m, u->level, &u->vertex_count, err);
	if (r)
		return r;
	const uint32_t P = ctx->palette_size, J = ctx->joint_count;
	size_t T = 0;
	for (uint32_t i = 0; i < m->part_count; i++)
		T += m->parts[i].rec.target_count;
	const size_t bbytes = bound_bytes(P, m->part_count, T);
	const size_t bytes = rt_mesh_tables_bytes(ctx, m);
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
