/*
 * test_rt_select.c: level selection along scripted camera paths: the
 * paper's alpha with per-layer intervals, the projected-pixel rule, the
 * TOC's distances, hysteresis (no switch back and forth inside the band)
 * and the batch update from positions.
 */
#include "rt_test.h"

static mlod_rt_ctx *open_fx(mlod_error *e)
{
	mlod_rt_ctx *ctx = NULL;
	mlod_rt_open_views(&fx_views, NULL, &ctx, e);
	return ctx;
}

/* The paper's rule as the header states it, computed here independently. */
static uint32_t alpha_rule(float d, float dn, float df, float ts, float te, uint32_t L)
{
	double a = (d - dn) / (df - dn);
	a = a < 0 ? 0 : a > 1 ? 1 : a;
	double u = te > ts ? (a - ts) / (te - ts) : (a < ts ? 0 : 1);
	u = u < 0 ? 0 : u > 1 ? 1 : u;
	double l = floor(u * (L - 1) + 0.5);
	return (uint32_t)(l > L - 1 ? L - 1 : l);
}

TEST(alpha_intervals)
{
	mlod_error e;
	mlod_rt_ctx *ctx = open_fx(&e);
	CHECK(ctx, "open: %s", e.message);
	mlod_rt_select sel;
	mlod_rt_select_default(&sel); /* d_near 2, d_far 200 */
	sel.hysteresis = 0;
	sel.t_start[MLOD_RT_MESH] = 0.2f, sel.t_end[MLOD_RT_MESH] = 0.8f;
	sel.t_start[MLOD_RT_MOTION] = sel.t_end[MLOD_RT_MOTION] = 0.5f;
	/* hand-computed: alpha = (d - 2) / 198; mesh u = (alpha - 0.2) / 0.6; level = round(2u) */
	static const struct { float d; uint32_t skel, mesh, motion; } pts[] = {
		{ 0, 0, 0, 0 },          { 2, 0, 0, 0 },           { 49.52f, 0, 0, 0 },  /* alpha 0.24 */
		{ 53.48f, 1, 0, 0 },     /* alpha 0.26: skeleton round(0.52) = 1 */
		{ 69.32f, 1, 0, 0 },     /* mesh u 0.2333: round(0.467) = 0 */
		{ 73.28f, 1, 1, 0 },     /* mesh u 0.2667: 1 */
		{ 101, 1, 1, 2 },        /* alpha 0.5: motion steps to its coarsest */
		{ 128.72f, 1, 1, 2 },    /* mesh u 0.7333: round(1.467) = 1 */
		{ 131.5f, 1, 2, 2 },     /* mesh u 0.7567: round(1.513) = 2 */
		{ 150.5f, 2, 2, 2 },     /* alpha 0.75: skeleton round(1.5) = 2 */
		{ 250, 2, 2, 2 },
	};
	for (size_t i = 0; i < sizeof pts / sizeof pts[0]; i++) {
		uint32_t s = mlod_rt_select_level(ctx, &sel, MLOD_RT_SKELETON, 0, pts[i].d, -1);
		uint32_t m = mlod_rt_select_level(ctx, &sel, MLOD_RT_MESH, 0, pts[i].d, -1);
		uint32_t a = mlod_rt_select_level(ctx, &sel, MLOD_RT_MOTION, 1, pts[i].d, -1);
		CHECK(s == pts[i].skel && m == pts[i].mesh && a == pts[i].motion,
		      "d %g: levels %u %u %u, expected %u %u %u", pts[i].d, s, m, a, pts[i].skel, pts[i].mesh,
		      pts[i].motion);
	}
	/* A scripted camera path, out and back, against the rule. */
	for (int k = 0; k <= 2000; k++) {
		float d = k <= 1000 ? 0.25f * (float)k : 0.25f * (float)(2000 - k);
		uint32_t m = mlod_rt_select_level(ctx, &sel, MLOD_RT_MESH, 0, d, -1);
		uint32_t x = alpha_rule(d, 2, 200, 0.2f, 0.8f, 3);
		CHECK(m == x, "d %g: mesh level %u, the rule says %u", d, m, x);
	}
	mlod_rt_close(ctx);
}

