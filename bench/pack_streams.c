/* bench/pack_streams.c: per chunk of a .mlod pack, its stored and raw
 * bytes, then the stored bytes per stream tag (summed over the chunk's
 * streams of that tag) and per tag over the whole file. A debugging aid
 * for the pack's size: reads the container directly, no decoding.
 * With -z, instead: per chunk type, what a general-purpose entropy stage
 * over each chunk's stream container (as stored, with its chunk codec;
 * a chunk kept as it is where the stage would not make it smaller) would
 * store, for zstd and deflate at a few levels, a zstd dictionary trained on
 * the pack's own chunks, and each one's decode speed (best of 7 CPU times
 * of decoding every chunk, MB/s of the container bytes it gives back).
 *
 * With -d: the CPU time of decoding every chunk through the reader
 * (lib/rt/pack.c: INFO, SKELETON, every skeleton, mesh and motion level
 * and DOC, as mlod-pack --info does), best of 15, and the stored and
 * decoded bytes per millisecond.
 *
 * With -m: per MESH level, its codec, stored bytes (with the coarser
 * levels it reads: layout b2 reads every coarser MESH chunk, a Draco level
 * only its own), the CPU time of mlod_pack_decode_mesh (best of 15) and
 * the decoded level's bytes (its float attributes and u32 indices, as the
 * reader hands them over) per second.
 *
 *   build/release/bench/pack_streams FILE.mlod [-v | -z | -d | -m]
 */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <zdict.h>
#include <zlib.h>
#include <zstd.h>

#include "rt/mlod_pack.h"

#define MAXTAGS 64
typedef struct { uint32_t tag; unsigned long long stored, raw, n; } tagsum;

static uint32_t rd32(const uint8_t *p) { return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24; }

static void add(tagsum *t, int *nt, uint32_t tag, unsigned long long stored, unsigned long long raw)
{
	for (int i = 0; i < *nt; i++)
		if (t[i].tag == tag) {
			t[i].stored += stored, t[i].raw += raw, t[i].n++;
			return;
		}
	if (*nt < MAXTAGS)
		t[(*nt)++] = (tagsum){tag, stored, raw, 1};
}

static void print(const tagsum *t, int nt, const char *indent)
{
	for (int i = 0; i < nt; i++)
		printf("%s%.4s %8llu stored %8llu raw (%llu streams)\n", indent, (const char *)&t[i].tag, t[i].stored,
		       t[i].raw, t[i].n);
}

/* The chunk's stream container: its bytes, or with an entropy stage
 * those bytes decoded (malloc'd into *own). Callers go through the
 * chunks in TOC order from chunk 0: the MESH levels' containers are kept
 * as the prefix of the finer ones, SKELETON's as the skeleton levels'
 * (format 6.0, MLOD_ENTROPY_ZSTD_PREFIX). */
static const uint8_t *container(const mlod_pack_chunk *ch, const uint8_t *d, size_t *n, uint8_t **own)
{
	static uint8_t *meshes, *skel0;
	static size_t nmeshes, capmeshes, nskel0;
	static const mlod_pack_chunk *last;
	if (!last || ch <= last)
		nmeshes = 0; /* a new pass */
	last = ch;
	*own = NULL;
	*n = ch->stored_size;
	const uint8_t *out = d + ch->offset;
	if (ch->entropy != MLOD_ENTROPY_NONE) {
		*own = malloc(ch->coded_size + 1);
		ZSTD_DCtx *dc = ZSTD_createDCtx();
		if (ch->entropy == MLOD_ENTROPY_ZSTD_PREFIX && ch->type == MLOD_CHUNK_SKELETON)
			ZSTD_DCtx_refPrefix(dc, skel0, nskel0);
		else if (ch->entropy == MLOD_ENTROPY_ZSTD_PREFIX)
			ZSTD_DCtx_refPrefix(dc, meshes, nmeshes);
		size_t got = *own ? ZSTD_decompressDCtx(dc, *own, ch->coded_size, d + ch->offset, ch->stored_size) : 0;
		ZSTD_freeDCtx(dc);
		if (ZSTD_isError(got) || got != ch->coded_size) {
			fprintf(stderr, "pack_streams: a chunk's zstd frame does not decode\n");
			exit(1);
		}
		*n = got;
		out = *own;
	}
	if (ch->type == MLOD_CHUNK_SKELETON && ch->level == 0) {
		free(skel0);
		skel0 = malloc(*n + 1);
		memcpy(skel0, out, *n);
		nskel0 = *n;
	}
	if (ch->type == MLOD_CHUNK_MESH) {
		if (nmeshes + *n > capmeshes) {
			capmeshes = 2 * (nmeshes + *n);
			meshes = realloc(meshes, capmeshes);
		}
		memcpy(meshes + nmeshes, out, *n);
		nmeshes += *n;
	}
	return out;
}

