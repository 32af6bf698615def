/*
 * test_rt_eval.c: sampling against hand-computed values (LINEAR lerp and
 * slerp, STEP, CUBICSPLINE, loop and clamp), folding at run time (skeleton
 * levels give the full skeleton's world matrices at their kept joints),
 * skinning against a hand-computed LBS (skinned, rigid, static parts;
 * strides), the vectorised kernel against the scalar one, the rigid
 * parts' 4-wide transform against a plain loop float for float, rigid
 * normals without renormalising only where the matrix allows, and no
 * allocation per frame (counting allocator). Morph targets: the runtime's
 * morphed output equals its output for the same character with the
 * deltas added to the positions by hand, at every mesh level and kind of
 * part; the weights' rules (count, finite, reset on create); no
 * allocation. The skin plan: mlod_rt_skin poses and multiplies only what
 * its mesh level reads, and that gives the very floats of the full pose
 * and palette, at every pair of skeleton and mesh levels (white box:
 * rt_internal.h).
 */
#include "rt_test.h"
#include "rt_internal.h"

static mlod_rt_ctx *open_all(mlod_rt_config *cfg, mlod_error *e)
{
	mlod_rt_ctx *ctx = NULL;
	if (mlod_rt_open_views(&fx_views, cfg, &ctx, e) != MLOD_OK)
		return NULL;
	if (fx_load_all(ctx) != 0) {
		mlod_rt_close(ctx);
		return NULL;
	}
	return ctx;
}

/* Updates one instance with every layer forced to level. */
static mlod_result force(mlod_rt_ctx *ctx, uint32_t id, int level, mlod_error *e)
{
	mlod_rt_select sel;
	mlod_rt_select_default(&sel);
	sel.force_level = level;
	float d = 1;
	return mlod_rt_update(ctx, &sel, &id, &d, 1, 0.0f, e);
}

/* The local transform of joint j: inverse(world[parent]) * world[j]. */
static void local_of(const float *W, int parent, int j, float *out)
{
	mlod_mat4 p, inv, w;
	memcpy(p.m, W + 16 * parent, sizeof p.m);
	memcpy(w.m, W + 16 * j, sizeof w.m);
	mlod_mat4_invert(&p, &inv);
	fx_mul(inv.m, w.m, out);
}

TEST(sample_hand_values)
{
	mlod_error e;
	mlod_rt_ctx *ctx = open_all(NULL, &e);
	CHECK(ctx, "open: %s", e.message);
	mlod_rt_scratch *s = mlod_rt_scratch_create(ctx);
	uint32_t id;
	CHECK_OK(mlod_rt_instance_create(ctx, 0, 0.25f, 0, &id, &e), e);
	CHECK_OK(force(ctx, id, 0, &e), e);
	const float *W;
	CHECK_OK(mlod_rt_pose(ctx, s, id, &W, NULL, NULL, &e), e);
	/* joint 0: lerp (0,0,0) -> (2,4,6) at 0.25, after base z + 0.5 */
	CHECK(NEAR(W[12], 0.5, 1e-6) && NEAR(W[13], 1.0, 1e-6) && NEAR(W[14], 2.0, 1e-6), "W0 t = %g %g %g", W[12],
	      W[13], W[14]);
	/* joint 1: slerp identity -> Rz(90) at 0.25: Rz(22.5) */
	const double c = cos(22.5 * M_PI / 180), sn = sin(22.5 * M_PI / 180);
	const float *W1 = W + 16;
	CHECK(NEAR(W1[0], c, 1e-6) && NEAR(W1[1], sn, 1e-6) && NEAR(W1[4], -sn, 1e-6) && NEAR(W1[5], c, 1e-6),
	      "W1 rotation %g %g %g %g", W1[0], W1[1], W1[4], W1[5]);
	CHECK(NEAR(W1[12], 0.5, 1e-6) && NEAR(W1[13], 2.0, 1e-6) && NEAR(W1[14], 2.0, 1e-6), "W1 t");
	/* joint 2: STEP holds identity before 0.5 */
	const float *W2 = W + 32;
	CHECK(NEAR(W2[12], 0.5 - sn, 1e-6) && NEAR(W2[13], 2.0 + c, 1e-6) && NEAR(W2[0], c, 1e-6), "W2");
	/* joint 3: CUBICSPLINE at u = 0.125, dt = 2 */
	float L[16];
	local_of(W, 2, 3, L);
	CHECK(NEAR(L[12], 0.19140625, 1e-5) && NEAR(L[13], 1.0859375, 1e-5) && NEAR(L[14], -0.0546875, 1e-5),
	      "L3 t = %.7g %.7g %.7g", L[12], L[13], L[14]);
	/* joint 4: scale lerp 1 -> 3 over [0, 2] at 0.25: 1.25 */
	local_of(W, 1, 4, L);
	CHECK(NEAR(L[0], 1.25, 1e-5) && NEAR(L[5], 1.25, 1e-5) && NEAR(L[10], 1.25, 1e-5), "L4 scale %g", L[0]);

	/* t = 0.75: STEP switched to Rx(90); slerp Rz(67.5) */
	CHECK_OK(mlod_rt_instance_set(ctx, id, 0, 0.75f, 0, &e), e);
	CHECK_OK(mlod_rt_pose(ctx, s, id, &W, NULL, NULL, &e), e);
	local_of(W, 1, 2, L);
	CHECK(NEAR(L[5], 0, 1e-6) && NEAR(L[6], 1, 1e-6) && NEAR(L[9], -1, 1e-6), "L2 is not Rx(90)");
	local_of(W, 0, 1, L);
	CHECK(NEAR(L[0], cos(67.5 * M_PI / 180), 1e-6) && NEAR(L[1], sin(67.5 * M_PI / 180), 1e-6), "L1 not Rz(67.5)");
	/* t = 1.5: between Rz(90) and Rz(180): Rz(135) */
	CHECK_OK(mlod_rt_instance_set(ctx, id, 0, 1.5f, 0, &e), e);
	CHECK_OK(mlod_rt_pose(ctx, s, id, &W, NULL, NULL, &e), e);
	local_of(W, 0, 1, L);
	CHECK(NEAR(L[0], cos(135 * M_PI / 180), 1e-6) && NEAR(L[1], sin(135 * M_PI / 180), 1e-6), "L1 not Rz(135)");
	mlod_rt_scratch_destroy(ctx, s);
	mlod_rt_close(ctx);
}

TEST(sample_loop_and_clamp)
{
	mlod_error e;
	mlod_rt_ctx *ctx = open_all(NULL, &e);
	CHECK(ctx, "open: %s", e.message);
	mlod_rt_scratch *s = mlod_rt_scratch_create(ctx);
	/* clip 1: joint 0 x from 0 to 4 over [0, 4] */
	static const struct { float time; uint32_t flags; float x; } cases[] = {
		{ 1.0f, 0, 1.0f }, { 5.0f, 0, 4.0f }, { -1.0f, 0, 0.0f },
		{ 5.0f, MLOD_RT_LOOP, 1.0f }, { -1.0f, MLOD_RT_LOOP, 3.0f }, { 9.5f, MLOD_RT_LOOP, 1.5f },
	};
	CHECK(NEAR(mlod_rt_clip_duration(ctx, 1), 4.0, 0), "clip 1 lasts %g", mlod_rt_clip_duration(ctx, 1));
	for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
		uint32_t id;
		const float *W;
		CHECK_OK(mlod_rt_instance_create(ctx, 1, cases[i].time, cases[i].flags, &id, &e), e);
		CHECK_OK(force(ctx, id, 0, &e), e);
		CHECK_OK(mlod_rt_pose(ctx, s, id, &W, NULL, NULL, &e), e);
		CHECK(NEAR(W[12], cases[i].x, 1e-5), "time %g flags %u: x = %g, expected %g", cases[i].time,
		      cases[i].flags, W[12], cases[i].x);
		mlod_rt_instance_destroy(ctx, id);
	}
	/* Time advances by dt in update; looping wraps it. */
	uint32_t id;
	CHECK_OK(mlod_rt_instance_create(ctx, 1, 3.5f, MLOD_RT_LOOP, &id, &e), e);
	mlod_rt_select sel;
	mlod_rt_select_default(&sel);
	sel.force_level = 0;
	float d = 1;
	CHECK_OK(mlod_rt_update(ctx, &sel, &id, &d, 1, 1.0f, &e), e);
	CHECK(NEAR(mlod_rt_instance_state(ctx, id)->time, 0.5, 1e-6), "time %g after wrap",
	      mlod_rt_instance_state(ctx, id)->time);
	mlod_rt_scratch_destroy(ctx, s);
	mlod_rt_close(ctx);
}