TEST(pixel_rule)
{
	mlod_error e;
	mlod_rt_ctx *ctx = open_fx(&e);
	CHECK(ctx, "open: %s", e.message);
	mlod_rt_select sel;
	mlod_rt_select_default(&sel);
	sel.mode = MLOD_RT_SELECT_PIXELS;
	sel.hysteresis = 0;
	/* mesh errors 0.01, 0.05 at 60 degrees, 1080 lines, 1 pixel: D1 = 9.353, D2 = 46.77 */
	static const struct { float d; uint32_t mesh; } pts[] = { { 9.3f, 0 }, { 9.4f, 1 }, { 46.7f, 1 }, { 46.8f, 2 } };
	for (size_t i = 0; i < 4; i++) {
		uint32_t m = mlod_rt_select_level(ctx, &sel, MLOD_RT_MESH, 0, pts[i].d, -1);
		CHECK(m == pts[i].mesh, "d %g: mesh level %u, expected %u", pts[i].d, m, pts[i].mesh);
	}
	/* Sweep against the rule: the coarsest level whose error projects to <= max pixels. */
	static const float errs[3][3] = { { 0, 0.02f, 0.1f }, { 0, 0.01f, 0.05f }, { 0, 0.005f, 0.03f } };
	const float setups[3][3] = { { 1.0472f, 1080, 1 }, { 0.7f, 2160, 1 }, { 1.0472f, 1080, 3 } };
	for (int s = 0; s < 3; s++) {
		sel.fov_y = setups[s][0], sel.lines = setups[s][1], sel.max_pixels = setups[s][2];
		for (int k = 1; k < 3000; k++) {
			float d = 0.1f * (float)k;
			for (int layer = 0; layer < 3; layer++) {
				uint32_t want = 0;
				for (uint32_t l = 0; l < 3; l++)
					if (errs[layer][l] * sel.lines / (2 * d * tan(sel.fov_y / 2)) <= sel.max_pixels)
						want = l;
				uint32_t got = mlod_rt_select_level(ctx, &sel, (mlod_rt_layer)layer, 0, d, -1);
				/* within float rounding of a threshold either answer is right */
				int edge = 0;
				for (uint32_t l = 1; l < 3; l++) {
					double D = errs[layer][l] * sel.lines / (2 * tan(sel.fov_y / 2) * sel.max_pixels);
					edge |= fabs(D - d) < 1e-4 * D;
				}
				CHECK(got == want || edge, "setup %d layer %d d %g: level %u, the rule says %u", s, layer, d, got,
				      want);
			}
		}
	}
	/* TOC mode uses the pack's switch distances (here the default pixel rule's). */
	sel.mode = MLOD_RT_SELECT_TOC;
	CHECK(mlod_rt_select_level(ctx, &sel, MLOD_RT_MESH, 0, 9.3f, -1) == 0 &&
	          mlod_rt_select_level(ctx, &sel, MLOD_RT_MESH, 0, 9.4f, -1) == 1 &&
	          mlod_rt_select_level(ctx, &sel, MLOD_RT_MESH, 0, 46.8f, -1) == 2,
	      "TOC mode does not follow the TOC's distances");
	mlod_rt_close(ctx);
}

