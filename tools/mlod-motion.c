/*
 * mlod-motion: motion levels of detail (paper 4.3): the multiresolution
 * motion tree, which drops whole frames, and per-channel key reduction
 * under a hierarchical error bound, which goes beyond the paper.
 *
 * Output: a glb where each clip gets its levels as extra animations
 * "<clip>@lod<k>" (originals untouched, extras.mlod on each level); or,
 * with --level K -o out.bvh, a BVH of level K at the clip's frame rate; or
 * a report.
 */
#define _GNU_SOURCE /* getopt_long */

#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common.h"

#define MAX_LEVELS 32
#define DEFAULT_MAX_ERROR "0.2%,1%,3%"
#define VERTEX_SAMPLES 60   /* measured times per clip for the skinned-vertex error */

static const char usage_text[] =
	"usage: mlod-motion [options] [input]\n"
	"\n"
	"Builds motion levels of detail for every clip of a character: the paper's\n"
	"multiresolution motion tree (whole frames merge) or per-channel key reduction\n"
	"under a hierarchical error bound. Input is glb, glTF or BVH. Output is a glb\n"
	"where each clip gets its levels as animations named <clip>@lod<k>, morph\n"
	"target weights channels reduced within the same bounds.\n"
	"\n"
	"options:\n"
	"  -o, --output FILE       write to FILE instead of stdout; a .bvh name writes\n"
	"                          the level chosen by --level as BVH\n"
	"  -r, --report[=FORMAT]   print the levels instead; FORMAT is table or json\n"
	"  -m, --method METHOD     frames (the paper's tree), keys (per-channel key\n"
	"                          reduction) or auto: per level the one with fewer\n"
	"                          bytes within the same bound (default auto)\n"
	"  -e, --max-error LIST    one level per bound on the world joint position\n"
	"                          error: E in scene units or E% of the skeleton height\n"
	"                          (the rest-pose joints' extent along +Y)\n"
	"                          (default " DEFAULT_MAX_ERROR ")\n"
	"  -t, --thresholds LIST   one level per frame distance threshold (frames method)\n"
	"  -k, --keys LIST         one level per fraction of the keys kept (0.5,0.2)\n"
	"      --merge MODE        frames method: remove (default) or average (not\n"
	"                          with -m keys)\n"
	"      --point-distance D  keys method: radius of the points carried by each\n"
	"                          joint (default 0.1 for glTF, height/18 for BVH)\n"
	"      --precision MODE    how level key values are stored, rounded within each\n"
	"                          bound so they compress well: auto stores rotations as\n"
	"                          normalised shorts (core glTF) and the rest as floats on\n"
	"                          power-of-two grids; float keeps every value float32 on\n"
	"                          such grids, first and last keys exact; full keeps the\n"
	"                          values as read (default auto)\n"
	"      --precision-share F the share of each bound left to rounding, the rest to\n"
	"                          removing keys (default 0.1)\n"
	"      --cubic-rate R      resample CUBICSPLINE clips at R frames/s (default 60)\n"
	"      --subdivide N       check the error bound at the frames and at N-1 evenly\n"
	"                          spaced times between each two (1: frames only;\n"
	"                          default 2, the midpoints too)\n"
	"  -l, --level K           with a .bvh output: the level to write (0 = as read)\n"
	"  -c, --clip N            with a .bvh output: the clip to write (default 0)\n"
	"  -j, --threads N         work on N threads (default: the processors it may\n"
	"                          run on, its CPU affinity);\n"
	"                          the output is the same at any N\n"
	"  -h, --help              show this help\n"
	"  -V, --version           show the version\n"
	"\n"
	"exit status: 0 success, 1 usage, 2 bad input, 3 unsupported input,\n"
	"4 output failure.\n" TOOL_OUTPUT_NOTE;

enum method { METHOD_AUTO = -1 };

struct spec {
	mlod_motion_target target;
	double value;    /* as given */
	int percent;     /* max error given in % of the height */
};

