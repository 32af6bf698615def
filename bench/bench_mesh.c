/*
 * bench_mesh.c: mesh layer benchmarks (paper 4.2 and Table 1).
 *
 *   bench_mesh table1 FILE...     paper Table 1: t_initBGM and t_10*decim
 *                                 per character, for each cost
 *   bench_mesh speed FILE...      time to build the 50/25/10% level chain,
 *                                 mlod against meshopt_simplify (0.18)
 *   bench_mesh chain FILE...      the same for the default posed chain
 *                                 alone, best of CHAIN_RUNS runs of the
 *                                 calling thread's CPU time (steadier on a
 *                                 shared machine than medians of wall time)
 *   bench_mesh profile FILE...    the default posed chain once per file
 *                                 and nothing else (for callgrind:
 *                                 --toggle-collect=mlod_levels)
 *   bench_mesh quality FILE [GLTFPACK50 GLTFPACK25 GLTFPACK10]
 *                                 posed error (mean and Hausdorff, % of the
 *                                 diagonal) at 50/25/10% of the triangles,
 *                                 over the clips' frames and over 8 seeded
 *                                 random poses of up to 40 degrees per joint:
 *                                 mlod's costs, placements and eligibility
 *                                 rules, meshopt_simplify (on its own indices
 *                                 and on positions only), gltfpack files
 *
 * Prints Markdown tables. Times are medians of repeated runs. The random
 * poses measured (seed 2008) are not those the posed cost trains on
 * (seed 1), as in mlod-bgm.
 */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <meshoptimizer.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bench.h"
#include "mlod.h"

#define RUNS 5

static const double ratios[] = {MLOD_MESH_RATIOS_DEFAULT}; /* the first three measured */

static int load(const char *path, mlod_character *c)
{
	return bench_load("bench_mesh", path, c, NULL);
}

/* Poses for the posed cost, as mlod-bgm makes them. */
static void train_poses(const mlod_character *c, mlod_pose_set *out)
{
	int clips = c->clip_count > 0 ? c->clip_count : 1, per = 24 / clips;
	per = per < 2 ? 2 : per > 8 ? 8 : per;
	mlod_pose_set_make(c, 0, per, MLOD_MESH_RANDOM_POSES, MLOD_MESH_TRAIN_SEED, MLOD_MESH_RANDOM_ANGLE, out, NULL);
}

/* ---------------------------------------------------------------- */
/* Levels                                                            */
/* ---------------------------------------------------------------- */

/* A character whose instance i uses meshes[i]; prims own their arrays
 * when owned[i][p]. */
struct levelset {
	mlod_mesh meshes[3][256];
	unsigned char owned[3][256][8];
	mlod_character view[3];
	int tris[3];
	int instances;
};

static void levelset_init(struct levelset *L, const mlod_character *c)
{
	memset(L, 0, sizeof *L);
	L->instances = c->instance_count < 256 ? c->instance_count : 256;
	for (int k = 0; k < 3; k++) {
		L->view[k] = *c;
		L->view[k].meshes = L->meshes[k];
		L->view[k].mesh_count = L->instances;
		L->view[k].instance_count = L->instances;
		L->view[k].instances = malloc(sizeof(mlod_instance) * (size_t)(L->instances + 1));
		for (int i = 0; i < L->instances; i++) {
			const mlod_mesh *m = &c->meshes[c->instances[i].mesh];
			L->view[k].instances[i] = c->instances[i];
			L->view[k].instances[i].mesh = i;
			L->meshes[k][i] = *m;
			L->meshes[k][i].primitives = calloc((size_t)m->primitive_count + 1, sizeof(mlod_primitive));
			for (int p = 0; p < m->primitive_count; p++)
				L->meshes[k][i].primitives[p] = m->primitives[p];
		}
	}
}

static void levelset_count(struct levelset *L)
{
	for (int k = 0; k < 3; k++)
		L->tris[k] = bench_character_triangles(&L->view[k]);
}

