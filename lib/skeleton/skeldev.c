/*
 * skeldev.c: the skinned-vertex deviation of a skeleton level
 * (mlod_skel_vertex_deviation, mlod_skeleton.h): mlod_vertex_deviation's
 * numbers, bit for bit, without posing what the level leaves in place.
 *
 * A level copies the meshes and keeps most joints as they were: a kept
 * joint whose ancestors are all kept has the same rest transform and the
 * same channels, so the same world and skin matrices at every time, and a
 * vertex whose weights were not transferred has the same weights. Such a
 * vertex is skinned by the same operations on the same bits in both
 * characters (mlod_skin_vertex), so its deviation is exactly 0: it is
 * counted, and adding 0 to the sum changes nothing. Whether the matrices
 * are equal is checked bit for bit at each time, not assumed from the
 * skeleton; only the other vertices are skinned, in both characters,
 * and a's positions can be kept for the next level (the cache).
 */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "skeleton/mlod_skeleton.h"

static long prim_triangles(const mlod_primitive *p)
{
	if (p->mode != 4 || p->vertex_count <= 0)
		return 0;
	return (p->index_count > 0 ? p->index_count : p->vertex_count) / 3;
}

static int instance_valid(const mlod_character *c, const mlod_instance *in)
{
	const mlod_skeleton *s = &c->skeleton;
	return in->mesh >= 0 && in->mesh < c->mesh_count && in->skin >= -1 && in->skin < s->skin_count &&
	       in->joint >= -1 && in->joint < s->joint_count;
}

/* 1 when b has a's instances and primitives (what mlod_skel_level_apply
 * makes): then the vertices pose in the same order in both. */
static int same_layout(const mlod_character *a, const mlod_character *b)
{
	if (a->instance_count != b->instance_count || a->clip_count != b->clip_count)
		return 0;
	for (int i = 0; i < a->instance_count; i++) {
		const mlod_instance *ia = &a->instances[i], *ib = &b->instances[i];
		if (!instance_valid(a, ia) || !instance_valid(b, ib) || ia->mesh != ib->mesh ||
		    (ia->skin >= 0) != (ib->skin >= 0))
			return 0;
		const mlod_mesh *ma = &a->meshes[ia->mesh], *mb = &b->meshes[ib->mesh];
		if (ma->primitive_count != mb->primitive_count)
			return 0;
		for (int p = 0; p < ma->primitive_count; p++) {
			const mlod_primitive *pa = &ma->primitives[p], *pb = &mb->primitives[p];
			if (pa->vertex_count != pb->vertex_count || pa->mode != pb->mode || pa->index_count != pb->index_count ||
			    prim_triangles(pa) != prim_triangles(pb))
				return 0;
			if (prim_triangles(pa) > 0 && memcmp(pa->positions, pb->positions, sizeof(float) * 3 * (size_t)pa->vertex_count))
				return 0;
		}
	}
	return 1;
}

/* The next influence of vertex v at or after slot *k (weight > 0), or -1. */
static int next_influence(const mlod_primitive *p, int v, int *k, float *w)
{
	for (; *k < 4 * p->weight_set_count; ++*k) {
		float x = p->weights[*k / 4][4 * v + *k % 4];
		if (x > 0.0f) {
			int j = p->joints[*k / 4][4 * v + *k % 4];
			*w = x;
			++*k;
			return j;
		}
	}
	return -1;
}

static int finite_position(const mlod_primitive *p, int v)
{
	return isfinite(p->positions[3 * v]) && isfinite(p->positions[3 * v + 1]) && isfinite(p->positions[3 * v + 2]);
}

/* 1 when vertex v has, in a and in b, the same finite position (b's is a
 * copy: same_layout) and the same finite weights in the same order; then
 * pairs[0..*n) gets the pairs of skin-local joints they weigh, as indices
 * ka * nb + kb into a table of a's skin (na joints) by b's (nb). */
