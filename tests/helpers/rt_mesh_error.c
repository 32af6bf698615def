/*
 * rt_mesh_error.c: measures a pack's mesh levels through the runtime
 * alone, against the errors its TOC states (issue 11).
 *
 *   rt_mesh_error [-n TIMES] [-r RATIO] pack.mlod
 *
 * For each mesh level k >= 1, at TIMES evenly spaced times of each clip
 * (default 61, the first at 0 and the last at the clip's duration; the
 * rest pose without clips), an instance at skeleton and motion level 0
 * showing mesh level 0 and one showing mesh level k are skinned by
 * mlod_rt_skin, and the two surfaces are compared both ways: every vertex
 * and triangle centroid of each to the nearest point of the other's
 * triangles (as mlod_surface_deviation samples them, but with none of the
 * bake library's code). Prints one line per level,
 *
 *   mesh level 2: stated 0.174 measured 0.112869 (clip 0 at 1.98333)
 *
 * and exits 1 when a level measures more than RATIO (default 1) times
 * its stated error, 2 when the pack cannot be read or skinned.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rt/mlod_rt.h"

static void die(const char *what, const mlod_error *e)
{
	fprintf(stderr, "rt_mesh_error: %s%s%s\n", what, e ? ": " : "", e ? e->message : "");
	exit(2);
}

/* ------------------------------------------------------------------ */
/* Nearest point on a triangle soup: a uniform grid of triangle lists  */
/* ------------------------------------------------------------------ */

typedef struct soup {
	const double *p;      /* 3 per vertex */
	const uint32_t *tri;  /* 3 per triangle */
	size_t nt;
	double lo[3], h;
	int n[3];
	uint32_t *start, *list; /* per cell: list[start[c] .. start[c + 1]) */
	uint32_t *mark, stamp;
} soup;

static int cell_of(const soup *g, double v, int a)
{
	int i = (int)floor((v - g->lo[a]) / g->h);
	return i < 0 ? 0 : i >= g->n[a] ? g->n[a] - 1 : i;
}

static double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* box: lo[3], hi[3] holding every query point and triangle. */
static void soup_build(soup *g, const double *p, const uint32_t *tri, size_t nt, const double *lo, const double *hi)
{
	memset(g, 0, sizeof *g);
	g->p = p;
	g->tri = tri;
	g->nt = nt;
	/* cells about the size of a triangle */
	double area = 0.0, ext = 0.0;
	for (size_t t = 0; t < nt; t++) {
		const double *a = p + 3 * tri[3 * t], *b = p + 3 * tri[3 * t + 1], *c = p + 3 * tri[3 * t + 2];
		double u[3], v[3], n[3];
		for (int i = 0; i < 3; i++)
			u[i] = b[i] - a[i], v[i] = c[i] - a[i];
		n[0] = u[1] * v[2] - u[2] * v[1];
		n[1] = u[2] * v[0] - u[0] * v[2];
		n[2] = u[0] * v[1] - u[1] * v[0];
		area += 0.5 * sqrt(dot3(n, n));
	}
	for (int a = 0; a < 3; a++) {
		g->lo[a] = lo[a];
		ext = hi[a] - lo[a] > ext ? hi[a] - lo[a] : ext;
	}
	g->h = sqrt(2.0 * area / (double)(nt ? nt : 1));
	if (!(g->h > ext / 256.0))
		g->h = ext / 256.0 + 1e-12; /* at most 256 cells a side */
	size_t cells = 1;
	for (int a = 0; a < 3; a++) {
		g->n[a] = (int)((hi[a] - lo[a]) / g->h) + 1;
		cells *= (size_t)g->n[a];
	}
	g->start = calloc(cells + 1, sizeof *g->start);
	uint32_t *fill = calloc(cells + 1, sizeof *fill);
	g->mark = calloc(nt + 1, sizeof *g->mark);
	if (!g->start || !fill || !g->mark)
		die("out of memory", NULL);
	for (int pass = 0; pass < 2; pass++) {
		if (pass == 1) {
			uint32_t s = 0;
			for (size_t c = 0; c <= cells; c++) {
				uint32_t k = g->start[c];
				g->start[c] = s;
				s += k;
			}
			if (!(g->list = malloc(sizeof *g->list * ((size_t)s + 1))))
				die("out of memory", NULL);
		}
		for (size_t t = 0; t < nt; t++) {
			int c0[3], c1[3];
			for (int a = 0; a < 3; a++) {
				double mn = INFINITY, mx = -INFINITY;
				for (int q = 0; q < 3; q++) {
					double v = p[3 * tri[3 * t + q] + a];
					mn = v < mn ? v : mn;
					mx = v > mx ? v : mx;
				}
				c0[a] = cell_of(g, mn, a);
				c1[a] = cell_of(g, mx, a);
			}
			for (int z = c0[2]; z <= c1[2]; z++)
				for (int y = c0[1]; y <= c1[1]; y++)
					for (int x = c0[0]; x <= c1[0]; x++) {
						size_t c = ((size_t)z * (size_t)g->n[1] + (size_t)y) * (size_t)g->n[0] + (size_t)x;
						if (pass == 0)
							g->start[c]++;
						else
							g->list[g->start[c] + fill[c]++] = (uint32_t)t;
					}
		}
	}
	free(fill);
}