static void levelset_free(struct levelset *L)
{
	for (int k = 0; k < 3; k++) {
		for (int i = 0; i < L->instances; i++) {
			for (int p = 0; p < L->meshes[k][i].primitive_count && p < 8; p++) {
				if (L->owned[k][i][p] == 1)
					mlod_primitive_free(&L->meshes[k][i].primitives[p]);
				else if (L->owned[k][i][p] == 2)
					free(L->meshes[k][i].primitives[p].indices);
			}
			free(L->meshes[k][i].primitives);
		}
		free(L->view[k].instances);
	}
}

/* mlod: every primitive of every instance on a joint or skin, simplified
 * as mlod-bgm does: with the posed cost a level's triangles are shared by
 * the whole character (mlod_bgm_share_budget), with compactness each
 * primitive keeps the ratio. Returns the seconds spent (poses, build,
 * collapses, extraction); build and collapse seconds and counts add into
 * the rest. */
struct mlod_stats {
	double build, collapse;
	int collapses, caps;
};

#define MAX_PARTS (256 * 8)

static double mlod_levels(const mlod_character *c, const mlod_bgm_options *base, struct levelset *L,
                          struct mlod_stats *st)
{
	double t0 = bench_now();
	mlod_pose_set train = {0};
	mlod_bgm_options opt = *base;
	int shared = opt.cost != MLOD_COST_COMPACTNESS;
	if (!(opt.cost == MLOD_COST_COMPACTNESS && opt.placement == MLOD_PLACE_BARYCENTER)) {
		train_poses(c, &train);
		opt.poses = &train;
	}
	double *eta = calloc((size_t)c->skeleton.joint_count + 1, sizeof *eta);
	mlod_joint_weight_average(c, eta, NULL);
	opt.eta = eta;
	static mlod_bgm *bgms[MAX_PARTS];
	static int where[MAX_PARTS][2], prefix[MAX_PARTS];
	int n = 0;
	long total = 0;
	for (int i = 0; i < L->instances; i++) {
		if (c->instances[i].skin < 0 && c->instances[i].joint < 0)
			continue;
		const mlod_mesh *m = &c->meshes[c->instances[i].mesh];
		for (int p = 0; p < m->primitive_count && p < 8; p++) {
			int T = bench_triangles(&m->primitives[p]);
			mlod_bgm *g = NULL;
			if (T < 4 || mlod_bgm_build(c, i, p, &opt, &g, NULL) != MLOD_OK)
				continue;
			mlod_bgm_simplify(g, shared ? 0 : (int)ceil(ratios[2] * T), 0, NULL);
			bgms[n] = g;
			where[n][0] = i, where[n][1] = p;
			total += mlod_bgm_triangles(g, 0);
			n++;
		}
	}
	for (int k = 0; k < 3; k++) {
		if (shared)
			mlod_bgm_share_budget(bgms, n, (long)ceil(ratios[k] * (double)total), prefix);
		for (int j = 0; j < n; j++) {
			int i = where[j][0], p = where[j][1];
			int pre = shared ? prefix[j] : mlod_bgm_prefix_for(bgms[j], (int)ceil(ratios[k] * bench_triangles(&c->meshes[c->instances[i].mesh].primitives[p])));
			if (mlod_bgm_extract(bgms[j], pre, c->instances[i].skin < 0, &L->meshes[k][i].primitives[p], NULL) == MLOD_OK)
				L->owned[k][i][p] = 1;
		}
	}
	for (int j = 0; j < n; j++) {
		if (st) {
			mlod_bgm_info info;
			mlod_bgm_get_info(bgms[j], &info);
			st->build += info.build_seconds;
			st->collapse += info.collapse_seconds;
			st->collapses += info.collapses;
			st->caps += info.caps;
		}
		mlod_bgm_free(bgms[j]);
	}
	free(eta);
	mlod_pose_set_free(&train);
	levelset_count(L);
	return bench_now() - t0;
}

/* meshopt_simplify on each primitive, each level from the full mesh (as
 * gltfpack does), no error limit so the triangle target decides. With
 * shadow, on a position-only mesh made once per primitive and timed with
 * the rest: meshopt_generateVertexRemap over the positions alone, the
 * indices and positions remapped, so every corner that shares a position
 * is one vertex and attribute seams do not lock edges (RobotExpressive,
 * flat-shaded: on its own indices meshopt_simplify keeps all 3,237
 * triangles). A shadow index buffer (meshopt_generateShadowIndexBuffer)
 * does not do it with 0.18: measured, the robot stays at 3,237 triangles
 * (the seam copies it leaves unreferenced are still at each position).
 * The levels' indices are mapped back to the first input vertex at each
 * position (as a shadow index buffer's are), so that they draw and pose
 * with the input's attributes and weights. */
