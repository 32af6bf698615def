/*
 * collapse.c: triangle decimation on the BindGraphMesh (Savoye & Meyer
 * 2008, 4.2.3), recorded as a progressive sequence.
 *
 * A triangle collapse contracts t = (a, b, c) into one new vertex v-bar:
 * t and the faces sharing an edge with it go (up to four), and the rest
 * of the mesh patch (the faces sharing a vertex with t) is re-meshed
 * around v-bar. Candidates wait in a priority queue: by compactness
 * 4 sqrt(3) area / (l1^2 + l2^2 + l3^2), lowest first (the paper), or by
 * the posed quadric error of quadric.c (beyond the paper, compactness
 * breaking ties); the faces a collapse creates join the queue.
 *
 * Beyond the paper, with the posed cost, the same machinery collapses an
 * edge (a, b) into v-bar: its two faces go and the rest of the patch is
 * re-meshed. A triangle collapse always merges three vertices into one
 * point, which costs something on any curved surface; an edge collapse
 * along a flat or straight direction costs nothing. Measured (bench/
 * RESULTS.md), edges alone give the lowest posed error, so they are the
 * posed cost's default; MLOD_OP_MIXED queues both, by cost per removed
 * face.
 *
 * The paper does not check validity; a collapse is refused when
 * - a collapsed vertex is locked or not eligible (4.2.2);
 * - two collapsed vertices are on a border but not joined by a border
 *   edge of t (the collapse would pinch the border), three are, or the
 *   border edge bounds a hole of three edges (it would close);
 * - the re-meshed patch would not be one fan around v-bar (the link
 *   condition generalised to a triangle: this also refuses duplicate
 *   faces and the closing of tunnels);
 * - a re-meshed face would be degenerate, turn in the bind pose by more
 *   than ~78 degrees from its current normal, or face more than 90
 *   degrees away from its reference (the normal of the input face it
 *   descends from: each re-meshed face stands for the face it replaces,
 *   so turns cannot add up over collapses to an inside-out face) or from
 *   the sum of its corners' NORMAL attribute (v-bar's as bgm_apply() makes
 *   it): what a renderer culls and shades;
 * - the attribute wedges of the patch cannot be carried over: at a
 *   texture seam (wedges differing in more than normals), v-bar snaps
 *   onto a seam (or, with a border, border) vertex s, and every wedge
 *   group (wedges joined through the removed faces) must hold exactly one
 *   wedge of s and at most one of each other vertex. Elsewhere v-bar gets
 *   one wedge interpolated inside t (along the edge), the corners of a
 *   vertex with hard normal edges keeping their own normals: every wedge
 *   of a flat-shaded vertex collapses the same way. So seams neither tear
 *   nor smear.
 * Open borders stay where they are: a collapse moving a border vertex
 * puts v-bar on a border vertex, or for an edge along the border also at
 * its midpoint, and the border planes of quadric.c price it. With the
 * posed cost a collapse along the border (two border vertices: the
 * border's shape changes) ranks with the rest at BORDER_PENALTY times its
 * cost (1 with mlod_bgm_options.allow_border); one whose only border
 * vertex stays put costs what it costs. The compactness cost, which
 * cannot price them, lets border collapses in only once nothing else
 * collapses. When the queue empties, every live face is queued once
 * more, so that the sequence ends where no valid collapse is left.
 * v-bar goes to t's barycenter (the paper) or to the posed quadric's
 * optimum (or the barycenter, or for an edge either end, when that is
 * cheaper), or with MLOD_PLACE_VERTEX to the cheapest of the collapsed
 * vertices that keeps every wedge group whole, snapped (its wedges and
 * influences copied as they are, so coarse levels reuse its vertices);
 * MLOD_PLACE_HYBRID weighs both per collapse: the cheapest whole vertex
 * when its posed cost is at most the cheapest other placement's, or at
 * most the square of hybrid_error percent of the diagonal (the cost being
 * a mean squared distance over the patch and the poses), else that other
 * placement (the collapse costing what the chosen placement costs);
 * otherwise Power Skinning
 * (powerskin.c) gives its weights, the same barycentric weights as its
 * attributes give its morph target offsets.
 *
 * Each collapse appends one vertex-split record (the faces it removed
 * and the faces it added), so any prefix of the sequence is a valid mesh
 * and can be rebuilt, undone or redone.
 *
 * This file holds the queue (a 4-ary heap ordered by key, then face,
 * then op: a total order, so the operations come out in the same order
 * whatever the heap's shape) and its loop: which operations are queued,
 * and what happens to one when it is popped. collapse.h maps the other
 * files: the lower bounds the queue is keyed by (lowerbound.c), the plan
 * (collapseplan.c) and its application (collapseapply.c).
 */
