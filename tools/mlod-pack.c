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
	"       mlod-pack --info [--json] [FILE]\n"
	"       mlod-pack -x [-o out.glb] [FILE]\n"
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
	"      --info [FILE]          print the pack's chunks (layer, level, clip,\n"
	"                             codec and entropy stage, sizes, error, switch\n"
	"                             distance) and totals;\n"
	"                             every chunk is decoded and checked, the DOC\n"
	"                             chunk's glb read as -x reads it (stdout\n"
	"                             only: not with -o). FILE, for --info and -x:\n"
	"                             the operand, in any order with the other\n"
	"                             options, or the value (--info=FILE, -xFILE);\n"
	"                             stdin without one\n"
	"      --json                 with --info: as JSON (= --report=json), with the\n"
	"                             rest bounds and every joint's name and parent\n"
	"  -x, --extract [FILE]       unpack FILE to a glb: MSFT_lod mesh levels (with\n"
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

/* Reads the pack of --info or -x (a file, or stdin when path is "-"). */
static void *read_pack(const char *path, size_t *size)
{
	if (strcmp(path, "-") == 0 && isatty(STDIN_FILENO))
		tool_usage_error("no input: give a pack, or pipe one into stdin");
	return tool_read_input(path, size);
}

/* --info: the pack's chunks and totals (mlod_pack_print_info), once every
 * chunk is decoded and the DOC chunk's glb read as -x reads it, so that a
 * CRC or a bound that does not hold exits 2 with the reader's message. */
static int pack_info(const char *path, enum tool_report report)
{
	const char *label = tool_input_label(path);
	size_t size = 0;
	void *data = read_pack(path, &size);
	mlod_error err = {0};
	mlod_result r = mlod_pack_print_info(stdout, label, data, size,
	                                     report == REPORT_JSON ? MLOD_PACK_TEXT_JSON : MLOD_PACK_TEXT_TABLE, &err);
	free(data);
	if (r != MLOD_OK)
		tool_die(tool_exit_code(r), label, "%s", err.message);
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
		{"info", optional_argument, NULL, OPT_INFO},
		{"json", no_argument, NULL, OPT_JSON},
		{"extract", optional_argument, NULL, 'x'},
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
	static const char shortopts[] = ":o:r::R:e:p:x::j:hV";
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
		/* The pack as the option's value (--info=FILE, -xFILE) or as the
		 * operand (--info FILE, -x FILE, in any order with --json, -o):
		 * "" until the operand is known. */
		case OPT_INFO: info = optarg ? optarg : ""; break;
		case 'x': extract = optarg ? optarg : ""; break;
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
	if (info && extract)
		tool_usage_error("--info and -x do not go together");
	if (argc - optind > 1)
		tool_usage_error("too many inputs: one file, or stdin");
	if (ratios_given && opt.mesh_max_error >= 0.0)
		tool_usage_error("--ratios and --max-error do not go together");
	if (opt.bgm.influence_budget > 0.0 && opt.mesh_max_error >= 0.0)
		tool_usage_error("--influence-budget and --max-error do not go together");
	if (opt.lossless_motion && level0_given)
		tool_usage_error("--lossless-motion and --motion-level0-error do not go together");
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
		const char **pack = info ? &info : &extract;
		if (**pack && optind < argc)
			tool_usage_error("%s names its pack '%s', and so does the operand '%s': give one", info ? "--info" : "-x",
			                 *pack, argv[optind]);
		if (!**pack)
			*pack = optind < argc ? argv[optind] : "-"; /* no pack named: stdin */
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
	if (c.mesh_count > 0 && st.mesh.levels == 0)
		tool_note(label, "no triangle mesh in the default scene: the pack has no mesh levels");
	else if (c.mesh_count == 0 && c.skeleton.joint_count == 0) /* as the stages' "nothing to" notes */
		tool_note(label, "no joints and no mesh: nothing to pack; the pack holds the document alone");
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
	if (report != REPORT_NONE)
		mlod_pack_print_stats(stdout, label, &st, codec_label,
		                      report == REPORT_JSON ? MLOD_PACK_TEXT_JSON : MLOD_PACK_TEXT_TABLE);
	if (fflush(stdout) != 0)
		tool_die(EXIT_OUTPUT, "<stdout>", "write error");
	mlod_free(pack);
	mlod_character_free(&c);
	mlod_gltf_free(doc);
	return 0;
}
