/*
 * test_rt_pack.c: the runtime on a real .mlod pack, written here byte by
 * byte from the format (mlod_pack.h; raw streams) from the hand-built
 * character of rt_test.h: three skeleton, three mesh and three motion
 * levels of two clips. Opened from memory, from a file and through read
 * callbacks, it must pose exactly as the views and skin within the
 * quantisation of positions, normals and weights; and pose to the same
 * floats as the pack decoded by its reader and handed over as views (the
 * runtime normalises the rotation keys of the levels it decodes, never the
 * views'). Then every truncated prefix and
 * 10,000 mutations (half with every CRC fixed, so that the decoders' own
 * checks are reached) go through open, streaming and one frame of
 * evaluation: an error is fine, a crash or a sanitizer report is not;
 * every finite vertex skinned must lie in mlod_rt_bounds' box, every
 * name read must be a string and every parent and stand-in come before
 * its joint.
 * All of these run under a tracking allocator whose blocks come from a
 * static arena, not malloc: every block the runtime frees must be one of
 * its live blocks, none may be left at close, the decoded levels must be
 * in it, and (glibc, outside ASan) the C library's heap must not grow
 * from open to close: the runtime allocates only through the hooks.
 * The runtime tests run twice: on the raw pack, then with every chunk
 * but INFO behind the zstd entropy stage (format 5.0; the decoder's
 * context comes from the hooks too).
 */
#define _POSIX_C_SOURCE 200809L /* mkstemp */
#include <unistd.h>
#if defined(__GLIBC__)
#include <malloc.h> /* mallinfo2: glibc's heap, to see that the runtime never calls malloc itself */
#endif

#include <zstd.h>

#include "rt_test.h"

/* ---------------------------------------------------------------- */
/* Writing a pack                                                    */
/* ---------------------------------------------------------------- */

typedef struct bytes {
	uint8_t *d;
	size_t n, cap;
} bytes;

static void put(bytes *b, const void *p, size_t n)
{
	if (b->n + n > b->cap) {
		b->cap = (b->n + n) * 2 + 256;
		b->d = realloc(b->d, b->cap);
	}
	if (n)
		memcpy(b->d + b->n, p, n);
	b->n += n;
}
static void put32(bytes *b, uint32_t v)
{
	uint8_t x[4] = { (uint8_t)v, (uint8_t)(v >> 8), (uint8_t)(v >> 16), (uint8_t)(v >> 24) };
	put(b, x, 4);
}
static void put16(bytes *b, uint16_t v)
{
	uint8_t x[2] = { (uint8_t)v, (uint8_t)(v >> 8) };
	put(b, x, 2);
}
static void put64(bytes *b, uint64_t v)
{
	put32(b, (uint32_t)v);
	put32(b, (uint32_t)(v >> 32));
}
static void putf(bytes *b, float f)
{
	uint32_t v;
	memcpy(&v, &f, 4);
	put32(b, v);
}
static void pad(bytes *b, size_t a)
{
	static const uint8_t z[16] = { 0 };
	put(b, z, (a - b->n % a) % a);
}

/* A chunk under construction: its streams. */
#define MAXS 64
typedef struct chunk {
	uint32_t type, layer, level, item;
	float error, distance;
	int ns;
	uint32_t tag[MAXS], count[MAXS], elsize[MAXS];
	bytes data[MAXS];
} chunk;

static bytes *stream(chunk *c, uint32_t tag, uint32_t elsize)
{
	c->tag[c->ns] = tag;
	c->elsize[c->ns] = elsize;
	c->count[c->ns] = 0;
	memset(&c->data[c->ns], 0, sizeof(bytes));
	return &c->data[c->ns++];
}
static void stream_end(chunk *c)
{
	c->count[c->ns - 1] = (uint32_t)(c->data[c->ns - 1].n / c->elsize[c->ns - 1]);
}

static void chunk_bytes(chunk *c, bytes *out)
{
	put32(out, (uint32_t)c->ns);
	for (int i = 0; i < c->ns; i++) {
		put32(out, c->tag[i]);
		put32(out, c->count[i]);
		put16(out, (uint16_t)c->elsize[i]);
		uint8_t z[2] = { 0, 0 };
		put(out, z, 2);
		put32(out, (uint32_t)c->data[i].n);
	}
	for (int i = 0; i < c->ns; i++) {
		put(out, c->data[i].d, c->data[i].n);
		pad(out, 4);
		free(c->data[i].d);
	}
}

static chunk chunks[32];
static int nchunks;

static chunk *new_chunk(uint32_t type, uint32_t layer, uint32_t level, uint32_t item, float error, float distance)
{
	chunk *c = &chunks[nchunks++];
	memset(c, 0, sizeof *c);
	c->type = type, c->layer = layer, c->level = level, c->item = item, c->error = error, c->distance = distance;
	return c;
}

/* The CRCs of every chunk, the TOC and the header, from the bytes. */
static void fix_crcs(uint8_t *d, size_t size)
{
	uint32_t n = (uint32_t)d[12] | (uint32_t)d[13] << 8 | (uint32_t)d[14] << 16 | (uint32_t)d[15] << 24;
	if (32 + (uint64_t)n * 48 > size)
		return;
	for (uint32_t i = 0; i < n; i++) {
		uint8_t *e = d + 32 + 48 * i;
		uint64_t off = 0;
		uint32_t st = 0;
		for (int k = 7; k >= 0; k--)
			off = off << 8 | e[16 + k];
		for (int k = 3; k >= 0; k--)
			st = st << 8 | e[24 + k];
		if (off <= size && st <= size - off) {
			uint32_t crc = mlod_pack_crc32(0, d + off, st);
			for (int k = 0; k < 4; k++)
				e[32 + k] = (uint8_t)(crc >> (8 * k));
		}
	}
	uint32_t t = mlod_pack_crc32(0, d + 32, (size_t)n * 48);
	for (int k = 0; k < 4; k++)
		d[24 + k] = (uint8_t)(t >> (8 * k));
	uint32_t h = mlod_pack_crc32(0, d, 28);
	for (int k = 0; k < 4; k++)
		d[28 + k] = (uint8_t)(h >> (8 * k));
}

/* When set, write_pack puts every chunk but INFO through zstd; when 2,
 * a MESH level but the coarsest and a skeleton level are coded on the
 * chunks they need (format 6.0's prefix stage: the coarser MESH levels'
 * containers, SKELETON's container). */
static int zstd_pack;