static int same_weights(const mlod_primitive *pa, const mlod_primitive *pb, int v, int na, int nb, uint32_t *pairs,
                        int *n)
{
	*n = 0;
	if (!finite_position(pa, v))
		return 0;
	int ka = 0, kb = 0;
	for (;;) {
		float wa = 0.0f, wb = 0.0f;
		int ja = next_influence(pa, v, &ka, &wa), jb = next_influence(pb, v, &kb, &wb);
		if (ja < 0 || jb < 0)
			return ja < 0 && jb < 0;
		if (memcmp(&wa, &wb, sizeof wa) != 0 || !isfinite(wa) || ja >= na || jb >= nb)
			return 0;
		pairs[(*n)++] = (uint32_t)ja * (uint32_t)nb + (uint32_t)jb;
	}
}

/* Pairs of skin matrices (a's local ka, b's local kb) compared at this
 * time: 0 not yet, 1 equal and finite, 2 otherwise. */
struct pairs {
	const mlod_mat4 *ma, *mb;
	int nb;
	unsigned char *state;
};

static int pair_equal(struct pairs *q, uint32_t pair)
{
	unsigned char *s = &q->state[pair];
	if (*s == 0) {
		const mlod_mat4 *x = &q->ma[pair / (uint32_t)q->nb], *y = &q->mb[pair % (uint32_t)q->nb];
		*s = 2;
		if (memcmp(x, y, sizeof(mlod_mat4)) == 0) {
			*s = 1;
			for (int e = 0; e < 16; e++)
				if (!isfinite(x->m[e]))
					*s = 2;
		}
	}
	return *s == 1;
}

static void pose_at(const mlod_character *c, int k, float t, mlod_trs *local, mlod_mat4 *world)
{
	mlod_pose_rest(&c->skeleton, local);
	if (k >= 0)
		mlod_clip_sample(&c->clips[k], t, local);
	mlod_pose_world(&c->skeleton, local, world);
}

/* The rest-pose bounding-box diagonal of c's posed vertices, as
 * mlod_vertex_deviation takes it. */
static mlod_result rest_diagonal(const mlod_character *c, const mlod_mat4 *world, double *diag, mlod_error *err)
{
	mlod_posed posed = {0};
	mlod_result r = mlod_pose_character(c, world, &posed, err);
	if (r != MLOD_OK)
		return r;
	float lo[3] = {FLT_MAX, FLT_MAX, FLT_MAX}, hi[3] = {-FLT_MAX, -FLT_MAX, -FLT_MAX};
	for (int i = 0; i < posed.vertex_count; i++)
		for (int e = 0; e < 3; e++) {
			lo[e] = fminf(lo[e], posed.positions[3 * i + e]);
			hi[e] = fmaxf(hi[e], posed.positions[3 * i + e]);
		}
	*diag = 0.0;
	if (posed.vertex_count > 0) {
		double dx = hi[0] - lo[0], dy = hi[1] - lo[1], dz = hi[2] - lo[2];
		*diag = sqrt(dx * dx + dy * dy + dz * dz);
	}
	mlod_posed_free(&posed);
	return MLOD_OK;
}

struct dev_work {
	mlod_trs *la, *lb;
	mlod_mat4 *wa, *wb, *sa, *sb;
	unsigned char *state;
	int *group;      /* per vertex: its group of pairs (same_weights), or -1 */
	int *run;        /* per vertex: how many vertices from it on have its group, in its primitive */
	int *first;      /* per group: its first pair; group g's are first[g]..first[g + 1] */
	uint32_t *pairs;
	int *hash;       /* open addressing over the groups of one instance */
	unsigned char *equal; /* per group, at this time: all its pairs are equal */
	int *groups_of;  /* instance i's groups are groups_of[i]..groups_of[i + 1] */
	float *times;
};

static void work_free(struct dev_work *w)
{
	free(w->la), free(w->lb), free(w->run), free(w->wa), free(w->wb), free(w->sa), free(w->sb);
	free(w->state), free(w->group), free(w->first), free(w->pairs), free(w->hash), free(w->equal), free(w->groups_of);
	free(w->times);
}

/* The cache: a's skinned positions at the measured times of each clip,
 * filled as vertices are skinned; at most MLOD_SKEL_CACHE_BYTES. */
struct mlod_skel_pose_cache {
	const mlod_character *a;
	int max_samples;
	size_t vertices;
	size_t bytes;
	int clip_count;
	float **pos;          /* per clip (or the one rest pose): times * vertices * 3 */
	unsigned char **have; /* per clip: times * vertices, 1 where pos is filled */
};

