/*
 * surface.h: inside lib/measure only. A posed mesh kept with the hierarchy
 * mlod_surface_deviation searches (deviation.c), so that the same mesh
 * measured against many others builds it once: the full character at each
 * pose of a pose set, against every level (posederror.c).
 */
#ifndef MLOD_MEASURE_SURFACE_H
#define MLOD_MEASURE_SURFACE_H

#include "measure/mlod_measure.h"

typedef struct mlod_surface mlod_surface;

/* A copy of m with its hierarchy; fails, with the message
 * mlod_surface_deviation gives for such a mesh a, when m cannot be one. */
mlod_result mlod_surface_make(const mlod_posed *m, mlod_surface **out, mlod_error *err);
void mlod_surface_free(mlod_surface *s);

/* 1 when s holds m: the same counts, positions and indices, byte for byte. */
int mlod_surface_is(const mlod_surface *s, const mlod_posed *m);

/* Warm starts for mlod_surface_deviation_to: for each sample of a (its
 * vertices, then its triangles; a_count of them) the triangle of b nearest
 * to it, and for each sample of b the triangle of a nearest to it, as the
 * meshes' triangle indices. With record set the search writes them; else
 * it starts each query from them (a tight first bound: the search prunes
 * more, and its result is the same, being the exact nearest either way).
 * Warm starts made for meshes of other counts are not used. */
typedef struct mlod_warm {
	int *a, *b;
	int a_count, b_count;
	int record;
} mlod_warm;

/* mlod_surface_deviation of a's mesh and b, the same result to the bit,
 * with warm starts when warm is not NULL. */
mlod_result mlod_surface_deviation_to(const mlod_surface *a, const mlod_posed *b, const mlod_warm *warm,
                                      mlod_deviation *out, mlod_error *err);

#endif /* MLOD_MEASURE_SURFACE_H */
