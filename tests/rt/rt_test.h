/*
 * rt_test.h: the runtime tests' harness and their hand-built character
 * (decoded views, no pack), for tests/rt/test_rt_*.c. These programs link
 * only libmlodrt.a, -lmeshoptimizer, -lzstd and -lm, and include only lib/core and
 * lib/rt headers. Each test prints "PASS name" or "FAIL name: why".
 *
 * The character: joints 0 (root, base = translate(0, 0, 0.5)), 1 (child
 * of 0, at (0, 1, 0)), 2 (child of 1, at (0, 1, 0)), 3 (child of 2, at
 * (0, 1, 0)), 4 (child of 1, at (1, 0, 0)); one skin over all five with
 * inverse binds = inverse rest world. Skeleton levels: 0 all, 1 keeps
 * {0, 2, 3} (1 removed in the middle of the chain, 4 a leaf), 2 keeps {0}.
 * Mesh levels 0..2: a skinned part, a rigid part on joint 4 and (level 0)
 * a static part. Two clips, three motion levels each.
 */
#ifndef RT_TEST_H
#define RT_TEST_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mlod_rt.h"

static int t_failed_, t_total_fail_;
static char t_msg_[1024];

#define TEST(name) static void test_##name(void)
#define RUN(name)                                                              \
	do {                                                                   \
		t_failed_ = 0;                                                 \
		test_##name();                                                 \
		if (t_failed_) {                                               \
			printf("FAIL %s: %s\n", #name, t_msg_);                \
			t_total_fail_++;                                       \
		} else {                                                       \
			printf("PASS %s\n", #name);                            \
		}                                                              \
		fflush(stdout);                                                \
	} while (0)
#define TEST_EXIT() return t_total_fail_ ? 1 : 0
#define CHECK(cond, ...)                                                       \
	do {                                                                   \
		if (!(cond)) {                                                 \
			int n_ = snprintf(t_msg_, sizeof t_msg_, "%s:%d: ", __FILE__, __LINE__); \
			snprintf(t_msg_ + n_, sizeof t_msg_ - (size_t)n_, __VA_ARGS__); \
			t_failed_ = 1;                                         \
			return;                                                \
		}                                                              \
	} while (0)
#define CHECK_OK(expr, e)                                                      \
	do {                                                                   \
		mlod_result r_ = (expr);                                       \
		CHECK(r_ == MLOD_OK, "%s: %s", #expr, (e).message);            \
	} while (0)
#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define NEAR(a, b, tol) (fabs((double)(a) - (double)(b)) <= (tol))

/* Read callbacks (mlod_rt_read, user = an rt_mem_source) over a pack in
 * memory: they count their calls, and fail (-1) while fail is set or for
 * a range past the end. */
typedef struct rt_mem_source {
	const uint8_t *data;
	size_t size;
	int fail;
	unsigned long reads;
} rt_mem_source;
static inline int rt_mem_read(void *user, uint64_t offset, size_t size, void *dst)
{
	rt_mem_source *m = user;
	m->reads++;
	if (m->fail || offset > m->size || size > m->size - offset)
		return -1;
	memcpy(dst, m->data + offset, size);
	return 0;
}

/* Allocator hooks (mlod_rt_allocator, user = an rt_counter) that count
 * the bytes and blocks they hold and can be told to fail: held is what
 * is live, mallocs every allocation asked for, fail_after the
 * allocations left before the hooks return NULL (-1: never). */
typedef struct rt_counter {
	size_t held;
	size_t mallocs;
	long fail_after;
} rt_counter;
typedef struct rt_counter_head {
	size_t size;
	max_align_t pad; /* the block after it aligned as malloc's */
} rt_counter_head;
static inline void *rt_counter_malloc(void *user, size_t size)
{
	rt_counter *c = user;
	c->mallocs++;
	if (c->fail_after == 0)
		return NULL;
	if (c->fail_after > 0)
		c->fail_after--;
	rt_counter_head *h = malloc(sizeof *h + size);
	if (!h)
		return NULL;
	h->size = size;
	c->held += size;
	return h + 1;
}
static inline void rt_counter_free(void *user, void *p)
{
	if (!p)
		return;
	rt_counter_head *h = (rt_counter_head *)p - 1;
	((rt_counter *)user)->held -= h->size;
	free(h);
}

/* ---------------------------------------------------------------- */
/* The hand-built character                                          */
/* ---------------------------------------------------------------- */

#define FX_J 5
static mlod_pack_joint_rec fx_joints[FX_J];
static const char *fx_joint_names[FX_J] = { "root", "spine", "chest", "head", "arm" };
static mlod_pack_skin_rec fx_skin = { FX_J, 0, 0 };
static const char *fx_skin_names[1] = { "skin" };
static uint32_t fx_skin_joints_0[FX_J] = { 0, 1, 2, 3, 4 };
static const uint32_t *fx_skin_joints[1] = { fx_skin_joints_0 };
static float fx_ibm_0[16 * FX_J];
static const float *fx_ibm[1] = { fx_ibm_0 };
static mlod_pack_skeleton fx_skel;
static float fx_rest_world[FX_J][16];

static uint32_t fx_kept1[3] = { 0, 2, 3 }, fx_kept2[1] = { 0 };
static uint32_t fx_palj1[FX_J] = { 0, 0, 2, 3, 0 }, fx_palj2[FX_J] = { 0, 0, 0, 0, 0 };
static float fx_palb1[16 * FX_J], fx_palb2[16 * FX_J];
static mlod_pack_skel_level fx_sl1, fx_sl2;

/* Mesh level 0: part 0 skinned (4 vertices), part 1 rigid on joint 4
 * (2 vertices), part 2 static (1 vertex). */
static float fx_m0_pos0[] = { 0, 0.5f, 0, 0, 1.5f, 0, 0, 2.5f, 0, 1, 1, 0 };
static float fx_m0_nrm0[] = { 1, 0, 0, 0, 0, 1, 1, 0, 0, 0.6f, 0.8f, 0 };
static uint16_t fx_m0_jnt0[] = { 0, 1, 2, 3, 1, 2, 0, 0, 2, 3, 0, 0, 4, 0, 0, 0 };
static float fx_m0_wgt0[] = { 1, 0, 0, 0, 0.5f, 0.5f, 0, 0, 0.75f, 0.25f, 0, 0, 1, 0, 0, 0 };
static float fx_m0_pos1[] = { 0, 0, 0, 0.25f, 0, 0 };
static float fx_m0_nrm1[] = { 0, 1, 0, 0, 0, 1 };
static float fx_m0_pos2[] = { 1, 2, 3 };
static uint32_t fx_idx[] = { 0, 1, 2 };
static mlod_pack_part fx_m0_parts[3], fx_m1_parts[2], fx_m2_parts[1];
static mlod_pack_mesh fx_mesh0, fx_mesh1, fx_mesh2;

/* Motion, clip 0 level 0:
 *  joint 0 translation LINEAR t 0, 1: (0,0,0) -> (2,4,6)
 *  joint 1 rotation LINEAR t 0, 1, 2: identity, Rz(90), Rz(180)
 *  joint 2 rotation STEP t 0, 0.5: identity, Rx(90)
 *  joint 3 translation CUBICSPLINE t 0, 2: (in, value, out) per key
 *  joint 4 scale LINEAR t 0, 2: 1 -> 3
 * clip 0 level 1: joint 0 and joint 1 (keys 0 and 2 only)
 * clip 0 level 2: joint 0 only
 * clip 1, every level: joint 0 translation LINEAR t 0, 4: (0,0,0) -> (4,0,0)
 */
static float fx_t01[] = { 0, 1 }, fx_t012[] = { 0, 1, 2 }, fx_t02[] = { 0, 2 }, fx_t005[] = { 0, 0.5f },
             fx_t04[] = { 0, 4 };
static float fx_v_j0t[] = { 0, 0, 0, 2, 4, 6 };
static float fx_v_j1r[12], fx_v_j1r_l1[8];
static float fx_v_j2r[8];
static float fx_v_j3t[] = { 0, 0, 0, 0, 1, 0, 1, 0, 0, /* key 0: in, value, out */
                            0, 0, 2, 0, 3, 0, 0, 0, 0 };  /* key 1 */
static float fx_v_j4s[] = { 1, 1, 1, 3, 3, 3 };
static float fx_v_c1[] = { 0, 0, 0, 4, 0, 0 };
static mlod_pack_channel fx_c0l0[5], fx_c0l1[2], fx_c0l2[1], fx_c1[1];
static mlod_pack_motion fx_mo[2][3];

static mlod_rt_view_level fx_vskel[3], fx_vmesh[3], fx_vmotion[6];
static mlod_rt_views fx_views;

static inline void fx_identity(float *m)
{
	memset(m, 0, 16 * sizeof *m);
	m[0] = m[5] = m[10] = m[15] = 1;
}

static inline void fx_quat_z(float deg, float *q)
{
	double a = deg * 3.14159265358979323846 / 360.0;
	q[0] = 0, q[1] = 0, q[2] = (float)sin(a), q[3] = (float)cos(a);
}

static inline void fx_quat_x(float deg, float *q)
{
	double a = deg * 3.14159265358979323846 / 360.0;
	q[0] = (float)sin(a), q[1] = 0, q[2] = 0, q[3] = (float)cos(a);
}

static inline void fx_part(mlod_pack_part *p, float *pos, float *nrm, uint16_t *jnt, float *wgt, uint32_t n, int skin,
                    int joint, const float *offset)
{
	memset(p, 0, sizeof *p);
	p->rec.vertex_count = n;
	p->rec.index_count = n >= 3 ? 3 : 0;
	p->rec.skin = skin;
	p->rec.joint = joint;
	p->rec.node = -1;
	p->rec.mesh = -1;
	p->rec.material = -1;
	p->rec.flags = (nrm ? MLOD_PART_NORMALS : 0) | (skin >= 0 ? MLOD_PART_SKINNED : 0);
	if (offset)
		memcpy(p->rec.offset, offset, sizeof p->rec.offset);
	else
		fx_identity(p->rec.offset);
	p->positions = pos;
	p->normals = nrm;
	p->joints = jnt;
	p->weights = wgt;
	p->indices = fx_idx;
}

static inline void fx_channel(mlod_pack_channel *c, uint32_t joint, uint32_t path, uint32_t interp, uint32_t keys,
                       const float *times, float *values)
{
	c->rec.joint = joint;
	c->rec.path = path;
	c->rec.interp = interp;
	c->rec.key_count = keys;
	c->times = times;
	c->values = values;
}

static inline void fx_motion(mlod_pack_motion *m, mlod_pack_channel *c, uint32_t n, float duration)
{
	m->channel_count = n;
	m->channels = c;
	m->duration = duration;
}

/* Builds everything; bytes != 0 gives each level a fixed byte cost:
 * skeleton 1000/500, mesh 4000/2000/1000, motion 3000/1500/700. */
static inline void fx_build(int bytes)
{
	static const float base[16] = { 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0.5f, 1 };
	static const float off[FX_J][3] = { { 0, 0, 0 }, { 0, 1, 0 }, { 0, 1, 0 }, { 0, 1, 0 }, { 1, 0, 0 } };
	static const int parent[FX_J] = { -1, 0, 1, 2, 1 };
	memset(fx_joints, 0, sizeof fx_joints);
	for (int j = 0; j < FX_J; j++) {
		mlod_pack_joint_rec *r = &fx_joints[j];
		r->parent = parent[j];
		memcpy(r->t, off[j], sizeof r->t);
		r->r[3] = 1;
		r->s[0] = r->s[1] = r->s[2] = 1;
		if (j == 0)
			memcpy(r->base, base, sizeof base);
		else
			fx_identity(r->base);
		r->node = j;
		/* rest world: translations only */
		float *w = fx_rest_world[j];
		if (parent[j] < 0)
			memcpy(w, base, sizeof base);
		else
			memcpy(w, fx_rest_world[parent[j]], 16 * sizeof *w);
		w[12] += off[j][0], w[13] += off[j][1], w[14] += off[j][2];
		fx_identity(fx_ibm_0 + 16 * j);
		fx_ibm_0[16 * j + 12] = -w[12], fx_ibm_0[16 * j + 13] = -w[13], fx_ibm_0[16 * j + 14] = -w[14];
	}
	memset(&fx_skel, 0, sizeof fx_skel);
	fx_skel.joint_count = FX_J;
	fx_skel.joints = fx_joints;
	fx_skel.joint_names = fx_joint_names;
	fx_skel.skin_count = 1;
	fx_skel.skins = &fx_skin;
	fx_skel.skin_names = fx_skin_names;
	fx_skel.skin_joints = fx_skin_joints;
	fx_skel.inverse_bind = fx_ibm;
	for (int i = 0; i < FX_J; i++) {
		memcpy(fx_palb1 + 16 * i, fx_ibm_0 + 16 * fx_palj1[i], 16 * sizeof(float));
		memcpy(fx_palb2 + 16 * i, fx_ibm_0 + 16 * fx_palj2[i], 16 * sizeof(float));
	}
	fx_sl1 = (mlod_pack_skel_level){ 3, fx_kept1, FX_J, fx_palj1, fx_palb1, NULL };
	fx_sl2 = (mlod_pack_skel_level){ 1, fx_kept2, FX_J, fx_palj2, fx_palb2, NULL };

	float rigid_off[16], static_off[16];
	fx_identity(rigid_off);
	rigid_off[12] = 0.5f;
	fx_identity(static_off);
	static_off[14] = -1;
	fx_part(&fx_m0_parts[0], fx_m0_pos0, fx_m0_nrm0, fx_m0_jnt0, fx_m0_wgt0, 4, 0, -1, NULL);
	fx_part(&fx_m0_parts[1], fx_m0_pos1, fx_m0_nrm1, NULL, NULL, 2, -1, 4, rigid_off);
	fx_part(&fx_m0_parts[2], fx_m0_pos2, NULL, NULL, NULL, 1, -1, -1, static_off);
	fx_part(&fx_m1_parts[0], fx_m0_pos0 + 3, fx_m0_nrm0 + 3, fx_m0_jnt0 + 4, fx_m0_wgt0 + 4, 2, 0, -1, NULL);
	fx_part(&fx_m1_parts[1], fx_m0_pos1, fx_m0_nrm1, NULL, NULL, 1, -1, 4, rigid_off);
	fx_part(&fx_m2_parts[0], fx_m0_pos0, fx_m0_nrm0, fx_m0_jnt0, fx_m0_wgt0, 1, 0, -1, NULL);
	fx_mesh0 = (mlod_pack_mesh){ 3, fx_m0_parts, NULL };
	fx_mesh1 = (mlod_pack_mesh){ 2, fx_m1_parts, NULL };
	fx_mesh2 = (mlod_pack_mesh){ 1, fx_m2_parts, NULL };

	fx_quat_z(0, fx_v_j1r), fx_quat_z(90, fx_v_j1r + 4), fx_quat_z(180, fx_v_j1r + 8);
	fx_quat_z(0, fx_v_j1r_l1), fx_quat_z(180, fx_v_j1r_l1 + 4);
	fx_quat_x(0, fx_v_j2r), fx_quat_x(90, fx_v_j2r + 4);
	fx_channel(&fx_c0l0[0], 0, 0, 0, 2, fx_t01, fx_v_j0t);
	fx_channel(&fx_c0l0[1], 1, 1, 0, 3, fx_t012, fx_v_j1r);
	fx_channel(&fx_c0l0[2], 2, 1, 1, 2, fx_t005, fx_v_j2r);
	fx_channel(&fx_c0l0[3], 3, 0, 2, 2, fx_t02, fx_v_j3t);
	fx_channel(&fx_c0l0[4], 4, 2, 0, 2, fx_t02, fx_v_j4s);
	fx_channel(&fx_c0l1[0], 0, 0, 0, 2, fx_t01, fx_v_j0t);
	fx_channel(&fx_c0l1[1], 1, 1, 0, 2, fx_t02, fx_v_j1r_l1);
	fx_channel(&fx_c0l2[0], 0, 0, 0, 2, fx_t01, fx_v_j0t);
	fx_channel(&fx_c1[0], 0, 0, 0, 2, fx_t04, fx_v_c1);
	fx_motion(&fx_mo[0][0], fx_c0l0, 5, 2);
	fx_motion(&fx_mo[0][1], fx_c0l1, 2, 2);
	fx_motion(&fx_mo[0][2], fx_c0l2, 1, 2); /* the clip's duration is its coarsest level's */
	for (int l = 0; l < 3; l++)
		fx_motion(&fx_mo[1][l], fx_c1, 1, 4);

	static const float skel_err[3] = { 0, 0.02f, 0.1f }, mesh_err[3] = { 0, 0.01f, 0.05f },
	                   mot_err[3] = { 0, 0.005f, 0.03f };
	static const size_t skel_b[3] = { 0, 1000, 500 }, mesh_b[3] = { 4000, 2000, 1000 },
	                    mot_b[3] = { 3000, 1500, 700 };
	const double k = 1080.0 / (2.0 * tan(30.0 * 3.14159265358979323846 / 180.0));
	const void *sl[3] = { NULL, &fx_sl1, &fx_sl2 };
	const void *ml[3] = { &fx_mesh0, &fx_mesh1, &fx_mesh2 };
	for (int l = 0; l < 3; l++) {
		fx_vskel[l] = (mlod_rt_view_level){ sl[l], skel_err[l], (float)(skel_err[l] * k), bytes ? skel_b[l] : 0 };
		fx_vmesh[l] = (mlod_rt_view_level){ ml[l], mesh_err[l], (float)(mesh_err[l] * k), bytes ? mesh_b[l] : 0 };
		for (int c = 0; c < 2; c++)
			fx_vmotion[c * 3 + l] =
				(mlod_rt_view_level){ &fx_mo[c][l], mot_err[l], (float)(mot_err[l] * k), bytes ? mot_b[l] : 0 };
	}
	fx_views = (mlod_rt_views){ &fx_skel, 3, fx_vskel, 3, fx_vmesh, 2, 3, fx_vmotion };
}

/* Loads every level (unlimited budget). */
static inline int fx_load_all(mlod_rt_ctx *ctx)
{
	for (int layer = 0; layer < MLOD_RT_LAYERS; layer++)
		for (uint32_t l = 0; l < mlod_rt_level_count(ctx, (mlod_rt_layer)layer); l++)
			for (uint32_t c = 0; c < (layer == MLOD_RT_MOTION ? mlod_rt_clip_count(ctx) : 1u); c++)
				if (mlod_rt_request(ctx, (mlod_rt_layer)layer, l, c, NULL) != MLOD_OK)
					return -1;
	return mlod_rt_stream(ctx, SIZE_MAX, NULL, NULL) == MLOD_OK ? 0 : -1;
}

/* 4x4 column-major helpers for expectations. */
static inline void fx_mul(const float *a, const float *b, float *out)
{
	float r[16];
	for (int c = 0; c < 4; c++)
		for (int row = 0; row < 4; row++) {
			double s = 0;
			for (int k = 0; k < 4; k++)
				s += (double)a[k * 4 + row] * b[c * 4 + k];
			r[c * 4 + row] = (float)s;
		}
	memcpy(out, r, sizeof r);
}

static inline double fx_maxdiff(const float *a, const float *b, int n)
{
	double d = 0;
	for (int i = 0; i < n; i++)
		if (fabs((double)a[i] - b[i]) > d)
			d = fabs((double)a[i] - b[i]);
	return d;
}

#endif
