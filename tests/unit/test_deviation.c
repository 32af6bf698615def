/* test_deviation.c: surface deviation against hand results and brute force. */
#include "test.h"
#include "measure/surface.h"

#define PI 3.14159265358979323846

static unsigned rng_state = 777u;
static double rnd(double lo, double hi)
{
	rng_state = rng_state * 1664525u + 1013904223u;
	return lo + (hi - lo) * (double)(rng_state >> 8) / (double)(1u << 24);
}

static mlod_posed alloc_mesh(int vertices, int triangles)
{
	mlod_posed m = { vertices, malloc((size_t)vertices * 3 * sizeof(float)), triangles,
	                 malloc((size_t)triangles * 3 * sizeof(uint32_t)) };
	return m;
}

/* An n x n grid of quads on z = 0 covering [0, size]^2. */
static mlod_posed grid(int n, float size)
{
	mlod_posed m = alloc_mesh((n + 1) * (n + 1), 2 * n * n);
	for (int y = 0; y <= n; y++)
		for (int x = 0; x <= n; x++) {
			float *p = m.positions + 3 * (y * (n + 1) + x);
			p[0] = size * x / n, p[1] = size * y / n, p[2] = 0.0f;
		}
	uint32_t *ix = m.indices;
	for (int y = 0; y < n; y++)
		for (int x = 0; x < n; x++) {
			uint32_t v = (uint32_t)(y * (n + 1) + x), w = (uint32_t)(n + 1);
			*ix++ = v, *ix++ = v + 1, *ix++ = v + w + 1;
			*ix++ = v, *ix++ = v + w + 1, *ix++ = v + w;
		}
	return m;
}

/* A UV sphere of radius r, rings x segments, with each vertex pushed
 * radially by up to noise. */
static mlod_posed sphere(int rings, int segs, double r, double noise)
{
	mlod_posed m = alloc_mesh((rings + 1) * segs, 2 * rings * segs);
	for (int i = 0; i <= rings; i++)
		for (int j = 0; j < segs; j++) {
			double th = PI * i / rings, ph = 2 * PI * j / segs, rr = r + rnd(-noise, noise);
			float *p = m.positions + 3 * (i * segs + j);
			p[0] = (float)(rr * sin(th) * cos(ph)), p[1] = (float)(rr * sin(th) * sin(ph)), p[2] = (float)(rr * cos(th));
		}
	uint32_t *ix = m.indices;
	for (int i = 0; i < rings; i++)
		for (int j = 0; j < segs; j++) {
			uint32_t a = (uint32_t)(i * segs + j), b = (uint32_t)(i * segs + (j + 1) % segs);
			uint32_t c = a + (uint32_t)segs, d = b + (uint32_t)segs;
			*ix++ = a, *ix++ = c, *ix++ = d; /* at the poles some are degenerate */
			*ix++ = a, *ix++ = d, *ix++ = b;
		}
	return m;
}

static mlod_posed copy_translated(const mlod_posed *m, float dx, float dy, float dz)
{
	mlod_posed c = alloc_mesh(m->vertex_count, m->triangle_count);
	memcpy(c.indices, m->indices, (size_t)m->triangle_count * 3 * sizeof(uint32_t));
	for (int v = 0; v < m->vertex_count; v++) {
		c.positions[3 * v] = m->positions[3 * v] + dx;
		c.positions[3 * v + 1] = m->positions[3 * v + 1] + dy;
		c.positions[3 * v + 2] = m->positions[3 * v + 2] + dz;
	}
	return c;
}

/* ---------------------------------------------------------------- */
/* Brute force: an independent point-triangle distance               */
/* ---------------------------------------------------------------- */

