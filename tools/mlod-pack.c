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

#include "common.h"

static const char usage_text[] =
	"usage: mlod-pack [options] [input]\n"
	"       mlod-pack --info FILE | -x FILE -o out.glb   (need the pack reader)\n"
	"\n"
	"Bakes the skeleton, mesh and motion levels of a character into one .mlod\n"
	"pack (mlod(5)), coarse levels first. Input is glb, glTF or BVH; levels left\n"
	"by mlod-skelgraph, mlod-bgm and mlod-motion are used as they are, and each\n"
	"layer the input lacks gets that tool's default levels.\n"
	"\n"
	"options:\n"
	"  -o, --output FILE          write to FILE instead of stdout\n"
	"  -r, --report[=FORMAT]      print what was packed (to stdout: with -o as\n"
	"                             well as the pack, else instead of it); FORMAT\n"
	"                             is table or json\n"
	"      --codec NAME           meshopt (default) or none (draco: not built yet)\n"
	"      --name NAME            the character's name in the pack (default: the\n"
	"                             input file's name without its extension)\n"
	"mesh levels (as mlod-bgm):\n"
	"  -R, --ratios LIST          levels keeping these fractions of the triangles\n"
	"                             (default %s)\n"
	"  -e, --max-error PCT        levels down to the coarsest whose posed error\n"
	"                             stays within PCT percent of the diagonal\n"
	"skeleton levels (mlod-skelgraph's --max-error):\n"
	"      --skeleton-max-error PCT  percent of the skeleton height (default %g)\n"
	"motion levels (mlod-motion's --max-error):\n"
	"      --motion-max-error LIST   one level per bound: E in scene units or E%%\n"
	"                             of the skeleton height (default 0.2%%,1%%,3%%)\n"
	"      --no-skeleton-levels, --no-mesh-levels, --no-motion-levels\n"
	"                             pack that layer at level 0 only\n"
	"  -h, --help                 show this help\n"
	"  -V, --version              show the version\n"
	"\n"
	"exit status: 0 success, 1 usage, 2 bad input, 3 unsupported input,\n"
	"4 output failure.\n";

static const char *input_name(const char *path, char *buf, size_t size)
{
	if (!path || strcmp(path, "-") == 0)
		return "";
	const char *base = strrchr(path, '/');
	base = base ? base + 1 : path;
	const char *dot = strrchr(base, '.');
	size_t n = dot && dot != base ? (size_t)(dot - base) : strlen(base);
	snprintf(buf, size, "%.*s", (int)n, base);
	return buf;
}

