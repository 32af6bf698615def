/*
 * compare.c: measures how far a level strays from the full character, over
 * the clips: skinned-vertex deviation (same mesh, other skeleton, weights
 * or keys) and joint position deviation (skeleton-only input).
 */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "measure/mlod_measure.h"

int mlod_clip_times(const mlod_clip *clip, int max_samples, float **times)
{
	/* The frames, or the key times (mlod_clip_key_times) and time 0. */
	float *t = NULL;
	int n = mlod_clip_key_times(clip, NULL, 1, &t, NULL);
	if (n < 0)
		return -1;
	int at = 0;
	while (at < n && t[at] < 0.0f)
		at++;
	if (at == n || t[at] != 0.0f) {
		float *g = realloc(t, sizeof(float) * ((size_t)n + 1));
		if (!g) {
			free(t);
			return -1;
		}
		t = g;
		memmove(t + at + 1, t + at, sizeof(float) * (size_t)(n - at));
		t[at] = 0.0f;
		n++;
	}
	if (max_samples > 1 && n > max_samples) {
		/* Evenly spaced picks, first and last included. */
		for (int i = 0; i < max_samples; i++)
			t[i] = t[(int)((long)i * (n - 1) / (max_samples - 1))];
		n = max_samples;
	}
	*times = t;
	return n;
}

/* Per-time pose buffers for one character. */
struct poser {
	const mlod_character *c;
	mlod_trs *local;
	mlod_mat4 *world;
	mlod_posed posed;
};

static int poser_init(struct poser *p, const mlod_character *c)
{
	size_t n = (size_t)(c->skeleton.joint_count > 0 ? c->skeleton.joint_count : 1);
	memset(p, 0, sizeof *p);
	p->c = c;
	p->local = malloc(sizeof *p->local * n);
	p->world = malloc(sizeof *p->world * n);
	return p->local && p->world ? 0 : -1;
}

static void poser_free(struct poser *p)
{
	free(p->local);
	free(p->world);
	mlod_posed_free(&p->posed);
}

/* Poses the character at time t of clip k (k < 0: the rest pose). */
static void poser_world(struct poser *p, int k, float t)
{
	mlod_pose_rest(&p->c->skeleton, p->local);
	if (k >= 0)
		mlod_clip_sample(&p->c->clips[k], t, p->local);
	mlod_pose_world(&p->c->skeleton, p->local, p->world);
}

static double bbox_diagonal(const float *pos, int n)
{
	float lo[3] = {FLT_MAX, FLT_MAX, FLT_MAX}, hi[3] = {-FLT_MAX, -FLT_MAX, -FLT_MAX};
	for (int i = 0; i < n; i++) {
		for (int a = 0; a < 3; a++) {
			lo[a] = fminf(lo[a], pos[3 * i + a]);
			hi[a] = fmaxf(hi[a], pos[3 * i + a]);
		}
	}
	if (n == 0)
		return 0.0;
	double dx = hi[0] - lo[0], dy = hi[1] - lo[1], dz = hi[2] - lo[2];
	return sqrt(dx * dx + dy * dy + dz * dz);
}

mlod_result mlod_vertex_deviation(const mlod_character *a, const mlod_character *b, int max_samples,
                                  mlod_deviation *out, mlod_error *err)
{
	struct poser pa, pb;
	mlod_result r = MLOD_OK;
	float *times = NULL;
	memset(out, 0, sizeof *out);
	if (a->clip_count != b->clip_count)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "the characters have %d and %d clips", a->clip_count,
		                 b->clip_count);
	if (poser_init(&pa, a) != 0 || poser_init(&pb, b) != 0) {
		r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory measuring deviation");
		goto done;
	}
	poser_world(&pa, -1, 0.0f);
	if ((r = mlod_pose_character(a, pa.world, &pa.posed, err)) != MLOD_OK)
		goto done;
	double diag = bbox_diagonal(pa.posed.positions, pa.posed.vertex_count);
	if (diag <= 0.0)
		diag = 1.0;
	double sum = 0.0;
	long count = 0;
	for (int k = a->clip_count > 0 ? 0 : -1; k < a->clip_count; k++) {
		int n = 1;
		free(times);
		times = NULL;
		if (k >= 0 && (n = mlod_clip_times(&a->clips[k], max_samples, &times)) < 0) {
			r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory measuring deviation");
			goto done;
		}
		for (int i = 0; i < n; i++) {
			float t = times ? times[i] : 0.0f;
			poser_world(&pa, k, t);
			poser_world(&pb, k, t);
			if ((r = mlod_pose_character(a, pa.world, &pa.posed, err)) != MLOD_OK ||
			    (r = mlod_pose_character(b, pb.world, &pb.posed, err)) != MLOD_OK)
				goto done;
			if (pa.posed.vertex_count != pb.posed.vertex_count) {
				r = mlod_fail(err, MLOD_ERR_INVALID_ARG, "the characters pose %d and %d vertices",
				              pa.posed.vertex_count, pb.posed.vertex_count);
				goto done;
			}
			for (int v = 0; v < pa.posed.vertex_count; v++) {
				const float *x = pa.posed.positions + 3 * v, *y = pb.posed.positions + 3 * v;
				double dx = x[0] - y[0], dy = x[1] - y[1], dz = x[2] - y[2];
				double d = sqrt(dx * dx + dy * dy + dz * dz);
				sum += d;
				count++;
				if (d > out->max)
					out->max = d;
			}
		}
	}
	out->mean = count ? 100.0 * sum / (double)count / diag : 0.0;
	out->max = 100.0 * out->max / diag;
	out->scale = diag;