typedef struct { double x, y, z; } d3;
static d3 dsub(d3 a, d3 b) { d3 r = { a.x - b.x, a.y - b.y, a.z - b.z }; return r; }
static double ddot(d3 a, d3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static d3 dcross(d3 a, d3 b) { d3 r = { a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x }; return r; }

static double seg_dist(d3 p, d3 a, d3 b)
{
	d3 ab = dsub(b, a);
	double l = ddot(ab, ab), s = l > 0 ? ddot(dsub(p, a), ab) / l : 0;
	s = fmin(1, fmax(0, s));
	d3 q = { a.x + s * ab.x, a.y + s * ab.y, a.z + s * ab.z };
	d3 d = dsub(p, q);
	return sqrt(ddot(d, d));
}

/* Project onto the plane; inside (all edge tests agree) gives the plane
 * distance, outside the nearest edge. */
static double tri_dist(d3 p, d3 a, d3 b, d3 c)
{
	d3 n = dcross(dsub(b, a), dsub(c, a));
	double nn = ddot(n, n);
	double e = fmin(seg_dist(p, a, b), fmin(seg_dist(p, b, c), seg_dist(p, c, a)));
	if (nn <= 1e-20)
		return e;
	double h = ddot(dsub(p, a), n) / nn;
	d3 q = { p.x - h * n.x, p.y - h * n.y, p.z - h * n.z };
	if (ddot(dcross(dsub(b, a), dsub(q, a)), n) >= 0 && ddot(dcross(dsub(c, b), dsub(q, b)), n) >= 0 &&
	    ddot(dcross(dsub(a, c), dsub(q, c)), n) >= 0)
		return fabs(h) * sqrt(nn);
	return e;
}

static d3 vert(const mlod_posed *m, uint32_t v)
{
	d3 r = { m->positions[3 * v], m->positions[3 * v + 1], m->positions[3 * v + 2] };
	return r;
}

static double surface_dist(d3 p, const mlod_posed *m)
{
	double best = INFINITY;
	for (int t = 0; t < m->triangle_count; t++) {
		const uint32_t *ix = m->indices + 3 * t;
		best = fmin(best, tri_dist(p, vert(m, ix[0]), vert(m, ix[1]), vert(m, ix[2])));
	}
	return best;
}

static void brute_side(const mlod_posed *from, const mlod_posed *to, double *sum, double *max, long *n)
{
	char *used = calloc((size_t)from->vertex_count, 1);
	for (int i = 0; i < 3 * from->triangle_count; i++)
		used[from->indices[i]] = 1;
	for (int v = 0; v < from->vertex_count; v++)
		if (used[v]) {
			double d = surface_dist(vert(from, (uint32_t)v), to);
			*sum += d, *max = fmax(*max, d), ++*n;
		}
	for (int t = 0; t < from->triangle_count; t++) {
		d3 a = vert(from, from->indices[3 * t]), b = vert(from, from->indices[3 * t + 1]),
		   c = vert(from, from->indices[3 * t + 2]);
		d3 g = { (a.x + b.x + c.x) / 3, (a.y + b.y + c.y) / 3, (a.z + b.z + c.z) / 3 };
		double d = surface_dist(g, to);
		*sum += d, *max = fmax(*max, d), ++*n;
	}
	free(used);
}

/* Diagonal of the bounding box of the vertices m's triangles use. */
static double diag_of(const mlod_posed *m)
{
	double lo[3] = { INFINITY, INFINITY, INFINITY }, hi[3] = { -INFINITY, -INFINITY, -INFINITY };
	for (int i = 0; i < 3 * m->triangle_count; i++)
		for (int k = 0; k < 3; k++) {
			lo[k] = fmin(lo[k], m->positions[3 * m->indices[i] + k]);
			hi[k] = fmax(hi[k], m->positions[3 * m->indices[i] + k]);
		}
	return sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) + (hi[2] - lo[2]) * (hi[2] - lo[2]));
}

static mlod_deviation brute(const mlod_posed *a, const mlod_posed *b)
{
	double sum = 0, max = 0, diag = diag_of(a);
	long n = 0;
	brute_side(a, b, &sum, &max, &n);
	brute_side(b, a, &sum, &max, &n);
	mlod_deviation d;
	d.mean = 100 * sum / n / diag;
	d.max = 100 * max / diag;
	d.scale = diag;
	return d;
}

/* ---------------------------------------------------------------- */
/* Tests                                                             */
/* ---------------------------------------------------------------- */

TEST(identical_meshes)
{
	mlod_posed s = sphere(12, 16, 1.0, 0.05);
	mlod_deviation d;
	CHECK_OK(mlod_surface_deviation(&s, &s, &d, &terr));
	CHECK_NEAR(d.mean, 0, 1e-6);
	CHECK_NEAR(d.max, 0, 1e-6);
	mlod_posed_free(&s);
}

TEST(plane_offset_along_normal)
{
	/* every sample is exactly 0.3 from the other plane; the diagonal is 2 sqrt 2 */
	mlod_posed a = grid(10, 2.0f), b = copy_translated(&a, 0, 0, 0.3f);
	mlod_deviation d;
	CHECK_OK(mlod_surface_deviation(&a, &b, &d, &terr));
	double want = 100 * 0.3 / sqrt(8.0);
	CHECK_NEAR(d.mean, want, 1e-4);
	CHECK_NEAR(d.max, want, 1e-4);
	CHECK_NEAR(d.scale, sqrt(8.0), 1e-6); /* the percentages are of a's diagonal */
	mlod_posed_free(&a);
	mlod_posed_free(&b);
}

