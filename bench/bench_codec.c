/*
 * bench_codec: the pack's mesh codecs on the same data, side by side.
 *
 *   bench_codec FILE.glb ...
 *
 * Every triangle primitive of each character is quantised as the pack
 * stores it (mlod(5): positions u16 of the part's box, normals octahedral
 * snorm16, UV set 0 u16 of its range, joints u8 or u16, weights u8, u32
 * indices), then encoded three ways:
 *   meshopt    meshoptimizer 0.18's vertex codec per stream, index codec
 *   draco eb   Draco 1.5's edgebreaker (reorders vertices), speed 5 (default)
 *   draco seq  Draco's sequential encoder (keeps the vertex order)
 * Draco gets the positions, normals and UVs as floats with the same bits
 * (16 for each), joints and weights as integers, so both store the same
 * precision. Decode speed is the quantised (raw) bytes decoded per second,
 * median of 9 runs, one core; Draco's includes its dequantisation to
 * floats, meshopt's is only the codec (dequantising is one more pass).
 */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <meshoptimizer.h>

#include "bench.h"
#include "mlod.h"
#include "pack/draco.h"

#define RUNS 9

static long dropped; /* triangles Draco's encoders left out (degenerate) */

typedef struct sums {
	double raw, meshopt, eb, seq;
	double t_meshopt, t_eb, t_seq; /* seconds to decode everything once */
	int parts, vertices, triangles;
} sums;

static int load(const char *path, mlod_character *c)
{
	return bench_load("bench_codec", path, c, NULL);
}

static uint16_t quant16(float x, float lo, float hi)
{
	double t = hi > lo ? ((double)x - lo) / ((double)hi - lo) : 0.0;
	return (uint16_t)lrint(fmin(fmax(t, 0.0), 1.0) * 65535.0);
}

static int16_t snorm16(float x)
{
	return (int16_t)lrint(fmin(fmax(x, -1.0f), 1.0f) * 32767.0);
}

/* Octahedral encoding of a unit vector. */
static void oct(const float *n, int16_t *out)
{
	float s = fabsf(n[0]) + fabsf(n[1]) + fabsf(n[2]);
	float x = s > 0 ? n[0] / s : 1, y = s > 0 ? n[1] / s : 0;
	if (n[2] < 0) {
		float ox = (1 - fabsf(y)) * (x >= 0 ? 1 : -1), oy = (1 - fabsf(x)) * (y >= 0 ? 1 : -1);
		x = ox, y = oy;
	}
	out[0] = snorm16(x), out[1] = snorm16(y);
}

/* The decoded stream equals the input (the index codec may rotate a
 * triangle's corners, keeping its winding). */
static int same(const void *dec, const void *data, size_t count, size_t size, int index)
{
	if (!index)
		return memcmp(dec, data, count * size) == 0;
	const uint32_t *a = dec, *b = data;
	for (size_t t = 0; t < count; t += 3) {
		int ok = 0;
		for (int r = 0; r < 3 && !ok; r++)
			ok = a[t] == b[t + r] && a[t + 1] == b[t + (r + 1) % 3] && a[t + 2] == b[t + (r + 2) % 3];
		if (!ok)
			return 0;
	}
	return 1;
}

/* One stream through meshopt: encoded size and decode seconds (median). */
static void meshopt_stream(const void *data, size_t count, size_t size, int index, size_t *bytes, double *secs)
{
	size_t bound = index ? meshopt_encodeIndexBufferBound(count, count) : meshopt_encodeVertexBufferBound(count, size);
	unsigned char *enc = malloc(bound);
	void *dec = malloc(count * size);
	*bytes = index ? meshopt_encodeIndexBuffer(enc, bound, data, count) : meshopt_encodeVertexBuffer(enc, bound, data, count, size);
	double t[RUNS];
	for (int r = 0; r < RUNS; r++) {
		double t0 = bench_now();
		int rc = index ? meshopt_decodeIndexBuffer(dec, count, 4, enc, *bytes)
		               : meshopt_decodeVertexBuffer(dec, count, size, enc, *bytes);
		t[r] = bench_now() - t0;
		if (rc != 0 || !same(dec, data, count, size, index)) {
			fprintf(stderr, "bench_codec: meshopt round trip failed\n");
			exit(1);
		}
	}
	*secs = bench_median(t, RUNS);
	free(enc);
	free(dec);
}