static double meshopt_levels(const mlod_character *c, struct levelset *L, int shadow)
{
	double t0 = bench_now();
	for (int i = 0; i < L->instances; i++) {
		if (c->instances[i].skin < 0 && c->instances[i].joint < 0)
			continue;
		const mlod_mesh *m = &c->meshes[c->instances[i].mesh];
		for (int p = 0; p < m->primitive_count && p < 8; p++) {
			const mlod_primitive *pr = &m->primitives[p];
			int T = bench_triangles(pr);
			if (T < 4)
				continue;
			uint32_t *idx = pr->indices, *own = NULL;
			if (pr->index_count == 0) {
				own = idx = malloc(sizeof(uint32_t) * (size_t)(3 * T));
				for (int v = 0; v < 3 * T; v++)
					idx[v] = (uint32_t)v;
			}
			const float *pos = pr->positions;
			size_t nv = (size_t)pr->vertex_count;
			float *shpos = NULL;
			uint32_t *rep = NULL;
			if (shadow) {
				uint32_t *remap = malloc(sizeof(uint32_t) * nv), *sh = malloc(sizeof(uint32_t) * (size_t)(3 * T));
				nv = meshopt_generateVertexRemap(remap, idx, (size_t)(3 * T), pos, nv, 3 * sizeof(float));
				shpos = malloc(3 * sizeof(float) * (nv ? nv : 1));
				rep = malloc(sizeof(uint32_t) * (nv ? nv : 1));
				meshopt_remapVertexBuffer(shpos, pos, (size_t)pr->vertex_count, 3 * sizeof(float), remap);
				meshopt_remapIndexBuffer(sh, idx, (size_t)(3 * T), remap);
				for (int v = pr->vertex_count - 1; v >= 0; v--) /* the first vertex at each position */
					if (remap[v] != ~0u)
						rep[remap[v]] = (uint32_t)v;
				free(remap);
				free(own);
				own = idx = sh;
				pos = shpos;
			}
			for (int k = 0; k < 3; k++) {
				uint32_t *dst = malloc(sizeof(uint32_t) * (size_t)(3 * T));
				float err = 0.0f;
				size_t n = meshopt_simplify(dst, idx, (size_t)(3 * T), pos, nv, 3 * sizeof(float), (size_t)floor(ratios[k] * T) * 3, 1.0f, 0, &err);
				for (size_t j = 0; rep && j < n; j++)
					dst[j] = rep[dst[j]];
				mlod_primitive *q = &L->meshes[k][i].primitives[p];
				q->indices = dst;
				q->index_count = (int)n;
				L->owned[k][i][p] = 2;
			}
			free(own);
			free(shpos);
			free(rep);
		}
	}
	levelset_count(L);
	return bench_now() - t0;
}

/* ---------------------------------------------------------------- */
/* Posed error                                                       */
/* ---------------------------------------------------------------- */

/* The error of level against full over poses; other is a character from
 * another file (gltfpack's), posed by joint name. */
static int posed_error(const mlod_character *full, const mlod_character *level, const mlod_pose_set *poses,
                       mlod_deviation *out)
{
	if (level->skeleton.joint_count == full->skeleton.joint_count) {
		int same = 1;
		for (int j = 0; j < full->skeleton.joint_count && same; j++)
			same = strcmp(full->skeleton.joints[j].name, level->skeleton.joints[j].name) == 0;
		if (same && level->skeleton.joints == full->skeleton.joints)
			return mlod_posed_error(full, level, poses, out, NULL) == MLOD_OK ? 0 : -1;
	}
	/* Map the other file's joints by name. */
	int J = level->skeleton.joint_count;
	int *map = bench_joint_map(full, level);
	if (!map)
		return -1;
	mlod_mat4 *world = malloc(sizeof *world * (size_t)(J + 1));
	mlod_posed a = {0}, b = {0};
	double sum = 0.0;
	memset(out, 0, sizeof *out);
	int r = 0;
	for (int k = 0; k < poses->count && r == 0; k++) {
		const mlod_mat4 *w = poses->world + (size_t)k * (size_t)poses->joint_count;
		for (int j = 0; j < J; j++)
			world[j] = w[map[j]];
		mlod_deviation d;
		if (mlod_pose_character(full, w, &a, NULL) != MLOD_OK || mlod_pose_character(level, world, &b, NULL) != MLOD_OK ||
		    mlod_surface_deviation(&a, &b, &d, NULL) != MLOD_OK) {
			r = -1;
			break;
		}
		sum += d.mean;
		if (d.max > out->max)
			out->max = d.max;
	}
	if (poses->count > 0)
		out->mean = sum / poses->count;
	mlod_posed_free(&a);
	mlod_posed_free(&b);
	free(world);
	free(map);
	return r;
}

