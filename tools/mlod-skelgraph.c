/*
 * mlod-skelgraph: builds the Multiresolution Skeletal Graph and extracts
 * nested skeleton levels (paper 4.1.3), with folded motion, transferred
 * skin weights and the measured error of each level.
 *
 * Output: a glb where each level is recorded in extras.mlod of the skins
 * and the scene, and becomes a real glTF skin over the kept joints (plus a
 * mesh with the transferred weights); or, with --level K, a BVH of level K;
 * or a report.
 */
#define _GNU_SOURCE /* getopt_long */

#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common.h"

/* A printf format: the default comes from the library. */
static const char usage_text[] =
	"usage: mlod-skelgraph [options] [input]\n"
	"\n"
	"Builds the Multiresolution Skeletal Graph of a character and extracts nested\n"
	"skeleton levels by joint energy. Input is glb, glTF or BVH (labels come from\n"
	"mlod-label's extras when present). Output is a glb with the levels.\n"
	"\n"
	"options:\n"
	"  -o, --output FILE       write to FILE instead of stdout; a .bvh name writes\n"
	"                          the level chosen by --level as BVH\n"
	"  -r, --report[=FORMAT]   print the levels instead; FORMAT is table or json\n"
	"  -t, --thresholds LIST   levels at these energy thresholds (E1,E2,...)\n"
	"  -j, --joints LIST       levels keeping these fractions of the joints (0.8,0.6);\n"
	"                          not threads, as -j is in mlod-bgm, mlod-motion and\n"
	"                          mlod-pack: mlod-skelgraph runs on one thread\n"
	"  -e, --max-error PCT     default levels stop before the error exceeds PCT\n"
	"                          percent of the skeleton height, the rest-pose\n"
	"                          joints' extent along +Y (default %g)\n"
	"  -l, --level K           with a .bvh output: the level to write (0 = full)\n"
	"  -c, --clip N            with a .bvh output: the clip to write (default 0)\n"
	"      --hub-factor F      labels' hub factor when they are computed (1.9)\n"
	"  -h, --help              show this help\n"
	"  -V, --version           show the version\n"
	"\n"
	"Default levels aim at removing 13%%, 26%% and 39%% of the joints (the paper's\n"
	"figure) and stop at the last level within --max-error: fewer levels, or\n"
	"less removed, where the bound cuts the chain (tubeman: 13%% and 23%%).\n"
	"\n"
	"exit status: 0 success, 1 usage, 2 bad input, 3 unsupported input,\n"
	"4 output failure.\n" TOOL_OUTPUT_NOTE;

struct job {
	const char *input;
	mlod_character c;
	mlod_joint_info *info;
	int labels_from_extras;
	mlod_skel_levels L;
	char notes[256]; /* what was said on stderr of the levels, for the reports */
};

static void removed_names(FILE *f, const struct job *job, const mlod_skel_built *lv, int json)
{
	const mlod_skeleton *s = &job->c.skeleton;
	int first = 1;
	for (int j = 0; j < s->joint_count; j++) {
		if (lv->skel.kept[j])
			continue;
		if (json) {
			fputs(first ? "" : ", ", f);
			tool_json_string(f, s->joints[j].name);
		} else {
			fputs(first ? "" : " ", f);
			tool_put_name(f, s->joints[j].name, 0);
		}
		first = 0;
	}
}