static void soup_free(soup *g)
{
	free(g->start);
	free(g->list);
	free(g->mark);
}

/* Squared distance from q to triangle abc (the closest point by the
 * triangle's Voronoi regions: vertices, edges, face). */
static double tri_dist2(const double *q, const double *a, const double *b, const double *c)
{
	double ab[3], ac[3], aq[3], r[3];
	for (int i = 0; i < 3; i++) {
		ab[i] = b[i] - a[i];
		ac[i] = c[i] - a[i];
		aq[i] = q[i] - a[i];
	}
	double d1 = dot3(ab, aq), d2 = dot3(ac, aq);
	double s, t; /* the closest point a + s ab + t ac */
	if (d1 <= 0 && d2 <= 0) {
		s = 0, t = 0;
	} else {
		double bq[3], cq[3];
		for (int i = 0; i < 3; i++) {
			bq[i] = q[i] - b[i];
			cq[i] = q[i] - c[i];
		}
		double d3 = dot3(ab, bq), d4 = dot3(ac, bq), d5 = dot3(ab, cq), d6 = dot3(ac, cq);
		double vc = d1 * d4 - d3 * d2, vb = d5 * d2 - d1 * d6, va = d3 * d6 - d5 * d4;
		if (d3 >= 0 && d4 <= d3)
			s = 1, t = 0;
		else if (d6 >= 0 && d5 <= d6)
			s = 0, t = 1;
		else if (vc <= 0 && d1 >= 0 && d3 <= 0)
			s = d1 / (d1 - d3), t = 0;
		else if (vb <= 0 && d2 >= 0 && d6 <= 0)
			s = 0, t = d2 / (d2 - d6);
		else if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
			double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
			s = 1 - w, t = w;
		} else {
			double den = 1.0 / (va + vb + vc);
			s = vb * den, t = vc * den;
		}
	}
	for (int i = 0; i < 3; i++)
		r[i] = a[i] + s * ab[i] + t * ac[i] - q[i];
	return dot3(r, r);
}

/* Distance from q (inside the grid's box) to the nearest triangle: the
 * cells in shells of growing radius r around q's cell, until the nearest
 * found is within r cells (every triangle not seen is farther). */
static double soup_dist(soup *g, const double *q)
{
	int c[3] = {cell_of(g, q[0], 0), cell_of(g, q[1], 1), cell_of(g, q[2], 2)};
	int rmax = g->n[0] + g->n[1] + g->n[2];
	double best = INFINITY;
	g->stamp++;
	for (int r = 0; r <= rmax; r++) {
		for (int z = c[2] - r; z <= c[2] + r; z++)
			for (int y = c[1] - r; y <= c[1] + r; y++)
				for (int x = c[0] - r; x <= c[0] + r; x++) {
					if (abs(x - c[0]) != r && abs(y - c[1]) != r && abs(z - c[2]) != r)
						continue;
					if (x < 0 || y < 0 || z < 0 || x >= g->n[0] || y >= g->n[1] || z >= g->n[2])
						continue;
					size_t cell = ((size_t)z * (size_t)g->n[1] + (size_t)y) * (size_t)g->n[0] + (size_t)x;
					for (uint32_t k = g->start[cell]; k < g->start[cell + 1]; k++) {
						uint32_t t = g->list[k];
						if (g->mark[t] == g->stamp)
							continue;
						g->mark[t] = g->stamp;
						const uint32_t *v = g->tri + 3 * t;
						double d = tri_dist2(q, g->p + 3 * v[0], g->p + 3 * v[1], g->p + 3 * v[2]);
						best = d < best ? d : best;
					}
				}
		/* every triangle not seen is outside the block scanned */
		double gap = INFINITY;
		for (int a = 0; a < 3; a++) {
			double in_lo = c[a] - r > 0 ? q[a] - (g->lo[a] + (c[a] - r) * g->h) : INFINITY;
			double in_hi = c[a] + r + 1 < g->n[a] ? g->lo[a] + (c[a] + r + 1) * g->h - q[a] : INFINITY;
			gap = in_lo < gap ? in_lo : gap;
			gap = in_hi < gap ? in_hi : gap;
		}
		if (best <= gap * gap)
			break;
	}
	return sqrt(best);
}

