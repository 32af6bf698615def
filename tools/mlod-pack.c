/*
 * mlod-pack: bakes every level of every layer of a character into one
 * .mlod pack (mlod(5)): the levels the input carries from mlod-skelgraph,
 * mlod-bgm and mlod-motion, and each layer's default levels where it has
 * none. The work is lib/pack's (mlod_pack_write); this is option handling.
 */
#define _GNU_SOURCE /* getopt_long */

#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "common.h"

static const char usage_text[] =
	"usage: mlod-pack [options] [input]\n"
	"       mlod-pack --info FILE [--json]\n"
	"       mlod-pack -x FILE [-o out.glb]\n"
	"\n"
	"Bakes the skeleton, mesh and motion levels of a character into one .mlod\n"
	"pack (mlod(5)), coarse levels first. Input is glb, glTF or BVH; levels left\n"
	"by mlod-skelgraph, mlod-bgm and mlod-motion are used as they are, and each\n"
	"layer the input lacks gets that tool's default levels.\n"
	"\n"
	"options:\n"
	"  -o, --output FILE          write to FILE instead of stdout\n"
	"  -r, --report[=FORMAT]      print what was packed (to stdout: with -o FILE\n"
	"                             as well as the pack, else instead of it; not\n"
	"                             with -o naming stdout); FORMAT is table or json\n"
	"      --codec NAME           meshopt (default), none, or draco (MESH levels as\n"
	"                             standalone Draco meshes: larger packs, slower\n"
	"                             to decode; mlod(5))\n"
	"      --entropy NAME         zstd (default): each chunk but INFO through\n"
	"                             zstd -19 after its codec where that stores\n"
	"                             fewer bytes (skeleton and finer mesh levels\n"
	"                             also on the chunks they need, format 6.0);\n"
	"                             none: the codec alone\n"
	"      --name NAME            the character's name in the pack (default: the\n"
	"                             name of the pack a glb of -x came from, else\n"
	"                             the input file's name without its extension)\n"
	"mesh levels (as mlod-bgm):\n"
	"  -R, --ratios LIST          levels keeping these fractions of the triangles\n"
	"                             (default %s)\n"
	"  -e, --max-error PCT        levels down to the coarsest whose posed error\n"
	"                             stays within PCT percent of the diagonal\n"
	"  -p, --placement NAME       new vertex of a collapse: optimal (default),\n"
	"                             barycenter, vertex (one of the collapsed vertices\n"
	"                             kept whole: smaller packs) or hybrid[=PCT] (whole\n"
	"                             where no costlier than optimal or within PCT%% of\n"
	"                             the diagonal, default 0.1)\n"
	"      --influence-budget F   fewer influences on the levels' vertices that\n"
	"                             move at most F times the level's mean posed\n"
	"                             error (0, the default: off; not with -e)\n"
	"mesh quantisation (mlod(5) QUANTISATION):\n"
	"      --position-bits N      positions: N bits of the part's box, 8-16\n"
	"                             (default %d)\n"
	"      --normal-bits N        normals and tangents: N-bit octahedral, 6-16\n"
	"                             (default %d)\n"
	"      --uv-bits N            UVs: N bits of the part's UV box, 8-16\n"
	"                             (default %d)\n"
	"skeleton levels (mlod-skelgraph's --max-error):\n"
	"      --skeleton-max-error PCT  percent of the skeleton height (default %g)\n"
	"motion levels (mlod-motion's --max-error):\n"
	"      --motion-max-error LIST   one level per bound: E in scene units or E%%\n"
	"                             of the skeleton height (default 0.2%%,1%%,3%%)\n"
	"      --motion-level0-error E   level 0: the clips within E (scene units, or\n"
	"                             E%% of the height; default %g%%), keys reduced;\n"
	"                             below the smallest --motion-max-error bound\n"
	"      --lossless-motion      level 0: every key of the clips as read (not\n"
	"                             with --motion-level0-error)\n"
	"      --no-skeleton-levels, --no-mesh-levels, --no-motion-levels\n"
	"                             pack that layer at level 0 only\n";
