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
	"      --merge MODE        frames method: remove (default) or average\n"
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
	"  -j, --threads N         work on N threads (default: the processors online);\n"
	"                          the output is the same at any N\n"
	"  -h, --help              show this help\n"
	"  -V, --version           show the version\n"
	"\n"
	"exit status: 0 success, 1 usage, 2 bad input, 3 unsupported input,\n"
	"4 output failure.\n";

enum method { METHOD_AUTO = -1 };

struct spec {
	mlod_motion_target target;
	double value;    /* as given */
	int percent;     /* max error given in % of the height */
};

struct level {
	int ok;          /* 0 when no level met the bound */
	double bound;    /* scene units, for max-error levels */
	mlod_motion_level l;
	int has_vertex;
	mlod_deviation vertex; /* % of the diagonal; scale is the diagonal */
	/* Morph weights channels of the level (glTF input with such channels). */
	mlod_weight_track *w;
	int w_count;
	int w_copied;    /* tracks kept as they are (CUBICSPLINE, or no mesh to measure) */
	double w_bound;  /* scene units: the level's bound, or its joint error without one */
	double w_error;  /* the largest vertex displacement bound of the reduced tracks */
	long w_keys, w_bytes;
};

struct clip {
	int index;
	int frames;
	mlod_motion_timeline timeline;
	long keys, bytes;   /* joint channels and morph weights */
	mlod_weight_track *w; /* the source's morph weights channels */
	int w_count;
	long w_keys;
	int level_count;
	struct level levels[MAX_LEVELS];
};

struct job {
	const char *input;
	const mlod_gltf *doc; /* glTF input, else NULL */
	mlod_format format;
	mlod_character c;
	double height;
	double point_distance;
	int method;       /* mlod_motion_method or METHOD_AUTO */
	mlod_motion_options opt;
	int spec_count;
	struct spec specs[MAX_LEVELS];
	int threads;
	int clip_count;
	struct clip *clips;
};

static const char *method_name(mlod_motion_method m)
{
	return m == MLOD_MOTION_KEYS ? "keys" : "frames";
}

static const char *target_name(mlod_motion_target t)
{
	return t == MLOD_MOTION_THRESHOLD ? "threshold" : t == MLOD_MOTION_FRACTION ? "keys" : "max_error";
}

/* Parses a comma-separated list (tool_parse_list); "E%" is allowed for
 * error bounds. */
