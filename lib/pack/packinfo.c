/*
 * packinfo.c: what mlod-pack --info, --report and the option parser need
 * beyond the reader (mlod_pack_write.h): the layers' totals of a pack's
 * TOC, a chunk's codec column, the codec and entropy names as options,
 * and the text of --info and --report (table or JSON).
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

/* ------------------------------------------------------------------ */
/* --report                                                            */
/* ------------------------------------------------------------------ */

/* The report's source column: a layer's levels from the input, or computed. */
static const char *source(const mlod_pack_layer_stats *l)
{
	return l->levels <= 1 ? "-" : l->from_input ? "input" : "computed";
}

static void report_table(FILE *rf, const char *input, const mlod_pack_stats *st, const char *codec)
{
	fputs("# ", rf);
	mlod_name_put(rf, input, 0, 0);
	fprintf(rf, ": %d joints, %d skins, %d parts, %d clips; height %.4g, diagonal %.4g; codec %s\n", st->joints,
	        st->skins, st->parts, st->clips, st->height, st->diagonal, codec);
	fprintf(rf, "%-9s %6s  %-8s  %10s  %10s  %9s  %s\n", "layer", "levels", "source", "stored", "raw", "ms",
	        "error per level (scene units)");
	const mlod_pack_layer_stats *ls[3] = {&st->skeleton, &st->mesh, &st->motion};
	const char *names[3] = {"skeleton", "mesh", "motion"};
	for (int i = 0; i < 3; i++) {
		fprintf(rf, "%-9s %6d  %-8s  %10llu  %10llu  %9.1f ", names[i], ls[i]->levels, source(ls[i]),
		        (unsigned long long)ls[i]->stored, (unsigned long long)ls[i]->raw, 1e3 * ls[i]->seconds);
		for (int k = 1; k < ls[i]->levels; k++)
			fprintf(rf, " %.4g", ls[i]->errors[k]);
		if (ls[i]->levels > 0 && ls[i]->errors[0] > 0)
			fprintf(rf, " (level 0: %.4g)", ls[i]->errors[0]);
		fputc('\n', rf);
	}
	fprintf(rf, "# total %llu bytes in %u chunks (info %llu, doc %llu); first drawable level: %u bytes\n",
	        (unsigned long long)st->total, st->chunks, (unsigned long long)st->info_bytes,
	        (unsigned long long)st->doc_bytes, st->first_drawable);
	if (st->notes[0]) {
		fputs("# note: ", rf);
		mlod_name_put(rf, st->notes, 0, 0);
		fputc('\n', rf);
	}
}

static void report_json(FILE *rf, const char *input, const mlod_pack_stats *st, const char *codec)
{
	fprintf(rf, "{\n  \"input\": ");
	mlod_name_put(rf, input, 1, 0);
	fprintf(rf, ",\n  \"codec\": \"%s\",\n  \"joints\": %d,\n  \"skins\": %d,\n  \"parts\": %d,\n  \"clips\": %d,\n",
	        codec, st->joints, st->skins, st->parts, st->clips);
	fprintf(rf, "  \"height\": %.9g,\n  \"diagonal\": %.9g,\n  \"layers\": {\n", st->height, st->diagonal);
	const mlod_pack_layer_stats *ls[3] = {&st->skeleton, &st->mesh, &st->motion};
	const char *names[3] = {"skeleton", "mesh", "motion"};
	for (int i = 0; i < 3; i++) {
		fprintf(rf, "    \"%s\": {\"levels\": %d, \"source\": \"%s\", \"stored\": %llu, \"raw\": %llu, \"ms\": %.6g, "
		        "\"errors\": [", names[i], ls[i]->levels, source(ls[i]), (unsigned long long)ls[i]->stored,
		        (unsigned long long)ls[i]->raw, 1e3 * ls[i]->seconds);
		for (int k = 1; k < ls[i]->levels; k++)
			fprintf(rf, "%s%.9g", k > 1 ? ", " : "", ls[i]->errors[k]);
		fprintf(rf, "], \"level0_error\": %.9g}%s\n", ls[i]->errors[0], i < 2 ? "," : "");
	}
	fprintf(rf, "  },\n  \"total\": %llu,\n  \"chunks\": %u,\n  \"info_bytes\": %llu,\n  \"doc_bytes\": %llu,\n",
	        (unsigned long long)st->total, st->chunks, (unsigned long long)st->info_bytes,
	        (unsigned long long)st->doc_bytes);
	fprintf(rf, "  \"first_drawable\": %u,\n  \"notes\": ", st->first_drawable);
	mlod_name_put(rf, st->notes, 1, 0);
	fprintf(rf, "\n}\n");
}

