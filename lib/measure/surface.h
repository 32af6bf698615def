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
/* The same; when like (NULL: none) holds m's triangles, byte for byte,
 * the copy shares like's instead of copying them: like must then outlive
 * it (the same mesh at another pose: a pose set's kept full character,
 * whose triangles every pose has). */
mlod_result mlod_surface_make_like(const mlod_posed *m, const mlod_surface *like, mlod_surface **out,
                                   mlod_error *err);
void mlod_surface_free(mlod_surface *s);

/* s's hierarchy, when a search needs it, is then like's refitted to s's
 * positions (built if like has none by then): like must be the same mesh
 * at another pose, outlive s and not be freed before it; else (other
 * triangles) nothing changes. */
void mlod_surface_like(mlod_surface *s, mlod_surface *like);

/* The mesh s holds (its copy of the one it was made from). */
const mlod_posed *mlod_surface_mesh(const mlod_surface *s);

/* Makes s's hierarchy now, if no search has (under its lock), as the
 * first search would: refitted from its like's (mlod_surface_like) when
 * that one is built by then, else built. */
mlod_result mlod_surface_build(mlod_surface *s, mlod_error *err);

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
	/* Searching only where the max may grow (set with record unset): a
	 * sample's distance to its warm triangle is an upper bound of its
	 * distance to the surface; when that bound is no more than floor (a
	 * fraction of a's diagonal known not to exceed the largest distance
	 * of the whole measure over a's diagonal: the recording pose's, which
	 * writes it) nor the largest distance searched so far in this call,
	 * the sample cannot raise the max and counts with its bound,
	 * unsearched. The max is then the same as searching every sample,
	 * and the mean an upper bound of it, equal where the warm triangle is
	 * still the nearest. Samples are then visited in the mesh's order, so
	 * the result depends on nothing else. The hierarchies are then built
	 * only when a sample is searched. */
	int bound;
	double floor;
	/* b's hierarchy at the recording pose, kept there (free it with
	 * mlod_warm_release); the other poses refit it when they search b */
	struct mlod_bvh *b_tree;
} mlod_warm;

/* Frees what a recording kept in w (not w itself). */
void mlod_warm_release(mlod_warm *w);

/* mlod_surface_deviation of a's mesh and b, the same result to the bit,
 * with warm starts when warm is not NULL (with its bound, the max only).
 * a's hierarchy is built by the first call that searches it (under a
 * lock: calls may share a). */
mlod_result mlod_surface_deviation_to(const mlod_surface *a, const mlod_posed *b, mlod_warm *warm,
                                      mlod_deviation *out, mlod_error *err);

#endif /* MLOD_MEASURE_SURFACE_H */