TEST(plane_offset_within_plane)
{
	/* shifted sideways by 0.5: the overlapping samples are at distance 0,
	 * the ones hanging over the edge at their distance to it */
	mlod_posed a = grid(4, 2.0f), b = copy_translated(&a, 0.5f, 0, 0);
	mlod_deviation d, w = brute(&a, &b);
	CHECK_OK(mlod_surface_deviation(&a, &b, &d, &terr));
	CHECK_NEAR(d.max, 100 * 0.5 / sqrt(8.0), 1e-4);
	CHECK_NEAR(d.mean, w.mean, 1e-5);
	mlod_posed_free(&a);
	mlod_posed_free(&b);
}

TEST(translated_sphere_matches_brute_force)
{
	mlod_posed a = sphere(10, 14, 1.0, 0.0), b = copy_translated(&a, 0.1f, -0.05f, 0.2f);
	double t = sqrt(0.1 * 0.1 + 0.05 * 0.05 + 0.2 * 0.2);
	mlod_deviation d, w = brute(&a, &b);
	CHECK_OK(mlod_surface_deviation(&a, &b, &d, &terr));
	CHECK_NEAR(d.mean, w.mean, 1e-4);
	CHECK_NEAR(d.max, w.max, 1e-4);
	/* no sample is farther than the translation; the farthest nearly is */
	double pct = 100.0 * t / diag_of(&a); /* the translation in % */
	CHECK(d.max <= pct + 1e-4);
	CHECK(d.max >= 0.8 * pct);
	CHECK(d.mean > 0.2 * pct);
	mlod_posed_free(&a);
	mlod_posed_free(&b);
}

TEST(random_meshes_match_brute_force)
{
	for (int round = 0; round < 4; round++) {
		/* a noisy sphere against a triangle soup with degenerate triangles */
		mlod_posed a = sphere(8 + round, 12, 1.0, 0.1);
		mlod_posed b = alloc_mesh(300, 400);
		for (int i = 0; i < 3 * b.vertex_count; i++)
			b.positions[i] = (float)rnd(-1.3, 1.3);
		for (int i = 0; i < 3 * b.triangle_count; i++)
			b.indices[i] = (uint32_t)rnd(0, b.vertex_count - 1e-9);
		for (int t = 0; t < 20; t++) {
			uint32_t *ix = b.indices + 3 * t;
			if (t % 2) {
				ix[2] = ix[1]; /* two corners the same */
			} else {        /* three collinear corners */
				float *p0 = b.positions + 3 * ix[0], *p1 = b.positions + 3 * ix[1], *p2 = b.positions + 3 * ix[2];
				for (int k = 0; k < 3; k++)
					p2[k] = p0[k] + 2.0f * (p1[k] - p0[k]);
			}
		}
		b.indices[60] = b.indices[61] = b.indices[62] = 7; /* a point */
		mlod_deviation d, w = brute(&a, &b);
		CHECK_OK(mlod_surface_deviation(&a, &b, &d, &terr));
		CHECK_MSG(fabs(d.mean - w.mean) < 1e-4, "round %d mean %g vs %g", round, d.mean, w.mean);
		CHECK_MSG(fabs(d.max - w.max) < 1e-4, "round %d max %g vs %g", round, d.max, w.max);
		CHECK(d.mean > 0 && d.max >= d.mean);
		/* deterministic, bit for bit */
		mlod_deviation again;
		CHECK_OK(mlod_surface_deviation(&a, &b, &again, &terr));
		CHECK(d.mean == again.mean && d.max == again.max && d.scale == again.scale);
		mlod_posed_free(&a);
		mlod_posed_free(&b);
	}
}

TEST(unused_vertices_do_not_count)
{
	mlod_posed a = grid(3, 1.0f), b = copy_translated(&a, 0, 0, 0);
	mlod_deviation d;
	/* a stray vertex far away that no triangle uses */
	b.positions[3 * 5 + 2] = 100.0f;
	for (int i = 0; i < 3 * b.triangle_count; i++)
		if (b.indices[i] == 5)
			b.indices[i] = 4;
	CHECK_OK(mlod_surface_deviation(&a, &b, &d, &terr));
	CHECK(d.max < 100.0);
	mlod_posed_free(&a);
	mlod_posed_free(&b);
}

