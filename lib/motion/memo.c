/*
 * memo.c: a memo of values keyed by three ints, by open addressing (at
 * most half full, at most MEMO_MAX slots). The tree (motiontree.c) keeps
 * in it the frame distances (a, b, -1) and residuals (p, x, q) between
 * frames of the common timeline: they depend only on the frames, and the
 * bisection on the threshold rebuilds the tree from the same line many
 * times. The frames method (framesmethod.c) keeps there which segments
 * of its lines are within its bound (p, q, -3).
 */
#include <stdlib.h>
#include <string.h>

#include "motion/motion_internal.h"

#define MEMO_MAX ((size_t)1 << 21) /* slots at most */

static size_t memo_hash(int a, int b, int c)
{
	unsigned long long h = (unsigned)a * 0x9E3779B97F4A7C15ull;
	h ^= (unsigned)b * 0xC2B2AE3D27D4EB4Full + (h >> 29);
	h ^= (unsigned)c * 0x165667B19E3779F9ull + (h >> 31);
	return (size_t)(h ^ (h >> 32));
}

int motion_memo_get(const motion_memo *mo, int a, int b, int c, double *v)
{
	if (!mo->slot)
		return 0;
	for (size_t i = memo_hash(a, b, c) & (mo->cap - 1);; i = (i + 1) & (mo->cap - 1)) {
		const motion_memo_slot *e = &mo->slot[i];
		if (e->a < 0)
			return 0;
		if (e->a == a && e->b == b && e->c == c) {
			*v = e->v;
			return 1;
		}
	}
}

void motion_memo_put(motion_memo *mo, int a, int b, int c, double v)
{
	if (2 * (mo->n + 1) > mo->cap) { /* at most half full */
		size_t cap = mo->cap ? 2 * mo->cap : 4096;
		if (cap > MEMO_MAX)
			return;
		motion_memo_slot *slot = malloc(sizeof *slot * cap);
		if (!slot)
			return;
		for (size_t i = 0; i < cap; i++)
			slot[i].a = -1;
		for (size_t k = 0; k < mo->cap; k++) {
			const motion_memo_slot *e = &mo->slot[k];
			if (e->a < 0)
				continue;
			size_t i = memo_hash(e->a, e->b, e->c) & (cap - 1);
			while (slot[i].a >= 0)
				i = (i + 1) & (cap - 1);
			slot[i] = *e;
		}
		free(mo->slot);
		mo->slot = slot;
		mo->cap = cap;
	}
	size_t i = memo_hash(a, b, c) & (mo->cap - 1);
	while (mo->slot[i].a >= 0)
		i = (i + 1) & (mo->cap - 1);
	mo->slot[i] = (motion_memo_slot){ a, b, c, v };
	mo->n++;
}

void motion_memo_clear(motion_memo *mo)
{
	free(mo->slot);
	memset(mo, 0, sizeof *mo);
}
