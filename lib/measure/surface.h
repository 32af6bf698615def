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

/* mlod_surface_deviation of a's mesh and b, the same result to the bit. */
mlod_result mlod_surface_deviation_to(const mlod_surface *a, const mlod_posed *b, mlod_deviation *out,
                                      mlod_error *err);

#endif /* MLOD_MEASURE_SURFACE_H */