#include <stdlib.h>

#include "collapse.h"

/* A queued operation, as the heap hands it back. */
typedef struct heap_entry {
	double key;
	int face;
	int op;
	int weak;   /* key is bgm_lower_key's bind-pose bound: bgm_exact_bound comes next */
	int memo;   /* into heap.memo, or -1 */
} heap_entry;

/* As the heap stores it: 16 bytes, four children to a 64-byte line
 * (tag: op in bits 0-1, weak in bit 2, memo + 1 above). */
struct bgm_heap_entry {
	double key;
	int face;
	unsigned tag;
};

/* A slot holding m; returns its index, or -1 when out of memory. */
static int memo_add(struct bgm_heap *h, const bgm_memo *m)
{
	int i = h->memo_free;
	if (i >= 0) {
		h->memo_free = h->memo[i].next_free;
	} else {
		if (bgm_grow((void **)&h->memo, &h->memo_cap, h->memo_count + 1, sizeof *h->memo))
			return -1;
		i = h->memo_count++;
	}
	h->memo[i] = *m;
	h->memo[i].next_free = -1;
	return i;
}

static void memo_release(struct bgm_heap *h, int i)
{
	if (i < 0)
		return;
	h->memo[i].next_free = h->memo_free;
	h->memo_free = i;
}

/* The queue's order: key, then face, then op (a total order, so the
 * operations come out in the same order whatever the heap's shape). */
static int entry_less(const struct bgm_heap_entry *a, const struct bgm_heap_entry *b)
{
	return a->key < b->key ||
	       (a->key == b->key && (a->face < b->face || (a->face == b->face && (a->tag & 3u) < (b->tag & 3u))));
}

/* A 4-ary heap: half the levels of a binary one, its entries' cache
 * misses being what a large mesh's collapses wait on. */
static int heap_push(struct bgm_heap *h, double key, int face, int op, int weak, int memo_slot)
{
	if (bgm_grow((void **)&h->e, &h->cap, h->count + 1, sizeof *h->e))
		return -1;
	int i = h->count++;
	struct bgm_heap_entry x = {key, face, (unsigned)op | (weak ? 4u : 0u) | (unsigned)(memo_slot + 1) << 3};
	if (isnan(key))
		h->unordered = 1;
	while (i > 0) {
		int p = (i - 1) / 4;
		if (!entry_less(&x, &h->e[p]))
			break;
		h->e[i] = h->e[p];
		i = p;
	}
	h->e[i] = x;
	return 0;
}

/* Puts x at slot i of the 4-ary heap or below it, moving the least
 * child up while it is less than x. */
static void sift_down(struct bgm_heap *h, int i, struct bgm_heap_entry x)
{
	const int n = h->count;
	for (;;) {
		int c = 4 * i + 1, m = c;
		if (c >= n)
			break;
		int end = c + 4 < n ? c + 4 : n;
		for (int j = c + 1; j < end; j++)
			if (entry_less(&h->e[j], &h->e[m]))
				m = j;
		if (!entry_less(&h->e[m], &x))
			break;
		h->e[i] = h->e[m];
		i = m;
	}
	h->e[i] = x;
}

static heap_entry heap_pop(struct bgm_heap *h)
{
	struct bgm_heap_entry t = h->e[0], x = h->e[--h->count];
	if (h->count > 0)
		sift_down(h, 0, x);
	heap_entry top = {t.key, t.face, (int)(t.tag & 3u), (int)(t.tag >> 2 & 1u), (int)(t.tag >> 3) - 1};
	return top;
}

/* Drops the entries of dead faces (what heap_pop's callers would drop
 * when they come up) and rebuilds the heap from the rest. Entries are
 * one per face and op and entry_less orders them totally (no NaN key
 * was queued), so the live entries come out in the same order as
 * before; a dead entry popped costs a walk down the heap, this one pass
 * over it. */
static void heap_purge(struct bgm_heap *h, const unsigned char *opstate, unsigned char dead)
{
	int n = 0;
	for (int i = 0; i < h->count; i++) {
		if (opstate[h->e[i].face] == dead) {
			memo_release(h, (int)(h->e[i].tag >> 3) - 1);
			continue;
		}
		h->e[n++] = h->e[i];
	}
	h->count = n;
	h->dead = 0;
	h->purges++;
	for (int s = n > 1 ? (n - 2) / 4 : -1; s >= 0; s--)
		sift_down(h, s, h->e[s]);
}

/* 1 when the queue takes lower bounds of the posed cost (bgm_lower_key) and
 * plans an operation only when it is popped. */