TEST(fold_matches_full_skeleton)
{
	mlod_error e;
	mlod_rt_ctx *ctx = open_all(NULL, &e);
	CHECK(ctx, "open: %s", e.message);
	mlod_rt_scratch *s = mlod_rt_scratch_create(ctx);
	mlod_rt_select sel;
	mlod_rt_select_default(&sel);
	sel.d_near = 0, sel.d_far = 100, sel.hysteresis = 0;
	sel.t_start[MLOD_RT_MOTION] = sel.t_end[MLOD_RT_MOTION] = 1; /* motion level 0 below alpha 1 */
	static const float times[] = { 0.0f, 0.3f, 0.77f, 1.4f, 1.99f };
	for (size_t k = 0; k < sizeof times / sizeof times[0]; k++) {
		uint32_t ids[3];
		float d[3] = { 0, 50, 99 }; /* skeleton levels 0, 1 (alpha 0.5), 2 (alpha 0.99) */
		for (int i = 0; i < 3; i++)
			CHECK_OK(mlod_rt_instance_create(ctx, 0, times[k], 0, &ids[i], &e), e);
		CHECK_OK(mlod_rt_update(ctx, &sel, ids, d, 3, 0.0f, &e), e);
		float full[16 * FX_J];
		const float *W;
		const uint32_t *kept;
		uint32_t nk;
		for (int i = 0; i < 3; i++) {
			const mlod_rt_state *st = mlod_rt_instance_state(ctx, ids[i]);
			CHECK(st->level[MLOD_RT_SKELETON] == i && st->level[MLOD_RT_MOTION] == 0, "instance %d: levels %u %u",
			      i, st->level[MLOD_RT_SKELETON], st->level[MLOD_RT_MOTION]);
			CHECK_OK(mlod_rt_pose(ctx, s, ids[i], &W, &kept, &nk, &e), e);
			if (i == 0) {
				memcpy(full, W, sizeof full);
				CHECK(nk == FX_J, "level 0 keeps %u", nk);
				continue;
			}
			CHECK(nk == (i == 1 ? 3u : 1u), "level %d keeps %u", i, nk);
			for (uint32_t q = 0; q < nk; q++) {
				double dd = fx_maxdiff(W + 16 * kept[q], full + 16 * kept[q], 16);
				CHECK(dd <= 1e-6, "t %g level %d joint %u: differs by %g from the full skeleton", times[k], i,
				      kept[q], dd);
			}
		}
		for (int i = 0; i < 3; i++)
			mlod_rt_instance_destroy(ctx, ids[i]);
	}
	mlod_rt_scratch_destroy(ctx, s);
	mlod_rt_close(ctx);
}

/* Expected LBS of one vertex from the pose's world matrices. */
static void lbs_expect(const float *W, const float *ibm, const uint16_t *j, const float *w, const float *p,
                       float *out)
{
	out[0] = out[1] = out[2] = 0;
	for (int k = 0; k < 4; k++) {
		if (w[k] == 0)
			continue;
		float M[16];
		fx_mul(W + 16 * j[k], ibm + 16 * j[k], M);
		for (int r = 0; r < 3; r++)
			out[r] += w[k] * (M[r] * p[0] + M[4 + r] * p[1] + M[8 + r] * p[2] + M[12 + r]);
	}
}

TEST(skin_hand_lbs)
{
	mlod_error e;
	mlod_rt_ctx *ctx = open_all(NULL, &e);
	CHECK(ctx, "open: %s", e.message);
	mlod_rt_scratch *s = mlod_rt_scratch_create(ctx);
	CHECK(mlod_rt_max_vertex_count(ctx) == 7, "max vertices %u", mlod_rt_max_vertex_count(ctx));
	float buf[8 * 7];
	uint32_t n, id;
	/* Rest pose (clip 1 at 0): skinned vertices stay, rigid follows joint 4, static its offset. */
	CHECK_OK(mlod_rt_instance_create(ctx, 1, 0.0f, 0, &id, &e), e);
	CHECK_OK(force(ctx, id, 0, &e), e);
	CHECK(mlod_rt_skin(ctx, s, id, buf, 32, buf + 3, 32, 6, &n, &e) == MLOD_ERR_LIMIT, "capacity not checked");
	CHECK_OK(mlod_rt_skin(ctx, s, id, buf, 32, buf + 3, 32, 7, &n, &e), e);
	CHECK(n == 7, "%u vertices", n);
	static const float rest[7][3] = { { 0, 0.5f, 0 }, { 0, 1.5f, 0 }, { 0, 2.5f, 0 }, { 1, 1, 0 },
	                                  { 1.5f, 1, 0.5f }, { 1.75f, 1, 0.5f }, { 1, 2, 2 } };
	for (int v = 0; v < 7; v++)
		CHECK(fx_maxdiff(buf + 8 * v, rest[v], 3) <= 1e-6, "rest vertex %d: %g %g %g", v, buf[8 * v],
		      buf[8 * v + 1], buf[8 * v + 2]);
	CHECK(fx_maxdiff(buf + 8 * 3 + 3, (const float[]){ 0.6f, 0.8f, 0 }, 3) <= 1e-6, "rest normal 3");
	CHECK(fx_maxdiff(buf + 8 * 6 + 3, (const float[]){ 0, 0, 0 }, 3) == 0, "a part without normals gets zeros");
	/* Translated root (clip 1 at 2: x + 2): all but the static part move. */
	CHECK_OK(mlod_rt_instance_set(ctx, id, 1, 2.0f, 0, &e), e);
	CHECK_OK(mlod_rt_skin(ctx, s, id, buf, 32, buf + 3, 32, 7, &n, &e), e);
	for (int v = 0; v < 7; v++) {
		float x[3] = { rest[v][0] + (v < 6 ? 2.0f : 0.0f), rest[v][1], rest[v][2] };
		CHECK(fx_maxdiff(buf + 8 * v, x, 3) <= 1e-6, "moved vertex %d: %g %g %g", v, buf[8 * v], buf[8 * v + 1],
		      buf[8 * v + 2]);
	}
	/* A bent pose (clip 0 at 0.25): LBS by hand from the world matrices. */
	CHECK_OK(mlod_rt_instance_set(ctx, id, 0, 0.25f, 0, &e), e);
	CHECK_OK(mlod_rt_skin(ctx, s, id, buf, 12, NULL, 0, 7, &n, &e), e);
	const float *W;
	CHECK_OK(mlod_rt_pose(ctx, s, id, &W, NULL, NULL, &e), e);
	for (int v = 0; v < 4; v++) {
		float x[3];
		lbs_expect(W, fx_ibm_0, fx_m0_jnt0 + 4 * v, fx_m0_wgt0 + 4 * v, fx_m0_pos0 + 3 * v, x);
		CHECK(fx_maxdiff(buf + 3 * v, x, 3) <= 1e-5, "bent vertex %d: %g %g %g, expected %g %g %g", v, buf[3 * v],
		      buf[3 * v + 1], buf[3 * v + 2], x[0], x[1], x[2]);
	}
	float R[16], x[3];
	fx_mul(W + 64, fx_m0_parts[1].rec.offset, R);
	x[0] = R[12] + 0.25f * R[0], x[1] = R[13] + 0.25f * R[1], x[2] = R[14] + 0.25f * R[2];
	CHECK(fx_maxdiff(buf + 15, x, 3) <= 1e-5, "rigid vertex 5");
	/* The palette is W * IBM. */
	const float *P;
	uint32_t pn;
	CHECK_OK(mlod_rt_palette(ctx, s, &P, &pn, &e), e);
	CHECK(pn == FX_J, "palette of %u", pn);
	fx_mul(W + 32, fx_ibm_0 + 32, R);
	CHECK(fx_maxdiff(P + 32, R, 16) <= 1e-6, "palette entry 2");
	/* Skeleton level 1 removes joint 4: the rigid part follows the stand-in 0
	 * with the rest offset from 0 to 4, (1, 1, 0). */
	mlod_rt_select sel;
	mlod_rt_select_default(&sel);
	sel.d_near = 0, sel.d_far = 100, sel.hysteresis = 0;
	sel.t_start[MLOD_RT_MOTION] = sel.t_end[MLOD_RT_MOTION] = 1;
	sel.t_start[MLOD_RT_MESH] = sel.t_end[MLOD_RT_MESH] = 1;
	float d = 50;
	CHECK_OK(mlod_rt_update(ctx, &sel, &id, &d, 1, 0.0f, &e), e);
	CHECK(mlod_rt_instance_state(ctx, id)->level[MLOD_RT_SKELETON] == 1, "not skeleton level 1");
	CHECK_OK(mlod_rt_skin(ctx, s, id, buf, 12, NULL, 0, 7, &n, &e), e);
	CHECK(fx_maxdiff(buf + 12, (const float[]){ 2.0f, 2.0f, 2.0f }, 3) <= 1e-5, "rigid on stand-in: %g %g %g",
	      buf[12], buf[13], buf[14]);
	/* The parts, for drawing: vertex ranges and local indices. */
	CHECK(mlod_rt_mesh_part_count(ctx, 0) == 3 && mlod_rt_mesh_part_count(ctx, 2) == 1, "part counts");
	mlod_rt_part_info pi;
	CHECK_OK(mlod_rt_mesh_part(ctx, 0, 1, &pi, &e), e);
	CHECK(pi.first_vertex == 4 && pi.vertex_count == 2 && pi.joint == 4 && pi.skin == -1 && pi.index_count == 0,
	      "part 1: first %u count %u joint %d", pi.first_vertex, pi.vertex_count, pi.joint);
	CHECK_OK(mlod_rt_mesh_part(ctx, 0, 0, &pi, &e), e);
	CHECK(pi.first_vertex == 0 && pi.index_count == 3 && pi.indices[2] == 2 && pi.skin == 0, "part 0");
	CHECK(mlod_rt_mesh_part(ctx, 0, 3, &pi, &e) == MLOD_ERR_INVALID_ARG, "part 3 of 3");
	mlod_rt_instance_destroy(ctx, id);
	mlod_rt_scratch_destroy(ctx, s);
	mlod_rt_close(ctx);
}

static unsigned rng_state = 12345;
static float frand(void)
{
	rng_state = rng_state * 1103515245u + 12345u;
	return (float)((rng_state >> 8) & 0xffff) / 65535.0f;
}

/* The kernel against the scalar loop: 1 to 4 influences in every pattern
 * (zero weights first, between and last; one influence of weight 1 and
 * of another weight), lengths around the kernel's runs
 * of 64, zero normals, no normals, and positions and normals interleaved
 * in one buffer with a gap the kernel must not touch. */