static void write_pack(bytes *out)
{
	bytes body[32];
	uint32_t raw[32], coded[32] = { 0 };
	uint8_t stage[32] = { 0 };
	bytes meshes = { 0 }, skel0 = { 0 };
	for (int i = 0; i < nchunks; i++) {
		memset(&body[i], 0, sizeof body[i]);
		chunk_bytes(&chunks[i], &body[i]);
		raw[i] = (uint32_t)body[i].n;
		if (zstd_pack && chunks[i].type != MLOD_CHUNK_INFO) {
			size_t cap = ZSTD_compressBound(body[i].n);
			bytes z = { malloc(cap), 0, cap };
			const bytes *pre = NULL;
			if (zstd_pack == 2 && chunks[i].type == MLOD_CHUNK_MESH && meshes.n)
				pre = &meshes;
			if (zstd_pack == 2 && chunks[i].type == MLOD_CHUNK_SKELETON && chunks[i].level > 0)
				pre = &skel0;
			ZSTD_CCtx *cc = ZSTD_createCCtx();
			ZSTD_CCtx_setParameter(cc, ZSTD_c_compressionLevel, 19);
			if (pre)
				ZSTD_CCtx_refPrefix(cc, pre->d, pre->n);
			z.n = ZSTD_compress2(cc, z.d, cap, body[i].d, body[i].n);
			ZSTD_freeCCtx(cc);
			if (ZSTD_isError(z.n))
				z.n = 0;
			coded[i] = raw[i];
			stage[i] = pre ? MLOD_ENTROPY_ZSTD_PREFIX : MLOD_ENTROPY_ZSTD;
			if (chunks[i].type == MLOD_CHUNK_MESH)
				put(&meshes, body[i].d, body[i].n);
			if (chunks[i].type == MLOD_CHUNK_SKELETON && chunks[i].level == 0)
				put(&skel0, body[i].d, body[i].n);
			free(body[i].d);
			body[i] = z;
		}
	}
	free(meshes.d);
	free(skel0.d);
	uint64_t off = 32 + 48 * (uint64_t)nchunks, offs[32];
	for (int i = 0; i < nchunks; i++) {
		off = (off + 15) / 16 * 16;
		offs[i] = off;
		off += body[i].n;
	}
	/* INFO's first_drawable (mlod(5)): where the last of INFO, SKELETON and
	 * the coarsest level of each layer ends (the coarsest: the largest level
	 * of its type here). Written into the INFO chunk's record when that says
	 * 0 and the chunk is the encoder's plain container with the record first
	 * (tests that set another value keep it). */
	uint32_t top[3] = { 0, 0, 0 }; /* SKELETON, MESH, MOTION */
	for (int i = 0; i < nchunks; i++) {
		const int k = chunks[i].type == MLOD_CHUNK_SKELETON ? 0 : chunks[i].type == MLOD_CHUNK_MESH ? 1
		              : chunks[i].type == MLOD_CHUNK_MOTION ? 2 : -1;
		if (k >= 0 && chunks[i].level > top[k])
			top[k] = chunks[i].level;
	}
	uint64_t drawable = 0;
	for (int i = 0; i < nchunks; i++) {
		const chunk *c = &chunks[i];
		const int coarse = c->type == MLOD_CHUNK_INFO ||
		                   (c->type == MLOD_CHUNK_SKELETON && (c->level == 0 || c->level == top[0])) ||
		                   (c->type == MLOD_CHUNK_MESH && c->level == top[1]) ||
		                   (c->type == MLOD_CHUNK_MOTION && c->level == top[2]);
		if (coarse && offs[i] + body[i].n > drawable)
			drawable = offs[i] + body[i].n;
	}
	for (int i = 0; i < nchunks; i++) {
		uint8_t *b = body[i].d;
		if (chunks[i].type != MLOD_CHUNK_INFO || stage[i] || body[i].n < 4 + 16 + 80 || b[0] == 0 ||
		    memcmp(b + 4, "INFO", 4) != 0)
			continue;
		uint8_t *fd = b + 4 + 16 * (size_t)b[0] + 64;
		if ((size_t)(fd + 4 - b) <= body[i].n && !(fd[0] | fd[1] | fd[2] | fd[3]))
			for (int k = 0; k < 4; k++)
				fd[k] = (uint8_t)(drawable >> (8 * k));
	}
	memset(out, 0, sizeof *out);
	put(out, "MLOD", 4);
	/* format 8.0, the layout this builder writes: its 'ROTQ' keys as they are
	 * (9.0 predicts them), no max_vertex_count (8.1) */
	put16(out, 8), put16(out, 0), put32(out, 0), put32(out, (uint32_t)nchunks), put64(out, off);
	put32(out, 0), put32(out, 0); /* CRCs below */
	for (int i = 0; i < nchunks; i++) {
		chunk *c = &chunks[i];
		put32(out, c->type);
		uint8_t lc[2] = { (uint8_t)c->layer, (uint8_t)(stage[i] << 4) };
		put(out, lc, 2);
		put16(out, (uint16_t)c->level), put16(out, (uint16_t)c->item), put16(out, 0), put32(out, coded[i]);
		put64(out, offs[i]);
		put32(out, (uint32_t)body[i].n), put32(out, raw[i]), put32(out, 0);
		putf(out, c->error), putf(out, c->distance), put32(out, 0);
	}
	for (int i = 0; i < nchunks; i++) {
		pad(out, 16);
		put(out, body[i].d, body[i].n);
		free(body[i].d);
	}
	fix_crcs(out->d, out->n);
}

static void put_mat(bytes *b, const float *m)
{
	for (int i = 0; i < 16; i++)
		putf(b, m[i]);
}

static void oct(const float *n, int16_t *q)
{
	float x = n[0], y = n[1], z = n[2], s = fabsf(x) + fabsf(y) + fabsf(z);
	x /= s, y /= s, z /= s;
	if (z < 0) {
		float ox = (1 - fabsf(y)) * (x >= 0 ? 1 : -1), oy = (1 - fabsf(x)) * (y >= 0 ? 1 : -1);
		x = ox, y = oy;
	}
	q[0] = (int16_t)lrintf(x * 32767), q[1] = (int16_t)lrintf(y * 32767);
}

/* The fixture's mesh levels as the pack stores them (layout b2): level
 * 0's parts at every level (a part a coarser fixture level lacks has no
 * vertices there), one grid per part (the union of its levels' boxes),
 * and each level's block holding all its vertices (no vertex shared with a
 * coarser level: the format allows it) after the coarser levels' blocks;
 * its indices use every vertex of its block in order, so that the reader's
 * gathered level is the fixture's, vertex for vertex. */
static const mlod_pack_mesh *fx_levels[3];

static const mlod_pack_part *level_part(uint32_t level, uint32_t i)
{
	return i < fx_levels[level]->part_count ? &fx_levels[level]->parts[i] : NULL;
}