static void report_table(const struct job *job)
{
	const mlod_skeleton *s = &job->c.skeleton;
	int minors = 0;
	for (int j = 0; j < s->joint_count; j++)
		minors += job->info[j].label == MLOD_LABEL_MINOR;
	fputs("# ", stdout);
	tool_put_name(stdout, job->input, 0);
	printf(": %d joints (%d minor) in %d sub-chains, %d closure edges; height %.4g; %d clips; labels %s\n", s->joint_count, minors, job->L.graph.chain_count, job->L.graph.edge_count, job->L.height,
	       job->c.clip_count, job->labels_from_extras ? "from extras" : "computed");
	printf("%5s  %12s  %6s  %7s  %10s  %10s  %10s  %10s  %6s\n", "level", "threshold", "joints", "removed",
	       "vtx max%", "vtx mean%", "jnt max%", "jnt mean%", "shear");
	printf("%5d  %12s  %6d  %7s  %10s  %10s  %10s  %10s  %6s\n", 0, "-", s->joint_count, "0%", "0", "0", "0",
	       "0", "0");
	for (int k = 0; k < job->L.count; k++) {
		const mlod_skel_built *lv = &job->L.levels[k];
		char vmax[32] = "-", vmean[32] = "-", removed[16];
		if (lv->has_mesh_error) {
			snprintf(vmax, sizeof vmax, "%.4f", lv->vertex.max);
			snprintf(vmean, sizeof vmean, "%.4f", lv->vertex.mean);
		}
		snprintf(removed, sizeof removed, "%.0f%%",
		         100.0 * (s->joint_count - lv->skel.kept_count) / s->joint_count);
		printf("%5d  %12.6g  %6d  %7s  %10s  %10s  %10.4f  %10.4f  %6d\n", k + 1, lv->skel.threshold,
		       lv->skel.kept_count, removed, vmax, vmean, 100.0 * lv->joint.max / job->L.height,
		       100.0 * lv->joint.mean / job->L.height, lv->stats.shear_samples);
	}
	for (int k = 0; k < job->L.count; k++) {
		printf("# level %d removes: ", k + 1);
		removed_names(stdout, job, &job->L.levels[k], 0);
		putchar('\n');
	}
	printf("# vtx: skinned-vertex deviation over the clips, %% of the bounding diagonal;"
	       " jnt: removed joints following their stand-ins, %% of the height\n");
	if (job->notes[0])
		tool_put_line(stdout, "# note: ", job->notes);
	if (job->c.notes && *job->c.notes)
		tool_put_lines(stdout, "# note: ", job->c.notes);
}

static void report_json(const struct job *job)
{
	const mlod_skeleton *s = &job->c.skeleton;
	printf("{\n  \"input\": ");
	tool_json_string(stdout, job->input);
	printf(",\n  \"joints\": %d,\n  \"chains\": %d,\n  \"closure_edges\": %d,\n  \"height\": %.9g,\n",
	       s->joint_count, job->L.graph.chain_count, job->L.graph.edge_count, job->L.height);
	printf("  \"labels\": \"%s\",\n  \"levels\": [\n", job->labels_from_extras ? "extras" : "computed");
	for (int k = 0; k < job->L.count; k++) {
		const mlod_skel_built *lv = &job->L.levels[k];
		printf("    {\"level\": %d, \"threshold\": %.9g, \"kept\": %d, \"removed\": [", k + 1,
		       lv->skel.threshold, lv->skel.kept_count);
		removed_names(stdout, job, lv, 1);
		printf("],\n     \"joint_error\": {\"max\": %.9g, \"mean\": %.9g, \"max_percent_height\": %.9g},\n",
		       lv->joint.max, lv->joint.mean, 100.0 * lv->joint.max / job->L.height);
		if (lv->has_mesh_error)
			printf("     \"vertex_error\": {\"max_percent_diagonal\": %.9g, \"mean_percent_diagonal\": %.9g},\n",
			       lv->vertex.max, lv->vertex.mean);
		printf("     \"shear_samples\": %d, \"weight_merges\": %d}%s\n", lv->stats.shear_samples,
		       lv->stats.weight_merges, k + 1 < job->L.count ? "," : "");
	}
	/* The level note and the input's notes, as one string (as the other
	 * tools' "notes"). */
	const char *in = job->c.notes ? job->c.notes : "";
	char *notes = malloc(strlen(job->notes) + strlen(in) + 3);
	if (!notes)
		tool_die(EXIT_OUTPUT, NULL, "out of memory");
	sprintf(notes, "%s%s%s", job->notes, job->notes[0] && in[0] ? "; " : "", in);
	printf("  ],\n  \"notes\": ");
	tool_json_string(stdout, notes);
	printf("\n}\n");
	free(notes);
}

