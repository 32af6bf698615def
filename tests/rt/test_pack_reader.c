/*
 * test_pack_reader.c: the pack reader (lib/rt/rd_*.c) against packs built
 * here, byte by byte, by a small test-local encoder (the writer, lib/pack,
 * is another part). Links libmlodrt.a alone (+ meshoptimizer for the
 * codecs and libm), which also proves the runtime boundary.
 *
 * One line per test, "PASS name" or "FAIL name: file:line: what", as
 * tests/unit/test.h prints (which this program cannot include: it sees
 * only lib/core and lib/rt).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <meshoptimizer.h>
#include <zstd.h>

#include "mlod_pack.h"

/* ------------------------------------------------------------------ */
/* Harness (as tests/unit/test.h)                                      */
/* ------------------------------------------------------------------ */

static int test_failed_;
static char test_msg_[1024];
static int test_total_fail_;

#define TEST(name) static void test_##name(void)
#define RUN(name)                                                                                               \
	do {                                                                                                    \
		test_failed_ = 0;                                                                               \
		test_##name();                                                                                  \
		if (test_failed_) {                                                                             \
			printf("FAIL %s: %s\n", #name, test_msg_);                                               \
			test_total_fail_++;                                                                     \
		} else {                                                                                        \
			printf("PASS %s\n", #name);                                                              \
		}                                                                                               \
		fflush(stdout);                                                                                 \
	} while (0)
#define CHECK_MSG(cond, ...)                                                                                    \
	do {                                                                                                    \
		if (!(cond)) {                                                                                  \
			int n_ = snprintf(test_msg_, sizeof test_msg_, "%s:%d: ", __FILE__, __LINE__);           \
			snprintf(test_msg_ + n_, sizeof test_msg_ - (size_t)n_, __VA_ARGS__);                   \
			test_failed_ = 1;                                                                       \
			return;                                                                                 \
		}                                                                                               \
	} while (0)
#define CHECK(cond) CHECK_MSG(cond, "%s", #cond)
#define CHECK_NEAR(a, b, tol)                                                                                   \
	do {                                                                                                    \
		double a_ = (double)(a), b_ = (double)(b);                                                      \
		CHECK_MSG(fabs(a_ - b_) <= (tol), "%s = %.9g, expected %s = %.9g (tol %g)", #a, a_, #b, b_,      \
		          (double)(tol));                                                                       \
	} while (0)
static mlod_error terr;
#define CHECK_OK(call)                                                                                          \
	do {                                                                                                    \
		memset(&terr, 0, sizeof terr);                                                                  \
		mlod_result r_ = (call);                                                                        \
		CHECK_MSG(r_ == MLOD_OK, "%s returned %d: %s", #call, (int)r_, terr.message);                   \
	} while (0)
/* The call fails with code and a message containing text. */
#define CHECK_ERR(call, code, text)                                                                             \
	do {                                                                                                    \
		memset(&terr, 0, sizeof terr);                                                                  \
		mlod_result r_ = (call);                                                                        \
		CHECK_MSG(r_ == (code), "%s returned %d (%s), expected %d", #call, (int)r_, terr.message, (int)(code)); \
		CHECK_MSG(strstr(terr.message, (text)) != NULL, "%s: message \"%s\" lacks \"%s\"", #call, terr.message, \
		          (text));                                                                              \
	} while (0)

/* ------------------------------------------------------------------ */
/* A deterministic random source                                       */
/* ------------------------------------------------------------------ */

static uint64_t rng_state = 0x9e3779b97f4a7c15ull;
static uint32_t rnd(void)
{
	uint64_t x = rng_state;
	x ^= x << 13;
	x ^= x >> 7;
	x ^= x << 17;
	rng_state = x;
	return (uint32_t)(x >> 16);
}
static float rndf(float lo, float hi)
{
	return lo + (hi - lo) * (float)(rnd() & 0xffffff) / (float)0xffffff;
}

/* ------------------------------------------------------------------ */
/* The test-local encoder                                              */
/* ------------------------------------------------------------------ */

typedef struct buf {
	uint8_t *p;
	size_t n, cap;
} buf;

static void put(buf *b, const void *src, size_t n)
{
	if (b->n + n > b->cap) {
		b->cap = (b->n + n) * 2 + 64;
		b->p = realloc(b->p, b->cap);
	}
	if (n)
		memcpy(b->p + b->n, src, n);
	b->n += n;
}
static void put8(buf *b, uint8_t v) { put(b, &v, 1); }
static void put16(buf *b, uint16_t v) { uint8_t e[2] = {(uint8_t)v, (uint8_t)(v >> 8)}; put(b, e, 2); }
static void put32(buf *b, uint32_t v)
{
	uint8_t e[4] = {(uint8_t)v, (uint8_t)(v >> 8), (uint8_t)(v >> 16), (uint8_t)(v >> 24)};
	put(b, e, 4);
}
static void put64(buf *b, uint64_t v) { put32(b, (uint32_t)v); put32(b, (uint32_t)(v >> 32)); }
static void putf(buf *b, float f) { uint32_t u; memcpy(&u, &f, 4); put32(b, u); }
static void pad_to(buf *b, size_t align) { while (b->n % align) put8(b, 0); }
static void wr32(uint8_t *p, uint32_t v) { p[0] = (uint8_t)v; p[1] = (uint8_t)(v >> 8); p[2] = (uint8_t)(v >> 16); p[3] = (uint8_t)(v >> 24); }
static void wr16(uint8_t *p, uint16_t v) { p[0] = (uint8_t)v; p[1] = (uint8_t)(v >> 8); }
static uint32_t get32(const uint8_t *p) { return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24; }
static uint64_t get64(const uint8_t *p) { return get32(p) | (uint64_t)get32(p + 4) << 32; }

#define MAXS 64
typedef struct wstream {
	uint32_t tag, count;
	uint16_t elsize;
	uint8_t codec;
	buf data; /* decoded bytes */
} wstream;

typedef struct wchunk {
	uint32_t type;
	uint8_t layer, codec;
	uint16_t level, item, flags;
	float error, distance;
	int ns;
	wstream s[MAXS];
	/* A raw payload instead of streams (unknown chunk types). */
	buf payload;
} wchunk;

static wstream *add_stream(wchunk *c, uint32_t tag, uint16_t elsize, uint8_t codec)
{
	wstream *s = &c->s[c->ns++];
	memset(s, 0, sizeof *s);
	s->tag = tag;
	s->elsize = elsize;
	s->codec = codec;
	return s;
}
/* Drops stream i of a chunk. */
static void wchunk_free_stream(wchunk *c, int i)
{
	free(c->s[i].data.p);
	memmove(&c->s[i], &c->s[i + 1], sizeof(wstream) * (size_t)(c->ns - i - 1));
	c->ns--;
}
static void wchunk_free(wchunk *c)
{
	for (int i = 0; i < c->ns; i++)
		free(c->s[i].data.p);
	free(c->payload.p);
	memset(c, 0, sizeof *c);
}

/* The chunk's stored bytes and raw size. */
static buf chunk_bytes(const wchunk *c, uint32_t *raw)
{
	buf out = {0};
	if (c->payload.n || c->ns == 0) {
		put(&out, c->payload.p, c->payload.n);
		*raw = (uint32_t)out.n;
		return out;
	}
	buf enc[MAXS] = {{0}};
	uint64_t r = 4 + 16 * (uint64_t)c->ns;
	for (int i = 0; i < c->ns; i++) {
		const wstream *s = &c->s[i];
		uint32_t count = s->count;
		if (s->codec == MLOD_SCODEC_MESHOPT_VERTEX) {
			size_t bound = meshopt_encodeVertexBufferBound(count, s->elsize);
			enc[i].p = malloc(bound);
			enc[i].n = meshopt_encodeVertexBuffer(enc[i].p, bound, s->data.p, count, s->elsize);
		} else if (s->codec == MLOD_SCODEC_MESHOPT_INDEX || s->codec == MLOD_SCODEC_MESHOPT_SEQUENCE) {
			unsigned *idx = malloc(sizeof(unsigned) * (count ? count : 1));
			unsigned maxv = 0;
			for (uint32_t k = 0; k < count; k++) {
				if (s->elsize == 2) {
					uint16_t v;
					memcpy(&v, s->data.p + 2 * k, 2);
					idx[k] = v;
				} else {
					memcpy(&idx[k], s->data.p + 4 * k, 4);
				}
				if (idx[k] > maxv)
					maxv = idx[k];
			}
			int seq = s->codec == MLOD_SCODEC_MESHOPT_SEQUENCE;
			size_t bound = seq ? meshopt_encodeIndexSequenceBound(count, maxv + 1)
			                   : meshopt_encodeIndexBufferBound(count, maxv + 1);
			enc[i].p = malloc(bound);
			enc[i].n = seq ? meshopt_encodeIndexSequence(enc[i].p, bound, idx, count)
			               : meshopt_encodeIndexBuffer(enc[i].p, bound, idx, count);
			free(idx);
		} else if (s->codec == MLOD_SCODEC_SUM255) { /* each element's first three bytes */
			for (size_t k = 0; k < count; k++)
				put(&enc[i], s->data.p + 4 * k, 3);
		} else if (s->codec == MLOD_SCODEC_PLANES || s->codec == MLOD_SCODEC_PLANES_DELTA) {
			/* byte j of element k at j * count + k (minus element k - 1's) */
			enc[i].p = malloc(s->data.n + 1);
			enc[i].n = s->data.n;
			for (size_t j = 0; j < s->elsize; j++)
				for (size_t k = 0; k < count; k++)
					enc[i].p[j * count + k] = (uint8_t)(s->data.p[k * s->elsize + j] -
					                                    (s->codec == MLOD_SCODEC_PLANES_DELTA && k
					                                             ? s->data.p[(k - 1) * s->elsize + j]
					                                             : 0));
		} else {
			put(&enc[i], s->data.p, s->data.n);
		}
		r += ((uint64_t)count * s->elsize + 3) & ~(uint64_t)3;
	}
	put32(&out, (uint32_t)c->ns);
	for (int i = 0; i < c->ns; i++) {
		const wstream *s = &c->s[i];
		put32(&out, s->tag);
		put32(&out, s->count);
		put16(&out, s->elsize);
		put8(&out, s->codec);
		put8(&out, 0);
		put32(&out, (uint32_t)enc[i].n);
	}
	for (int i = 0; i < c->ns; i++) {
		put(&out, enc[i].p, enc[i].n);
		pad_to(&out, 4);
		free(enc[i].p);
	}
	*raw = (uint32_t)r;
	return out;
}

/* Re-stamps every CRC: each chunk's (where the TOC entry lies inside the
 * data), the TOC's and the header's. */
static void restamp(uint8_t *d, size_t n)
{
	if (n < 32)
		return;
	uint32_t count = get32(d + 12);
	uint64_t toc_end = 32 + 48 * (uint64_t)count;
	if (toc_end > n) {
		wr32(d + 28, mlod_pack_crc32(0, d, 28));
		return;
	}
	for (uint32_t i = 0; i < count; i++) {
		uint8_t *e = d + 32 + 48 * (size_t)i;
		uint64_t off = get64(e + 16), size = get32(e + 24);
		if (off <= n && size <= n - off)
			wr32(e + 32, mlod_pack_crc32(0, d + off, (size_t)size));
	}
	wr32(d + 24, mlod_pack_crc32(0, d + 32, (size_t)(toc_end - 32)));
	wr32(d + 28, mlod_pack_crc32(0, d, 28));
}

/* When set, build_pack gives every chunk with streams but INFO the zstd
 * entropy stage at this level (format 5.0), smaller or not, where its
 * container is at most its raw size (the format's bound; MESH level 0's
 * random indices and MOTION level 0's meshopt streams code to more). */
static int zstd_level;
/* With zstd_level: every MESH chunk after the first (in TOC order, a
 * finer level) coded with the earlier MESH chunks' containers as its
 * prefix (MLOD_ENTROPY_ZSTD_PREFIX, format 6.0), and every skeleton level
 * with SKELETON's container, smaller or not. */
static int zstd_prefix;
/* MESH level 0's streams raw (so that its container is its raw size and
 * may take an entropy stage). */
static int mesh0_raw;
/* With zstd_prefix: code the prefix-coded chunks on this chunk's
 * container instead of the coarser MESH levels' (a wrong prefix); -1 none. */
static int wrong_prefix = -1;

/* The zstd frame of a chunk's container. */
static buf zstd_frame(const buf *in, int level)
{
	buf z = {0};
	size_t cap = ZSTD_compressBound(in->n);
	z.p = malloc(cap);
	z.n = ZSTD_compress(z.p, cap, in->p, in->n, level);
	if (ZSTD_isError(z.n))
		z.n = 0;
	return z;
}

/* The file: header, TOC, chunks on 16-byte boundaries. */
static buf build_pack(const wchunk *c, int nc, uint16_t major, uint16_t minor)
{
	uint32_t coded[64] = {0};
	uint8_t stage[64] = {0};
	buf chunks[64], plain = {0}, meshes = {0}, skel0 = {0};
	uint32_t raw[64];
	uint64_t off[64];
	uint64_t at = 32 + 48 * (uint64_t)nc;
	for (int i = 0; i < nc; i++) {
		at = (at + 15) & ~(uint64_t)15;
		chunks[i] = chunk_bytes(&c[i], &raw[i]);
		if (zstd_level && c[i].type != MLOD_CHUNK_INFO && c[i].ns && !c[i].payload.n && chunks[i].n <= raw[i]) {
			buf z = zstd_frame(&chunks[i], zstd_level);
			stage[i] = MLOD_ENTROPY_ZSTD;
			int skel_level = c[i].type == MLOD_CHUNK_SKELETON && c[i].level > 0 && skel0.n;
			if (zstd_prefix && ((c[i].type == MLOD_CHUNK_MESH && meshes.n) || skel_level)) {
				const buf *pre = skel_level ? &skel0 : &meshes;
				buf other = {0};
				if (wrong_prefix >= 0) {
					uint32_t r;
					other = chunk_bytes(&c[wrong_prefix], &r);
					pre = &other;
				}
				size_t cap = ZSTD_compressBound(chunks[i].n);
				ZSTD_CCtx *cc = ZSTD_createCCtx();
				ZSTD_CCtx_setParameter(cc, ZSTD_c_compressionLevel, zstd_level);
				ZSTD_CCtx_refPrefix(cc, pre->p, pre->n);
				free(z.p);
				z.p = malloc(cap);
				z.n = ZSTD_compress2(cc, z.p, cap, chunks[i].p, chunks[i].n);
				if (ZSTD_isError(z.n))
					z.n = 0;
				ZSTD_freeCCtx(cc);
				free(other.p);
				stage[i] = MLOD_ENTROPY_ZSTD_PREFIX;
			}
			coded[i] = (uint32_t)chunks[i].n;
			plain = chunks[i];
			chunks[i] = z;
		}
		if (c[i].type == MLOD_CHUNK_MESH) /* its container: the finer levels' prefix */
			put(&meshes, plain.p ? plain.p : chunks[i].p, plain.p ? plain.n : chunks[i].n);
		if (c[i].type == MLOD_CHUNK_SKELETON && c[i].level == 0) /* the skeleton levels' prefix */
			put(&skel0, plain.p ? plain.p : chunks[i].p, plain.p ? plain.n : chunks[i].n);
		free(plain.p);
		plain = (buf){0};
		off[i] = at;
		at += chunks[i].n;
	}
	/* INFO's first_drawable (mlod(5)): where the last of INFO, SKELETON and
	 * the coarsest level of each layer ends (the coarsest: the largest level
	 * of its type here). Written into the INFO chunk's record when that says
	 * 0 and the chunk is the encoder's plain container with the record first
	 * (tests that set another value keep it). */
	uint32_t top[3] = {0, 0, 0}; /* SKELETON, MESH, MOTION */
	for (int i = 0; i < nc; i++) {
		const int k = c[i].type == MLOD_CHUNK_SKELETON ? 0 : c[i].type == MLOD_CHUNK_MESH ? 1
		              : c[i].type == MLOD_CHUNK_MOTION ? 2 : -1;
		if (k >= 0 && c[i].level > top[k])
			top[k] = c[i].level;
	}
	uint64_t drawable = 0;
	for (int i = 0; i < nc; i++) {
		const int coarse = c[i].type == MLOD_CHUNK_INFO ||
		                   (c[i].type == MLOD_CHUNK_SKELETON && (c[i].level == 0 || c[i].level == top[0])) ||
		                   (c[i].type == MLOD_CHUNK_MESH && c[i].level == top[1]) ||
		                   (c[i].type == MLOD_CHUNK_MOTION && c[i].level == top[2]);
		if (coarse && off[i] + chunks[i].n > drawable)
			drawable = off[i] + chunks[i].n;
	}
	/* INFO's max_vertex_count (format 8.1): the most vertices of a MESH
	 * level, the sum of its 'PART' records' vertex counts; written the
	 * same way (when 0, in a pack of 8.1 or later). */
	uint32_t maxv = 0;
	for (int i = 0; i < nc; i++)
		for (int k = 0; c[i].type == MLOD_CHUNK_MESH && k < c[i].ns; k++)
			if (c[i].s[k].tag == MLOD_STREAM_PART && c[i].s[k].elsize == sizeof(mlod_pack_part_rec)) {
				uint32_t v = 0;
				for (uint32_t r = 0; r < c[i].s[k].count && (r + 1) * sizeof(mlod_pack_part_rec) <= c[i].s[k].data.n; r++)
					v += get32(c[i].s[k].data.p + r * sizeof(mlod_pack_part_rec) +
					           offsetof(mlod_pack_part_rec, vertex_count));
				maxv = v > maxv ? v : maxv;
			}
	for (int i = 0; i < nc; i++) {
		uint8_t *b = chunks[i].p;
		if (c[i].type != MLOD_CHUNK_INFO || stage[i] || chunks[i].n < 4 + 16 + 80 || b[0] == 0 ||
		    memcmp(b + 4, "INFO", 4) != 0)
			continue;
		uint8_t *fd = b + 4 + 16 * (size_t)b[0] + 64;
		if ((size_t)(fd + 4 - b) <= chunks[i].n && !(fd[0] | fd[1] | fd[2] | fd[3]))
			for (int k = 0; k < 4; k++)
				fd[k] = (uint8_t)(drawable >> (8 * k));
		uint8_t *mv = fd + 4;
		if (mlod_pack_version_has_max_vertices(major, minor) && (size_t)(mv + 4 - b) <= chunks[i].n &&
		    !(mv[0] | mv[1] | mv[2] | mv[3]))
			wr32(mv, maxv);
	}
	buf out = {0};
	put(&out, "MLOD", 4);
	put16(&out, major);
	put16(&out, minor);
	put32(&out, 0);
	put32(&out, (uint32_t)nc);
	put64(&out, at);
	put32(&out, 0);
	put32(&out, 0);
	for (int i = 0; i < nc; i++) {
		put32(&out, c[i].type);
		put8(&out, c[i].layer);
		put8(&out, (uint8_t)(c[i].codec | stage[i] << 4));
		put16(&out, c[i].level);
		put16(&out, c[i].item);
		put16(&out, c[i].flags);
		put32(&out, coded[i]);
		put64(&out, off[i]);
		put32(&out, (uint32_t)chunks[i].n);
		put32(&out, raw[i]);
		put32(&out, 0);
		putf(&out, c[i].error);
		putf(&out, c[i].distance);
		put32(&out, 0);
	}
	for (int i = 0; i < nc; i++) {
		pad_to(&out, 16);
		put(&out, chunks[i].p, chunks[i].n);
		free(chunks[i].p);
	}
	free(meshes.p);
	free(skel0.p);
	restamp(out.p, out.n);
	return out;
}

/* ------------------------------------------------------------------ */
/* The character: what the encoder writes, kept to compare with        */
/* ------------------------------------------------------------------ */

#define NJ 4
#define NV0 40 /* part 0 vertices */
#define NV1 24 /* part 1 vertices */
#define NI0 60
#define NI1 36
#define NK 5 /* keys */

/* A part at one level (layout b2): its prefix is truth vertices 0 .. V - 1,
 * of which its chunk's block holds first .. V - 1 (the coarser level's
 * block the rest); its indices refer to the prefix. */
typedef struct part_truth {
	uint32_t flags, V, I, uv_sets, T, first;
	int32_t skin, joint;
	float pos[NV0][3], nrm[NV0][3], tan[NV0][4], uv[2][NV0][2], col[NV0][4], wgt[NV0][4], morph[NV0][3];
	uint16_t jnt[NV0][4];
	uint8_t wq[NV0][4], cq[NV0][4];
	uint32_t idx[NI0];
	float pos_min[3], pos_scale[3], uv_min[2][2], uv_scale[2][2], mscale;
} part_truth;

static part_truth parts_truth[4]; /* level 0: parts 0, 1; level 1: parts 0, 1 as 2, 3 */
static float ibm_truth[NJ][16];
static float time_truth[NK];
static float vec_truth[NK * 3][3];
static float rot_truth[NK * 3][4];
static int16_t rotq_truth[NK][4], rotq_enc[NK][4];
static int rotq_v9 = 1; /* make_chunks' 'ROTQ' as format 9.0 codes it (0: 2.0 to 8.x) */

static const int32_t parents[NJ] = {-1, 0, 1, 1};

static void oct_encode(const float n[3], int16_t *qx, int16_t *qy)
{
	float s = fabsf(n[0]) + fabsf(n[1]) + fabsf(n[2]);
	float x = n[0] / s, y = n[1] / s;
	if (n[2] < 0) {
		float ox = x;
		x = (1 - fabsf(y)) * (ox >= 0 ? 1.0f : -1.0f);
		y = (1 - fabsf(ox)) * (y >= 0 ? 1.0f : -1.0f);
	}
	*qx = (int16_t)lrintf(x * 32767.0f);
	*qy = (int16_t)lrintf(y * 32767.0f);
}

static void rnd_unit(float *v)
{
	float l;
	do {
		v[0] = rndf(-1, 1), v[1] = rndf(-1, 1), v[2] = rndf(-1, 1);
		l = sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
	} while (l < 0.1f || l > 1);
	v[0] /= l, v[1] /= l, v[2] /= l;
}

/* Weights quantised to unorm8 summing to 255 (largest remainder). */
static void quant_weights(const float *w, uint8_t *q)
{
	int sum = 0;
	float frac[4];
	for (int a = 0; a < 4; a++) {
		float f = w[a] * 255.0f;
		q[a] = (uint8_t)floorf(f);
		frac[a] = f - floorf(f);
		sum += q[a];
	}
	while (sum < 255) {
		int best = 0;
		for (int a = 1; a < 4; a++)
			if (frac[a] > frac[best])
				best = a;
		q[best]++;
		frac[best] = -1;
		sum++;
	}
}

static void make_part(part_truth *t, uint32_t flags, uint32_t V, uint32_t I, uint32_t uv_sets, uint32_t T, int32_t skin,
                      int32_t joint)
{
	memset(t, 0, sizeof *t);
	t->flags = flags, t->V = V, t->I = I, t->uv_sets = uv_sets, t->T = T, t->skin = skin, t->joint = joint;
	float lo[3] = {-0.5f, 0.0f, -0.25f}, hi[3] = {0.5f, 1.8f, 0.25f};
	for (int a = 0; a < 3; a++) {
		t->pos_min[a] = lo[a];
		t->pos_scale[a] = (hi[a] - lo[a]) / 65535.0f;
	}
	for (uint32_t s = 0; s < uv_sets; s++)
		for (int a = 0; a < 2; a++) {
			t->uv_min[s][a] = -1.0f + (float)s;
			t->uv_scale[s][a] = 2.0f / 65535.0f;
		}
	t->mscale = 0.1f / 32767.0f;
	for (uint32_t v = 0; v < V; v++) {
		for (int a = 0; a < 3; a++)
			t->pos[v][a] = rndf(lo[a], hi[a]);
		rnd_unit(t->nrm[v]);
		rnd_unit(t->tan[v]);
		t->tan[v][3] = (rnd() & 1) ? 1.0f : -1.0f;
		for (uint32_t s = 0; s < uv_sets; s++)
			for (int a = 0; a < 2; a++)
				t->uv[s][v][a] = rndf(t->uv_min[s][a], t->uv_min[s][a] + 2.0f);
		for (int a = 0; a < 4; a++) {
			t->cq[v][a] = (uint8_t)(rnd() & 0xff);
			t->col[v][a] = t->cq[v][a] / 255.0f;
		}
		float sum = 0;
		for (int a = 0; a < 4; a++) {
			t->wgt[v][a] = a < 2 || (rnd() & 1) ? rndf(0.05f, 1) : 0;
			sum += t->wgt[v][a];
			t->jnt[v][a] = (uint16_t)(rnd() % NJ);
		}
		for (int a = 0; a < 4; a++)
			t->wgt[v][a] /= sum;
		quant_weights(t->wgt[v], t->wq[v]);
		for (int a = 0; a < 3; a++)
			t->morph[v][a] = rndf(-0.1f, 0.1f);
	}
	for (uint32_t k = 0; k < I; k++)
		t->idx[k] = rnd() % V;
}

/* The vertices of the prefix a part's indices use. */
static uint32_t used_vertices(const part_truth *t)
{
	uint8_t seen[NV0] = {0};
	uint32_t n = 0;
	for (uint32_t k = 0; k < t->I; k++)
		if (!seen[t->idx[k]])
			seen[t->idx[k]] = 1, n++;
	return n;
}

/* Level 1 of a part: the first V vertices of level 0's, I indices; the
 * first V of them 0 .. V - 1, so that the gathered vertices keep their
 * order (a raw chunk: the index codec rotates no triangle). */
static void coarse_part(part_truth *t, const part_truth *fine, uint32_t V, uint32_t I, uint32_t flags)
{
	*t = *fine;
	t->V = V, t->I = I, t->first = 0, t->flags = flags;
	for (uint32_t k = 0; k < I; k++)
		t->idx[k] = k < V ? k : rnd() % V;
}

static void part_rec(const part_truth *t, uint32_t instance, buf *b)
{
	mlod_pack_part_rec r;
	memset(&r, 0, sizeof r);
	r.instance = instance;
	r.node = (int32_t)instance + 1;
	r.mesh = 0;
	r.primitive = instance;
	r.skin = t->skin;
	r.joint = t->joint;
	r.material = -1;
	r.flags = t->flags;
	r.vertex_count = used_vertices(t);
	r.index_count = t->I;
	r.uv_sets = t->uv_sets;
	r.target_count = t->T;
	for (int k = 0; k < 16; k++)
		r.offset[k] = k % 5 == 0 ? 1.0f : 0.0f;
	memcpy(r.pos_min, t->pos_min, sizeof r.pos_min);
	memcpy(r.pos_scale, t->pos_scale, sizeof r.pos_scale);
	memcpy(r.uv_min, t->uv_min, sizeof t->uv_min);
	memcpy(r.uv_scale, t->uv_scale, sizeof t->uv_scale);
	put(b, &r, sizeof r);
}

/* Appends a part's streams; vc/ic: the codecs of vertex and index streams. */
static void part_streams(wchunk *c, const part_truth *t, uint8_t vc, uint8_t ic)
{
	const uint32_t F = t->first, n = t->V - t->first;
	wstream *s = add_stream(c, MLOD_STREAM_POSQ, 8, vc);
	s->count = n;
	for (uint32_t v = F; v < t->V; v++) {
		for (int a = 0; a < 3; a++)
			put16(&s->data, (uint16_t)lrintf((t->pos[v][a] - t->pos_min[a]) / t->pos_scale[a]));
		put16(&s->data, 0);
	}
	if (t->flags & MLOD_PART_NORMALS) {
		s = add_stream(c, MLOD_STREAM_NRMQ, 4, vc);
		s->count = n;
		for (uint32_t v = F; v < t->V; v++) {
			int16_t qx, qy;
			oct_encode(t->nrm[v], &qx, &qy);
			put16(&s->data, (uint16_t)qx);
			put16(&s->data, (uint16_t)qy);
		}
	}
	if (t->flags & MLOD_PART_TANGENTS) {
		s = add_stream(c, MLOD_STREAM_TANQ, 8, vc);
		s->count = n;
		for (uint32_t v = F; v < t->V; v++) {
			int16_t qx, qy;
			oct_encode(t->tan[v], &qx, &qy);
			put16(&s->data, (uint16_t)qx);
			put16(&s->data, (uint16_t)qy);
			put16(&s->data, (uint16_t)(t->tan[v][3] > 0 ? 32767 : -32767));
			put16(&s->data, 0);
		}
	}
	for (uint32_t u = 0; u < t->uv_sets; u++) {
		s = add_stream(c, MLOD_STREAM_UVQ0 + (u << 24), 4, vc);
		s->count = n;
		for (uint32_t v = F; v < t->V; v++)
			for (int a = 0; a < 2; a++)
				put16(&s->data, (uint16_t)lrintf((t->uv[u][v][a] - t->uv_min[u][a]) / t->uv_scale[u][a]));
	}
	if (t->flags & MLOD_PART_COLORS) {
		s = add_stream(c, MLOD_STREAM_COLQ, 4, vc);
		s->count = n;
		put(&s->data, t->cq[F], 4 * (size_t)n);
	}
	if (t->flags & MLOD_PART_SKINNED) {
		int j16 = (t->flags & MLOD_PART_JOINTS16) != 0;
		s = add_stream(c, j16 ? MLOD_STREAM_JN16 : MLOD_STREAM_JNT8, j16 ? 8 : 4, vc);
		s->count = n;
		for (uint32_t v = F; v < t->V; v++)
			for (int a = 0; a < 4; a++) {
				if (j16)
					put16(&s->data, t->jnt[v][a]);
				else
					put8(&s->data, (uint8_t)t->jnt[v][a]);
			}
		s = add_stream(c, MLOD_STREAM_WGT8, 4, vc);
		s->count = n;
		put(&s->data, t->wq[F], 4 * (size_t)n);
	}
	int i16 = (t->flags & MLOD_PART_INDEX16) != 0;
	uint32_t local[NI0], at[NV0], nmap = 0;
	for (uint32_t k = 0; k < t->I; k++)
		local[k] = t->idx[k];
	if (t->flags & MLOD_PART_LOCAL) {
		/* The prefix vertices in first-use order; with NEWBITS, 'INEW'
		 * marks those that are the block's next ones, and 'IMAP' lists
		 * the others. */
		uint32_t map[NV0], words[NV0 / 32 + 1] = {0}, nnew = 0, nold = 0;
		for (uint32_t v = 0; v < NV0; v++)
			at[v] = UINT32_MAX;
		for (uint32_t k = 0; k < t->I; k++) {
			if (at[t->idx[k]] == UINT32_MAX)
				map[nmap] = t->idx[k], at[t->idx[k]] = nmap++;
			local[k] = at[t->idx[k]];
		}
		if (t->flags & MLOD_PART_NEWBITS) {
			for (uint32_t v = 0; v < nmap; v++)
				if (map[v] == F + nnew)
					words[v / 32] |= 1u << (v % 32), nnew++;
			s = add_stream(c, MLOD_STREAM_INEW, 4, MLOD_SCODEC_RAW);
			s->count = (nmap + 31) / 32;
			for (uint32_t w = 0; w < s->count; w++)
				put32(&s->data, words[w]);
		}
		s = add_stream(c, MLOD_STREAM_IMAP, i16 ? 2 : 4,
		               ic == MLOD_SCODEC_MESHOPT_INDEX ? MLOD_SCODEC_MESHOPT_SEQUENCE : MLOD_SCODEC_RAW);
		for (uint32_t v = 0; v < nmap; v++) {
			if (words[v / 32] >> (v % 32) & 1u)
				continue;
			if (i16)
				put16(&s->data, (uint16_t)map[v]);
			else
				put32(&s->data, map[v]);
			nold++;
		}
		s->count = nold;
	}
	s = add_stream(c, MLOD_STREAM_IDX, i16 ? 2 : 4, ic);
	s->count = t->I;
	for (uint32_t k = 0; k < t->I; k++) {
		if (i16)
			put16(&s->data, (uint16_t)local[k]);
		else
			put32(&s->data, local[k]);
	}
	if (t->T) {
		s = add_stream(c, MLOD_STREAM_MTSC, 4, MLOD_SCODEC_RAW);
		s->count = t->T;
		for (uint32_t k = 0; k < t->T; k++)
			putf(&s->data, t->mscale);
		for (uint32_t k = 0; k < t->T; k++) {
			s = add_stream(c, MLOD_STREAM_MTPQ, 8, vc);
			s->count = n;
			for (uint32_t v = F; v < t->V; v++) {
				for (int a = 0; a < 3; a++)
					put16(&s->data, (uint16_t)(int16_t)lrintf(t->morph[v][a] / t->mscale));
				put16(&s->data, 0);
			}
		}
	}
}

/* Parts 1 of level 0 (its map a list) and 0 of level 1 (its vertices all
 * the block's, NEWBITS) in their own numbering (format 3.0), unless a
 * test sets it 0 (a format 2.0 pack). */
static uint32_t local_flag = MLOD_PART_LOCAL;
/* SKELETON level 1's palette as 'PALR' and 'PALX' (format 7.0), unless a
 * test sets it 0 ('PALJ' and 'PALB', as 2.x to 6.x packs store it). */
static int pal_refs = 1;
static const uint32_t palj_truth[NJ] = {0, 1, 1, 1};

/* The chunks of the test character, in the format's order:
 * INFO, SKELETON, SKELETON 1, MESH 1, MOTION 1/0, MESH 0, MOTION 0/0, DOC.
 * with_unknown adds an 'XTRA' chunk after INFO. */
enum { C_INFO, C_SKEL, C_SKEL1, C_MESH1, C_MOT1, C_MESH0, C_MOT0, C_DOC, C_COUNT };

static int make_chunks(wchunk *c, int with_unknown)
{
	rng_state = 0x9e3779b97f4a7c15ull;
	memset(c, 0, sizeof(wchunk) * (C_COUNT + 1));
	wstream *s;
	/* INFO */
	wchunk *ch = &c[C_INFO];
	ch->type = MLOD_CHUNK_INFO;
	mlod_pack_info_rec info;
	memset(&info, 0, sizeof info);
	info.joint_count = NJ;
	info.skin_count = 1;
	info.skeleton_levels = 2;
	info.mesh_levels = 2;
	info.clip_count = 1;
	info.motion_levels = 2;
	info.instance_count = 2;
	info.name = 0;
	info.bounds_min[0] = -0.5f, info.bounds_max[0] = 0.5f, info.bounds_max[1] = 1.8f;
	info.height = 1.8f;
	info.diagonal = 1.9f;
	info.first_drawable = 0;
	s = add_stream(ch, MLOD_STREAM_INFO, sizeof info, MLOD_SCODEC_RAW);
	s->count = 1;
	put(&s->data, &info, sizeof info);
	s = add_stream(ch, MLOD_STREAM_NAME, 1, MLOD_SCODEC_RAW);
	put(&s->data, "hero\0walk\0", 10);
	s->count = 10;

	/* SKELETON */
	ch = &c[C_SKEL];
	ch->type = MLOD_CHUNK_SKELETON, ch->layer = MLOD_LAYER_SKELETON;
	s = add_stream(ch, MLOD_STREAM_JNTS, sizeof(mlod_pack_joint_rec), MLOD_SCODEC_RAW);
	s->count = NJ;
	static const char jnames[] = "root\0hip\0leg_l\0leg_r\0skin\0";
	static const uint32_t jname_off[NJ] = {0, 5, 9, 15};
	for (int j = 0; j < NJ; j++) {
		mlod_pack_joint_rec r;
		memset(&r, 0, sizeof r);
		r.parent = parents[j];
		r.name = jname_off[j];
		r.t[1] = j ? 0.5f : 0.0f;
		r.t[0] = 0.125f * (float)j;
		r.r[3] = 1;
		r.s[0] = r.s[1] = r.s[2] = 1;
		for (int k = 0; k < 16; k++)
			r.base[k] = k % 5 == 0 ? 1.0f : 0.0f;
		r.node = j + 10;
		put(&s->data, &r, sizeof r);
	}
	s = add_stream(ch, MLOD_STREAM_NAME, 1, MLOD_SCODEC_RAW);
	put(&s->data, jnames, sizeof jnames - 1);
	s->count = sizeof jnames - 1;
	s = add_stream(ch, MLOD_STREAM_SKIN, sizeof(mlod_pack_skin_rec), MLOD_SCODEC_RAW);
	s->count = 1;
	mlod_pack_skin_rec sk = {NJ, 21, 0};
	put(&s->data, &sk, sizeof sk);
	s = add_stream(ch, MLOD_STREAM_SKJT, 4, MLOD_SCODEC_RAW);
	s->count = NJ;
	for (int j = 0; j < NJ; j++)
		put32(&s->data, (uint32_t)j);
	s = add_stream(ch, MLOD_STREAM_IBMS, 64, MLOD_SCODEC_RAW);
	s->count = NJ;
	for (int j = 0; j < NJ; j++)
		for (int k = 0; k < 16; k++) {
			ibm_truth[j][k] = k % 5 == 0 ? 1.0f : (k == 13 ? -0.5f * (float)j : 0.0f);
			putf(&s->data, ibm_truth[j][k]);
		}

	/* SKELETON level 1: keeps root and hip; the legs follow the hip. */
	ch = &c[C_SKEL1];
	ch->type = MLOD_CHUNK_SKELETON, ch->layer = MLOD_LAYER_SKELETON, ch->level = 1;
	ch->error = 0.02f, ch->distance = 10.0f;
	s = add_stream(ch, MLOD_STREAM_KEPT, 4, MLOD_SCODEC_RAW);
	s->count = 2;
	put32(&s->data, 0);
	put32(&s->data, 1);
	if (pal_refs) {
		/* Joints 0 and 1 their own IBM (0), joint 2 IBMS entry 1 (2),
		 * joint 3 the same matrix as 'PALX' matrix 0 (NJ + 1). */
		s = add_stream(ch, MLOD_STREAM_PALR, 4, MLOD_SCODEC_RAW);
		s->count = NJ;
		static const uint32_t palr[NJ] = {0, 0, 2, NJ + 1};
		for (int j = 0; j < NJ; j++)
			put32(&s->data, palr[j]);
		s = add_stream(ch, MLOD_STREAM_PALX, 64, MLOD_SCODEC_RAW);
		s->count = 1;
		for (int k = 0; k < 16; k++)
			putf(&s->data, ibm_truth[1][k]);
	} else {
		s = add_stream(ch, MLOD_STREAM_PALJ, 4, MLOD_SCODEC_RAW);
		s->count = NJ;
		for (int j = 0; j < NJ; j++)
			put32(&s->data, palj_truth[j]);
		s = add_stream(ch, MLOD_STREAM_PALB, 64, MLOD_SCODEC_RAW);
		s->count = NJ;
		for (int j = 0; j < NJ; j++)
			for (int k = 0; k < 16; k++)
				putf(&s->data, ibm_truth[palj_truth[j]][k]);
	}

	/* The parts: level 0's, then level 1's from them (16 and 10 of their
	 * vertices; part 0 with u16 indices at level 1, u32 at level 0). */
	make_part(&parts_truth[0],
	          MLOD_PART_NORMALS | MLOD_PART_TANGENTS | MLOD_PART_COLORS | MLOD_PART_SKINNED, NV0, NI0, 2, 1, 0, -1);
	make_part(&parts_truth[1], MLOD_PART_SKINNED | MLOD_PART_JOINTS16 | MLOD_PART_INDEX16 | local_flag, NV1, NI1, 0, 0,
	          0, 2);
	coarse_part(&parts_truth[2], &parts_truth[0], 16, 24,
	            parts_truth[0].flags | MLOD_PART_INDEX16 | local_flag | (local_flag ? MLOD_PART_NEWBITS : 0));
	coarse_part(&parts_truth[3], &parts_truth[1], 10, 12, parts_truth[1].flags & ~MLOD_PART_LOCAL);
	parts_truth[0].first = 16, parts_truth[1].first = 10;

	/* MESH level 1: the two parts raw: every vertex of their prefixes. */
	ch = &c[C_MESH1];
	ch->type = MLOD_CHUNK_MESH, ch->layer = MLOD_LAYER_MESH, ch->level = 1;
	ch->error = 0.01f, ch->distance = 9.35f;
	s = add_stream(ch, MLOD_STREAM_PART, sizeof(mlod_pack_part_rec), MLOD_SCODEC_RAW);
	s->count = 2;
	part_rec(&parts_truth[2], 0, &s->data);
	part_rec(&parts_truth[3], 1, &s->data);
	part_streams(ch, &parts_truth[2], MLOD_SCODEC_RAW, MLOD_SCODEC_RAW);
	part_streams(ch, &parts_truth[3], MLOD_SCODEC_RAW, MLOD_SCODEC_RAW);

	/* MOTION level 1 of clip 0: one raw channel. */
	ch = &c[C_MOT1];
	ch->type = MLOD_CHUNK_MOTION, ch->layer = MLOD_LAYER_MOTION, ch->level = 1;
	ch->error = 0.01f, ch->distance = 9.35f;
	for (int k = 0; k < NK; k++)
		time_truth[k] = 0.25f * (float)k;
	s = add_stream(ch, MLOD_STREAM_CHAN, sizeof(mlod_pack_channel_rec), MLOD_SCODEC_RAW);
	s->count = 1;
	mlod_pack_channel_rec cr = {0, 0, 0, 2, 0};
	put(&s->data, &cr, sizeof cr);
	s = add_stream(ch, MLOD_STREAM_STEP, 8, MLOD_SCODEC_RAW);
	s->count = 1;
	double no_step = 0;
	put(&s->data, &no_step, 8);
	s = add_stream(ch, MLOD_STREAM_TIME, 4, MLOD_SCODEC_RAW);
	s->count = 2;
	putf(&s->data, 0.0f);
	putf(&s->data, 1.0f);
	add_stream(ch, MLOD_STREAM_ROTQ, 8, MLOD_SCODEC_RAW);
	add_stream(ch, MLOD_STREAM_ROTD, 8, MLOD_SCODEC_RAW);
	add_stream(ch, MLOD_STREAM_ROTF, 16, MLOD_SCODEC_RAW);
	s = add_stream(ch, MLOD_STREAM_VEC3, 12, MLOD_SCODEC_RAW);
	s->count = 2;
	for (int k = 0; k < 6; k++)
		putf(&s->data, (float)k);
	add_stream(ch, MLOD_STREAM_VECD, 12, MLOD_SCODEC_RAW);

	/* MESH level 0: the two parts' new vertices, meshopt-coded. */
	ch = &c[C_MESH0];
	ch->type = MLOD_CHUNK_MESH, ch->layer = MLOD_LAYER_MESH, ch->codec = MLOD_CODEC_MESHOPT;
	const uint8_t vc0 = mesh0_raw ? MLOD_SCODEC_RAW : MLOD_SCODEC_MESHOPT_VERTEX;
	const uint8_t ic0 = mesh0_raw ? MLOD_SCODEC_RAW : MLOD_SCODEC_MESHOPT_INDEX;
	s = add_stream(ch, MLOD_STREAM_PART, sizeof(mlod_pack_part_rec), vc0);
	s->count = 2;
	part_rec(&parts_truth[0], 0, &s->data);
	part_rec(&parts_truth[1], 1, &s->data);
	part_streams(ch, &parts_truth[0], vc0, ic0);
	part_streams(ch, &parts_truth[1], vc0, ic0);

	/* MOTION level 0 of clip 0: translation (linear), rotation (ROTQ),
	 * rotation (cubic, ROTF), scale (step); the first three share time
	 * array 0, the scale has array 1 (the same times): ticks of 0.25 s,
	 * meshopt-coded. */
	ch = &c[C_MOT0];
	ch->type = MLOD_CHUNK_MOTION, ch->layer = MLOD_LAYER_MOTION, ch->codec = MLOD_CODEC_MESHOPT;
	s = add_stream(ch, MLOD_STREAM_CHAN, sizeof(mlod_pack_channel_rec), MLOD_SCODEC_RAW);
	s->count = 4;
	mlod_pack_channel_rec chans[4] = {{0, 0, 0, NK, 0}, {1, 1, 0, NK, 0}, {2, 1, 2, NK, 0}, {3, 2, 1, NK, 1}};
	put(&s->data, chans, sizeof chans);
	s = add_stream(ch, MLOD_STREAM_STEP, 8, MLOD_SCODEC_RAW);
	s->count = 1;
	double step = 0.25;
	put(&s->data, &step, 8);
	for (int k = 0; k < NK * 3; k++) {
		for (int a = 0; a < 3; a++)
			vec_truth[k][a] = rndf(-2, 2);
		float q[4], l = 0;
		for (int a = 0; a < 4; a++)
			q[a] = rndf(-1, 1), l += q[a] * q[a];
		for (int a = 0; a < 4; a++)
			rot_truth[k][a] = q[a] / sqrtf(l);
	}
	/* ROTQ: the three components but the largest, on the lattice, then
	 * its index; the reader rebuilds it non-negative, then continues the
	 * sign of the key before (rotq_truth: what it returns, x 32767). */
	for (int k = 0; k < NK; k++) {
		int big = 0;
		for (int a = 1; a < 4; a++)
			big = fabsf(rot_truth[k][a]) > fabsf(rot_truth[k][big]) ? a : big;
		float sign = rot_truth[k][big] < 0 ? -1.0f : 1.0f;
		double sum = 0, dot = 0;
		for (int a = 0, j = 0; a < 4; a++)
			if (a != big) {
				rotq_enc[k][j++] = rotq_truth[k][a] = (int16_t)lrintf(sign * rot_truth[k][a] * 32767.0f);
				float f = (float)(rotq_truth[k][a] / 32767.0);
				sum += (double)f * f;
			}
		rotq_enc[k][3] = (int16_t)big;
		rotq_truth[k][big] = (int16_t)lrint(sqrt(1.0 - sum) * 32767.0);
		for (int a = 0; k > 0 && a < 4; a++)
			dot += (double)rotq_truth[k][a] * rotq_truth[k - 1][a];
		for (int a = 0; dot < 0 && a < 4; a++)
			rotq_truth[k][a] = (int16_t)-rotq_truth[k][a];
	}
	/* the two time arrays, one after the other, as ticks: each array's
	 * first (0), then each next's difference (1) */
	s = add_stream(ch, MLOD_STREAM_TICK, 4, MLOD_SCODEC_MESHOPT_VERTEX);
	s->count = 2 * NK;
	for (int a = 0; a < 2; a++)
		for (int k = 0; k < NK; k++)
			put32(&s->data, k > 0);
	/* the values: ROTQ (channel 1), ROTF (channel 2), VEC3 (channels 0, 3) */
	s = add_stream(ch, MLOD_STREAM_ROTQ, 8, MLOD_SCODEC_MESHOPT_VERTEX);
	s->count = NK;
	for (int k = 0; k < NK; k++) {
		int16_t e[4];
		memcpy(e, rotq_enc[k], sizeof e);
		/* format 9.0: every key but the first as its three components
		 * minus the key before's (as returned; negated where its
		 * component at the index is negative: no key of a base level
		 * here), zigzagged: 0 -1 1 -2 as 0 1 2 3 */
		for (int a = 0, j = 0, big = e[3] & 3; rotq_v9 && k > 0 && a < 4; a++)
			if (a != big) {
				int sign = rotq_truth[k - 1][big] < 0 ? -1 : 1;
				long d = (int16_t)(uint16_t)((long)e[j] - sign * (long)rotq_truth[k - 1][a]); /* wrapped */
				e[j++] = (int16_t)(uint16_t)(d >= 0 ? 2 * d : -2 * d - 1);
			}
		for (int a = 0; a < 4; a++)
			put16(&s->data, (uint16_t)e[a]);
	}
	add_stream(ch, MLOD_STREAM_ROTD, 8, MLOD_SCODEC_MESHOPT_VERTEX);
	s = add_stream(ch, MLOD_STREAM_ROTF, 16, MLOD_SCODEC_RAW);
	s->count = NK * 3;
	for (int k = 0; k < NK * 3; k++)
		for (int a = 0; a < 4; a++)
			putf(&s->data, rot_truth[k][a]);
	s = add_stream(ch, MLOD_STREAM_VEC3, 12, MLOD_SCODEC_MESHOPT_VERTEX);
	s->count = 2 * NK;
	for (int cidx = 0; cidx < 2; cidx++)
		for (int k = 0; k < NK; k++)
			for (int a = 0; a < 3; a++)
				putf(&s->data, vec_truth[k][a]);
	add_stream(ch, MLOD_STREAM_VECD, 12, MLOD_SCODEC_MESHOPT_VERTEX);

	/* DOC */
	ch = &c[C_DOC];
	ch->type = MLOD_CHUNK_DOC;
	s = add_stream(ch, MLOD_STREAM_GLB, 1, MLOD_SCODEC_RAW);
	put(&s->data, "glTF\x02\0\0\0(a glb without geometry)", 32);
	s->count = 32;

	int n = C_COUNT;
	if (with_unknown) {
		memmove(&c[2], &c[1], sizeof(wchunk) * (C_COUNT - 1));
		memset(&c[1], 0, sizeof c[1]);
		c[1].type = MLOD_FOURCC('X', 'T', 'R', 'A');
		c[1].layer = 7;
		c[1].codec = 9;
		put(&c[1].payload, "anything at all, not even streams", 33);
		n++;
	}
	return n;
}

static void free_chunks(wchunk *c, int n)
{
	for (int i = 0; i < n; i++)
		wchunk_free(&c[i]);
}

static buf make_pack(int with_unknown)
{
	static wchunk c[C_COUNT + 1];
	int n = make_chunks(c, with_unknown);
	buf b = build_pack(c, n, MLOD_PACK_MAJOR, MLOD_PACK_MINOR);
	free_chunks(c, n);
	return b;
}

/* Opens and decodes every chunk; the count of chunks decoded, or -1 when
 * open fails. Checks the guarantees of whatever decodes. */
static int decode_all(const uint8_t *d, size_t n, const mlod_pack_skeleton *given_skel, int *bad)
{
	mlod_pack p;
	mlod_error e;
	if (mlod_pack_open(d, n, &p, &e) != MLOD_OK) {
		if (!e.message[0])
			*bad = 1;
		return -1;
	}
	int ok = 0;
	mlod_pack_info info;
	if (mlod_pack_decode_info(&p, d, n, &info, &e) == MLOD_OK) {
		ok++;
		if (!info.name)
			*bad = 1;
		for (uint32_t c = 0; c < info.rec.clip_count; c++)
			if (!info.clip_names[c])
				*bad = 1;
	} else if (!e.message[0]) {
		*bad = 1;
	}
	mlod_pack_info_free(&info);
	mlod_pack_skeleton skel;
	const mlod_pack_skeleton *sk = given_skel;
	if (mlod_pack_decode_skeleton(&p, d, n, &skel, &e) == MLOD_OK) {
		ok++;
		for (uint32_t j = 0; j < skel.joint_count; j++)
			if (skel.joints[j].parent >= (int32_t)j || !skel.joint_names[j])
				*bad = 1;
		if (!given_skel)
			sk = &skel;
	}
	for (uint32_t i = 0; i < p.chunk_count; i++) {
		const mlod_pack_chunk *c = &p.chunks[i];
		mlod_result r = MLOD_OK;
		e.message[0] = 0;
		if (c->type == MLOD_CHUNK_SKELETON && c->level > 0 && sk) {
			mlod_pack_skel_level l;
			r = mlod_pack_decode_skel_level(&p, i, d, n, sk, &l, &e);
			if (r == MLOD_OK)
				for (uint32_t k = 0; k < l.palette_size; k++)
					if (l.palette_joint[k] >= sk->joint_count)
						*bad = 1;
			mlod_pack_skel_level_free(&l);
		} else if (c->type == MLOD_CHUNK_MESH) {
			mlod_pack_mesh m;
			r = mlod_pack_decode_mesh(&p, i, d, n, sk, &m, &e);
			for (uint32_t k = 0; r == MLOD_OK && k < m.part_count; k++) {
				const mlod_pack_part *pt = &m.parts[k];
				for (uint32_t x = 0; x < pt->rec.index_count; x++)
					if (pt->indices[x] >= pt->rec.vertex_count)
						*bad = 1;
				for (uint32_t v = 0; v < pt->rec.vertex_count; v++) {
					for (int a = 0; a < 3; a++)
						if (!isfinite(pt->positions[3 * v + a]))
							*bad = 1;
					if (pt->weights) {
						float s = 0;
						for (int a = 0; a < 4; a++)
							s += pt->weights[4 * v + a];
						if (fabsf(s - 1) > 1e-5f)
							*bad = 1;
					}
					if (pt->normals) {
						const float *nn = pt->normals + 3 * v;
						if (fabsf(nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2] - 1) > 1e-5f)
							*bad = 1;
					}
				}
			}
			mlod_pack_mesh_free(&m);
		} else if (c->type == MLOD_CHUNK_MOTION) {
			mlod_pack_motion m;
			r = mlod_pack_decode_motion(&p, i, d, n, sk, &m, &e);
			for (uint32_t k = 0; r == MLOD_OK && k < m.channel_count; k++)
				if (!sk || m.channels[k].rec.joint >= sk->joint_count)
					*bad = 1;
			mlod_pack_motion_free(&m);
		} else if (c->type == MLOD_CHUNK_DOC && c->entropy == MLOD_ENTROPY_NONE) {
			const void *g;
			size_t gs;
			r = mlod_pack_doc(&p, d, n, &g, &gs, &e);
			if (r == MLOD_OK && ((const uint8_t *)g < d || (const uint8_t *)g + gs > d + n))
				*bad = 1;
		} else if (c->type == MLOD_CHUNK_DOC) {
			mlod_pack_doc_bytes g;
			r = mlod_pack_decode_doc(&p, d, n, &g, &e);
			if (r == MLOD_OK && (g.size > c->raw_size || (g.size && !g.glb)))
				*bad = 1;
			mlod_pack_doc_free(&g);
		} else {
			continue;
		}
		if (r == MLOD_OK)
			ok++;
		else if (!e.message[0])
			*bad = 1;
	}
	mlod_pack_skeleton_free(&skel);
	mlod_pack_close(&p);
	return ok;
}

/* ------------------------------------------------------------------ */
/* Tests                                                               */
/* ------------------------------------------------------------------ */

TEST(crc_known_vectors)
{
	CHECK(mlod_pack_crc32(0, "123456789", 9) == 0xCBF43926u);
	CHECK(mlod_pack_crc32(0, "", 0) == 0);
	CHECK(mlod_pack_crc32(0, "The quick brown fox jumps over the lazy dog", 43) == 0x414FA339u);
	CHECK(mlod_pack_crc32(0, "a", 1) == 0xE8B7BE43u);
	/* Incremental, as zlib's crc32. */
	CHECK(mlod_pack_crc32(mlod_pack_crc32(0, "12345", 5), "6789", 4) == 0xCBF43926u);
}

TEST(open_reads_header_and_toc)
{
	buf b = make_pack(0);
	mlod_pack p;
	CHECK_OK(mlod_pack_open(b.p, b.n, &p, &terr));
	int ok = p.major == MLOD_PACK_MAJOR && p.minor == MLOD_PACK_MINOR && p.chunk_count == C_COUNT && p.file_size == b.n &&
	         p.chunks[C_MESH0].type == MLOD_CHUNK_MESH && p.chunks[C_MESH0].codec == MLOD_CODEC_MESHOPT &&
	         p.chunks[C_MESH1].level == 1 && p.chunks[C_MESH1].error == 0.01f &&
	         p.chunks[C_MESH1].distance == 9.35f && p.chunks[C_MESH1].offset % 16 == 0;
	int f1 = mlod_pack_find(&p, MLOD_CHUNK_MESH, 1, 0), f2 = mlod_pack_find(&p, MLOD_CHUNK_MOTION, 0, 0),
	    f3 = mlod_pack_find(&p, MLOD_CHUNK_MOTION, 0, 1), f4 = mlod_pack_find(&p, MLOD_CHUNK_DOC, 0, 0);
	mlod_pack_close(&p);
	static const mlod_pack zero_pack;
	int zeroed = memcmp(&p, &zero_pack, sizeof p) == 0;
	free(b.p);
	CHECK(ok);
	CHECK(f1 == C_MESH1 && f2 == C_MOT0 && f3 == -1 && f4 == C_DOC);
	CHECK(zeroed);
}

TEST(names)
{
	CHECK(strcmp(mlod_pack_type_name(MLOD_CHUNK_INFO), "INFO") == 0);
	CHECK(strcmp(mlod_pack_type_name(MLOD_CHUNK_SKELETON), "SKEL") == 0);
	CHECK(strcmp(mlod_pack_type_name(MLOD_CHUNK_MESH), "MESH") == 0);
	CHECK(strcmp(mlod_pack_type_name(MLOD_CHUNK_MOTION), "ANIM") == 0);
	CHECK(strcmp(mlod_pack_type_name(MLOD_CHUNK_DOC), "DOC") == 0);
	CHECK(strcmp(mlod_pack_type_name(MLOD_FOURCC('X', 'X', 'X', 'X')), "unknown") == 0);
	CHECK(strcmp(mlod_pack_codec_name(0), "none") == 0 && strcmp(mlod_pack_codec_name(1), "meshopt") == 0 &&
	      strcmp(mlod_pack_codec_name(2), "draco") == 0 && strcmp(mlod_pack_codec_name(3), "unknown") == 0);
	CHECK(strcmp(mlod_pack_layer_name(0), "none") == 0 && strcmp(mlod_pack_layer_name(1), "skeleton") == 0 &&
	      strcmp(mlod_pack_layer_name(2), "mesh") == 0 && strcmp(mlod_pack_layer_name(3), "motion") == 0 &&
	      strcmp(mlod_pack_layer_name(4), "unknown") == 0);
}

TEST(decode_info)
{
	buf b = make_pack(0);
	mlod_pack p = {0};
	mlod_pack_info info = {0};
	CHECK_OK(mlod_pack_open(b.p, b.n, &p, &terr));
	memset(&terr, 0, sizeof terr);
	mlod_result r = mlod_pack_decode_info(&p, b.p, b.n, &info, &terr);
	int ok = r == MLOD_OK && info.rec.joint_count == NJ && info.rec.skin_count == 1 && info.rec.clip_count == 1 &&
	         info.rec.mesh_levels == 2 && info.rec.height == 1.8f && strcmp(info.name, "hero") == 0 &&
	         strcmp(info.clip_names[0], "walk") == 0 && info.block != NULL;
	mlod_pack_info_free(&info);
	static const mlod_pack_info zero_info;
	int zeroed = memcmp(&info, &zero_info, sizeof info) == 0;
	mlod_pack_close(&p);
	free(b.p);
	CHECK_MSG(r == MLOD_OK, "%s", terr.message);
	CHECK(ok);
	CHECK(zeroed);
}

TEST(decode_skeleton_and_level)
{
	buf b = make_pack(0);
	mlod_pack p = {0};
	mlod_pack_skeleton s = {0};
	mlod_pack_skel_level l = {0};
	CHECK_OK(mlod_pack_open(b.p, b.n, &p, &terr));
	CHECK_OK(mlod_pack_decode_skeleton(&p, b.p, b.n, &s, &terr));
	CHECK_OK(mlod_pack_decode_skel_level(&p, C_SKEL1, b.p, b.n, &s, &l, &terr));
	int ok = s.joint_count == NJ && s.skin_count == 1 && strcmp(s.joint_names[2], "leg_l") == 0 &&
	         strcmp(s.skin_names[0], "skin") == 0 && s.joints[3].parent == 1 && s.joints[2].t[0] == 0.25f &&
	         s.joints[3].node == 13 && s.skins[0].joint_count == NJ && s.skin_joints[0][3] == 3 &&
	         memcmp(s.inverse_bind[0], ibm_truth, sizeof ibm_truth) == 0;
	int lok = l.kept_count == 2 && l.kept[1] == 1 && l.palette_size == NJ;
	for (int j = 0; lok && j < NJ; j++)
		lok = l.palette_joint[j] == palj_truth[j] && memcmp(l.palette_bind + 16 * j, ibm_truth[palj_truth[j]], 64) == 0;
	/* The level's chunk is not the full skeleton, and vice versa. */
	mlod_pack_skel_level l2;
	mlod_result r1 = mlod_pack_decode_skel_level(&p, C_SKEL, b.p, b.n, &s, &l2, &terr);
	mlod_result r2 = mlod_pack_decode_skel_level(&p, C_MESH1, b.p, b.n, &s, &l2, &terr);
	mlod_pack_mesh m2;
	mlod_result r3 = mlod_pack_decode_mesh(&p, 99, b.p, b.n, &s, &m2, &terr);
	mlod_pack_skel_level_free(&l);
	mlod_pack_skeleton_free(&s);
	mlod_pack_close(&p);
	free(b.p);
	CHECK(ok);
	CHECK(lok);
	CHECK(r1 == MLOD_ERR_INVALID_ARG && r2 == MLOD_ERR_INVALID_ARG && r3 == MLOD_ERR_INVALID_ARG);
}

/* The angle between two unit vectors (float), in double. */
static double angle3(const float *a, const float *b)
{
	double c0 = (double)a[1] * b[2] - (double)a[2] * b[1], c1 = (double)a[2] * b[0] - (double)a[0] * b[2],
	       c2 = (double)a[0] * b[1] - (double)a[1] * b[0];
	return atan2(sqrt(c0 * c0 + c1 * c1 + c2 * c2), (double)a[0] * b[0] + (double)a[1] * b[1] + (double)a[2] * b[2]);
}

/* Decoded vertex dv of pt against truth vertex tv of t: 0 and why when
 * they differ. */
static int check_vertex(const mlod_pack_part *pt, uint32_t v, const part_truth *t, uint32_t w, char *why, size_t n)
{
	/* Octahedral snorm16: at most 3 * sqrt(2) / 2 / 32767 = 6.4742e-5 rad
	 * (at a face's centre, mlod(5)); 1e-6 more for float rounding. */
	const double oct_bound = 3.0 * sqrt(2.0) / 2.0 / 32767.0 + 1e-6;
	for (int a = 0; a < 3; a++)
		if (fabs(pt->positions[3 * v + a] - t->pos[w][a]) > 0.5 * t->pos_scale[a] + 1e-6)
			return snprintf(why, n, "vertex %u position %d: %g vs %g", v, a, pt->positions[3 * v + a], t->pos[w][a]),
			       0;
	if (t->flags & MLOD_PART_NORMALS) {
		double ang = angle3(pt->normals + 3 * v, t->nrm[w]);
		if (ang > oct_bound)
			return snprintf(why, n, "vertex %u normal off by %g rad", v, ang), 0;
	} else if (pt->normals) {
		return snprintf(why, n, "normals without the flag"), 0;
	}
	if (t->flags & MLOD_PART_TANGENTS) {
		const float *d = pt->tangents + 4 * v;
		double ang = angle3(d, t->tan[w]);
		if (ang > oct_bound || d[3] != t->tan[w][3])
			return snprintf(why, n, "vertex %u tangent off by %g rad, w %g", v, ang, d[3]), 0;
	}
	for (uint32_t s = 0; s < t->uv_sets; s++)
		for (int a = 0; a < 2; a++)
			if (fabs(pt->uvs[s][2 * v + a] - t->uv[s][w][a]) > 0.5 * t->uv_scale[s][a] + 1e-6)
				return snprintf(why, n, "vertex %u uv %u", v, s), 0;
	if (t->flags & MLOD_PART_COLORS)
		for (int a = 0; a < 4; a++)
			if (pt->colors[4 * v + a] != t->col[w][a])
				return snprintf(why, n, "vertex %u colour", v), 0;
	if (t->flags & MLOD_PART_SKINNED) {
		float sum = 0;
		for (int a = 0; a < 4; a++) {
			if (pt->joints[4 * v + a] != t->jnt[w][a])
				return snprintf(why, n, "vertex %u joint %d", v, a), 0;
			if (pt->weights[4 * v + a] != t->wq[w][a] / 255.0f)
				return snprintf(why, n, "vertex %u weight %d", v, a), 0;
			/* Largest remainder: within 3/4 of a step of the input. */
			if (fabs(pt->weights[4 * v + a] - t->wgt[w][a]) > 0.75 / 255 + 1e-6)
				return snprintf(why, n, "vertex %u weight %d off the input", v, a), 0;
			sum += pt->weights[4 * v + a];
		}
		if (fabsf(sum - 1) > 1e-5f)
			return snprintf(why, n, "vertex %u weights sum to %g", v, sum), 0;
	}
	for (uint32_t k = 0; k < t->T; k++)
		for (int a = 0; a < 3; a++)
			if (fabs(pt->targets[k][3 * v + a] - t->morph[w][a]) > 0.5 * t->mscale + 1e-7)
				return snprintf(why, n, "vertex %u morph %u", v, k), 0;
	return 1;
}

/* Compares a decoded part with what was encoded: the reader gathers the
 * vertices the level's indices use (in first-use order), so each decoded
 * triangle must carry the truth triangle's vertices, up to the rotation
 * of its corners the index codec may make (it keeps the triangles' order
 * and winding); and no two truth vertices may become one. */
static int check_part(const mlod_pack_part *pt, const part_truth *t, char *why, size_t n)
{
	if (pt->rec.vertex_count != used_vertices(t) || pt->rec.index_count != t->I ||
	    (pt->rec.flags & ~MLOD_PART_INDEX16) != (t->flags & ~MLOD_PART_INDEX16) || pt->rec.uv_sets != t->uv_sets ||
	    pt->rec.target_count != t->T || pt->rec.skin != t->skin || pt->rec.joint != t->joint)
		return snprintf(why, n, "record differs"), 0;
	uint32_t of[NV0];
	for (uint32_t v = 0; v < NV0; v++)
		of[v] = UINT32_MAX;
	for (uint32_t k = 0; k < t->I; k += 3) {
		const uint32_t *a = pt->indices + k, *e = t->idx + k;
		int same = 0;
		char w2[256] = "";
		for (int r = 0; r < 3 && !same; r++) {
			same = 1;
			for (int j = 0; j < 3 && same; j++)
				same = a[j] < pt->rec.vertex_count && check_vertex(pt, a[j], t, e[(j + r) % 3], w2, sizeof w2) &&
				       (of[a[j]] == UINT32_MAX || of[a[j]] == e[(j + r) % 3]);
			for (int j = 0; same && j < 3; j++)
				of[a[j]] = e[(j + r) % 3];
		}
		if (!same)
			return snprintf(why, n, "triangle %u: %u %u %u vs %u %u %u (%s)", k / 3, a[0], a[1], a[2], e[0], e[1],
			                e[2], w2),
			       0;
	}
	return 1;
}

TEST(decode_mesh_meshopt_and_raw)
{
	buf b = make_pack(0);
	mlod_pack p = {0};
	mlod_pack_skeleton s = {0};
	mlod_pack_mesh m0 = {0}, m1 = {0};
	CHECK_OK(mlod_pack_open(b.p, b.n, &p, &terr));
	CHECK_OK(mlod_pack_decode_skeleton(&p, b.p, b.n, &s, &terr));
	CHECK_OK(mlod_pack_decode_mesh(&p, C_MESH0, b.p, b.n, &s, &m0, &terr));
	CHECK_OK(mlod_pack_decode_mesh(&p, C_MESH1, b.p, b.n, &s, &m1, &terr));
	char why[256] = "";
	int ok = m0.part_count == 2 && m1.part_count == 2 && check_part(&m0.parts[0], &parts_truth[0], why, sizeof why) &&
	         check_part(&m0.parts[1], &parts_truth[1], why, sizeof why) &&
	         check_part(&m1.parts[0], &parts_truth[2], why, sizeof why) &&
	         check_part(&m1.parts[1], &parts_truth[3], why, sizeof why) && m0.parts[1].rec.instance == 1 &&
	         m0.parts[1].normals == NULL && m0.parts[1].uvs[0] == NULL && m0.parts[1].targets == NULL;
	mlod_pack_mesh_free(&m0);
	mlod_pack_mesh_free(&m1);
	mlod_pack_mesh_free(&m1); /* twice: the struct is zeroed */
	mlod_pack_skeleton_free(&s);
	mlod_pack_close(&p);
	free(b.p);
	CHECK_MSG(ok, "%s", why);
}

/* mlod_pack_check decodes every chunk: the test pack passes, with and
 * without the entropy stage; a byte changed inside MESH level 1 fails it
 * naming that chunk, and a byte changed inside DOC fails it naming DOC
 * (the last chunk: every chunk before it was decoded). */
TEST(check_decodes_every_chunk)
{
	for (int z = 0; z < 2; z++) {
		zstd_level = z ? 19 : 0;
		buf b = make_pack(0);
		mlod_pack p = {0};
		CHECK_OK(mlod_pack_open(b.p, b.n, &p, &terr));
		CHECK_OK(mlod_pack_check(&p, b.p, b.n, &terr));
		const uint32_t bad[2] = {C_MESH1, C_DOC};
		const char *text[2] = {"MESH level 1: CRC mismatch", "DOC: CRC mismatch"};
		for (int k = 0; k < 2; k++) {
			uint8_t *at = b.p + p.chunks[bad[k]].offset + p.chunks[bad[k]].stored_size / 2;
			*at ^= 0x5a;
			CHECK_ERR(mlod_pack_check(&p, b.p, b.n, &terr), MLOD_ERR_PARSE, text[k]);
			*at ^= 0x5a;
		}
		mlod_pack_close(&p);
		free(b.p);
	}
	zstd_level = 0;
}

/* MOTION level 0's key times as 'TBIT' (format 3.0) instead of 'TICK':
 * the two arrays' first ticks (0, 0), then the bits of ticks 1 to NK - 1
 * of each, set: the same times; words as given. */
static void motion_tbit(wchunk *c, uint32_t bits, uint32_t words)
{
	for (int i = 0; i < c[C_MOT0].ns; i++) {
		wstream *s = &c[C_MOT0].s[i];
		if (s->tag != MLOD_STREAM_TICK)
			continue;
		s->tag = MLOD_STREAM_TBIT;
		s->data.n = 0;
		put32(&s->data, 0);
		put32(&s->data, 0);
		put32(&s->data, bits);
		for (uint32_t w = 3; w < words; w++)
			put32(&s->data, 0);
		s->count = words;
	}
}

TEST(motion_tick_bits)
{
	_Static_assert(NK == 5, "the bits below are for 5 keys per array");
	static const struct {
		uint32_t bits, words;
		mlod_result code;
		const char *text;
	} cases[] = {
	        {0xff, 3, MLOD_OK, ""},
	        {0x7f, 3, MLOD_ERR_PARSE, "MOTION level 0 of clip 0: stream 2 'TBIT': time array 1: key 4: the bits run out"},
	        {0xff, 4, MLOD_ERR_PARSE,
	         "MOTION level 0 of clip 0: stream 2 'TBIT' has 4 elements, expected 3 (the arrays' first ticks and bits)"},
	};
	for (size_t k = 0; k < sizeof cases / sizeof *cases; k++) {
		static wchunk c[C_COUNT + 1];
		int n = make_chunks(c, 0);
		motion_tbit(c, cases[k].bits, cases[k].words);
		buf b = build_pack(c, n, MLOD_PACK_MAJOR, 0);
		free_chunks(c, n);
		mlod_pack p = {0};
		mlod_pack_skeleton s = {0};
		mlod_pack_motion m = {0};
		CHECK_OK(mlod_pack_open(b.p, b.n, &p, &terr));
		CHECK_OK(mlod_pack_decode_skeleton(&p, b.p, b.n, &s, &terr));
		memset(&terr, 0, sizeof terr);
		mlod_result r = mlod_pack_decode_motion(&p, C_MOT0, b.p, b.n, &s, &m, &terr);
		int ok = r == cases[k].code && strstr(terr.message, cases[k].text) != NULL;
		for (int q = 0; ok && r == MLOD_OK && q < NK; q++)
			ok = m.channels[1].times[q] == time_truth[q] && m.channels[3].times[q] == time_truth[q];
		CHECK_MSG(ok, "case %zu: returned %d: %s", k, (int)r, terr.message);
		mlod_pack_motion_free(&m);
		mlod_pack_skeleton_free(&s);
		mlod_pack_close(&p);
		free(b.p);
	}
}

TEST(decode_motion)
{
	buf b = make_pack(0);
	mlod_pack p = {0};
	mlod_pack_skeleton s = {0};
	mlod_pack_motion m = {0}, m1 = {0};
	CHECK_OK(mlod_pack_open(b.p, b.n, &p, &terr));
	CHECK_OK(mlod_pack_decode_skeleton(&p, b.p, b.n, &s, &terr));
	CHECK_OK(mlod_pack_decode_motion(&p, C_MOT0, b.p, b.n, &s, &m, &terr));
	CHECK_OK(mlod_pack_decode_motion(&p, C_MOT1, b.p, b.n, &s, &m1, &terr));
	int ok = m.channel_count == 4 && m.duration == time_truth[NK - 1] && m1.duration == 1.0f &&
	         m1.channels[0].values[5] == 5.0f;
	for (int k = 0; ok && k < NK; k++) {
		ok = m.channels[1].times[k] == time_truth[k] && m.channels[3].times[k] == time_truth[k];
		for (int a = 0; ok && a < 3; a++)
			ok = m.channels[0].values[3 * k + a] == vec_truth[k][a] && m.channels[3].values[3 * k + a] == vec_truth[k][a];
		for (int a = 0; ok && a < 4; a++)
			ok = m.channels[1].values[4 * k + a] == (float)(rotq_truth[k][a] / 32767.0) &&
			     fminf(fabsf(m.channels[1].values[4 * k + a] - rot_truth[k][a]),
			           fabsf(m.channels[1].values[4 * k + a] + rot_truth[k][a])) <= 2.0f / 32767 + 1e-7f;
	}
	for (int k = 0; ok && k < 3 * NK; k++)
		for (int a = 0; ok && a < 4; a++)
			ok = m.channels[2].values[4 * k + a] == rot_truth[k][a];
	ok = ok && m.channels[2].rec.interp == 2 && m.channels[3].rec.path == 2;
	/* one time array for channels 0 to 2, another for channel 3 */
	ok = ok && m.channels[0].times == m.channels[1].times && m.channels[1].times == m.channels[2].times &&
	     m.channels[3].times != m.channels[0].times;
	mlod_pack_motion_free(&m);
	mlod_pack_motion_free(&m1);
	mlod_pack_skeleton_free(&s);
	mlod_pack_close(&p);
	free(b.p);
	CHECK(ok);
}

TEST(doc_points_into_the_data)
{
	buf b = make_pack(0);
	mlod_pack p = {0};
	const void *glb = NULL;
	size_t gs = 0;
	CHECK_OK(mlod_pack_open(b.p, b.n, &p, &terr));
	CHECK_OK(mlod_pack_doc(&p, b.p, b.n, &glb, &gs, &terr));
	size_t at = (size_t)((const uint8_t *)glb - b.p);
	int ok = gs == 32 && memcmp(glb, "glTF\x02", 5) == 0 && at > 0 && at + gs <= b.n;
	mlod_pack_close(&p);
	free(b.p);
	CHECK(ok);
}

TEST(free_accepts_zeroed)
{
	mlod_pack p = {0};
	mlod_pack_info i = {0};
	mlod_pack_skeleton s = {0};
	mlod_pack_skel_level l = {0};
	mlod_pack_mesh m = {0};
	mlod_pack_motion a = {0};
	mlod_pack_close(&p);
	mlod_pack_info_free(&i);
	mlod_pack_skeleton_free(&s);
	mlod_pack_skel_level_free(&l);
	mlod_pack_mesh_free(&m);
	mlod_pack_motion_free(&a);
	mlod_pack_close(NULL);
	mlod_pack_mesh_free(NULL);
	CHECK(1);
}

TEST(unknown_chunks_are_skipped)
{
	buf b = make_pack(1);
	mlod_pack p = {0};
	CHECK_OK(mlod_pack_open(b.p, b.n, &p, &terr));
	int unknown = p.chunk_count == C_COUNT + 1 && p.chunks[1].type == MLOD_FOURCC('X', 'T', 'R', 'A');
	int mesh = mlod_pack_find(&p, MLOD_CHUNK_MESH, 0, 0);
	mlod_pack_close(&p);
	int bad = 0;
	int ok = decode_all(b.p, b.n, NULL, &bad);
	free(b.p);
	CHECK(unknown);
	CHECK(mesh == C_MESH0 + 1);
	/* INFO, SKELETON, the skeleton level, 2 meshes, 2 motions, DOC. */
	CHECK_MSG(ok == 8 && !bad, "%d chunks decoded, bad %d", ok, bad);
}

TEST(newer_major_is_refused)
{
	static wchunk c[C_COUNT + 1];
	int n = make_chunks(c, 0);
	buf b = build_pack(c, n, MLOD_PACK_MAJOR + 1, 0);
	buf m = build_pack(c, n, MLOD_PACK_MAJOR, 7); /* a newer minor reads */
	free_chunks(c, n);
	mlod_pack p = {0};
	memset(&terr, 0, sizeof terr);
	mlod_result r = mlod_pack_open(b.p, b.n, &p, &terr);
	char msg[sizeof terr.message];
	memcpy(msg, terr.message, sizeof msg);
	mlod_result r2 = mlod_pack_open(m.p, m.n, &p, &terr);
	int minor = p.minor;
	mlod_pack_close(&p);
	free(b.p);
	free(m.p);
	CHECK_MSG(r == MLOD_ERR_UNSUPPORTED, "returned %d: %s", (int)r, msg);
	CHECK_MSG(strcmp(msg, "pack format 10.0 is newer than this reader's 9.x") == 0, "message: %s", msg);
	CHECK(r2 == MLOD_OK && minor == 7);
}

/* Format 4.0's shifted 'ROTQ' keys: e[3] = index | shift << 2, the three
 * stored components times 2^shift; the rebuilt one as at shift 0; shift 0
 * as before. */
TEST(rotq_shift_decodes)
{
	int16_t e[4] = {100, -50, 20, (int16_t)(3 | 2 << 2)}, n[4];
	mlod_pack_rotq_key(e, NULL, NULL, n);
	double s = 0;
	for (int c = 0; c < 3; c++)
		s += (double)(float)(n[c] / 32767.0) * (float)(n[c] / 32767.0);
	CHECK_MSG(n[0] == 400 && n[1] == -200 && n[2] == 80 && n[3] == (int16_t)lrint(sqrt(1.0 - s) * 32767.0),
	          "%d %d %d %d", n[0], n[1], n[2], n[3]);
	int16_t z[4] = {400, -200, 80, 3}, m[4];
	mlod_pack_rotq_key(z, NULL, NULL, m);
	CHECK(memcmp(n, m, sizeof n) == 0);
}

/* Format 9.0 stores a 'ROTQ' key but a channel's first as the zigzagged
 * difference to its prediction; an 8.x pack's keys, as they are, still
 * read to the same keys, and the same bytes read as 9.0 do not. */
/* Format 9.0's ROTQ prediction is integer arithmetic after F = lrint(f
 * 2^24), so that every compiler and flag set (fused multiply-adds) reads
 * the same keys: exact values, ties half away from zero (lrint's ties to
 * even gave 0 for both halves below), the dot product's sign, the big
 * component's sign, a shift, and no next key. */
TEST(rotq_predict_integers)
{
	int16_t pred[3];
	const int16_t a[4] = { 100, 200, 300, 32000 }, b[4] = { 102, 204, 306, 32000 };
	mlod_pack_rotq_predict(3, a, b, 0.5, pred);
	CHECK_MSG(pred[0] == 101 && pred[1] == 202 && pred[2] == 303, "%d %d %d", pred[0], pred[1], pred[2]);
	const int16_t z[4] = { 0, 0, 0, 32767 }, h[4] = { 1, -1, 3, 32767 };
	mlod_pack_rotq_predict(3, z, h, 0.5, pred);
	CHECK_MSG(pred[0] == 1 && pred[1] == -1 && pred[2] == 2, "ties: %d %d %d", pred[0], pred[1], pred[2]);
	const int16_t t[4] = { 3000, 0, 0, 32000 };
	mlod_pack_rotq_predict(3, z, t, 1.0 / 3.0, pred); /* 3000 * 5592405 / 2^24 = 999.99994 */
	CHECK_MSG(pred[0] == 1000 && pred[1] == 0 && pred[2] == 0, "thirds: %d %d %d", pred[0], pred[1], pred[2]);
	const int16_t n[4] = { -400, 0, 0, -32000 }; /* dot < 0: the prediction runs to -n */
	mlod_pack_rotq_predict(3, a, n, 1.0, pred);
	CHECK_MSG(pred[0] == 400 && pred[1] == 0 && pred[2] == 0, "dot: %d %d %d", pred[0], pred[1], pred[2]);
	const int16_t m[4] = { 800, -400, 40, -32000 }; /* big component negative: negated, then / 2^2 */
	mlod_pack_rotq_predict(3 + 4 * 2, m, NULL, 0.0, pred);
	CHECK_MSG(pred[0] == -200 && pred[1] == 100 && pred[2] == -10, "shift: %d %d %d", pred[0], pred[1], pred[2]);
}

TEST(format_8_rotq_reads)
{
	static wchunk c[C_COUNT + 1];
	rotq_v9 = 0;
	int n = make_chunks(c, 0);
	buf b8 = build_pack(c, n, 8, 1), b9 = build_pack(c, n, 9, 0);
	free_chunks(c, n);
	rotq_v9 = 1;
	mlod_pack p = {0}, p9 = {0};
	mlod_pack_skeleton s = {0};
	mlod_pack_motion m = {0}, m9 = {0};
	CHECK_OK(mlod_pack_open(b8.p, b8.n, &p, &terr));
	CHECK_OK(mlod_pack_decode_skeleton(&p, b8.p, b8.n, &s, &terr));
	CHECK_OK(mlod_pack_decode_motion(&p, C_MOT0, b8.p, b8.n, &s, &m, &terr));
	CHECK_OK(mlod_pack_open(b9.p, b9.n, &p9, &terr));
	mlod_result r9 = mlod_pack_decode_motion(&p9, C_MOT0, b9.p, b9.n, &s, &m9, &terr);
	int ok = p.major == 8 && m.channel_count == 4, differs = r9 != MLOD_OK;
	for (int k = 0; ok && k < NK; k++)
		for (int a = 0; ok && a < 4; a++) {
			ok = m.channels[1].values[4 * k + a] == (float)(rotq_truth[k][a] / 32767.0);
			differs |= r9 == MLOD_OK && m9.channels[1].values[4 * k + a] != m.channels[1].values[4 * k + a];
		}
	mlod_pack_motion_free(&m);
	mlod_pack_motion_free(&m9);
	mlod_pack_skeleton_free(&s);
	mlod_pack_close(&p);
	mlod_pack_close(&p9);
	free(b8.p);
	free(b9.p);
	CHECK(ok);
	CHECK(differs);
}

/* Format 2.0 changed the MESH layout (b2) and the MOTION streams: a 1.x
 * pack is refused whole, with what to do; there is no 1.x decode. */
TEST(older_major_is_refused)
{
	static wchunk c[C_COUNT + 1];
	int n = make_chunks(c, 0);
	buf b = build_pack(c, n, 1, 0);
	free_chunks(c, n);
	mlod_pack p = {0};
	memset(&terr, 0, sizeof terr);
	mlod_result r = mlod_pack_open(b.p, b.n, &p, &terr);
	free(b.p);
	CHECK_MSG(r == MLOD_ERR_UNSUPPORTED && p.chunks == NULL, "returned %d: %s", (int)r, terr.message);
	CHECK_MSG(strcmp(terr.message, "mlod 1.0 pack: made by an older mlod-pack; pack the input again (this reader "
	                               "reads 2.x to 9.x)") == 0,
	          "message: %s", terr.message);
}

/* Format 3.0 added parts in their own numbering (MLOD_PART_LOCAL, 'IMAP')
 * and the index sequence codec; a 2.0 pack, which has neither, reads. */
TEST(format_2_0_reads)
{
	static wchunk c[C_COUNT + 1];
	local_flag = 0, pal_refs = 0;
	int n = make_chunks(c, 0);
	buf b = build_pack(c, n, 2, 0);
	free_chunks(c, n);
	mlod_pack p = {0};
	mlod_pack_skeleton s = {0};
	mlod_pack_mesh m0 = {0}, m1 = {0};
	CHECK_OK(mlod_pack_open(b.p, b.n, &p, &terr));
	CHECK(p.major == 2 && p.minor == 0);
	CHECK(!(parts_truth[1].flags & MLOD_PART_LOCAL) && !(parts_truth[2].flags & MLOD_PART_LOCAL));
	CHECK_OK(mlod_pack_decode_skeleton(&p, b.p, b.n, &s, &terr));
	CHECK_OK(mlod_pack_decode_mesh(&p, C_MESH0, b.p, b.n, &s, &m0, &terr));
	CHECK_OK(mlod_pack_decode_mesh(&p, C_MESH1, b.p, b.n, &s, &m1, &terr));
	char why[256] = "";
	int ok = m0.part_count == 2 && m1.part_count == 2 && check_part(&m0.parts[0], &parts_truth[0], why, sizeof why) &&
	         check_part(&m0.parts[1], &parts_truth[1], why, sizeof why) &&
	         check_part(&m1.parts[0], &parts_truth[2], why, sizeof why) &&
	         check_part(&m1.parts[1], &parts_truth[3], why, sizeof why) &&
	         !(m0.parts[1].rec.flags & MLOD_PART_LOCAL);
	mlod_pack_mesh_free(&m0);
	mlod_pack_mesh_free(&m1);
	mlod_pack_skeleton_free(&s);
	mlod_pack_close(&p);
	free(b.p);
	local_flag = MLOD_PART_LOCAL, pal_refs = 1;
	CHECK_MSG(ok, "%s", why);
}

static uint8_t *stream_data(wchunk *c, int chunk, uint32_t tag, int nth);

/* Format 7.0 stores a skeleton level's palette as references ('PALR',
 * 'PALX') and derives its joints; a 6.0 pack's 'PALJ' and 'PALB' still
 * read, to the same palette, and a 'PALJ' entry that is not the nearest
 * kept ancestor is still refused. A 7.0 pack with 'PALJ' and 'PALB' is
 * refused. */
TEST(format_6_0_palette_reads)
{
	static wchunk c[C_COUNT + 1];
	pal_refs = 0;
	int n = make_chunks(c, 0);
	buf b = build_pack(c, n, 6, 0), b7 = build_pack(c, n, 7, 0);
	wr32(stream_data(c, C_SKEL1, MLOD_STREAM_PALJ, 0) + 4 * 3, 2);
	buf bad = build_pack(c, n, 6, 0);
	free_chunks(c, n);
	pal_refs = 1;
	mlod_pack p = {0}, p7 = {0}, pb = {0};
	mlod_pack_skeleton s = {0};
	mlod_pack_skel_level l = {0}, l7 = {0}, lb = {0};
	CHECK_OK(mlod_pack_open(b.p, b.n, &p, &terr));
	CHECK_OK(mlod_pack_decode_skeleton(&p, b.p, b.n, &s, &terr));
	CHECK_OK(mlod_pack_decode_skel_level(&p, C_SKEL1, b.p, b.n, &s, &l, &terr));
	int ok = p.major == 6 && l.kept_count == 2 && l.palette_size == NJ;
	for (int j = 0; ok && j < NJ; j++)
		ok = l.palette_joint[j] == palj_truth[j] && memcmp(l.palette_bind + 16 * j, ibm_truth[palj_truth[j]], 64) == 0;
	CHECK_OK(mlod_pack_open(b7.p, b7.n, &p7, &terr));
	mlod_result r7 = mlod_pack_decode_skel_level(&p7, C_SKEL1, b7.p, b7.n, &s, &l7, &terr);
	char m7[sizeof terr.message];
	snprintf(m7, sizeof m7, "%s", terr.message);
	CHECK_OK(mlod_pack_open(bad.p, bad.n, &pb, &terr));
	mlod_result rb = mlod_pack_decode_skel_level(&pb, C_SKEL1, bad.p, bad.n, &s, &lb, &terr);
	mlod_pack_skel_level_free(&l);
	mlod_pack_skeleton_free(&s);
	mlod_pack_close(&p);
	mlod_pack_close(&p7);
	mlod_pack_close(&pb);
	free(b.p);
	free(b7.p);
	free(bad.p);
	CHECK(ok);
	CHECK_MSG(r7 == MLOD_ERR_PARSE && strcmp(m7, "SKELETON level 1: stream 1 is 'PALJ', expected 'PALR'") == 0,
	          "7.0 with PALJ: %d %s", (int)r7, m7);
	CHECK_MSG(rb == MLOD_ERR_PARSE && strcmp(terr.message, "SKELETON level 1: palette entry 3 (skin 0 joint 3): joint "
	                                                       "2 is not a kept joint") == 0,
	          "6.0 bad PALJ: %d %s", (int)rb, terr.message);
}

/* A nested MOTION level (TOC flag MLOD_PACK_CHUNK_NESTED) builds on the
 * clip's next coarser level: the coarsest cannot be nested, and
 * mlod_pack_decode_motion_on needs the base; with one whose channel
 * (joint 1's translation) level 0 lacks, every key of level 0 stands on
 * its own and decodes as before. */
TEST(nested_motion_needs_its_base)
{
	static wchunk c[C_COUNT + 1];
	int n = make_chunks(c, 0);
	c[C_MOT1].flags = MLOD_PACK_CHUNK_NESTED;
	buf b1 = build_pack(c, n, MLOD_PACK_MAJOR, 0);
	c[C_MOT1].flags = 0;
	c[C_MOT0].flags = MLOD_PACK_CHUNK_NESTED;
	wr32(stream_data(c, C_MOT1, MLOD_STREAM_CHAN, 0), 1); /* joint 1's translation: no key of level 0's */
	buf b0 = build_pack(c, n, MLOD_PACK_MAJOR, 0);
	free_chunks(c, n);
	mlod_pack p = {0};
	mlod_pack_skeleton s = {0};
	mlod_pack_motion m = {0}, base = {0};
	CHECK_OK(mlod_pack_open(b1.p, b1.n, &p, &terr));
	CHECK_OK(mlod_pack_decode_skeleton(&p, b1.p, b1.n, &s, &terr));
	memset(&terr, 0, sizeof terr);
	mlod_result r = mlod_pack_decode_motion(&p, C_MOT1, b1.p, b1.n, &s, &m, &terr);
	CHECK_MSG(r == MLOD_ERR_PARSE &&
	              strcmp(terr.message, "MOTION level 1 of clip 0: builds on level 2, which the pack lacks") == 0,
	          "returned %d: %s", (int)r, terr.message);
	mlod_pack_close(&p);
	CHECK_OK(mlod_pack_open(b0.p, b0.n, &p, &terr));
	memset(&terr, 0, sizeof terr);
	r = mlod_pack_decode_motion_on(&p, C_MOT0, b0.p, b0.n, &s, NULL, &m, &terr);
	CHECK_MSG(r == MLOD_ERR_PARSE &&
	              strcmp(terr.message, "MOTION level 0 of clip 0: builds on level 1, which was not given") == 0,
	          "returned %d: %s", (int)r, terr.message);
	CHECK_OK(mlod_pack_decode_motion(&p, C_MOT0, b0.p, b0.n, &s, &m, &terr));
	CHECK_OK(mlod_pack_decode_motion(&p, C_MOT1, b0.p, b0.n, &s, &base, &terr));
	mlod_pack_motion m2 = {0};
	CHECK_OK(mlod_pack_decode_motion_on(&p, C_MOT0, b0.p, b0.n, &s, &base, &m2, &terr));
	int same = m.channel_count == 4 && m2.channel_count == 4;
	for (int k = 0; same && k < NK; k++)
		for (int a = 0; same && a < 4; a++)
			same = m.channels[1].values[4 * k + a] == (float)(rotq_truth[k][a] / 32767.0) &&
			       m2.channels[1].values[4 * k + a] == m.channels[1].values[4 * k + a];
	CHECK(same);
	mlod_pack_motion_free(&m);
	mlod_pack_motion_free(&m2);
	mlod_pack_motion_free(&base);
	mlod_pack_skeleton_free(&s);
	mlod_pack_close(&p);
	free(b1.p);
	free(b0.p);
}

TEST(draco_chunks_are_unsupported)
{
	static wchunk c[C_COUNT + 1];
	int n = make_chunks(c, 0);
	c[C_MESH1].codec = MLOD_CODEC_DRACO;
	buf b = build_pack(c, n, MLOD_PACK_MAJOR, 0);
	free_chunks(c, n);
	mlod_pack p = {0};
	mlod_pack_mesh m = {0};
	CHECK_OK(mlod_pack_open(b.p, b.n, &p, &terr));
	memset(&terr, 0, sizeof terr);
	mlod_result r = mlod_pack_decode_mesh(&p, C_MESH1, b.p, b.n, NULL, &m, &terr);
#if MLOD_DRACO
	/* With the Draco decoder: a layout-b2 chunk marked Draco is malformed
	 * for it (here its part refers to a skin, and no skeleton is given),
	 * and a finer b2 level cannot build on it. */
	char first[sizeof terr.message];
	memcpy(first, terr.message, sizeof first);
	memset(&terr, 0, sizeof terr);
	mlod_result r0 = mlod_pack_decode_mesh(&p, C_MESH0, b.p, b.n, NULL, &m, &terr);
	mlod_pack_close(&p);
	free(b.p);
	CHECK_MSG(r == MLOD_ERR_PARSE && strstr(first, "MESH level 1: part 0: ") == first, "%d %s", r, first);
	CHECK(m.parts == NULL);
	CHECK_MSG(r0 == MLOD_ERR_PARSE && strcmp(terr.message, "MESH level 0: builds on MESH level 1, which is "
	                                                        "Draco-coded (a Draco level stands alone; layout b2 "
	                                                        "levels cannot use its vertices)") == 0,
	          "%d %s", r0, terr.message);
#else
	mlod_pack_close(&p);
	free(b.p);
	CHECK(r == MLOD_ERR_UNSUPPORTED);
	CHECK_MSG(strcmp(terr.message, "MESH level 1: Draco chunks need the Draco decoder, not built in") == 0, "%s",
	          terr.message);
#endif
}

/* A prefix of the pack: open fails until the TOC is in, and then each chunk
 * decodes exactly when its end lies inside the prefix. */
static void every_prefix_of_pack(void);
TEST(every_prefix)
{
	every_prefix_of_pack();
}

/* Every prefix again with the entropy stage on every chunk but INFO. */
TEST(every_prefix_zstd)
{
	zstd_level = 3;
	every_prefix_of_pack();
	zstd_level = 0;
}

/* With the entropy stage, every chunk decodes to what it decodes to
 * without it: the same records, attributes, keys and DOC bytes. */
TEST(entropy_decodes_the_same)
{
	buf a = make_pack(0);
	zstd_level = 19;
	buf z = make_pack(0);
	zstd_level = 0;
	mlod_pack pa, pz;
	CHECK_OK(mlod_pack_open(a.p, a.n, &pa, &terr));
	CHECK_OK(mlod_pack_open(z.p, z.n, &pz, &terr));
	int coded = 0;
	for (uint32_t i = 0; i < pz.chunk_count; i++)
		coded += pz.chunks[i].entropy == MLOD_ENTROPY_ZSTD;
	int plain_mesh0_mot0 = pz.chunks[C_MESH0].entropy || pz.chunks[C_MOT0].entropy;
	mlod_pack_skeleton sa, sz;
	CHECK_OK(mlod_pack_decode_skeleton(&pa, a.p, a.n, &sa, &terr));
	CHECK_OK(mlod_pack_decode_skeleton(&pz, z.p, z.n, &sz, &terr));
	int same = sa.joint_count == sz.joint_count &&
	           memcmp(sa.joints, sz.joints, sizeof *sa.joints * sa.joint_count) == 0 &&
	           memcmp(sa.inverse_bind[0], sz.inverse_bind[0], 64 * (size_t)sa.skins[0].joint_count) == 0;
	for (uint32_t i = 0; i < pa.chunk_count; i++) {
		const mlod_pack_chunk *c = &pa.chunks[i];
		if (c->type == MLOD_CHUNK_MESH) {
			mlod_pack_mesh ma, mz;
			CHECK_OK(mlod_pack_decode_mesh(&pa, i, a.p, a.n, &sa, &ma, &terr));
			CHECK_OK(mlod_pack_decode_mesh(&pz, i, z.p, z.n, &sz, &mz, &terr));
			for (uint32_t k = 0; k < ma.part_count; k++) {
				const mlod_pack_part *x = &ma.parts[k], *y = &mz.parts[k];
				same = same && memcmp(&x->rec, &y->rec, sizeof x->rec) == 0 &&
				       memcmp(x->positions, y->positions, 12 * (size_t)x->rec.vertex_count) == 0 &&
				       memcmp(x->indices, y->indices, 4 * (size_t)x->rec.index_count) == 0;
			}
			mlod_pack_mesh_free(&ma);
			mlod_pack_mesh_free(&mz);
		} else if (c->type == MLOD_CHUNK_MOTION) {
			mlod_pack_motion ma, mz;
			CHECK_OK(mlod_pack_decode_motion(&pa, i, a.p, a.n, &sa, &ma, &terr));
			CHECK_OK(mlod_pack_decode_motion(&pz, i, z.p, z.n, &sz, &mz, &terr));
			same = same && ma.channel_count == mz.channel_count && ma.duration == mz.duration;
			for (uint32_t k = 0; same && k < ma.channel_count; k++) {
				const mlod_pack_channel *x = &ma.channels[k], *y = &mz.channels[k];
				size_t nv = (x->rec.path == 1 ? 4 : 3) * (x->rec.interp == 2 ? 3 : 1) * (size_t)x->rec.key_count;
				same = memcmp(&x->rec, &y->rec, sizeof x->rec) == 0 &&
				       memcmp(x->times, y->times, 4 * (size_t)x->rec.key_count) == 0 &&
				       memcmp(x->values, y->values, 4 * nv) == 0;
			}
			mlod_pack_motion_free(&ma);
			mlod_pack_motion_free(&mz);
		}
	}
	const void *g;
	size_t gs;
	mlod_pack_doc_bytes gz;
	CHECK_OK(mlod_pack_doc(&pa, a.p, a.n, &g, &gs, &terr));
	CHECK_OK(mlod_pack_decode_doc(&pz, z.p, z.n, &gz, &terr));
	same = same && gs == gz.size && memcmp(g, gz.glb, gs) == 0;
	/* mlod_pack_doc cannot point into a zstd frame: it says so. */
	CHECK_ERR(mlod_pack_doc(&pz, z.p, z.n, &g, &gs, &terr), MLOD_ERR_INVALID_ARG,
	          "DOC: stored with the zstd entropy stage");
	mlod_pack_doc_free(&gz);
	mlod_pack_skeleton_free(&sa);
	mlod_pack_skeleton_free(&sz);
	mlod_pack_close(&pa);
	mlod_pack_close(&pz);
	free(a.p);
	free(z.p);
	CHECK_MSG(coded == C_COUNT - 3 && !plain_mesh0_mot0, "%d chunks with the entropy stage", coded);
	CHECK(same);
}

/* The entropy stage's hostile cases, each naming the chunk: the TOC's
 * coded size against the raw size and the frame, a frame without its
 * size, a bomb (a frame that says, or gives, more than the coded size),
 * a truncated or damaged frame, an entropy stage in a 4.0 pack or on
 * INFO, an unknown stage. */
TEST(entropy_checks)
{
	zstd_level = 19;
	buf b = make_pack(0);
	zstd_level = 0;
	uint8_t *d = malloc(b.n + 4096);
	mlod_pack p;
	mlod_pack_mesh m;
	uint8_t *e1 = b.p + 32 + 48 * C_MESH1;
	uint64_t off = get64(e1 + 16);
	uint32_t stored = get32(e1 + 24), raw = get32(e1 + 28), coded = get32(e1 + 12);
	CHECK(e1[5] >> 4 == MLOD_ENTROPY_ZSTD && coded > 0 && coded <= raw);
#define OPEN_FAILS(stmt, code, text)                                                                             \
	do {                                                                                                    \
		memcpy(d, b.p, b.n);                                                                            \
		uint8_t *e = d + 32 + 48 * C_MESH1;                                                             \
		(void)e;                                                                                        \
		stmt;                                                                                           \
		restamp(d, b.n);                                                                                \
		CHECK_ERR(mlod_pack_open(d, b.n, &p, &terr), code, text);                                       \
	} while (0)
#define DECODE_FAILS(stmt, code, text)                                                                           \
	do {                                                                                                    \
		memcpy(d, b.p, b.n);                                                                            \
		uint8_t *e = d + 32 + 48 * C_MESH1;                                                             \
		(void)e;                                                                                        \
		stmt;                                                                                           \
		restamp(d, b.n);                                                                                \
		CHECK_OK(mlod_pack_open(d, b.n, &p, &terr));                                                    \
		CHECK_ERR(mlod_pack_decode_mesh(&p, C_MESH1, d, b.n, NULL, &m, &terr), code, text);             \
		mlod_pack_close(&p);                                                                            \
	} while (0)
	OPEN_FAILS(wr32(e + 12, raw + 1), MLOD_ERR_PARSE, "TOC entry 3 (MESH level 1): coded size");
	OPEN_FAILS(wr32(e + 12, 0), MLOD_ERR_PARSE, "TOC entry 3 (MESH level 1): coded size 0 is not 4 to its raw size");
	OPEN_FAILS((wr16(d + 4, 4), wr16(d + 6, 0)), MLOD_ERR_PARSE,
	           "TOC entry 1 (SKELETON): codec 0x10: an entropy stage in a 4.0 pack");
	OPEN_FAILS(d[32 + 5] = 0x10, MLOD_ERR_PARSE, "TOC entry 0 (INFO): INFO has no entropy stage");
	DECODE_FAILS(e[5] = 0x30, MLOD_ERR_UNSUPPORTED, "MESH level 1: unknown entropy stage 3");
	/* The TOC says fewer bytes than the frame holds (a bomb): refused
	 * before decoding; more: the frame does not give them. */
	DECODE_FAILS(wr32(e + 12, coded - 1), MLOD_ERR_PARSE, "MESH level 1: the zstd frame says");
	DECODE_FAILS(wr32(e + 12, coded + 1 <= raw ? coded + 1 : coded - 1), MLOD_ERR_PARSE,
	             "MESH level 1: the zstd frame says");
	/* Damaged and truncated frames (CRC re-stamped). */
	DECODE_FAILS(d[off] ^= 0xff, MLOD_ERR_PARSE, "MESH level 1: not a zstd frame");
	DECODE_FAILS(wr32(e + 24, stored - 3), MLOD_ERR_PARSE, "MESH level 1: the zstd frame is truncated or malformed");
	/* The frame's last block damaged: zstd's own checks, or the container's. */
	memcpy(d, b.p, b.n);
	d[off + stored - 2] ^= 0x5a;
	restamp(d, b.n);
	CHECK_OK(mlod_pack_open(d, b.n, &p, &terr));
	memset(&terr, 0, sizeof terr);
	mlod_result r = mlod_pack_decode_mesh(&p, C_MESH1, d, b.n, NULL, &m, &terr);
	mlod_pack_close(&p);
	CHECK_MSG(r == MLOD_ERR_PARSE && strncmp(terr.message, "MESH level 1: ", 14) == 0, "returned %d: %s", (int)r,
	          terr.message);
	free(d);
	free(b.p);
	/* A frame without its content size, and a bomb: a frame of 1 MiB of
	 * zeros (about 100 bytes) in place of DOC, whose TOC says 40 bytes. */
	static wchunk c[C_COUNT + 1];
	int n = make_chunks(c, 0);
	zstd_level = 19;
	buf z = build_pack(c, n, MLOD_PACK_MAJOR, 0);
	zstd_level = 0;
	free_chunks(c, n);
	mlod_pack pz;
	CHECK_OK(mlod_pack_open(z.p, z.n, &pz, &terr));
	const mlod_pack_chunk *doc = &pz.chunks[C_DOC];
	size_t big = (size_t)1 << 20;
	uint8_t *zeros = calloc(1, big);
	size_t cap = ZSTD_compressBound(big);
	uint8_t *bomb = malloc(cap);
	size_t bn = ZSTD_compress(bomb, cap, zeros, big, 19);
	ZSTD_CCtx *cc = ZSTD_createCCtx();
	ZSTD_CCtx_setParameter(cc, ZSTD_c_contentSizeFlag, 0);
	uint8_t *nosize = malloc(cap);
	size_t nn = ZSTD_compress2(cc, nosize, cap, zeros, 40);
	ZSTD_freeCCtx(cc);
	CHECK(!ZSTD_isError(bn) && !ZSTD_isError(nn) && bn <= doc->stored_size + 4096 && nn <= 4096);
	for (int k = 0; k < 2; k++) {
		const uint8_t *frame = k ? nosize : bomb;
		size_t fn = k ? nn : bn;
		buf t = {0};
		put(&t, z.p, doc->offset);
		put(&t, frame, fn);
		uint8_t *e = t.p + 32 + 48 * C_DOC;
		wr32(e + 24, (uint32_t)fn);
		wr32(e + 12, 40);
		wr32(t.p + 16, (uint32_t)t.n);
		restamp(t.p, t.n);
		mlod_pack q;
		mlod_pack_doc_bytes g;
		CHECK_OK(mlod_pack_open(t.p, t.n, &q, &terr));
		CHECK_ERR(mlod_pack_decode_doc(&q, t.p, t.n, &g, &terr), MLOD_ERR_PARSE,
		          k ? "DOC: the zstd frame does not state its size (the TOC's coded size is 40)"
		            : "DOC: the zstd frame says 1048576 bytes, the TOC's coded size is 40");
		mlod_pack_close(&q);
		free(t.p);
	}
	free(zeros);
	free(bomb);
	free(nosize);
	mlod_pack_close(&pz);
	free(z.p);
#undef OPEN_FAILS
#undef DECODE_FAILS
}

/* Format 6.0's prefix stage: MESH level 0 (raw streams, so that its
 * container may take a stage) coded on MESH level 1's container. */
static buf prefix_pack(void)
{
	zstd_level = 19, zstd_prefix = 1, mesh0_raw = 1;
	buf b = make_pack(0);
	zstd_level = 0, zstd_prefix = 0, mesh0_raw = 0;
	return b;
}

/* The prefix-coded level decodes to what the plain one does, from a
 * whole file and through a fetch; mlod_pack_check passes; a 5.0 pack
 * (the zstd stage alone) still reads. */
static mlod_result fetch_from(void *user, uint32_t chunk, const void **bytes, mlod_error *err)
{
	const uint8_t *d = user;
	(void)err;
	*bytes = d + get64(d + 32 + 48 * (size_t)chunk + 16);
	return MLOD_OK;
}

TEST(prefix_decodes_the_same)
{
	mesh0_raw = 1;
	buf a = make_pack(0);
	mesh0_raw = 0;
	buf z = prefix_pack();
	mlod_pack pa, pz;
	CHECK_OK(mlod_pack_open(a.p, a.n, &pa, &terr));
	CHECK_OK(mlod_pack_open(z.p, z.n, &pz, &terr));
	CHECK(pz.major == MLOD_PACK_MAJOR && pz.chunks[C_MESH0].entropy == MLOD_ENTROPY_ZSTD_PREFIX &&
	      pz.chunks[C_SKEL1].entropy == MLOD_ENTROPY_ZSTD_PREFIX && pz.chunks[C_SKEL].entropy == MLOD_ENTROPY_ZSTD &&
	      pz.chunks[C_MESH1].entropy == MLOD_ENTROPY_ZSTD && pz.chunks[C_MOT1].entropy == MLOD_ENTROPY_ZSTD);
	CHECK(strcmp(mlod_pack_entropy_name(MLOD_ENTROPY_ZSTD_PREFIX), "zstd-prefix") == 0);
	mlod_pack_skeleton sa;
	CHECK_OK(mlod_pack_decode_skeleton(&pa, a.p, a.n, &sa, &terr));
	int same = 1;
	mlod_pack_skel_level la, lz;
	CHECK_OK(mlod_pack_decode_skel_level(&pa, C_SKEL1, a.p, a.n, &sa, &la, &terr));
	CHECK_OK(mlod_pack_decode_skel_level(&pz, C_SKEL1, z.p, z.n, &sa, &lz, &terr));
	same &= la.kept_count == lz.kept_count && memcmp(la.kept, lz.kept, 4 * (size_t)la.kept_count) == 0;
	mlod_pack_skel_level_free(&la);
	mlod_pack_skel_level_free(&lz);
	for (int k = 0; k < 3; k++) {
		uint32_t ci = k == 2 ? C_MESH1 : C_MESH0;
		mlod_pack_mesh ma, mz;
		CHECK_OK(mlod_pack_decode_mesh(&pa, ci, a.p, a.n, &sa, &ma, &terr));
		if (k == 1)
			CHECK_OK(mlod_pack_decode_mesh_fetch(&pz, ci, fetch_from, z.p, &sa, &mz, &terr));
		else
			CHECK_OK(mlod_pack_decode_mesh(&pz, ci, z.p, z.n, &sa, &mz, &terr));
		same &= ma.part_count == mz.part_count;
		for (uint32_t i = 0; same && i < ma.part_count; i++) {
			const mlod_pack_part *x = &ma.parts[i], *y = &mz.parts[i];
			same = memcmp(&x->rec, &y->rec, sizeof x->rec) == 0 &&
			       memcmp(x->positions, y->positions, 12 * (size_t)x->rec.vertex_count) == 0 &&
			       memcmp(x->indices, y->indices, 4 * (size_t)x->rec.index_count) == 0;
		}
		mlod_pack_mesh_free(&ma);
		mlod_pack_mesh_free(&mz);
	}
	CHECK(same);
	CHECK_OK(mlod_pack_check(&pz, z.p, z.n, &terr));
	/* A truncated prefix of the file that holds MESH level 1 but not level 0
	 * still decodes level 1; level 0 is refused as truncated. */
	size_t cut = (size_t)pz.chunks[C_MESH0].offset + pz.chunks[C_MESH0].stored_size - 1;
	mlod_pack_mesh m;
	CHECK_OK(mlod_pack_decode_mesh(&pz, C_MESH1, z.p, cut, &sa, &m, &terr));
	mlod_pack_mesh_free(&m);
	CHECK_ERR(mlod_pack_decode_mesh(&pz, C_MESH0, z.p, cut, &sa, &m, &terr), MLOD_ERR_PARSE,
	          "MESH level 0: truncated");
	mlod_pack_skeleton_free(&sa);
	mlod_pack_close(&pa);
	mlod_pack_close(&pz);
	/* 5.0: the zstd stage alone reads; the prefix stage is refused. */
	zstd_level = 19, pal_refs = 0;
	buf f = make_pack(0);
	zstd_level = 0, pal_refs = 1;
	wr16(f.p + 4, 5);
	restamp(f.p, f.n);
	mlod_pack p5;
	CHECK_OK(mlod_pack_open(f.p, f.n, &p5, &terr));
	CHECK_OK(mlod_pack_check(&p5, f.p, f.n, &terr));
	mlod_pack_close(&p5);
	free(f.p);
	free(a.p);
	free(z.p);
}

/* The prefix stage's hostile cases, each naming the chunk. */
TEST(prefix_checks)
{
	buf b = prefix_pack();
	uint8_t *d = malloc(b.n);
	mlod_pack p;
	mlod_pack_mesh m;
	const uint8_t *e0 = b.p + 32 + 48 * C_MESH0;
	uint32_t coded = get32(e0 + 12);
	CHECK(e0[5] >> 4 == MLOD_ENTROPY_ZSTD_PREFIX);
	mlod_pack_skeleton sk;
	CHECK_OK(mlod_pack_open(b.p, b.n, &p, &terr));
	CHECK_OK(mlod_pack_decode_skeleton(&p, b.p, b.n, &sk, &terr));
	mlod_pack_close(&p);
#define EDIT(stmt)                                                                                               \
	do {                                                                                                    \
		memcpy(d, b.p, b.n);                                                                            \
		uint8_t *e = d + 32 + 48 * C_MESH0;                                                             \
		(void)e;                                                                                        \
		stmt;                                                                                           \
		restamp(d, b.n);                                                                                \
	} while (0)
#define OPEN_FAILS(stmt, text)                                                                                   \
	do {                                                                                                    \
		EDIT(stmt);                                                                                     \
		CHECK_ERR(mlod_pack_open(d, b.n, &p, &terr), MLOD_ERR_PARSE, text);                             \
	} while (0)
#define DECODE_FAILS(stmt, text)                                                                                 \
	do {                                                                                                    \
		EDIT(stmt);                                                                                     \
		CHECK_OK(mlod_pack_open(d, b.n, &p, &terr));                                                    \
		CHECK_ERR(mlod_pack_decode_mesh(&p, C_MESH0, d, b.n, &sk, &m, &terr), MLOD_ERR_PARSE, text);    \
		mlod_pack_close(&p);                                                                            \
	} while (0)
	/* A 5.x pack has no prefix stage (a 5.x reader refuses 6.0 whole). */
	OPEN_FAILS((wr16(d + 4, 5), wr16(d + 6, 0)),
	           "TOC entry 2 (SKELETON level 1): codec 0x20: a zstd prefix stage in a 5.0 pack");
	/* The coarsest level has nothing to be coded on; other types have no
	 * prefix (their dependencies are not MESH levels). */
	OPEN_FAILS(d[32 + 48 * C_MESH1 + 5] = 0x20, "TOC entry 3 (MESH level 1): the zstd prefix stage on the coarsest");
	OPEN_FAILS(d[32 + 48 * C_MOT1 + 5] = 0x20, "TOC entry 4 (MOTION level 1 of clip 0): the zstd prefix stage is for "
	                                           "MESH and skeleton levels only");
	OPEN_FAILS(d[32 + 48 * C_SKEL + 5] = 0x21, "TOC entry 1 (SKELETON): the zstd prefix stage is for MESH and");
	OPEN_FAILS(d[32 + 48 * C_DOC + 5] = 0x20, "TOC entry 7 (DOC): the zstd prefix stage is for MESH and");
	/* A skeleton level read without its prefix; with SKELETON damaged
	 * (not re-stamped), the error names SKELETON. */
	EDIT(d[32 + 48 * C_SKEL1 + 5] = 0x10);
	CHECK_OK(mlod_pack_open(d, b.n, &p, &terr));
	mlod_pack_skel_level sl;
	CHECK_ERR(mlod_pack_decode_skel_level(&p, C_SKEL1, d, b.n, &sk, &sl, &terr), MLOD_ERR_PARSE, "SKELETON level 1: ");
	mlod_pack_close(&p);
	memcpy(d, b.p, b.n);
	d[get64(d + 32 + 48 * C_SKEL + 16) + 7] ^= 1;
	CHECK_OK(mlod_pack_open(d, b.n, &p, &terr));
	CHECK_ERR(mlod_pack_decode_skel_level(&p, C_SKEL1, d, b.n, &sk, &sl, &terr), MLOD_ERR_PARSE, "SKELETON: CRC mismatch");
	mlod_pack_close(&p);
	/* The frame read without its prefix, a damaged coarser level (named
	 * before level 0 is read), a bomb (the frame says more than the TOC). */
	DECODE_FAILS(e[5] = 0x11, "MESH level 0: zstd: ");
	memcpy(d, b.p, b.n);
	d[get64(d + 32 + 48 * C_MESH1 + 16) + 5] ^= 1; /* not re-stamped: the chunk's CRC */
	CHECK_OK(mlod_pack_open(d, b.n, &p, &terr));
	CHECK_ERR(mlod_pack_decode_mesh(&p, C_MESH0, d, b.n, &sk, &m, &terr), MLOD_ERR_PARSE, "MESH level 1: CRC mismatch");
	mlod_pack_close(&p);
	DECODE_FAILS(wr32(e + 12, coded - 1), "MESH level 0: the zstd frame says");
	/* A prefix too big: MESH level 1's TOC says a container of 96 MiB
	 * (its raw size too, so open takes it): refused before any allocation. */
	DECODE_FAILS((wr32(d + 32 + 48 * C_MESH1 + 12, 96u << 20), wr32(d + 32 + 48 * C_MESH1 + 28, 96u << 20)),
	             "MESH level 0: its prefix (MESH levels 1 to 1's containers) is 100663296 bytes, more than the "
	             "format's 67108864");
	free(d);
	free(b.p);
	/* A frame coded on another chunk's container (MOTION level 1's, not a
	 * dependency): it does not decode to a valid container; the error names
	 * MESH level 0, never a crash. */
	wrong_prefix = C_MOT1;
	buf w = prefix_pack();
	wrong_prefix = -1;
	CHECK_OK(mlod_pack_open(w.p, w.n, &p, &terr));
	memset(&terr, 0, sizeof terr);
	mlod_result r = mlod_pack_decode_mesh(&p, C_MESH0, w.p, w.n, &sk, &m, &terr);
	mlod_pack_close(&p);
	CHECK_MSG(r == MLOD_ERR_PARSE && strncmp(terr.message, "MESH level 0: ", 14) == 0, "returned %d: %s", (int)r,
	          terr.message);
	free(w.p);
	mlod_pack_skeleton_free(&sk);
#undef EDIT
#undef OPEN_FAILS
#undef DECODE_FAILS
}

/* Every prefix of the file again with the prefix stage. */
TEST(every_prefix_zstd_prefix)
{
	zstd_level = 19, zstd_prefix = 1, mesh0_raw = 1;
	every_prefix_of_pack();
	zstd_level = 0, zstd_prefix = 0, mesh0_raw = 0;
}

static void every_prefix_of_pack(void)
{
	buf b = make_pack(0);
	mlod_pack full = {0};
	mlod_pack_skeleton skel = {0};
	CHECK_OK(mlod_pack_open(b.p, b.n, &full, &terr));
	CHECK_OK(mlod_pack_decode_skeleton(&full, b.p, b.n, &skel, &terr));
	size_t toc_end = 32 + 48 * (size_t)full.chunk_count;
	char why[800] = "";
	for (size_t len = 0; len < b.n && !why[0]; len++) {
		/* A copy of exactly len bytes, so that ASan sees any read past it. */
		uint8_t *d = malloc(len ? len : 1);
		memcpy(d, b.p, len);
		mlod_pack p;
		mlod_error e = {0};
		mlod_result r = mlod_pack_open(d, len, &p, &e);
		if ((r == MLOD_OK) != (len >= toc_end) || (r != MLOD_OK && !e.message[0])) {
			snprintf(why, sizeof why, "prefix %zu: open returned %d: %s", len, (int)r, e.message);
		} else if (r == MLOD_OK) {
			int bad = 0;
			int got = decode_all(d, len, &skel, &bad);
			int want = 0;
			for (uint32_t i = 0; i < full.chunk_count; i++)
				if (full.chunks[i].offset + full.chunks[i].stored_size <= len)
					want++;
			if (got != want || bad)
				snprintf(why, sizeof why, "prefix %zu: %d chunks decoded, expected %d (bad %d)", len, got, want,
				         bad);
			mlod_pack_close(&p);
		}
		free(d);
	}
	mlod_pack_skeleton_free(&skel);
	mlod_pack_close(&full);
	free(b.p);
	CHECK_MSG(!why[0], "%s", why);
}

/* Random mutations, plain (the CRCs catch them) and with every CRC
 * re-stamped (the structural checks must). Nothing may crash or read out
 * of bounds (the sanitize build runs this too), and whatever decodes keeps
 * the reader's guarantees. */
static void mutate(uint8_t *d, size_t n)
{
	int kind = (int)(rnd() % 6);
	int times = kind == 0 ? 1 : 1 + (int)(rnd() % 8);
	for (int t = 0; t < times; t++) {
		size_t at = rnd() % n;
		switch (kind) {
		case 0:
		case 1: d[at] ^= (uint8_t)(1u << (rnd() % 8)); break;
		case 2: d[at] = (uint8_t)rnd(); break;
		case 3: d[at] = (rnd() & 1) ? 0xff : 0; break;
		case 4: /* a 32-bit field around here to an edge value */
		{
			static const uint32_t edges[] = {0, 1, 2, 3, 4, 255, 256, 0x7fffffffu, 0x80000000u, 0xffffffffu,
			                                 0xfffffffeu, 65535, 65536};
			at &= ~(size_t)3;
			if (at + 4 <= n)
				wr32(d + at, edges[rnd() % (sizeof edges / sizeof *edges)]);
			break;
		}
		default: /* a small int32 nudge */
			at &= ~(size_t)3;
			if (at + 4 <= n)
				wr32(d + at, get32(d + at) + (uint32_t)((int)(rnd() % 5) - 2));
			break;
		}
	}
}

static void run_mutations(int restamped, int iterations, int *opened, int *decoded, int *bad_out, char *why,
                          size_t whysize)
{
	buf b = make_pack(0);
	uint8_t *d = malloc(b.n);
	for (int it = 0; it < iterations; it++) {
		memcpy(d, b.p, b.n);
		mutate(d, b.n);
		if (restamped)
			restamp(d, b.n);
		int bad = 0;
		int got = decode_all(d, b.n, NULL, &bad);
		if (got >= 0)
			(*opened)++;
		if (got > 0)
			*decoded += got;
		if (bad && !*bad_out) {
			*bad_out = 1;
			snprintf(why, whysize, "iteration %d: a decode broke a guarantee or failed without a message", it);
		}
	}
	free(d);
	free(b.p);
}

TEST(mutations_plain)
{
	rng_state = 12345;
	int opened = 0, decoded = 0, bad = 0;
	char why[200] = "";
	run_mutations(0, 10000, &opened, &decoded, &bad, why, sizeof why);
	CHECK_MSG(!bad, "%s", why);
	/* Mutations in the chunks leave the header and TOC intact. */
	CHECK_MSG(opened > 1000, "only %d of 10000 opened", opened);
}

TEST(mutations_restamped)
{
	rng_state = 67890;
	int opened = 0, decoded = 0, bad = 0;
	char why[200] = "";
	run_mutations(1, 10000, &opened, &decoded, &bad, why, sizeof why);
	CHECK_MSG(!bad, "%s", why);
	CHECK_MSG(opened > 3000 && decoded > 10000, "%d opened, %d chunks decoded", opened, decoded);
}

/* The same with every chunk but INFO behind the zstd entropy stage: a
 * mutated frame fails with a message (zstd's own checks, the frame's
 * content size against the TOC's coded size), never a crash or a read
 * past the data. */
TEST(mutations_zstd)
{
	zstd_level = 19;
	rng_state = 24680;
	int opened = 0, decoded = 0, bad = 0;
	char why[200] = "";
	run_mutations(0, 10000, &opened, &decoded, &bad, why, sizeof why);
	CHECK_MSG(!bad, "%s", why);
	CHECK_MSG(opened > 1000, "only %d of 10000 opened", opened);
	rng_state = 13579;
	opened = decoded = bad = 0;
	run_mutations(1, 10000, &opened, &decoded, &bad, why, sizeof why);
	zstd_level = 0;
	CHECK_MSG(!bad, "%s", why);
	CHECK_MSG(opened > 3000 && decoded > 3000, "%d opened, %d chunks decoded", opened, decoded);
}

/* The same on a pack whose MESH level 0 is prefix-coded (format 6.0):
 * mutated frames, prefixes and TOC entries fail with a message. */
TEST(mutations_zstd_prefix)
{
	zstd_level = 19, zstd_prefix = 1, mesh0_raw = 1;
	rng_state = 97531;
	int opened = 0, decoded = 0, bad = 0;
	char why[200] = "";
	run_mutations(0, 10000, &opened, &decoded, &bad, why, sizeof why);
	CHECK_MSG(!bad, "%s", why);
	CHECK_MSG(opened > 1000, "only %d of 10000 opened", opened);
	rng_state = 86420;
	opened = decoded = bad = 0;
	run_mutations(1, 10000, &opened, &decoded, &bad, why, sizeof why);
	zstd_level = 0, zstd_prefix = 0, mesh0_raw = 0;
	CHECK_MSG(!bad, "%s", why);
	CHECK_MSG(opened > 3000 && decoded > 3000, "%d opened, %d chunks decoded", opened, decoded);
}

/* A pack with one change to the character, for the targeted checks. */
typedef void (*edit_fn)(wchunk *c);
static buf edited_pack(edit_fn edit)
{
	static wchunk c[C_COUNT + 1];
	int n = make_chunks(c, 0);
	edit(c);
	buf b = build_pack(c, n, MLOD_PACK_MAJOR, 0);
	free_chunks(c, n);
	return b;
}

static uint8_t *stream_data(wchunk *c, int chunk, uint32_t tag, int nth)
{
	for (int i = 0; i < c[chunk].ns; i++)
		if (c[chunk].s[i].tag == tag && nth-- == 0)
			return c[chunk].s[i].data.p;
	return NULL;
}

static void e_index(wchunk *c) { wr32(stream_data(c, C_MESH0, MLOD_STREAM_IDX, 0) + 4 * 7, NV0 + 3); }
/* Level 1's part 1 (u16 indices, a prefix of 10 vertices): index 10. */
static void e_index_coarse(wchunk *c)
{
	uint8_t *d = stream_data(c, C_MESH1, MLOD_STREAM_IDX, 1);
	d[8] = 10, d[9] = 0;
}
static void e_part_count(wchunk *c) { c[C_MESH0].s[0].count = 1, c[C_MESH0].s[0].data.n = sizeof(mlod_pack_part_rec); }
/* Level 0's part 1 on another grid than level 1's: pos_min[0]. */
static void e_part_grid(wchunk *c)
{
	uint8_t *d = stream_data(c, C_MESH0, MLOD_STREAM_PART, 0) + sizeof(mlod_pack_part_rec) + 112;
	wr32(d, 0x3f000000u);
}
static void e_parent(wchunk *c) { wr32(stream_data(c, C_SKEL, MLOD_STREAM_JNTS, 0) + 116 * 2, 3); }
static void e_palr(wchunk *c) { wr32(stream_data(c, C_SKEL1, MLOD_STREAM_PALR, 0) + 4 * 3, NJ + 2); }
static void e_palx_count(wchunk *c)
{
	wstream *x = &c[C_SKEL1].s[2];
	x->count = NJ + 1;
	for (int k = 0; k < 16 * NJ; k++)
		putf(&x->data, 1.0f);
}
static void e_palx_nan(wchunk *c) { wr32(stream_data(c, C_SKEL1, MLOD_STREAM_PALX, 0) + 4 * 5, 0x7fc00000u); }
static void e_weights(wchunk *c) { stream_data(c, C_MESH1, MLOD_STREAM_WGT8, 0)[4 * 5] ^= 1; }
static void e_skin_joint(wchunk *c) { stream_data(c, C_MESH1, MLOD_STREAM_JNT8, 0)[4 * 2 + 1] = NJ; }
static void e_uv_sets(wchunk *c) { wr32(stream_data(c, C_MESH1, MLOD_STREAM_PART, 0) + 40, 5); }
static void e_stream_order(wchunk *c)
{
	wstream t = c[C_MESH1].s[2];
	c[C_MESH1].s[2] = c[C_MESH1].s[3];
	c[C_MESH1].s[3] = t;
}
static void e_vertex_count(wchunk *c) { c[C_MESH1].s[2].count--, c[C_MESH1].s[2].data.n -= 4; }
static void e_nan(wchunk *c) { wr32(stream_data(c, C_MOT1, MLOD_STREAM_VEC3, 0) + 8, 0x7fc00000u); }
static void e_time(wchunk *c) { wr32(stream_data(c, C_MOT1, MLOD_STREAM_TIME, 0) + 4, 0); }
static void e_chan_joint(wchunk *c) { wr32(stream_data(c, C_MOT1, MLOD_STREAM_CHAN, 0), NJ); }
static void e_kept_root(wchunk *c)
{
	wr32(stream_data(c, C_SKEL1, MLOD_STREAM_KEPT, 0), 1);
	wr32(stream_data(c, C_SKEL1, MLOD_STREAM_KEPT, 0) + 4, 2);
}
static void e_skjt(wchunk *c) { wr32(stream_data(c, C_SKEL, MLOD_STREAM_SKJT, 0) + 4, 99); }
static void e_vertex_elsize(wchunk *c)
{
	/* A meshopt vertex stream of 6-byte elements. */
	wstream *s = &c[C_MESH0].s[1];
	s->codec = MLOD_SCODEC_RAW;
	s->elsize = 6;
	s->count = (uint32_t)(s->data.n / 6);
	s->data.n = (size_t)s->count * 6;
	c[C_MESH0].codec = MLOD_CODEC_MESHOPT;
}
static void e_info_levels(wchunk *c) { wr32(stream_data(c, C_INFO, MLOD_STREAM_INFO, 0) + 8, 1); }
static void e_clip_names(wchunk *c) { c[C_INFO].s[1].count = 5, c[C_INFO].s[1].data.n = 5; }
static void e_extra_stream(wchunk *c)
{
	wstream *s = add_stream(&c[C_MOT1], MLOD_STREAM_VEC3, 12, MLOD_SCODEC_RAW);
	s->count = 1;
	for (int a = 0; a < 3; a++)
		putf(&s->data, 2.0f);
}
static void e_dup_channel(wchunk *c) { wr32(stream_data(c, C_MOT0, MLOD_STREAM_CHAN, 0) + 20 * 2, 1); }
static void e_no_vec3(wchunk *c)
{
	wchunk_free_stream(&c[C_MOT1], 7); /* VECD */
	wchunk_free_stream(&c[C_MOT1], 6);
}
static void e_missing_rotation(wchunk *c) { wr32(stream_data(c, C_MOT1, MLOD_STREAM_CHAN, 0) + 4, 1); }
static void e_time_order(wchunk *c) { wr32(stream_data(c, C_MOT0, MLOD_STREAM_CHAN, 0) + 20 * 3 + 16, 2); }
static void e_time_keys(wchunk *c) { wr32(stream_data(c, C_MOT1, MLOD_STREAM_CHAN, 0) + 12, 3); }
static void e_time_shared_keys(wchunk *c) { wr32(stream_data(c, C_MOT0, MLOD_STREAM_CHAN, 0) + 20 + 12, NK + 1); }
static void e_step_zero(wchunk *c) { memset(stream_data(c, C_MOT0, MLOD_STREAM_STEP, 0), 0, 8); }
static void e_step_nan(wchunk *c)
{
	double nan = NAN;
	memcpy(stream_data(c, C_MOT1, MLOD_STREAM_STEP, 0), &nan, 8);
}
static void e_tick_elsize(wchunk *c)
{
	/* a TICK stream of 1-byte elements */
	wstream *s = &c[C_MOT0].s[2];
	s->codec = MLOD_SCODEC_RAW;
	s->elsize = 1;
	s->data.n = s->count;
}
static void e_tick_overflow(wchunk *c)
{
	/* ticks 0, 2^32 - 1, then one more: past u32 */
	uint8_t *d = stream_data(c, C_MOT0, MLOD_STREAM_TICK, 0);
	wr32(d + 4, 0xffffffffu);
	wr32(d + 8, 1);
}
static void e_tick_repeat(wchunk *c)
{
	/* a difference of 0: a key at the time before's */
	wr32(stream_data(c, C_MOT0, MLOD_STREAM_TICK, 0) + 8, 0);
}
static void e_morph_scale(wchunk *c) { wr32(stream_data(c, C_MESH0, MLOD_STREAM_MTSC, 0), 0xbf800000u); }
static void e_no_skin(wchunk *c) { wr32(stream_data(c, C_MESH1, MLOD_STREAM_PART, 0) + 16, 0xffffffffu); }
static void e_rotq_cubic(wchunk *c) { wr32(stream_data(c, C_MOT0, MLOD_STREAM_CHAN, 0) + 20 + 8, 2); }
static void e_rotq_index(wchunk *c)
{
	wr16(stream_data(c, C_MOT0, MLOD_STREAM_ROTQ, 0) + 8 * 2 + 6, 4 * MLOD_PACK_ROTQ_SHIFT_MAX + 4);
}
/* Format 4.0: key 0 (stored as it is in 9.0 too) at shift 8 (index 0),
 * its first component 200 past 32767 >> 8. */
static void e_rotq_past(wchunk *c)
{
	uint8_t *d = stream_data(c, C_MOT0, MLOD_STREAM_ROTQ, 0);
	wr16(d, 200);
	wr16(d + 6, 4 * 8);
}
static void e_part_flags(wchunk *c) { wr32(stream_data(c, C_MESH1, MLOD_STREAM_PART, 0) + 28, 0x108); }
static void e_newbits_alone(wchunk *c) { wr32(stream_data(c, C_MESH1, MLOD_STREAM_PART, 0) + 28, 0x88); }
/* Level 0's part 1 in its own numbering (u16): its map's first vertex
 * past the prefix. Level 1's part 0 (16 vertices, every one marked new):
 * an index past its vertices; vertex 0 not marked new, with no 'IMAP'
 * entry for it. */
static void e_imap_past(wchunk *c)
{
	uint8_t *d = stream_data(c, C_MESH0, MLOD_STREAM_IMAP, 0);
	d[0] = NV1, d[1] = 0;
}
static void e_inew_imap(wchunk *c) { stream_data(c, C_MESH1, MLOD_STREAM_INEW, 0)[0] = 0xfe; }
static void e_local_index(wchunk *c)
{
	uint8_t *d = stream_data(c, C_MESH1, MLOD_STREAM_IDX, 0);
	d[8] = 16, d[9] = 0;
}

TEST(structural_checks_name_the_chunk)
{
	struct {
		edit_fn edit;
		int chunk;
		mlod_result code;
		const char *text;
	} cases[] = {
		{e_index, C_MESH0, MLOD_ERR_PARSE, "MESH level 0: part 0: index 43 refers past its prefix of 40 vertices (MESH levels 1 to 0; at position 7)"},
		{e_index_coarse, C_MESH1, MLOD_ERR_PARSE, "MESH level 1: part 1: index 10 refers past its prefix of 10 vertices (MESH levels 1 to 1; at position 4)"},
		{e_part_count, C_MESH0, MLOD_ERR_PARSE, "MESH level 0: stream 0 'PART' has 1 elements, expected 2 (the parts of the coarsest level)"},
		{e_part_grid, C_MESH0, MLOD_ERR_PARSE, "MESH level 0: part 1: its record differs from MESH level 1's"},
		{e_parent, C_SKEL, MLOD_ERR_PARSE, "SKELETON: joint 2: parent 3 is not -1 or an earlier joint"},
		{e_palr, C_SKEL1, MLOD_ERR_PARSE, "SKELETON level 1: palette entry 3 refers to bind matrix 6, beyond the 4 skin joints and 1 in 'PALX'"},
		{e_palx_count, C_SKEL1, MLOD_ERR_PARSE, "SKELETON level 1: 5 bind matrices in 'PALX', more than the 4 skin joints"},
		{e_palx_nan, C_SKEL1, MLOD_ERR_PARSE, "SKELETON level 1: a palette bind matrix is not finite"},
		{e_weights, C_MESH1, MLOD_ERR_PARSE, "MESH level 1: part 0: vertex 5: weights sum to"},
		{e_skin_joint, C_MESH1, MLOD_ERR_PARSE, "MESH level 1: part 0: vertex 2: joint 4 is not below skin 0's 4 joints"},
		{e_uv_sets, C_MESH1, MLOD_ERR_PARSE, "MESH level 1: part 0: 5 UV sets, more than 4"},
		{e_stream_order, C_MESH1, MLOD_ERR_PARSE, "MESH level 1: part 0: stream 2 is 'TANQ', expected 'NRMQ'"},
		{e_vertex_count, C_MESH1, MLOD_ERR_PARSE, "MESH level 1: part 0: stream 2 'NRMQ' has 15 elements, expected 16 (the block's vertex count)"},
		{e_nan, C_MOT1, MLOD_ERR_PARSE, "MOTION level 1 of clip 0: channel 0: a translation value is not finite"},
		{e_time, C_MOT1, MLOD_ERR_PARSE, "MOTION level 1 of clip 0: time array 0: key 1: time 0 is not after 0"},
		{e_chan_joint, C_MOT1, MLOD_ERR_PARSE, "MOTION level 1 of clip 0: channel 0: joint 4 is not below the skeleton's 4 joints"},
		{e_kept_root, C_SKEL1, MLOD_ERR_PARSE, "SKELETON level 1: root joint 0 is not kept"},
		{e_skjt, C_SKEL, MLOD_ERR_PARSE, "SKELETON: skin 0: joint 1 is 99, not below the joint count 4"},
		{e_vertex_elsize, C_MESH0, MLOD_ERR_PARSE, "MESH level 0: part 0: stream 1 'POSQ' has elements of 6 bytes, expected 8"},
		{e_info_levels, C_INFO, MLOD_ERR_PARSE, "INFO: the TOC has SKELETON level 1, but INFO counts"},
		{e_clip_names, C_INFO, MLOD_ERR_PARSE, "INFO: the string table 'NAME' ends before clip 0's name"},
		{e_extra_stream, C_MOT1, MLOD_ERR_PARSE, "MOTION level 1 of clip 0: 1 unexpected streams after the last one it needs (stream 8 'VEC3')"},
		{e_time_order, C_MOT0, MLOD_ERR_PARSE, "MOTION level 0 of clip 0: channel 3: time array 2 is not below 2 (the arrays go in first-use order)"},
		{e_time_keys, C_MOT1, MLOD_ERR_PARSE, "MOTION level 1 of clip 0: stream 2 'TIME' has 2 elements, expected 3 (the time arrays' keys)"},
		{e_time_shared_keys, C_MOT0, MLOD_ERR_PARSE, "MOTION level 0 of clip 0: channel 1: 6 keys, but time array 0 has 5"},
		{e_step_zero, C_MOT0, MLOD_ERR_PARSE, "MOTION level 0 of clip 0: stream 2 is 'TICK', expected 'TIME' (step 0)"},
		{e_step_nan, C_MOT1, MLOD_ERR_PARSE, "MOTION level 1 of clip 0: step nan is not finite and >= 0"},
		{e_tick_elsize, C_MOT0, MLOD_ERR_PARSE, "MOTION level 0 of clip 0: stream 2 'TICK' has elements of 1 bytes, expected 2 or 4"},
		{e_tick_overflow, C_MOT0, MLOD_ERR_PARSE, "MOTION level 0 of clip 0: stream 2 'TICK': time array 0: key 2: tick 4294967296 is above 2^32 - 1"},
		{e_tick_repeat, C_MOT0, MLOD_ERR_PARSE, "MOTION level 0 of clip 0: time array 0: key 2: time 0.25 is not after 0.25"},
		{e_dup_channel, C_MOT0, MLOD_ERR_PARSE, "MOTION level 0 of clip 0: channel 2: a second rotation channel of joint 1"},
		{e_missing_rotation, C_MOT1, MLOD_ERR_PARSE, "MOTION level 1 of clip 0: stream 3 'ROTQ' has 0 elements, expected 2 (rotation keys without a base key)"},
		{e_no_vec3, C_MOT1, MLOD_ERR_PARSE, "MOTION level 1 of clip 0: missing stream 'VEC3' (the chunk has 6 streams)"},
		{e_morph_scale, C_MESH0, MLOD_ERR_PARSE, "MESH level 0: part 0: morph target 0: scale -1 is not finite and >= 0"},
		{e_no_skin, C_MESH1, MLOD_ERR_PARSE, "MESH level 1: part 0: skinned, but without a skin"},
		{e_rotq_cubic, C_MOT0, MLOD_ERR_PARSE, "MOTION level 0 of clip 0: stream 3 'ROTQ' has 5 elements, expected 0 (rotation keys without a base key)"},
		{e_rotq_index, C_MOT0, MLOD_ERR_PARSE, "MOTION level 0 of clip 0: channel 1: rotation key 2: component index and shift 36 out of range"},
		{e_rotq_past, C_MOT0, MLOD_ERR_PARSE, "MOTION level 0 of clip 0: channel 1: rotation key 0: component 200 past the lattice"},
		{e_part_flags, C_MESH1, MLOD_ERR_PARSE, "MESH level 1: part 0: unknown flags 0x100"},
		{e_newbits_alone, C_MESH1, MLOD_ERR_PARSE, "MESH level 1: part 0: NEWBITS without LOCAL"},
		{e_imap_past, C_MESH0, MLOD_ERR_PARSE, "MESH level 0: part 1: vertex 0 maps to 24, past its prefix of 24 vertices (MESH levels 1 to 0)"},
		{e_inew_imap, C_MESH1, MLOD_ERR_PARSE, "MESH level 1: part 0: stream 10 'IMAP' has 0 elements, expected 1 (the vertices 'INEW' leaves)"},
		{e_local_index, C_MESH1, MLOD_ERR_PARSE, "MESH level 1: part 0: index 16 refers past its 16 vertices (at position 4)"},
	};
	for (size_t k = 0; k < sizeof cases / sizeof *cases; k++) {
		buf b = edited_pack(cases[k].edit);
		/* The edited chunk may be shorter now: rebuilt, the TOC fits. */
		mlod_pack p = {0};
		mlod_pack_skeleton s = {0};
		/* The unedited skeleton, from a clean pack. */
		buf clean = make_pack(0);
		mlod_pack cp = {0};
		mlod_error e = {0};
		mlod_result r = mlod_pack_open(clean.p, clean.n, &cp, &e);
		if (r == MLOD_OK)
			r = mlod_pack_decode_skeleton(&cp, clean.p, clean.n, &s, &e);
		mlod_pack_close(&cp);
		free(clean.p);
		if (r == MLOD_OK)
			r = mlod_pack_open(b.p, b.n, &p, &e);
		if (r == MLOD_OK) {
			memset(&e, 0, sizeof e);
			uint32_t i = (uint32_t)cases[k].chunk;
			if (i == C_INFO) {
				mlod_pack_info x;
				r = mlod_pack_decode_info(&p, b.p, b.n, &x, &e);
				mlod_pack_info_free(&x);
			} else if (i == C_SKEL) {
				mlod_pack_skeleton x;
				r = mlod_pack_decode_skeleton(&p, b.p, b.n, &x, &e);
				mlod_pack_skeleton_free(&x);
			} else if (i == C_SKEL1) {
				mlod_pack_skel_level x;
				r = mlod_pack_decode_skel_level(&p, i, b.p, b.n, &s, &x, &e);
				mlod_pack_skel_level_free(&x);
			} else if (i == C_MESH0 || i == C_MESH1) {
				mlod_pack_mesh x;
				r = mlod_pack_decode_mesh(&p, i, b.p, b.n, &s, &x, &e);
				mlod_pack_mesh_free(&x);
			} else {
				mlod_pack_motion x;
				r = mlod_pack_decode_motion(&p, i, b.p, b.n, &s, &x, &e);
				mlod_pack_motion_free(&x);
			}
		}
		mlod_pack_close(&p);
		mlod_pack_skeleton_free(&s);
		free(b.p);
		CHECK_MSG(r == cases[k].code, "case %zu: returned %d: %s", k, (int)r, e.message);
		CHECK_MSG(strstr(e.message, cases[k].text) != NULL, "case %zu: \"%s\" lacks \"%s\"", k, e.message,
		          cases[k].text);
	}
}

/* The order of the levels with fewer motion levels than mesh levels (the
 * test pack without MOTION level 1): the coarsest of both layers first
 * (MESH 1, MOTION 0, MESH 0), or level with level as the writers before
 * wrote it (MESH 1, MESH 0, MOTION 0); MOTION 0 before MESH 1 is in
 * neither. */
TEST(toc_order_ranks)
{
	static wchunk c[C_COUNT + 1];
	int n = make_chunks(c, 0);
	wchunk w[C_COUNT];
	const int orders[3][C_COUNT - 1] = {
		{C_INFO, C_SKEL, C_SKEL1, C_MESH1, C_MOT0, C_MESH0, C_DOC},
		{C_INFO, C_SKEL, C_SKEL1, C_MESH1, C_MESH0, C_MOT0, C_DOC},
		{C_INFO, C_SKEL, C_SKEL1, C_MOT0, C_MESH1, C_MESH0, C_DOC},
	};
	for (int o = 0; o < 3; o++) {
		for (int i = 0; i < C_COUNT - 1; i++)
			w[i] = c[orders[o][i]];
		buf b = build_pack(w, C_COUNT - 1, MLOD_PACK_MAJOR, MLOD_PACK_MINOR);
		mlod_pack p;
		if (o < 2) {
			memset(&terr, 0, sizeof terr);
			mlod_result r = mlod_pack_open(b.p, b.n, &p, &terr);
			CHECK_MSG(r == MLOD_OK, "order %d: %s", o, terr.message);
			if (r == MLOD_OK)
				mlod_pack_close(&p);
		} else {
			CHECK_ERR(mlod_pack_open(b.p, b.n, &p, &terr), MLOD_ERR_PARSE, "TOC entry 4 (MESH level 1) is out of order");
		}
		free(b.p);
	}
	free_chunks(c, n);
}

/* TOC and header damage, each with the CRCs re-stamped. */
TEST(toc_checks)
{
	buf b = make_pack(0);
	uint8_t *d = malloc(b.n);
	mlod_pack p;
	uint8_t *mesh1 = d + 32 + 48 * C_MESH1;
#define DAMAGE(stmt, code, text)                                                                                \
	do {                                                                                                    \
		memcpy(d, b.p, b.n);                                                                            \
		stmt;                                                                                           \
		restamp(d, b.n);                                                                                \
		CHECK_ERR(mlod_pack_open(d, b.n, &p, &terr), code, text);                                       \
	} while (0)
	DAMAGE(d[0] = 'X', MLOD_ERR_PARSE, "not an mlod pack");
	DAMAGE(wr32(mesh1 + 16, get32(mesh1 + 16) + 4), MLOD_ERR_PARSE, "TOC entry 3 (MESH level 1): offset");
	DAMAGE(wr32(mesh1 + 16, get32(mesh1 + 16) - 16), MLOD_ERR_PARSE, "overlaps the previous chunk");
	DAMAGE(wr32(d + 16, get32(d + 16) + 16), MLOD_ERR_PARSE, "pack header: file size");
	DAMAGE(wr32(d + 16, 40), MLOD_ERR_PARSE, "is less than the header and TOC");
	DAMAGE(wr32(d + 12, 70000), MLOD_ERR_PARSE, "70000 chunks, more than the format's 65536");
	DAMAGE(wr32(d + 12, 60000), MLOD_ERR_PARSE, "truncated pack: the TOC of 60000 chunks");
	DAMAGE(wr32(mesh1 + 24, 0x7fffffff), MLOD_ERR_PARSE, "lie outside the file");
	DAMAGE(mesh1[4] = MLOD_LAYER_MOTION, MLOD_ERR_PARSE, "TOC entry 3 (MESH level 1): layer 3, expected 2 (mesh)");
	/* MESH levels 0, 0: in neither order from entry 5 (the second) on */
	DAMAGE(mesh1[6] = 0, MLOD_ERR_PARSE, "TOC entry 5 (MESH level 0) is out of order");
	DAMAGE((wr32(d + 32 + 48 * C_MOT0, MLOD_CHUNK_MESH), d[32 + 48 * C_MOT0 + 4] = MLOD_LAYER_MESH), MLOD_ERR_PARSE,
	       "TOC entry 6 (MESH level 0): a second chunk of that type, level and item");
	DAMAGE(wr32(d + 32 + 48 * C_MOT1 + 36, 0xff800000u), MLOD_ERR_PARSE, "must be finite");
	DAMAGE(d[32 + 48 * C_SKEL1 + 8] = 1, MLOD_ERR_PARSE, "TOC entry 2 (SKELETON level 1): item 1, expected 0");
	DAMAGE(d[32 + 48 * C_DOC + 6] = 1, MLOD_ERR_PARSE, "TOC entry 7 (DOC): level 1, expected 0");
	/* DOC before the levels. */
	DAMAGE(wr32(d + 32 + 48 * C_MOT0, MLOD_CHUNK_DOC), MLOD_ERR_PARSE, "layer 3, expected 0");
	/* Unstamped damage: the CRCs. */
	memcpy(d, b.p, b.n);
	d[33] ^= 1;
	CHECK_ERR(mlod_pack_open(d, b.n, &p, &terr), MLOD_ERR_PARSE, "pack TOC: CRC mismatch");
	memcpy(d, b.p, b.n);
	d[9] ^= 1;
	CHECK_ERR(mlod_pack_open(d, b.n, &p, &terr), MLOD_ERR_PARSE, "pack header: CRC mismatch");
	memcpy(d, b.p, b.n);
	d[b.n - 1] ^= 1;
	CHECK_OK(mlod_pack_open(d, b.n, &p, &terr));
	const void *g;
	size_t gs;
	memset(&terr, 0, sizeof terr);
	mlod_result r = mlod_pack_doc(&p, d, b.n, &g, &gs, &terr);
	mlod_pack_close(&p);
	free(d);
	free(b.p);
	CHECK(r == MLOD_ERR_PARSE && strstr(terr.message, "DOC: CRC mismatch") != NULL);
#undef DAMAGE
}

/* A chunk whose headers claim huge streams fails before allocating them. */
TEST(absurd_sizes)
{
	static wchunk c[C_COUNT + 1];
	int n = make_chunks(c, 0);
	/* A meshopt stream of 16 M part records (3.4 GB decoded, raw size
	 * consistent): refused at open (the raw size is more than meshopt
	 * can expand the container to), before any allocation. */
	wchunk *m = &c[C_MESH1]; /* the coarsest: it sets the part count */
	m->codec = MLOD_CODEC_MESHOPT;
	for (int i = 0; i < m->ns; i++)
		free(m->s[i].data.p);
	m->ns = 0;
	wstream *s = add_stream(m, MLOD_STREAM_PART, 200, MLOD_SCODEC_MESHOPT_VERTEX);
	s->count = 0;
	buf b = build_pack(c, n, MLOD_PACK_MAJOR, 0);
	/* Patch the stream header and the raw size in place. */
	mlod_pack p;
	CHECK_OK(mlod_pack_open(b.p, b.n, &p, &terr));
	uint8_t *ch = b.p + p.chunks[C_MESH1].offset;
	mlod_pack_close(&p);
	wr32(ch + 4 + 4, 0x01000000u);
	uint64_t raw = 4 + 16 + (uint64_t)0x01000000 * 200;
	wr32(b.p + 32 + 48 * C_MESH1 + 28, (uint32_t)raw);
	restamp(b.p, b.n);
	mlod_pack_mesh mesh;
	memset(&terr, 0, sizeof terr);
	mlod_result r1 = mlod_pack_open(b.p, b.n, &p, &terr);
	char m1[sizeof terr.message];
	memcpy(m1, terr.message, sizeof m1);
	/* The same with a raw size within the limit: PARSE, from the stream
	 * (its 201 bytes cannot hold 16 M records). */
	wr32(b.p + 32 + 48 * C_MESH1 + 28, 1000);
	restamp(b.p, b.n);
	mlod_pack_close(&p);
	CHECK_OK(mlod_pack_open(b.p, b.n, &p, &terr));
	memset(&terr, 0, sizeof terr);
	mlod_result r2 = mlod_pack_decode_mesh(&p, C_MESH1, b.p, b.n, NULL, &mesh, &terr);
	mlod_pack_close(&p);
	free(b.p);
	free_chunks(c, n);
	CHECK_MSG(r1 == MLOD_ERR_PARSE && strstr(m1, "(MESH level 1): raw size 3355443220 is more than 64 times"),
	          "returned %d: %s", (int)r1, m1);
	CHECK_MSG(r2 == MLOD_ERR_PARSE && strstr(terr.message, "MESH level 1: stream 0 'PART'") &&
	              strstr(terr.message, "cannot hold 16777216 elements"),
	          "returned %d: %s", (int)r2, terr.message);
}

/* Found by make fuzz: a CRC-valid pack whose TOC raw size of a meshopt
 * MESH chunk (no entropy stage) was 721 MB for 2724 stored bytes made the
 * reader allocate that much before reading the chunk. Now open refuses a
 * raw size past 64 times the container (meshopt's most), and a container
 * refuses a meshopt stream whose elements its bytes cannot hold, even when
 * the raw size agrees. */
TEST(expansion_limits)
{
	static wchunk c[C_COUNT + 1];
	int n = make_chunks(c, 0);
	wchunk *m = &c[C_MESH1];
	m->codec = MLOD_CODEC_MESHOPT;
	for (int i = 0; i < m->ns; i++)
		free(m->s[i].data.p);
	m->ns = 0;
	wstream *s = add_stream(m, MLOD_STREAM_PART, 200, MLOD_SCODEC_MESHOPT_VERTEX);
	s->count = 0;
	buf b = build_pack(c, n, MLOD_PACK_MAJOR, 0);
	mlod_pack p;
	CHECK_OK(mlod_pack_open(b.p, b.n, &p, &terr));
	uint8_t *ch = b.p + p.chunks[C_MESH1].offset;
	uint32_t stored_size = p.chunks[C_MESH1].stored_size, raw0 = p.chunks[C_MESH1].raw_size;
	mlod_pack_close(&p);
	uint8_t *toc_raw = b.p + 32 + 48 * C_MESH1 + 28;
	/* 1: the TOC's raw size alone, one byte past the limit. */
	wr32(toc_raw, 64 * stored_size + 1);
	restamp(b.p, b.n);
	memset(&terr, 0, sizeof terr);
	mlod_result r1 = mlod_pack_open(b.p, b.n, &p, &terr);
	if (r1 == MLOD_OK)
		mlod_pack_close(&p);
	char m1[sizeof terr.message];
	memcpy(m1, terr.message, sizeof m1);
	/* 2: a stream of more elements than its bytes can hold, with the raw
	 * size agreeing and within the limit. */
	uint32_t stored = (uint32_t)ch[16] | (uint32_t)ch[17] << 8 | (uint32_t)ch[18] << 16 | (uint32_t)ch[19] << 24;
	uint32_t count = (64 * stored + 64) / 200 + 1;
	wr32(ch + 4 + 4, count);
	uint32_t raw = 4 + 16 + (count * 200 + 3) / 4 * 4;
	wr32(toc_raw, raw);
	restamp(b.p, b.n);
	CHECK_OK(mlod_pack_open(b.p, b.n, &p, &terr));
	memset(&terr, 0, sizeof terr);
	mlod_pack_mesh mesh;
	mlod_result r2 = mlod_pack_decode_mesh(&p, C_MESH1, b.p, b.n, NULL, &mesh, &terr);
	if (r2 == MLOD_OK)
		mlod_pack_mesh_free(&mesh);
	mlod_pack_close(&p);
	free(b.p);
	free_chunks(c, n);
	CHECK(raw0 <= 64 * stored_size && raw <= 64 * stored_size);
	CHECK_MSG(r1 == MLOD_ERR_PARSE && strstr(m1, "(MESH level 1): raw size") && strstr(m1, "more than 64 times"),
	          "returned %d: %s", (int)r1, m1);
	CHECK_MSG(r2 == MLOD_ERR_PARSE && strstr(terr.message, "MESH level 1: stream 0 'PART'") &&
	              strstr(terr.message, "cannot hold"),
	          "returned %d: %s", (int)r2, terr.message);
}

/* A zstd frame whose header states 64 MB but whose one block is a
 * 100-byte RLE run: refused from its blocks before the container is
 * allocated (before, the reader allocated the stated 64 MB first). */
TEST(zstd_forged_size)
{
	static wchunk c[C_COUNT + 1];
	int n = make_chunks(c, 0);
	buf b = build_pack(c, n, MLOD_PACK_MAJOR, 0);
	free_chunks(c, n);
	mlod_pack p;
	CHECK_OK(mlod_pack_open(b.p, b.n, &p, &terr));
	uint64_t off = p.chunks[C_MOT1].offset;
	uint32_t stored = p.chunks[C_MOT1].stored_size;
	mlod_pack_close(&p);
	CHECK(stored >= 13);
	const uint32_t said = 64u << 20;
	uint8_t *f = b.p + off;
	wr32(f, 0xFD2FB528u);  /* zstd magic */
	f[4] = 0xA0;           /* single segment, 4-byte content size */
	wr32(f + 5, said);
	uint32_t h = 1u | 1u << 1 | 100u << 3; /* last block, RLE, 100 bytes */
	f[9] = (uint8_t)h, f[10] = (uint8_t)(h >> 8), f[11] = (uint8_t)(h >> 16);
	f[12] = 0;
	uint8_t *e = b.p + 32 + 48 * C_MOT1;
	e[5] = (uint8_t)(e[5] | MLOD_ENTROPY_ZSTD << 4);
	wr32(e + 12, said); /* coded size */
	wr32(e + 24, 13);   /* stored size */
	wr32(e + 28, said); /* raw size */
	restamp(b.p, b.n);
	CHECK_OK(mlod_pack_open(b.p, b.n, &p, &terr));
	mlod_pack_motion m;
	memset(&terr, 0, sizeof terr);
	mlod_result r = mlod_pack_decode_motion(&p, C_MOT1, b.p, b.n, NULL, &m, &terr);
	if (r == MLOD_OK)
		mlod_pack_motion_free(&m);
	mlod_pack_close(&p);
	free(b.p);
	CHECK_MSG(r == MLOD_ERR_PARSE && strstr(terr.message, "MOTION level ") &&
	              strstr(terr.message, "the zstd frame's 13 bytes cannot decode to its stated 67108864"),
	          "returned %d: %s", (int)r, terr.message);
}

/* Found by make fuzz: a MESH level of an unknown codec and entropy stage
 * (0xf5) saying 654 MB raw, above the level decoded. The raw sizes of
 * every level read were summed and allocated before any chunk's codec was
 * checked; now the unknown codec is refused first (UNSUPPORTED, naming
 * the chunk), and nothing large is allocated. */
static size_t big_alloc;
static void *count_malloc(void *user, size_t n)
{
	(void)user;
	if (n > big_alloc)
		big_alloc = n;
	return malloc(n);
}
static void count_free(void *user, void *q)
{
	(void)user;
	free(q);
}

TEST(unknown_codec_raw_size)
{
	static wchunk c[C_COUNT + 1];
	int n = make_chunks(c, 0);
	buf b = build_pack(c, n, MLOD_PACK_MAJOR, 0);
	free_chunks(c, n);
	uint8_t *e = b.p + 32 + 48 * C_MESH1;
	e[5] = 0x05;                  /* codec 5, unknown */
	wr32(e + 28, 600u << 20);     /* raw size 600 MB */
	restamp(b.p, b.n);
	mlod_pack_alloc al = {count_malloc, count_free, NULL};
	mlod_pack p;
	CHECK_OK(mlod_pack_open_alloc(b.p, b.n, &al, &p, &terr));
	big_alloc = 0;
	mlod_pack_mesh m;
	memset(&terr, 0, sizeof terr);
	mlod_result r = mlod_pack_decode_mesh(&p, C_MESH0, b.p, b.n, NULL, &m, &terr);
	if (r == MLOD_OK)
		mlod_pack_mesh_free(&m);
	mlod_pack_close(&p);
	free(b.p);
	CHECK_MSG(r == MLOD_ERR_UNSUPPORTED && strstr(terr.message, "MESH level 1: unknown chunk codec 5"),
	          "returned %d: %s", (int)r, terr.message);
	CHECK_MSG(big_alloc < (1u << 20), "largest allocation %zu bytes", big_alloc);
}

/* The meshopt codecs' constraints, and a damaged meshopt stream. */
/* Format 7.0's byte-plane stream codecs: every stream of MESH level 0,
 * the skeleton level and a MOTION level in planes (alternately with and
 * without deltas; the weights without their sums, codec 6) decodes to
 * what the raw streams do; a plane stream whose stored size is not its
 * decoded size, a plane stream in a 6.0 pack and one in a chunk of codec
 * none are refused, and so are weights whose three bytes pass 255 and
 * the sum codec on elements of another size. */
TEST(plane_streams)
{
	static wchunk c[C_COUNT + 1];
	int n = make_chunks(c, 0);
	int chunks[] = {C_SKEL, C_SKEL1, C_MESH1, C_MESH0, C_MOT1, C_MOT0}, planes = 0, sums = 0;
	for (int q = 0; q < 6; q++) {
		c[chunks[q]].codec = MLOD_CODEC_MESHOPT;
		for (int i = 0; i < c[chunks[q]].ns; i++)
			if (c[chunks[q]].s[i].tag == MLOD_STREAM_WGT8)
				c[chunks[q]].s[i].codec = MLOD_SCODEC_SUM255, sums++;
			else if (c[chunks[q]].s[i].codec == MLOD_SCODEC_RAW && c[chunks[q]].s[i].count)
				c[chunks[q]].s[i].codec = planes++ % 2 ? MLOD_SCODEC_PLANES_DELTA : MLOD_SCODEC_PLANES;
	}
	buf b = build_pack(c, n, MLOD_PACK_MAJOR, 0), b6 = build_pack(c, n, 6, 0);
	free_chunks(c, n);
	buf a = make_pack(0);
	mlod_pack p, pa;
	CHECK_OK(mlod_pack_open(b.p, b.n, &p, &terr));
	CHECK_OK(mlod_pack_open(a.p, a.n, &pa, &terr));
	CHECK_OK(mlod_pack_check(&p, b.p, b.n, &terr));
	mlod_pack_skeleton sk, ska;
	mlod_pack_skel_level l, la;
	mlod_pack_mesh m, ma;
	mlod_pack_motion mo, moa;
	CHECK_OK(mlod_pack_decode_skeleton(&p, b.p, b.n, &sk, &terr));
	CHECK_OK(mlod_pack_decode_skeleton(&pa, a.p, a.n, &ska, &terr));
	CHECK_OK(mlod_pack_decode_skel_level(&p, C_SKEL1, b.p, b.n, &sk, &l, &terr));
	CHECK_OK(mlod_pack_decode_skel_level(&pa, C_SKEL1, a.p, a.n, &ska, &la, &terr));
	int same = memcmp(sk.inverse_bind[0], ska.inverse_bind[0], 64 * NJ) == 0 &&
	           memcmp(sk.joints, ska.joints, sizeof *sk.joints * NJ) == 0 &&
	           memcmp(l.palette_bind, la.palette_bind, 64 * NJ) == 0 && memcmp(l.kept, la.kept, 4 * l.kept_count) == 0;
	char why[256] = "";
	for (int lv = 0; lv < 2; lv++) {
		CHECK_OK(mlod_pack_decode_mesh(&p, lv ? C_MESH1 : C_MESH0, b.p, b.n, &sk, &m, &terr));
		for (uint32_t i = 0; i < m.part_count; i++)
			same = same && check_part(&m.parts[i], &parts_truth[2 * lv + (int)i], why, sizeof why);
		mlod_pack_mesh_free(&m);
		CHECK_OK(mlod_pack_decode_motion(&p, lv ? C_MOT1 : C_MOT0, b.p, b.n, &sk, &mo, &terr));
		CHECK_OK(mlod_pack_decode_motion(&pa, lv ? C_MOT1 : C_MOT0, a.p, a.n, &ska, &moa, &terr));
		same = same && mo.channel_count == moa.channel_count;
		for (uint32_t i = 0; same && i < mo.channel_count; i++) {
			uint32_t k = mo.channels[i].rec.key_count, w = mo.channels[i].rec.path == 1 ? 4 : 3;
			same = memcmp(&mo.channels[i].rec, &moa.channels[i].rec, sizeof mo.channels[i].rec) == 0 &&
			       memcmp(mo.channels[i].times, moa.channels[i].times, 4 * k) == 0 &&
			       memcmp(mo.channels[i].values, moa.channels[i].values, 4 * w * k * (mo.channels[i].rec.interp == 2 ? 3 : 1)) == 0;
		}
		mlod_pack_motion_free(&mo);
		mlod_pack_motion_free(&moa);
	}
	mlod_pack_skel_level_free(&l);
	mlod_pack_skel_level_free(&la);
	mlod_pack_skeleton_free(&ska);
	CHECK_MSG(same && planes > 10 && sums >= 2, "%d plane and %d sum streams: %s", planes, sums, why);
	/* The weights stream of MESH level 1's part 0 (sum codec): a vertex's
	 * three bytes summing past 255, then the codec on 'PART' (200 bytes). */
	{
		uint8_t *chw = b.p + p.chunks[C_MESH1].offset, *w = NULL, *hw = NULL;
		uint32_t nsw = get32(chw);
		size_t atw = 4 + 16 * (size_t)nsw;
		for (uint32_t t = 0; t < nsw && !w; t++) {
			uint8_t *ht = chw + 4 + 16 * t;
			if (get32(ht) == MLOD_STREAM_WGT8)
				w = chw + atw, hw = ht;
			atw += (get32(ht + 12) + 3) & ~3u;
		}
		CHECK(w && hw[10] == MLOD_SCODEC_SUM255 && get32(hw + 12) == 3 * get32(hw + 4));
		uint8_t keep = w[3 * 5];
		w[3 * 5] = 255;
		restamp(b.p, b.n);
		mlod_pack_close(&p);
		CHECK_OK(mlod_pack_open(b.p, b.n, &p, &terr));
		CHECK_ERR(mlod_pack_decode_mesh(&p, C_MESH1, b.p, b.n, &sk, &ma, &terr), MLOD_ERR_PARSE,
		          "'WGT8': element 5: its three bytes sum to ");
		w[3 * 5] = keep;
		restamp(b.p, b.n);
		mlod_pack_close(&p);
		CHECK_OK(mlod_pack_open(b.p, b.n, &p, &terr));
		CHECK_OK(mlod_pack_decode_mesh(&p, C_MESH1, b.p, b.n, &sk, &ma, &terr));
		mlod_pack_mesh_free(&ma);
		uint8_t *h0 = chw + 4, c0 = h0[10];
		h0[10] = MLOD_SCODEC_SUM255;
		restamp(b.p, b.n);
		mlod_pack_close(&p);
		CHECK_OK(mlod_pack_open(b.p, b.n, &p, &terr));
		CHECK_ERR(mlod_pack_decode_mesh(&p, C_MESH1, b.p, b.n, &sk, &ma, &terr), MLOD_ERR_PARSE,
		          "MESH level 1: stream 0 'PART': the sum codec needs an element size of 4, not 200");
		h0[10] = c0;
		restamp(b.p, b.n);
		mlod_pack_close(&p);
		CHECK_OK(mlod_pack_open(b.p, b.n, &p, &terr));
	}
	/* A 6.0 pack with them: refused, naming the format that added them. */
	mlod_pack p6;
	CHECK_OK(mlod_pack_open(b6.p, b6.n, &p6, &terr));
	CHECK_ERR(mlod_pack_decode_mesh(&p6, C_MESH1, b6.p, b6.n, &sk, &ma, &terr), MLOD_ERR_PARSE,
	          "MESH level 1: stream 0 'PART': stream codec 4 in a 6.x pack (format 7.0 added it)");
	mlod_pack_close(&p6);
	/* A stored size that is not the decoded size; a chunk of codec none. */
	uint8_t *ch = b.p + p.chunks[C_MESH1].offset, *h0 = ch + 4, save[16];
	memcpy(save, h0, 16);
	wr32(h0 + 12, get32(h0 + 12) - 4);
	wr32(h0 + 16 + 12, get32(h0 + 16 + 12) + 4);
	restamp(b.p, b.n);
	mlod_pack_close(&p);
	CHECK_OK(mlod_pack_open(b.p, b.n, &p, &terr));
	CHECK_ERR(mlod_pack_decode_mesh(&p, C_MESH1, b.p, b.n, &sk, &ma, &terr), MLOD_ERR_PARSE,
	          "MESH level 1: stream 0 'PART': 396 bytes stored for 2 elements of 200 bytes");
	wr32(h0 + 12, get32(h0 + 12) + 4);
	wr32(h0 + 16 + 12, get32(h0 + 16 + 12) - 4);
	b.p[32 + 48 * C_MESH1 + 5] = (uint8_t)(b.p[32 + 48 * C_MESH1 + 5] & 0xf0);
	restamp(b.p, b.n);
	mlod_pack_close(&p);
	CHECK_OK(mlod_pack_open(b.p, b.n, &p, &terr));
	CHECK_ERR(mlod_pack_decode_mesh(&p, C_MESH1, b.p, b.n, &sk, &ma, &terr), MLOD_ERR_PARSE,
	          "MESH level 1: stream 0 'PART' is in byte planes in a chunk of codec none");
	mlod_pack_skeleton_free(&sk);
	mlod_pack_close(&p);
	mlod_pack_close(&pa);
	free(a.p);
	free(b.p);
	free(b6.p);
}

/* The zero padding between chunks, which no CRC covers: mlod_pack_check
 * (what mlod-pack --info and -x run first) refuses a byte set in it,
 * naming the chunk after it. */
TEST(padding_is_checked)
{
	buf b = make_pack(0);
	mlod_pack p;
	CHECK_OK(mlod_pack_open(b.p, b.n, &p, &terr));
	CHECK_OK(mlod_pack_check(&p, b.p, b.n, &terr));
	uint32_t gap = 0;
	for (uint32_t i = 1; i < p.chunk_count && !gap; i++)
		if (p.chunks[i].offset > p.chunks[i - 1].offset + p.chunks[i - 1].stored_size)
			gap = i;
	CHECK(gap > 0);
	uint64_t at = p.chunks[gap].offset - 1;
	b.p[at] = 0x5a;
	char want[128];
	snprintf(want, sizeof want, "padding byte %llu before the chunk is not zero", (unsigned long long)at);
	CHECK_ERR(mlod_pack_check(&p, b.p, b.n, &terr), MLOD_ERR_PARSE, want);
	mlod_pack_close(&p);
	free(b.p);
}

TEST(meshopt_streams)
{
	static wchunk c[C_COUNT + 1];
	int n = make_chunks(c, 0);
	c[C_MESH1].codec = MLOD_CODEC_MESHOPT;
	c[C_MESH1].s[0].codec = MLOD_SCODEC_MESHOPT_VERTEX;
	buf b = build_pack(c, n, MLOD_PACK_MAJOR, 0);
	free_chunks(c, n);
	mlod_pack p;
	mlod_pack_mesh m;
	mlod_pack_skeleton sk;
	char why[256] = "";
	CHECK_OK(mlod_pack_open(b.p, b.n, &p, &terr));
	CHECK_OK(mlod_pack_decode_skeleton(&p, b.p, b.n, &sk, &terr));
	CHECK_OK(mlod_pack_decode_mesh(&p, C_MESH1, b.p, b.n, &sk, &m, &terr));
	int ok = check_part(&m.parts[0], &parts_truth[2], why, sizeof why);
	mlod_pack_mesh_free(&m);
	mlod_pack_skeleton_free(&sk);
	CHECK_MSG(ok, "%s", why);
	uint8_t *ch = b.p + p.chunks[C_MESH1].offset;
	uint32_t ns = get32(ch);
	uint8_t *h0 = ch + 4;
	uint8_t save[16];
	memcpy(save, h0, 16);
	/* Element size 200 -> 202: not a multiple of 4. */
	h0[8] = 202;
	restamp(b.p, b.n);
	mlod_pack_close(&p);
	CHECK_OK(mlod_pack_open(b.p, b.n, &p, &terr));
	CHECK_ERR(mlod_pack_decode_mesh(&p, C_MESH1, b.p, b.n, NULL, &m, &terr), MLOD_ERR_PARSE,
	          "stream 0 'PART': the meshopt vertex codec needs an element size that is a multiple of 4");
	memcpy(h0, save, 16);
	/* The index codec on the part records. */
	h0[10] = MLOD_SCODEC_MESHOPT_INDEX;
	restamp(b.p, b.n);
	mlod_pack_close(&p);
	CHECK_OK(mlod_pack_open(b.p, b.n, &p, &terr));
	CHECK_ERR(mlod_pack_decode_mesh(&p, C_MESH1, b.p, b.n, NULL, &m, &terr), MLOD_ERR_PARSE,
	          "the meshopt index codec needs an element size of 2 or 4");
	memcpy(h0, save, 16);
	/* Damaged encoded bytes: the decoder's return code. */
	uint8_t *data = ch + 4 + 16 * ns;
	uint8_t first = data[0];
	data[0] = 0x00;
	restamp(b.p, b.n);
	mlod_pack_close(&p);
	CHECK_OK(mlod_pack_open(b.p, b.n, &p, &terr));
	CHECK_ERR(mlod_pack_decode_mesh(&p, C_MESH1, b.p, b.n, NULL, &m, &terr), MLOD_ERR_PARSE,
	          "MESH level 1: stream 0 'PART': the meshopt vertex codec failed");
	data[0] = first;
	restamp(b.p, b.n);
	mlod_pack_close(&p);
	CHECK_OK(mlod_pack_open(b.p, b.n, &p, &terr));
	/* Skinned part without a skeleton. */
	CHECK_ERR(mlod_pack_decode_mesh(&p, C_MESH1, b.p, b.n, NULL, &m, &terr), MLOD_ERR_PARSE,
	          "MESH level 1: part 0: skin 0 is not -1 or below the skeleton's 0 skins");
	mlod_pack_close(&p);
	free(b.p);
}

/* test_pack_reader --write-seed FILE writes the test character's pack
 * (make fuzz starts its corpus with it); --write-seed-zstd the same with
 * the zstd entropy stage. */
int main(int argc, char **argv)
{
	if (argc == 3 && (strcmp(argv[1], "--write-seed") == 0 || strcmp(argv[1], "--write-seed-zstd") == 0 ||
	                  strcmp(argv[1], "--write-seed-prefix") == 0)) {
		zstd_level = argv[1][12] ? 19 : 0;
		zstd_prefix = mesh0_raw = argv[1][12] && argv[1][13] == 'p';
		buf b = make_pack(0);
		FILE *f = fopen(argv[2], "wb");
		int ok = f && fwrite(b.p, 1, b.n, f) == b.n;
		if (f && fclose(f) != 0)
			ok = 0;
		free(b.p);
		if (!ok)
			fprintf(stderr, "test_pack_reader: cannot write %s\n", argv[2]);
		return ok ? 0 : 1;
	}
	RUN(crc_known_vectors);
	RUN(open_reads_header_and_toc);
	RUN(names);
	RUN(decode_info);
	RUN(decode_skeleton_and_level);
	RUN(decode_mesh_meshopt_and_raw);
	RUN(check_decodes_every_chunk);
	RUN(decode_motion);
	RUN(doc_points_into_the_data);
	RUN(free_accepts_zeroed);
	RUN(unknown_chunks_are_skipped);
	RUN(newer_major_is_refused);
	RUN(plane_streams);
	RUN(padding_is_checked);
	RUN(format_6_0_palette_reads);
	RUN(older_major_is_refused);
	RUN(rotq_shift_decodes);
	RUN(rotq_predict_integers);
	RUN(format_8_rotq_reads);
	RUN(format_2_0_reads);
	RUN(motion_tick_bits);
	RUN(nested_motion_needs_its_base);
	RUN(draco_chunks_are_unsupported);
	RUN(every_prefix);
	RUN(entropy_decodes_the_same);
	RUN(every_prefix_zstd);
	RUN(entropy_checks);
	RUN(structural_checks_name_the_chunk);
	RUN(toc_order_ranks);
	RUN(toc_checks);
	RUN(absurd_sizes);
	RUN(expansion_limits);
	RUN(zstd_forged_size);
	RUN(unknown_codec_raw_size);
	RUN(meshopt_streams);
	RUN(mutations_plain);
	RUN(mutations_restamped);
	RUN(mutations_zstd);
	RUN(prefix_decodes_the_same);
	RUN(prefix_checks);
	RUN(every_prefix_zstd_prefix);
	RUN(mutations_zstd_prefix);
	return test_total_fail_ ? 1 : 0;
}