TEST(bad_input)
{
	mlod_posed a = grid(2, 1.0f), b = grid(2, 1.0f), empty = { 0 };
	mlod_deviation d;
	mlod_error e;
	CHECK(mlod_surface_deviation(&a, &empty, &d, &e) == MLOD_ERR_INVALID_ARG);
	CHECK(mlod_surface_deviation(&empty, &a, &d, &e) == MLOD_ERR_INVALID_ARG);
	CHECK(mlod_surface_deviation(NULL, &a, &d, &e) == MLOD_ERR_INVALID_ARG);
	CHECK(mlod_surface_deviation(&a, &b, NULL, &e) == MLOD_ERR_INVALID_ARG);
	b.positions[4] = NAN;
	CHECK(mlod_surface_deviation(&a, &b, &d, &e) == MLOD_ERR_PARSE);
	CHECK(strstr(e.message, "vertex 1") != NULL);
	b.positions[4] = 0.0f;
	b.indices[5] = 99;
	CHECK(mlod_surface_deviation(&a, &b, &d, &e) == MLOD_ERR_INVALID_ARG);
	b.indices[5] = 0;
	for (int i = 0; i < 3 * a.vertex_count; i++)
		a.positions[i] = 1.0f; /* all of a at one point: no scale */
	CHECK(mlod_surface_deviation(&a, &b, &d, &e) == MLOD_ERR_INVALID_ARG);
	mlod_posed_free(&a);
	mlod_posed_free(&b);
}

/* mlod_posed_error with a set from mlod_pose_set_make, which keeps the
 * full character posed at each pose with its hierarchy, against the same
 * poses in a set made by hand (nothing kept): the same bits, for the
 * first call, the calls that reuse what it kept, on two threads, and for
 * another full character, which must not get the first one's. */
static mlod_character view_of(const mlod_character *c, mlod_mesh *level)
{
	mlod_character v = *c;
	v.meshes = level;
	v.mesh_count = c->instance_count;
	v.instances = malloc(sizeof *v.instances * (size_t)c->instance_count);
	for (int i = 0; i < c->instance_count; i++) {
		v.instances[i] = c->instances[i];
		v.instances[i].mesh = i;
	}
	return v;
}

static int same_deviation(const mlod_deviation *x, const mlod_deviation *y)
{
	return memcmp(&x->mean, &y->mean, sizeof x->mean) == 0 && memcmp(&x->max, &y->max, sizeof x->max) == 0 &&
	       memcmp(&x->scale, &y->scale, sizeof x->scale) == 0;
}

TEST(posed_error_kept_full)
{
	mlod_character c;
	CHECK(test_load("samples/tubeman.glb", &c) == 0);
	mlod_pose_set poses;
	CHECK_OK(mlod_pose_set_make(&c, 1, 3, 4, 2008, 0.6981317f, &poses, &terr));
	CHECK(poses.cache != NULL);
	mlod_pose_set hand = { poses.count, poses.joint_count, poses.world, 0, NULL };
	mlod_bgm_options opt = {0};
	mlod_bgm *g;
	CHECK_OK(mlod_bgm_build(&c, 0, 0, &opt, &g, &terr));
	mlod_bgm_info info;
	mlod_bgm_get_info(g, &info);
	CHECK_OK(mlod_bgm_simplify(g, info.triangles / 10, 0, &terr));
	mlod_primitive q[2];
	mlod_mesh mesh[2] = { {0}, {0} };
	mlod_character v[2];
	for (int k = 0; k < 2; k++) {
		CHECK_OK(mlod_bgm_extract(g, mlod_bgm_prefix_for(g, info.triangles / (k ? 10 : 2)), 0, &q[k], &terr));
		mesh[k].primitive_count = 1;
		mesh[k].primitives = &q[k];
		v[k] = view_of(&c, &mesh[k]);
	}
	for (int pass = 0; pass < 3; pass++) {
		poses.threads = pass == 2 ? 2 : 1;
		for (int k = 0; k < 2; k++) {
			mlod_deviation kept, fresh;
			CHECK_OK(mlod_posed_error(&c, &v[k], &poses, &kept, &terr));
			CHECK_OK(mlod_posed_error(&c, &v[k], &hand, &fresh, &terr));
			CHECK_MSG(same_deviation(&kept, &fresh), "pass %d level %d: %.17g/%.17g kept, %.17g/%.17g fresh", pass,
			          k, kept.mean, kept.max, fresh.mean, fresh.max);
		}
		/* another full character on the same set: not the kept one */
		mlod_deviation kept, fresh;
		CHECK_OK(mlod_posed_error(&v[0], &v[1], &poses, &kept, &terr));
		CHECK_OK(mlod_posed_error(&v[0], &v[1], &hand, &fresh, &terr));
		CHECK(same_deviation(&kept, &fresh));
		CHECK(!same_deviation(&kept, &(mlod_deviation){0}) && kept.mean > 0.0);
	}
	for (int k = 0; k < 2; k++) {
		mlod_primitive_free(&q[k]);
		free(v[k].instances);
	}
	mlod_bgm_free(g);
	mlod_pose_set_free(&poses);
	CHECK(poses.cache == NULL);
	mlod_character_free(&c);
}