static const char usage_more[] = /* printf's format ends above (ISO C's 4095-character string limit) */
	"      --info FILE            print the pack's chunks (layer, level, clip,\n"
	"                             codec and entropy stage, sizes, error, switch\n"
	"                             distance) and totals;\n"
	"                             every chunk is decoded and checked, the DOC\n"
	"                             chunk's glb read as -x reads it (stdout\n"
	"                             only: not with -o)\n"
	"      --json                 with --info: as JSON (= --report=json), with the\n"
	"                             rest bounds and every joint's name and parent\n"
	"  -x, --extract FILE         unpack FILE to a glb: MSFT_lod mesh levels (with\n"
	"                             the pack's weights, on the full skin),\n"
	"                             skeleton-level skins, <clip>@lod<k> animations\n"
	"  -j, --threads N            compute mesh levels on N threads (default: the\n"
	"                             processors it may run on, its CPU affinity);\n"
	"                             the same pack at any N\n"
	"  -h, --help                 show this help\n"
	"  -V, --version              show the version\n"
	"\n"
	"exit status: 0 success, 1 usage, 2 bad input, 3 unsupported input,\n"
	"4 output failure.\n" TOOL_OUTPUT_NOTE;

/* "0.2%,1%,3%" or "0.01,0.05". */
static int parse_bounds(const char *value, mlod_pack_options *opt)
{
	int pct[MLOD_PACK_MAX_MOTION_LEVELS];
	int n = tool_parse_list_percent("--motion-max-error", value, opt->motion_bounds, pct, MLOD_PACK_MAX_MOTION_LEVELS,
	                                1e-12, 1e12);
	n = tool_drop_repeats("--motion-max-error", opt->motion_bounds, pct, n); /* the same level twice */
	for (int i = 0; i < n; i++)
		if ((opt->motion_percent[i] = (unsigned char)pct[i]) && opt->motion_bounds[i] > 100.0)
			tool_usage_error("--motion-max-error: %g%% is out of range [1e-12, 100]", opt->motion_bounds[i]);
	return n;
}

/* "0.05%" or "0.001". */
static void parse_level0(const char *value, mlod_pack_options *opt)
{
	char tok[64];
	size_t len = strlen(value);
	int percent = len > 0 && value[len - 1] == '%';
	snprintf(tok, sizeof tok, "%.*s", (int)(percent ? len - 1 : len), value);
	opt->motion_level0_error = tool_parse_double("--motion-level0-error", tok, 1e-12, percent ? 100.0 : 1e12);
	opt->motion_level0_percent = (unsigned char)percent;
}

/* The report's source column: a layer's levels from the input, or computed. */
static const char *source(const mlod_pack_layer_stats *l)
{
	return l->levels <= 1 ? "-" : l->from_input ? "input" : "computed";
}

static void report_table(FILE *rf, const char *input, const mlod_pack_stats *st, const char *codec)
{
	fputs("# ", rf);
	tool_put_name(rf, input, 0);
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
	if (st->notes[0])
		tool_put_line(rf, "# note: ", st->notes);
}

static void report_json(FILE *rf, const char *input, const mlod_pack_stats *st, const char *codec)
{
	fprintf(rf, "{\n  \"input\": ");
	tool_json_string(rf, input);
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
	tool_json_string(rf, st->notes);
	fprintf(rf, "\n}\n");
}

/* Reads the pack of --info or -x (a file, or stdin when path is "-"). */
static void *read_pack(const char *path, size_t *size)
{
	if (strcmp(path, "-") == 0 && isatty(STDIN_FILENO))
		tool_usage_error("no input: give a pack, or pipe one into stdin");
	return tool_read_input(path, size);
}

/* --info: every chunk is first decoded through the reader (lib/rt,
 * mlod_pack_check), and the DOC chunk's glb read as -x reads it
 * (mlod_pack_check_doc), so that a CRC or a bound that does not hold
 * exits 2 with the reader's message. */