static void mesh_chunk(const mlod_pack_mesh *m, uint32_t level)
{
	(void)m;
	const mlod_pack_mesh *m0 = fx_levels[0];
	chunk *c = new_chunk(MLOD_CHUNK_MESH, MLOD_LAYER_MESH, level, 0, fx_vmesh[level].error, fx_vmesh[level].distance);
	bytes *b = stream(c, MLOD_STREAM_PART, sizeof(mlod_pack_part_rec));
	for (uint32_t i = 0; i < m0->part_count; i++) {
		mlod_pack_part_rec r = m0->parts[i].rec;
		const mlod_pack_part *p = level_part(level, i);
		r.vertex_count = p ? p->rec.vertex_count : 0;
		r.index_count = (r.vertex_count + 2) / 3 * 3;
		for (int a = 0; a < 3; a++) {
			float lo = 1e30f, hi = -1e30f;
			for (uint32_t l = 0; l < 3; l++) {
				const mlod_pack_part *q = level_part(l, i);
				for (uint32_t v = 0; q && v < q->rec.vertex_count; v++) {
					float x = q->positions[3 * v + a];
					lo = x < lo ? x : lo, hi = x > hi ? x : hi;
				}
			}
			r.pos_min[a] = lo;
			r.pos_scale[a] = (hi - lo) / 65535.0f;
		}
		put(b, &r, sizeof r);
	}
	stream_end(c);
	for (uint32_t i = 0; i < m0->part_count; i++) {
		const mlod_pack_part *p = level_part(level, i);
		const mlod_pack_part_rec *r = (const mlod_pack_part_rec *)c->data[0].d + i;
		uint32_t base = 0;
		for (uint32_t l = level + 1; l < 3; l++)
			base += level_part(l, i) ? level_part(l, i)->rec.vertex_count : 0;
		b = stream(c, MLOD_STREAM_POSQ, 8);
		for (uint32_t v = 0; v < r->vertex_count; v++) {
			for (int a = 0; a < 3; a++)
				put16(b, (uint16_t)(r->pos_scale[a] > 0 ? lrintf((p->positions[3 * v + a] - r->pos_min[a]) / r->pos_scale[a]) : 0));
			put16(b, 0);
		}
		stream_end(c);
		if (r->flags & MLOD_PART_NORMALS) {
			b = stream(c, MLOD_STREAM_NRMQ, 4);
			for (uint32_t v = 0; v < r->vertex_count; v++) {
				int16_t q[2];
				oct(p->normals + 3 * v, q);
				put16(b, (uint16_t)q[0]), put16(b, (uint16_t)q[1]);
			}
			stream_end(c);
		}
		if (r->flags & MLOD_PART_SKINNED) {
			b = stream(c, MLOD_STREAM_JNT8, 4);
			for (uint32_t k = 0; k < 4 * r->vertex_count; k++) {
				uint8_t j = (uint8_t)p->joints[k];
				put(b, &j, 1);
			}
			stream_end(c);
			b = stream(c, MLOD_STREAM_WGT8, 4);
			for (uint32_t v = 0; v < r->vertex_count; v++) {
				uint8_t w[4];
				int sum = 0, big = 0;
				for (int k = 0; k < 4; k++) {
					w[k] = (uint8_t)lrintf(p->weights[4 * v + k] * 255);
					sum += w[k];
					big = w[k] > w[big] ? k : big;
				}
				w[big] = (uint8_t)(w[big] + 255 - sum);
				put(b, w, 4);
			}
			stream_end(c);
		}
		b = stream(c, MLOD_STREAM_IDX, 4);
		for (uint32_t k = 0; k < r->index_count; k++)
			put32(b, base + (k < r->vertex_count ? k : r->vertex_count - 1));
		stream_end(c);
	}
}

static void motion_chunk(const mlod_pack_motion *m, uint32_t level, uint32_t clip)
{
	const mlod_rt_view_level *vl = &fx_vmotion[clip * 3 + level];
	chunk *c = new_chunk(MLOD_CHUNK_MOTION, MLOD_LAYER_MOTION, level, clip, vl->error, vl->distance);
	/* one f32 time array per channel (channel i refers to array i), in
	 * one 'TIME' stream */
	bytes *b = stream(c, MLOD_STREAM_CHAN, sizeof(mlod_pack_channel_rec));
	for (uint32_t i = 0; i < m->channel_count; i++) {
		mlod_pack_channel_rec rec = m->channels[i].rec;
		rec.time = i;
		put(b, &rec, sizeof rec);
	}
	stream_end(c);
	b = stream(c, MLOD_STREAM_STEP, 8);
	double no_step = 0;
	put(b, &no_step, 8);
	stream_end(c);
	b = stream(c, MLOD_STREAM_TIME, 4);
	for (uint32_t i = 0; i < m->channel_count; i++) {
		const mlod_pack_channel *ch = &m->channels[i];
		for (uint32_t k = 0; k < ch->rec.key_count; k++)
			putf(b, ch->times[k]);
	}
	stream_end(c);
	/* the values: ROTQ, ROTD (none: not nested), ROTF, VEC3, each its
	 * channels' keys in order */
	for (int kind = 0; kind < 3; kind++) {
		if (kind == 1) {
			stream(c, MLOD_STREAM_ROTD, 8);
			stream_end(c);
		}
		b = stream(c, kind == 0 ? MLOD_STREAM_ROTQ : kind == 1 ? MLOD_STREAM_ROTF : MLOD_STREAM_VEC3,
		           kind == 0 ? 8 : kind == 1 ? 16 : 12);
		for (uint32_t i = 0; i < m->channel_count; i++) {
			const mlod_pack_channel *ch = &m->channels[i];
			const uint32_t K = ch->rec.key_count, per = ch->rec.interp == 2 ? 3 : 1;
			int is = ch->rec.path == 1 ? (per == 1 ? 0 : 1) : 2;
			if (is != kind)
				continue;
			for (uint32_t k = 0; kind == 0 && k < K; k++) {
				/* smallest three: the components but the largest, then its index */
				const float *v = ch->values + 4 * (size_t)k;
				int big = 0;
				for (int a = 1; a < 4; a++)
					big = fabsf(v[a]) > fabsf(v[big]) ? a : big;
				float sign = v[big] < 0 ? -1.0f : 1.0f;
				for (int a = 0; a < 4; a++)
					if (a != big) {
						int16_t q = (int16_t)lrintf(sign * v[a] * 32767.0f);
						put(b, &q, 2);
					}
				int16_t q = (int16_t)big;
				put(b, &q, 2);
			}
			for (uint32_t k = 0; kind != 0 && k < K * per * (kind == 2 ? 3 : 4); k++)
				putf(b, ch->values[k]);
		}
		stream_end(c);
	}
	stream(c, MLOD_STREAM_VECD, 12); /* none: not nested */
	stream_end(c);
}

