/*
 * mlod-bgm: the mesh layer (paper 4.2): builds the BindGraphMesh of every
 * triangle primitive of a character, records its triangle collapses
 * (Power Skinning giving the new vertices their weights), and writes
 * discrete levels: by triangle ratio (the default, 50%, 25% and 10%) or
 * down to a measured posed error.
 *
 * Output: a glb where each simplified mesh node lists one node per level
 * in MSFT_lod (with MSFT_screencoverage from each level's measured error);
 * level nodes use the node's skin, or the matching skeleton level's skin
 * when mlod-skelgraph ran before; rigid meshes under a joint become meshes
 * skinned to it with weight 1; static meshes (no joint, no skin) keep the
 * node's transform; level nodes that keep morph targets get copies of the
 * node's weight animation channels. Or a report. --split also writes one
 * glb per level: the input document with that level's meshes in place.
 */
#define _GNU_SOURCE /* getopt_long */

#include <errno.h>
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "common.h"

static const char usage_text[] =
	"usage: mlod-bgm [options] [input]\n"
	"\n"
	"Simplifies the meshes of a character with the BindGraphMesh, triangle (or\n"
	"edge) collapses and Power Skinning (Savoye & Meyer 2008, 4.2). Input is glb or\n"
	"glTF (BVH has no mesh and passes through). Output is a glb whose mesh nodes\n"
	"carry their levels in MSFT_lod.\n"
	"\n"
	"options:\n"
	"  -o, --output FILE        write to FILE instead of stdout\n"
	"  -r, --report[=FORMAT]    print the levels instead; FORMAT is table or json\n"
	"  -R, --ratios LIST        levels keeping these fractions of the triangles\n"
	"                           (default %s)\n"
	"  -e, --max-error PCT      levels halving the triangles down to the coarsest\n"
	"                           whose posed error stays within PCT percent of the\n"
	"                           bounding diagonal\n"
	"  -c, --cost NAME          collapse order: posed (default) or compactness\n"
	"  -C, --collapse NAME      what collapses: edge (the default with the posed\n"
	"                           cost), triangle (the paper; the only one with\n"
	"                           compactness) or mixed (both, by cost per face)\n"
	"  -B, --budget NAME        a level's triangles: character (shared by all\n"
	"                           primitives, cheapest collapses first; the posed\n"
	"                           cost only, its default) or primitive (each keeps\n"
	"                           the ratio; the default with compactness)\n"
	"  -p, --placement NAME     new vertex: optimal (default), barycenter, vertex\n"
	"                           (one of the collapsed vertices kept whole: coarse\n"
	"                           levels reuse level-0 vertices) or hybrid[=PCT] (one\n"
	"                           kept whole where that costs no more than optimal or\n"
	"                           within PCT%% of the diagonal, default 0.1)\n"
	"  -E, --eligibility NAME   vertices that may go: all, bend or literal\n"
	"                           (default: all with the posed cost, bend otherwise)\n"
	"  -t, --tau T              eligibility threshold factor (default 1)\n"
	"  -b, --allow-border       rank collapses along open borders at their plain\n"
	"                           posed cost (default: 50 times it)\n"
	"  -F, --fast-cost          posed cost: pull each vertex's posed quadrics back\n"
	"                           into bind space with its own weights (faster; the\n"
	"                           new vertex's weights no longer count, some more\n"
	"                           posed error)\n"
	"  -I, --influence-budget F drop influences of a level's skinned vertices\n"
	"                           while each moves at most F times the level's mean\n"
	"                           posed error at every training pose; the level is\n"
	"                           measured again (0, the default: off; 2 is\n"
	"                           measured in bench/RESULTS.md; not with -e)\n"
	"  -s, --split DIR          also write one glb per level into DIR (made if\n"
	"                           missing, not its parents): DIR/NAME.lodK.glb, the\n"
	"                           input with that level's meshes in place; NAME is\n"
	"                           the input's, from stdin -o's (a regular file's),\n"
	"                           else stdin\n"
	"  -j, --threads N          work on N threads (default: the processors it may\n"
	"                           run on, its CPU affinity);\n"
	"                           the output is the same at any N\n"
	"  -h, --help               show this help\n"
	"  -V, --version            show the version\n"
	"\n"
	"exit status: 0 success, 1 usage, 2 bad input, 3 unsupported input,\n"
	"4 output failure.\n" TOOL_OUTPUT_NOTE;