mlod_skel_pose_cache *mlod_skel_pose_cache_new(void)
{
	return calloc(1, sizeof(mlod_skel_pose_cache));
}

void mlod_skel_pose_cache_free(mlod_skel_pose_cache *cache)
{
	if (!cache)
		return;
	for (int k = 0; k < cache->clip_count; k++) {
		free(cache->pos[k]);
		free(cache->have[k]);
	}
	free(cache->pos);
	free(cache->have);
	free(cache);
}

/* Clip k's part of the cache (k < 0: the rest pose), n times, or NULL
 * (no cache, another character, over budget, out of memory). */
static int cache_clip(mlod_skel_pose_cache *cache, const mlod_character *a, int max_samples, size_t vertices, int k,
                      int n, float **pos, unsigned char **have)
{
	*pos = NULL;
	*have = NULL;
	if (!cache)
		return 0;
	if (!cache->pos) {
		int clips = a->clip_count > 0 ? a->clip_count : 1;
		cache->pos = calloc((size_t)clips, sizeof *cache->pos);
		cache->have = calloc((size_t)clips, sizeof *cache->have);
		if (!cache->pos || !cache->have) {
			free(cache->pos), free(cache->have);
			cache->pos = NULL, cache->have = NULL;
			return 0;
		}
		cache->a = a;
		cache->max_samples = max_samples;
		cache->vertices = vertices;
		cache->clip_count = clips;
	}
	if (cache->a != a || cache->max_samples != max_samples || cache->vertices != vertices)
		return 0;
	int slot = k < 0 ? 0 : k;
	if (!cache->pos[slot]) {
		size_t entries = (size_t)n * vertices;
		size_t bytes = entries * (3 * sizeof(float) + 1);
		if (vertices == 0 || entries / vertices != (size_t)n || cache->bytes + bytes > MLOD_SKEL_CACHE_BYTES)
			return 0;
		cache->pos[slot] = malloc(entries * 3 * sizeof(float));
		cache->have[slot] = calloc(entries, 1);
		if (!cache->pos[slot] || !cache->have[slot]) {
			free(cache->pos[slot]), free(cache->have[slot]);
			cache->pos[slot] = NULL, cache->have[slot] = NULL;
			return 0;
		}
		cache->bytes += bytes;
	}
	*pos = cache->pos[slot];
	*have = cache->have[slot];
	return 1;
}