static int pack_info(const char *path, enum tool_report report)
{
	const char *label = tool_input_label(path);
	size_t size = 0;
	void *data = read_pack(path, &size);
	mlod_pack p;
	mlod_pack_info info;
	mlod_error err = {0};
	mlod_result r = mlod_pack_inspect(data, size, &p, &info, &err);
	if (r != MLOD_OK)
		tool_die(tool_exit_code(r), label, "%s", err.message);
	const mlod_pack_info_rec *ir = &info.rec;
	mlod_pack_totals t;
	mlod_pack_totals_sum(&p, &t);
	uint64_t stored = t.all_stored, raw = t.all_raw, overhead = t.overhead;
	FILE *f = stdout;
	if (report == REPORT_JSON) {
		fprintf(f, "{\n  \"file\": ");
		tool_json_string(f, label);
		fprintf(f, ",\n  \"version\": \"%u.%u\",\n  \"size\": %llu,\n  \"flags\": %u,\n  \"name\": ", p.major, p.minor,
		        (unsigned long long)p.file_size, p.flags);
		tool_json_string(f, info.name);
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
		if ((r = mlod_pack_decode_skeleton(&p, data, size, &sk, &err)) != MLOD_OK)
			tool_die(tool_exit_code(r), label, "%s", err.message);
		fprintf(f, "  \"skeleton\": [");
		for (uint32_t j = 0; j < sk.joint_count; j++) {
			fprintf(f, "%s\n    {\"joint\": ", j ? "," : "");
			tool_json_string(f, sk.joint_names[j]);
			fprintf(f, ", \"parent\": %d}", (int)sk.joints[j].parent);
		}
		fprintf(f, "%s],\n  \"chunks\": [\n", sk.joint_count ? "\n  " : "");
		mlod_pack_skeleton_free(&sk);
		for (uint32_t i = 0; i < p.chunk_count; i++) {
			const mlod_pack_chunk *c = &p.chunks[i];
			double ref = c->layer == MLOD_LAYER_MESH ? ir->diagonal : ir->height;
			fprintf(f, "    {\"type\": \"%s\", \"layer\": \"%s\", \"level\": %u, \"item\": %u, \"clip\": ",
			        mlod_pack_type_name(c->type), mlod_pack_layer_name(c->layer), c->level, c->item);
			if (c->type == MLOD_CHUNK_MOTION && c->item < ir->clip_count)
				tool_json_string(f, info.clip_names[c->item]);
			else
				fputs("null", f);
			fprintf(f, ", \"codec\": \"%s\", \"entropy\": \"%s\", \"offset\": %llu, \"stored\": %u, \"coded\": %u, "
			        "\"raw\": %u, \"crc\": %u, \"error\": %.9g, \"error_percent\": %.9g, \"distance\": %.9g}%s\n",
			        mlod_pack_codec_name(c->codec), mlod_pack_entropy_name(c->entropy), (unsigned long long)c->offset,
			        c->stored_size, c->entropy ? c->coded_size : c->stored_size, c->raw_size, c->crc,
			        c->error, ref > 0.0 ? 100.0 * c->error / ref : 0.0, c->distance, i + 1 < p.chunk_count ? "," : "");
		}
		fprintf(f, "  ],\n  \"layers\": {\n");
		for (unsigned l = 0; l < 4; l++)
			fprintf(f, "    \"%s\": {\"chunks\": %u, \"stored\": %llu, \"raw\": %llu}%s\n", mlod_pack_layer_name(l),
			        t.chunks[l], (unsigned long long)t.stored[l], (unsigned long long)t.raw[l], l < 3 ? "," : "");
		fprintf(f, "  },\n  \"stored\": %llu,\n  \"raw\": %llu,\n  \"overhead\": %llu,\n  \"total\": %llu,\n",
		        (unsigned long long)stored, (unsigned long long)raw, (unsigned long long)overhead,
		        (unsigned long long)(stored + overhead));
		fprintf(f, "  \"first_drawable\": %u\n}\n", ir->first_drawable);
	} else {
		fputs("# ", f);
		tool_put_name(f, label, 0);
		fprintf(f, ": mlod %u.%u, %llu bytes, %u chunks\n# character '", p.major, p.minor,
		        (unsigned long long)p.file_size, p.chunk_count);
		tool_put_name(f, info.name, 0);
		fprintf(f, "': %u joints, %u skins, %u parts, %u clips; levels: skeleton %u, mesh %u, motion %u; "
		        "height %.4g, diagonal %.4g\n", ir->joint_count, ir->skin_count, ir->instance_count,
		        ir->clip_count, ir->skeleton_levels, ir->mesh_levels, ir->motion_levels, ir->height, ir->diagonal);
		fprintf(f, "%-5s %-8s %5s  %-20s %-19s %10s %10s %11s %9s %11s\n", "type", "layer", "level", "item", "codec",
		        "stored", "raw", "error", "error%", "distance");
		for (uint32_t i = 0; i < p.chunk_count; i++) {
			const mlod_pack_chunk *c = &p.chunks[i];
			double ref = c->layer == MLOD_LAYER_MESH ? ir->diagonal : ir->height;
			const char *item = c->type == MLOD_CHUNK_MOTION && c->item < ir->clip_count ? info.clip_names[c->item] : "-";
			char cc[32];
			fprintf(f, "%-5s %-8s %5u  ", mlod_pack_type_name(c->type), mlod_pack_layer_name(c->layer), c->level);
			tool_put_name(f, item, 20);
			fprintf(f, " %-19s %10u %10u %11.4g %8.4g%% %11.4g\n", mlod_pack_codec_label(c, cc, sizeof cc), c->stored_size,
			        c->raw_size, c->error, ref > 0.0 ? 100.0 * c->error / ref : 0.0, c->distance);
		}
		for (unsigned l = 0; l < 4; l++)
			fprintf(f, "# total %-8s %4u chunks, stored %10llu, raw %10llu\n", mlod_pack_layer_name(l), t.chunks[l],
			        (unsigned long long)t.stored[l], (unsigned long long)t.raw[l]);
		fprintf(f, "# total %llu bytes: %llu stored in chunks (raw %llu), %llu header, TOC and padding\n",
		        (unsigned long long)(stored + overhead), (unsigned long long)stored, (unsigned long long)raw,
		        (unsigned long long)overhead);
		fprintf(f, "# first drawable level: %u bytes\n", ir->first_drawable);
	}
	mlod_pack_info_free(&info);
	mlod_pack_close(&p);
	free(data);
	if (fflush(stdout) != 0)
		tool_die(EXIT_OUTPUT, "<stdout>", "write error");
	return 0;
}