TEST(kernel_matches_scalar)
{
	enum { N = 1000, P = 8, S = 8 }; /* S floats per interleaved vertex */
	static float pos[3 * N], nrm[3 * N], wgt[4 * N], pal[16 * P], a[3 * N], b[3 * N], an[3 * N], bn[3 * N];
	static float ia[S * N], ib[S * N];
	static uint16_t jnt[4 * N];
	for (int m = 0; m < P; m++) {
		mlod_trs t = { { frand(), frand(), frand() },
		               mlod_quat_normalize((mlod_quat){ frand() - 0.5f, frand() - 0.5f, frand() - 0.5f, 1 }),
		               { 1, 1, 1 } };
		mlod_mat4 M = mlod_mat4_from_trs(&t);
		memcpy(pal + 16 * m, M.m, sizeof M.m);
	}
	int pattern_seen[16] = { 0 }, unit_seen[3] = { 0 };
	for (int v = 0; v < N; v++) {
		float s = 0;
		for (int k = 0; k < 3; k++)
			pos[3 * v + k] = frand() * 2 - 1, nrm[3 * v + k] = v % 97 == 5 ? 0.0f : frand() - 0.5f;
		/* Which influences are non-zero: every pattern but none; runs of
		 * one pattern (as meshes have) and mixed stretches. */
		int mask = v < N / 2 ? (v / 40) % 15 + 1 : (int)(frand() * 14.99f) + 1;
		pattern_seen[mask] = 1;
		for (int k = 0; k < 4; k++) {
			jnt[4 * v + k] = (uint16_t)(frand() * (P - 1) + 0.5f);
			wgt[4 * v + k] = mask >> k & 1 ? frand() + 0.01f : 0.0f;
			s += wgt[4 * v + k];
		}
		for (int k = 0; k < 4; k++)
			wgt[4 * v + k] /= s;
		/* One influence: of weight exactly 1 (x / x: the kernel's own
		 * bucket) or, every other such vertex, of weight 0.75. */
		if (mask == 1 && v % 2)
			wgt[4 * v] = 0.75f;
		unit_seen[mask == 1 ? wgt[4 * v] == 1.0f : 2] = 1;
	}
	for (int m = 1; m < 16; m++)
		CHECK(pattern_seen[m], "influence pattern %d not covered", m);
	CHECK(unit_seen[0] && unit_seen[1], "one influence of weight 1 and of another weight not both covered");
	static const int lengths[] = { 0, 1, 3, 63, 64, 65, 127, 129, 200, N };
	for (size_t l = 0; l < sizeof lengths / sizeof lengths[0]; l++) {
		const int n = lengths[l];
		const int off = l % 2 ? 0 : 37; /* also an unaligned start */
		if (off + n > N)
			continue;
		memset(a, 0, sizeof a), memset(b, 0, sizeof b), memset(an, 0, sizeof an), memset(bn, 0, sizeof bn);
		mlod_rt_skin_lbs((size_t)n, pos + 3 * off, nrm + 3 * off, jnt + 4 * off, wgt + 4 * off, pal, a, 12, an, 12);
		mlod_rt_skin_lbs_scalar((size_t)n, pos + 3 * off, nrm + 3 * off, jnt + 4 * off, wgt + 4 * off, pal, b, 12,
		                        bn, 12);
		double d = fx_maxdiff(a, b, 3 * N), dn = fx_maxdiff(an, bn, 3 * N);
		CHECK(d <= 1e-5 && dn <= 1e-5, "n %d: kernel and scalar differ: %g (positions), %g (normals)", n, d, dn);
		/* Without normals: same positions, the normal buffer untouched. */
		memset(a, 0, sizeof a), memset(an, 0, sizeof an);
		mlod_rt_skin_lbs((size_t)n, pos + 3 * off, NULL, jnt + 4 * off, wgt + 4 * off, pal, a, 12, an, 12);
		d = fx_maxdiff(a, b, 3 * N);
		CHECK(d <= 1e-5, "n %d, no normals: positions differ by %g", n, d);
		for (int i = 0; i < 3 * N; i++)
			CHECK(an[i] == 0.0f, "n %d: normals written without normals", n);
		/* Interleaved: position at 0, normal at 4, floats 3 and 7 a gap. */
		for (int i = 0; i < S * N; i++)
			ia[i] = ib[i] = -7.0f;
		mlod_rt_skin_lbs((size_t)n, pos + 3 * off, nrm + 3 * off, jnt + 4 * off, wgt + 4 * off, pal, ia, 4 * S,
		                 ia + 4, 4 * S);
		mlod_rt_skin_lbs_scalar((size_t)n, pos + 3 * off, nrm + 3 * off, jnt + 4 * off, wgt + 4 * off, pal, ib,
		                        4 * S, ib + 4, 4 * S);
		d = fx_maxdiff(ia, ib, S * N);
		CHECK(d <= 1e-5, "n %d, interleaved: kernel and scalar differ by %g", n, d);
		for (int i = 0; i < S * N; i++)
			CHECK(i >= S * n || (i % S != 3 && i % S != 7) ? 1 : ia[i] == -7.0f, "n %d: gap %d written", n, i);
		for (int i = S * n; i < S * N; i++)
			CHECK(ia[i] == -7.0f, "n %d: wrote past the last vertex (float %d)", n, i);
	}
}

/* Rigid and static parts (rt_transform, white box): the point M p and
 * the normal M n normalised, against a plain loop in the documented order
 * of operations, float for float (== : the 4-wide loop and its AVX2 clone
 * must give the same floats); lengths around the 4-wide step, packed and
 * interleaved outputs with a gap it must not touch, zero normals (length
 * 0: a zero normal), no input normals (zeros written), no output normals. */
TEST(rigid_transform_exact)
{
	enum { N = 300, S = 8 };
	static float pos[3 * N], nrm[3 * N], a[S * N], an[S * N], b[S * N], bn[S * N];
	mlod_trs t = { { 0.3f, -1.2f, 2.5f },
	               mlod_quat_normalize((mlod_quat){ 0.2f, -0.4f, 0.1f, 0.9f }),
	               { 1.0f, 1.5f, 0.75f } };
	mlod_mat4 MM = mlod_mat4_from_trs(&t);
	const float *M = MM.m;
	float U[12];
	for (int k = 0; k < 12; k++)
		U[k] = M[k] * 0.5f + (float)k;
	for (int v = 0; v < N; v++)
		for (int k = 0; k < 3; k++)
			pos[3 * v + k] = frand() * 4 - 2, nrm[3 * v + k] = v % 7 == 3 ? 0.0f : frand() - 0.5f;
	static const int lengths[] = { 0, 1, 2, 3, 4, 5, 7, 8, 9, 63, 64, 65, 255, N };
	static const size_t strides[] = { 12, 16, 32 };
	int checked = 0;
	for (size_t l = 0; l < sizeof lengths / sizeof lengths[0]; l++)
		for (size_t si = 0; si < 3; si++)
			for (int mode = 0; mode < 4; mode++) { /* normals, no input normals, no output normals, by U */
				const int n = lengths[l];
				const size_t st = strides[si], fs = st / 4;
				for (int i = 0; i < S * N; i++)
					a[i] = b[i] = an[i] = bn[i] = -7.0f;
				const float *in_n = mode == 1 ? NULL : nrm;
				rt_transform((size_t)n, pos, in_n, M, mode == 3 ? U : NULL, a, st, mode == 2 ? NULL : an, st);
				for (int v = 0; v < n; v++) {
					const float *q = pos + 3 * v;
					float *o = b + fs * (size_t)v, *on = bn + fs * (size_t)v;
					for (int r = 0; r < 3; r++)
						o[r] = M[r] * q[0] + M[4 + r] * q[1] + M[8 + r] * q[2] + M[12 + r];
					if (mode == 2)
						continue;
					if (!in_n) {
						on[0] = on[1] = on[2] = 0.0f;
						continue;
					}
					const float *nn = nrm + 3 * v;
					float tt[3];
					if (mode == 3) { /* U n as it is */
						for (int r = 0; r < 3; r++)
							on[r] = U[r] * nn[0] + U[4 + r] * nn[1] + U[8 + r] * nn[2];
						continue;
					}
					for (int r = 0; r < 3; r++)
						tt[r] = M[r] * nn[0] + M[4 + r] * nn[1] + M[8 + r] * nn[2];
					const float len2 = tt[0] * tt[0] + tt[1] * tt[1] + tt[2] * tt[2];
					const float il = len2 > 0.0f ? 1.0f / sqrtf(len2) : 0.0f;
					for (int r = 0; r < 3; r++)
						on[r] = tt[r] * il;
				}
				CHECK(memcmp(a, b, sizeof a) == 0, "n %d stride %zu mode %d: positions differ from the plain loop", n,
				      st, mode);
				CHECK(memcmp(an, bn, sizeof an) == 0, "n %d stride %zu mode %d: normals differ from the plain loop",
				      n, st, mode);
				checked++;
			}
	printf("# rt_transform: %d cases equal to the plain loop, float for float\n", checked);
}

/* Rigid normals without renormalising (rigid_unit in rt_eval.c): the
 * rigid part on joint 4 (scaled uniformly 1 -> 3 by clip 0) gives normals
 * equal to M n normalised to within the bound (3e-6 plus rounding) with its
 * offset a rotation, a rotation times 2, and, where renormalising cannot be
 * skipped, a non-uniform scale (1, 2, 0.5), a shear, and input normals that
 * are not unit (the part's normals scaled by 1.5). Fails when the skip
 * ignores the scale or takes a matrix or normals it does not hold for. */
