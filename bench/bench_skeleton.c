/*
 * bench_skeleton.c: skeleton layer benchmarks.
 *
 *   bench_skeleton graph FILE...   time to label, build the graph and extract
 *                                  the default levels, per character
 *   bench_skeleton crowd FILE      paper Figure 15: pose + skinning-matrix cost
 *                                  of crowds, full skeleton against the level
 *                                  that removes about 39% of the joints
 *
 * Prints Markdown tables. Times are medians of repeated runs.
 */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bench.h"
#include "mlod.h"

static int load(const char *path, mlod_character *c)
{
	return bench_load("bench_skeleton", path, c, NULL);
}

/* Levels at 13%, 26% and 39% of the joints removed. */
static int build_levels(const mlod_character *c, mlod_joint_info *info, mlod_skelgraph *g, mlod_skel_level *levels)
{
	mlod_error err = {0};
	int n = c->skeleton.joint_count;
	if (mlod_label_skeleton(c, NULL, info, &err) != MLOD_OK ||
	    mlod_skelgraph_build(&c->skeleton, info, g, &err) != MLOD_OK)
		return -1;
	static const double fractions[] = {MLOD_SKEL_REMOVED_DEFAULT};
	int *order = malloc(sizeof(int) * (size_t)n);
	int minors = mlod_skel_removal_order(&c->skeleton, info, order);
	for (int k = 0; k < 3; k++) {
		int removed = (int)lround(fractions[k] * n);
		if (mlod_skelgraph_extract_first(g, info, order, removed < minors ? removed : minors, &levels[k], &err) != MLOD_OK) {
			free(order);
			return -1;
		}
	}
	free(order);
	return 0;
}

static int bench_graph(int argc, char **argv)
{
	printf("| character | joints | clips | label + energy (ms) | graph + 3 levels (ms) | closure edges |\n");
	printf("|---|---:|---:|---:|---:|---:|\n");
	for (int i = 0; i < argc; i++) {
		mlod_character c = {0};
		if (load(argv[i], &c) != 0)
			return 1;
		int n = c.skeleton.joint_count, reps = 21;
		mlod_joint_info *info = calloc((size_t)n, sizeof *info);
		double tl[21], tg[21];
		int edges = 0;
		for (int r = 0; r < reps; r++) {
			mlod_skelgraph g;
			mlod_skel_level levels[3];
			mlod_error err = {0};
			double t0 = bench_now();
			mlod_label_skeleton(&c, NULL, info, &err);
			double t1 = bench_now();
			int *order = malloc(sizeof(int) * (size_t)n);
			int minors = mlod_skel_removal_order(&c.skeleton, info, order);
			mlod_skelgraph_build(&c.skeleton, info, &g, &err);
			static const double removal[] = {MLOD_SKEL_REMOVED_DEFAULT};
			for (int k = 0; k < 3; k++) {
				int removed = (int)lround(removal[k] * n);
				mlod_skelgraph_extract_first(&g, info, order, removed < minors ? removed : minors, &levels[k], &err);
			}
			double t2 = bench_now();
			free(order);
			tl[r] = t1 - t0;
			tg[r] = t2 - t1;
			edges = g.edge_count;
			for (int k = 0; k < 3; k++)
				mlod_skel_level_free(&levels[k]);
			mlod_skelgraph_free(&g);
		}
		const char *name = strrchr(argv[i], '/');
		printf("| %s | %d | %d | %.3f | %.4f | %d |\n", name ? name + 1 : argv[i], n, c.clip_count,
		       1e3 * bench_median(tl, reps), 1e3 * bench_median(tg, reps), edges);
		free(info);
		mlod_character_free(&c);
	}
	return 0;
}

/* Inverse bind matrices: the skin's when there is one, else the inverse of
 * the rest pose. */
static void inverse_binds(const mlod_character *c, mlod_mat4 *ibm)
{
	int n = c->skeleton.joint_count;
	mlod_trs *local = malloc(sizeof *local * (size_t)n);
	mlod_mat4 *world = malloc(sizeof *world * (size_t)n);
	mlod_pose_rest(&c->skeleton, local);
	mlod_pose_world(&c->skeleton, local, world);
	for (int j = 0; j < n; j++)
		mlod_mat4_invert(&world[j], &ibm[j]);
	free(local);
	free(world);
}