static void write_bvh(const struct job *job, const char *output, int level, int clip)
{
	const mlod_character *c = level == 0 ? &job->c : &job->L.levels[level - 1].c;
	char *text = NULL;
	size_t size = 0;
	mlod_error err = {0};
	if (clip >= c->clip_count)
		tool_die(EXIT_USAGE, NULL, "--clip %d: the input has %d clips", clip, c->clip_count);
	mlod_result r = mlod_bvh_write(c, clip, 0.0f, &text, &size, &err);
	if (r != MLOD_OK)
		tool_die(r == MLOD_ERR_UNSUPPORTED ? EXIT_UNSUPPORTED : EXIT_OUTPUT, output, "%s", err.message);
	tool_write_output(output, text, size, 0);
	mlod_free(text);
	/* What the BVH cannot hold. */
	char note[MLOD_SKEL_BVH_NOTE_SIZE];
	double max;
	int joint;
	if (mlod_skel_bvh_end_sites(c, clip, &max, &joint, note, sizeof note, &err) != MLOD_OK)
		tool_die(tool_exit_code(err.code), job->input, "%s", err.message);
	if (note[0])
		tool_note(job->input, "%s", note);
}

/* Adds the levels and their record to the document and writes it. */
static void write_glb(struct job *job, mlod_gltf *doc, const char *output)
{
	const mlod_skeleton *s = &job->c.skeleton;
	int n = job->L.count, sc = s->skin_count;
	mlod_error err = {0};
	mlod_record stage;
	mlod_result r = mlod_record_read(doc, &stage, &err);
	if (r != MLOD_OK)
		tool_die(tool_exit_code(r), job->input, "%s", err.message);
	const int mesh_levels = stage.mesh_level_count, skel_levels = stage.skel_level_count;
	mlod_record_free(&stage);
	if (skel_levels > 0) {
		/* Levels on top of levels would leave the old ones unused: pass it through. */
		tool_note(job->input, "the input already has %d skeleton level%s: written unchanged; run %s on the input "
		        "without them to bake them again", skel_levels, skel_levels == 1 ? "" : "s",
		        tool_name);
		tool_write_gltf(output, doc);
		return;
	}
	mlod_skel_level_record records[MLOD_SKEL_MAX_LEVELS];
	mlod_record_skel_level rec[MLOD_SKEL_MAX_LEVELS];
	int *skins = malloc(sizeof(int) * ((size_t)n * (size_t)sc + 1)), *full = malloc(sizeof(int) * ((size_t)sc + 1));
	if (!skins || !full)
		tool_die(EXIT_OUTPUT, NULL, "out of memory");
	for (int i = 0; i < sc; i++)
		full[i] = s->skins[i].gltf_index;
	mlod_skel_levels_records(&job->L, records);
	/* Mesh levels already in MSFT_lod (mlod-bgm ran first) stay there. */
	if (mesh_levels > 0 && n > 0)
		tool_note(job->input, "the input's %d mesh level(s) stay in MSFT_lod, weighted on the full skeleton; "
		          "run mlod-skelgraph before mlod-bgm for mesh levels on the skeleton levels", mesh_levels);
	if ((r = mlod_gltf_add_skel_levels(doc, &job->c, records, n, skins, mesh_levels == 0, &err)) != MLOD_OK ||
	    (r = mlod_record_skel_levels_make(&job->c, records, n, skins, rec, &err)) != MLOD_OK)
		tool_die(r == MLOD_ERR_UNSUPPORTED ? EXIT_UNSUPPORTED : EXIT_INPUT, job->input, "%s", err.message);
	r = mlod_record_write_skeleton(doc, rec, n, full, sc, &err);
	for (int k = 0; k < n; k++)
		mlod_record_skel_level_free(&rec[k]);
	free(skins);
	free(full);
	if (r != MLOD_OK)
		tool_die(r == MLOD_ERR_UNSUPPORTED ? EXIT_UNSUPPORTED : EXIT_INPUT, job->input, "%s", err.message);
	tool_write_gltf(output, doc);
}