/* mlod_pose_set_bound_mean (mlod-bgm's levels): at every pose after the
 * first, only the samples that may raise the max are searched: against
 * the exact measure on the same set, the max has the same bits and the
 * mean is no less; the result is the same on two threads, and a set made
 * by hand (nothing kept) is measured exactly. */
TEST(posed_error_bound_mean)
{
	mlod_character c;
	CHECK(test_load("samples/tubeman.glb", &c) == 0);
	mlod_pose_set poses;
	CHECK_OK(mlod_pose_set_make(&c, 1, 4, 8, 2008, 0.6981317f, &poses, &terr));
	mlod_pose_set hand = { poses.count, poses.joint_count, poses.world, 0, NULL };
	mlod_bgm_options opt = {0};
	mlod_bgm *g;
	CHECK_OK(mlod_bgm_build(&c, 0, 0, &opt, &g, &terr));
	mlod_bgm_info info;
	mlod_bgm_get_info(g, &info);
	CHECK_OK(mlod_bgm_simplify(g, info.triangles / 30, 0, &terr));
	const int keep[3] = { 2, 10, 30 };
	double moved = 0.0;
	for (int k = 0; k < 3; k++) {
		mlod_primitive q;
		mlod_mesh mesh = {0};
		CHECK_OK(mlod_bgm_extract(g, mlod_bgm_prefix_for(g, info.triangles / keep[k]), 0, &q, &terr));
		mesh.primitive_count = 1;
		mesh.primitives = &q;
		mlod_character v = view_of(&c, &mesh);
		mlod_deviation exact, bounded, two, by_hand;
		mlod_pose_set_bound_mean(&poses, 0);
		poses.threads = 1;
		CHECK_OK(mlod_posed_error(&c, &v, &poses, &exact, &terr));
		mlod_pose_set_bound_mean(&poses, 1);
		CHECK_OK(mlod_posed_error(&c, &v, &poses, &bounded, &terr));
		poses.threads = 2;
		CHECK_OK(mlod_posed_error(&c, &v, &poses, &two, &terr));
		mlod_pose_set_bound_mean(&hand, 1); /* nothing to set: measured exactly */
		CHECK_OK(mlod_posed_error(&c, &v, &hand, &by_hand, &terr));
		CHECK_MSG(bounded.max == exact.max && bounded.mean >= exact.mean,
		          "1/%d of the triangles: bounded %.17g/%.17g, exact %.17g/%.17g", keep[k], bounded.mean,
		          bounded.max, exact.mean, exact.max);
		CHECK(same_deviation(&bounded, &two));
		CHECK(same_deviation(&by_hand, &exact));
		moved = fmax(moved, bounded.mean / exact.mean);
		mlod_primitive_free(&q);
		free(v.instances);
	}
	CHECK(moved > 1.0 && moved < 1.5); /* the bound is not the exact mean here, nor far from it */
	mlod_bgm_free(g);
	mlod_pose_set_free(&poses);
	mlod_character_free(&c);
}

/* mlod_posed_errors (mlod-bgm's levels, measured together over levels and
 * poses) after mlod_pose_set_keep (the full character kept posed, here in
 * reverse pose order, so that pose 0 comes last): the bits of one
 * mlod_posed_error per level on a set where nothing was kept, bounded
 * mean on, at one and two threads, and again after mlod_pose_set_forget;
 * another full character on the kept set gets its own measure, not the
 * kept one's. */