static int lazy_keys(const mlod_bgm *g)
{
	return g->opt.cost == MLOD_COST_POSED && g->rquad && g->pose_count > 0 && g->opt.op != MLOD_OP_MIXED;
}

/* Queues operation op on face f (new, or back from being blocked). */
static int push_op(mlod_bgm *g, int f, int op, bgm_plan *scratch)
{
	const bgm_face *F = &g->faces[f];
	for (int i = 0; i < 3; i++) {
		if (op != OP_TRIANGLE && i != op && i != (op + 1) % 3)
			continue;
		int fl = g->nodes[F->n[i]].flags;
		if ((fl & BGM_LOCKED) || !(fl & BGM_ELIGIBLE) || (!bgm_borders_ok(g) && (fl & BGM_BORDER)))
			return 0; /* never collapsible while these nodes live */
	}
	double key;
	int weak = 0;
	if (lazy_keys(g)) {
		key = bgm_lower_key(g, f, op, &weak);
	} else if (g->opt.cost == MLOD_COST_POSED) {
		if (!bgm_plan_op(g, f, op, !g->opt.fast_cost, scratch, NULL)) {
			g->opstate[f] |= (unsigned char)BLOCKED(op);
			return 0;
		}
		key = scratch->cost;
	} else {
		key = bgm_compactness(g->nodes[F->n[0]].p, g->nodes[F->n[1]].p, g->nodes[F->n[2]].p);
	}
	g->opstate[f] |= (unsigned char)QUEUED(op);
	return heap_push(&g->heap, key, f, op, weak, -1);
}

/* 1 when the face across edge e of face f holds a queue entry for that
 * edge. An edge has two faces and is queued from one of them. */
BGM_INLINE int queued_across(const mlod_bgm *g, int f, int e)
{
	const bgm_face *F = &g->faces[f];
	int across = F->adj[e];
	if (across < 0)
		return 0;
	const bgm_face *A = &g->faces[across];
	for (int k = 0; k < 3; k++)
		if (A->n[k] == F->n[(e + 1) % 3] && A->n[(k + 1) % 3] == F->n[e])
			return (g->opstate[across] & QUEUED(k)) != 0;
	return 0;
}

/* Queues face f's triangle collapse and its edges, as the option asks,
 * except edges the face across has queued. The queue is lazy: a popped
 * entry is planned (with the posed cost, queued under bgm_lower_key's bound,
 * for the first time) and goes back with its cost when that is above its
 * key; one whose cost fell (its neighbourhood changed which placements
 * are valid) waits at its old key, an approximation that saves
 * re-planning every operation around each collapse. */
static int push_face(mlod_bgm *g, int f, bgm_plan *scratch)
{
	if (g->opt.op != MLOD_OP_EDGE && push_op(g, f, OP_TRIANGLE, scratch))
		return -1;
	if (g->opt.op == MLOD_OP_TRIANGLE)
		return 0;
	for (int e = 0; e < 3; e++)
		if (!queued_across(g, f, e) && push_op(g, f, e, scratch))
			return -1;
	return 0;
}