done:
	free(times);
	poser_free(&pa);
	poser_free(&pb);
	return r;
}

/* mlod_joint_deviation at the times of each clip (mlod_clip_times), or at
 * the at_count times `at` when at is not NULL. */
static mlod_result joint_deviation(const mlod_character *a, const mlod_character *b, const int *stand_in,
                                   const int *a_to_b, int max_samples, const float *at, int at_count,
                                   mlod_deviation *out, mlod_error *err)
{
	const mlod_skeleton *s = &a->skeleton;
	int n = s->joint_count;
	struct poser pa, pb;
	mlod_result r = MLOD_OK;
	float *times = NULL;
	mlod_mat4 *rel = malloc(sizeof *rel * (size_t)(n > 0 ? n : 1));
	int *carrier = malloc(sizeof(int) * (size_t)(n > 0 ? n : 1));
	memset(out, 0, sizeof *out);
	if (a->clip_count != b->clip_count)
		r = mlod_fail(err, MLOD_ERR_INVALID_ARG, "the characters have %d and %d clips", a->clip_count,
		              b->clip_count);
	if (poser_init(&pa, a) != 0 || poser_init(&pb, b) != 0 || !rel || !carrier)
		r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory measuring deviation");
	if (r != MLOD_OK)
		goto done;
	/* carrier[j]: the joint of b that carries j; rel[j]: j in the frame of
	 * its stand-in, from a's rest pose. */
	poser_world(&pa, -1, 0.0f);
	for (int j = 0; j < n; j++) {
		int sa = stand_in ? stand_in[j] : j;
		carrier[j] = sa >= 0 ? (a_to_b ? a_to_b[sa] : sa) : -1;
		if (carrier[j] >= b->skeleton.joint_count) {
			r = mlod_fail(err, MLOD_ERR_INVALID_ARG, "joint %d maps past the other skeleton", j);
			goto done;
		}
		rel[j] = mlod_mat4_identity();
		mlod_mat4 inv;
		if (sa >= 0 && sa != j && mlod_mat4_invert(&pa.world[sa], &inv) == 0)
			rel[j] = mlod_mat4_mul(&inv, &pa.world[j]);
	}
	double sum = 0.0;
	long count = 0;
	for (int k = 0; k < a->clip_count; k++) {
		int nt = at ? at_count : mlod_clip_times(&a->clips[k], max_samples, &times);
		const float *tk = at ? at : times;
		if (nt < 0) {
			r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory measuring deviation");
			goto done;
		}
		for (int i = 0; i < nt; i++) {
			poser_world(&pa, k, tk[i]);
			poser_world(&pb, k, tk[i]);
			for (int j = 0; j < n; j++) {
				if (carrier[j] < 0)
					continue;
				mlod_mat4 mb = mlod_mat4_mul(&pb.world[carrier[j]], &rel[j]);
				for (int e = 0; e < 1 + (s->joints[j].has_end_site != 0); e++) {
					mlod_v3 o = {0, 0, 0};
					if (e == 1)
						o = s->joints[j].end_site;
					mlod_v3 x = mlod_mat4_point(&pa.world[j], o), y = mlod_mat4_point(&mb, o);
					double d = mlod_v3_length(mlod_v3_sub(x, y));
					sum += d;
					count++;
					if (d > out->max)
						out->max = d;
				}
			}
		}
		free(times);
		times = NULL;
	}
	out->mean = count ? sum / (double)count : 0.0;
done:
	free(times);
	free(rel);
	free(carrier);
	poser_free(&pa);
	poser_free(&pb);
	return r;
}

mlod_result mlod_joint_deviation(const mlod_character *a, const mlod_character *b, const int *stand_in,
                                 const int *a_to_b, int max_samples, mlod_deviation *out, mlod_error *err)
{
	return joint_deviation(a, b, stand_in, a_to_b, max_samples, NULL, 0, out, err);
}

mlod_result mlod_joint_deviation_at(const mlod_character *a, const mlod_character *b, const float *times, int count,
                                    mlod_deviation *out, mlod_error *err)
{
	if (!times || count <= 0) {
		memset(out, 0, sizeof *out);
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_joint_deviation_at: no times");
	}
	return joint_deviation(a, b, NULL, NULL, 0, times, count, out, err);
}