static void build_pack(bytes *out)
{
	nchunks = 0;
	chunk *c = new_chunk(MLOD_CHUNK_INFO, MLOD_LAYER_NONE, 0, 0, 0, 0);
	mlod_pack_info_rec info;
	memset(&info, 0, sizeof info);
	info.joint_count = FX_J, info.skin_count = 1, info.skeleton_levels = 3, info.mesh_levels = 3;
	info.clip_count = 2, info.motion_levels = 3, info.instance_count = 3;
	info.bounds_max[0] = info.bounds_max[1] = info.bounds_max[2] = 3, info.height = 3, info.diagonal = 5.2f;
	put(stream(c, MLOD_STREAM_INFO, sizeof info), &info, sizeof info);
	stream_end(c);
	put(stream(c, MLOD_STREAM_NAME, 1), "fx\0walk\0run", 12);
	stream_end(c);

	c = new_chunk(MLOD_CHUNK_SKELETON, MLOD_LAYER_SKELETON, 0, 0, 0, 0);
	bytes *b = stream(c, MLOD_STREAM_JNTS, sizeof(mlod_pack_joint_rec));
	static const uint32_t name_off[FX_J] = { 0, 5, 11, 17, 22 }; /* "root spine chest head arm" */
	for (int j = 0; j < FX_J; j++) {
		mlod_pack_joint_rec r = fx_joints[j];
		r.name = name_off[j];
		r.node = -1;
		put(b, &r, sizeof r);
	}
	stream_end(c);
	put(stream(c, MLOD_STREAM_NAME, 1), "root\0spine\0chest\0head\0arm\0skin", 31);
	stream_end(c);
	mlod_pack_skin_rec sk = { FX_J, 26, -1 };
	put(stream(c, MLOD_STREAM_SKIN, sizeof sk), &sk, sizeof sk);
	stream_end(c);
	b = stream(c, MLOD_STREAM_SKJT, 4);
	for (int j = 0; j < FX_J; j++)
		put32(b, fx_skin_joints_0[j]);
	stream_end(c);
	b = stream(c, MLOD_STREAM_IBMS, 64);
	for (int j = 0; j < FX_J; j++)
		put_mat(b, fx_ibm_0 + 16 * j);
	stream_end(c);
	const mlod_pack_skel_level *sl[3] = { NULL, &fx_sl1, &fx_sl2 };
	for (int l = 2; l >= 1; l--) {
		c = new_chunk(MLOD_CHUNK_SKELETON, MLOD_LAYER_SKELETON, (uint32_t)l, 0, fx_vskel[l].error,
		              fx_vskel[l].distance);
		b = stream(c, MLOD_STREAM_KEPT, 4);
		for (uint32_t i = 0; i < sl[l]->kept_count; i++)
			put32(b, sl[l]->kept[i]);
		stream_end(c);
		/* Format 7.0: each bind matrix as IBMS entry i's (0) or as the
		 * next 'PALX' matrix (FX_J + 1 + its index); the reader derives
		 * the palette joints. */
		b = stream(c, MLOD_STREAM_PALR, 4);
		uint32_t nx = 0;
		for (uint32_t i = 0; i < FX_J; i++)
			put32(b, memcmp(sl[l]->palette_bind + 16 * i, fx_ibm_0 + 16 * i, 64) == 0 ? 0 : FX_J + 1 + nx++);
		stream_end(c);
		b = stream(c, MLOD_STREAM_PALX, 64);
		for (uint32_t i = 0; i < FX_J; i++)
			if (memcmp(sl[l]->palette_bind + 16 * i, fx_ibm_0 + 16 * i, 64) != 0)
				put_mat(b, sl[l]->palette_bind + 16 * i);
		stream_end(c);
	}
	const mlod_pack_mesh *ml[3] = { &fx_mesh0, &fx_mesh1, &fx_mesh2 };
	memcpy(fx_levels, ml, sizeof ml);
	for (int l = 2; l >= 0; l--) {
		mesh_chunk(ml[l], (uint32_t)l);
		for (uint32_t clip = 0; clip < 2; clip++)
			motion_chunk(&fx_mo[clip][l], (uint32_t)l, clip);
	}
	write_pack(out);
}

/* ---------------------------------------------------------------- */
/* Tests                                                             */
/* ---------------------------------------------------------------- */

static bytes pack;
static int reads;

static int mem_read(void *user, uint64_t offset, size_t size, void *dst)
{
	const bytes *b = user;
	reads++;
	if (offset > b->n || size > b->n - offset)
		return -1;
	memcpy(dst, b->d + offset, size);
	return 0;
}

/* Poses and skins instance id of a and b at the same levels; the largest
 * differences. */
static void compare(mlod_rt_ctx *a, mlod_rt_ctx *b, double *dw, double *dp, double *dn, mlod_error *e)
{
	mlod_rt_scratch *sa = mlod_rt_scratch_create(a), *sb = mlod_rt_scratch_create(b);
	float pa[21], pb[21], na[21], nb[21];
	*dw = *dp = *dn = 0;
	mlod_rt_select sel;
	mlod_rt_select_default(&sel);
	sel.hysteresis = 0;
	for (int k = 0; k < 40; k++) {
		uint32_t ia, ib, n1, n2;
		float d = (float)(k % 10) * 22.0f, t = 0.13f * (float)k;
		mlod_rt_instance_create(a, (uint32_t)k % 2, t, MLOD_RT_LOOP, &ia, e);
		mlod_rt_instance_create(b, (uint32_t)k % 2, t, MLOD_RT_LOOP, &ib, e);
		mlod_rt_update(a, &sel, &ia, &d, 1, 0, e);
		mlod_rt_update(b, &sel, &ib, &d, 1, 0, e);
		const float *wa, *wb;
		if (mlod_rt_pose(a, sa, ia, &wa, NULL, NULL, e) || mlod_rt_pose(b, sb, ib, &wb, NULL, NULL, e) ||
		    memcmp(mlod_rt_instance_state(a, ia)->level, mlod_rt_instance_state(b, ib)->level, 6) != 0) {
			*dw = 1e9;
			break;
		}
		for (int j = 0; j < FX_J; j++) {
			double x = fx_maxdiff(wa + 16 * j, wb + 16 * j, 16);
			*dw = x > *dw ? x : *dw;
		}
		if (mlod_rt_skin(a, sa, ia, pa, 12, na, 12, 7, &n1, e) || mlod_rt_skin(b, sb, ib, pb, 12, nb, 12, 7, &n2, e) ||
		    n1 != n2) {
			*dp = 1e9;
			break;
		}
		double x = fx_maxdiff(pa, pb, 3 * (int)n1), y = fx_maxdiff(na, nb, 3 * (int)n1);
		*dp = x > *dp ? x : *dp;
		*dn = y > *dn ? y : *dn;
		mlod_rt_instance_destroy(a, ia);
		mlod_rt_instance_destroy(b, ib);
	}
	mlod_rt_scratch_destroy(a, sa);
	mlod_rt_scratch_destroy(b, sb);
}

