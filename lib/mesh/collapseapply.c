/*
 * collapseapply.c: a planned collapse (collapseplan.c) applied to the
 * BindGraphMesh: v-bar appended as a node with the plan's position and
 * influences, its wedges (copied from a snapped or whole vertex, or
 * interpolated inside the collapsed triangle or edge), the patch killed
 * and re-meshed around v-bar with its dual graph, the border flags as
 * the new faces leave them, and one vertex-split record appended.
 */
#include <math.h>
#include <string.h>

#include "collapse.h"

/* Interpolates wedge attributes: out = sum_i l[i] * attr(w[i]), with unit
 * normals and tangents. */
static void interpolate_wedge(mlod_bgm *g, int out, const int *w, const double *l)
{
	const bgm_layout *L = &g->lay;
	int S = L->stride;
	if (S == 0)
		return;
	float *o = g->wedge_attr + (size_t)out * (size_t)S;
	const float *x[3];
	for (int i = 0; i < 3; i++)
		x[i] = g->wedge_attr + (size_t)w[i] * (size_t)S;
	for (int k = 0; k < S; k++)
		o[k] = (float)(l[0] * x[0][k] + l[1] * x[1][k] + l[2] * x[2][k]);
	if (L->normal >= 0) {
		float *n = o + L->normal;
		double len = sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
		int m = l[0] >= l[1] && l[0] >= l[2] ? 0 : l[1] >= l[2] ? 1 : 2;
		if (len > 1e-6)
			for (int i = 0; i < 3; i++)
				n[i] = (float)(n[i] / len);
		else
			memcpy(n, x[m] + L->normal, 3 * sizeof(float));
	}
	if (L->tangent >= 0) {
		float *tg = o + L->tangent;
		double len = sqrt((double)tg[0] * tg[0] + (double)tg[1] * tg[1] + (double)tg[2] * tg[2]);
		int m = l[0] >= l[1] && l[0] >= l[2] ? 0 : l[1] >= l[2] ? 1 : 2;
		if (len > 1e-6)
			for (int i = 0; i < 3; i++)
				tg[i] = (float)(tg[i] / len);
		else
			memcpy(tg, x[m] + L->tangent, 3 * sizeof(float));
		tg[3] = x[m][L->tangent + 3] < 0.0f ? -1.0f : 1.0f;
	}
}

/* 1 when node v has a live edge with one face. */
static int on_border(const mlod_bgm *g, int v)
{
	const bgm_node *n = &g->nodes[v];
	for (int i = 0; i < n->inc_count; i++) {
		const bgm_face *F = &g->faces[g->inc[n->inc_first + i]];
		for (int e = 0; e < 3; e++)
			if (F->adj[e] < 0 && (F->n[e] == v || F->n[(e + 1) % 3] == v))
				return 1;
	}
	return 0;
}

/* v-bar's wedges (v its node), cw[j] the one kept[j]'s corner takes.
 * Snapped: one per wedge group, a copy of the snap vertex's wedge there;
 * kept whole: a copy of each wedge of v[snap] taken. Free (no texture
 * seam at a, b, c): the attributes interpolated inside t, except that
 * corners of a vertex with hard normal edges keep their own normals (so
 * faceted meshes stay faceted); equal results share a wedge. Returns 0,
 * or -1 when out of memory. */