TEST(rigid_unit_normals)
{
	static const float c = 0.8f, sn = 0.6f;
	const float rot[16] = { c, sn, 0, 0, -sn, c, 0, 0, 0, 0, 1, 0, 0.5f, 0, 0, 1 };
	float offs[5][16];
	for (int k = 0; k < 5; k++)
		memcpy(offs[k], rot, sizeof rot);
	for (int k = 0; k < 12; k++)
		offs[1][k] *= 2.0f;
	for (int r = 0; r < 3; r++)
		offs[2][r] *= 1.0f, offs[2][4 + r] *= 2.0f, offs[2][8 + r] *= 0.5f;
	offs[3][4] += 0.3f; /* shear */
	float saved_off[16], big[6];
	memcpy(saved_off, fx_m0_parts[1].rec.offset, sizeof saved_off);
	for (int k = 0; k < 6; k++)
		big[k] = 1.5f * fx_m0_nrm1[k];
	for (int cse = 0; cse < 5; cse++) {
		memcpy(fx_m0_parts[1].rec.offset, offs[cse == 4 ? 0 : cse], sizeof saved_off);
		if (cse == 4)
			fx_m0_parts[1].normals = big;
		mlod_error e;
		mlod_rt_ctx *ctx = open_all(NULL, &e);
		CHECK(ctx, "open: %s", e.message);
		mlod_rt_scratch *s = mlod_rt_scratch_create(ctx);
		uint32_t id, n;
		CHECK_OK(mlod_rt_instance_create(ctx, 0, 0.0f, 0, &id, &e), e);
		CHECK_OK(force(ctx, id, 0, &e), e);
		double worst = 0;
		for (int step = 0; step <= 8; step++) {
			float buf[6 * 7];
			CHECK_OK(mlod_rt_instance_set(ctx, id, 0, 0.25f * (float)step, 0, &e), e);
			CHECK_OK(mlod_rt_skin(ctx, s, id, buf, 24, buf + 3, 24, 7, &n, &e), e);
			const float *W;
			CHECK_OK(mlod_rt_pose(ctx, s, id, &W, NULL, NULL, &e), e);
			const float *O = fx_m0_parts[1].rec.offset, *in = fx_m0_parts[1].normals;
			for (int v = 0; v < 2; v++) {
				double t[3], l = 0;
				for (int r = 0; r < 3; r++) {
					t[r] = 0;
					for (int a = 0; a < 3; a++) { /* (W4 O) column a, row r, times n[a] */
						double m = 0;
						for (int b = 0; b < 3; b++)
							m += (double)W[16 * 4 + 4 * b + r] * O[4 * a + b];
						t[r] += m * in[3 * v + a];
					}
					l += t[r] * t[r];
				}
				for (int r = 0; r < 3; r++) {
					const double d = fabs(buf[6 * (4 + v) + 3 + r] - t[r] / sqrt(l));
					worst = d > worst ? d : worst;
				}
			}
		}
		/* A rotation (times a scale): within the skip's bound; else
		 * renormalised, so within rounding. */
		const double tol = cse <= 1 ? 4e-6 : 5e-7;
		printf("# rigid normals, offset case %d: worst %.3g (tolerance %.3g)\n", cse, worst, tol);
		CHECK(worst <= tol, "offset case %d: rigid normals off by %g", cse, worst);
		mlod_rt_scratch_destroy(ctx, s);
		mlod_rt_close(ctx);
	}
	memcpy(fx_m0_parts[1].rec.offset, saved_off, sizeof saved_off);
	fx_m0_parts[1].normals = fx_m0_nrm1;
}

/* The counting allocator. */
static size_t n_alloc, n_free;
static void *count_malloc(void *user, size_t size)
{
	(void)user;
	n_alloc++;
	return malloc(size);
}
static void count_free(void *user, void *p)
{
	(void)user;
	if (p)
		n_free++;
	free(p);
}

TEST(no_allocation_per_frame)
{
	mlod_rt_allocator a = { count_malloc, count_free, NULL };
	mlod_rt_config cfg = { 0, 64, &a };
	mlod_error e;
	n_alloc = n_free = 0;
	mlod_rt_ctx *ctx = open_all(&cfg, &e);
	CHECK(ctx, "open: %s", e.message);
	CHECK(n_alloc > 0, "the allocator hooks were not used");
	mlod_rt_scratch *s = mlod_rt_scratch_create(ctx);
	uint32_t ids[50];
	for (int i = 0; i < 50; i++)
		CHECK_OK(mlod_rt_instance_create(ctx, (uint32_t)i % 2, 0.1f * (float)i, MLOD_RT_LOOP, &ids[i], &e), e);
	const size_t before = n_alloc, freed = n_free;
	mlod_rt_select sel;
	mlod_rt_select_default(&sel);
	float d[50], buf[3 * 7], nb[3 * 7];
	for (int f = 0; f < 500; f++) {
		for (int i = 0; i < 50; i++)
			d[i] = 2.0f + (float)((i * 37 + f * 3) % 200);
		sel.mode = (mlod_rt_select_mode)(f % 3);
		CHECK_OK(mlod_rt_update(ctx, &sel, ids, d, 50, 1.0f / 60, &e), e);
		CHECK_OK(mlod_rt_stream(ctx, 1 << 20, NULL, &e), e);
		for (int i = 0; i < 50; i++) {
			uint32_t n;
			const float *P;
			CHECK_OK(mlod_rt_skin(ctx, s, ids[i], buf, 12, nb, 12, 7, &n, &e), e);
			CHECK_OK(mlod_rt_palette(ctx, s, &P, NULL, &e), e);
		}
		/* the pool: destroy and create again */
		mlod_rt_instance_destroy(ctx, ids[f % 50]);
		CHECK_OK(mlod_rt_instance_create(ctx, 0, 0, 0, &ids[f % 50], &e), e);
	}
	CHECK(n_alloc == before && n_free == freed, "%zu allocations and %zu frees in 500 frames", n_alloc - before,
	      n_free - freed);
	mlod_rt_scratch_destroy(ctx, s);
	mlod_rt_close(ctx);
	CHECK(n_alloc == n_free, "%zu allocations, %zu frees: a leak", n_alloc, n_free);
}

/* The fixture with morph targets: level 0 part 0 (skinned) 2 targets,
 * part 2 (static) 1; level 1 part 0 (skinned, level 0's vertices 1..2)
 * 2 targets; level 1 part 1 (rigid) 1 target, which level 0 part 1 lacks:
 * views take the most targets of any level. mw (non-NULL) gives the same
 * character with the weighted deltas added to its positions instead. */
static float mt_d00[12], mt_d01[12], mt_d1[6], mt_d2[3];
static float *mt_t0[2] = { mt_d00, mt_d01 }, *mt_t0l1[2] = { mt_d00 + 3, mt_d01 + 3 }, *mt_t1[1] = { mt_d1 },
             *mt_t2[1] = { mt_d2 };
static float mt_pos0[12], mt_pos1[6], mt_pos2[3];
static mlod_pack_part mt_p0[3], mt_p1[2], mt_p2[1];
static mlod_pack_mesh mt_m[3];
static mlod_rt_view_level mt_vm[3];
static mlod_rt_views mt_views;

static void morph_views(const float *mw)
{
	for (int i = 0; i < 12; i++)
		mt_d00[i] = 0.1f * (float)(i % 5) - 0.2f, mt_d01[i] = (i % 3 == 1) ? 0.5f : -0.05f * (float)i;
	for (int i = 0; i < 6; i++)
		mt_d1[i] = 0.3f - 0.1f * (float)i;
	mt_d2[0] = 1, mt_d2[1] = -2, mt_d2[2] = 0.5f;
	memcpy(mt_p0, fx_m0_parts, sizeof mt_p0);
	memcpy(mt_p1, fx_m1_parts, sizeof mt_p1);
	memcpy(mt_p2, fx_m2_parts, sizeof mt_p2);
	if (mw) { /* weights: part 0 mw[0], mw[1]; part 1 mw[2]; part 2 mw[3] */
		for (int i = 0; i < 12; i++)
			mt_pos0[i] = fx_m0_pos0[i] + mw[0] * mt_d00[i] + mw[1] * mt_d01[i];
		for (int i = 0; i < 6; i++)
			mt_pos1[i] = fx_m0_pos1[i] + mw[2] * mt_d1[i];
		for (int i = 0; i < 3; i++)
			mt_pos2[i] = fx_m0_pos2[i] + mw[3] * mt_d2[i];
		mt_p0[0].positions = mt_pos0, mt_p0[2].positions = mt_pos2;
		mt_p1[0].positions = mt_pos0 + 3, mt_p1[1].positions = mt_pos1;
		mt_p2[0].positions = mt_pos0;
	} else {
		mt_p0[0].targets = mt_t0, mt_p0[0].rec.target_count = 2;
		mt_p0[2].targets = mt_t2, mt_p0[2].rec.target_count = 1;
		mt_p1[0].targets = mt_t0l1, mt_p1[0].rec.target_count = 2;
		mt_p1[1].targets = mt_t1, mt_p1[1].rec.target_count = 1;
		mt_p2[0].targets = mt_t0, mt_p2[0].rec.target_count = 2;
	}
	mt_m[0] = (mlod_pack_mesh){ 3, mt_p0, NULL };
	mt_m[1] = (mlod_pack_mesh){ 2, mt_p1, NULL };
	mt_m[2] = (mlod_pack_mesh){ 1, mt_p2, NULL };
	for (int l = 0; l < 3; l++)
		mt_vm[l] = fx_vmesh[l], mt_vm[l].data = &mt_m[l];
	mt_views = fx_views;
	mt_views.mesh = mt_vm;
}