/* ---------------------------------------------------------------- */
/* Commands                                                          */
/* ---------------------------------------------------------------- */

/* Loads a character with triangles: returns their count, or 0 (nothing
 * loaded) when it cannot be read or has none. */
static int load_meshed(const char *path, mlod_character *c)
{
	if (load(path, c) != 0)
		return 0;
	int T = bench_character_triangles(c);
	if (T == 0)
		mlod_character_free(c);
	return T;
}

static void table1(int argc, char **argv)
{
	printf("| character | triangles | cost | t_initBGM (ms) | t_10*decim (ms) | collapses | paper t_initBGM | "
	       "paper t_10*decim |\n|---|---:|---|---:|---:|---:|---:|---:|\n");
	for (int a = 0; a < argc; a++) {
		mlod_character c;
		int T = load_meshed(argv[a], &c);
		if (T == 0)
			continue;
		for (int cost = 0; cost < 2; cost++) {
			mlod_bgm_options opt = {0};
			opt.cost = cost ? MLOD_COST_COMPACTNESS : MLOD_COST_POSED;
			opt.placement = cost ? MLOD_PLACE_BARYCENTER : MLOD_PLACE_OPTIMAL;
			double build[RUNS], decim[RUNS];
			int collapses = 0;
			for (int run = 0; run < RUNS; run++) {
				struct levelset L;
				struct mlod_stats st = {0};
				levelset_init(&L, &c);
				mlod_levels(&c, &opt, &L, &st);
				levelset_free(&L);
				build[run] = 1e3 * st.build;
				decim[run] = st.collapses > 0 ? 1e4 * st.collapse / st.collapses : 0.0;
				collapses = st.collapses;
			}
			printf("| %s | %d | %s | %.2f | %.3f | %d | %s | %s |\n", bench_base_name(argv[a]), T,
			       cost ? "compactness, triangle (paper)" : "posed, edge (default)", bench_median(build, RUNS), bench_median(decim, RUNS), collapses,
			       "142 ms (982 tris), 7.7-8.8 s (7186), 11.6 s (6656)", "1-12 ms");
		}
		mlod_character_free(&c);
	}
	printf("\nt_initBGM: building the BindGraphMesh of every primitive (weld, dual graph, flags; with the posed cost "
	       "also the posed quadrics); t_10*decim: collapse time per 10 collapses (edge collapses with the posed "
	       "cost, triangle collapses with compactness), down to 10%% of each primitive's triangles with compactness "
	       "and as far as the posed cost goes (its character budget then picks the levels). Medians of %d runs.\n",
	       RUNS);
}