void mlod_pack_print_stats(FILE *f, const char *input, const mlod_pack_stats *st, const char *codec,
                           mlod_pack_text form)
{
	if (form == MLOD_PACK_TEXT_JSON)
		report_json(f, input, st, codec);
	else
		report_table(f, input, st, codec);
}

/* ------------------------------------------------------------------ */
/* --info                                                              */
/* ------------------------------------------------------------------ */

/* A chunk's error in percent of what the layer measures against: the
 * diagonal for the mesh, else the height. */
static double error_percent(const mlod_pack_chunk *c, const mlod_pack_info_rec *ir)
{
	double ref = c->layer == MLOD_LAYER_MESH ? ir->diagonal : ir->height;
	return ref > 0.0 ? 100.0 * c->error / ref : 0.0;
}

static mlod_result info_json(FILE *f, const char *label, const void *data, size_t size, const mlod_pack *p,
                             const mlod_pack_info *info, const mlod_pack_totals *t, mlod_error *err)
{
	const mlod_pack_info_rec *ir = &info->rec;
	uint64_t stored = t->all_stored, raw = t->all_raw, overhead = t->overhead;
	fprintf(f, "{\n  \"file\": ");
	mlod_name_put(f, label, 1, 0);
	fprintf(f, ",\n  \"version\": \"%u.%u\",\n  \"size\": %llu,\n  \"flags\": %u,\n  \"name\": ", p->major, p->minor,
	        (unsigned long long)p->file_size, p->flags);
	mlod_name_put(f, info->name, 1, 0);
	fprintf(f, ",\n  \"joints\": %u,\n  \"skins\": %u,\n  \"parts\": %u,\n  \"clips\": %u,\n", ir->joint_count,
	        ir->skin_count, ir->instance_count, ir->clip_count);
	fprintf(f, "  \"skeleton_levels\": %u,\n  \"mesh_levels\": %u,\n  \"motion_levels\": %u,\n",
	        ir->skeleton_levels, ir->mesh_levels, ir->motion_levels);
	fprintf(f, "  \"height\": %.9g,\n  \"diagonal\": %.9g,\n", ir->height, ir->diagonal);
	fprintf(f, "  \"bounds_min\": [%.9g, %.9g, %.9g],\n  \"bounds_max\": [%.9g, %.9g, %.9g],\n", ir->bounds_min[0],
	        ir->bounds_min[1], ir->bounds_min[2], ir->bounds_max[0], ir->bounds_max[1], ir->bounds_max[2]);
	/* the joints' names and parents, as the runtime gives them (mlod_rt_info(3)) */
	mlod_pack_skeleton sk;
	memset(&sk, 0, sizeof sk);
	mlod_result r = mlod_pack_decode_skeleton(p, data, size, &sk, err);
	if (r != MLOD_OK)
		return r;
	fprintf(f, "  \"skeleton\": [");
	for (uint32_t j = 0; j < sk.joint_count; j++) {
		fprintf(f, "%s\n    {\"joint\": ", j ? "," : "");
		mlod_name_put(f, sk.joint_names[j], 1, 0);
		fprintf(f, ", \"parent\": %d}", (int)sk.joints[j].parent);
	}
	fprintf(f, "%s],\n  \"chunks\": [\n", sk.joint_count ? "\n  " : "");
	mlod_pack_skeleton_free(&sk);
	for (uint32_t i = 0; i < p->chunk_count; i++) {
		const mlod_pack_chunk *c = &p->chunks[i];
		fprintf(f, "    {\"type\": \"%s\", \"layer\": \"%s\", \"level\": %u, \"item\": %u, \"clip\": ",
		        mlod_pack_type_name(c->type), mlod_pack_layer_name(c->layer), c->level, c->item);
		if (c->type == MLOD_CHUNK_MOTION && c->item < ir->clip_count)
			mlod_name_put(f, info->clip_names[c->item], 1, 0);
		else
			fputs("null", f);
		fprintf(f, ", \"codec\": \"%s\", \"entropy\": \"%s\", \"offset\": %llu, \"stored\": %u, \"coded\": %u, "
		        "\"raw\": %u, \"crc\": %u, \"error\": %.9g, \"error_percent\": %.9g, \"distance\": %.9g}%s\n",
		        mlod_pack_codec_name(c->codec), mlod_pack_entropy_name(c->entropy), (unsigned long long)c->offset,
		        c->stored_size, c->entropy ? c->coded_size : c->stored_size, c->raw_size, c->crc,
		        c->error, error_percent(c, ir), c->distance, i + 1 < p->chunk_count ? "," : "");
	}
	fprintf(f, "  ],\n  \"layers\": {\n");
	for (unsigned l = 0; l < 4; l++)
		fprintf(f, "    \"%s\": {\"chunks\": %u, \"stored\": %llu, \"raw\": %llu}%s\n", mlod_pack_layer_name(l),
		        t->chunks[l], (unsigned long long)t->stored[l], (unsigned long long)t->raw[l], l < 3 ? "," : "");
	fprintf(f, "  },\n  \"stored\": %llu,\n  \"raw\": %llu,\n  \"overhead\": %llu,\n  \"total\": %llu,\n",
	        (unsigned long long)stored, (unsigned long long)raw, (unsigned long long)overhead,
	        (unsigned long long)(stored + overhead));
	fprintf(f, "  \"first_drawable\": %u,\n  \"max_vertex_count\": ", ir->first_drawable);
	if (info->has_max_vertices)
		fprintf(f, "%u\n}\n", ir->max_vertex_count);
	else
		fputs("null\n}\n", f); /* not stated before format 8.1 */
	return MLOD_OK;
}

