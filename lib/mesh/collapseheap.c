/*
 * collapseheap.c: the queue of candidate operations of mlod_bgm_simplify
 * (collapse.c), a 4-ary heap ordered by key, then face, then op (a total
 * order, so the operations come out in the same order whatever the
 * heap's shape), and the slots that keep the exact placement costs of
 * operations put back in it (bgm_memo, collapsecost.c), reused through a
 * free list.
 */
#include <math.h>

#include "collapse.h"

/* As the heap stores it: 16 bytes, four children to a 64-byte line
 * (tag: op in bits 0-1, weak in bit 2, memo + 1 above). */
struct bgm_heap_entry {
	double key;
	int face;
	unsigned tag;
};

/* A slot holding m; returns its index, or -1 when out of memory. */
int bgm_memo_add(struct bgm_heap *h, const bgm_memo *m)
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

void bgm_memo_release(struct bgm_heap *h, int i)
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
int bgm_heap_push(struct bgm_heap *h, double key, int face, int op, int weak, int memo_slot)
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

bgm_heap_item bgm_heap_pop(struct bgm_heap *h)
{
	struct bgm_heap_entry t = h->e[0], x = h->e[--h->count];
	if (h->count > 0)
		sift_down(h, 0, x);
	bgm_heap_item top = {t.key, t.face, (int)(t.tag & 3u), (int)(t.tag >> 2 & 1u), (int)(t.tag >> 3) - 1};
	return top;
}

/* Drops the entries of dead faces (what bgm_heap_pop's callers would drop
 * when they come up) and rebuilds the heap from the rest. Entries are
 * one per face and op and entry_less orders them totally (no NaN key
 * was queued), so the live entries come out in the same order as
 * before; a dead entry popped costs a walk down the heap, this one pass
 * over it. */
void bgm_heap_purge(struct bgm_heap *h, const unsigned char *opstate, unsigned char dead)
{
	int n = 0;
	for (int i = 0; i < h->count; i++) {
		if (opstate[h->e[i].face] == dead) {
			bgm_memo_release(h, (int)(h->e[i].tag >> 3) - 1);
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