/* -x: the pack back to a glb (lib/pack/unpack.c). */
static int pack_extract(const char *path, const char *output)
{
	const char *label = tool_input_label(path);
	size_t size = 0;
	void *data = read_pack(path, &size);
	mlod_gltf *doc = NULL;
	mlod_error err = {0};
	mlod_result r = mlod_pack_unpack(data, size, &doc, &err);
	free(data);
	if (r != MLOD_OK)
		tool_die(tool_exit_code(r), label, "%s", err.message);
	tool_write_gltf(output, doc);
	mlod_gltf_free(doc);
	return 0;
}

int main(int argc, char **argv)
{
	enum { OPT_CODEC = 256, OPT_ENTROPY, OPT_NAME, OPT_SKEL_ERR, OPT_MOTION_ERR, OPT_NO_SKEL, OPT_NO_MESH,
	       OPT_NO_MOTION, OPT_INFO, OPT_JSON, OPT_POS_BITS, OPT_NRM_BITS, OPT_UV_BITS, OPT_LEVEL0_ERR,
	       OPT_LOSSLESS_MOTION, OPT_INFLUENCE };
	static const struct option longopts[] = {
		{"output", required_argument, NULL, 'o'},
		{"report", optional_argument, NULL, 'r'},
		{"codec", required_argument, NULL, OPT_CODEC},
		{"entropy", required_argument, NULL, OPT_ENTROPY},
		{"name", required_argument, NULL, OPT_NAME},
		{"ratios", required_argument, NULL, 'R'},
		{"max-error", required_argument, NULL, 'e'},
		{"placement", required_argument, NULL, 'p'},
		{"influence-budget", required_argument, NULL, OPT_INFLUENCE},
		{"skeleton-max-error", required_argument, NULL, OPT_SKEL_ERR},
		{"motion-max-error", required_argument, NULL, OPT_MOTION_ERR},
		{"position-bits", required_argument, NULL, OPT_POS_BITS},
		{"normal-bits", required_argument, NULL, OPT_NRM_BITS},
		{"uv-bits", required_argument, NULL, OPT_UV_BITS},
		{"no-skeleton-levels", no_argument, NULL, OPT_NO_SKEL},
		{"no-mesh-levels", no_argument, NULL, OPT_NO_MESH},
		{"no-motion-levels", no_argument, NULL, OPT_NO_MOTION},
		{"motion-level0-error", required_argument, NULL, OPT_LEVEL0_ERR},
		{"lossless-motion", no_argument, NULL, OPT_LOSSLESS_MOTION},
		{"info", required_argument, NULL, OPT_INFO},
		{"json", no_argument, NULL, OPT_JSON},
		{"extract", required_argument, NULL, 'x'},
		{"threads", required_argument, NULL, 'j'},
		{"help", no_argument, NULL, 'h'},
		{"version", no_argument, NULL, 'V'},
		{NULL, 0, NULL, 0},
	};
	mlod_pack_options opt;
	mlod_pack_options_default(&opt);
	opt.bgm.threads = mlod_thread_count();
	const char *output = NULL, *name = NULL, *info = NULL, *extract = NULL, *codec = "meshopt";
	enum tool_report report = REPORT_NONE;
	int ratios_given = 0, json = 0, level0_given = 0, ch;
	/* The first option given that bakes (not for --info or -x), and the
	 * first of each layer's computed levels. */
	const char *bake = NULL, *skel_opt = NULL, *mesh_opt = NULL, *motion_opt = NULL;
#define BAKE(name) (bake = bake ? bake : (name))
#define LAYER(var, name) (BAKE(name), var = var ? var : (name))

	tool_name = "mlod-pack";
	static const char shortopts[] = ":o:r::R:e:p:x:j:hV";
	opterr = 0;
	while ((ch = getopt_long(argc, argv, shortopts, longopts, NULL)) != -1) {
		switch (ch) {
		case 'o': output = optarg; break;
		case 'r': report = tool_parse_report(optarg); break;
		case OPT_CODEC:
			BAKE("--codec");
			if (mlod_pack_codec_parse(optarg, &opt))
				tool_usage_error("--codec: unknown value '%s' (meshopt, none or draco)", optarg);
			codec = optarg;
			break;
		case OPT_ENTROPY:
			BAKE("--entropy");
			if (mlod_pack_entropy_parse(optarg, &opt))
				tool_usage_error("--entropy: unknown value '%s' (zstd or none)", optarg);
			break;
		case OPT_NAME: name = optarg, BAKE("--name"); break;
		case 'R':
			LAYER(mesh_opt, "--ratios");
			opt.ratio_count = tool_parse_list("--ratios", optarg, opt.ratios, MLOD_MESH_MAX_LEVELS, 1e-6, 1.0);
			ratios_given = 1;
			break;
		case 'e':
			LAYER(mesh_opt, "--max-error");
			opt.mesh_max_error = tool_parse_percent("--max-error", optarg, 0.0, 100.0);
			break;
		case 'p':
			LAYER(mesh_opt, "--placement");
			if (mlod_mesh_placement_parse(optarg, &opt.bgm.placement, &opt.bgm.hybrid_error))
				tool_usage_error("--placement: unknown value '%s' (optimal, barycenter, vertex or hybrid[=PCT])",
				                 optarg);
			break;
		case OPT_INFLUENCE:
			LAYER(mesh_opt, "--influence-budget");
			opt.bgm.influence_budget = tool_parse_double("--influence-budget", optarg, 0.0, 1e3);
			opt.bgm.influence_budget = opt.bgm.influence_budget > 0.0 ? opt.bgm.influence_budget : -1.0;
			break;
		case OPT_SKEL_ERR:
			LAYER(skel_opt, "--skeleton-max-error");
			opt.skel_max_error = tool_parse_percent("--skeleton-max-error", optarg, 0.0, 1e6);
			break;
		case OPT_MOTION_ERR:
			LAYER(motion_opt, "--motion-max-error");
			opt.motion_bound_count = parse_bounds(optarg, &opt);
			break;
		case OPT_POS_BITS: BAKE("--position-bits"), opt.position_bits = tool_parse_int("--position-bits", optarg, MLOD_PACK_POSITION_BITS_MIN, 16); break;
		case OPT_NRM_BITS: BAKE("--normal-bits"), opt.normal_bits = tool_parse_int("--normal-bits", optarg, MLOD_PACK_NORMAL_BITS_MIN, 16); break;
		case OPT_UV_BITS: BAKE("--uv-bits"), opt.uv_bits = tool_parse_int("--uv-bits", optarg, MLOD_PACK_UV_BITS_MIN, 16); break;
		case OPT_NO_SKEL: opt.no_skeleton_levels = 1, BAKE("--no-skeleton-levels"); break;
		case OPT_NO_MESH: opt.no_mesh_levels = 1, BAKE("--no-mesh-levels"); break;
		case OPT_NO_MOTION: opt.no_motion_levels = 1, BAKE("--no-motion-levels"); break;
		case OPT_LEVEL0_ERR: parse_level0(optarg, &opt), level0_given = 1, BAKE("--motion-level0-error"); break;
		case OPT_LOSSLESS_MOTION: opt.lossless_motion = 1, BAKE("--lossless-motion"); break;
		case OPT_INFO: info = optarg; break;
		case 'x': extract = optarg; break;
		case 'j': opt.bgm.threads = tool_parse_threads(optarg), BAKE("--threads"); break;
		case OPT_JSON: json = 1; break;
		case 'h': {
			static const double defaults[] = {MLOD_MESH_RATIOS_DEFAULT};
			char list[64] = "";
			for (size_t i = 0, n = 0; i < sizeof defaults / sizeof *defaults; i++)
				n += (size_t)snprintf(list + n, sizeof list - n, "%s%g", i ? "," : "", defaults[i]);
			printf(usage_text, list, MLOD_PACK_POSITION_BITS_DEFAULT, MLOD_PACK_NORMAL_BITS_DEFAULT,
			       MLOD_PACK_UV_BITS_DEFAULT, MLOD_SKEL_MAX_ERROR_DEFAULT, MLOD_PACK_MOTION_LEVEL0_DEFAULT);
			fputs(usage_more, stdout);
			return 0;
		}
		case 'V': tool_version();
		default: tool_option_error(ch, shortopts, argv);
		}
	}
	if (argc - optind > 1)
		tool_usage_error("too many inputs: one file, or stdin");
	if (ratios_given && opt.mesh_max_error >= 0.0)
		tool_usage_error("--ratios and --max-error do not go together");
	if (opt.bgm.influence_budget > 0.0 && opt.mesh_max_error >= 0.0)
		tool_usage_error("--influence-budget and --max-error do not go together");
	if (opt.lossless_motion && level0_given)
		tool_usage_error("--lossless-motion and --motion-level0-error do not go together");
	if (info && extract)
		tool_usage_error("--info and -x do not go together");
	if ((info || extract) && bake)
		tool_usage_error("%s bakes a pack: not with %s, which reads one", bake, info ? "--info" : "-x");
	if (opt.no_skeleton_levels && skel_opt)
		tool_usage_error("%s and --no-skeleton-levels do not go together", skel_opt);
	if (opt.no_mesh_levels && mesh_opt)
		tool_usage_error("%s and --no-mesh-levels do not go together", mesh_opt);
	if (opt.no_motion_levels && motion_opt)
		tool_usage_error("%s and --no-motion-levels do not go together", motion_opt);
	if (info && output)
		tool_usage_error("--info prints to stdout, -o does not go with it (redirect stdout)");
	if (json && !info)
		tool_usage_error("--json goes with --info (else use --report=json)");
	if (info || extract) {
		if (optind < argc)
			tool_usage_error("%s takes its pack as the option's value", info ? "--info" : "-x");
		if (info)
			return pack_info(info, json ? REPORT_JSON : report);
		if (report != REPORT_NONE)
			tool_usage_error("-x and --report do not go together");
		return pack_extract(extract, output);
	}
	if (report != REPORT_NONE && output && tool_output_is_stdout(output))
		tool_usage_error("--report prints to stdout, and -o names stdout too: the pack and the report would "
		                 "share one stream (write the pack to a file, or drop -o for the report alone)");
	const char *path = optind < argc ? argv[optind] : NULL;
	const char *label = tool_input_label(path);
	char namebuf[256];
	opt.name = name; /* else the input's record's (a glb of -x), else the file's */
	opt.default_name = tool_input_stem(path, "", namebuf, sizeof namebuf);
	mlod_gltf *doc = NULL;
	mlod_character c;
	mlod_record_input in;
	size_t size = 0;
	memset(&c, 0, sizeof c);
	void *bytes = tool_load_keep(path, &doc, &c, &in, &size);

	mlod_pack_stats st;
	mlod_error err = {0};
	void *pack = NULL;
	size_t pack_size = 0;
	mlod_result r = mlod_pack_write(doc, &c, in.format, bytes, size, &opt, &pack, &pack_size, &st, &err);
	free(bytes);
	if (r != MLOD_OK)
		tool_die(tool_exit_code(r), label, "%s", err.message);
	if (c.clip_count == 0 && c.skeleton.joint_count > 0)
		tool_note(label, "no animation: the pack has no motion levels");
	tool_note_lines(label, st.warnings); /* what the pack does not keep, or keeps changed */
	/* A layer option the input's own levels (mlod-skelgraph's, mlod-bgm's,
	 * mlod-motion's) leave unused. */
	const char *const layer_opt[3] = {skel_opt, mesh_opt, motion_opt};
	const mlod_pack_layer_stats *const layer_st[3] = {&st.skeleton, &st.mesh, &st.motion};
	static const char *const layer_name[3] = {"skeleton", "mesh", "motion"};
	for (int i = 0; i < 3; i++)
		if (layer_opt[i] && layer_st[i]->from_input)
			tool_note(label, "%s not used: the input has its own %s levels", layer_opt[i], layer_name[i]);
	if (st.doc_note[0]) { /* the pack is far larger than a stripped one: said, with or without --report */
		tool_note(label, "%s", mlod_name_text(st.doc_note, 0, (char[4 * sizeof st.doc_note]){0}, 4 * sizeof st.doc_note));
	}
	if (output || report == REPORT_NONE)
		tool_write_output(output, pack, pack_size, 1);
	char codec_label[48];
	snprintf(codec_label, sizeof codec_label, "%s%s", codec, opt.entropy == MLOD_ENTROPY_ZSTD ? "+zstd" : "");
	if (report == REPORT_TABLE)
		report_table(stdout, label, &st, codec_label);
	else if (report == REPORT_JSON)
		report_json(stdout, label, &st, codec_label);
	if (fflush(stdout) != 0)
		tool_die(EXIT_OUTPUT, "<stdout>", "write error");
	mlod_free(pack);
	mlod_character_free(&c);
	mlod_gltf_free(doc);
	return 0;
}