TEST(posed_errors_batch_kept)
{
	mlod_character c;
	CHECK(test_load("samples/tubeman.glb", &c) == 0);
	mlod_pose_set kept, fresh;
	CHECK_OK(mlod_pose_set_make(&c, 1, 4, 8, 2008, 0.6981317f, &kept, &terr));
	mlod_pose_set_bound_mean(&kept, 1);
	mlod_bgm_options opt = {0};
	mlod_bgm *g;
	CHECK_OK(mlod_bgm_build(&c, 0, 0, &opt, &g, &terr));
	mlod_bgm_info info;
	mlod_bgm_get_info(g, &info);
	CHECK_OK(mlod_bgm_simplify(g, info.triangles / 30, 0, &terr));
	const int part[3] = { 2, 10, 30 };
	mlod_primitive q[3];
	mlod_mesh mesh[3] = { {0}, {0}, {0} };
	mlod_character v[3];
	const mlod_character *views[3];
	mlod_deviation one[3];
	for (int k = 0; k < 3; k++) {
		CHECK_OK(mlod_bgm_extract(g, mlod_bgm_prefix_for(g, info.triangles / part[k]), 0, &q[k], &terr));
		mesh[k].primitive_count = 1;
		mesh[k].primitives = &q[k];
		v[k] = view_of(&c, &mesh[k]);
		views[k] = &v[k];
		/* the reference: a set of its own each, nothing kept before */
		CHECK_OK(mlod_pose_set_make(&c, 1, 4, 8, 2008, 0.6981317f, &fresh, &terr));
		mlod_pose_set_bound_mean(&fresh, 1);
		CHECK_OK(mlod_posed_error(&c, &v[k], &fresh, &one[k], &terr));
		mlod_pose_set_free(&fresh);
	}
	for (int k = kept.count - 1; k >= 0; k--)
		CHECK_OK(mlod_pose_set_keep(&kept, &c, k, &terr));
	CHECK(mlod_pose_set_keep(&kept, &c, kept.count, &terr) == MLOD_ERR_INVALID_ARG);
	for (int threads = 1; threads <= 2; threads++) {
		mlod_deviation all[3];
		kept.threads = threads;
		CHECK_OK(mlod_posed_errors(&c, views, 3, &kept, all, &terr));
		for (int k = 0; k < 3; k++)
			CHECK_MSG(same_deviation(&all[k], &one[k]), "%d threads, level %d: %.17g/%.17g, alone %.17g/%.17g",
			          threads, k, all[k].mean, all[k].max, one[k].mean, one[k].max);
		CHECK(one[0].max < one[1].max && one[1].max < one[2].max);
	}
	/* forgotten (mlod_pose_set_forget, as mlod_mesh_levels does once its
	 * levels are measured): posed and kept again by the next call, the
	 * later poses sharing pose 0's triangles, with the same bits */
	for (int threads = 1; threads <= 2; threads++) {
		mlod_deviation all[3];
		mlod_pose_set_forget(&kept);
		kept.threads = threads;
		CHECK_OK(mlod_posed_errors(&c, views, 3, &kept, all, &terr));
		CHECK_OK(mlod_posed_errors(&c, views, 3, &kept, all, &terr)); /* and from what that call kept */
		for (int k = 0; k < 3; k++)
			CHECK_MSG(same_deviation(&all[k], &one[k]), "forgotten, %d threads, level %d: %.17g/%.17g, alone %.17g/%.17g",
			          threads, k, all[k].mean, all[k].max, one[k].mean, one[k].max);
	}
	mlod_pose_set_forget(&kept);
	for (int k = kept.count - 1; k >= 0; k--)
		CHECK_OK(mlod_pose_set_keep(&kept, &c, k, &terr));
	/* another full character: the poses are kept for c, so it is measured
	 * on its own, posed at each pose and exactly, as on a set made by hand */
	mlod_deviation other, alone;
	mlod_pose_set hand = { kept.count, kept.joint_count, kept.world, 1, NULL };
	CHECK_OK(mlod_pose_set_keep(&kept, &v[0], 0, &terr));
	CHECK_OK(mlod_posed_error(&v[0], &v[2], &kept, &other, &terr));
	CHECK_OK(mlod_posed_error(&v[0], &v[2], &hand, &alone, &terr));
	CHECK(same_deviation(&other, &alone) && other.max > 0.0);
	views[1] = NULL;
	CHECK(mlod_posed_errors(&c, views, 3, &kept, &other, &terr) == MLOD_ERR_INVALID_ARG);
	CHECK_OK(mlod_posed_errors(&c, views, 0, &kept, NULL, &terr));
	for (int k = 0; k < 3; k++) {
		mlod_primitive_free(&q[k]);
		free(v[k].instances);
	}
	mlod_bgm_free(g);
	mlod_pose_set_free(&kept);
	mlod_character_free(&c);
}