TEST(morph_targets)
{
	mlod_error e;
	mlod_rt_allocator a = { count_malloc, count_free, NULL };
	mlod_rt_config cfg = { 0, 8, &a };
	static const float w[4] = { 0.75f, -1.5f, 2.0f, 0.5f };
	for (int level = 0; level < 3; level++) {
		/* the reference: positions morphed by hand, no targets */
		morph_views(w);
		mlod_rt_views saved = fx_views;
		fx_views = mt_views; /* open_all opens fx_views */
		mlod_rt_ctx *ref = open_all(NULL, &e);
		fx_views = saved;
		CHECK(ref, "open: %s", e.message);
		CHECK(mlod_rt_morph_target_count(ref, 0) == 0, "targets in the reference");
		mlod_rt_scratch *rs = mlod_rt_scratch_create(ref);
		uint32_t rid;
		CHECK_OK(mlod_rt_instance_create(ref, 0, 0.7f, MLOD_RT_LOOP, &rid, &e), e);
		CHECK_OK(force(ref, rid, level, &e), e);
		float rp[3 * 7], rn[3 * 7], mp[3 * 7], mn[3 * 7], zp[3 * 7], zn[3 * 7];
		uint32_t rc, mc, zc;
		CHECK_OK(mlod_rt_skin(ref, rs, rid, rp, 12, rn, 12, 7, &rc, &e), e);
		mlod_rt_scratch_destroy(ref, rs);
		mlod_rt_close(ref);

		morph_views(NULL);
		fx_views = mt_views;
		n_alloc = n_free = 0;
		mlod_rt_ctx *ctx = open_all(&cfg, &e);
		fx_views = saved;
		CHECK(ctx, "open: %s", e.message);
		CHECK(mlod_rt_morph_target_count(ctx, 0) == 2 && mlod_rt_morph_target_count(ctx, 1) == 1 &&
		          mlod_rt_morph_target_count(ctx, 2) == 1 && mlod_rt_morph_target_count(ctx, 3) == 0,
		      "target counts %u %u %u %u", mlod_rt_morph_target_count(ctx, 0), mlod_rt_morph_target_count(ctx, 1),
		      mlod_rt_morph_target_count(ctx, 2), mlod_rt_morph_target_count(ctx, 3));
		mlod_rt_scratch *s = mlod_rt_scratch_create(ctx);
		uint32_t id, other;
		CHECK_OK(mlod_rt_instance_create(ctx, 0, 0.7f, MLOD_RT_LOOP, &id, &e), e);
		CHECK_OK(mlod_rt_instance_create(ctx, 0, 0.7f, MLOD_RT_LOOP, &other, &e), e);
		CHECK_OK(force(ctx, id, level, &e), e);
		CHECK_OK(force(ctx, other, level, &e), e);
		const size_t allocs = n_alloc;
		/* the rules */
		const float nan = NAN, three[3] = { 1, 2, 3 };
		CHECK(mlod_rt_instance_set_morph_weights(ctx, id, 0, three, 3, &e) == MLOD_ERR_INVALID_ARG,
		      "3 weights for 2 targets accepted");
		CHECK(mlod_rt_instance_set_morph_weights(ctx, id, 0, &nan, 1, &e) == MLOD_ERR_INVALID_ARG,
		      "a NaN weight accepted");
		CHECK(mlod_rt_instance_set_morph_weights(ctx, id, 3, w, 1, &e) == MLOD_ERR_INVALID_ARG,
		      "a weight for a part without targets accepted");
		CHECK(mlod_rt_instance_set_morph_weights(ctx, 7, 0, w, 1, &e) == MLOD_ERR_INVALID_ARG,
		      "weights for an instance not alive accepted");
		CHECK(mlod_rt_instance_set_morph_weights(ctx, id, 0, NULL, 1, &e) == MLOD_ERR_INVALID_ARG, "NULL accepted");
		/* other: one weight of part 0 (the second is 0), then cleared by count 0 */
		CHECK_OK(mlod_rt_instance_set_morph_weights(ctx, other, 0, three, 2, &e), e);
		CHECK_OK(mlod_rt_instance_set_morph_weights(ctx, other, 0, w, 1, &e), e);
		CHECK_OK(mlod_rt_instance_set_morph_weights(ctx, other, 0, NULL, 0, &e), e);
		CHECK_OK(mlod_rt_instance_set_morph_weights(ctx, id, 0, w, 2, &e), e);
		CHECK_OK(mlod_rt_instance_set_morph_weights(ctx, id, 1, w + 2, 1, &e), e);
		CHECK_OK(mlod_rt_instance_set_morph_weights(ctx, id, 2, w + 3, 1, &e), e);
		CHECK_OK(mlod_rt_skin(ctx, s, id, mp, 12, mn, 12, 7, &mc, &e), e);
		CHECK_OK(mlod_rt_skin(ctx, s, other, zp, 12, zn, 12, 7, &zc, &e), e);
		CHECK(n_alloc == allocs, "%zu allocations setting weights and skinning", n_alloc - allocs);
		CHECK(mc == rc && zc == rc, "level %d: %u and %u vertices, the reference %u", level, mc, zc, rc);
		double d = fx_maxdiff(mp, rp, 3 * (int)rc), dn = fx_maxdiff(mn, rn, 3 * (int)rc);
		CHECK(d <= 1e-5 && dn <= 1e-6, "level %d: morphed positions differ by %g, normals by %g", level, d, dn);
		/* other has no weights left: it must differ from the morphed one */
		CHECK(fx_maxdiff(zp, mp, 3 * (int)rc) > 0.1, "level %d: zero weights morphed anyway", level);
		/* a new instance in a slot that had weights starts at 0 */
		mlod_rt_instance_destroy(ctx, id);
		uint32_t again;
		CHECK_OK(mlod_rt_instance_create(ctx, 0, 0.7f, MLOD_RT_LOOP, &again, &e), e);
		/* the pool reuses the slot (last freed, first taken) under a new
		 * generation: the old id names nothing now */
		CHECK(again != id, "the pool gave the destroyed id %#x again", id);
		CHECK(mlod_rt_instance_state(ctx, id) == NULL, "the destroyed id %#x still names an instance", id);
		CHECK_OK(force(ctx, again, level, &e), e);
		CHECK_OK(mlod_rt_skin(ctx, s, again, mp, 12, mn, 12, 7, &mc, &e), e);
		CHECK(fx_maxdiff(zp, mp, 3 * (int)rc) == 0, "level %d: a new instance kept the old weights", level);
		mlod_rt_scratch_destroy(ctx, s);
		mlod_rt_close(ctx);
		CHECK(n_alloc == n_free, "%zu allocations, %zu frees: a leak", n_alloc, n_free);
	}
}

/* mlod_rt_skin poses only the joints its mesh level's palette entries and
 * rigid parts follow (and their ancestors) and multiplies only those
 * entries: they, the posed joints' world matrices and the skinned
 * vertices must be the floats of the full pose (mlod_rt_pose) and palette
 * (mlod_rt_palette), at every skeleton level with every mesh level, and
 * mlod_rt_palette after mlod_rt_skin must give the whole palette. */
TEST(skin_plan_matches_full_pose)
{
	mlod_error e;
	mlod_rt_ctx *ctx = open_all(NULL, &e);
	CHECK(ctx, "open: %s", e.message);
	mlod_rt_scratch *s1 = mlod_rt_scratch_create(ctx), *s2 = mlod_rt_scratch_create(ctx);
	CHECK(s1 && s2, "scratch");
	const uint32_t J = mlod_rt_joint_count(ctx), P = mlod_rt_palette_size(ctx);
	uint32_t id, fewest = J, checked = 0;
	CHECK_OK(mlod_rt_instance_create(ctx, 0, 0, MLOD_RT_LOOP, &id, &e), e);
	float out[3 * 16], nrm[3 * 16], ref[3 * 16], refn[3 * 16];
	for (uint32_t ls = 0; ls < 3; ls++)
		for (uint32_t lm = 0; lm < 3; lm++)
			for (int f = 0; f < 23; f++) {
				mlod_rt_select sel;
				mlod_rt_select_default(&sel);
				sel.force_level = 0;
				float d = 1;
				CHECK_OK(mlod_rt_update(ctx, &sel, &id, &d, 1, 0.0913f, &e), e);
				mlod_rt_state *st = &rt_live(ctx, id)->st; /* the levels under test */
				st->level[MLOD_RT_SKELETON] = (uint16_t)ls, st->level[MLOD_RT_MESH] = (uint16_t)lm;
				st->level[MLOD_RT_MOTION] = (uint16_t)(f % 3);
				uint32_t n = 0;
				CHECK_OK(mlod_rt_skin(ctx, s1, id, out, 12, nrm, 12, 16, &n, &e), e);
				const float *W2, *P2, *P1;
				CHECK_OK(mlod_rt_pose(ctx, s2, id, &W2, NULL, NULL, &e), e);
				CHECK_OK(mlod_rt_palette(ctx, s2, &P2, NULL, &e), e);
				const rt_unit *mu = rt_unit_get(ctx, MLOD_RT_MESH, lm, 0);
				CHECK(s1->plan_mesh == mu && s1->plan_count >= 1 && s1->plan_count <= J, "plan of %u joints",
				      s1->plan_count);
				fewest = s1->plan_count < fewest ? s1->plan_count : fewest;
				for (uint32_t k = 0; k < s1->plan_count; k++) {
					const uint32_t j = s1->plan_posed[k];
					CHECK(memcmp(s1->world + 16 * j, W2 + 16 * j, 64) == 0,
					      "skeleton %u mesh %u frame %d: joint %u's world differs", ls, lm, f, j);
				}
				for (uint32_t k = 0; k < mu->pal_used_count; k++) {
					const uint32_t x = mu->pal_used[k];
					CHECK(memcmp(s1->palette + 16 * x, P2 + 16 * x, 64) == 0,
					      "skeleton %u mesh %u frame %d: palette entry %u differs", ls, lm, f, x);
				}
				/* the skinned parts again with the full palette */
				size_t base = 0;
				for (uint32_t i = 0; i < mu->mesh->part_count; i++) {
					const mlod_pack_part *p = &mu->mesh->parts[i];
					if (p->rec.skin >= 0) {
						mlod_rt_skin_lbs(p->rec.vertex_count, p->positions, p->normals, p->joints, p->weights,
						                 P2 + 16 * (size_t)ctx->skin_offset[p->rec.skin], ref, 12, refn, 12);
						CHECK(memcmp(ref, out + 3 * base, 12 * p->rec.vertex_count) == 0 &&
						          memcmp(refn, nrm + 3 * base, 12 * p->rec.vertex_count) == 0,
						      "skeleton %u mesh %u frame %d: part %u skins differently", ls, lm, f, i);
					}
					base += p->rec.vertex_count;
				}
				CHECK(base == n, "%u vertices, %zu in the parts", n, base);
				CHECK_OK(mlod_rt_palette(ctx, s1, &P1, NULL, &e), e);
				CHECK(memcmp(P1, P2, 64 * (size_t)P) == 0, "skeleton %u mesh %u: the palette after skinning differs",
				      ls, lm);
				checked++;
			}
	CHECK(fewest < J, "every plan posed all %u joints: nothing left out", J);
	printf("# %u skins at 3 x 3 level pairs: the plan's floats are the full pose's; fewest joints posed %u of %u\n",
	       checked, fewest, J);
	mlod_rt_scratch_destroy(ctx, s1), mlod_rt_scratch_destroy(ctx, s2);
	mlod_rt_close(ctx);
}

