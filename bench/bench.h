/* bench.h: timing helpers shared by the benchmark programs. */
#ifndef MLOD_BENCH_H
#define MLOD_BENCH_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "mlod.h"

/* Monotonic time in seconds. */
static inline double bench_now(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static inline int bench_cmp_double(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return (x > y) - (x < y);
}

/* The median of n values (sorts v). */
static inline double bench_median(double *v, int n)
{
	qsort(v, (size_t)n, sizeof *v, bench_cmp_double);
	return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/* Loads a glb, glTF or BVH file into c (and its document, when doc is
 * not NULL); prints "who: path: why" and returns -1 on failure. */
static inline int bench_load(const char *who, const char *path, mlod_character *c, mlod_gltf **doc)
{
	FILE *f = fopen(path, "rb");
	if (!f) {
		fprintf(stderr, "%s: %s: cannot open\n", who, path);
		return -1;
	}
	fseek(f, 0, SEEK_END);
	long size = ftell(f);
	fseek(f, 0, SEEK_SET);
	void *data = size >= 0 ? malloc((size_t)size + 1) : NULL;
	size_t got = data ? fread(data, 1, (size_t)size, f) : 0;
	fclose(f);
	mlod_error err = {0};
	mlod_result r = data ? mlod_load(data, got, ".", doc, c, NULL, &err) : MLOD_ERR_NOMEM;
	free(data);
	if (r != MLOD_OK)
		fprintf(stderr, "%s: %s: %s\n", who, path, data ? err.message : "out of memory");
	return r == MLOD_OK ? 0 : -1;
}

/* The file name of a path (after its last '/'). */
static inline const char *bench_base_name(const char *path)
{
	const char *s = strrchr(path, '/');
	return s ? s + 1 : path;
}

/* Triangles of a primitive (mode 4, indexed or not; 0 for other modes)
 * and of a character's instances. */
static inline int bench_triangles(const mlod_primitive *p)
{
	return p->mode == 4 ? (p->index_count > 0 ? p->index_count : p->vertex_count) / 3 : 0;
}

static inline int bench_character_triangles(const mlod_character *c)
{
	int t = 0;
	for (int i = 0; i < c->instance_count; i++)
		for (int p = 0; p < c->meshes[c->instances[i].mesh].primitive_count; p++)
			t += bench_triangles(&c->meshes[c->instances[i].mesh].primitives[p]);
	return t;
}

/* map[j]: the joint of full with the name of level's joint j (a peer's
 * file has its own skeleton); NULL when a name is missing or out of
 * memory. The caller frees it. */
static inline int *bench_joint_map(const mlod_character *full, const mlod_character *level)
{
	int J = level->skeleton.joint_count;
	int *map = malloc(sizeof(int) * (size_t)(J + 1));
	for (int j = 0; map && j < J; j++) {
		map[j] = -1;
		for (int k = 0; k < full->skeleton.joint_count; k++)
			if (strcmp(full->skeleton.joints[k].name, level->skeleton.joints[j].name) == 0)
				map[j] = k;
		if (map[j] < 0) {
			free(map);
			return NULL;
		}
	}
	return map;
}

#endif