int main(int argc, char **argv)
{
	static const struct option longopts[] = {
		{"output", required_argument, NULL, 'o'},
		{"report", optional_argument, NULL, 'r'},
		{"thresholds", required_argument, NULL, 't'},
		{"joints", required_argument, NULL, 'j'},
		{"max-error", required_argument, NULL, 'e'},
		{"level", required_argument, NULL, 'l'},
		{"clip", required_argument, NULL, 'c'},
		{"hub-factor", required_argument, NULL, 'H'},
		{"help", no_argument, NULL, 'h'},
		{"version", no_argument, NULL, 'V'},
		{NULL, 0, NULL, 0},
	};
	const char *output = NULL;
	enum tool_report report = REPORT_NONE;
	double thresholds[MLOD_SKEL_MAX_LEVELS], fractions[MLOD_SKEL_MAX_LEVELS];
	int threshold_count = -1, fraction_count = -1, level = -1, clip = 0, clip_given = 0;
	double max_error = MLOD_SKEL_MAX_ERROR_DEFAULT;
	mlod_label_options lopt = {0};
	int ch;

	tool_name = "mlod-skelgraph";
	static const char shortopts[] = ":o:r::t:j:e:l:c:hV";
	opterr = 0;
	while ((ch = getopt_long(argc, argv, shortopts, longopts, NULL)) != -1) {
		switch (ch) {
		case 'o': output = optarg; break;
		case 'r': report = tool_parse_report(optarg); break;
		case 't': threshold_count = tool_parse_list("--thresholds", optarg, thresholds, MLOD_SKEL_MAX_LEVELS, 0.0, 1e9); break;
		case 'j':
			/* "-j 2", as the other tools' --threads: said plainly. */
			if (strspn(optarg, "0123456789") == strlen(optarg) && atoi(optarg) > 1)
				tool_usage_error("--joints: %s is out of range [0, 1]: -j here keeps fractions of the joints, "
				                 "not threads (mlod-skelgraph runs on one thread)", optarg);
			fraction_count = tool_parse_list("--joints", optarg, fractions, MLOD_SKEL_MAX_LEVELS, 0.0, 1.0);
			break;
		case 'e': max_error = tool_parse_percent("--max-error", optarg, 0.0, 1e6); break;
		case 'l': level = tool_parse_int("--level", optarg, 0, MLOD_SKEL_MAX_LEVELS); break;
		case 'c': clip = tool_parse_int("--clip", optarg, 0, 1000000), clip_given = 1; break;
		case 'H': lopt.hub_factor = tool_parse_double("--hub-factor", optarg, 1e-6, 1e6); break;
		case 'h': printf(usage_text, MLOD_SKEL_MAX_ERROR_DEFAULT); return 0;
		case 'V': tool_version();
		default: tool_option_error(ch, shortopts, argv);
		}
	}
	if (argc - optind > 1)
		tool_usage_error("too many inputs: one file, or stdin");
	if (threshold_count >= 0 && fraction_count >= 0)
		tool_usage_error("--thresholds and --joints do not go together");
	/* An equal value would bake the same level twice; --joints 1 a level
	 * that removes no joint (packed with switch distance 0). */
	if (threshold_count > 0)
		threshold_count = tool_drop_repeats("--thresholds", thresholds, NULL, threshold_count);
	if (fraction_count > 0) {
		int n = 0;
		for (int i = 0; i < fraction_count; i++)
			if (fractions[i] < 1.0)
				fractions[n++] = fractions[i];
			else
				tool_note(NULL, "--joints: 1 keeps every joint: no level");
		fraction_count = tool_drop_repeats("--joints", fractions, NULL, n);
	}
	int bvh_out = output && tool_ends_with(output, ".bvh");
	if (level >= 0 && !bvh_out)
		tool_usage_error("--level needs a .bvh output (-o out.bvh)");
	if (clip_given && !bvh_out)
		tool_usage_error("--clip needs a .bvh output (-o out.bvh)");
	if (report != REPORT_NONE && output)
		tool_usage_error("--report and --output do not go together");

	struct job job = {0};
	mlod_gltf *doc = NULL;
	mlod_error err = {0};
	job.input = tool_input_label(optind < argc ? argv[optind] : NULL);
	tool_load(optind < argc ? argv[optind] : NULL, &doc, &job.c, NULL);
	if (job.c.skeleton.joint_count == 0 && report == REPORT_NONE && !bvh_out) {
		/* A static prop: no skeleton to reduce; pass it through. */
		tool_note(job.input, "no joints: no skeleton levels; written unchanged");
		tool_write_gltf(output, doc);
		mlod_character_free(&job.c);
		mlod_gltf_free(doc);
		return 0;
	}
	job.info = calloc((size_t)job.c.skeleton.joint_count + 1, sizeof *job.info);
	if (!job.info)
		tool_die(EXIT_INPUT, job.input, "out of memory");
	mlod_result r = mlod_label_skeleton(&job.c, &lopt, job.info, &err);
	if (r != MLOD_OK)
		tool_die(tool_exit_code(r), job.input, "%s", err.message);
	if ((r = mlod_record_read_joints(doc, &job.c, job.info, &job.labels_from_extras, &err)) != MLOD_OK)
		tool_die(tool_exit_code(r), job.input, "%s", err.message);
	if ((r = mlod_skel_levels_init(&job.L, &job.c, job.info, &err)) != MLOD_OK)
		tool_die(tool_exit_code(r), job.input, "%s", err.message);

	if (threshold_count >= 0)
		r = mlod_skel_levels_thresholds(&job.L, thresholds, threshold_count, &err);
	else if (fraction_count >= 0)
		r = mlod_skel_levels_fractions(&job.L, fractions, fraction_count, &err);
	else
		r = mlod_skel_levels_default(&job.L, max_error, &err);
	if (r != MLOD_OK)
		tool_die(tool_exit_code(r), job.input, "%s", err.message);
	if (threshold_count < 0 && fraction_count < 0 && job.L.count == 0 && job.L.minor_count > 0) {
		mlod_skel_built first;
		if ((r = mlod_skel_levels_make(&job.L, -1.0, 1, &first, &err)) != MLOD_OK)
			tool_die(tool_exit_code(r), job.input, "%s", err.message);
		snprintf(job.notes, sizeof job.notes, "no skeleton level within --max-error %g%%: removing %s alone costs %.3g%%",
		         max_error, MLOD_QUOTED(job.c.skeleton.joints[job.L.order[0]].name), first.bound_error);
		tool_note(job.input, "%s", job.notes);
		mlod_skel_built_free(&first);
	}

	if (report == REPORT_TABLE)
		report_table(&job);
	else if (report == REPORT_JSON)
		report_json(&job);
	else if (bvh_out) {
		if (level < 0)
			level = job.L.count;
		if (level > job.L.count)
			tool_die(EXIT_USAGE, NULL, "--level %d: the levels are 0..%d", level, job.L.count);
		write_bvh(&job, output, level, clip);
	} else
		write_glb(&job, doc, output);

	if (fflush(stdout) != 0)
		tool_die(EXIT_OUTPUT, "<stdout>", "write error");
	mlod_skel_levels_free(&job.L);
	free(job.info);
	mlod_character_free(&job.c);
	mlod_gltf_free(doc);
	return 0;
}