TEST(hysteresis_no_flicker)
{
	mlod_error e;
	mlod_rt_ctx *ctx = open_fx(&e);
	CHECK(ctx, "open: %s", e.message);
	mlod_rt_select sel;
	mlod_rt_select_default(&sel);
	sel.mode = MLOD_RT_SELECT_PIXELS;
	sel.hysteresis = 0.1f;
	const double D1 = 0.01 * 1080 / (2 * tan(30 * M_PI / 180)); /* 9.353 */
	uint32_t id;
	CHECK_OK(mlod_rt_instance_create(ctx, 0, 0, MLOD_RT_LOOP, &id, &e), e);
	/* finer at the threshold, coarser only past D1 * 1.1 */
	static const struct { double f; uint32_t mesh; } path[] = {
		{ 0.5, 0 }, { 1.02, 0 }, { 1.09, 0 }, { 1.11, 1 }, { 1.05, 1 }, { 1.001, 1 }, { 0.99, 0 }, { 1.05, 0 },
	};
	for (size_t i = 0; i < sizeof path / sizeof path[0]; i++) {
		float d = (float)(path[i].f * D1);
		CHECK_OK(mlod_rt_update(ctx, &sel, &id, &d, 1, 0.01f, &e), e);
		const mlod_rt_state *st = mlod_rt_instance_state(ctx, id);
		CHECK(st->wanted[MLOD_RT_MESH] == path[i].mesh, "step %zu (d = %.3f D1): wanted %u, expected %u", i,
		      path[i].f, st->wanted[MLOD_RT_MESH], path[i].mesh);
	}
	/* A character oscillating inside the band never switches, from either side. */
	for (int from = 0; from < 2; from++) {
		float d = (float)(from ? 1.2 * D1 : 0.8 * D1);
		CHECK_OK(mlod_rt_update(ctx, &sel, &id, &d, 1, 0.01f, &e), e);
		uint32_t start = mlod_rt_instance_state(ctx, id)->wanted[MLOD_RT_MESH];
		CHECK(start == (uint32_t)from, "start level %u", start);
		int switches = 0;
		uint32_t last = start;
		for (int f = 0; f < 1000; f++) {
			d = (float)(D1 * (1.05 + 0.045 * sin(0.37 * f)));
			CHECK_OK(mlod_rt_update(ctx, &sel, &id, &d, 1, 0.01f, &e), e);
			uint32_t now = mlod_rt_instance_state(ctx, id)->wanted[MLOD_RT_MESH];
			switches += now != last;
			last = now;
		}
		CHECK(switches == 0, "%d switches inside the band (from %s)", switches, from ? "outside" : "inside");
	}
	/* The same rule in alpha mode: thresholds of the rounded alpha. */
	sel.mode = MLOD_RT_SELECT_ALPHA;
	sel.d_near = 0, sel.d_far = 100;
	/* skeleton level 1 from alpha 0.25 (d 25), coarser only past 27.5 */
	static const struct { float d; uint32_t skel; } ap[] = { { 10, 0 }, { 26, 0 }, { 27.6f, 1 }, { 25.5f, 1 },
	                                                        { 24.9f, 0 } };
	for (size_t i = 0; i < 5; i++) {
		float d = ap[i].d;
		CHECK_OK(mlod_rt_update(ctx, &sel, &id, &d, 1, 0.01f, &e), e);
		CHECK(mlod_rt_instance_state(ctx, id)->wanted[MLOD_RT_SKELETON] == ap[i].skel, "alpha step %zu: %u", i,
		      mlod_rt_instance_state(ctx, id)->wanted[MLOD_RT_SKELETON]);
	}
	mlod_rt_close(ctx);
}

TEST(update_from_positions)
{
	mlod_error e;
	mlod_rt_ctx *ctx = open_fx(&e);
	CHECK(ctx, "open: %s", e.message);
	mlod_rt_select sel;
	mlod_rt_select_default(&sel);
	uint32_t ids[20];
	float pos[60], d[20];
	const float cam[3] = { 1, 2, 3 };
	for (int i = 0; i < 20; i++) {
		CHECK_OK(mlod_rt_instance_create(ctx, (uint32_t)i % 2, 0, 0, &ids[i], &e), e);
		pos[3 * i] = 1 + 10.0f * (float)i, pos[3 * i + 1] = 2, pos[3 * i + 2] = 3;
		d[i] = 10.0f * (float)i;
	}
	CHECK_OK(mlod_rt_update_positions(ctx, &sel, cam, ids, pos, 20, 0, &e), e);
	mlod_rt_state a[20];
	for (int i = 0; i < 20; i++)
		a[i] = *mlod_rt_instance_state(ctx, ids[i]);
	CHECK_OK(mlod_rt_update(ctx, &sel, ids, d, 20, 0, &e), e);
	for (int i = 0; i < 20; i++) {
		const mlod_rt_state *b = mlod_rt_instance_state(ctx, ids[i]);
		CHECK(memcmp(a[i].wanted, b->wanted, sizeof a[i].wanted) == 0 && NEAR(a[i].distance, b->distance, 1e-4),
		      "instance %d differs", i);
	}
	/* Level counts, errors. */
	CHECK(mlod_rt_level_count(ctx, MLOD_RT_MESH) == 3 && mlod_rt_clip_count(ctx) == 2, "counts");
	mlod_rt_level_info li;
	CHECK_OK(mlod_rt_level_info_get(ctx, MLOD_RT_MOTION, 2, 1, &li, &e), e);
	CHECK(NEAR(li.error, 0.03, 1e-7) && li.resident, "motion level 2 of clip 1: error %g resident %d", li.error,
	      li.resident);
	mlod_rt_close(ctx);
}