struct job {
	const char *input;
	const mlod_gltf *doc; /* glTF input, else NULL */
	mlod_record_input in;
	mlod_character c;
	double height;
	double point_distance;
	int method;       /* mlod_motion_method or METHOD_AUTO */
	mlod_motion_options opt;
	int spec_count;
	struct spec specs[MAX_LEVELS];
	int threads;
};

/* Parses a comma-separated list (tool_parse_list); "E%" is allowed for
 * error bounds. */
static int parse_list(const char *option, const char *value, struct spec *out, mlod_motion_target target,
                      double lo, double hi)
{
	double v[MAX_LEVELS];
	int pct[MAX_LEVELS] = {0};
	int n = target == MLOD_MOTION_MAX_ERROR ? tool_parse_list_percent(option, value, v, pct, MAX_LEVELS, lo, hi)
	                                        : tool_parse_list(option, value, v, MAX_LEVELS, lo, hi);
	/* An equal value (in the same unit) would bake the same level twice. */
	n = tool_drop_repeats(option, v, pct, n);
	for (int i = 0; i < n; i++) {
		out[i].target = target;
		out[i].percent = target == MLOD_MOTION_MAX_ERROR && pct[i];
		out[i].value = v[i];
		if (target == MLOD_MOTION_FRACTION && !(v[i] > 0.0))
			tool_usage_error("%s: a fraction of keys must be above 0", option);
	}
	return n;
}

static int spec_order(const void *a, const void *b)
{
	const struct spec *x = a, *y = b;
	/* Coarser last: larger bounds and thresholds, smaller fractions. */
	double u = x->target == MLOD_MOTION_FRACTION ? -x->value : x->value;
	double v = y->target == MLOD_MOTION_FRACTION ? -y->value : y->value;
	return (u > v) - (u < v);
}

/* Samples per frame interval at which the bounds are checked. */
static int subdivide(const struct job *job)
{
	return job->opt.subdivide > 0 ? job->opt.subdivide : MLOD_DEFAULT_SUBDIVIDE;
}

/* Builds the levels of the clips (all, or the one a BVH output writes) on
 * job->threads threads; says the notes, and dies at a failure. */
static void bake(const struct job *job, const int *clips, int clip_count, mlod_motion_bake *out)
{
	mlod_motion_method methods[2];
	mlod_motion_spec specs[MAX_LEVELS];
	mlod_motion_bake_options o;
	memset(&o, 0, sizeof o);
	o.motion = job->opt;
	o.methods = methods;
	if (job->method == METHOD_AUTO) {
		methods[o.method_count++] = MLOD_MOTION_FRAMES;
		methods[o.method_count++] = MLOD_MOTION_KEYS;
	} else {
		methods[o.method_count++] = (mlod_motion_method)job->method;
	}
	for (int s = 0; s < job->spec_count; s++) {
		const struct spec *sp = &job->specs[s];
		specs[s].target = sp->target;
		specs[s].value = sp->percent ? sp->value * job->height / 100.0 : sp->value;
	}
	o.specs = specs;
	o.spec_count = job->spec_count;
	o.threads = job->threads;
	o.vertex_samples = VERTEX_SAMPLES;
	mlod_error err = {0};
	mlod_result r = mlod_motion_bake_run(&job->c, job->doc, clips, clip_count, &o, out, &err);
	for (int i = 0; i < out->note_count; i++)
		tool_note(job->input, "%s", out->notes[i]);
	if (r != MLOD_OK)
		tool_die(tool_exit_code(r), job->input, "%s", err.message);
}

static void print_report(const struct job *job, const mlod_motion_bake *b, enum tool_report kind)
{
	mlod_motion_report_info info = { job->input, job->height, job->point_distance, subdivide(job), job->opt.precision };
	char *text = NULL;
	mlod_error err = {0};
	mlod_result r = kind == REPORT_JSON ? mlod_motion_bake_json(b, &job->c, &info, &text, &err)
	                                    : mlod_motion_bake_table(b, &job->c, &info, &text, &err);
	if (r != MLOD_OK)
		tool_die(EXIT_OUTPUT, NULL, "%s", err.message);
	fputs(text, stdout);
	free(text);
}

