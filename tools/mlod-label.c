/*
 * mlod-label: labels the joints of a skeleton and measures their energy
 * (paper 4.1.1 and 4.1.2).
 *
 * Reads glb, glTF or BVH from a file or stdin. By default writes a glb to
 * stdout (or -o FILE) with each joint node's extras.mlod holding its depth,
 * neighbours, children, label, weight and energy (the stage record,
 * lib/record); --report prints a table (or JSON) instead.
 */
#define _GNU_SOURCE /* getopt_long */

#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common.h"


/* A printf format: the defaults come from the library. */
static const char usage_text[] =
	"usage: mlod-label [options] [input]\n"
	"\n"
	"Labels each joint (root, end-effector, major, extreme, minor) and computes\n"
	"its energy from the motion. Input is glb, glTF or BVH, from a file or stdin.\n"
	"Output is a glb with the results in each joint node's extras.mlod.\n"
	"\n"
	"options:\n"
	"  -o, --output FILE      write the glb (or .gltf) to FILE instead of stdout\n"
	"  -r, --report[=FORMAT]  print a report instead of a glb; FORMAT is table\n"
	"                         (default) or json\n"
	"      --hub-factor F     a joint is a hub when its neighbours exceed F times\n"
	"                         the average (default %g)\n"
	"      --max-angle DEG    rotation range per Euler axis that normalises the\n"
	"                         energy (default %g)\n"
	"  -h, --help             show this help\n"
	"  -V, --version          show the version\n"
	"\n"
	"exit status: 0 success, 1 usage, 2 bad input, 3 unsupported input,\n"
	"4 output failure.\n" TOOL_OUTPUT_NOTE;

struct stats {
	double avg_neighbors, avg_depth;
	int count[5];
};

static struct stats summarize(const mlod_skeleton *s, const mlod_joint_info *info)
{
	struct stats st = {0};
	for (int j = 0; j < s->joint_count; j++) {
		st.avg_neighbors += info[j].neighbors;
		st.avg_depth += info[j].depth;
		st.count[info[j].label]++;
	}
	st.avg_neighbors /= s->joint_count;
	st.avg_depth /= s->joint_count;
	return st;
}

static const char *parent_name(const mlod_skeleton *s, int j)
{
	int p = s->joints[j].parent;
	return p >= 0 ? s->joints[p].name : "-";
}

static void report_table(const char *input, const mlod_character *c, const mlod_joint_info *info,
                         const mlod_label_options *opt)
{
	const mlod_skeleton *s = &c->skeleton;
	struct stats st = summarize(s, info);
	int w = 5;
	for (int j = 0; j < s->joint_count; j++) {
		int n = tool_name_width(s->joints[j].name);
		if (n > w)
			w = n;
	}
	fputs("# ", stdout);
	tool_put_name(stdout, input, 0);
	printf(": %d joints, %d clips; hub factor %g, average neighbours %.3f, average depth %.3f\n", s->joint_count, c->clip_count, opt->hub_factor, st.avg_neighbors, st.avg_depth);
	printf("%-*s  %-*s  %5s  %10s  %-14s  %10s\n", w, "joint", w, "parent", "depth", "neighbours",
	       "label", "energy");
	for (int j = 0; j < s->joint_count; j++) {
		char label[32];
		snprintf(label, sizeof label, "%s %s", mlod_label_symbol(info[j].label), mlod_label_name(info[j].label));
		/* The Greek letter is 2 bytes but 1 column wide. */
		tool_put_name(stdout, s->joints[j].name, w);
		fputs("  ", stdout);
		tool_put_name(stdout, parent_name(s, j), w);
		printf("  %5d  %10d  %-15s  %10.4f\n", info[j].depth, info[j].neighbors, label, info[j].energy);
	}
	printf("# root %d, end-effector %d, major %d, extreme %d, minor %d\n", st.count[MLOD_LABEL_ROOT],
	       st.count[MLOD_LABEL_END_EFFECTOR], st.count[MLOD_LABEL_MAJOR], st.count[MLOD_LABEL_EXTREME],
	       st.count[MLOD_LABEL_MINOR]);
	if (c->notes && *c->notes)
		tool_put_lines(stdout, "# note: ", c->notes);
}