/* A level as the stage record lists it. */
static mlod_record_mesh_level level_record(const mlod_mesh_level *lv, int k)
{
	mlod_record_mesh_level r = {.level = k + 1, .ratio = lv->ratio, .triangles = lv->triangles,
	                            .vertices = lv->vertices, .error = lv->error};
	return r;
}

struct job {
	const char *input;
	mlod_character c;
	mlod_mesh_levels L;
};

static int double_desc(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return (x < y) - (x > y);
}

/* The skeleton levels of mlod-skelgraph, when the input has them: mesh
 * level k follows skeleton level k. */
static void follow_skeleton(struct job *job, const mlod_record *rec, mlod_mesh_skeleton *sk)
{
	mlod_error err = {0};
	for (int k = 0; k < rec->skel_level_count; k++)
		mlod_record_mesh_skeleton(&rec->skel_levels[k], &sk[k]);
	if (mlod_mesh_levels_follow(&job->L, sk, rec->skel_level_count, &err) != MLOD_OK)
		tool_die(EXIT_INPUT, job->input, "%s", err.message);
}

/* Writes the levels under MSFT_lod, and their record. */
static void write_glb(struct job *job, mlod_gltf *doc, const char *output)
{
	mlod_error err = {0};
	mlod_mesh_lod lod;
	mlod_record_mesh_level rec[MLOD_MESH_MAX_LEVELS];
	/* Adding the levels to the document in memory: its failure is the
	 * input's (or memory's), not the output file's, nor a usage error. */
	mlod_result r = mlod_mesh_levels_write(&job->L, doc, &lod, &err);
	if (r != MLOD_OK)
		tool_die(r == MLOD_ERR_UNSUPPORTED ? EXIT_UNSUPPORTED : EXIT_INPUT, job->input, "%s", err.message);
	tool_note_items(job->input, job->L.notes, "stay outside the level list"); /* the input's own MSFT_lod */
	for (int k = 0; k < job->L.count; k++)
		rec[k] = level_record(&job->L.levels[k], k);
	if ((r = mlod_record_write_mesh_nodes(doc, &job->L, &lod, &err)) != MLOD_OK ||
	    (job->L.count > 0 && (r = mlod_record_write_mesh_levels(doc, rec, job->L.count, &err)) != MLOD_OK))
		tool_die(r == MLOD_ERR_UNSUPPORTED ? EXIT_UNSUPPORTED : EXIT_INPUT, job->input, "%s", err.message);
	mlod_mesh_lod_free(&lod);
	tool_write_gltf(output, doc);
}

/* Whether -o names a file whose name can stand for the input's: a
 * regular file or a new one, not a device, FIFO or socket (-o /dev/null
 * gave null.lod1.glb) nor standard output. */
static int output_names_file(const char *output)
{
	struct stat st;
	if (!output || strcmp(output, "-") == 0 || tool_output_is_stdout(output))
		return 0;
	return stat(output, &st) != 0 ? errno == ENOENT : S_ISREG(st.st_mode);
}

/* One glb per level in dir (made when missing, not its parents):
 * DIR/<name>.lod<k>.glb, name the input file's without its extension; from
 * stdin -o's (a regular or new file's), else "stdin". */