/* Seconds per frame to pose `count` characters at staggered phases: clip
 * sampling, forward kinematics and skinning matrices. */
static double crowd_frame(const mlod_character *c, int count, int frames)
{
	int n = c->skeleton.joint_count;
	const mlod_clip *clip = &c->clips[0];
	mlod_trs *local = malloc(sizeof *local * (size_t)n);
	mlod_mat4 *world = malloc(sizeof *world * (size_t)n);
	mlod_mat4 *ibm = malloc(sizeof *ibm * (size_t)n);
	mlod_mat4 *palette = malloc(sizeof *palette * (size_t)n);
	volatile float sink = 0.0f;
	inverse_binds(c, ibm);
	double t0 = bench_now();
	for (int f = 0; f < frames; f++) {
		for (int i = 0; i < count; i++) {
			float t = fmodf((float)f / 60.0f + 0.37f * (float)i, clip->duration > 0 ? clip->duration : 1.0f);
			mlod_pose_rest(&c->skeleton, local);
			mlod_clip_sample(clip, t, local);
			mlod_pose_world(&c->skeleton, local, world);
			for (int j = 0; j < n; j++)
				palette[j] = mlod_mat4_mul(&world[j], &ibm[j]);
			sink += palette[n - 1].m[12];
		}
	}
	double dt = (bench_now() - t0) / frames;
	(void)sink;
	free(local);
	free(world);
	free(ibm);
	free(palette);
	return dt;
}

static int bench_crowd(const char *path)
{
	mlod_character c = {0};
	if (load(path, &c) != 0 || c.clip_count == 0)
		return 1;
	int n = c.skeleton.joint_count;
	mlod_joint_info *info = calloc((size_t)n, sizeof *info);
	mlod_skelgraph g;
	mlod_skel_level levels[3];
	mlod_character lod = {0};
	mlod_error err = {0};
	if (build_levels(&c, info, &g, levels) != 0 || mlod_skel_level_apply(&c, &levels[2], &lod, NULL, &err) != MLOD_OK) {
		fprintf(stderr, "bench_skeleton: %s\n", err.message);
		return 1;
	}
	printf("Full skeleton %d joints; level %d joints (%.0f%% removed).\n\n", n, lod.skeleton.joint_count,
	       100.0 * (n - lod.skeleton.joint_count) / n);
	printf("| characters | full (ms/frame) | level (ms/frame) | speed-up |\n|---:|---:|---:|---:|\n");
	static const int crowds[] = {1, 10, 50, 100, 250, 1000, 10000};
	for (size_t k = 0; k < sizeof crowds / sizeof *crowds; k++) {
		int count = crowds[k];
		int frames = count >= 1000 ? 10 : count >= 100 ? 60 : 600;
		double full[5], lvl[5];
		for (int r = 0; r < 5; r++) {
			full[r] = crowd_frame(&c, count, frames);
			lvl[r] = crowd_frame(&lod, count, frames);
		}
		double a = bench_median(full, 5), b = bench_median(lvl, 5);
		printf("| %d | %.4f | %.4f | %.2fx |\n", count, 1e3 * a, 1e3 * b, a / b);
	}
	for (int k = 0; k < 3; k++)
		mlod_skel_level_free(&levels[k]);
	mlod_skelgraph_free(&g);
	mlod_character_free(&lod);
	mlod_character_free(&c);
	free(info);
	return 0;
}

int main(int argc, char **argv)
{
	if (argc >= 3 && strcmp(argv[1], "graph") == 0)
		return bench_graph(argc - 2, argv + 2);
	if (argc == 3 && strcmp(argv[1], "crowd") == 0)
		return bench_crowd(argv[2]);
	fprintf(stderr, "usage: bench_skeleton graph FILE... | crowd FILE\n");
	return 1;
}