/* A selection the header does not allow (a mode out of range, a float
 * member not finite, a negative hysteresis) is MLOD_ERR_INVALID_ARG
 * naming the member, from both update calls, and changes nothing: the
 * instance keeps its time and wanted levels. */
TEST(update_bad_selection)
{
	mlod_error e;
	mlod_rt_ctx *ctx = open_fx(&e);
	CHECK(ctx, "open: %s", e.message);
	uint32_t id;
	CHECK_OK(mlod_rt_instance_create(ctx, 0, 0, 0, &id, &e), e);
	mlod_rt_select good;
	mlod_rt_select_default(&good);
	const float d = 120.0f, cam[3] = { 0, 0, 0 }, pos[3] = { 120.0f, 0, 0 };
	CHECK_OK(mlod_rt_update(ctx, &good, &id, &d, 1, 0.5f, &e), e);
	const mlod_rt_state before = *mlod_rt_instance_state(ctx, id);
	struct { const char *what; mlod_rt_select sel; } bad[12];
	for (int k = 0; k < 12; k++)
		bad[k].sel = good;
	bad[0].what = "mode 9", bad[0].sel.mode = (mlod_rt_select_mode)9;
	bad[1].what = "d_near nan", bad[1].sel.d_near = NAN;
	bad[2].what = "hysteresis -1 is negative", bad[2].sel.hysteresis = -1.0f;
	bad[3].what = "d_far inf", bad[3].sel.d_far = INFINITY;
	bad[4].what = "layer 2", bad[4].sel.t_end[2] = NAN;
	bad[5].what = "distance_scale nan", bad[5].sel.distance_scale = NAN;
	/* in range: each of these put every layer at level 0 at any distance
	 * (fov_y, lines, max_pixels) or turned the ramp into a step */
	bad[6].what = "fov_y 0 is not between 0 and pi", bad[6].sel.fov_y = 0.0f;
	bad[7].what = "fov_y 4 is not between 0 and pi", bad[7].sel.fov_y = 4.0f;
	bad[8].what = "lines -1080, max_pixels 1: both must be > 0", bad[8].sel.lines = -1080.0f;
	bad[9].what = "lines 1080, max_pixels 0: both must be > 0", bad[9].sel.max_pixels = 0.0f;
	bad[10].what = "d_near 300, d_far 200: need 0 <= d_near <= d_far", bad[10].sel.d_near = 300.0f;
	bad[11].what = "distance_scale -2 is negative", bad[11].sel.distance_scale = -2.0f;
	for (int k = 0; k < 12; k++) {
		CHECK(mlod_rt_update(ctx, &bad[k].sel, &id, &d, 1, 0.5f, &e) == MLOD_ERR_INVALID_ARG &&
		      strstr(e.message, bad[k].what) && strstr(e.message, "mlod_rt_update:"),
		      "update, %s: %s", bad[k].what, e.message);
		CHECK(mlod_rt_update_positions(ctx, &bad[k].sel, cam, &id, pos, 1, 0.5f, &e) == MLOD_ERR_INVALID_ARG &&
		      strstr(e.message, bad[k].what) && strstr(e.message, "mlod_rt_update_positions:"),
		      "update_positions, %s: %s", bad[k].what, e.message);
	}
	const mlod_rt_state *after = mlod_rt_instance_state(ctx, id);
	CHECK(after->time == before.time && memcmp(after->wanted, before.wanted, sizeof before.wanted) == 0,
	      "a refused update changed the instance");
	mlod_rt_close(ctx);
}

int main(void)
{
	fx_build(0);
	RUN(alpha_intervals);
	RUN(pixel_rule);
	RUN(hysteresis_no_flicker);
	RUN(update_from_positions);
	RUN(update_bad_selection);
	TEST_EXIT();
}