static double cpu_now(void)
{
	struct timespec t;
	clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
	return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* The container of a chunk as stored, before any entropy stage: the chunk
 * itself for a pack whose chunks have none. */
typedef struct blob { const uint8_t *p; size_t n; uint32_t type; } blob;

enum { M_ZSTD, M_DEFLATE, M_ZSTD_DICT };
typedef struct method { int kind, level; size_t dict; const char *name; } method;

/* Compresses b with m into out (capacity cap); returns the size, 0 on failure. */
static size_t enc(const method *m, const blob *b, uint8_t *out, size_t cap, const ZSTD_CDict *cd)
{
	if (m->kind == M_DEFLATE) {
		uLongf n = cap;
		return compress2(out, &n, b->p, b->n, m->level) == Z_OK ? n : 0;
	}
	ZSTD_CCtx *c = ZSTD_createCCtx();
	size_t n = cd ? ZSTD_compress_usingCDict(c, out, cap, b->p, b->n, cd)
	              : ZSTD_compressCCtx(c, out, cap, b->p, b->n, m->level);
	ZSTD_freeCCtx(c);
	return ZSTD_isError(n) ? 0 : n;
}

static int entropy_table(const mlod_pack *p, const uint8_t *d)
{
	uint32_t nc = p->chunk_count;
	blob *bl = calloc(nc, sizeof *bl);
	size_t maxn = 0, total_n = 0;
	uint8_t **own = calloc(nc, sizeof *own);
	for (uint32_t c = 0; c < nc; c++) {
		size_t cn;
		const uint8_t *cp = container(&p->chunks[c], d, &cn, &own[c]);
		bl[c] = (blob){cp, cn, p->chunks[c].type};
		maxn = bl[c].n > maxn ? bl[c].n : maxn;
		total_n += bl[c].n;
	}
	static const uint32_t types[] = {MLOD_CHUNK_INFO, MLOD_CHUNK_SKELETON, MLOD_CHUNK_MESH, MLOD_CHUNK_MOTION,
	                                 MLOD_CHUNK_DOC};
	static const method ms[] = {
		{M_ZSTD, 1, 0, "zstd 1"},       {M_ZSTD, 3, 0, "zstd 3"},       {M_ZSTD, 9, 0, "zstd 9"},
		{M_ZSTD, 19, 0, "zstd 19"},     {M_ZSTD, 22, 0, "zstd 22"},     {M_DEFLATE, 1, 0, "deflate 1"},
		{M_DEFLATE, 6, 0, "deflate 6"}, {M_DEFLATE, 9, 0, "deflate 9"}, {M_ZSTD_DICT, 19, 2048, "zstd 19 + dict 2K"},
		{M_ZSTD_DICT, 19, 8192, "zstd 19 + dict 8K"},
	};
	size_t cap = ZSTD_compressBound(maxn) + compressBound(maxn) + 64;
	uint8_t *out = malloc(cap), *back = malloc(maxn + 1);
	size_t *csz = calloc(nc, sizeof *csz);
	uint8_t **cbuf = calloc(nc, sizeof *cbuf);
	printf("| method | INFO | SKEL | MESH | ANIM | DOC | whole | dict | decode MB/s |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|\n");
	unsigned long long none[5] = {0};
	for (uint32_t c = 0; c < nc; c++)
		for (int t = 0; t < 5; t++)
			if (bl[c].type == types[t])
				none[t] += bl[c].n;
	printf("| as stored |");
	for (int t = 0; t < 5; t++)
		printf(" %llu |", none[t]);
	unsigned long long as_stored = p->file_size; /* without any entropy stage */
	for (uint32_t c = 0; c < nc; c++)
		as_stored += bl[c].n - p->chunks[c].stored_size;
	printf(" %llu | | |\n", as_stored);
	for (size_t mi = 0; mi < sizeof ms / sizeof ms[0]; mi++) {
		const method *m = &ms[mi];
		ZSTD_CDict *cd = NULL;
		ZSTD_DDict *dd = NULL;
		size_t dsize = 0;
		uint8_t *dict = NULL;
		if (m->kind == M_ZSTD_DICT) {
			uint8_t *samples = malloc(total_n);
			size_t *lens = malloc(nc * sizeof *lens), o = 0;
			for (uint32_t c = 0; c < nc; c++)
				memcpy(samples + o, bl[c].p, bl[c].n), o += bl[c].n, lens[c] = bl[c].n;
			dict = malloc(m->dict);
			dsize = ZDICT_trainFromBuffer(dict, m->dict, samples, lens, nc);
			free(samples);
			free(lens);
			if (ZDICT_isError(dsize)) {
				printf("| %s | training failed: %s |\n", m->name, ZDICT_getErrorName(dsize));
				free(dict);
				continue;
			}
			cd = ZSTD_createCDict(dict, dsize, m->level);
			dd = ZSTD_createDDict(dict, dsize);
		}
		unsigned long long sum[5] = {0}, whole = as_stored, decoded = 0;
		for (uint32_t c = 0; c < nc; c++) {
			size_t n = enc(m, &bl[c], out, cap, cd);
			free(cbuf[c]);
			cbuf[c] = NULL;
			csz[c] = 0;
			if (n && n < bl[c].n) { /* kept only where smaller */
				cbuf[c] = malloc(n);
				memcpy(cbuf[c], out, n);
				csz[c] = n;
				whole -= bl[c].n - n; /* ignoring the 16-byte alignment, at most 15 bytes a chunk either way */
				decoded += bl[c].n;
			}
			for (int t = 0; t < 5; t++)
				if (bl[c].type == types[t])
					sum[t] += csz[c] ? csz[c] : bl[c].n;
		}
		whole += dsize;
		double best = 1e30;
		ZSTD_DCtx *dc = ZSTD_createDCtx();
		for (int rep = 0; rep < 7; rep++) {
			double t0 = cpu_now();
			for (uint32_t c = 0; c < nc; c++) {
				if (!csz[c])
					continue;
				size_t got;
				if (m->kind == M_DEFLATE) {
					uLongf n = bl[c].n;
					got = uncompress(back, &n, cbuf[c], csz[c]) == Z_OK ? n : 0;
				} else if (dd) {
					got = ZSTD_decompress_usingDDict(dc, back, bl[c].n, cbuf[c], csz[c], dd);
				} else {
					got = ZSTD_decompressDCtx(dc, back, bl[c].n, cbuf[c], csz[c]);
				}
				if (got != bl[c].n || memcmp(back, bl[c].p, got) != 0) {
					fprintf(stderr, "pack_streams: %s: chunk %u does not come back\n", m->name, c);
					return 1;
				}
			}
			double t = cpu_now() - t0;
			best = t < best ? t : best;
		}
		ZSTD_freeDCtx(dc);
		printf("| %s |", m->name);
		for (int t = 0; t < 5; t++)
			printf(" %llu |", sum[t]);
		printf(" %llu | %zu | %.0f |\n", whole, dsize, best > 0 ? decoded / best / 1e6 : 0.0);
		ZSTD_freeCDict(cd);
		ZSTD_freeDDict(dd);
		free(dict);
	}
	for (uint32_t c = 0; c < nc; c++)
		free(cbuf[c]), free(own[c]);
	free(own);
	free(cbuf);
	free(csz);
	free(out);
	free(back);
	free(bl);
	return 0;
}


/* -p: each chunk's container under zstd 19 alone, and with a prefix
 * dictionary (ZSTD_CCtx_refPrefix) of other chunks' containers, coarsest
 * first: "deps" the chunks it already depends on (a MESH level: every
 * coarser MESH level; a nested MOTION level: its clip's next coarser
 * level), "deps+skel" those after the SKELETON container (every chunk but
 * INFO and DOC already takes the decoded full skeleton), "all before" every
 * earlier chunk (a new dependency; the bound). Bytes per chunk type, and the
 * decode time of every chunk (best of 7). */
static size_t zc(ZSTD_CCtx *c, uint8_t *out, size_t cap, const blob *b, const uint8_t *pre, size_t npre)
{
	ZSTD_CCtx_reset(c, ZSTD_reset_session_and_parameters);
	ZSTD_CCtx_setParameter(c, ZSTD_c_compressionLevel, 19);
	ZSTD_CCtx_setParameter(c, ZSTD_c_contentSizeFlag, 1);
	if (npre)
		ZSTD_CCtx_refPrefix(c, pre, npre);
	size_t n = ZSTD_compress2(c, out, cap, b->p, b->n);
	return ZSTD_isError(n) ? 0 : n;
}

static int is_dep(const mlod_pack *p, uint32_t c, uint32_t o, int mode)
{
	const mlod_pack_chunk *a = &p->chunks[c], *b = &p->chunks[o];
	if (o >= c)
		return 0;
	if (mode == 3)
		return 1;
	if (mode == 2 && b->type == MLOD_CHUNK_SKELETON && b->level == 0 && a->type != MLOD_CHUNK_DOC)
		return 1;
	if (a->type == MLOD_CHUNK_MESH && b->type == MLOD_CHUNK_MESH && b->level > a->level)
		return 1;
	if (a->type == MLOD_CHUNK_MOTION && (a->flags & 1) && b->type == MLOD_CHUNK_MOTION && b->item == a->item &&
	    b->level == a->level + 1)
		return 1;
	return 0;
}

static int prefix_table(const mlod_pack *p, const uint8_t *d)
{
	uint32_t nc = p->chunk_count;
	blob *bl = calloc(nc, sizeof *bl);
	uint8_t **own = calloc(nc, sizeof *own);
	size_t maxn = 0, total = 0;
	for (uint32_t c = 0; c < nc; c++) {
		size_t cn;
		bl[c] = (blob){container(&p->chunks[c], d, &cn, &own[c]), 0, p->chunks[c].type};
		bl[c].n = cn;
		maxn = cn > maxn ? cn : maxn;
		total += cn;
	}
	static const uint32_t types[] = {MLOD_CHUNK_INFO, MLOD_CHUNK_SKELETON, MLOD_CHUNK_MESH, MLOD_CHUNK_MOTION,
	                                 MLOD_CHUNK_DOC};
	static const char *names[] = {"zstd 19 alone", "prefix: deps", "prefix: deps+skel", "prefix: all before"};
	size_t cap = ZSTD_compressBound(maxn) + 64;
	uint8_t *out = malloc(cap), *back = malloc(maxn + 1), *pre = malloc(total + 1);
	uint8_t **cbuf = calloc(nc, sizeof *cbuf);
	size_t *csz = calloc(nc, sizeof *csz), *poff = calloc(nc, sizeof *poff), *plen = calloc(nc, sizeof *plen);
	uint8_t **pbuf = calloc(nc, sizeof *pbuf);
	ZSTD_CCtx *cc = ZSTD_createCCtx();
	ZSTD_DCtx *dc = ZSTD_createDCtx();
	printf("| method | INFO | SKEL | MESH | ANIM | DOC | chunks | whole | decode ms |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|\n");
	for (int mode = 0; mode < 4; mode++) {
		unsigned long long sum[5] = {0}, whole = p->file_size;
		for (uint32_t c = 0; c < nc; c++) {
			size_t np = 0;
			if (mode)
				for (uint32_t o = 0; o < c; o++)
					if (is_dep(p, c, o, mode))
						memcpy(pre + np, bl[o].p, bl[o].n), np += bl[o].n;
			free(pbuf[c]);
			pbuf[c] = np ? malloc(np) : NULL;
			if (np)
				memcpy(pbuf[c], pre, np);
			plen[c] = np;
			(void)poff;
			size_t n = bl[c].type == MLOD_CHUNK_INFO ? 0 : zc(cc, out, cap, &bl[c], pre, np);
			free(cbuf[c]);
			cbuf[c] = NULL;
			csz[c] = 0;
			if (n && n < bl[c].n) {
				cbuf[c] = malloc(n), memcpy(cbuf[c], out, n), csz[c] = n;
			}
			size_t now = csz[c] ? csz[c] : bl[c].n;
			whole = whole - p->chunks[c].stored_size + now; /* alignment ignored */
			for (int t = 0; t < 5; t++)
				if (bl[c].type == types[t])
					sum[t] += now;
		}
		double best = 1e30;
		for (int rep = 0; rep < 7; rep++) {
			double t0 = cpu_now();
			for (uint32_t c = 0; c < nc; c++) {
				if (!csz[c])
					continue;
				ZSTD_DCtx_reset(dc, ZSTD_reset_session_only);
				if (plen[c])
					ZSTD_DCtx_refPrefix(dc, pbuf[c], plen[c]);
				size_t got = ZSTD_decompressDCtx(dc, back, bl[c].n, cbuf[c], csz[c]);
				if (got != bl[c].n || memcmp(back, bl[c].p, got) != 0) {
					fprintf(stderr, "pack_streams: %s: chunk %u does not come back\n", names[mode], c);
					return 1;
				}
			}
			double t = cpu_now() - t0;
			best = t < best ? t : best;
		}
		unsigned long long chunks = 0;
		for (int t = 0; t < 5; t++)
			chunks += sum[t];
		printf("| %s |", names[mode]);
		for (int t = 0; t < 5; t++)
			printf(" %llu |", sum[t]);
		printf(" %llu | %llu | %.3f |\n", chunks, whole, 1e3 * best);
	}
	ZSTD_freeCCtx(cc);
	ZSTD_freeDCtx(dc);
	for (uint32_t c = 0; c < nc; c++)
		free(cbuf[c]), free(own[c]), free(pbuf[c]);
	free(own), free(cbuf), free(csz), free(poff), free(plen), free(pbuf), free(out), free(back), free(pre), free(bl);
	return 0;
}


/* -g: each chunk's container (format 6.0's prefix stage left aside: every
 * chunk alone) under zstd 19 as stored; with its streams' bytes grouped
 * by tag (a stable sort: every part's POSQ, then every NRMQ, ...; the
 * headers first as stored); and each stream compressed on its own, kept
 * only where smaller (per-stream entropy choice; 4 bytes a stream counted
 * for a stored size). Bytes summed per chunk type. */
typedef struct sref { uint32_t tag, idx; const uint8_t *p; size_t n; } sref;
static int sref_cmp(const void *a, const void *b)
{
	const sref *x = a, *y = b;
	if (x->tag != y->tag)
		return x->tag < y->tag ? -1 : 1;
	return x->idx < y->idx ? -1 : x->idx > y->idx;
}

static int group_table(const mlod_pack *p, const uint8_t *d)
{
	static const uint32_t types[] = {MLOD_CHUNK_INFO, MLOD_CHUNK_SKELETON, MLOD_CHUNK_MESH, MLOD_CHUNK_MOTION,
	                                 MLOD_CHUNK_DOC};
	unsigned long long sum[3][5] = {{0}};
	for (uint32_t c = 0; c < p->chunk_count; c++) {
		const mlod_pack_chunk *ch = &p->chunks[c];
		size_t cn;
		uint8_t *own;
		const uint8_t *b = container(ch, d, &cn, &own);
		int t = 0;
		while (t < 5 && types[t] != ch->type)
			t++;
		if (t == 5 || ch->type == MLOD_CHUNK_INFO) {
			for (int k = 0; k < 3 && t < 5; k++)
				sum[k][t] += cn;
			free(own);
			continue;
		}
		uint32_t ns = rd32(b);
		sref *sr = calloc(ns + 1, sizeof *sr);
		size_t at = 4 + 16 * (size_t)ns;
		for (uint32_t s = 0; s < ns; s++) {
			const uint8_t *h = b + 4 + 16 * (size_t)s;
			size_t st = rd32(h + 12);
			sr[s] = (sref){rd32(h), s, b + at, st};
			at += (st + 3) & ~(size_t)3;
		}
		size_t cap = ZSTD_compressBound(cn) + 64;
		uint8_t *out = malloc(cap), *g = malloc(cn + 1);
		size_t n0 = ZSTD_compress(out, cap, b, cn, 19);
		sum[0][t] += n0 < cn ? n0 : cn;
		qsort(sr, ns, sizeof *sr, sref_cmp);
		size_t o = 4 + 16 * (size_t)ns;
		memcpy(g, b, o);
		for (uint32_t s = 0; s < ns; s++) {
			memcpy(g + o, sr[s].p, sr[s].n);
			o += sr[s].n;
		}
		size_t n1 = ZSTD_compress(out, cap, g, o, 19);
		sum[1][t] += n1 < o ? n1 : o;
		size_t n2 = 4 + 16 * (size_t)ns;
		for (uint32_t s = 0; s < ns; s++) {
			size_t z = sr[s].n ? ZSTD_compress(out, cap, sr[s].p, sr[s].n, 19) : 0;
			n2 += 4 + (z < sr[s].n ? z : sr[s].n);
		}
		sum[2][t] += n2 < cn ? n2 : cn;
		free(out), free(g), free(sr), free(own);
	}
	static const char *names[] = {"zstd 19 per chunk (alone)", "streams grouped by tag", "zstd 19 per stream"};
	printf("| method | INFO | SKEL | MESH | ANIM | DOC | chunks |\n|---|---:|---:|---:|---:|---:|---:|\n");
	for (int k = 0; k < 3; k++) {
		unsigned long long all = 0;
		printf("| %s |", names[k]);
		for (int t = 0; t < 5; t++)
			printf(" %llu |", sum[k][t]), all += sum[k][t];
		printf(" %llu |\n", all);
	}
	return 0;
}

/* Decodes every chunk once; 0 on success. */
static int decode_every_chunk(const mlod_pack *p, const uint8_t *d, size_t n)
{
	mlod_error e;
	mlod_pack_info info;
	mlod_pack_skeleton sk;
	if (mlod_pack_decode_info(p, d, n, &info, &e) != MLOD_OK || mlod_pack_decode_skeleton(p, d, n, &sk, &e) != MLOD_OK) {
		fprintf(stderr, "pack_streams: %s\n", e.message);
		return 1;
	}
	mlod_pack_info_free(&info);
	int rc = 0;
	for (uint32_t i = 0; i < p->chunk_count && !rc; i++) {
		const mlod_pack_chunk *c = &p->chunks[i];
		mlod_result r = MLOD_OK;
		if (c->type == MLOD_CHUNK_SKELETON && c->level > 0) {
			mlod_pack_skel_level x;
			r = mlod_pack_decode_skel_level(p, i, d, n, &sk, &x, &e);
			mlod_pack_skel_level_free(&x);
		} else if (c->type == MLOD_CHUNK_MESH) {
			mlod_pack_mesh x;
			r = mlod_pack_decode_mesh(p, i, d, n, &sk, &x, &e);
			mlod_pack_mesh_free(&x);
		} else if (c->type == MLOD_CHUNK_MOTION) {
			mlod_pack_motion x;
			r = mlod_pack_decode_motion(p, i, d, n, &sk, &x, &e);
			mlod_pack_motion_free(&x);
		} else if (c->type == MLOD_CHUNK_DOC) {
			mlod_pack_doc_bytes x;
			r = mlod_pack_decode_doc(p, d, n, &x, &e);
			mlod_pack_doc_free(&x);
		}
		if (r != MLOD_OK) {
			fprintf(stderr, "pack_streams: %s\n", e.message);
			rc = 1;
		}
	}
	mlod_pack_skeleton_free(&sk);
	return rc;
}

/* The bytes of a decoded level: attributes as floats (joints u16), indices u32. */
static unsigned long long mesh_bytes(const mlod_pack_mesh *m)
{
	unsigned long long b = 0;
	for (uint32_t i = 0; i < m->part_count; i++) {
		const mlod_pack_part *pt = &m->parts[i];
		unsigned long long V = pt->rec.vertex_count;
		b += V * 12 + (pt->normals ? V * 12 : 0) + (pt->tangents ? V * 16 : 0) + pt->rec.uv_sets * V * 8 +
		     (pt->colors ? V * 16 : 0) + (pt->joints ? V * 8 + V * 16 : 0) + pt->rec.target_count * V * 12 +
		     4ull * pt->rec.index_count;
	}
	return b;
}

static int mesh_table(const mlod_pack *p, const uint8_t *d, size_t n)
{
	mlod_error e;
	mlod_pack_skeleton sk = {0};
	int has_skel = mlod_pack_find(p, MLOD_CHUNK_SKELETON, 0, 0) >= 0;
	if (has_skel && mlod_pack_decode_skeleton(p, d, n, &sk, &e) != MLOD_OK)
		return fprintf(stderr, "pack_streams: %s\n", e.message), 1;
	printf("| MESH level | codec | stored bytes read | decoded bytes | decode ms (best of 15) | MB/s decoded | MB/s "
	       "stored |\n|---:|---|---:|---:|---:|---:|---:|\n");
	int rc = 0;
	for (uint32_t i = 0; i < p->chunk_count && !rc; i++) {
		const mlod_pack_chunk *c = &p->chunks[i];
		if (c->type != MLOD_CHUNK_MESH)
			continue;
		unsigned long long stored = c->stored_size, out = 0;
		for (uint32_t j = 0; j < p->chunk_count && c->codec != MLOD_CODEC_DRACO; j++)
			if (p->chunks[j].type == MLOD_CHUNK_MESH && p->chunks[j].level > c->level)
				stored += p->chunks[j].stored_size;
		double best = 1e30;
		for (int rep = 0; rep < 15 && !rc; rep++) {
			mlod_pack_mesh x;
			double t0 = cpu_now();
			if (mlod_pack_decode_mesh(p, i, d, n, has_skel ? &sk : NULL, &x, &e) != MLOD_OK) {
				fprintf(stderr, "pack_streams: %s\n", e.message);
				rc = 1;
				break;
			}
			double t = cpu_now() - t0;
			best = t < best ? t : best;
			out = mesh_bytes(&x);
			mlod_pack_mesh_free(&x);
		}
		if (!rc)
			printf("| %u | %s%s%s | %llu | %llu | %.3f | %.0f | %.1f |\n", c->level, mlod_pack_codec_name(c->codec),
			       c->entropy ? "+" : "", c->entropy ? mlod_pack_entropy_name(c->entropy) : "", stored, out,
			       1e3 * best, out / best / 1e6, stored / best / 1e6);
	}
	mlod_pack_skeleton_free(&sk);
	return rc;
}

int main(int argc, char **argv)
{
	if (argc < 2) {
		fprintf(stderr, "usage: pack_streams FILE.mlod [-v | -z]\n");
		return 1;
	}
	int verbose = argc > 2 && strcmp(argv[2], "-v") == 0;
	int entropy = argc > 2 && strcmp(argv[2], "-z") == 0;
	int decode = argc > 2 && strcmp(argv[2], "-d") == 0;
	int prefix = argc > 2 && strcmp(argv[2], "-p") == 0;
	int group = argc > 2 && strcmp(argv[2], "-g") == 0;
	int meshes = argc > 2 && strcmp(argv[2], "-m") == 0;
	FILE *f = fopen(argv[1], "rb");
	if (!f)
		return perror(argv[1]), 1;
	fseek(f, 0, SEEK_END);
	long n = ftell(f);
	fseek(f, 0, SEEK_SET);
	uint8_t *d = malloc((size_t)n + 1);
	if (!d || fread(d, 1, (size_t)n, f) != (size_t)n)
		return fprintf(stderr, "read failed\n"), 1;
	fclose(f);
	mlod_pack p;
	mlod_error e = {0};
	if (mlod_pack_open(d, (size_t)n, &p, &e) != MLOD_OK)
		return fprintf(stderr, "%s\n", e.message), 1;
	if (decode) {
		double best = 1e30;
		int rc = 0;
		for (int rep = 0; rep < 15 && !rc; rep++) {
			double t0 = cpu_now();
			rc = decode_every_chunk(&p, d, (size_t)n);
			double t = cpu_now() - t0;
			best = t < best ? t : best;
		}
		unsigned long long stored = 0, raw = 0;
		for (uint32_t c = 0; c < p.chunk_count; c++)
			stored += p.chunks[c].stored_size, raw += p.chunks[c].raw_size;
		if (!rc)
			printf("%s: every chunk decoded in %.3f ms CPU (best of 15): %llu stored bytes (%.1f MB/s), %llu raw "
			       "(%.1f MB/s)\n",
			       argv[1], 1e3 * best, stored, stored / best / 1e6, raw, raw / best / 1e6);
		mlod_pack_close(&p);
		free(d);
		return rc;
	}
	if (meshes) {
		int rc = mesh_table(&p, d, (size_t)n);
		mlod_pack_close(&p);
		free(d);
		return rc;
	}
	if (group) {
		int rc = group_table(&p, d);
		mlod_pack_close(&p);
		free(d);
		return rc;
	}
	if (prefix) {
		int rc = prefix_table(&p, d);
		mlod_pack_close(&p);
		free(d);
		return rc;
	}
	if (entropy) {
		int rc = entropy_table(&p, d);
		mlod_pack_close(&p);
		free(d);
		return rc;
	}
	tagsum all[MAXTAGS];
	int nall = 0;
	for (uint32_t c = 0; c < p.chunk_count; c++) {
		const mlod_pack_chunk *ch = &p.chunks[c];
		size_t cn;
		uint8_t *own;
		const uint8_t *b = container(ch, d, &cn, &own);
		uint32_t ns = rd32(b);
		printf("%-4s %-8s level %u item %u: %u stored (%zu before %s), %u raw, %u streams\n",
		       mlod_pack_type_name(ch->type), mlod_pack_layer_name(ch->layer), ch->level, ch->item, ch->stored_size, cn,
		       mlod_pack_entropy_name(ch->entropy), ch->raw_size, ns);
		tagsum t[MAXTAGS];
		int nt = 0;
		for (uint32_t s = 0; s < ns; s++) {
			const uint8_t *h = b + 4 + 16 * (size_t)s;
			unsigned long long raw = (unsigned long long)rd32(h + 4) * (h[8] | h[9] << 8);
			add(t, &nt, rd32(h), rd32(h + 12), raw);
			add(all, &nall, rd32(h), rd32(h + 12), raw);
		}
		if (verbose)
			print(t, nt, "    ");
		free(own);
	}
	printf("per tag, whole file:\n");
	print(all, nall, "    ");
	mlod_pack_close(&p);
	free(d);
	return 0;
}