static int vbar_wedges(mlod_bgm *g, const bgm_plan *pl, int v, int *cw)
{
	int gw[MAX_WEDGES], K = pl->k;
	int S = g->lay.stride;
	if (pl->whole) {
		/* One new wedge per wedge of v[snap] taken, a copy of it. */
		for (int j = 0; j < pl->nk; j++) {
			int prev = -1;
			for (int i = 0; i < j && prev < 0; i++)
				if (pl->src[i] == pl->src[j])
					prev = cw[i];
			if (prev >= 0) {
				cw[j] = prev;
				continue;
			}
			if ((cw[j] = bgm_add_wedge(g, v)) < 0)
				return -1;
			if (S > 0)
				memcpy(g->wedge_attr + (size_t)cw[j] * (size_t)S, g->wedge_attr + (size_t)pl->src[j] * (size_t)S,
				       sizeof(float) * (size_t)S);
		}
	} else if (pl->snap >= 0) {
		for (int k = 0; k < pl->ngroups; k++) {
			if ((gw[k] = bgm_add_wedge(g, v)) < 0)
				return -1;
			for (int i = 0; i < pl->nw; i++)
				if (pl->group[i] == k && g->wedge_node[pl->wedges[i]] == pl->v[pl->snap] && S > 0)
					memcpy(g->wedge_attr + (size_t)gw[k] * (size_t)S, g->wedge_attr + (size_t)pl->wedges[i] * (size_t)S,
					       sizeof(float) * (size_t)S);
		}
		for (int j = 0; j < pl->nk; j++)
			cw[j] = gw[pl->group[bgm_wedge_slot(pl, g->faces[pl->kept[j]].w[pl->corner[j]])]];
	} else {
		int base = bgm_add_wedge(g, v), T = g->prim->target_count;
		if (base < 0)
			return -1;
		/* The collapsed vertices' wedges in t (an edge: its two ends). */
		const bgm_face *TF = &g->faces[pl->t];
		int tw[3] = {TF->w[0], TF->w[1], TF->w[2]};
		if (K == 2)
			tw[0] = TF->w[pl->op], tw[1] = TF->w[(pl->op + 1) % 3], tw[2] = tw[0];
		interpolate_wedge(g, base, tw, pl->lambda);
		for (int j = 0; j < pl->nk; j++) {
			int w = g->faces[pl->kept[j]].w[pl->corner[j]], x = g->wedge_node[w];
			int o = x == pl->v[0] ? 0 : x == pl->v[1] ? 1 : 2;
			cw[j] = base;
			if (!pl->hard[o] || S == 0)
				continue;
			/* The interpolated wedge with this corner's own normals. */
			int nw = bgm_add_wedge(g, v);
			if (nw < 0)
				return -1;
			float *dst = g->wedge_attr + (size_t)nw * (size_t)S;
			const float *own = g->wedge_attr + (size_t)w * (size_t)S;
			memcpy(dst, g->wedge_attr + (size_t)base * (size_t)S, sizeof(float) * (size_t)S);
			for (int k = 0; k < S; k++)
				if (bgm_is_normal_float(&g->lay, k, T))
					dst[k] = own[k];
			cw[j] = nw;
			for (int prev = base; prev < nw; prev++) /* this collapse's wedges are contiguous */
				if (memcmp(g->wedge_attr + (size_t)prev * (size_t)S, dst, sizeof(float) * (size_t)S) == 0) {
					cw[j] = prev;
					g->wedge_count--; /* drop the duplicate just made (the last) */
					break;
				}
		}
	}
	return 0;
}