/* Warm starts (surface.h) change only where each search begins: recorded
 * at one placement and used at another, or filled with nonsense, or made
 * for meshes of other sizes, the result has the same bits as without. */
TEST(warm_starts_same_bits)
{
	mlod_posed a = sphere(14, 20, 1.0, 0.08), b = sphere(9, 13, 1.0, 0.15);
	mlod_surface *s;
	CHECK_OK(mlod_surface_make(&a, &s, &terr));
	int na = a.vertex_count + a.triangle_count, nb = b.vertex_count + b.triangle_count;
	int *wa = malloc(sizeof *wa * (size_t)na), *wb = malloc(sizeof *wb * (size_t)nb);
	for (int i = 0; i < na; i++)
		wa[i] = -7;
	for (int i = 0; i < nb; i++)
		wb[i] = -7;
	mlod_warm rec = { wa, wb, na, nb, 1, 0, 0.0, NULL };
	mlod_deviation cold, d;
	CHECK_OK(mlod_surface_deviation(&a, &b, &cold, &terr));
	CHECK_OK(mlod_surface_deviation_to(s, &b, &rec, &d, &terr));
	CHECK(same_deviation(&cold, &d));
	int in_range = 1;
	for (int i = 0; i < na; i++)
		in_range &= wa[i] >= 0 && wa[i] < b.triangle_count;
	for (int i = 0; i < nb; i++)
		in_range &= wb[i] >= 0 && wb[i] < a.triangle_count;
	CHECK(in_range); /* every sample got its nearest triangle */
	/* b moved and bent a little: the recorded triangles are near, not all nearest */
	mlod_posed b2 = copy_translated(&b, 0.03f, -0.02f, 0.05f);
	for (int i = 0; i < 3 * b2.vertex_count; i++)
		b2.positions[i] += (float)rnd(-0.02, 0.02);
	mlod_warm use = { wa, wb, na, nb, 0, 0, 0.0, NULL };
	CHECK_OK(mlod_surface_deviation(&a, &b2, &cold, &terr));
	CHECK_OK(mlod_surface_deviation_to(s, &b2, &use, &d, &terr));
	CHECK(same_deviation(&cold, &d));
	CHECK_OK(mlod_surface_deviation_to(s, &b2, NULL, &d, &terr));
	CHECK(same_deviation(&cold, &d));
	/* bounded (searching only what may raise the max), with no floor: the
	 * same max, a mean no less, and here more (some recorded triangles are
	 * no longer the nearest) */
	mlod_warm bounded = { wa, wb, na, nb, 0, 1, 0.0, NULL };
	CHECK_OK(mlod_surface_deviation_to(s, &b2, &bounded, &d, &terr));
	CHECK_MSG(d.max == cold.max && d.mean > cold.mean, "bounded %.17g/%.17g, exact %.17g/%.17g", d.mean, d.max,
	          cold.mean, cold.max);
	/* a floor above every distance: nothing searched, every sample counted
	 * with its recorded triangle, the max then at least the exact one */
	bounded.floor = 10.0;
	CHECK_OK(mlod_surface_deviation_to(s, &b2, &bounded, &d, &terr));
	CHECK(d.max >= cold.max && d.mean > cold.mean);
	/* nonsense: out of range, negative, far triangles */
	for (int i = 0; i < na; i++)
		wa[i] = i % 3 == 0 ? -1 - i : i % 3 == 1 ? b.triangle_count + i : (int)rnd(0, b.triangle_count - 1e-9);
	for (int i = 0; i < nb; i++)
		wb[i] = i % 2 ? a.triangle_count - 1 - i % a.triangle_count : 1 << 30;
	CHECK_OK(mlod_surface_deviation_to(s, &b2, &use, &d, &terr));
	CHECK(same_deviation(&cold, &d));
	/* bounded with nonsense: each sample without a recorded triangle is
	 * searched, a far one gives a bound that is searched when above the
	 * max so far: the max the same bits */
	mlod_warm nonsense = { wa, wb, na, nb, 0, 1, 0.0, NULL };
	CHECK_OK(mlod_surface_deviation_to(s, &b2, &nonsense, &d, &terr));
	CHECK(d.max == cold.max && d.mean >= cold.mean);
	/* made for meshes of other sizes */
	mlod_warm other = { wa, wb, na - 1, nb, 0, 0, 0.0, NULL };
	CHECK_OK(mlod_surface_deviation_to(s, &b2, &other, &d, &terr));
	CHECK(same_deviation(&cold, &d));
	mlod_warm_release(&rec); /* the tree the recording kept for the other poses */
	free(wa);
	free(wb);
	mlod_surface_free(s);
	mlod_posed_free(&a);
	mlod_posed_free(&b);
	mlod_posed_free(&b2);
}