static void report_json(const char *input, const mlod_character *c, const mlod_joint_info *info,
                        const mlod_label_options *opt, double max_angle_degrees)
{
	const mlod_skeleton *s = &c->skeleton;
	struct stats st = summarize(s, info);
	printf("{\n  \"input\": ");
	tool_json_string(stdout, input);
	/* max_angle in degrees, as --max-angle took it (opt holds radians). */
	printf(",\n  \"hub_factor\": %.17g,\n  \"max_angle\": %.17g,\n", opt->hub_factor, max_angle_degrees);
	printf("  \"average_neighbors\": %.17g,\n  \"average_depth\": %.17g,\n", st.avg_neighbors, st.avg_depth);
	printf("  \"clips\": %d,\n  \"notes\": ", c->clip_count);
	tool_json_string(stdout, c->notes ? c->notes : "");
	printf(",\n  \"joints\": [\n");
	for (int j = 0; j < s->joint_count; j++) {
		printf("    {\"name\": ");
		tool_json_string(stdout, s->joints[j].name);
		printf(", \"parent\": ");
		if (s->joints[j].parent >= 0)
			tool_json_string(stdout, parent_name(s, j));
		else
			printf("null");
		printf(", \"depth\": %d, \"children\": %d, \"neighbors\": %d, \"label\": \"%s\", "
		       "\"weight\": %.17g, \"energy\": %.17g}%s\n",
		       info[j].depth, info[j].children, info[j].neighbors, mlod_label_name(info[j].label),
		       info[j].weight, info[j].energy, j + 1 < s->joint_count ? "," : "");
	}
	printf("  ]\n}\n");
}

int main(int argc, char **argv)
{
	static const struct option longopts[] = {
		{"output", required_argument, NULL, 'o'},
		{"report", optional_argument, NULL, 'r'},
		{"hub-factor", required_argument, NULL, 'H'},
		{"max-angle", required_argument, NULL, 'A'},
		{"help", no_argument, NULL, 'h'},
		{"version", no_argument, NULL, 'V'},
		{NULL, 0, NULL, 0},
	};
	const char *output = NULL;
	enum tool_report report = REPORT_NONE;
	mlod_label_options opt = {MLOD_LABEL_HUB_FACTOR_DEFAULT, MLOD_LABEL_MAX_ANGLE_DEFAULT * MLOD_PI / 180.0};
	double max_angle_degrees = MLOD_LABEL_MAX_ANGLE_DEFAULT;
	int ch;

	tool_name = "mlod-label";
	static const char shortopts[] = ":o:r::hV";
	opterr = 0;
	while ((ch = getopt_long(argc, argv, shortopts, longopts, NULL)) != -1) {
		switch (ch) {
		case 'o': output = optarg; break;
		case 'r': report = tool_parse_report(optarg); break;
		case 'H': opt.hub_factor = tool_parse_double("--hub-factor", optarg, 1e-6, 1e6); break;
		case 'A':
			max_angle_degrees = tool_parse_double("--max-angle", optarg, 1e-3, 1e6);
			opt.max_angle = max_angle_degrees * MLOD_PI / 180.0;
			break;
		case 'h': printf(usage_text, MLOD_LABEL_HUB_FACTOR_DEFAULT, MLOD_LABEL_MAX_ANGLE_DEFAULT); return 0;
		case 'V': tool_version();
		default: tool_option_error(ch, shortopts, argv);
		}
	}
	if (argc - optind > 1)
		tool_usage_error("too many inputs: one file, or stdin");
	const char *input = optind < argc ? argv[optind] : NULL;
	if (report != REPORT_NONE && output)
		tool_usage_error("--report and --output do not go together");

	mlod_gltf *doc = NULL;
	mlod_character c = {0};
	tool_load(input, report == REPORT_NONE ? &doc : NULL, &c, NULL);

	if (c.skeleton.joint_count == 0 && report == REPORT_NONE) {
		/* A static prop: nothing to label; pass it through. */
		tool_note(tool_input_label(input), "no joints: nothing to label; written unchanged");
		tool_write_gltf(output, doc);
		mlod_character_free(&c);
		mlod_gltf_free(doc);
		return 0;
	}
	mlod_joint_info *info = calloc((size_t)c.skeleton.joint_count + 1, sizeof *info);
	mlod_error err = {0};
	if (!info)
		tool_die(EXIT_INPUT, tool_input_label(input), "out of memory");
	mlod_result r = mlod_label_skeleton(&c, &opt, info, &err);
	if (r != MLOD_OK)
		tool_die(tool_exit_code(r), tool_input_label(input), "%s", err.message);

	if (report == REPORT_TABLE) {
		report_table(tool_input_label(input), &c, info, &opt);
	} else if (report == REPORT_JSON) {
		report_json(tool_input_label(input), &c, info, &opt, max_angle_degrees);
	} else {
		if ((r = mlod_record_write_joints(doc, &c, info, &err)) != MLOD_OK)
			tool_die(EXIT_OUTPUT, NULL, "%s", err.message);
		tool_write_gltf(output, doc);
	}
	if (fflush(stdout) != 0)
		tool_die(EXIT_OUTPUT, "<stdout>", "write error");
	free(info);
	mlod_character_free(&c);
	mlod_gltf_free(doc);
	return 0;
}