static void write_split(struct job *job, const mlod_gltf *input, const char *dir, const char *input_path,
                        const char *output)
{
	struct stat st;
	if (stat(dir, &st) != 0) {
		if (errno != ENOENT || mkdir(dir, 0777) != 0)
			tool_die(EXIT_OUTPUT, dir, "cannot create the directory: %s", strerror(errno));
	} else if (!S_ISDIR(st.st_mode)) {
		tool_die(EXIT_OUTPUT, dir, "not a directory");
	}
	const char *from = input_path && strcmp(input_path, "-") != 0 ? input_path
	                   : output_names_file(output)               ? output
	                                                              : "stdin";
	const char *base = strrchr(from, '/');
	base = base ? base + 1 : from;
	size_t blen = strlen(base);
	const char *dot = strrchr(base, '.');
	if (dot && dot != base)
		blen = (size_t)(dot - base);
	int unpruned = 0;
	for (int k = 0; k < job->L.count; k++) {
		mlod_gltf *doc = NULL;
		mlod_error err = {0};
		mlod_record_mesh_level rec = level_record(&job->L.levels[k], k);
		if (mlod_mesh_levels_split(&job->L, input, k, &doc, &unpruned, &err) != MLOD_OK ||
		    mlod_record_write_mesh_split(doc, &rec, &err) != MLOD_OK)
			tool_die(EXIT_OUTPUT, dir, "level %d: %s", k + 1, err.message);
		size_t n = strlen(dir) + blen + 32;
		char *path = malloc(n);
		if (!path)
			tool_die(EXIT_OUTPUT, dir, "out of memory");
		snprintf(path, n, "%s/%.*s.lod%d.glb", dir, (int)blen, base, k + 1);
		tool_write_gltf(path, doc);
		free(path);
		mlod_gltf_free(doc);
	}
}

static void report_table(const struct job *job)
{
	const mlod_mesh_levels *L = &job->L;
	mlod_bgm_info t;
	mlod_mesh_levels_totals(L, &t);
	fputs("# ", stdout);
	tool_put_name(stdout, job->input, 0);
	printf(": %d triangles, %d vertices (%d welded nodes, %d on seams, %d eligible, %d locked); "
	       "%d border and %d non-manifold edges; %d primitives simplified; build %.1f ms\n", L->triangles, L->vertices, t.nodes, t.seam_nodes, t.eligible_nodes, t.locked_nodes,
	       t.border_edges, t.nonmanifold_edges, L->simplified, 1e3 * L->build_seconds);
	char whole[48] = "";
	if (L->opt.placement == MLOD_PLACE_HYBRID)
		snprintf(whole, sizeof whole, " (whole within %g%%)", L->opt.hybrid_error);
	printf("# cost %s%s, %s collapses, budget per %s, placement %s%s, eligibility %s (tau %g)%s, influence budget %g; error "
	       "over %d poses (rest, clip frames, %d random up to 40 degrees)\n",
	       mlod_mesh_cost_name(L->opt.cost), L->opt.fast_cost && L->opt.cost == MLOD_COST_POSED ? " (fast)" : "",
	       mlod_mesh_op_name(L->opt.op), mlod_mesh_budget_name(L->budget), mlod_mesh_placement_name(L->opt.placement),
	       whole, mlod_mesh_eligibility_name(L->opt.eligibility), L->opt.tau,
	       L->opt.allow_border ? ", border collapses at plain cost" : "",
	       L->opt.influence_budget > 0.0 ? L->opt.influence_budget : 0.0, L->measure.count, MLOD_MESH_RANDOM_POSES);
	printf("%5s  %6s  %9s  %8s  %10s  %10s  %5s  %9s  %11s\n", "level", "ratio", "triangles", "vertices", "mean%",
	       "max%", "caps", "build ms", "collapse ms");
	printf("%5d  %6s  %9d  %8d  %10s  %10s  %5s  %9s  %11s\n", 0, "1", L->triangles, L->vertices, "0", "0", "-",
	       "-", "-");
	for (int k = 0; k < L->count; k++) {
		const mlod_mesh_level *lv = &L->levels[k];
		printf("%5d  %6.4g  %9d  %8d  %10.4f  %10.4f  %5d  %9.1f  %11.1f\n", k + 1, lv->ratio, lv->triangles,
		       lv->vertices, lv->error.mean, lv->error.max, lv->caps, 1e3 * L->build_seconds,
		       1e3 * lv->collapse_seconds);
	}
	printf("# mean%%, max%%: posed surface deviation (mean, Hausdorff) in %% of the bounding diagonal; caps: new "
	       "vertices whose influences were cut to 4\n");
	if (L->notes[0])
		tool_put_line(stdout, "# note: ", L->notes);
	if (job->c.notes && *job->c.notes)
		tool_put_lines(stdout, "# input: ", job->c.notes);
}