/* The bounded measure (its triangles read from the mesh, their
 * degenerate flags made once per mesh, not per sample) with degenerate
 * triangles on both sides, and a non-finite vertex no triangle uses (the
 * input check's quick path): recorded at the same positions and with a
 * floor above every distance, nothing is searched and every sample
 * counts with its recorded triangle, its nearest: the same bits as the
 * exact measure. (A sample measured against a wrong triangle fails it.) */
TEST(bounded_degenerate_same_bits)
{
	mlod_posed g = grid(6, 1.0f), h = grid(3, 1.0f);
	mlod_posed a = alloc_mesh(g.vertex_count + 1, g.triangle_count), b = copy_translated(&h, 0.01f, 0.02f, 0.05f);
	memcpy(a.positions, g.positions, 3 * sizeof(float) * (size_t)g.vertex_count);
	memcpy(a.indices, g.indices, 3 * sizeof(uint32_t) * (size_t)g.triangle_count);
	a.positions[3 * g.vertex_count] = NAN; /* the extra vertex: no triangle uses it */
	a.positions[3 * g.vertex_count + 1] = a.positions[3 * g.vertex_count + 2] = 0.0f;
	for (int t = 0; t < a.triangle_count; t += 5)
		a.indices[3 * t + 2] = a.indices[3 * t + 1]; /* a segment */
	for (int t = 0; t < b.triangle_count; t += 3)
		b.indices[3 * t + 2] = b.indices[3 * t];
	mlod_surface *s;
	CHECK_OK(mlod_surface_make(&a, &s, &terr));
	int na = a.vertex_count + a.triangle_count, nb = b.vertex_count + b.triangle_count;
	int *wa = malloc(sizeof *wa * (size_t)na), *wb = malloc(sizeof *wb * (size_t)nb);
	mlod_warm rec = { wa, wb, na, nb, 1, 0, 0.0, NULL };
	mlod_deviation cold, d;
	CHECK_OK(mlod_surface_deviation(&a, &b, &cold, &terr));
	CHECK_OK(mlod_surface_deviation_to(s, &b, &rec, &d, &terr));
	CHECK(same_deviation(&cold, &d));
	int on_degenerate = 0;
	for (int i = 0; i < na; i++)
		on_degenerate += wa[i] >= 0 && wa[i] % 3 == 0; /* b's degenerate ones */
	for (int i = 0; i < nb; i++)
		on_degenerate += wb[i] >= 0 && wb[i] % 5 == 0; /* a's */
	CHECK_MSG(on_degenerate > 0, "no sample's nearest triangle is degenerate");
	mlod_warm bounded = { wa, wb, na, nb, 0, 1, 10.0, NULL };
	CHECK_OK(mlod_surface_deviation_to(s, &b, &bounded, &d, &terr));
	CHECK_MSG(same_deviation(&cold, &d), "bounded %.17g/%.17g, exact %.17g/%.17g", d.mean, d.max, cold.mean,
	          cold.max);
	a.indices[0] = (uint32_t)g.vertex_count; /* now a triangle uses it */
	CHECK(mlod_surface_deviation(&a, &b, &d, &terr) == MLOD_ERR_PARSE);
	CHECK(strstr(terr.message, "not finite") != NULL);
	mlod_warm_release(&rec);
	free(wa);
	free(wb);
	mlod_surface_free(s);
	mlod_posed_free(&a);
	mlod_posed_free(&b);
	mlod_posed_free(&g);
	mlod_posed_free(&h);
}

int main(void)
{
	RUN(identical_meshes);
	RUN(plane_offset_along_normal);
	RUN(plane_offset_within_plane);
	RUN(translated_sphere_matches_brute_force);
	RUN(random_meshes_match_brute_force);
	RUN(unused_vertices_do_not_count);
	RUN(bad_input);
	RUN(posed_error_kept_full);
	RUN(posed_error_bound_mean);
	RUN(posed_errors_batch_kept);
	RUN(warm_starts_same_bits);
	RUN(bounded_degenerate_same_bits);
	TEST_EXIT();
}