static int parse_list(const char *option, const char *value, struct spec *out, mlod_motion_target target,
                      double lo, double hi)
{
	double v[MAX_LEVELS];
	int pct[MAX_LEVELS] = {0};
	int n = target == MLOD_MOTION_MAX_ERROR ? tool_parse_list_percent(option, value, v, pct, MAX_LEVELS, lo, hi)
	                                        : tool_parse_list(option, value, v, MAX_LEVELS, lo, hi);
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

/* A shallow character: c's skeleton and meshes with one clip. */
static mlod_character with_clip(const mlod_character *c, const mlod_clip *clip)
{
	mlod_character s = *c;
	s.clip_count = 1;
	s.clips = (mlod_clip *)clip;
	s.notes = NULL;
	return s;
}

/* A copy of a weight track (NULL values when out of memory). */
static mlod_result copy_track(const mlod_weight_track *in, mlod_weight_track *out)
{
	size_t n = (size_t)in->key_count, v = n * (size_t)in->targets * (in->interp == MLOD_INTERP_CUBICSPLINE ? 3 : 1);
	*out = *in;
	out->times = malloc(sizeof(float) * n);
	out->values = malloc(sizeof(float) * v);
	if (!out->times || !out->values)
		return MLOD_ERR_NOMEM;
	memcpy(out->times, in->times, sizeof(float) * n);
	memcpy(out->values, in->values, sizeof(float) * v);
	return MLOD_OK;
}

/* A level's measures: its skinned-vertex error and its morph weights, each
 * track reduced within the level's bound (or, for a level chosen by keys or
 * threshold, its joint error). Fills only lv; on failure err says why and
 * *vertex_failed whether the vertex error failed (the weights not made). */
static mlod_result level_extras(const struct job *job, const struct clip *cl, struct level *lv, int *vertex_failed,
                                mlod_error *err)
{
	*vertex_failed = 0;
	if (job->c.instance_count > 0) {
		mlod_character a = with_clip(&job->c, &job->c.clips[cl->index]), b = with_clip(&job->c, &lv->l.clip);
		mlod_result r = mlod_vertex_deviation(&a, &b, VERTEX_SAMPLES, &lv->vertex, err);
		if (r != MLOD_OK) {
			*vertex_failed = 1;
			return r;
		}
		lv->has_vertex = 1;
	}
	if (cl->w_count == 0)
		return MLOD_OK;
	lv->w = calloc((size_t)cl->w_count, sizeof *lv->w);
	if (!lv->w)
		return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
	lv->w_count = cl->w_count;
	lv->w_bound = lv->bound >= 0.0 ? lv->bound : lv->l.error.max;
	int sub = job->opt.subdivide > 0 ? job->opt.subdivide : MLOD_DEFAULT_SUBDIVIDE;
	for (int i = 0; i < cl->w_count; i++) {
		const mlod_weight_track *t = &cl->w[i];
		double *reach = malloc(sizeof(double) * (size_t)t->targets), e = 0.0;
		if (!reach)
			return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
		mlod_error why = {0};
		mlod_result r = t->interp == MLOD_INTERP_CUBICSPLINE
		                    ? MLOD_ERR_UNSUPPORTED
		                    : mlod_morph_target_reach(&job->c, t->node, t->targets, reach, &why);
		if (r == MLOD_OK)
			r = mlod_weight_track_reduce(t, reach, lv->w_bound, sub, &lv->w[i], &e, &why);
		free(reach);
		if (r == MLOD_ERR_NOMEM) {
			*err = why;
			return r;
		}
		if (r != MLOD_OK) {
			if (copy_track(t, &lv->w[i]) != MLOD_OK)
				return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
			lv->w_copied++;
		} else if (e > lv->w_error) {
			lv->w_error = e;
		}
	}
	lv->w_keys = mlod_weight_tracks_keys(lv->w, lv->w_count);
	lv->w_bytes = mlod_weight_tracks_bytes(lv->w, lv->w_count);
	return MLOD_OK;
}

/* What building a clip's levels gave, gathered before anything is said. */
struct clip_outcome {
	mlod_result w_result; /* reading its morph weights channels */
	mlod_error w_error;
	mlod_motion_clip_levels built;
	mlod_result *extras;  /* per level: level_extras' result */
	mlod_error *extras_error;
	int *vertex_failed;
};

struct extras_ctx {
	const struct job *job;
	struct clip_outcome *out;
	int *item_clip, *item_level;
};

static mlod_result extras_item(void *ctx, int i)
{
	struct extras_ctx *x = ctx;
	int k = x->item_clip[i], s = x->item_level[i];
	struct clip_outcome *o = &x->out[k];
	struct clip *cl = &x->job->clips[k];
	o->extras[s] = level_extras(x->job, cl, &cl->levels[s], &o->vertex_failed[s], &o->extras_error[s]);
	return MLOD_OK;
}

/* Says what one clip's levels gave, in the order they were asked for:
 * messages and failures come out as if the clips and levels were built
 * one after another. */
static void clip_report(struct job *job, struct clip *cl, const struct clip_outcome *o)
{
	const mlod_clip *src = &job->c.clips[cl->index];
	if (o->w_result != MLOD_OK)
		tool_die(EXIT_INPUT, job->input, "%s", o->w_error.message);
	if (o->built.result != MLOD_OK)
		tool_die(tool_exit_code(o->built.result), job->input, "%s", o->built.error.message);
	if (cl->frames < 3) {
		fprintf(stderr, "%s: %s: clip \"%s\" has %d frame%s: nothing to reduce, no levels\n", tool_name, job->input,
		        src->name, cl->frames, cl->frames == 1 ? "" : "s");
		return;
	}
	for (int s = 0; s < o->built.level_count; s++) {
		mlod_result r = o->built.results[s];
		if (r != MLOD_OK && r != MLOD_ERR_LIMIT)
			tool_die(tool_exit_code(r), job->input, "%s", o->built.errors[s].message);
		if (r == MLOD_ERR_LIMIT) {
			fprintf(stderr, "%s: %s: %s\n", tool_name, job->input, o->built.errors[s].message);
			continue;
		}
		if (o->extras[s] != MLOD_OK) {
			if (o->vertex_failed[s])
				tool_die(tool_exit_code(o->extras[s]), job->input, "clip \"%s\": %s", src->name,
				         o->extras_error[s].message);
			tool_die(EXIT_INPUT, job->input, "%s", o->extras_error[s].message);
		}
	}
}

/* Builds the levels of every clip of the job, their measures and morph
 * weights, on job->threads threads. */
static void build_levels(struct job *job)
{
	mlod_motion_method methods[2];
	int method_count = 0;
	if (job->method == METHOD_AUTO) {
		methods[method_count++] = MLOD_MOTION_FRAMES;
		methods[method_count++] = MLOD_MOTION_KEYS;
	} else {
		methods[method_count++] = (mlod_motion_method)job->method;
	}
	mlod_motion_spec specs[MAX_LEVELS];
	for (int s = 0; s < job->spec_count; s++) {
		const struct spec *sp = &job->specs[s];
		specs[s].target = sp->target;
		specs[s].value = sp->percent ? sp->value * job->height / 100.0 : sp->value;
	}
	int n = job->clip_count, items = 0;
	int *clips = malloc(sizeof(int) * (size_t)n);
	struct clip_outcome *out = calloc((size_t)n, sizeof *out);
	mlod_motion_clip_levels *built = calloc((size_t)n, sizeof *built);
	int *item_clip = malloc(sizeof(int) * (size_t)n * MAX_LEVELS), *item_level = malloc(sizeof(int) * (size_t)n * MAX_LEVELS);
	if (!clips || !out || !built || !item_clip || !item_level)
		tool_die(EXIT_INPUT, job->input, "out of memory");
	for (int k = 0; k < n; k++) {
		struct clip *cl = &job->clips[k];
		const mlod_clip *src = &job->c.clips[cl->index];
		clips[k] = cl->index;
		cl->keys = mlod_clip_key_count(src);
		cl->bytes = mlod_clip_key_bytes(src);
		if (job->doc && src->gltf_index >= 0) {
			out[k].w_result = mlod_gltf_weight_tracks(job->doc, src->gltf_index, &cl->w, &cl->w_count, &out[k].w_error);
			cl->w_keys = mlod_weight_tracks_keys(cl->w, cl->w_count);
			cl->keys += cl->w_keys;
			cl->bytes += mlod_weight_tracks_bytes(cl->w, cl->w_count);
		}
	}
	mlod_error err = {0};
	mlod_result r = mlod_motion_build_levels(&job->c, clips, n, &job->opt, methods, method_count, specs,
	                                         job->spec_count, job->threads, built, &err);
	if (r != MLOD_OK)
		tool_die(tool_exit_code(r), job->input, "%s", err.message);
	for (int k = 0; k < n; k++) {
		struct clip *cl = &job->clips[k];
		struct clip_outcome *o = &out[k];
		o->built = built[k];
		cl->timeline = o->built.timeline;
		cl->frames = cl->timeline.frames;
		int count = o->built.level_count;
		o->extras = calloc((size_t)count + 1, sizeof *o->extras);
		o->extras_error = calloc((size_t)count + 1, sizeof *o->extras_error);
		o->vertex_failed = calloc((size_t)count + 1, sizeof *o->vertex_failed);
		if (!o->extras || !o->extras_error || !o->vertex_failed)
			tool_die(EXIT_INPUT, job->input, "out of memory");
		if (o->w_result != MLOD_OK || o->built.result != MLOD_OK)
			continue;
		for (int s = 0; s < count; s++) {
			const struct spec *sp = &job->specs[s];
			struct level *lv = &cl->levels[cl->level_count++];
			lv->bound = sp->target == MLOD_MOTION_MAX_ERROR ? specs[s].value : -1.0;
			lv->ok = o->built.results[s] == MLOD_OK;
			if (lv->ok) {
				lv->l = o->built.levels[s];
				memset(&o->built.levels[s], 0, sizeof o->built.levels[s]);
				item_clip[items] = k;
				item_level[items++] = s;
			}
		}
	}
	struct extras_ctx x = { job, out, item_clip, item_level };
	mlod_parallel_for(items, job->threads, extras_item, &x);
	for (int k = 0; k < n; k++)
		clip_report(job, &job->clips[k], &out[k]);
	for (int k = 0; k < n; k++) {
		free(out[k].extras);
		free(out[k].extras_error);
		free(out[k].vertex_failed);
	}
	mlod_motion_clip_levels_free(built, n);
	free(built);
	free(out);
	free(clips);
	free(item_clip);
	free(item_level);
}

/* What was done to a level's morph weights, as a JSON object. */
static void weights_json(char *buf, size_t size, const struct clip *cl, const struct level *lv)
{
	snprintf(buf, size,
	         "{\"channels\": %d, \"keys\": %ld, \"source_keys\": %ld, \"bytes\": %ld, \"bound\": %.9g, "
	         "\"error\": %.9g, \"copied\": %d, \"error_measure\": \"sum over targets of |weight error| times the "
	         "target's largest vertex offset in the rest pose, scene units\"}",
	         lv->w_count, lv->w_keys, cl->w_keys, lv->w_bytes, lv->w_bound, lv->w_error, lv->w_copied);
}

static void timeline_note(char *buf, size_t size, const struct clip *cl)
{
	if (!cl->timeline.resampled)
		snprintf(buf, size, "own keys");
	else
		snprintf(buf, size, "resampled to %d common frames (%d channels on other times, %d CUBICSPLINE)",
		         cl->frames, cl->timeline.mismatched_channels, cl->timeline.cubic_channels);
}

/* Samples per frame interval at which the bounds are checked. */
static int subdivide(const struct job *job)
{
	return job->opt.subdivide > 0 ? job->opt.subdivide : MLOD_DEFAULT_SUBDIVIDE;
}

static void report_table(const struct job *job)
{
	printf("# %s: %d joints, height %.4g, %d clips; point distance %.4g\n", job->input, job->c.skeleton.joint_count,
	       job->height, job->c.clip_count, job->point_distance);
	printf("%-16s %5s %6s %10s %7s %7s %8s %10s %8s %10s %8s %10s %8s\n", "clip", "level", "method", "threshold",
	       "keys", "keys%", "bytes", "jnt max", "max%", "jnt mean", "mean%", "pt max", "vtx max%");
	for (int k = 0; k < job->clip_count; k++) {
		const struct clip *cl = &job->clips[k];
		const char *name = job->c.clips[cl->index].name;
		printf("%-16s %5d %6s %10s %7ld %6.1f%% %8ld %10s %8s %10s %8s %10s %8s\n", name, 0, "-", "-", cl->keys, 100.0,
		       cl->bytes, "0", "0", "0", "0", "0", job->c.instance_count ? "0" : "-");
		for (int i = 0; i < cl->level_count; i++) {
			const struct level *lv = &cl->levels[i];
			if (!lv->ok) {
				printf("%-16s %5d %6s (no level within %.4g)\n", name, i + 1, "-", lv->bound);
				continue;
			}
			char vtx[32] = "-";
			if (lv->has_vertex)
				snprintf(vtx, sizeof vtx, "%.4f", lv->vertex.max);
			long keys = lv->l.keys + lv->w_keys;
			printf("%-16s %5d %6s %10.4g %7ld %6.1f%% %8ld %10.4g %8.4f %10.4g %8.4f %10.4g %8s\n", name, i + 1,
			       method_name(lv->l.method), lv->l.threshold, keys, 100.0 * (double)keys / (double)cl->keys,
			       lv->l.bytes + lv->w_bytes, lv->l.error.max, 100.0 * lv->l.error.max / job->height, lv->l.error.mean,
			       100.0 * lv->l.error.mean / job->height, lv->l.point_error, vtx);
		}
	}
	for (int k = 0; k < job->clip_count; k++) {
		const struct clip *cl = &job->clips[k];
		if (cl->timeline.resampled) {
			char note[256];
			timeline_note(note, sizeof note, cl);
			printf("# clip %s: %s\n", job->c.clips[cl->index].name, note);
		}
	}
	for (int k = 0; k < job->clip_count; k++) {
		const struct clip *cl = &job->clips[k];
		if (cl->w_count == 0)
			continue;
		printf("# clip %s: %d morph weights channels, %ld keys; per level kept keys (vertex error bound, scene units):",
		       job->c.clips[cl->index].name, cl->w_count, cl->w_keys);
		for (int i = 0; i < cl->level_count; i++)
			if (cl->levels[i].ok)
				printf(" %d: %ld (%.4g%s)", i + 1, cl->levels[i].w_keys, cl->levels[i].w_error,
				       cl->levels[i].w_copied ? ", some copied" : "");
		printf("\n");
	}
	printf("# threshold: frame distance (frames) or error budget in scene units (keys); jnt: world joint\n"
	       "# position error against the clip as read, scene units and %% of the height; pt: point error (joint\n"
	       "# origins and points within the point distance), scene units; vtx: skinned-vertex error, %% of the\n"
	       "# bounding diagonal\n");
	int sub = subdivide(job);
	if (sub == 1)
		printf("# jnt and pt measured at the frames of each clip's common timeline (--subdivide 1)\n");
	else
		printf("# jnt and pt measured at the frames of each clip's common timeline and %d time%s between each two "
		       "(--subdivide %d)\n", sub - 1, sub == 2 ? "" : "s", sub);
	if (job->opt.precision != MLOD_MOTION_PRECISION_FULL)
		printf("# key values rounded within each level's bound (--precision %s)\n",
		       job->opt.precision == MLOD_MOTION_PRECISION_AUTO ? "auto" : "float");
	if (job->c.notes && *job->c.notes)
		printf("# note: %s\n", job->c.notes);
}

static void report_json(const struct job *job)
{
	printf("{\n  \"input\": ");
	tool_json_string(stdout, job->input);
	printf(",\n  \"joints\": %d,\n  \"height\": %.9g,\n  \"point_distance\": %.9g,\n  \"subdivide\": %d,\n  \"clips\": [\n",
	       job->c.skeleton.joint_count, job->height, job->point_distance, subdivide(job));
	for (int k = 0; k < job->clip_count; k++) {
		const struct clip *cl = &job->clips[k];
		printf("    {\"name\": ");
		tool_json_string(stdout, job->c.clips[cl->index].name);
		printf(", \"index\": %d, \"duration\": %.9g, \"frames\": %d, \"resampled\": %s, "
		       "\"mismatched_channels\": %d, \"cubic_channels\": %d, \"keys\": %ld, \"bytes\": %ld,\n     \"levels\": [",
		       cl->index, (double)job->c.clips[cl->index].duration, cl->frames, cl->timeline.resampled ? "true" : "false",
		       cl->timeline.mismatched_channels, cl->timeline.cubic_channels, cl->keys, cl->bytes);
		for (int i = 0; i < cl->level_count; i++) {
			const struct level *lv = &cl->levels[i];
			const struct spec *sp = &job->specs[i];
			printf("%s\n       {\"level\": %d, \"target\": \"%s\", \"value\": %.9g, ", i ? "," : "", i + 1,
			       target_name(sp->target), sp->percent ? sp->value * job->height / 100.0 : sp->value);
			if (lv->bound >= 0.0)
				printf("\"bound\": %.9g, \"bound_percent_height\": %.9g, ", lv->bound, 100.0 * lv->bound / job->height);
			if (!lv->ok) {
				printf("\"ok\": false}");
				continue;
			}
			long keys = lv->l.keys + lv->w_keys;
			printf("\"ok\": true, \"method\": \"%s\", \"threshold\": %.9g, \"keys\": %ld, \"keys_percent\": %.6g, "
			       "\"bytes\": %ld,\n        \"joint_error\": {\"max\": %.9g, \"mean\": %.9g, \"max_percent_height\": %.9g, "
			       "\"mean_percent_height\": %.9g},\n        \"point_error\": %.9g, \"grid\": %.9g",
			       method_name(lv->l.method), lv->l.threshold, keys, 100.0 * (double)keys / (double)cl->keys,
			       lv->l.bytes + lv->w_bytes, lv->l.error.max, lv->l.error.mean, 100.0 * lv->l.error.max / job->height,
			       100.0 * lv->l.error.mean / job->height, lv->l.point_error, lv->l.grid);
			if (lv->has_vertex)
				printf(",\n        \"vertex_error\": {\"max\": %.9g, \"max_percent_diagonal\": %.9g, "
				       "\"mean_percent_diagonal\": %.9g}",
				       lv->vertex.max * lv->vertex.scale / 100.0, lv->vertex.max, lv->vertex.mean);
			if (lv->w_count) {
				char w[512];
				weights_json(w, sizeof w, cl, lv);
				printf(",\n        \"morph_weights\": %s", w);
			}
			printf("}");
		}
		printf("]}%s\n", k + 1 < job->clip_count ? "," : "");
	}
	printf("  ]\n}\n");
}

/* The frame time a BVH of the clip plays at: its own, else the mean
 * spacing of its common timeline. */
static float bvh_frame_time(const mlod_clip *src, const struct clip *cl)
{
	if (src->frame_time > 0.0f)
		return 0.0f; /* the clip's own */
	int frames = cl->frames;
	float *times = NULL;
	if (frames == 0) { /* level 0 alone: the clip's key times */
		frames = mlod_clip_times(src, 0, &times);
		mlod_free(times);
	}
	if (frames > 1 && src->duration > 0.0f)
		return src->duration / (float)(frames - 1);
	return 0.0f;
}

static void write_bvh(const struct job *job, const char *output, int level, int clip)
{
	const struct clip *cl = &job->clips[0];
	const mlod_clip *src = &job->c.clips[clip];
	const mlod_clip *use = src;
	if (level > 0) {
		if (level > cl->level_count)
			tool_die(EXIT_USAGE, NULL, "--level %d: clip %d has %d levels", level, clip, cl->level_count);
		if (!cl->levels[level - 1].ok)
			tool_die(EXIT_INPUT, job->input, "--level %d: no level within its bound", level);
		use = &cl->levels[level - 1].l.clip;
	}
	mlod_character c = with_clip(&job->c, use);
	char *text = NULL;
	size_t size = 0;
	mlod_error err = {0};
	mlod_result r = mlod_bvh_write(&c, 0, bvh_frame_time(src, cl), &text, &size, &err);
	if (r != MLOD_OK)
		tool_die(r == MLOD_ERR_UNSUPPORTED ? EXIT_UNSUPPORTED : EXIT_OUTPUT, output, "%s", err.message);
	tool_write_output(output, text, size, 0);
	mlod_free(text);
}

/* Adds the levels as animations "<clip>@lod<k>" with extras.mlod. */
static void write_glb(struct job *job, mlod_gltf *doc, const char *output)
{
	mlod_error err = {0};
	for (int k = 0; k < job->clip_count; k++) {
		struct clip *cl = &job->clips[k];
		const mlod_clip *src = &job->c.clips[cl->index];
		for (int i = 0; i < cl->level_count; i++) {
			struct level *lv = &cl->levels[i];
			if (!lv->ok)
				continue;
			const char *base = src->name ? src->name : "";
			char *name = malloc(strlen(base) + 32);
			if (!name)
				tool_die(EXIT_OUTPUT, NULL, "out of memory");
			sprintf(name, "%s@lod%d", base, i + 1);
			free(lv->l.clip.name);
			lv->l.clip.name = name;
			int index;
			if (mlod_gltf_add_animation(doc, &job->c.skeleton, &lv->l.clip, &index, &err) != MLOD_OK)
				tool_die(EXIT_OUTPUT, NULL, "clip \"%s\": %s", base, err.message);
			/* The level's stage record (mlod-record(5)). */
			mlod_record_motion_level rec = {0};
			rec.level = i + 1;
			rec.source_animation = src->gltf_index >= 0 ? src->gltf_index : cl->index;
			rec.method = lv->l.method;
			rec.threshold = lv->l.threshold;
			rec.has_bound = lv->bound >= 0.0;
			rec.bound = lv->bound;
			rec.keys = lv->l.keys + lv->w_keys;
			rec.source_keys = cl->keys;
			rec.bytes = lv->l.bytes + lv->w_bytes;
			rec.joint_error = lv->l.error;
			rec.joint_error_max_percent_height = 100.0 * lv->l.error.max / job->height;
			rec.point_error = lv->l.point_error;
			rec.grid = lv->l.grid;
			rec.subdivide = subdivide(job);
			rec.has_vertex_error = lv->has_vertex;
			rec.vertex_error_percent_diagonal = lv->vertex.max;
			if (lv->w_count) {
				rec.has_morph_weights = 1;
				rec.morph_weights = (mlod_record_morph_weights){lv->w_count, lv->w_keys, cl->w_keys, lv->w_bytes,
				                                                lv->w_bound, lv->w_error, lv->w_copied};
				if (mlod_gltf_add_weight_tracks(doc, index, lv->w, lv->w_count, &err) != MLOD_OK)
					tool_die(EXIT_OUTPUT, NULL, "clip \"%s\": %s", base, err.message);
			}
			if (mlod_record_write_motion(doc, index, &rec, &err) != MLOD_OK)
				tool_die(EXIT_OUTPUT, NULL, "%s", err.message);
		}
	}
	tool_write_gltf(output, doc);
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
	int level = -1, clip = 0, ch, kinds = 0, method_given = 0;
	double point_distance = 0.0;
	memset(&job, 0, sizeof job);
	job.method = METHOD_AUTO;
	job.threads = mlod_thread_count();

	tool_name = "mlod-motion";
	opterr = 0;
	while ((ch = getopt_long(argc, argv, ":o:r::m:e:t:k:l:c:j:hV", longopts, NULL)) != -1) {
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
				tool_usage_error("--precision-share: %s is not between 0 and 1", optarg);
			break;
		case 'D': {
			double v = tool_parse_double("--subdivide", optarg, 1, MLOD_MAX_SUBDIVIDE);
			if (v != floor(v))
				tool_usage_error("--subdivide: %s is not a whole number", optarg);
			job.opt.subdivide = (int)v;
			break;
		}
		case 'l': level = (int)tool_parse_double("--level", optarg, 0, MAX_LEVELS); break;
		case 'c': clip = (int)tool_parse_double("--clip", optarg, 0, 1e6); break;
		case 'j': job.threads = tool_parse_threads(optarg); break;
		case 'h': fputs(usage_text, stdout); return 0;
		case 'V': tool_version();
		case ':': tool_usage_error("option '%s' needs a value", argv[optind - 1]);
		default: tool_usage_error("unknown option '%s'", argv[optind - 1]);
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
	if (job.spec_count == 0)
		job.spec_count = parse_list("--max-error", DEFAULT_MAX_ERROR, job.specs, MLOD_MOTION_MAX_ERROR, 0.0, 1e12);
	qsort(job.specs, (size_t)job.spec_count, sizeof *job.specs, spec_order);
	int bvh_out = output && tool_ends_with(output, ".bvh");
	if (level >= 0 && !bvh_out)
		tool_usage_error("--level needs a .bvh output (-o out.bvh)");
	if (report != REPORT_NONE && output)
		tool_usage_error("--report and --output do not go together");

	mlod_gltf *doc = NULL;
	job.input = tool_input_label(optind < argc ? argv[optind] : NULL);
	tool_load(optind < argc ? argv[optind] : NULL, bvh_out ? NULL : &doc, &job.c, &job.format);
	job.doc = doc;
	if (job.c.clip_count == 0) {
		/* Nothing to reduce (a static prop, a character without clips):
		 * pass it through, so that a pipeline over many assets goes on. */
		const char *why = job.format == MLOD_FORMAT_BVH ? "no animation (the BVH has 'Frames: 0')" : "no animation";
		if (bvh_out)
			tool_die(EXIT_INPUT, job.input, "%s: no clip to write as BVH", why);
		if (report == REPORT_NONE) {
			fprintf(stderr, "%s: %s: %s: nothing to reduce; written unchanged\n", tool_name, job.input, why);
			tool_write_gltf(output, doc);
			mlod_character_free(&job.c);
			mlod_gltf_free(doc);
			return 0;
		}
	}
	job.height = mlod_skeleton_height(&job.c.skeleton);
	/* 10 cm: glTF is in metres; a BVH's unit is its own. */
	job.point_distance = point_distance > 0.0 ? point_distance
	                                          : mlod_motion_point_distance(&job.c.skeleton, job.format != MLOD_FORMAT_BVH);
	job.opt.point_distance = job.point_distance;
	for (int s = 0; s < job.spec_count; s++)
		if (job.specs[s].percent && !(job.height > 0.0) && job.c.clip_count > 0)
			tool_die(EXIT_INPUT, job.input, "--max-error in %%: the skeleton has no height");

	if (bvh_out && clip >= job.c.clip_count)
		tool_die(EXIT_USAGE, NULL, "--clip %d: the input has %d clips", clip, job.c.clip_count);
	job.clip_count = bvh_out ? 1 : job.c.clip_count;
	job.clips = calloc((size_t)job.clip_count + 1, sizeof *job.clips);
	if (!job.clips)
		tool_die(EXIT_INPUT, job.input, "out of memory");
	for (int k = 0; k < job.clip_count; k++)
		job.clips[k].index = bvh_out ? clip : k;
	if (!(bvh_out && level == 0))
		build_levels(&job);
	for (int k = 0; k < job.clip_count && report == REPORT_NONE; k++)
		if (job.clips[k].timeline.resampled) {
			char note[256];
			timeline_note(note, sizeof note, &job.clips[k]);
			fprintf(stderr, "%s: %s: clip \"%s\": %s\n", tool_name, job.input, job.c.clips[job.clips[k].index].name,
			        note);
		}

	if (report == REPORT_TABLE)
		report_table(&job);
	else if (report == REPORT_JSON)
		report_json(&job);
	else if (bvh_out)
		write_bvh(&job, output, level < 0 ? job.clips[0].level_count : level, clip);
	else
		write_glb(&job, doc, output);

	if (fflush(stdout) != 0)
		tool_die(EXIT_OUTPUT, "<stdout>", "write error");
	for (int k = 0; k < job.clip_count; k++) {
		for (int i = 0; i < job.clips[k].level_count; i++)
			if (job.clips[k].levels[i].ok) {
				mlod_motion_level_free(&job.clips[k].levels[i].l);
				mlod_weight_tracks_free(job.clips[k].levels[i].w, job.clips[k].levels[i].w_count);
			}
		mlod_weight_tracks_free(job.clips[k].w, job.clips[k].w_count);
	}
	free(job.clips);
	mlod_character_free(&job.c);
	mlod_gltf_free(doc);
	return 0;
}