static void report_json(const struct job *job)
{
	const mlod_mesh_levels *L = &job->L;
	mlod_bgm_info t;
	mlod_mesh_levels_totals(L, &t);
	printf("{\n  \"input\": ");
	tool_json_string(stdout, job->input);
	printf(",\n  \"triangles\": %d,\n  \"vertices\": %d,\n  \"nodes\": %d,\n  \"seam_nodes\": %d,\n", L->triangles,
	       L->vertices, t.nodes, t.seam_nodes);
	printf("  \"border_edges\": %d,\n  \"nonmanifold_edges\": %d,\n  \"locked_nodes\": %d,\n  \"eligible_nodes\": %d,\n",
	       t.border_edges, t.nonmanifold_edges, t.locked_nodes, t.eligible_nodes);
	printf("  \"simplified_primitives\": %d,\n  \"static_primitives\": %d,\n  \"build_ms\": %.6g,\n  \"measure_ms\": %.6g,\n",
	       L->simplified, L->statics, 1e3 * L->build_seconds, 1e3 * L->measure_seconds);
	printf("  \"options\": {\"cost\": \"%s\", \"collapse\": \"%s\", \"budget\": \"%s\", \"placement\": \"%s\", "
	       "\"hybrid_error\": %g, \"eligibility\": \"%s\", \"tau\": %g, \"allow_border\": %s, \"fast_cost\": %s, "
	       "\"influence_budget\": %g},\n",
	       mlod_mesh_cost_name(L->opt.cost), mlod_mesh_op_name(L->opt.op), mlod_mesh_budget_name(L->budget),
	       mlod_mesh_placement_name(L->opt.placement),
	       L->opt.placement == MLOD_PLACE_HYBRID ? L->opt.hybrid_error : 0.0,
	       mlod_mesh_eligibility_name(L->opt.eligibility), L->opt.tau, L->opt.allow_border ? "true" : "false", L->opt.fast_cost ? "true" : "false",
	       L->opt.influence_budget > 0.0 ? L->opt.influence_budget : 0.0);
	printf("  \"measured_poses\": %d,\n  \"levels\": [\n", L->measure.count);
	for (int k = 0; k < L->count; k++) {
		const mlod_mesh_level *lv = &L->levels[k];
		printf("    {\"level\": %d, \"ratio\": %.6g, \"triangles\": %d, \"vertices\": %d, "
		       "\"error_percent\": {\"mean\": %.9g, \"max\": %.9g}, \"caps\": %d, \"collapses\": %d, "
		       "\"build_ms\": %.6g, \"collapse_ms\": %.6g}%s\n",
		       k + 1, lv->ratio, lv->triangles, lv->vertices, lv->error.mean, lv->error.max, lv->caps, lv->collapses,
		       1e3 * L->build_seconds, 1e3 * lv->collapse_seconds, k + 1 < L->count ? "," : "");
	}
	printf("  ],\n  \"notes\": ");
	tool_json_string(stdout, L->notes);
	printf("\n}\n");
}

static int parse_enum(const char *option, const char *value, const char *const *names, int count)
{
	for (int i = 0; i < count; i++)
		if (strcmp(value, names[i]) == 0)
			return i;
	tool_usage_error("%s: unknown value '%s'", option, value);
}