static void write_bvh(const struct job *job, const mlod_motion_bake *b, const char *output, int level, int clip)
{
	const mlod_motion_bake_clip *cl = &b->clips[0];
	const mlod_clip *use = NULL;
	if (level > 0) {
		if (level > cl->level_count)
			tool_die(EXIT_USAGE, NULL, "--level %d: clip %d's levels are 0..%d", level, clip, cl->level_count);
		if (!cl->levels[level - 1].ok)
			tool_die(EXIT_INPUT, job->input, "--level %d: no level within its bound", level);
		use = &cl->levels[level - 1].l.clip;
	}
	char *text = NULL;
	size_t size = 0;
	mlod_error err = {0};
	mlod_result r = mlod_motion_bvh(&job->c, clip, use, cl->frames, &text, &size, &err);
	if (r != MLOD_OK)
		tool_die(r == MLOD_ERR_UNSUPPORTED ? EXIT_UNSUPPORTED : EXIT_OUTPUT, output, "%s", err.message);
	tool_write_output(output, text, size, 0);
	mlod_free(text);
	/* What the BVH cannot hold (of the clip as read). */
	char note[MLOD_SKEL_BVH_NOTE_SIZE];
	double max;
	int joint;
	if (mlod_skel_bvh_end_sites(&job->c, clip, &max, &joint, note, sizeof note, &err) != MLOD_OK)
		tool_die(tool_exit_code(err.code), job->input, "%s", err.message);
	if (note[0])
		tool_note(job->input, "%s", note);
}