/* One case of skin_buckets_at_load: 0 when equal, else 1 and t_msg_
 * says why. */
static int skin_buckets_case(mlod_rt_ctx *ctx, mlod_rt_scratch *s, uint32_t id, int morph, uint32_t n_,
                             const float *pos, const float *nrm, const uint16_t *jnt, const float *wgt,
                             const float *dlt, float *mor, float *out, float *outn, float *ref, float *refn)
{
	mlod_error e;
	const float w = morph ? 0.625f : 0.0f;
	const float *P;
	uint32_t n;
	if (mlod_rt_instance_set_morph_weights(ctx, id, 0, &w, 1, &e) ||
	    mlod_rt_skin(ctx, s, id, out, 12, outn, 12, n_, &n, &e) || mlod_rt_palette(ctx, s, &P, NULL, &e)) {
		snprintf(t_msg_, sizeof t_msg_, "morph %d: %s", morph, e.message);
		return 1;
	}
	if (n != n_) {
		snprintf(t_msg_, sizeof t_msg_, "%u vertices written, %u expected", n, n_);
		return 1;
	}
	for (size_t k = 0; k < 3 * (size_t)n_; k++) /* the runtime's morph: position, then + weight * delta */
		mor[k] = pos[k], mor[k] += w * dlt[k];
	mlod_rt_skin_lbs(n_, morph ? mor : pos, nrm, jnt, wgt, P, ref, 12, refn, 12);
	for (uint32_t v = 0; v < n_; v++)
		if (memcmp(out + 3 * v, ref + 3 * v, 12) || memcmp(outn + 3 * v, refn + 3 * v, 12)) {
			snprintf(t_msg_, sizeof t_msg_, "morph %d vertex %u: (%g %g %g) against mlod_rt_skin_lbs's (%g %g %g)",
			         morph, v, out[3 * v], out[3 * v + 1], out[3 * v + 2], ref[3 * v], ref[3 * v + 1], ref[3 * v + 2]);
			return 1;
		}
	return 0;
}

/* mlod_rt_skin skins with the buckets built when its mesh level loaded
 * (rt_skin_order): a skinned part of 1,000 vertices (16 runs, the last
 * partial) whose influence patterns are every one of the 16 (zeros before
 * the last non-zero weight too), with and without a morph target (runs
 * of 128 through the stack buffer), gives mlod_rt_skin_lbs's floats on
 * the same palette, bit for bit. A bucket list offset by a run, a wrong
 * count or a stale order would move vertices. */
TEST(skin_buckets_at_load)
{
	enum { N = 1000 };
	static float pos[3 * N], nrm[3 * N], wgt[4 * N], dlt[3 * N], mor[3 * N];
	static float out[3 * N], outn[3 * N], ref[3 * N], refn[3 * N];
	static uint16_t jnt[4 * N];
	static float *targets[1] = { dlt };
	unsigned seed = 12345;
	for (int v = 0; v < N; v++) {
		for (int c = 0; c < 3; c++) {
			seed = seed * 1103515245u + 12345u;
			pos[3 * v + c] = (float)((seed >> 8) % 2000) / 1000.0f - 1.0f;
			nrm[3 * v + c] = (float)((seed >> 4) % 200) / 100.0f - 1.0f;
			dlt[3 * v + c] = (float)((seed >> 12) % 100) / 400.0f;
		}
		seed = seed * 1103515245u + 12345u;
		const unsigned pattern = ((seed >> 16) % 15) + 1; /* non-zero weights: bits of 1..15 */
		float sum = 0;
		for (int k = 0; k < 4; k++) {
			jnt[4 * v + k] = (uint16_t)((v + 3 * k) % FX_J);
			wgt[4 * v + k] = (pattern >> k) & 1 ? (float)(k + 1) : 0.0f;
			sum += wgt[4 * v + k];
		}
		for (int k = 0; k < 4; k++)
			wgt[4 * v + k] /= sum;
	}
	mlod_pack_part part;
	fx_part(&part, pos, nrm, jnt, wgt, N, 0, -1, NULL);
	part.targets = targets;
	part.rec.target_count = 1;
	mlod_pack_mesh saved = fx_mesh0;
	fx_mesh0 = (mlod_pack_mesh){ 1, &part, NULL };
	mlod_error e;
	mlod_rt_ctx *ctx = open_all(NULL, &e); /* the views point at fx_mesh0: restored after closing */
	if (!ctx)
		fx_mesh0 = saved;
	CHECK(ctx, "open: %s", e.message);
	mlod_rt_scratch *s = mlod_rt_scratch_create(ctx);
	uint32_t id;
	int failed = 0;
	if (mlod_rt_instance_create(ctx, 0, 0.7f, MLOD_RT_LOOP, &id, &e) || force(ctx, id, 0, &e)) {
		snprintf(t_msg_, sizeof t_msg_, "instance: %s", e.message);
		failed = 1;
	}
	for (int morph = 0; morph < 2 && !failed; morph++)
		failed = skin_buckets_case(ctx, s, id, morph, N, pos, nrm, jnt, wgt, dlt, mor, out, outn, ref, refn);
	mlod_rt_scratch_destroy(ctx, s);
	mlod_rt_close(ctx);
	fx_mesh0 = saved;
	if (failed) /* t_msg_ says why */
		t_failed_ = 1;
}

/* fixed_joints_and_near_slerp's checks on the open ctx: NULL, or what
 * went wrong. */
#define FCHECK(cond, ...)                                                                                            \
	do {                                                                                                       \
		if (!(cond)) {                                                                                     \
			snprintf(why, sizeof why, __VA_ARGS__);                                                    \
			return why;                                                                                \
		}                                                                                                  \
	} while (0)
static const char *fixed_check(mlod_rt_ctx *ctx, mlod_rt_scratch *s)
{
	static char why[200];
	mlod_error e;
	uint32_t id;
	FCHECK(mlod_rt_instance_create(ctx, 1, 1.0f, 0, &id, &e) == MLOD_OK, "create: %.120s", e.message);
	FCHECK(force(ctx, id, 0, &e) == MLOD_OK, "update: %.120s", e.message);
	const float *W;
	FCHECK(mlod_rt_pose(ctx, s, id, &W, NULL, NULL, &e) == MLOD_OK, "pose: %.120s", e.message);
	/* joint 0, no channel: its rest world matrix */
	FCHECK(fx_maxdiff(W, fx_rest_world[0], 16) <= 1e-6, "joint 0 is not at rest");
	float L[16];
	local_of(W, 0, 1, L); /* Rz(30), the rest translation */
	const double c30 = cos(30 * M_PI / 180), s30 = sin(30 * M_PI / 180);
	FCHECK(NEAR(L[0], c30, 1e-6) && NEAR(L[1], s30, 1e-6) && NEAR(L[4], -s30, 1e-6) && NEAR(L[5], c30, 1e-6) &&
	           NEAR(L[10], 1, 1e-6),
	       "L1 is not Rz(30): %g %g %g %g", L[0], L[1], L[4], L[5]);
	FCHECK(NEAR(L[12], fx_joints[1].t[0], 1e-6) && NEAR(L[13], fx_joints[1].t[1], 1e-6) &&
	           NEAR(L[14], fx_joints[1].t[2], 1e-6),
	       "L1 t = %g %g %g", L[12], L[13], L[14]);
	local_of(W, 1, 2, L); /* translation: the later channel's */
	FCHECK(NEAR(L[12], 0.25, 1e-6) && NEAR(L[13], 0, 1e-6) && NEAR(L[14], 0, 1e-6), "L2 t = %g %g %g", L[12],
	       L[13], L[14]);
	local_of(W, 2, 3, L); /* slerp Rz(0) -> Rz(40) at 1 / 4: Rz(10), scaled by 2 */
	const double c10 = cos(10 * M_PI / 180), s10 = sin(10 * M_PI / 180);
	FCHECK(NEAR(L[0], 2 * c10, 2e-6) && NEAR(L[1], 2 * s10, 2e-6) && NEAR(L[4], -2 * s10, 2e-6) &&
	           NEAR(L[5], 2 * c10, 2e-6) && NEAR(L[10], 2, 2e-6),
	       "L3 is not 2 Rz(10): %.7g %.7g %.7g", L[0], L[1], L[10]);
	/* joint 4, no channel: its rest local transform under joint 1 */
	local_of(W, 1, 4, L);
	FCHECK(NEAR(L[12], fx_joints[4].t[0], 1e-6) && NEAR(L[13], fx_joints[4].t[1], 1e-6) &&
	           NEAR(L[14], fx_joints[4].t[2], 1e-6),
	       "L4 t = %g %g %g", L[12], L[13], L[14]);
	return NULL;
}
#undef FCHECK

