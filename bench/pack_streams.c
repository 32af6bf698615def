/* bench/pack_streams.c: per chunk of a .mlod pack, its stored and raw
 * bytes, then the stored bytes per stream tag (summed over the chunk's
 * streams of that tag) and per tag over the whole file. A debugging aid
 * for the pack's size: reads the container directly, no decoding.
 *
 *   build/release/bench/pack_streams FILE.mlod [-v]
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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

int main(int argc, char **argv)
{
	if (argc < 2) {
		fprintf(stderr, "usage: pack_streams FILE.mlod [-v]\n");
		return 1;
	}
	int verbose = argc > 2 && strcmp(argv[2], "-v") == 0;
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
	tagsum all[MAXTAGS];
	int nall = 0;
	for (uint32_t c = 0; c < p.chunk_count; c++) {
		const mlod_pack_chunk *ch = &p.chunks[c];
		const uint8_t *b = d + ch->offset;
		uint32_t ns = rd32(b);
		printf("%-4s %-8s level %u item %u: %u stored, %u raw, %u streams\n", mlod_pack_type_name(ch->type),
		       mlod_pack_layer_name(ch->layer), ch->level, ch->item, ch->stored_size, ch->raw_size, ns);
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
	}
	printf("per tag, whole file:\n");
	print(all, nall, "    ");
	mlod_pack_close(&p);
	free(d);
	return 0;
}