TEST(pack_equals_views)
{
	mlod_error e;
	mlod_rt_ctx *v = NULL, *m = NULL, *p = NULL, *r = NULL;
	CHECK_OK(mlod_rt_open_views(&fx_views, NULL, &v, &e), e);
	CHECK_OK(mlod_rt_open_memory(pack.d, pack.n, NULL, &m, &e), e);
	char path[] = "/tmp/mlod-rt-test-XXXXXX";
	int fd = mkstemp(path);
	CHECK(fd >= 0, "mkstemp");
	CHECK(write(fd, pack.d, pack.n) == (ssize_t)pack.n, "write");
	close(fd);
	mlod_result res = mlod_rt_open_path(path, NULL, &p, &e);
	remove(path);
	CHECK(res == MLOD_OK, "open_path: %s", e.message);
	reads = 0;
	CHECK_OK(mlod_rt_open_read(mem_read, &pack, pack.n, NULL, &r, &e), e);
	CHECK(reads > 0, "no read through the callback");
	CHECK(mlod_rt_level_count(m, MLOD_RT_SKELETON) == 3 && mlod_rt_level_count(m, MLOD_RT_MESH) == 3 &&
	          mlod_rt_level_count(m, MLOD_RT_MOTION) == 3 && mlod_rt_clip_count(m) == 2,
	      "level counts from the pack");
	mlod_rt_level_info li;
	CHECK_OK(mlod_rt_level_info_get(m, MLOD_RT_MESH, 1, 0, &li, &e), e);
	CHECK(NEAR(li.error, 0.01, 1e-7) && !li.resident && li.stored_size > 0, "mesh level 1 from the TOC");
	CHECK(fx_load_all(v) == 0 && fx_load_all(m) == 0 && fx_load_all(p) == 0 && fx_load_all(r) == 0,
	      "streaming every level failed");
	mlod_rt_ctx *ctxs[3] = { m, p, r };
	for (int i = 0; i < 3; i++) {
		double dw, dp, dn;
		compare(v, ctxs[i], &dw, &dp, &dn, &e);
		/* positions quantised to 1/65535 of a part's extent (<= 3), normals to
		 * 1/32767, and weights to 1/255 (0.75 becomes 191/255: about 1e-3
		 * of the 2 units between the blended joints) */
		CHECK(dw <= 1e-6 && dp <= 5e-3 && dn <= 5e-3, "source %d: pose %g, positions %g, normals %g", i, dw, dp, dn);
	}
	mlod_rt_stats s;
	mlod_rt_stats_get(r, &s); /* 4 coarse levels at open, then 7 (skeleton level 0 comes with SKELETON) */
	CHECK(s.loads == 11 && s.failures == 0, "%llu loads, %llu failures", (unsigned long long)s.loads,
	      (unsigned long long)s.failures);
	mlod_rt_close(v), mlod_rt_close(m), mlod_rt_close(p), mlod_rt_close(r);
	CHECK(mlod_rt_open_path("/nonexistent/x.mlod", NULL, &p, &e) == MLOD_ERR_IO && !p, "missing file");
}

/* The pack decoded by its reader into views: the runtime reads views and
 * never changes them, while it normalises the rotation keys of the levels
 * it decodes itself when loading them (and then skips normalising them
 * each frame). Both must pose to the same floats, at every level, clip
 * and many times (and so give the same palettes). */
TEST(pack_poses_as_its_decoded_views)
{
	mlod_error e;
	mlod_pack pk;
	CHECK_OK(mlod_pack_open(pack.d, pack.n, &pk, &e), e);
	mlod_pack_skeleton sk;
	CHECK_OK(mlod_pack_decode_skeleton(&pk, pack.d, pack.n, &sk, &e), e);
	enum { L = 3, C = 2 };
	mlod_pack_skel_level sl[L];
	mlod_pack_mesh ml[L];
	mlod_pack_motion mo[C * L];
	mlod_rt_view_level vs[L], vm[L], vo[C * L];
	memset(vs, 0, sizeof vs), memset(vm, 0, sizeof vm), memset(vo, 0, sizeof vo);
	int got = 0;
	for (uint32_t i = 0; i < pk.chunk_count; i++) {
		const mlod_pack_chunk *c = &pk.chunks[i];
		if (c->level >= L || c->item >= C)
			continue;
		if (c->type == MLOD_CHUNK_SKELETON && c->level > 0) {
			CHECK_OK(mlod_pack_decode_skel_level(&pk, i, pack.d, pack.n, &sk, &sl[c->level], &e), e);
			vs[c->level].data = &sl[c->level], got++;
		} else if (c->type == MLOD_CHUNK_MESH) {
			CHECK_OK(mlod_pack_decode_mesh(&pk, i, pack.d, pack.n, &sk, &ml[c->level], &e), e);
			vm[c->level].data = &ml[c->level], got++;
		} else if (c->type == MLOD_CHUNK_MOTION) {
			const uint32_t k = c->item * L + c->level;
			CHECK_OK(mlod_pack_decode_motion(&pk, i, pack.d, pack.n, &sk, &mo[k], &e), e);
			vo[k].data = &mo[k], got++;
		}
	}
	CHECK(got == (L - 1) + L + C * L, "%d levels decoded", got);
	const mlod_rt_views views = { &sk, L, vs, L, vm, C, L, vo };
	mlod_rt_ctx *v = NULL, *m = NULL;
	CHECK_OK(mlod_rt_open_views(&views, NULL, &v, &e), e);
	CHECK_OK(mlod_rt_open_memory(pack.d, pack.n, NULL, &m, &e), e);
	CHECK(fx_load_all(v) == 0 && fx_load_all(m) == 0, "streaming every level failed");
	mlod_rt_scratch *sv = mlod_rt_scratch_create(v), *sm = mlod_rt_scratch_create(m);
	double worst = 0;
	int poses = 0;
	for (uint32_t clip = 0; clip < C; clip++)
		for (int level = 0; level < L; level++) {
			uint32_t iv, im;
			CHECK_OK(mlod_rt_instance_create(v, clip, 0, MLOD_RT_LOOP, &iv, &e), e);
			CHECK_OK(mlod_rt_instance_create(m, clip, 0, MLOD_RT_LOOP, &im, &e), e);
			mlod_rt_select sel;
			mlod_rt_select_default(&sel);
			sel.force_level = level;
			float d = 1;
			for (int f = 0; f < 97; f++) {
				const float dt = f ? 0.0371f : 0.0f;
				CHECK_OK(mlod_rt_update(v, &sel, &iv, &d, 1, dt, &e), e);
				CHECK_OK(mlod_rt_update(m, &sel, &im, &d, 1, dt, &e), e);
				const float *wv, *wm, *pv, *pm;
				uint32_t nv, nm, qv, qm;
				const uint32_t *jv, *jm;
				CHECK_OK(mlod_rt_pose(v, sv, iv, &wv, &jv, &nv, &e), e);
				CHECK_OK(mlod_rt_pose(m, sm, im, &wm, &jm, &nm, &e), e);
				CHECK(nv == nm && memcmp(jv, jm, nv * sizeof *jv) == 0, "kept joints differ");
				for (uint32_t j = 0; j < nv; j++) {
					double x = fx_maxdiff(wv + 16 * jv[j], wm + 16 * jm[j], 16);
					worst = x > worst ? x : worst;
				}
				CHECK_OK(mlod_rt_palette(v, sv, &pv, &qv, &e), e);
				CHECK_OK(mlod_rt_palette(m, sm, &pm, &qm, &e), e);
				CHECK(qv == qm, "palettes of %u and %u", qv, qm);
				double x = fx_maxdiff(pv, pm, 16 * (int)qv);
				worst = x > worst ? x : worst;
				poses++;
			}
			mlod_rt_instance_destroy(v, iv);
			mlod_rt_instance_destroy(m, im);
		}
	CHECK(worst == 0, "the pack's own decode poses %g away from its decoded views", worst);
	printf("# %d poses of the pack, decoded by the runtime and as views: equal\n", poses);
	mlod_rt_scratch_destroy(v, sv), mlod_rt_scratch_destroy(m, sm);
	mlod_rt_close(v), mlod_rt_close(m);
	for (int l = 0; l < L; l++) {
		if (l > 0)
			mlod_pack_skel_level_free(&sl[l]);
		mlod_pack_mesh_free(&ml[l]);
	}
	for (int k = 0; k < C * L; k++)
		mlod_pack_motion_free(&mo[k]);
	mlod_pack_skeleton_free(&sk);
	mlod_pack_close(&pk);
}