/* ------------------------------------------------------------------ */
/* A level skinned through the runtime                                 */
/* ------------------------------------------------------------------ */

typedef struct posed {
	double *p;
	uint32_t *tri;
	uint32_t nv;
	size_t nt;
} posed;

static mlod_rt_ctx *ctx;
static mlod_rt_scratch *scratch;
static float *buf;
static uint32_t cap;

/* Instance id at skeleton and motion level 0 and mesh level k: the
 * paper's alpha with the skeleton and motion intervals past 1 (their
 * levels never wanted) and the mesh's over [0, 1] at distance k / (L - 1). */
static void show_level(uint32_t id, uint32_t k)
{
	mlod_rt_select s;
	mlod_error e;
	mlod_rt_select_default(&s);
	s.mode = MLOD_RT_SELECT_ALPHA;
	s.d_near = 0.0f;
	s.d_far = 1.0f;
	s.hysteresis = 0.0f;
	for (int l = 0; l < MLOD_RT_LAYERS; l++)
		s.t_start[l] = s.t_end[l] = 2.0f;
	s.t_start[MLOD_RT_MESH] = 0.0f;
	s.t_end[MLOD_RT_MESH] = 1.0f;
	uint32_t L = mlod_rt_level_count(ctx, MLOD_RT_MESH);
	float d = L > 1 ? (float)k / (float)(L - 1) : 0.0f;
	if (mlod_rt_update(ctx, &s, &id, &d, 1, 0.0f, &e) != MLOD_OK)
		die("mlod_rt_update", &e);
	const mlod_rt_state *st = mlod_rt_instance_state(ctx, id);
	if (!st || st->level[MLOD_RT_SKELETON] != 0 || st->level[MLOD_RT_MOTION] != 0 || st->level[MLOD_RT_MESH] != k) {
		fprintf(stderr, "rt_mesh_error: mesh level %u not shown at skeleton and motion level 0\n", k);
		exit(2);
	}
}

static void skin_level(uint32_t id, uint32_t k, posed *out)
{
	mlod_error e;
	uint32_t vc = 0;
	if (mlod_rt_skin(ctx, scratch, id, buf, 12, NULL, 12, cap, &vc, &e) != MLOD_OK)
		die("mlod_rt_skin", &e);
	out->nv = vc;
	out->p = malloc(sizeof *out->p * 3 * ((size_t)vc + 1));
	if (!out->p)
		die("out of memory", NULL);
	for (size_t i = 0; i < 3 * (size_t)vc; i++)
		out->p[i] = buf[i];
	uint32_t parts = mlod_rt_mesh_part_count(ctx, k);
	size_t nt = 0, at = 0;
	mlod_rt_part_info pi;
	for (uint32_t p = 0; p < parts; p++) {
		if (mlod_rt_mesh_part(ctx, k, p, &pi, &e) != MLOD_OK)
			die("mlod_rt_mesh_part", &e);
		nt += pi.index_count / 3;
	}
	out->nt = nt;
	out->tri = malloc(sizeof *out->tri * 3 * (nt + 1));
	if (!out->tri)
		die("out of memory", NULL);
	for (uint32_t p = 0; p < parts; p++) {
		mlod_rt_mesh_part(ctx, k, p, &pi, &e);
		for (uint32_t i = 0; i < pi.index_count / 3 * 3; i++)
			out->tri[at++] = pi.first_vertex + pi.indices[i];
	}
}

/* The largest distance from a's vertices and triangle centroids to b's
 * surface (g). */
static double one_way(const posed *a, soup *g)
{
	double worst = 0.0;
	for (uint32_t i = 0; i < a->nv; i++) {
		double d = soup_dist(g, a->p + 3 * (size_t)i);
		worst = d > worst ? d : worst;
	}
	for (size_t t = 0; t < a->nt; t++) {
		double q[3];
		for (int c = 0; c < 3; c++)
			q[c] = (a->p[3 * a->tri[3 * t] + c] + a->p[3 * a->tri[3 * t + 1] + c] + a->p[3 * a->tri[3 * t + 2] + c]) /
			       3.0;
		double d = soup_dist(g, q);
		worst = d > worst ? d : worst;
	}
	return worst;
}

static void box_of(const posed *a, double *lo, double *hi)
{
	for (uint32_t i = 0; i < a->nv; i++)
		for (int c = 0; c < 3; c++) {
			double v = a->p[3 * (size_t)i + c];
			lo[c] = v < lo[c] ? v : lo[c];
			hi[c] = v > hi[c] ? v : hi[c];
		}
}

