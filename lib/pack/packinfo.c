/*
 * packinfo.c: what mlod-pack --info and the option parser need beyond the
 * reader (mlod_pack_write.h): the layers' totals of a pack's TOC, a
 * chunk's codec column, and the codec and entropy names as options.
 */
#include <stdio.h>
#include <string.h>

#include "pack/mlod_pack_write.h"

void mlod_pack_totals_sum(const mlod_pack *p, mlod_pack_totals *t)
{
	memset(t, 0, sizeof *t);
	for (uint32_t i = 0; i < p->chunk_count; i++) {
		unsigned l = p->chunks[i].layer < 4 ? p->chunks[i].layer : 0;
		t->stored[l] += p->chunks[i].stored_size;
		t->raw[l] += p->chunks[i].raw_size;
		t->chunks[l]++;
	}
	for (unsigned l = 0; l < 4; l++) {
		t->all_stored += t->stored[l];
		t->all_raw += t->raw[l];
	}
	t->overhead = p->file_size - t->all_stored;
}

const char *mlod_pack_codec_label(const mlod_pack_chunk *c, char *buf, size_t n)
{
	if (c->entropy == MLOD_ENTROPY_NONE)
		snprintf(buf, n, "%s", mlod_pack_codec_name(c->codec));
	else
		snprintf(buf, n, "%s+%s", mlod_pack_codec_name(c->codec), mlod_pack_entropy_name(c->entropy));
	return buf;
}

int mlod_pack_codec_parse(const char *name, mlod_pack_options *opt)
{
	static const struct { const char *name; mlod_pack_codec codec; } codecs[] = {
		{"meshopt", MLOD_CODEC_MESHOPT}, {"none", MLOD_CODEC_NONE}, {"draco", MLOD_CODEC_DRACO}};
	for (size_t i = 0; i < sizeof codecs / sizeof *codecs; i++)
		if (strcmp(name, codecs[i].name) == 0) {
			opt->codec = codecs[i].codec;
			return 0;
		}
	return -1;
}

int mlod_pack_entropy_parse(const char *name, mlod_pack_options *opt)
{
	if (strcmp(name, "zstd") == 0)
		opt->entropy = MLOD_ENTROPY_ZSTD;
	else if (strcmp(name, "none") == 0)
		opt->entropy = MLOD_ENTROPY_NONE;
	else
		return -1;
	return 0;
}