/* A motion level's one-key channels (their joints' local matrices made at
 * load), a joint without channels (the rest matrix), two one-key channels
 * of one joint and path (the later wins), a joint mixing a one-key and an
 * animated channel, and a slerp within 26 degrees (the series weights):
 * clip 1's levels replaced by such a level while the ctx is open. */
TEST(fixed_joints_and_near_slerp)
{
	static const float t0[1] = { 0 }, t04[2] = { 0, 4 };
	static float r1[4], tr2a[3] = { 0.5f, 0, 0 }, tr2b[3] = { 0.25f, 0, 0 }, r3[8], s3[3] = { 2, 2, 2 };
	fx_quat_z(30, r1);
	for (int k = 0; k < 4; k++)
		r1[k] *= 2; /* not unit */
	fx_quat_z(0, r3), fx_quat_z(40, r3 + 4);
	mlod_pack_channel ch[5];
	fx_channel(&ch[0], 1, 1, 0, 1, t0, r1);
	fx_channel(&ch[1], 2, 0, 0, 1, t0, tr2a);
	fx_channel(&ch[2], 2, 0, 1, 1, t0, tr2b);
	fx_channel(&ch[3], 3, 1, 0, 2, t04, r3);
	fx_channel(&ch[4], 3, 2, 0, 1, t0, s3);
	mlod_pack_motion saved[3];
	memcpy(saved, fx_mo[1], sizeof saved);
	for (int l = 0; l < 3; l++)
		fx_motion(&fx_mo[1][l], ch, 5, 4);
	mlod_error e;
	mlod_rt_ctx *ctx = open_all(NULL, &e); /* the views stay until close */
	mlod_rt_scratch *s = ctx ? mlod_rt_scratch_create(ctx) : NULL;
	const char *why = s ? fixed_check(ctx, s) : "open failed";
	mlod_rt_scratch_destroy(ctx, s);
	mlod_rt_close(ctx);
	memcpy(fx_mo[1], saved, sizeof saved);
	CHECK(!why, "%s", why);
}

/* slerp_batches' checks: NULL, or what went wrong. */
static const char *slerp_batch_check(mlod_rt_ctx *ctx, mlod_rt_scratch *s)
{
	static char why[200];
	mlod_error e;
	uint32_t id;
	const float *W;
	if (mlod_rt_instance_create(ctx, 1, 1.0f, 0, &id, &e) || force(ctx, id, 0, &e) ||
	    mlod_rt_pose(ctx, s, id, &W, NULL, NULL, &e)) {
		snprintf(why, sizeof why, "pose: %.120s", e.message);
		return why;
	}
	/* t = 1 of keys at 0 and 4: a quarter of each joint's last arc about
	 * z, but joint 4, whose last channel is Rx(90) (STEP) */
	static const int parent[5] = { -1, 0, 1, 2, 1 };
	static const double want_z[5] = { 0, 42.5, 0.005, 10, 0 }; /* degrees */
	for (int j = 1; j < 5; j++) {
		float L[16];
		local_of(W, parent[j], j, L);
		if (j == 4) {
			if (!(NEAR(L[0], 1, 1e-6) && NEAR(L[5], 0, 1e-6) && NEAR(L[6], 1, 1e-6) && NEAR(L[9], -1, 1e-6))) {
				snprintf(why, sizeof why, "joint 4 is not Rx(90): %.7g %.7g %.7g %.7g", L[0], L[5], L[6], L[9]);
				return why;
			}
			continue;
		}
		const double c = cos(want_z[j] * M_PI / 180), sn = sin(want_z[j] * M_PI / 180);
		if (!(NEAR(L[0], c, 1e-6) && NEAR(L[1], sn, 1e-6) && NEAR(L[4], -sn, 1e-6) && NEAR(L[5], c, 1e-6) &&
		      NEAR(L[10], 1, 1e-6))) {
			snprintf(why, sizeof why, "joint %d is not Rz(%g): %.7g %.7g %.7g %.7g", j, want_z[j], L[0], L[1],
			         L[4], L[5]);
			return why;
		}
	}
	return NULL;
}

/* The pose slerps LINEAR rotation channels in batches of up to 8, one per
 * lane of double vectors (rt_eval.c). 14 channels over joints 1-4, each joint's
 * last one winning: a first batch of 8 (flushed when the ninth comes:
 * out of order, its 80-degree arcs would win); a second of 4 ending
 * with a joint that a STEP rotation then sets (the batch must be
 * slerped before it); a last batch of one (a partial vector: lanes left
 * from the batch before would set joint 4 after its STEP). The second
 * batch holds every branch of the slerp in one vector: 170 degrees
 * (acos), 0.02 (nearly parallel), 40 with keys of length 2 (not flagged
 * unit) and 70 (the series); the last channel is 40 degrees against the
 * negated key, of length 2 (the series the short way round). */
TEST(slerp_batches)
{
	enum { NC = 14 };
	static const float t04[2] = { 0, 4 };
	static const uint32_t joint[NC] = { 1, 2, 3, 4, 1, 2, 3, 4, 1, 2, 3, 4, 4, 3 };
	static const float arc[NC] = { 80, 80, 80, 80, 60, 60, 60, 60, 170, 0.02f, 40, 70, 0, 40 };
	static float q[NC][8];
	mlod_pack_channel ch[NC];
	for (int c = 0; c < NC; c++) {
		if (c == 12) { /* STEP Rx(90) */
			fx_quat_x(90, q[c]), fx_quat_x(90, q[c] + 4);
			fx_channel(&ch[c], joint[c], 1, 1, 2, t04, q[c]);
			continue;
		}
		fx_quat_z(0, q[c]), fx_quat_z(arc[c], q[c] + 4);
		for (int k = 0; k < 8; k++) {
			if (c == 10 || c == 13)
				q[c][k] *= 2;
			if (c == 13 && k >= 4)
				q[c][k] = -q[c][k];
		}
		fx_channel(&ch[c], joint[c], 1, 0, 2, t04, q[c]);
	}
	mlod_pack_motion saved[3];
	memcpy(saved, fx_mo[1], sizeof saved);
	for (int l = 0; l < 3; l++)
		fx_motion(&fx_mo[1][l], ch, NC, 4);
	mlod_error e;
	mlod_rt_ctx *ctx = open_all(NULL, &e);
	mlod_rt_scratch *s = ctx ? mlod_rt_scratch_create(ctx) : NULL;
	const char *why = s ? slerp_batch_check(ctx, s) : "open failed";
	mlod_rt_scratch_destroy(ctx, s);
	mlod_rt_close(ctx);
	memcpy(fx_mo[1], saved, sizeof saved);
	CHECK(!why, "%s", why);
}

/* Palette entries that follow the same joint with the same bind matrix
 * are copied from the first of them (rt_palette_sources) instead of
 * multiplied again: every entry of mlod_rt_palette, and of mlod_rt_skin's
 * entries, must still be W[joint] * bind, bit for bit, at every skeleton
 * level, and some entries must be copies (else this tests nothing). A
 * source pointing at another joint's entry, or at an entry the skin plan
 * did not make, gives other floats. */