int main(int argc, char **argv)
{
	int times = 61;
	double ratio = 1.0;
	int i = 1;
	for (; i + 1 < argc && argv[i][0] == '-'; i += 2) {
		if (strcmp(argv[i], "-n") == 0)
			times = atoi(argv[i + 1]);
		else if (strcmp(argv[i], "-r") == 0)
			ratio = atof(argv[i + 1]);
		else
			break;
	}
	if (i != argc - 1 || times < 2 || !(ratio > 0.0)) {
		fprintf(stderr, "usage: rt_mesh_error [-n TIMES] [-r RATIO] pack.mlod\n");
		return 2;
	}
	mlod_error e;
	if (mlod_rt_open_path(argv[i], NULL, &ctx, &e) != MLOD_OK)
		die(argv[i], &e);
	uint32_t levels = mlod_rt_level_count(ctx, MLOD_RT_MESH), clips = mlod_rt_clip_count(ctx);
	for (uint32_t k = 0; k < levels; k++)
		if (mlod_rt_request(ctx, MLOD_RT_MESH, k, 0, &e) != MLOD_OK)
			die("mlod_rt_request", &e);
	for (uint32_t c = 0; c < clips; c++)
		if (mlod_rt_request(ctx, MLOD_RT_MOTION, 0, c, &e) != MLOD_OK)
			die("mlod_rt_request", &e);
	if (mlod_rt_stream(ctx, (size_t)-1, NULL, &e) != MLOD_OK)
		die("mlod_rt_stream", &e);
	if (!(scratch = mlod_rt_scratch_create(ctx)))
		die("out of memory", NULL);
	cap = mlod_rt_max_vertex_count(ctx) + 1;
	if (!(buf = malloc(sizeof *buf * 3 * (size_t)cap)))
		die("out of memory", NULL);
	uint32_t full, level;
	if (mlod_rt_instance_create(ctx, 0, 0.0f, 0, &full, &e) != MLOD_OK ||
	    mlod_rt_instance_create(ctx, 0, 0.0f, 0, &level, &e) != MLOD_OK)
		die("mlod_rt_instance_create", &e);
	/* Per clip and time: every level skinned, level 0's grid built once
	 * over the box of all of them. */
	double *worst = calloc((size_t)levels + 1, sizeof *worst), *worst_t = calloc((size_t)levels + 1, sizeof *worst_t);
	uint32_t *worst_c = calloc((size_t)levels + 1, sizeof *worst_c);
	posed *lv = calloc((size_t)levels + 1, sizeof *lv);
	if (!worst || !worst_t || !worst_c || !lv)
		die("out of memory", NULL);
	for (uint32_t c = 0; c < (clips ? clips : 1); c++) {
		float dur = clips ? mlod_rt_clip_duration(ctx, c) : 0.0f;
		for (int s = 0; s < (clips ? times : 1); s++) {
			float t = dur * (float)s / (float)(times - 1);
			double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
			for (uint32_t k = 0; k < levels; k++) {
				uint32_t id = k == 0 ? full : level;
				if (mlod_rt_instance_set(ctx, id, c, t, 0, &e) != MLOD_OK)
					die("mlod_rt_instance_set", &e);
				show_level(id, k);
				skin_level(id, k, &lv[k]);
				box_of(&lv[k], lo, hi);
			}
			soup g0;
			soup_build(&g0, lv[0].p, lv[0].tri, lv[0].nt, lo, hi);
			for (uint32_t k = 1; k < levels; k++) {
				soup gk;
				soup_build(&gk, lv[k].p, lv[k].tri, lv[k].nt, lo, hi);
				double d1 = one_way(&lv[0], &gk), d2 = one_way(&lv[k], &g0), d = d1 > d2 ? d1 : d2;
				if (d > worst[k])
					worst[k] = d, worst_t[k] = t, worst_c[k] = c;
				soup_free(&gk);
			}
			soup_free(&g0);
			for (uint32_t k = 0; k < levels; k++) {
				free(lv[k].p);
				free(lv[k].tri);
			}
		}
	}
	int over = 0;
	for (uint32_t k = 1; k < levels; k++) {
		mlod_rt_level_info li;
		if (mlod_rt_level_info_get(ctx, MLOD_RT_MESH, k, 0, &li, &e) != MLOD_OK)
			die("mlod_rt_level_info_get", &e);
		printf("mesh level %u: stated %g measured %g (clip %u at %g)\n", k, (double)li.error, worst[k], worst_c[k],
		       worst_t[k]);
		over |= worst[k] > ratio * (double)li.error;
	}
	free(worst);
	free(worst_t);
	free(worst_c);
	free(lv);
	mlod_rt_scratch_destroy(ctx, scratch);
	mlod_rt_close(ctx);
	free(buf);
	return over;
}