/* ---------------------------------------------------------------- */
/* The tracking allocator                                            */
/* ---------------------------------------------------------------- */

/* Blocks from a static arena (never malloc), each after a 16-byte head:
 * a tag saying live or freed, and its size. The arena starts over when
 * nothing is live. */
enum { ARENA = 8 << 20, HEAD = 16, TAG_LIVE = 0x4c495645, TAG_FREED = 0x46524545 };
static _Alignas(16) unsigned char arena[ARENA];
static size_t arena_used, track_live, track_live_bytes, track_calls;
static int track_bad;   /* a foreign or double free */
static int track_leaks; /* runs of one_frame that left blocks or freed foreign ones */

static void *track_malloc(void *user, size_t size)
{
	(void)user;
	track_calls++;
	size_t need = HEAD + (size + 15) / 16 * 16;
	if (size > ARENA || need > ARENA - arena_used)
		return NULL;
	unsigned char *h = arena + arena_used;
	arena_used += need;
	uint32_t tag = TAG_LIVE;
	uint64_t n = size;
	memcpy(h, &tag, 4);
	memcpy(h + 8, &n, 8);
	track_live++;
	track_live_bytes += size;
	return h + HEAD;
}

static void track_free(void *user, void *p)
{
	(void)user;
	if (!p)
		return;
	unsigned char *h = (unsigned char *)p - HEAD;
	uint32_t tag;
	uint64_t n;
	if ((unsigned char *)p < arena + HEAD || (unsigned char *)p > arena + arena_used ||
	    (size_t)(h - arena) % 16 != 0) {
		track_bad++; /* not ours: something the runtime got elsewhere */
		return;
	}
	memcpy(&tag, h, 4);
	memcpy(&n, h + 8, 8);
	if (tag != TAG_LIVE) {
		track_bad++; /* freed twice, or not a block's start */
		return;
	}
	tag = TAG_FREED;
	memcpy(h, &tag, 4);
	track_live--;
	track_live_bytes -= (size_t)n;
	if (track_live == 0)
		arena_used = 0;
}

static const mlod_rt_allocator tracker = { track_malloc, track_free, NULL };

/* A fresh tracker (a failed test may have left a context open). */
static void track_reset(void)
{
	arena_used = track_live = track_live_bytes = track_calls = 0;
	track_bad = track_leaks = 0;
}

/* The C library's heap in use, or 0 where it cannot be told (ASan has
 * its own heap; other C libraries). */
static size_t libc_heap(void)
{
#if defined(__SANITIZE_ADDRESS__)
	return 0;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
	return 0;
#endif
#endif
#if defined(__GLIBC__) && (__GLIBC__ > 2 || (__GLIBC__ == 2 && __GLIBC_MINOR__ >= 33))
	struct mallinfo2 mi = mallinfo2();
	return mi.uordblks + mi.hblkhd;
#else
	return 0;
#endif
}

TEST(hooks_only)
{
	mlod_error e;
	/* 0: memory, 1: read callbacks (mlod_rt_open_path's FILE is the C
	 * library's, opened by fopen: the one allocation not the runtime's) */
	for (int source = 0; source < 2; source++) {
		track_reset();
		const size_t heap0 = libc_heap();
		mlod_rt_ctx *ctx = NULL;
		mlod_rt_config cfg = { 0, 16, &tracker };
		if (source == 0)
			CHECK_OK(mlod_rt_open_memory(pack.d, pack.n, &cfg, &ctx, &e), e);
		else
			CHECK_OK(mlod_rt_open_read(mem_read, &pack, pack.n, &cfg, &ctx, &e), e);
		CHECK(track_calls > 0, "source %d: the hooks were not called", source);
		CHECK(fx_load_all(ctx) == 0, "source %d: streaming every level failed", source);
		mlod_rt_stats st;
		mlod_rt_stats_get(ctx, &st);
		/* Every decoded level (and the skeleton) is in the hooks' blocks:
		 * they hold at least what the runtime counts as resident. */
		CHECK(st.resident_levels > 0 && track_live_bytes >= st.resident_bytes,
		      "source %d: %zu bytes live in the hooks, %zu resident: levels decoded elsewhere", source,
		      track_live_bytes, st.resident_bytes);
		mlod_rt_scratch *sc = mlod_rt_scratch_create(ctx);
		CHECK(sc, "source %d: scratch", source);
		uint32_t ids[4];
		for (int i = 0; i < 4; i++)
			CHECK_OK(mlod_rt_instance_create(ctx, (uint32_t)i % 2, 0.3f * (float)i, MLOD_RT_LOOP, &ids[i], &e), e);
		mlod_rt_select sel;
		mlod_rt_select_default(&sel);
		static float buf[2 * 3 * 4096];
		const uint32_t cap = mlod_rt_max_vertex_count(ctx);
		CHECK(cap <= 4096, "source %d: %u vertices", source, cap);
		for (int f = 0; f < 20; f++) {
			float d[4] = { 1.0f + f, 40.0f, 90.0f - f, 300.0f };
			CHECK_OK(mlod_rt_update(ctx, &sel, ids, d, 4, 0.05f, &e), e);
			CHECK_OK(mlod_rt_stream(ctx, SIZE_MAX, NULL, &e), e);
			for (int i = 0; i < 4; i++)
				CHECK_OK(mlod_rt_skin(ctx, sc, ids[i], buf, 12, buf + 3 * 4096, 12, cap, NULL, &e), e);
		}
		mlod_rt_scratch_destroy(ctx, sc);
		const size_t heap1 = libc_heap();
		mlod_rt_close(ctx);
		const size_t heap2 = libc_heap();
		CHECK(!track_bad, "source %d: the runtime freed %d blocks the hooks did not give", source, track_bad);
		CHECK(track_live == 0, "source %d: %zu blocks (%zu bytes) left at close", source, track_live,
		      track_live_bytes);
		CHECK(heap1 == heap0 && heap2 == heap0,
		      "source %d: the C library's heap went from %zu to %zu bytes (%zu after close): malloc called directly",
		      source, heap0, heap1, heap2);
		if (source == 0 && heap0 == 0)
			printf("# hooks_only: the C library's heap cannot be read here (ASan): that check is skipped\n");
	}
}