int main(int argc, char **argv)
{
	static const struct option longopts[] = {
		{"output", required_argument, NULL, 'o'},
		{"report", optional_argument, NULL, 'r'},
		{"ratios", required_argument, NULL, 'R'},
		{"max-error", required_argument, NULL, 'e'},
		{"cost", required_argument, NULL, 'c'},
		{"collapse", required_argument, NULL, 'C'},
		{"budget", required_argument, NULL, 'B'},
		{"placement", required_argument, NULL, 'p'},
		{"eligibility", required_argument, NULL, 'E'},
		{"tau", required_argument, NULL, 't'},
		{"allow-border", no_argument, NULL, 'b'},
		{"fast-cost", no_argument, NULL, 'F'},
		{"influence-budget", required_argument, NULL, 'I'},
		{"split", required_argument, NULL, 's'},
		{"threads", required_argument, NULL, 'j'},
		{"help", no_argument, NULL, 'h'},
		{"version", no_argument, NULL, 'V'},
		{NULL, 0, NULL, 0},
	};
	static const char *const costs[] = {"compactness", "posed"};
	static const char *const ops[] = {"triangle", "edge", "mixed"};
	static const char *const budgets[] = {"character", "primitive"};
	static const char *const rules[] = {"literal", "bend", "all"};
	static const double defaults[] = {MLOD_MESH_RATIOS_DEFAULT};
	const char *output = NULL, *split = NULL;
	enum tool_report report = REPORT_NONE;
	double ratios[MLOD_MESH_MAX_LEVELS], max_error = -1.0;
	int ratio_count = 0, ch;
	mlod_bgm_options opt = {0};
	opt.threads = mlod_thread_count();
	mlod_mesh_budget budget = MLOD_BUDGET_DEFAULT;
	struct job job;
	memset(&job, 0, sizeof job);

	tool_name = "mlod-bgm";
	static const char shortopts[] = ":o:r::R:e:c:C:B:p:E:t:bFI:s:j:hV";
	opterr = 0;
	while ((ch = getopt_long(argc, argv, shortopts, longopts, NULL)) != -1) {
		switch (ch) {
		case 'o': output = optarg; break;
		case 'r': report = tool_parse_report(optarg); break;
		case 'R': ratio_count = tool_parse_list("--ratios", optarg, ratios, MLOD_MESH_MAX_LEVELS, 1e-6, 1.0); break;
		case 'e': max_error = tool_parse_percent("--max-error", optarg, 0.0, 100.0); break;
		case 'c': opt.cost = (mlod_mesh_cost)(MLOD_COST_COMPACTNESS + parse_enum("--cost", optarg, costs, 2)); break;
		case 'C': opt.op = (mlod_collapse_op)(MLOD_OP_TRIANGLE + parse_enum("--collapse", optarg, ops, 3)); break;
		case 'B': budget = (mlod_mesh_budget)(MLOD_BUDGET_CHARACTER + parse_enum("--budget", optarg, budgets, 2)); break;
		case 'p':
			if (mlod_mesh_placement_parse(optarg, &opt.placement, &opt.hybrid_error))
				tool_usage_error("--placement: unknown value '%s' (optimal, barycenter, vertex, hybrid or "
				                 "hybrid=PCT, 0 < PCT <= 100)", optarg);
			break;
		case 'E':
			opt.eligibility = (mlod_eligibility)(MLOD_ELIGIBLE_LITERAL + parse_enum("--eligibility", optarg, rules, 3));
			break;
		case 't': opt.tau = tool_parse_double("--tau", optarg, 1e-6, 1e6); break;
		case 'b': opt.allow_border = 1; break;
		case 'F': opt.fast_cost = 1; break;
		case 'I':
			opt.influence_budget = tool_parse_double("--influence-budget", optarg, 0.0, 1e3);
			opt.influence_budget = opt.influence_budget > 0.0 ? opt.influence_budget : -1.0;
			break;
		case 's': split = optarg; break;
		case 'j': opt.threads = tool_parse_threads(optarg); break;
		case 'h': {
			char list[64] = "";
			for (size_t i = 0, n = 0; i < sizeof defaults / sizeof *defaults; i++)
				n += (size_t)snprintf(list + n, sizeof list - n, "%s%g", i ? "," : "", defaults[i]);
			printf(usage_text, list);
			return 0;
		}
		case 'V': tool_version();
		default: tool_option_error(ch, shortopts, argv);
		}
	}
	if (argc - optind > 1)
		tool_usage_error("too many inputs: one file, or stdin");
	if (ratio_count && max_error >= 0.0)
		tool_usage_error("--ratios and --max-error do not go together");
	if (opt.influence_budget > 0.0 && max_error >= 0.0)
		tool_usage_error("--influence-budget and --max-error do not go together");
	if (report != REPORT_NONE && output)
		tool_usage_error("--report and --output do not go together");
	if (opt.cost == MLOD_COST_COMPACTNESS && opt.op != MLOD_OP_DEFAULT && opt.op != MLOD_OP_TRIANGLE)
		tool_usage_error("--collapse %s needs --cost posed: compactness ranks triangles only", mlod_mesh_op_name(opt.op));
	if (opt.cost == MLOD_COST_COMPACTNESS && budget == MLOD_BUDGET_CHARACTER)
		tool_usage_error("--budget character needs --cost posed: compactness costs do not compare across primitives");
	mlod_mesh_resolve(&opt, &budget);
	if (!ratio_count)
		for (size_t i = 0; i < sizeof defaults / sizeof *defaults; i++)
			ratios[ratio_count++] = defaults[i];
	qsort(ratios, (size_t)ratio_count, sizeof *ratios, double_desc);

	mlod_gltf *doc = NULL;
	mlod_error err = {0};
	mlod_result r;
	const char *input_path = optind < argc ? argv[optind] : NULL;
	job.input = tool_input_label(input_path);
	tool_load(input_path, &doc, &job.c, NULL);

	if (mlod_mesh_triangle_primitives(&job.c) == 0) {
		/* Nothing to simplify (a BVH, a skeleton): pass it through. */
		job.L.opt = opt;
		job.L.budget = budget;
		snprintf(job.L.notes, sizeof job.L.notes, "no triangle mesh: nothing to simplify");
		if (report == REPORT_TABLE)
			report_table(&job);
		else if (report == REPORT_JSON)
			report_json(&job);
		else {
			tool_note(job.input, "no triangle mesh; written unchanged");
			tool_write_gltf(output, doc);
		}
	} else {
		mlod_record rec;
		if ((r = mlod_record_read(doc, &rec, &err)) != MLOD_OK)
			tool_die(tool_exit_code(r), job.input, "%s", err.message);
		if (rec.mesh_level_count > 0 && report == REPORT_NONE && !split) {
			/* Levels on top of levels would leave the old ones unused: pass it through. */
			tool_note(job.input, "the input already has %d mesh level%s (MSFT_lod): written unchanged; run %s on "
			        "the input without them to bake them again", rec.mesh_level_count,
			        rec.mesh_level_count == 1 ? "" : "s", tool_name);
			tool_write_gltf(output, doc);
			mlod_record_free(&rec);
			mlod_character_free(&job.c);
			mlod_gltf_free(doc);
			return 0;
		}
		mlod_mesh_skeleton *sk = calloc((size_t)rec.skel_level_count + 1, sizeof *sk);
		if (!sk)
			tool_die(EXIT_INPUT, job.input, "out of memory");
		r = mlod_mesh_levels_init(&job.L, &job.c, &opt, budget, max_error >= 0.0 ? 0.0 : ratios[ratio_count - 1], &err);
		if (r == MLOD_OK)
			r = max_error >= 0.0 ? mlod_mesh_levels_by_error(&job.L, max_error, &err)
			                     : mlod_mesh_levels_by_ratio(&job.L, ratios, ratio_count, &err);
		if (r != MLOD_OK)
			tool_die(tool_exit_code(r), job.input, "%s", err.message);
		if (max_error >= 0.0 && job.L.count == 0)
			tool_note(job.input, "no mesh level within --max-error %g%%", max_error);
		if (report == REPORT_NONE) /* a ratio that gives no coarser level: the report's note */
			tool_note_items(job.input, job.L.notes, ": dropped");
		follow_skeleton(&job, &rec, sk);
		if (split) /* first: write_glb changes doc */
			write_split(&job, doc, split, input_path, output);
		if (report == REPORT_TABLE)
			report_table(&job);
		else if (report == REPORT_JSON)
			report_json(&job);
		else
			write_glb(&job, doc, output);
		mlod_record_free(&rec);
		free(sk);
	}
	if (fflush(stdout) != 0)
		tool_die(EXIT_OUTPUT, "<stdout>", "write error");
	mlod_mesh_levels_free(&job.L);
	mlod_character_free(&job.c);
	mlod_gltf_free(doc);
	return 0;
}