mlod_result mlod_skel_vertex_deviation(const mlod_character *a, const mlod_character *b, int max_samples,
                                       mlod_skel_pose_cache *cache, mlod_deviation *out, mlod_error *err)
{
	memset(out, 0, sizeof *out);
	if (!same_layout(a, b))
		return mlod_vertex_deviation(a, b, max_samples, out, err);

	/* Buffers: poses, the largest skins, the pair table, the vertex flags. */
	size_t ja = (size_t)(a->skeleton.joint_count > 0 ? a->skeleton.joint_count : 1);
	size_t jb = (size_t)(b->skeleton.joint_count > 0 ? b->skeleton.joint_count : 1);
	size_t na = 1, nb = 1, vertices = 0;
	for (int i = 0; i < a->instance_count; i++) {
		const mlod_instance *ia = &a->instances[i], *ib = &b->instances[i];
		if (ia->skin >= 0 && (size_t)a->skeleton.skins[ia->skin].joint_count > na)
			na = (size_t)a->skeleton.skins[ia->skin].joint_count;
		if (ib->skin >= 0 && (size_t)b->skeleton.skins[ib->skin].joint_count > nb)
			nb = (size_t)b->skeleton.skins[ib->skin].joint_count;
		const mlod_mesh *m = &a->meshes[ia->mesh];
		for (int p = 0; p < m->primitive_count; p++)
			if (prim_triangles(&m->primitives[p]) > 0)
				vertices += (size_t)m->primitives[p].vertex_count;
	}
	struct dev_work w = {
		.la = malloc(sizeof(mlod_trs) * ja), .lb = malloc(sizeof(mlod_trs) * jb),
		.wa = malloc(sizeof(mlod_mat4) * ja), .wb = malloc(sizeof(mlod_mat4) * jb),
		.sa = malloc(sizeof(mlod_mat4) * na), .sb = malloc(sizeof(mlod_mat4) * nb), .state = malloc(na * nb),
		.group = malloc(sizeof(int) * (vertices + 1)), .run = malloc(sizeof(int) * (vertices + 1)),
		.first = malloc(sizeof(int) * (vertices + 2)),
		.pairs = malloc(sizeof(uint32_t) * (4 * MLOD_MAX_SETS * vertices + 1)), .equal = malloc(vertices + 1),
		.groups_of = malloc(sizeof(int) * ((size_t)a->instance_count + 1))};
	size_t hash_size = 16;
	while (hash_size < 2 * vertices)
		hash_size *= 2;
	w.hash = malloc(sizeof(int) * hash_size);
	mlod_result r = MLOD_OK;
	if (!w.la || !w.lb || !w.wa || !w.wb || !w.sa || !w.sb || !w.state || !w.group || !w.run || !w.first || !w.pairs ||
	    !w.hash || !w.equal || !w.groups_of) {
		r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory measuring deviation");
		goto done;
	}
	/* Which vertices may stay in place (same position and weights), in
	 * groups of the same pairs of skin matrices, per instance. */
	size_t at = 0;
	int groups = 0;
	w.first[0] = 0;
	for (int i = 0; i < a->instance_count; i++) {
		const mlod_instance *ia = &a->instances[i], *ib = &b->instances[i];
		const mlod_mesh *ma = &a->meshes[ia->mesh], *mb = &b->meshes[ib->mesh];
		int skinned = ia->skin >= 0;
		int sna = skinned ? a->skeleton.skins[ia->skin].joint_count : 0;
		int snb = skinned ? b->skeleton.skins[ib->skin].joint_count : 0;
		w.groups_of[i] = groups;
		for (size_t h = 0; h < hash_size; h++)
			w.hash[h] = -1;
		for (int p = 0; p < ma->primitive_count; p++) {
			const mlod_primitive *pa = &ma->primitives[p], *pb = &mb->primitives[p];
			if (prim_triangles(pa) == 0)
				continue;
			size_t base = at;
			for (int v = 0; v < pa->vertex_count; v++, at++) {
				int n = 0;
				uint32_t *list = w.pairs + w.first[groups];
				w.group[at] = -1;
				if (!skinned) {
					w.group[at] = finite_position(pa, v) ? 0 : -1;
					continue;
				}
				if (!same_weights(pa, pb, v, sna, snb, list, &n))
					continue;
				uint32_t h = 2166136261u;
				for (int e = 0; e < n; e++)
					h = (h ^ list[e]) * 16777619u;
				size_t slot = h & (hash_size - 1);
				for (;; slot = (slot + 1) & (hash_size - 1)) {
					int g = w.hash[slot];
					if (g < 0) { /* a new group */
						w.hash[slot] = groups;
						w.group[at] = groups++;
						w.first[groups] = w.first[groups - 1] + n;
						break;
					}
					if (w.first[g + 1] - w.first[g] == n &&
					    memcmp(w.pairs + w.first[g], list, sizeof *list * (size_t)n) == 0) {
						w.group[at] = g;
						break;
					}
				}
			}
			for (size_t e = at; e-- > base;)
				w.run[e] = e + 1 < at && w.group[e + 1] == w.group[e] ? w.run[e + 1] + 1 : 1;
		}
	}
	w.groups_of[a->instance_count] = groups;

	pose_at(a, -1, 0.0f, w.la, w.wa);
	double diag;
	if ((r = rest_diagonal(a, w.wa, &diag, err)) != MLOD_OK)
		goto done;
	if (diag <= 0.0)
		diag = 1.0;
	double sum = 0.0;
	long count = 0;
	for (int k = a->clip_count > 0 ? 0 : -1; k < a->clip_count; k++) {
		int n = 1;
		free(w.times);
		w.times = NULL;
		if (k >= 0 && (n = mlod_clip_times(&a->clips[k], max_samples, &w.times)) < 0) {
			r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory measuring deviation");
			goto done;
		}
		float *cpos;
		unsigned char *chave;
		cache_clip(cache, a, max_samples, vertices, k, n, &cpos, &chave);
		for (int ti = 0; ti < n; ti++) {
			float t = w.times ? w.times[ti] : 0.0f;
			float *tpos = cpos ? cpos + (size_t)ti * vertices * 3 : NULL;
			unsigned char *thave = chave ? chave + (size_t)ti * vertices : NULL;
			pose_at(a, k, t, w.la, w.wa);
			pose_at(b, k, t, w.lb, w.wb);
			at = 0;
			for (int i = 0; i < a->instance_count; i++) {
				const mlod_instance *ia = &a->instances[i], *ib = &b->instances[i];
				const mlod_mesh *ma = &a->meshes[ia->mesh], *mb = &b->meshes[ib->mesh];
				struct pairs q = {w.sa, w.sb, 0, w.state};
				mlod_mat4 ra = ia->offset, rb = ib->offset;
				int rigid_same = 0;
				if (ia->skin >= 0) {
					const mlod_skin *ska = &a->skeleton.skins[ia->skin], *skb = &b->skeleton.skins[ib->skin];
					mlod_skin_matrices(ska, w.wa, w.sa);
					mlod_skin_matrices(skb, w.wb, w.sb);
					q.nb = skb->joint_count;
					memset(w.state, 0, (size_t)ska->joint_count * (size_t)skb->joint_count);
					for (int g = w.groups_of[i]; g < w.groups_of[i + 1]; g++) {
						int e = w.first[g];
						while (e < w.first[g + 1] && pair_equal(&q, w.pairs[e]))
							e++;
						w.equal[g] = e == w.first[g + 1];
					}
				} else {
					if (ia->joint >= 0)
						ra = mlod_mat4_mul(&w.wa[ia->joint], &ia->offset);
					if (ib->joint >= 0)
						rb = mlod_mat4_mul(&w.wb[ib->joint], &ib->offset);
					rigid_same = memcmp(&ra, &rb, sizeof ra) == 0;
					for (int e = 0; e < 16; e++)
						if (!isfinite(ra.m[e]))
							rigid_same = 0;
				}
				for (int p = 0; p < ma->primitive_count; p++) {
					const mlod_primitive *pa = &ma->primitives[p], *pb = &mb->primitives[p];
					if (prim_triangles(pa) == 0)
						continue;
					count += pa->vertex_count;
					for (int v = 0; v < pa->vertex_count; v++, at++) {
						float x[3], y[3];
						if (ia->skin >= 0) {
							if (w.group[at] >= 0 && w.equal[w.group[at]]) {
								/* deviation 0, and for the rest of the run */
								v += w.run[at] - 1;
								at += (size_t)w.run[at] - 1;
								continue;
							}
							if (thave && thave[at]) {
								memcpy(x, tpos + 3 * at, sizeof x);
							} else {
								mlod_skin_vertex(pa, v, w.sa, x);
								if (thave) {
									memcpy(tpos + 3 * at, x, sizeof x);
									thave[at] = 1;
								}
							}
							mlod_skin_vertex(pb, v, w.sb, y);
						} else {
							if (rigid_same && w.group[at] >= 0) {
								v += w.run[at] - 1;
								at += (size_t)w.run[at] - 1;
								continue;
							}
							const float *s = pa->positions + 3 * v, *u = pb->positions + 3 * v;
							mlod_v3 px = mlod_mat4_point(&ra, (mlod_v3){s[0], s[1], s[2]});
							mlod_v3 py = mlod_mat4_point(&rb, (mlod_v3){u[0], u[1], u[2]});
							x[0] = px.x, x[1] = px.y, x[2] = px.z;
							y[0] = py.x, y[1] = py.y, y[2] = py.z;
						}
						double dx = x[0] - y[0], dy = x[1] - y[1], dz = x[2] - y[2];
						double d = sqrt(dx * dx + dy * dy + dz * dz);
						sum += d;
						if (d > out->max)
							out->max = d;
					}
				}
			}
		}
	}
	out->mean = count ? 100.0 * sum / (double)count / diag : 0.0;
	out->max = 100.0 * out->max / diag;
	out->scale = diag;
done:
	work_free(&w);
	return r;
}