static void speed(int argc, char **argv)
{
	printf("| character | triangles | mlod posed (ms) | mlod compactness (ms) | meshopt_simplify (ms) | posed / meshopt | "
	       "compactness / meshopt |\n|---|---:|---:|---:|---:|---:|---:|\n");
	for (int a = 0; a < argc; a++) {
		mlod_character c;
		int T = load_meshed(argv[a], &c);
		if (T == 0)
			continue;
		double t[3][RUNS];
		for (int run = 0; run < RUNS; run++) {
			for (int m = 0; m < 3; m++) {
				struct levelset L;
				levelset_init(&L, &c);
				mlod_bgm_options opt = {0};
				if (m == 1) {
					opt.cost = MLOD_COST_COMPACTNESS;
					opt.placement = MLOD_PLACE_BARYCENTER;
				}
				t[m][run] = 1e3 * (m < 2 ? mlod_levels(&c, &opt, &L, NULL) : meshopt_levels(&c, &L, 0));
				levelset_free(&L);
			}
		}
		double tp = bench_median(t[0], RUNS), tc = bench_median(t[1], RUNS), tm = bench_median(t[2], RUNS);
		printf("| %s | %d | %.1f | %.1f | %.2f | %.0fx | %.0fx |\n", bench_base_name(argv[a]), T, tp, tc, tm, tp / tm, tc / tm);
		mlod_character_free(&c);
	}
	printf("\nThe whole chain of three levels (50%%, 25%%, 10%% of the triangles): mlod makes its poses, builds "
	       "the BGMs, collapses once (as far as it goes with the posed cost, whose character budget then shares "
	       "each level among the primitives; to 10%% of each primitive with compactness) and extracts the three "
	       "prefixes; meshopt_simplify simplifies each primitive's level from the full mesh, positions only. "
	       "Medians of %d runs.\n",
	       RUNS);
}