/* "0.2%,1%,3%" or "0.01,0.05". */
static int parse_bounds(const char *value, mlod_pack_options *opt)
{
	char *copy = strdup(value), *save = NULL;
	int n = 0;
	if (!copy)
		tool_die(EXIT_USAGE, NULL, "out of memory");
	for (char *tok = strtok_r(copy, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
		if (n == MLOD_PACK_MAX_MOTION_LEVELS)
			tool_usage_error("--motion-max-error: at most %d bounds", MLOD_PACK_MAX_MOTION_LEVELS);
		size_t len = strlen(tok);
		int percent = len > 0 && tok[len - 1] == '%';
		if (percent)
			tok[len - 1] = '\0';
		opt->motion_bounds[n] = tool_parse_double("--motion-max-error", tok, 1e-12, percent ? 100.0 : 1e12);
		opt->motion_percent[n++] = (unsigned char)percent;
	}
	free(copy);
	if (n == 0)
		tool_usage_error("--motion-max-error: no bound in '%s'", value);
	return n;
}

static const char *source(const mlod_pack_layer_stats *l)
{
	return l->levels <= 1 ? "-" : l->from_input ? "input" : "computed";
}

static void report_table(FILE *rf, const char *input, const mlod_pack_stats *st, const char *codec)
{
	fprintf(rf, "# %s: %d joints, %d skins, %d parts, %d clips; height %.4g, diagonal %.4g; codec %s\n", input,
	        st->joints, st->skins, st->parts, st->clips, st->height, st->diagonal, codec);
	fprintf(rf, "%-9s %6s  %-8s  %10s  %10s  %9s  %s\n", "layer", "levels", "source", "stored", "raw", "ms",
	        "error per level (scene units)");
	const mlod_pack_layer_stats *ls[3] = {&st->skeleton, &st->mesh, &st->motion};
	const char *names[3] = {"skeleton", "mesh", "motion"};
	for (int i = 0; i < 3; i++) {
		fprintf(rf, "%-9s %6d  %-8s  %10llu  %10llu  %9.1f ", names[i], ls[i]->levels, source(ls[i]),
		        (unsigned long long)ls[i]->stored, (unsigned long long)ls[i]->raw, 1e3 * ls[i]->seconds);
		for (int k = 1; k < ls[i]->levels; k++)
			fprintf(rf, " %.4g", ls[i]->errors[k]);
		fputc('\n', rf);
	}
	fprintf(rf, "# total %llu bytes in %u chunks (info %llu, doc %llu); first drawable level: %u bytes\n",
	        (unsigned long long)st->total, st->chunks, (unsigned long long)st->info_bytes,
	        (unsigned long long)st->doc_bytes, st->first_drawable);
	if (st->notes[0])
		fprintf(rf, "# note: %s\n", st->notes);
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
		fprintf(rf, "]}%s\n", i < 2 ? "," : "");
	}
	fprintf(rf, "  },\n  \"total\": %llu,\n  \"chunks\": %u,\n  \"info_bytes\": %llu,\n  \"doc_bytes\": %llu,\n",
	        (unsigned long long)st->total, st->chunks, (unsigned long long)st->info_bytes,
	        (unsigned long long)st->doc_bytes);
	fprintf(rf, "  \"first_drawable\": %u,\n  \"notes\": ", st->first_drawable);
	tool_json_string(rf, st->notes);
	fprintf(rf, "\n}\n");
}