/* one_frame's findings over all its runs: finite skinned coordinates
 * outside mlod_rt_bounds' box and parents or stand-ins after their joint
 * (parents come first), and the names' bytes read (every name a string). */
static size_t bound_misses, name_bytes;

/* Open plus one frame: everything wanted streamed, every instance
 * bounded (mlod_rt_bounds), posed and skinned, every name and joint
 * level read, under the tracking allocator (nothing left, nothing
 * foreign freed, checked by the callers through track_leaks). */
static int one_frame(const void *data, size_t size, int through_read)
{
	mlod_error e;
	mlod_rt_ctx *ctx = NULL;
	mlod_rt_config cfg = { 0, 8, &tracker };
	bytes view = { (uint8_t *)data, size, size };
	mlod_result r = through_read ? mlod_rt_open_read(mem_read, &view, size, &cfg, &ctx, &e)
	                             : mlod_rt_open_memory(data, size, &cfg, &ctx, &e);
	if (r != MLOD_OK) {
		if (track_live || track_bad)
			track_leaks++;
		track_bad = 0;
		return 0;
	}
	mlod_rt_scratch *s = mlod_rt_scratch_create(ctx);
	uint32_t ids[4];
	float d[4] = { 0, 30, 90, 500 };
	int n = 0;
	for (int i = 0; i < 4; i++)
		if (mlod_rt_instance_create(ctx, mlod_rt_clip_count(ctx) ? (uint32_t)i % mlod_rt_clip_count(ctx) : 0,
		                            0.4f * (float)i, MLOD_RT_LOOP, &ids[n], &e) == MLOD_OK)
			n++;
	/* sized at open, before any level streams in (format 8.1: INFO's
	 * max_vertex_count) */
	const uint32_t cap = mlod_rt_max_vertex_count(ctx);
	float *buf = malloc(24 * (size_t)cap + 24);
	mlod_rt_select sel;
	mlod_rt_select_default(&sel);
	mlod_rt_update(ctx, &sel, ids, d, (size_t)n, 0.1f, &e);
	mlod_rt_stream(ctx, SIZE_MAX, NULL, &e);
	for (int i = 0; i < n && s && buf; i++) {
		uint32_t nv = 0;
		const float *P;
		float mn[3], mx[3];
		const mlod_result rb = mlod_rt_bounds(ctx, s, ids[i], mn, mx, &e);
		if (mlod_rt_skin(ctx, s, ids[i], buf, 12, buf + 3 * (size_t)cap, 12, cap, &nv, &e) == MLOD_OK &&
		    rb == MLOD_OK)
			for (uint32_t v = 0; v < 3 * nv; v++) /* a finite vertex outside its box */
				bound_misses += isfinite(buf[v]) && !(buf[v] >= mn[v % 3] && buf[v] <= mx[v % 3]);
		mlod_rt_palette(ctx, s, &P, NULL, &e);
	}
	/* the names, the hierarchy and the skeleton levels' joints */
	mlod_rt_character ch;
	if (mlod_rt_character_get(ctx, &ch, &e) == MLOD_OK)
		name_bytes += strlen(ch.name);
	for (uint32_t k = 0; k < mlod_rt_clip_count(ctx); k++)
		name_bytes += strlen(mlod_rt_clip_name(ctx, k));
	for (uint32_t j = 0; j < mlod_rt_joint_count(ctx); j++) {
		name_bytes += strlen(mlod_rt_joint_name(ctx, j));
		bound_misses += mlod_rt_joint_parent(ctx, j) >= (int32_t)j;
		mlod_rt_joint_level jl;
		for (uint32_t l = 0; l < mlod_rt_level_count(ctx, MLOD_RT_SKELETON); l++)
			if (mlod_rt_joint_level_get(ctx, l, j, &jl, &e) == MLOD_OK)
				bound_misses += jl.stand_in > j || jl.parent >= (int32_t)j;
	}
	free(buf);
	mlod_rt_scratch_destroy(ctx, s);
	mlod_rt_close(ctx);
	if (track_live || track_bad)
		track_leaks++;
	track_bad = 0;
	return 1;
}

TEST(truncated_prefixes)
{
	track_reset();
	int opened = 0;
	for (size_t k = 0; k < pack.n; k++) {
		opened += one_frame(pack.d, k, 0);
		opened += one_frame(pack.d, k, 1);
	}
	CHECK(opened == 0, "%d truncated packs opened", opened);
	CHECK(track_live == 0 && track_leaks == 0 && !track_bad, "%zu blocks left or foreign frees after a failed open",
	      track_live);
	CHECK(one_frame(pack.d, pack.n, 0) && one_frame(pack.d, pack.n, 1), "the whole pack does not open");
}

TEST(mutations)
{
	track_reset();
	bound_misses = name_bytes = 0;
	uint8_t *m = malloc(pack.n);
	unsigned seed = 99;
	int opened = 0;
	for (int i = 0; i < 10000; i++) {
		memcpy(m, pack.d, pack.n);
		seed = seed * 1103515245u + 12345u;
		int flips = 1 + (int)((seed >> 16) % 4);
		for (int f = 0; f < flips; f++) {
			seed = seed * 1103515245u + 12345u;
			size_t at = (seed >> 8) % pack.n;
			seed = seed * 1103515245u + 12345u;
			switch ((seed >> 12) % 3) {
			case 0: m[at] ^= (uint8_t)(1u << ((seed >> 20) % 8)); break;
			case 1: m[at] = (uint8_t)(seed >> 24); break;
			default: m[at] = (seed >> 24) & 1 ? 0xff : 0; break;
			}
		}
		if (i % 2)
			fix_crcs(m, pack.n);
		opened += one_frame(m, pack.n, i % 4 == 1);
	}
	free(m);
	printf("# mutations: %d of 10000 opened and ran a frame; %zu bytes of names read, %zu vertices outside "
	       "their bound or joints out of order\n",
	       opened, name_bytes, bound_misses);
	CHECK(bound_misses == 0, "%zu finite vertices outside mlod_rt_bounds' box, or joints out of order", bound_misses);
	CHECK(track_live == 0 && track_leaks == 0 && !track_bad,
	      "%d runs left blocks or freed foreign ones (%zu live now)", track_leaks, track_live);
	CHECK(opened > 0, "no mutated pack opened: the CRC-fixed half should reach the decoders");
}