static void info_table(FILE *f, const char *label, const mlod_pack *p, const mlod_pack_info *info,
                       const mlod_pack_totals *t)
{
	const mlod_pack_info_rec *ir = &info->rec;
	uint64_t stored = t->all_stored, raw = t->all_raw, overhead = t->overhead;
	fputs("# ", f);
	mlod_name_put(f, label, 0, 0);
	fprintf(f, ": mlod %u.%u, %llu bytes, %u chunks\n# character '", p->major, p->minor,
	        (unsigned long long)p->file_size, p->chunk_count);
	mlod_name_put(f, info->name, 0, 0);
	fprintf(f, "': %u joints, %u skins, %u parts, %u clips; levels: skeleton %u, mesh %u, motion %u; "
	        "height %.4g, diagonal %.4g\n", ir->joint_count, ir->skin_count, ir->instance_count,
	        ir->clip_count, ir->skeleton_levels, ir->mesh_levels, ir->motion_levels, ir->height, ir->diagonal);
	fprintf(f, "%-5s %-8s %5s  %-20s %-19s %10s %10s %11s %9s %11s\n", "type", "layer", "level", "item", "codec",
	        "stored", "raw", "error", "error%", "distance");
	for (uint32_t i = 0; i < p->chunk_count; i++) {
		const mlod_pack_chunk *c = &p->chunks[i];
		const char *item = c->type == MLOD_CHUNK_MOTION && c->item < ir->clip_count ? info->clip_names[c->item] : "-";
		char cc[32];
		fprintf(f, "%-5s %-8s %5u  ", mlod_pack_type_name(c->type), mlod_pack_layer_name(c->layer), c->level);
		mlod_name_put(f, item, 0, 20);
		fprintf(f, " %-19s %10u %10u %11.4g %8.4g%% %11.4g\n", mlod_pack_codec_label(c, cc, sizeof cc), c->stored_size,
		        c->raw_size, c->error, error_percent(c, ir), c->distance);
	}
	for (unsigned l = 0; l < 4; l++)
		fprintf(f, "# total %-8s %4u chunks, stored %10llu, raw %10llu\n", mlod_pack_layer_name(l), t->chunks[l],
		        (unsigned long long)t->stored[l], (unsigned long long)t->raw[l]);
	fprintf(f, "# total %llu bytes: %llu stored in chunks (raw %llu), %llu header, TOC and padding\n",
	        (unsigned long long)(stored + overhead), (unsigned long long)stored, (unsigned long long)raw,
	        (unsigned long long)overhead);
	fprintf(f, "# first drawable level: %u bytes\n", ir->first_drawable);
	if (info->has_max_vertices)
		fprintf(f, "# largest mesh level: %u vertices\n", ir->max_vertex_count);
	else
		fprintf(f, "# largest mesh level: not stated (format %u.%u, before 8.1)\n", p->major, p->minor);
}

/* Every chunk is first decoded through the reader (lib/rt,
 * mlod_pack_check) and the DOC chunk's glb read as -x reads it
 * (mlod_pack_check_doc): mlod_pack_inspect. */
mlod_result mlod_pack_print_info(FILE *f, const char *label, const void *data, size_t size, mlod_pack_text form,
                                 mlod_error *err)
{
	mlod_pack p;
	mlod_pack_info info;
	mlod_result r = mlod_pack_inspect(data, size, &p, &info, err);
	if (r != MLOD_OK)
		return r;
	mlod_pack_totals t;
	mlod_pack_totals_sum(&p, &t);
	if (form == MLOD_PACK_TEXT_JSON)
		r = info_json(f, label, data, size, &p, &info, &t, err);
	else
		info_table(f, label, &p, &info, &t);
	mlod_pack_info_free(&info);
	mlod_pack_close(&p);
	return r;
}