int main(int argc, char **argv)
{
	enum { OPT_CODEC = 256, OPT_NAME, OPT_SKEL_ERR, OPT_MOTION_ERR, OPT_NO_SKEL, OPT_NO_MESH, OPT_NO_MOTION, OPT_INFO };
	static const struct option longopts[] = {
		{"output", required_argument, NULL, 'o'},
		{"report", optional_argument, NULL, 'r'},
		{"codec", required_argument, NULL, OPT_CODEC},
		{"name", required_argument, NULL, OPT_NAME},
		{"ratios", required_argument, NULL, 'R'},
		{"max-error", required_argument, NULL, 'e'},
		{"skeleton-max-error", required_argument, NULL, OPT_SKEL_ERR},
		{"motion-max-error", required_argument, NULL, OPT_MOTION_ERR},
		{"no-skeleton-levels", no_argument, NULL, OPT_NO_SKEL},
		{"no-mesh-levels", no_argument, NULL, OPT_NO_MESH},
		{"no-motion-levels", no_argument, NULL, OPT_NO_MOTION},
		{"info", required_argument, NULL, OPT_INFO},
		{"extract", required_argument, NULL, 'x'},
		{"help", no_argument, NULL, 'h'},
		{"version", no_argument, NULL, 'V'},
		{NULL, 0, NULL, 0},
	};
	mlod_pack_options opt;
	mlod_pack_options_default(&opt);
	const char *output = NULL, *name = NULL, *info = NULL, *extract = NULL, *codec = "meshopt";
	enum tool_report report = REPORT_NONE;
	int ratios_given = 0, ch;

	tool_name = "mlod-pack";
	opterr = 0;
	while ((ch = getopt_long(argc, argv, ":o:r::R:e:x:hV", longopts, NULL)) != -1) {
		switch (ch) {
		case 'o': output = optarg; break;
		case 'r': report = tool_parse_report(optarg); break;
		case OPT_CODEC:
			if (strcmp(optarg, "meshopt") == 0)
				opt.codec = MLOD_CODEC_MESHOPT;
			else if (strcmp(optarg, "none") == 0)
				opt.codec = MLOD_CODEC_NONE;
			else if (strcmp(optarg, "draco") == 0)
				opt.codec = MLOD_CODEC_DRACO;
			else
				tool_usage_error("--codec: unknown value '%s' (meshopt, none or draco)", optarg);
			codec = optarg;
			break;
		case OPT_NAME: name = optarg; break;
		case 'R':
			opt.ratio_count = tool_parse_list("--ratios", optarg, opt.ratios, MLOD_MESH_MAX_LEVELS, 1e-6, 1.0);
			ratios_given = 1;
			break;
		case 'e': opt.mesh_max_error = tool_parse_double("--max-error", optarg, 0.0, 100.0); break;
		case OPT_SKEL_ERR: opt.skel_max_error = tool_parse_double("--skeleton-max-error", optarg, 0.0, 1e6); break;
		case OPT_MOTION_ERR: opt.motion_bound_count = parse_bounds(optarg, &opt); break;
		case OPT_NO_SKEL: opt.no_skeleton_levels = 1; break;
		case OPT_NO_MESH: opt.no_mesh_levels = 1; break;
		case OPT_NO_MOTION: opt.no_motion_levels = 1; break;
		case OPT_INFO: info = optarg; break;
		case 'x': extract = optarg; break;
		case 'h': {
			static const double defaults[] = {MLOD_MESH_RATIOS_DEFAULT};
			char list[64] = "";
			for (size_t i = 0, n = 0; i < sizeof defaults / sizeof *defaults; i++)
				n += (size_t)snprintf(list + n, sizeof list - n, "%s%g", i ? "," : "", defaults[i]);
			printf(usage_text, list, MLOD_SKEL_MAX_ERROR_DEFAULT);
			return 0;
		}
		case 'V': tool_version();
		case ':': tool_usage_error("option '%s' needs a value", argv[optind - 1]);
		default: tool_usage_error("unknown option '%s'", argv[optind - 1]);
		}
	}
	if (argc - optind > 1)
		tool_usage_error("too many inputs: one file, or stdin");
	if (ratios_given && opt.mesh_max_error >= 0.0)
		tool_usage_error("--ratios and --max-error do not go together");
	if (info && extract)
		tool_usage_error("--info and -x do not go together");
	if (info || extract) {
		/* Hooks for the pack reader (lib/rt/pack.c), which is not merged yet. */
		if (optind < argc)
			tool_usage_error("%s takes its pack as the option's value", info ? "--info" : "-x");
		tool_die(EXIT_UNSUPPORTED, info ? info : extract, "%s needs the pack reader, which is not built yet",
		         info ? "--info" : "-x");
	}
	if (opt.codec == MLOD_CODEC_DRACO)
		tool_die(EXIT_UNSUPPORTED, NULL, "--codec draco: not built yet (use meshopt or none)");

	const char *path = optind < argc ? argv[optind] : NULL;
	const char *label = tool_input_label(path);
	char namebuf[256];
	opt.name = name ? name : input_name(path, namebuf, sizeof namebuf);
	mlod_gltf *doc = NULL;
	mlod_character c;
	mlod_format format = MLOD_FORMAT_UNKNOWN;
	size_t size = 0;
	memset(&c, 0, sizeof c);
	void *bytes = tool_load_keep(path, &doc, &c, &format, &size);

	mlod_pack_stats st;
	mlod_error err = {0};
	void *pack = NULL;
	size_t pack_size = 0;
	mlod_result r = mlod_pack_write(doc, &c, format, bytes, size, &opt, &pack, &pack_size, &st, &err);
	free(bytes);
	if (r != MLOD_OK)
		tool_die(r == MLOD_ERR_NOMEM ? EXIT_OUTPUT : tool_exit_code(r), label, "%s", err.message);
	if (c.clip_count == 0 && c.skeleton.joint_count > 0)
		fprintf(stderr, "%s: %s: no animation: the pack has no motion levels\n", tool_name, label);
	if (output || report == REPORT_NONE)
		tool_write_output(output, pack, pack_size, 1);
	if (report == REPORT_TABLE)
		report_table(stdout, label, &st, codec);
	else if (report == REPORT_JSON)
		report_json(stdout, label, &st, codec);
	if (fflush(stdout) != 0)
		tool_die(EXIT_OUTPUT, "<stdout>", "write error");
	mlod_free(pack);
	mlod_character_free(&c);
	mlod_gltf_free(doc);
	return 0;
}