static void draco_part(const mlod_primitive *p, const uint16_t *joints, const uint8_t *weights, int joints16,
                       int sequential, size_t *bytes, double *secs)
{
	mlod_draco_attr a[5];
	int n = 0;
	a[n++] = (mlod_draco_attr){MLOD_DRACO_POSITION, MLOD_DRACO_F32, 3, 16, p->positions};
	if (p->normals)
		a[n++] = (mlod_draco_attr){MLOD_DRACO_NORMAL, MLOD_DRACO_F32, 3, 16, p->normals};
	if (p->uv_set_count > 0)
		a[n++] = (mlod_draco_attr){MLOD_DRACO_TEXCOORD, MLOD_DRACO_F32, 2, 16, p->uvs[0]};
	uint8_t *j8 = NULL;
	if (joints) {
		if (joints16)
			a[n++] = (mlod_draco_attr){MLOD_DRACO_GENERIC, MLOD_DRACO_U16, 4, 0, (void *)joints};
		else {
			j8 = malloc(4 * (size_t)p->vertex_count);
			for (int i = 0; i < 4 * p->vertex_count; i++)
				j8[i] = (uint8_t)joints[i];
			a[n++] = (mlod_draco_attr){MLOD_DRACO_GENERIC, MLOD_DRACO_U8, 4, 0, j8};
		}
		a[n++] = (mlod_draco_attr){MLOD_DRACO_GENERIC, MLOD_DRACO_U8, 4, 0, (void *)weights};
	}
	void *enc;
	mlod_error err = {0};
	if (mlod_draco_encode(p->vertex_count, a, n, p->indices, p->index_count, sequential, 5, &enc, bytes, &err)) {
		fprintf(stderr, "bench_codec: %s\n", err.message);
		exit(1);
	}
	double t[RUNS];
	for (int r = 0; r < RUNS; r++) {
		mlod_draco_attr d[5];
		memcpy(d, a, sizeof a);
		int vc, ic;
		uint32_t *ix;
		double t0 = bench_now();
		if (mlod_draco_decode(enc, *bytes, d, n, &vc, &ix, &ic, &err)) {
			fprintf(stderr, "bench_codec: %s\n", err.message);
			exit(1);
		}
		t[r] = bench_now() - t0;
		if (r == 0 && (vc != p->vertex_count || ic != p->index_count))
			dropped += p->index_count / 3 - ic / 3; /* degenerate faces Draco leaves out */
		for (int k = 0; k < n; k++)
			mlod_free(d[k].data);
		mlod_free(ix);
	}
	*secs = bench_median(t, RUNS);
	mlod_free(enc);
	free(j8);
}