int main(int argc, char **argv)
{
	static const struct option longopts[] = {
		{"output", required_argument, NULL, 'o'},
		{"report", optional_argument, NULL, 'r'},
		{"method", required_argument, NULL, 'm'},
		{"max-error", required_argument, NULL, 'e'},
		{"thresholds", required_argument, NULL, 't'},
		{"keys", required_argument, NULL, 'k'},
		{"merge", required_argument, NULL, 'M'},
		{"point-distance", required_argument, NULL, 'P'},
		{"cubic-rate", required_argument, NULL, 'C'},
		{"precision", required_argument, NULL, 'p'},
		{"precision-share", required_argument, NULL, 'S'},
		{"subdivide", required_argument, NULL, 'D'},
		{"level", required_argument, NULL, 'l'},
		{"clip", required_argument, NULL, 'c'},
		{"threads", required_argument, NULL, 'j'},
		{"help", no_argument, NULL, 'h'},
		{"version", no_argument, NULL, 'V'},
		{NULL, 0, NULL, 0},
	};
	const char *output = NULL;
	enum tool_report report = REPORT_NONE;
	struct job job;
	int level = -1, clip = 0, clip_given = 0, ch, kinds = 0, method_given = 0, merge_given = 0;
	double point_distance = 0.0;
	memset(&job, 0, sizeof job);
	job.method = METHOD_AUTO;
	job.threads = mlod_thread_count();

	tool_name = "mlod-motion";
	static const char shortopts[] = ":o:r::m:e:t:k:l:c:j:hV";
	opterr = 0;
	while ((ch = getopt_long(argc, argv, shortopts, longopts, NULL)) != -1) {
		switch (ch) {
		case 'o': output = optarg; break;
		case 'r': report = tool_parse_report(optarg); break;
		case 'm':
			method_given = 1;
			if (strcmp(optarg, "frames") == 0)
				job.method = MLOD_MOTION_FRAMES;
			else if (strcmp(optarg, "keys") == 0)
				job.method = MLOD_MOTION_KEYS;
			else if (strcmp(optarg, "auto") == 0)
				job.method = METHOD_AUTO;
			else
				tool_usage_error("--method: unknown method '%s' (frames, keys or auto)", optarg);
			break;
		case 'e':
			job.spec_count = parse_list("--max-error", optarg, job.specs, MLOD_MOTION_MAX_ERROR, 0.0, 1e12);
			kinds++;
			break;
		case 't':
			job.spec_count = parse_list("--thresholds", optarg, job.specs, MLOD_MOTION_THRESHOLD, 0.0, 1e12);
			kinds++;
			break;
		case 'k':
			job.spec_count = parse_list("--keys", optarg, job.specs, MLOD_MOTION_FRACTION, 0.0, 1.0);
			kinds++;
			break;
		case 'M':
			if (strcmp(optarg, "remove") == 0)
				job.opt.merge = MLOD_MOTION_REMOVE;
			else if (strcmp(optarg, "average") == 0)
				job.opt.merge = MLOD_MOTION_AVERAGE;
			else
				tool_usage_error("--merge: unknown mode '%s' (remove or average)", optarg);
			merge_given = 1;
			break;
		case 'P': point_distance = tool_parse_double("--point-distance", optarg, 1e-12, 1e12); break;
		case 'C': job.opt.cubic_rate = tool_parse_double("--cubic-rate", optarg, 1.0, 1e4); break;
		case 'p':
			if (strcmp(optarg, "auto") == 0)
				job.opt.precision = MLOD_MOTION_PRECISION_AUTO;
			else if (strcmp(optarg, "float") == 0)
				job.opt.precision = MLOD_MOTION_PRECISION_FLOAT;
			else if (strcmp(optarg, "full") == 0)
				job.opt.precision = MLOD_MOTION_PRECISION_FULL;
			else
				tool_usage_error("--precision: unknown mode '%s' (auto, float or full)", optarg);
			break;
		case 'S':
			job.opt.precision_share = tool_parse_double("--precision-share", optarg, 0.0, 1.0);
			if (!(job.opt.precision_share > 0.0 && job.opt.precision_share < 1.0))
				tool_usage_error("--precision-share: %s is out of range (0, 1): above 0 and below 1", optarg);
			break;
		case 'D': job.opt.subdivide = tool_parse_int("--subdivide", optarg, 1, MLOD_MAX_SUBDIVIDE); break;
		case 'l': level = tool_parse_int("--level", optarg, 0, MAX_LEVELS); break;
		case 'c': clip = tool_parse_int("--clip", optarg, 0, 1000000), clip_given = 1; break;
		case 'j': job.threads = tool_parse_threads(optarg); break;
		case 'h': fputs(usage_text, stdout); return 0;
		case 'V': tool_version();
		default: tool_option_error(ch, shortopts, argv);
		}
	}
	if (argc - optind > 1)
		tool_usage_error("too many inputs: one file, or stdin");
	if (kinds > 1)
		tool_usage_error("--max-error, --thresholds and --keys do not go together");
	if (job.spec_count && job.specs[0].target == MLOD_MOTION_THRESHOLD) {
		if (method_given && job.method == MLOD_MOTION_KEYS)
			tool_usage_error("--thresholds are frame distances: they need --method frames");
		job.method = MLOD_MOTION_FRAMES;
	}
	if (merge_given && job.method == MLOD_MOTION_KEYS)
		tool_usage_error("--merge is for the frames method: not with --method keys");
	if (job.spec_count == 0)
		job.spec_count = parse_list("--max-error", DEFAULT_MAX_ERROR, job.specs, MLOD_MOTION_MAX_ERROR, 0.0, 1e12);
	qsort(job.specs, (size_t)job.spec_count, sizeof *job.specs, spec_order);
	int bvh_out = output && tool_ends_with(output, ".bvh");
	if (level >= 0 && !bvh_out)
		tool_usage_error("--level needs a .bvh output (-o out.bvh)");
	if (clip_given && !bvh_out)
		tool_usage_error("--clip needs a .bvh output (-o out.bvh)");
	if (report != REPORT_NONE && output)
		tool_usage_error("--report and --output do not go together");

	mlod_gltf *doc = NULL;
	job.input = tool_input_label(optind < argc ? argv[optind] : NULL);
	tool_load(optind < argc ? argv[optind] : NULL, bvh_out ? NULL : &doc, &job.c, &job.in);
	job.doc = doc;
	if (job.c.clip_count == 0) {
		/* Nothing to reduce (a static prop, a character without clips):
		 * pass it through, so that a pipeline over many assets goes on. */
		const char *why = job.in.format == MLOD_FORMAT_BVH ? "no animation (the BVH has 'Frames: 0')" : "no animation";
		if (bvh_out)
			tool_die(EXIT_INPUT, job.input, "%s: no clip to write as BVH", why);
		if (report == REPORT_NONE) {
			tool_note(job.input, "%s: nothing to reduce; written unchanged", why);
			tool_write_gltf(output, doc);
			mlod_character_free(&job.c);
			mlod_gltf_free(doc);
			return 0;
		}
	}
	int existing = 0;
	if (doc && report == REPORT_NONE && !bvh_out) {
		mlod_error err = {0};
		mlod_result r = mlod_record_motion_level_count(doc, &existing, &err);
		if (r != MLOD_OK)
			tool_die(tool_exit_code(r), job.input, "%s", err.message);
	}
	if (existing > 0) {
		/* Levels of levels would be baked from the old levels too: pass it through. */
		tool_note(job.input, "the input already has %d motion level%s (<clip>@lod<k>): written unchanged; run %s "
		        "on the input without them to bake them again", existing,
		        existing == 1 ? "" : "s", tool_name);
		tool_write_gltf(output, doc);
		mlod_character_free(&job.c);
		mlod_gltf_free(doc);
		return 0;
	}
	job.height = mlod_skeleton_height(&job.c.skeleton);
	/* 10 cm: glTF is in metres; a BVH's unit is its own, and so is a glb's
	 * made from a BVH (its stage record says so). */
	job.point_distance = point_distance > 0.0 ? point_distance
	                                          : mlod_motion_point_distance(&job.c.skeleton, !job.in.from_bvh);
	job.opt.point_distance = job.point_distance;
	for (int s = 0; s < job.spec_count; s++)
		if (job.specs[s].percent && !(job.height > 0.0) && job.c.clip_count > 0)
			tool_die(EXIT_INPUT, job.input, "--max-error in %%: the skeleton has no height");

	if (bvh_out && clip >= job.c.clip_count)
		tool_die(EXIT_USAGE, NULL, "--clip %d: the input has %d clips", clip, job.c.clip_count);
	int count = bvh_out ? 1 : job.c.clip_count;
	int *clips = malloc(sizeof(int) * (size_t)(count + 1));
	if (!clips)
		tool_die(EXIT_INPUT, job.input, "out of memory");
	for (int k = 0; k < count; k++)
		clips[k] = bvh_out ? clip : k;
	mlod_motion_bake b;
	mlod_motion_bake_clip as_read; /* --level 0: the clip as read, no levels */
	memset(&b, 0, sizeof b);
	memset(&as_read, 0, sizeof as_read);
	if (!(bvh_out && level == 0)) {
		bake(&job, clips, count, &b);
	} else {
		as_read.index = clip;
		b.clip_count = 1;
		b.clips = &as_read;
	}
	for (int k = 0; k < b.clip_count && report == REPORT_NONE; k++) {
		char note[256];
		if (mlod_motion_bake_timeline_note(&b, k, note, sizeof note)) {
			tool_note(job.input, "clip %s: %s", MLOD_QUOTED(job.c.clips[b.clips[k].index].name), note);
		}
	}

	if (report != REPORT_NONE) {
		print_report(&job, &b, report);
	} else if (bvh_out) {
		write_bvh(&job, &b, output, level < 0 ? b.clips[0].level_count : level, clip);
	} else {
		mlod_error err = {0};
		if (mlod_motion_bake_to_gltf(&b, &job.c, doc, job.height, subdivide(&job), &err) != MLOD_OK)
			tool_die(EXIT_OUTPUT, NULL, "%s", err.message);
		tool_write_gltf(output, doc);
	}

	if (fflush(stdout) != 0)
		tool_die(EXIT_OUTPUT, "<stdout>", "write error");
	if (b.clips != &as_read)
		mlod_motion_bake_free(&b);
	free(clips);
	mlod_character_free(&job.c);
	mlod_gltf_free(doc);
	return 0;
}
