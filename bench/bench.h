/* bench.h: timing helpers shared by the benchmark programs. */
#ifndef MLOD_BENCH_H
#define MLOD_BENCH_H

#include <stdio.h>
#include <stdlib.h>
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

#endif