static void part(const mlod_primitive *p, int skin_joints, sums *s)
{
	int n = p->vertex_count;
	float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
	float ulo[2] = {INFINITY, INFINITY}, uhi[2] = {-INFINITY, -INFINITY};
	for (int v = 0; v < n; v++)
		for (int a = 0; a < 3; a++) {
			lo[a] = fminf(lo[a], p->positions[3 * v + a]);
			hi[a] = fmaxf(hi[a], p->positions[3 * v + a]);
			if (a < 2 && p->uv_set_count > 0) {
				ulo[a] = fminf(ulo[a], p->uvs[0][2 * v + a]);
				uhi[a] = fmaxf(uhi[a], p->uvs[0][2 * v + a]);
			}
		}
	uint16_t *pos = calloc(4 * (size_t)n, 2), *uv = calloc(2 * (size_t)n, 2);
	int16_t *nrm = calloc(2 * (size_t)n, 2);
	uint16_t *jnt = p->weight_set_count ? calloc(4 * (size_t)n, 2) : NULL;
	uint8_t *j8 = p->weight_set_count ? calloc(4 * (size_t)n, 1) : NULL, *wgt = p->weight_set_count ? calloc(4 * (size_t)n, 1) : NULL;
	int joints16 = skin_joints > 256;
	for (int v = 0; v < n; v++) {
		for (int a = 0; a < 3; a++)
			pos[4 * v + a] = quant16(p->positions[3 * v + a], lo[a], hi[a]);
		if (p->normals)
			oct(p->normals + 3 * v, nrm + 2 * v);
		if (p->uv_set_count > 0)
			for (int a = 0; a < 2; a++)
				uv[2 * v + a] = quant16(p->uvs[0][2 * v + a], ulo[a], uhi[a]);
		if (jnt) {
			int sum = 0, big = 0;
			for (int k = 0; k < 4; k++) {
				jnt[4 * v + k] = p->joints[0][4 * v + k];
				j8[4 * v + k] = (uint8_t)p->joints[0][4 * v + k];
				wgt[4 * v + k] = (uint8_t)lrint(fmin(fmax(p->weights[0][4 * v + k], 0.0f), 1.0f) * 255.0);
				sum += wgt[4 * v + k];
				if (wgt[4 * v + k] > wgt[4 * v + big])
					big = k;
			}
			wgt[4 * v + big] = (uint8_t)(wgt[4 * v + big] + 255 - sum); /* sums to 255 */
		}
	}
	size_t b;
	double t;
	s->raw += 8.0 * n + 4.0 * p->index_count;
	meshopt_stream(pos, (size_t)n, 8, 0, &b, &t), s->meshopt += (double)b, s->t_meshopt += t;
	if (p->normals)
		s->raw += 4.0 * n, meshopt_stream(nrm, (size_t)n, 4, 0, &b, &t), s->meshopt += (double)b, s->t_meshopt += t;
	if (p->uv_set_count > 0)
		s->raw += 4.0 * n, meshopt_stream(uv, (size_t)n, 4, 0, &b, &t), s->meshopt += (double)b, s->t_meshopt += t;
	if (jnt) {
		if (joints16)
			s->raw += 8.0 * n, meshopt_stream(jnt, (size_t)n, 8, 0, &b, &t);
		else
			s->raw += 4.0 * n, meshopt_stream(j8, (size_t)n, 4, 0, &b, &t);
		s->meshopt += (double)b, s->t_meshopt += t;
		s->raw += 4.0 * n, meshopt_stream(wgt, (size_t)n, 4, 0, &b, &t), s->meshopt += (double)b, s->t_meshopt += t;
	}
	meshopt_stream(p->indices, (size_t)p->index_count, 4, 1, &b, &t), s->meshopt += (double)b, s->t_meshopt += t;
	draco_part(p, jnt, wgt, joints16, 0, &b, &t), s->eb += (double)b, s->t_eb += t;
	draco_part(p, jnt, wgt, joints16, 1, &b, &t), s->seq += (double)b, s->t_seq += t;
	s->parts++, s->vertices += n, s->triangles += p->index_count / 3;
	free(pos), free(uv), free(nrm), free(jnt), free(j8), free(wgt);
}

int main(int argc, char **argv)
{
	if (argc < 2) {
		fprintf(stderr, "usage: bench_codec FILE.glb ...\n");
		return 1;
	}
	printf("| input | parts | vertices | triangles | quantised raw | meshopt | draco edgebreaker | draco sequential |"
	       " decode meshopt | decode draco eb | decode draco seq |\n");
	printf("|---|---|---|---|---|---|---|---|---|---|---|\n");
	for (int i = 1; i < argc; i++) {
		mlod_character c = {0};
		if (load(argv[i], &c))
			continue;
		sums s = {0};
		for (int k = 0; k < c.instance_count; k++) {
			const mlod_instance *in = &c.instances[k];
			const mlod_mesh *m = &c.meshes[in->mesh];
			int skin_joints = in->skin >= 0 ? c.skeleton.skins[in->skin].joint_count : 0;
			for (int q = 0; q < m->primitive_count; q++)
				if (m->primitives[q].mode == 4 && m->primitives[q].index_count >= 3)
					part(&m->primitives[q], skin_joints, &s);
		}
		const char *name = strrchr(argv[i], '/') ? strrchr(argv[i], '/') + 1 : argv[i];
		printf("| %s | %d | %d | %d | %.0f | %.0f (%.1f%%) | %.0f (%.1f%%) | %.0f (%.1f%%) | %.0f MB/s | %.0f MB/s | %.0f MB/s |\n",
		       name, s.parts, s.vertices, s.triangles, s.raw, s.meshopt, 100 * s.meshopt / s.raw, s.eb,
		       100 * s.eb / s.raw, s.seq, 100 * s.seq / s.raw, s.raw / s.t_meshopt / 1e6, s.raw / s.t_eb / 1e6,
		       s.raw / s.t_seq / 1e6);
		mlod_character_free(&c);
	}
	printf("\nDraco left out %ld degenerate triangles (counted over both methods).\n", dropped);
	return 0;
}