mlod_result mlod_bgm_simplify(mlod_bgm *g, int target, int max_collapses, mlod_error *err)
{
	if (!g)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_bgm_simplify: NULL");
	if (g->released)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_bgm_simplify: the collapse state was released (the chain is final)");
	double t0 = bgm_seconds();
	mlod_result r = MLOD_OK;
	bgm_plan *pl = malloc(sizeof *pl), *scratch = malloc(sizeof *scratch);
	if (!g->qsum && g->pose_count > 0)
		g->qsum = malloc(sizeof(double) * 10 * (size_t)g->pose_count);
	if (!pl || !scratch || bgm_face_arrays_grow(g) || (g->pose_count > 0 && !g->qsum)) {
		r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory simplifying");
		goto done;
	}
	if (!g->heap.ready) {
		g->heap.ready = 1;
		g->swept = g->record_count;
		g->heap.memo_free = -1;
		for (int f = 0; f < g->face_count; f++)
			if (g->faces[f].death == BGM_ALIVE && push_face(g, f, scratch)) {
				r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory simplifying");
				goto done;
			}
	}
	int done_count = 0;
	while ((target <= 0 || g->live_triangles > target) && (max_collapses <= 0 || done_count < max_collapses)) {
		if (g->heap.count == 0) {
			/* Nothing else collapses: without --allow-border, open borders
			 * go last (every prefix before is what it was without them).
			 * Every live face is queued again, border collapses with it. */
			if (!bgm_borders_ok(g) && g->border_edges > 0)
				g->border_phase = 1;
			else if (g->record_count == g->swept)
				break;
			g->swept = g->record_count;
			g->heap.dead = 0;
			for (int f = 0; f < g->opstate_cap; f++)
				g->opstate[f] = f < g->face_count && g->faces[f].death != BGM_ALIVE ? DEAD : 0;
			for (int f = 0; f < g->face_count; f++)
				if (g->faces[f].death == BGM_ALIVE && push_face(g, f, scratch)) {
					r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory simplifying");
					goto done;
				}
			continue;
		}
		/* Mostly dead entries: drop them at once (the same order). */
		if (g->heap.dead > 256 && 2 * g->heap.dead > g->heap.count && !g->heap.unordered && !g->heap.no_purge) {
			heap_purge(&g->heap, g->opstate, DEAD);
			continue;
		}
		heap_entry e = heap_pop(&g->heap);
		if (g->opstate[e.face] == DEAD) {
			g->heap.dead -= g->heap.dead > 0;
			memo_release(&g->heap, e.memo);
			continue;
		}
		/* An operation going back keeps what its placements cost. */
		bgm_memo local, *mm = e.memo >= 0 ? &g->heap.memo[e.memo] : &local;
		if (e.memo < 0) {
			/* Nothing known: the rest is read only once its bit says it
			 * was written (not cleared at every pop: w[] is large). */
			local.opt_state = 0;
			local.known = local.skinned = local.stopped = 0;
			local.next_free = -1;
		}
		double back = -1.0;
		if (e.weak) {
			double b = bgm_exact_bound(g, e.face, e.op, mm);
			if (b > e.key * (1.0 + 1e-9) + 1e-300)
				back = b;
		}
		if (back < 0.0) {
			g->opstate[e.face] &= (unsigned char)~QUEUED(e.op);
			if (!bgm_plan_op(g, e.face, e.op, !g->opt.fast_cost, pl, g->opt.fast_cost ? NULL : mm)) {
				memo_release(&g->heap, e.memo);
				g->refused++;
				g->opstate[e.face] |= (unsigned char)BLOCKED(e.op);
				continue;
			}
			if (g->opt.cost == MLOD_COST_POSED && pl->cost > e.key * (1.0 + 1e-9) + 1e-300) {
				g->opstate[e.face] |= (unsigned char)QUEUED(e.op);
				back = pl->cost;
			}
		}
		if (back >= 0.0) {
			int slot = e.memo;
			if (slot < 0 && !g->opt.fast_cost && (slot = memo_add(&g->heap, &local)) < 0) {
				r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory simplifying");
				goto done;
			}
			if (heap_push(&g->heap, back, e.face, e.op, 0, slot)) {
				r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory simplifying");
				goto done;
			}
			continue;
		}
		memo_release(&g->heap, e.memo);
		int first = g->face_count;
		if (bgm_apply(g, pl)) {
			r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory simplifying");
			goto done;
		}
		done_count++;
		g->records[g->record_count - 1].seconds = g->collapse_seconds + (bgm_seconds() - t0);
		/* Queue the new faces, and give blocked faces around the patch
		 * another chance: their neighbourhood changed. */
		for (int f = first; f < g->face_count; f++)
			if (push_face(g, f, scratch)) {
				r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory simplifying");
				goto done;
			}
		int v = g->node_count - 1;
		const bgm_node *N = &g->nodes[v];
		for (int k = 0; k < N->inc_count; k++) {
			const bgm_face *F = &g->faces[g->inc[N->inc_first + k]];
			for (int i = 0; i < 3; i++) {
				if (F->n[i] == v)
					continue;
				int ring = F->n[i];
				const bgm_node *L = &g->nodes[ring];
				for (int m = 0; m < L->inc_count; m++) {
					int h = g->inc[L->inc_first + m];
					if (h >= first || !(g->opstate[h] & ALL_BLOCKED))
						continue;
					/* Its triangle, and its edges that end at the ring
					 * vertex (the others' patches did not change). */
					const bgm_face *H = &g->faces[h];
					unsigned retry = BLOCKED(OP_TRIANGLE);
					for (int e = 0; e < 3; e++)
						if (H->n[e] == ring || H->n[(e + 1) % 3] == ring)
							retry |= BLOCKED(e);
					unsigned bits = g->opstate[h] & retry;
					g->opstate[h] &= (unsigned char)~retry;
					for (int op = 0; op <= OP_TRIANGLE; op++)
						if ((bits >> op & 1u) && (op == OP_TRIANGLE || !queued_across(g, h, op)) &&
						    push_op(g, h, op, scratch)) {
							r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory simplifying");
							goto done;
						}
				}
			}
		}
	}
done:
	free(pl);
	free(scratch);
	g->collapse_seconds += bgm_seconds() - t0;
	return r;
}
