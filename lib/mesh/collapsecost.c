/*
 * collapsecost.c: what the plan of a collapse (collapseplan.c) and the
 * queue's lower bounds (lowerbound.c) both price it with: each face's
 * normal and compactness, worked out once (a face's nodes never change)
 * in per-face arrays grown with the faces (with those of the queue's
 * state and of the reference normals, collapseplan.c); the
 * collapsed vertices' posed quadrics summed per pose; and the Power
 * Skinning (powerskin.c) of a placement by its role, remembered for the
 * operation while its face lives (bgm_memo).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#ifdef __SSE2__
#include <emmintrin.h>
#endif

#include "collapse.h"

/* Face h's bgm_face_normal (0-2), its length (3) and its compactness
 * (4), worked out once (its nodes, in its order, never change): the
 * same arithmetic every time. */
const double *bgm_face_geo(mlod_bgm *g, int h)
{
	double *o = g->fgeo + 5 * (size_t)h;
	if (isnan(o[3])) {
		const bgm_face *F = &g->faces[h];
		const double *a = g->nodes[F->n[0]].p, *b = g->nodes[F->n[1]].p, *c = g->nodes[F->n[2]].p;
		bgm_face_normal(a, b, c, o);
		o[3] = sqrt(o[0] * o[0] + o[1] * o[1] + o[2] * o[2]);
		o[4] = bgm_compactness(a, b, c);
	}
	return o;
}

int bgm_face_arrays_grow(mlod_bgm *g)
{
	if (g->opstate_cap < g->face_cap) {
		unsigned char *b = realloc(g->opstate, (size_t)g->face_cap);
		if (!b)
			return -1;
		for (int f = g->opstate_cap; f < g->face_cap; f++)
			b[f] = f < g->face_count && g->faces[f].death != BGM_ALIVE ? DEAD : 0;
		g->opstate = b;
		g->opstate_cap = g->face_cap;
	}
	if (g->ftie_cap < g->face_cap) {
		double *t = realloc(g->ftie, sizeof *t * (size_t)g->face_cap);
		if (!t)
			return -1;
		g->ftie = t;
		double *o = realloc(g->fgeo, sizeof *o * 5 * (size_t)g->face_cap);
		if (!o)
			return -1;
		g->fgeo = o;
		double *rf = realloc(g->fref, sizeof *rf * 4 * (size_t)g->face_cap);
		if (!rf)
			return -1;
		g->fref = rf;
		for (int f = g->ftie_cap; f < g->face_cap; f++)
			t[f] = o[5 * (size_t)f + 3] = rf[4 * (size_t)f + 3] = NAN;
		g->ftie_cap = g->face_cap;
	}
	return 0;
}

/* The collapsed vertices' posed quadrics summed per pose, as bgm_plan_op()
 * sums them. */
void bgm_sum_quadrics(const mlod_bgm *g, const bgm_plan *pl, double *Q)
{
	/* Each sum from 0 in the vertices' order (the same bits whatever
	 * loop makes it). */
	size_t n = 10 * (size_t)g->qpose_count;
	const double *a = g->quadric + (size_t)g->qslot[pl->v[0]] * n, *b = pl->k > 1 ? g->quadric + (size_t)g->qslot[pl->v[1]] * n : NULL;
#ifdef __SSE2__
	/* Two entries at a time (n is even): each lane the sum below. */
	if (pl->k == 2 || pl->k == 3) {
		const __m128d zero = _mm_setzero_pd();
		if (pl->k == 3) {
			const double *c = g->quadric + (size_t)g->qslot[pl->v[2]] * n;
			for (size_t k = 0; k < n; k += 2)
				_mm_storeu_pd(Q + k, _mm_add_pd(_mm_add_pd(_mm_add_pd(zero, _mm_load_pd(a + k)), _mm_load_pd(b + k)),
				                                _mm_load_pd(c + k)));
		} else {
			for (size_t k = 0; k < n; k += 2)
				_mm_storeu_pd(Q + k, _mm_add_pd(_mm_add_pd(zero, _mm_load_pd(a + k)), _mm_load_pd(b + k)));
		}
		return;
	}
#endif
	if (pl->k == 3) {
		const double *c = g->quadric + (size_t)g->qslot[pl->v[2]] * n;
		for (size_t k = 0; k < n; k++) {
			double s = 0.0;
			s += a[k];
			s += b[k];
			s += c[k];
			Q[k] = s;
		}
	} else if (pl->k == 2) {
		for (size_t k = 0; k < n; k++) {
			double s = 0.0;
			s += a[k];
			s += b[k];
			Q[k] = s;
		}
	} else {
		for (size_t k = 0; k < n; k++) {
			double s = 0.0;
			for (int j = 0; j < pl->k; j++)
				s += g->quadric[(size_t)g->qslot[pl->v[j]] * n + k];
			Q[k] = s;
		}
	}
}

/* mlod_power_skin of the collapsed vertices (V, in3) at x, placement
 * role's position (the same for the operation while its face lives), as
 * mm remembers it (when mm is not NULL). */
int bgm_skin_role(bgm_memo *mm, int role, const mlod_v3 *V, const mlod_influences *in3, int K, const double *x,
                  mlod_influences *w)
{
	if (mm && role < MEMO_SKINNED && (mm->skinned >> role & 1u)) {
		*w = mm->w[role];
		return mm->capped[role];
	}
	int capped = mlod_power_skin(V, in3, K, (mlod_v3){(float)x[0], (float)x[1], (float)x[2]}, w);
	if (mm && role < MEMO_SKINNED) {
		mm->w[role] = *w;
		mm->capped[role] = (unsigned char)capped;
		mm->skinned |= 1u << role;
	}
	return capped;
}