static double cpu_now(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

#ifndef CHAIN_RUNS
#define CHAIN_RUNS 11
#endif

static void chain(int argc, char **argv)
{
	printf("| character | triangles | mlod posed (ms) | mlod posed --fast-cost (ms) | meshopt_simplify (ms) | posed / meshopt | "
	       "fast / meshopt | mlod posed -p vertex (ms) | vertex / meshopt | meshopt_simplify positions only (ms) | "
	       "posed / positions only | fast / positions only | triangles kept at 50/25/10%%: mlod, meshopt, positions only |\n"
	       "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|\n");
	for (int a = 0; a < argc; a++) {
		mlod_character c;
		int T = load_meshed(argv[a], &c);
		if (T == 0)
			continue;
		double best[5] = {HUGE_VAL, HUGE_VAL, HUGE_VAL, HUGE_VAL, HUGE_VAL};
		int kept[5][3] = {{0}};
		for (int run = 0; run < CHAIN_RUNS; run++)
			for (int m = 0; m < 5; m++) {
				struct levelset L;
				levelset_init(&L, &c);
				mlod_bgm_options opt = {0};
				opt.fast_cost = m == 1;
				if (m == 3)
					opt.placement = MLOD_PLACE_VERTEX;
				double t0 = cpu_now();
				if (m == 2 || m == 4)
					meshopt_levels(&c, &L, m == 4);
				else
					mlod_levels(&c, &opt, &L, NULL);
				double t = 1e3 * (cpu_now() - t0);
				best[m] = t < best[m] ? t : best[m];
				memcpy(kept[m], L.tris, sizeof kept[m]);
				levelset_free(&L);
			}
		printf("| %s | %d | %.2f | %.2f | %.2f | %.1fx | %.1fx | %.2f | %.1fx | %.2f | %.1fx | %.1fx | %d/%d/%d, %d/%d/%d, %d/%d/%d |\n",
		       bench_base_name(argv[a]), T, best[0], best[1], best[2], best[0] / best[2], best[1] / best[2], best[3],
		       best[3] / best[2], best[4], best[0] / best[4], best[1] / best[4], kept[0][0], kept[0][1], kept[0][2],
		       kept[2][0], kept[2][1], kept[2][2], kept[4][0], kept[4][1], kept[4][2]);
		mlod_character_free(&c);
	}
	printf("\nThe posed chain of the speed table (default, with --fast-cost, and with -p vertex) against meshopt_simplify, "
	       "on the primitives' own indices and on positions only (meshopt_generateVertexRemap over the positions, "
	       "timed with it: seams do not lock vertices, so it reaches the targets where the other may not); best of %d "
	       "runs, CPU time of the calling thread.\n",
	       CHAIN_RUNS);
}

/* One default posed chain per file, nothing timed or printed but the
 * triangles it kept: a run for instruction counts. */
static void profile(int argc, char **argv)
{
	for (int a = 0; a < argc; a++) {
		mlod_character c;
		int T = load_meshed(argv[a], &c);
		if (T == 0)
			continue;
		struct levelset L;
		levelset_init(&L, &c);
		mlod_bgm_options opt = {0};
		mlod_levels(&c, &opt, &L, NULL);
		printf("%s: %d triangles\n", bench_base_name(argv[a]), T);
		levelset_free(&L);
		mlod_character_free(&c);
	}
}

struct method {
	const char *name;
	int kind; /* 0 mlod, 1 meshopt, 2 gltfpack file, 3 meshopt on positions only */
	mlod_bgm_options opt;
};

static void quality(int argc, char **argv)
{
	mlod_character c;
	if (argc < 1 || load(argv[0], &c) != 0)
		return;
	const char *name = bench_base_name(argv[0]);
	struct method methods[] = {
		{"mlod posed, optimal, all, edge (default)", 0, {.cost = MLOD_COST_POSED, .placement = MLOD_PLACE_OPTIMAL, .op = MLOD_OP_EDGE, .eligibility = MLOD_ELIGIBLE_ALL}},
		{"mlod posed --fast-cost, optimal, all, edge", 0, {.cost = MLOD_COST_POSED, .placement = MLOD_PLACE_OPTIMAL, .op = MLOD_OP_EDGE, .eligibility = MLOD_ELIGIBLE_ALL, .fast_cost = 1}},
		{"mlod posed, optimal, all, mixed", 0, {.cost = MLOD_COST_POSED, .placement = MLOD_PLACE_OPTIMAL, .op = MLOD_OP_MIXED, .eligibility = MLOD_ELIGIBLE_ALL}},
		{"mlod posed, optimal, all, triangle", 0, {.cost = MLOD_COST_POSED, .placement = MLOD_PLACE_OPTIMAL, .op = MLOD_OP_TRIANGLE, .eligibility = MLOD_ELIGIBLE_ALL}},
		{"mlod posed, optimal, bend, edge", 0, {.cost = MLOD_COST_POSED, .placement = MLOD_PLACE_OPTIMAL, .op = MLOD_OP_EDGE, .eligibility = MLOD_ELIGIBLE_BEND}},
		{"mlod posed, optimal, literal, edge", 0, {.cost = MLOD_COST_POSED, .placement = MLOD_PLACE_OPTIMAL, .op = MLOD_OP_EDGE, .eligibility = MLOD_ELIGIBLE_LITERAL}},
		{"mlod posed, barycenter, all, edge", 0, {.cost = MLOD_COST_POSED, .placement = MLOD_PLACE_BARYCENTER, .op = MLOD_OP_EDGE, .eligibility = MLOD_ELIGIBLE_ALL}},
		{"mlod posed, vertex, all, edge", 0, {.cost = MLOD_COST_POSED, .placement = MLOD_PLACE_VERTEX, .op = MLOD_OP_EDGE, .eligibility = MLOD_ELIGIBLE_ALL}},
		{"mlod compactness, barycenter, bend (paper)", 0, {.cost = MLOD_COST_COMPACTNESS, .placement = MLOD_PLACE_BARYCENTER, .eligibility = MLOD_ELIGIBLE_BEND}},
		{"mlod compactness, barycenter, literal", 0, {.cost = MLOD_COST_COMPACTNESS, .placement = MLOD_PLACE_BARYCENTER, .eligibility = MLOD_ELIGIBLE_LITERAL}},
		{"mlod compactness, barycenter, all", 0, {.cost = MLOD_COST_COMPACTNESS, .placement = MLOD_PLACE_BARYCENTER, .eligibility = MLOD_ELIGIBLE_ALL}},
		{"meshopt_simplify 0.18", 1, {0}},
		{"meshopt_simplify 0.18, positions only", 3, {0}},
		{"gltfpack 1.3 -si R -se 1 -noq", 2, {0}},
	};
	int nm = (int)(sizeof methods / sizeof *methods);
	mlod_pose_set clip = {0}, random = {0};
	mlod_pose_set_make(&c, 0, 16, 0, 0, 0.0f, &clip, NULL);
	mlod_pose_set_make(&c, 0, 0, MLOD_MESH_RANDOM_POSES, MLOD_MESH_MEASURE_SEED, MLOD_MESH_RANDOM_ANGLE, &random, NULL);
	int T = bench_character_triangles(&c);
	/* results[method][pose set][level] */
	mlod_deviation res[16][2][3];
	int tris[16][3], ok[16][3];
	memset(ok, 0, sizeof ok);
	for (int m = 0; m < nm; m++) {
		if (methods[m].kind == 2) {
			for (int k = 0; k < 3; k++) {
				mlod_character g;
				if (argc < 4 || load(argv[1 + k], &g) != 0)
					continue;
				tris[m][k] = bench_character_triangles(&g);
				ok[m][k] = posed_error(&c, &g, &clip, &res[m][0][k]) == 0 && posed_error(&c, &g, &random, &res[m][1][k]) == 0;
				mlod_character_free(&g);
			}
			continue;
		}
		struct levelset L;
		levelset_init(&L, &c);
		if (methods[m].kind == 0)
			mlod_levels(&c, &methods[m].opt, &L, NULL);
		else
			meshopt_levels(&c, &L, methods[m].kind == 3);
		for (int k = 0; k < 3; k++) {
			tris[m][k] = L.tris[k];
			ok[m][k] = mlod_posed_error(&c, &L.view[k], &clip, &res[m][0][k], NULL) == MLOD_OK &&
			           mlod_posed_error(&c, &L.view[k], &random, &res[m][1][k], NULL) == MLOD_OK;
		}
		levelset_free(&L);
	}
	for (int set = 0; set < 2; set++) {
		printf("\n**%s, %d triangles: %s** (mean / Hausdorff, %% of the diagonal)\n\n", name, T,
		       set == 0 ? (c.clip_count ? "the clips' frames" : "the rest pose")
		                : "8 random poses, up to 40 degrees per joint (seed 2008)");
		printf("| method | 50%%: tris | mean | Hausdorff | 25%%: tris | mean | Hausdorff | 10%%: tris | mean | "
		       "Hausdorff |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
		for (int m = 0; m < nm; m++) {
			printf("| %s", methods[m].name);
			for (int k = 0; k < 3; k++) {
				if (!ok[m][k])
					printf(" | - | - | -");
				else
					printf(" | %d | %.4f | %.3f", tris[m][k], res[m][set][k].mean, res[m][set][k].max);
			}
			printf(" |\n");
		}
		/* Ratios of the default and of the vertex placement against the
		 * peers, where the counts match within 1%. */
		int vertex_row = 0;
		for (int m = 0; m < nm; m++)
			if (methods[m].kind == 0 && methods[m].opt.placement == MLOD_PLACE_VERTEX)
				vertex_row = m;
		for (int row = 0; row < 2; row++)
			for (int peer = nm - 3; peer < nm; peer++) {
				int me = row ? vertex_row : 0;
				printf("| %s / %s", row ? "vertex" : "default",
				       methods[peer].kind == 1 ? "meshopt" : methods[peer].kind == 3 ? "meshopt positions only" : "gltfpack");
				for (int k = 0; k < 3; k++) {
					if (!ok[me][k] || !ok[peer][k] || fabs((double)tris[me][k] - tris[peer][k]) > 0.01 * tris[peer][k] + 1)
						printf(" | unequal | - | -");
					else
						printf(" | | %.2f | %.2f", res[me][set][k].mean / fmax(res[peer][set][k].mean, 1e-12),
						       res[me][set][k].max / fmax(res[peer][set][k].max, 1e-12));
				}
				printf(" |\n");
			}
	}
	mlod_pose_set_free(&clip);
	mlod_pose_set_free(&random);
	mlod_character_free(&c);
}

int main(int argc, char **argv)
{
	if (argc < 3) {
		fprintf(stderr, "usage: bench_mesh table1|speed|chain|profile FILE... | bench_mesh quality FILE [GP50 GP25 GP10]\n");
		return 1;
	}
	if (strcmp(argv[1], "table1") == 0)
		table1(argc - 2, argv + 2);
	else if (strcmp(argv[1], "speed") == 0)
		speed(argc - 2, argv + 2);
	else if (strcmp(argv[1], "chain") == 0)
		chain(argc - 2, argv + 2);
	else if (strcmp(argv[1], "profile") == 0)
		profile(argc - 2, argv + 2);
	else if (strcmp(argv[1], "quality") == 0)
		quality(argc - 2, argv + 2);
	else {
		fprintf(stderr, "bench_mesh: unknown command %s\n", argv[1]);
		return 1;
	}
	return 0;
}