/* A read source loads a MESH level by reading its chunk and every coarser
 * MESH chunk again through the callback (layout b2: the level's indices
 * refer to the coarser levels' vertex blocks), one after the other, and
 * keeps nothing of them; with a budget, through the callback too, the
 * resident bytes never pass it. */
TEST(read_source_rereads_coarser_mesh)
{
	mlod_error e;
	mlod_rt_ctx *ctx = NULL;
	CHECK_OK(mlod_rt_open_read(mem_read, &pack, pack.n, NULL, &ctx, &e), e);
	CHECK_OK(mlod_rt_request(ctx, MLOD_RT_MESH, 0, 0, &e), e);
	int before = reads;
	uint32_t loaded = 0;
	CHECK_OK(mlod_rt_stream(ctx, SIZE_MAX, &loaded, &e), e);
	CHECK(loaded == 1 && reads - before == 3, "%u loads, %d reads (MESH levels 2, 1 and 0 expected)", loaded,
	      reads - before);
	CHECK(mlod_rt_mesh_vertex_count(ctx, 0) == 7 && mlod_rt_mesh_part_count(ctx, 0) == 3,
	      "level 0: %u vertices, %u parts", mlod_rt_mesh_vertex_count(ctx, 0), mlod_rt_mesh_part_count(ctx, 0));
	mlod_rt_close(ctx);
	mlod_rt_stats s;
	CHECK_OK(mlod_rt_open_read(mem_read, &pack, pack.n, NULL, &ctx, &e), e);
	mlod_rt_stats_get(ctx, &s);
	const size_t at_open = s.resident_bytes; /* the coarse levels and the staging buffer */
	mlod_rt_close(ctx);
	for (size_t extra = 0; extra <= 8000; extra += 1000) {
		mlod_rt_config cfg = { at_open + extra, 16, NULL };
		CHECK_OK(mlod_rt_open_read(mem_read, &pack, pack.n, &cfg, &ctx, &e), e);
		mlod_rt_select sel;
		mlod_rt_select_default(&sel);
		uint32_t ids[4];
		float d[4];
		for (int i = 0; i < 4; i++)
			CHECK_OK(mlod_rt_instance_create(ctx, (uint32_t)i % 2, 0, MLOD_RT_LOOP, &ids[i], &e), e);
		for (int f = 0; f < 30; f++) {
			for (int i = 0; i < 4; i++)
				d[i] = (float)((i * 37 + f * 11) % 200);
			CHECK_OK(mlod_rt_update(ctx, &sel, ids, d, 4, 0.05f, &e), e);
			CHECK_OK(mlod_rt_stream(ctx, 4096, NULL, &e), e);
			mlod_rt_stats_get(ctx, &s);
			CHECK(s.peak_resident_bytes <= at_open + extra, "budget %zu: peak %zu", at_open + extra,
			      s.peak_resident_bytes);
			for (int i = 0; i < 4; i++) /* always some level to show */
				CHECK(mlod_rt_instance_state(ctx, ids[i])->level[MLOD_RT_MESH] < 3, "instance %d has no mesh level", i);
		}
		mlod_rt_close(ctx);
	}
}

TEST(pack_budget)
{
	mlod_error e;
	mlod_rt_ctx *ctx = NULL;
	CHECK_OK(mlod_rt_open_memory(pack.d, pack.n, NULL, &ctx, &e), e);
	mlod_rt_stats s;
	mlod_rt_stats_get(ctx, &s);
	const size_t coarse = s.resident_bytes;
	mlod_rt_close(ctx);
	for (size_t extra = 0; extra <= 20000; extra += 500) {
		mlod_rt_config cfg = { coarse + extra, 16, NULL };
		CHECK_OK(mlod_rt_open_memory(pack.d, pack.n, &cfg, &ctx, &e), e);
		mlod_rt_select sel;
		mlod_rt_select_default(&sel);
		uint32_t ids[8];
		float d[8];
		for (int i = 0; i < 8; i++)
			CHECK_OK(mlod_rt_instance_create(ctx, (uint32_t)i % 2, 0, MLOD_RT_LOOP, &ids[i], &e), e);
		for (int f = 0; f < 50; f++) {
			for (int i = 0; i < 8; i++)
				d[i] = (float)((i * 31 + f * 7) % 200);
			CHECK_OK(mlod_rt_update(ctx, &sel, ids, d, 8, 0.05f, &e), e);
			CHECK_OK(mlod_rt_stream(ctx, 4096, NULL, &e), e);
			mlod_rt_stats_get(ctx, &s);
			CHECK(s.peak_resident_bytes <= coarse + extra, "budget %zu: peak %zu", coarse + extra,
			      s.peak_resident_bytes);
		}
		mlod_rt_close(ctx);
	}
}

int main(void)
{
	fx_build(0);
	/* the pack's clip durations are their coarsest level's largest key time */
	for (int l = 0; l < 3; l++)
		fx_mo[0][l].duration = 1;
	build_pack(&pack);
	printf("# pack of %zu bytes, %d chunks\n", pack.n, nchunks);
	RUN(pack_equals_views);
	RUN(pack_poses_as_its_decoded_views);
	RUN(read_source_rereads_coarser_mesh);
	RUN(pack_budget);
	RUN(hooks_only);
	RUN(truncated_prefixes);
	RUN(mutations);
	free(pack.d);
	zstd_pack = 1;
	build_pack(&pack);
	printf("# with the zstd entropy stage: %zu bytes\n", pack.n);
	RUN(pack_equals_views);
	RUN(pack_poses_as_its_decoded_views);
	RUN(read_source_rereads_coarser_mesh);
	RUN(pack_budget);
	RUN(hooks_only);
	RUN(truncated_prefixes);
	RUN(mutations);
	free(pack.d);
	zstd_pack = 2;
	build_pack(&pack);
	printf("# with the zstd prefix stage (format 6.0): %zu bytes\n", pack.n);
	RUN(pack_equals_views);
	RUN(pack_poses_as_its_decoded_views);
	RUN(read_source_rereads_coarser_mesh);
	RUN(pack_budget);
	RUN(hooks_only);
	RUN(truncated_prefixes);
	RUN(mutations);
	free(pack.d);
	TEST_EXIT();
}