TEST(palette_copies_equal_products)
{
	mlod_error e;
	mlod_rt_ctx *ctx = open_all(NULL, &e);
	CHECK(ctx, "open: %s", e.message);
	mlod_rt_scratch *s1 = mlod_rt_scratch_create(ctx), *s2 = mlod_rt_scratch_create(ctx);
	CHECK(s1 && s2, "scratch");
	const uint32_t P = mlod_rt_palette_size(ctx), LS = mlod_rt_level_count(ctx, MLOD_RT_SKELETON),
	               LM = mlod_rt_level_count(ctx, MLOD_RT_MESH);
	uint32_t id, copies = 0;
	CHECK_OK(mlod_rt_instance_create(ctx, 0, 0, MLOD_RT_LOOP, &id, &e), e);
	for (uint32_t ls = 0; ls < LS; ls++)
		for (uint32_t lm = 0; lm < LM; lm++)
			for (int f = 0; f < 7; f++) {
				mlod_rt_select sel;
				mlod_rt_select_default(&sel);
				sel.force_level = 0;
				float d = 1;
				CHECK_OK(mlod_rt_update(ctx, &sel, &id, &d, 1, 0.0713f, &e), e);
				mlod_rt_state *st = &rt_live(ctx, id)->st;
				st->level[MLOD_RT_SKELETON] = (uint16_t)ls, st->level[MLOD_RT_MESH] = (uint16_t)lm;
				const rt_unit *su = ls ? rt_unit_get(ctx, MLOD_RT_SKELETON, ls, 0) : NULL;
				const uint32_t *joint = su ? su->plan.palette_joint : ctx->pal_joint0;
				const uint32_t *src = su ? su->plan.palette_src : ctx->pal_src0;
				const float *W, *Pal;
				uint32_t n;
				float out[3 * 16], nrm[3 * 16], ref[16];
				CHECK_OK(mlod_rt_pose(ctx, s2, id, &W, NULL, NULL, &e), e);
				CHECK_OK(mlod_rt_palette(ctx, s2, &Pal, NULL, &e), e);
				for (uint32_t x = 0; x < P; x++) {
					const float *bind = su ? su->plan.palette_bind + 16 * (size_t)x : ctx->pal_bind0[x];
					rt_mat_mul(W + 16 * (size_t)joint[x], bind, ref);
					CHECK(memcmp(Pal + 16 * (size_t)x, ref, 64) == 0,
					      "skeleton %u frame %d: palette entry %u (copied from %u) is not its product", ls, f, x,
					      src[x]);
					copies += f == 0 && lm == 0 && src[x] != x;
				}
				CHECK_OK(mlod_rt_skin(ctx, s1, id, out, 12, nrm, 12, 16, &n, &e), e);
				const rt_unit *mu = rt_unit_get(ctx, MLOD_RT_MESH, lm, 0);
				for (uint32_t k = 0; k < mu->pal_used_count; k++) {
					const uint32_t x = mu->pal_used[k];
					CHECK(memcmp(s1->palette + 16 * (size_t)x, Pal + 16 * (size_t)x, 64) == 0,
					      "skeleton %u mesh %u frame %d: mlod_rt_skin's entry %u is not its product", ls, lm, f, x);
				}
			}
	CHECK(copies > 0, "no palette entry is a copy: the test checks nothing");
	printf("# %u skeleton levels x %u mesh levels: %u palette entries copied, each its product\n", LS, LM, copies);
	mlod_rt_scratch_destroy(ctx, s1), mlod_rt_scratch_destroy(ctx, s2);
	mlod_rt_close(ctx);
}

/* Views (no INFO): the character's name and the clips' are "", the
 * joints' the skeleton's; the hierarchy at each skeleton level as
 * rt_test.h builds it (level 1 keeps 0, 2, 3: joint 1 removed but posed
 * as 2's ancestor, joint 4 removed and not posed, both following 0, 4 at
 * (1, 1, 0) from it); and mlod_rt_bounds around every vertex mlod_rt_skin
 * writes (the skinned, rigid and static parts) at every pair of skeleton
 * and mesh levels over both clips, and at levels 0 at most 0.25 beyond
 * them on any side (measured 0.239: the vertices weighted to two joints
 * lie inside their joints' boxes' hull, not on its corners; a box of
 * +-FLT_MAX would pass the first check, not this one). */
TEST(views_names_hierarchy_bounds)
{
	mlod_error e;
	mlod_rt_ctx *ctx = NULL;
	CHECK_OK(mlod_rt_open_views(&fx_views, NULL, &ctx, &e), e);
	CHECK(fx_load_all(ctx) == 0, "load");
	mlod_rt_character ch;
	CHECK_OK(mlod_rt_character_get(ctx, &ch, &e), e);
	CHECK(strcmp(ch.name, "") == 0 && ch.diagonal == 0 && ch.bounds_max[0] == 0, "views' character");
	CHECK(mlod_rt_clip_name(ctx, 1) && strcmp(mlod_rt_clip_name(ctx, 1), "") == 0 && !mlod_rt_clip_name(ctx, 2),
	      "views' clip names");
	uint32_t f = 9;
	CHECK_OK(mlod_rt_clip_find(ctx, "", &f, &e), e);
	CHECK(f == 0, "clip \"\" at %u", f);
	CHECK(mlod_rt_clip_find(ctx, "Walk", &f, &e) == MLOD_ERR_INVALID_ARG && strstr(e.message, "no clip named \"Walk\""),
	      "%s", e.message);
	for (uint32_t j = 0; j < FX_J; j++) {
		CHECK(strcmp(mlod_rt_joint_name(ctx, j), fx_joint_names[j]) == 0, "joint %u", j);
		CHECK(mlod_rt_joint_parent(ctx, j) == fx_joints[j].parent, "joint %u's parent", j);
		CHECK_OK(mlod_rt_joint_find(ctx, fx_joint_names[j], &f, &e), e);
		CHECK(f == j, "%s found at %u", fx_joint_names[j], f);
	}
	CHECK(mlod_rt_joint_find(ctx, "RightHand", &f, &e) == MLOD_ERR_INVALID_ARG &&
	          strstr(e.message, "no joint named \"RightHand\""),
	      "%s", e.message);
	static const struct {
		int kept, posed;
		uint32_t stand;
		int32_t parent;
	} want[3][FX_J] = { { { 1, 1, 0, -1 }, { 1, 1, 1, 0 }, { 1, 1, 2, 1 }, { 1, 1, 3, 2 }, { 1, 1, 4, 1 } },
		            { { 1, 1, 0, -1 }, { 0, 1, 0, 0 }, { 1, 1, 2, 0 }, { 1, 1, 3, 2 }, { 0, 0, 0, 0 } },
		            { { 1, 1, 0, -1 }, { 0, 0, 0, 0 }, { 0, 0, 0, 0 }, { 0, 0, 0, 0 }, { 0, 0, 0, 0 } } };
	for (uint32_t l = 0; l < 3; l++)
		for (uint32_t j = 0; j < FX_J; j++) {
			mlod_rt_joint_level jl;
			CHECK_OK(mlod_rt_joint_level_get(ctx, l, j, &jl, &e), e);
			CHECK(jl.kept == want[l][j].kept && jl.posed == want[l][j].posed && jl.stand_in == want[l][j].stand &&
			          jl.parent == want[l][j].parent,
			      "level %u joint %u: kept %d posed %d stand-in %u parent %d", l, j, jl.kept, jl.posed, jl.stand_in,
			      (int)jl.parent);
		}
	mlod_rt_joint_level jl;
	CHECK_OK(mlod_rt_joint_level_get(ctx, 1, 4, &jl, &e), e);
	CHECK(jl.rest_from_stand_in[12] == 1 && jl.rest_from_stand_in[13] == 1 && jl.rest_from_stand_in[14] == 0,
	      "joint 4 from joint 0 at rest: (%g, %g, %g)", jl.rest_from_stand_in[12], jl.rest_from_stand_in[13],
	      jl.rest_from_stand_in[14]);
	mlod_rt_scratch *s = mlod_rt_scratch_create(ctx);
	CHECK(s, "scratch");
	uint32_t id;
	CHECK_OK(mlod_rt_instance_create(ctx, 0, 0, 0, &id, &e), e);
	uint32_t checked = 0;
	double loose = 0;
	for (uint32_t ls = 0; ls < 3; ls++)
		for (uint32_t lm = 0; lm < 3; lm++)
			for (uint32_t clip = 0; clip < 2; clip++)
				for (int k = 0; k <= 20; k++) {
					CHECK_OK(mlod_rt_instance_set(ctx, id, clip, 0.02f * (float)k, 0, &e), e);
					mlod_rt_state *st = &rt_live(ctx, id)->st;
					st->level[MLOD_RT_SKELETON] = (uint16_t)ls, st->level[MLOD_RT_MESH] = (uint16_t)lm;
					st->level[MLOD_RT_MOTION] = 0;
					float out[3 * 16], mn[3], mx[3];
					uint32_t n = 0;
					CHECK_OK(mlod_rt_bounds(ctx, s, id, mn, mx, &e), e);
					CHECK_OK(mlod_rt_skin(ctx, s, id, out, 12, NULL, 12, 16, &n, &e), e);
					CHECK(n > 0, "no vertex");
					float lo[3] = { INFINITY, INFINITY, INFINITY }, hi[3] = { -INFINITY, -INFINITY, -INFINITY };
					for (uint32_t v = 0; v < n; v++)
						for (int a = 0; a < 3; a++) {
							const float x = out[3 * v + a];
							CHECK(x >= mn[a] && x <= mx[a],
							      "skeleton %u mesh %u clip %u t %g: vertex %u axis %d at %g outside [%g, %g]", ls,
							      lm, clip, 0.02 * k, v, a, x, mn[a], mx[a]);
							lo[a] = fminf(lo[a], x), hi[a] = fmaxf(hi[a], x);
						}
					if (ls == 0 && lm == 0)
						for (int a = 0; a < 3; a++)
							loose = fmax(loose, fmax(lo[a] - mn[a], mx[a] - hi[a]));
					checked += n;
				}
	printf("# views: %u skinned vertices inside their box; at level 0 the box reaches %.3g beyond them\n", checked,
	       loose);
	CHECK(loose <= 0.25, "the box at level 0 reaches %g beyond the vertices", loose);
	mlod_rt_scratch_destroy(ctx, s);
	mlod_rt_close(ctx);
}

int main(void)
{
	fx_build(0);
	RUN(sample_hand_values);
	RUN(sample_loop_and_clamp);
	RUN(fixed_joints_and_near_slerp);
	RUN(slerp_batches);
	RUN(fold_matches_full_skeleton);
	RUN(skin_hand_lbs);
	RUN(kernel_matches_scalar);
	RUN(rigid_transform_exact);
	RUN(rigid_unit_normals);
	RUN(no_allocation_per_frame);
	RUN(morph_targets);
	RUN(skin_plan_matches_full_pose);
	RUN(skin_buckets_at_load);
	RUN(palette_copies_equal_products);
	RUN(views_names_hierarchy_bounds);
	TEST_EXIT();
}