/* Applies a planned collapse; returns 0, or -1 when out of memory. */
int bgm_apply(mlod_bgm *g, bgm_plan *pl)
{
	int rec = g->record_count, stamp = rec + 1;
	if (bgm_grow((void **)&g->records, &g->record_cap, rec + 1, sizeof *g->records) ||
	    bgm_grow((void **)&g->removed, &g->removed_cap, g->removed_len + pl->nf, sizeof *g->removed))
		return -1;
	int v = bgm_add_node(g);
	if (v < 0)
		return -1;
	bgm_node *N = &g->nodes[v];
	for (int i = 0; i < 3; i++)
		N->p[i] = pl->pos[i];
	g->inf[v] = pl->inf;
	int fl = 0, K = pl->k;
	for (int i = 0; i < K; i++)
		fl |= g->nodes[pl->v[i]].flags & BGM_BORDER;
	if (bgm_node_eligible(g, &pl->inf))
		fl |= BGM_ELIGIBLE;
	N->flags = fl;
	if (g->lay.morph_stride > 0) {
		float *m = g->morph + (size_t)v * (size_t)g->lay.morph_stride;
		for (int k = 0; k < g->lay.morph_stride; k++) {
			double x = 0.0;
			for (int i = 0; i < K; i++)
				x += pl->lambda[i] * g->morph[(size_t)pl->v[i] * (size_t)g->lay.morph_stride + (size_t)k];
			m[k] = (float)x;
		}
	}
	if (g->pose_count > 0) {
		/* The parents' sums, each from 0 in their order (bgm_sum_quadrics),
		 * into the first parent's row, which dies with it below: the sum
		 * reads each entry of it before writing that entry. */
		g->qslot[v] = g->qslot[pl->v[0]];
		bgm_sum_quadrics(g, pl, g->quadric + (size_t)g->qslot[v] * (size_t)g->qpose_count * 10);
		bgm_quadric_rest_reset(g, v);
	}

	/* New wedges. */
	int cw[MAX_PATCH];
	if (vbar_wedges(g, pl, v, cw))
		return -1;

	/* Remove the patch. */
	for (int j = 0; j < pl->nf; j++) {
		bgm_face *f = &g->faces[pl->faces[j]];
		f->death = stamp;
		unsigned queued = g->opstate[pl->faces[j]] >> 4;
		g->heap.dead += (int)(queued & 1u) + (int)(queued >> 1 & 1u) + (int)(queued >> 2 & 1u) + (int)(queued >> 3 & 1u);
		g->opstate[pl->faces[j]] = DEAD;
		for (int k = 0; k < 3; k++)
			bgm_inc_remove(g, f->n[k], pl->faces[j]);
		g->removed[g->removed_len + j] = pl->faces[j];
	}
	for (int i = 0; i < K; i++)
		g->nodes[pl->v[i]].flags |= BGM_DEAD;
	g->live_triangles -= pl->nf;

	/* Re-mesh it around v-bar. */
	int first = g->face_count;
	for (int j = 0; j < pl->nk; j++) {
		const bgm_face *old = &g->faces[pl->kept[j]];
		int w[3];
		for (int k = 0; k < 3; k++)
			w[k] = old->w[k];
		w[pl->corner[j]] = cw[j];
		int f = bgm_add_face(g, w, stamp);
		if (f < 0)
			return -1;
		for (int k = 0; k < 3; k++)
			if (bgm_inc_add(g, g->faces[f].n[k], f))
				return -1;
	}
	g->live_triangles += pl->nk;
	/* The dual graph of the new faces. */
	for (int j = 0; j < pl->nk; j++) {
		int f = first + j, ci = pl->corner[j];
		bgm_face *F = &g->faces[f];
		const bgm_face *old = &g->faces[pl->kept[j]];
		int p = F->n[(ci + 1) % 3], q = F->n[(ci + 2) % 3];
		/* (p, q): the face that was across it, or its replacement. */
		int across = old->adj[(ci + 1) % 3];
		int repl = -1;
		for (int k = 0; k < pl->nk && across >= 0; k++)
			if (pl->kept[k] == across)
				repl = first + k;
		if (repl >= 0) {
			F->adj[(ci + 1) % 3] = repl;
		} else if (across >= 0) {
			F->adj[(ci + 1) % 3] = across;
			bgm_face *A = &g->faces[across];
			for (int k = 0; k < 3; k++)
				if (A->adj[k] == pl->kept[j])
					A->adj[k] = f;
		}
		/* (v-bar, p) and (q, v-bar): the new faces whose links end at p
		 * and start at q. */
		for (int k = 0; k < pl->nk; k++) {
			const bgm_face *G = &g->faces[first + k];
			int ck = pl->corner[k];
			if (G->n[(ck + 2) % 3] == p)
				F->adj[ci] = first + k;
			if (G->n[(ck + 1) % 3] == q)
				F->adj[(ci + 2) % 3] = first + k;
		}
	}

	/* Border flags as the new faces leave them: a collapse along a border
	 * can close a hole, leaving v-bar or a ring vertex inside. */
	/* Each node once (v-bar is a corner of every new face, a ring vertex
	 * of one or two): on_border reads faces, not flags. */
	int seen[2 * MAX_PATCH + 1], ns = 0;
	for (int j = 0; j < pl->nk; j++)
		for (int k = 0; k < 3; k++) {
			int x = g->faces[first + j].n[k], dup = 0;
			for (int i = 0; i < ns && !dup; i++)
				dup = seen[i] == x;
			if (dup)
				continue;
			seen[ns++] = x;
			bgm_node *n = &g->nodes[x];
			if (on_border(g, x))
				n->flags |= BGM_BORDER;
			else
				n->flags &= ~BGM_BORDER;
		}

	mlod_vsplit *r = &g->records[g->record_count++];
	memset(r, 0, sizeof *r);
	for (int i = 0; i < 3; i++)
		r->parents[i] = pl->v[i];
	r->parent_count = K;
	r->node = v;
	r->snapped = pl->snap;
	r->removed_first = g->removed_len;
	r->removed_count = pl->nf;
	r->added_first = first;
	r->added_count = pl->nk;
	r->triangles = g->live_triangles;
	r->capped = pl->capped;
	r->cost = pl->cost;
	g->removed_len += pl->nf;
	g->caps += pl->capped;
	g->snaps += pl->snap >= 0;
	if (bgm_face_arrays_grow(g))
		return -1;
	/* Each new face stands for what the face it replaced stood for. */
	for (int j = 0; j < pl->nk; j++)
		memcpy(g->fref + 4 * (size_t)(first + j), pl->rnormal[j], 4 * sizeof *g->fref);
	return 0;
}
