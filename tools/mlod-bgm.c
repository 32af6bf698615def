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

#include <ctype.h>
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "common.h"

#define MAX_LEVELS 16
#define DEG40 0.69813170f
#define TRAIN_SEED 1       /* the posed cost's random poses */
#define MEASURE_SEED 2008  /* the measured error's random poses: others than the cost saw */
#define RANDOM_POSES 8

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
	"                           (default 0.5,0.25,0.1)\n"
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
	"  -p, --placement NAME     new vertex: optimal (default) or barycenter\n"
	"  -E, --eligibility NAME   vertices that may go: all, bend or literal\n"
	"                           (default: all with the posed cost, bend otherwise)\n"
	"  -t, --tau T              eligibility threshold factor (default 1)\n"
	"  -b, --allow-border       let collapses move and remove border vertices\n"
	"  -s, --split DIR          also write one glb per level into DIR: the input\n"
	"                           with that level's meshes in place\n"
	"  -h, --help               show this help\n"
	"  -V, --version            show the version\n"
	"\n"
	"exit status: 0 success, 1 usage, 2 bad input, 3 unsupported input,\n"
	"4 output failure.\n";

/* One primitive of one instance. */
struct part {
	mlod_bgm *bgm;          /* NULL: left as it is */
	int triangles;
	int prefix[MAX_LEVELS];
	int k;                  /* the level being made: its prefix */
};

enum budget { BUDGET_DEFAULT, BUDGET_CHARACTER, BUDGET_PRIMITIVE };

struct level {
	double ratio;           /* requested, or found under --max-error */
	mlod_mesh *meshes;      /* one per instance */
	unsigned char **owned;  /* per instance and primitive: extracted (else the original's) */
	int *skins;             /* per instance: the glTF skin of a skinned level mesh (level_skins) */
	mlod_character view;    /* the character with these meshes */
	int triangles, vertices, caps, collapses;
	double collapse_seconds;
	mlod_deviation error;
};

struct job {
	const char *input;
	mlod_character c;
	mlod_bgm_options opt;
	enum budget budget;
	double *eta;
	mlod_pose_set train, measure;
	struct part **parts;    /* per instance, per primitive */
	int simplified;         /* primitives with a BGM */
	int statics;            /* of them, on no joint and no skin */
	int triangles, vertices;
	double build_seconds;
	int level_count;
	struct level levels[MAX_LEVELS];
	char notes[2048];
	int skeleton_levels;    /* skeleton levels found in the input */
};

static void note(struct job *job, const char *fmt, ...)
#if defined(__GNUC__)
	__attribute__((format(printf, 2, 3)))
#endif
	;

static void note(struct job *job, const char *fmt, ...)
{
	size_t n = strlen(job->notes);
	if (n + 4 >= sizeof job->notes)
		return;
	if (n)
		n += (size_t)snprintf(job->notes + n, sizeof job->notes - n, "; ");
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(job->notes + n, sizeof job->notes - n, fmt, ap);
	va_end(ap);
}

static int double_desc(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return (x < y) - (x > y);
}

/* ---------------------------------------------------------------- */
/* A small JSON reader for extras.mlod.skeleton_levels               */
/* ---------------------------------------------------------------- */

typedef struct jv {
	char type;          /* 'o' object, 'a' array, 'n' number, 's' string, 'l' literal */
	double number;
	char *key;          /* member name inside an object */
	char *text;         /* string value */
	int count;
	struct jv *items;
	const char *start, *end; /* the value's text */
} jv;

static void jv_free(jv *v)
{
	for (int i = 0; i < v->count; i++)
		jv_free(&v->items[i]);
	free(v->items);
	free(v->key);
	free(v->text);
}

static const char *skip_ws(const char *s)
{
	while (*s && isspace((unsigned char)*s))
		s++;
	return s;
}

/* Parses a JSON string at s (after the quote); NULL on error. */
static const char *parse_string(const char *s, char **out)
{
	size_t cap = 16, n = 0;
	char *buf = malloc(cap);
	if (!buf)
		return NULL;
	while (*s && *s != '"') {
		char ch = *s++;
		if (ch == '\\') {
			if (!*s) {
				free(buf);
				return NULL;
			}
			ch = *s++;
			if (ch == 'u') { /* keep escapes of names as '?' */
				for (int i = 0; i < 4; i++)
					if (!isxdigit((unsigned char)*s++)) {
						free(buf);
						return NULL;
					}
				ch = '?';
			} else if (ch == 'n')
				ch = '\n';
			else if (ch == 't')
				ch = '\t';
		}
		if (n + 2 > cap) {
			char *b = realloc(buf, cap *= 2);
			if (!b) {
				free(buf);
				return NULL;
			}
			buf = b;
		}
		buf[n++] = ch;
	}
	if (*s != '"') {
		free(buf);
		return NULL;
	}
	buf[n] = 0;
	*out = buf;
	return s + 1;
}

static const char *parse_value1(const char *s, jv *v, int depth);

static const char *parse_value(const char *s, jv *v, int depth)
{
	s = skip_ws(s);
	const char *end = parse_value1(s, v, depth);
	if (!end) {
		jv_free(v);
		memset(v, 0, sizeof *v);
		return NULL;
	}
	v->start = s;
	v->end = end;
	return end;
}

static const char *parse_value1(const char *s, jv *v, int depth)
{
	memset(v, 0, sizeof *v);
	if (depth > 64)
		return NULL;
	if (*s == '{' || *s == '[') {
		char close = *s == '{' ? '}' : ']';
		v->type = *s == '{' ? 'o' : 'a';
		s = skip_ws(s + 1);
		if (*s == close)
			return s + 1;
		for (;;) {
			jv item;
			char *key = NULL;
			if (v->type == 'o') {
				if (*s != '"' || !(s = parse_string(s + 1, &key)))
					return NULL;
				s = skip_ws(s);
				if (*s != ':') {
					free(key);
					return NULL;
				}
				s++;
			}
			if (!(s = parse_value(s, &item, depth + 1))) {
				free(key);
				return NULL;
			}
			item.key = key;
			jv *items = realloc(v->items, sizeof *items * (size_t)(v->count + 1));
			if (!items) {
				jv_free(&item);
				return NULL;
			}
			v->items = items;
			v->items[v->count++] = item;
			s = skip_ws(s);
			if (*s == ',') {
				s = skip_ws(s + 1);
				continue;
			}
			if (*s != close)
				return NULL;
			return s + 1;
		}
	}
	if (*s == '"') {
		v->type = 's';
		return parse_string(s + 1, &v->text);
	}
	char *end;
	v->number = strtod(s, &end);
	if (end != s) {
		v->type = 'n';
		return end;
	}
	v->type = 'l';
	while (isalpha((unsigned char)*s))
		s++;
	return s;
}

static const jv *member(const jv *o, const char *key)
{
	if (!o || o->type != 'o')
		return NULL;
	for (int i = 0; i < o->count; i++)
		if (o->items[i].key && strcmp(o->items[i].key, key) == 0)
			return &o->items[i];
	return NULL;
}

/* ---------------------------------------------------------------- */
/* Building and simplifying                                          */
/* ---------------------------------------------------------------- */

static int primitive_triangles(const mlod_primitive *p)
{
	if (p->mode != 4)
		return 0;
	return (p->index_count > 0 ? p->index_count : p->vertex_count) / 3;
}

static void make_poses(struct job *job)
{
	mlod_error err = {0};
	int clips = job->c.clip_count > 0 ? job->c.clip_count : 1;
	int per_train = 24 / clips, per_measure = 16 / clips;
	per_train = per_train < 2 ? 2 : per_train > 8 ? 8 : per_train;
	per_measure = per_measure < 2 ? 2 : per_measure > 4 ? 4 : per_measure; /* mlod_clip_times: 1 means all */
	mlod_result r = mlod_pose_set_make(&job->c, 0, per_train, RANDOM_POSES, TRAIN_SEED, DEG40, &job->train, &err);
	if (r == MLOD_OK)
		r = mlod_pose_set_make(&job->c, 1, per_measure, RANDOM_POSES, MEASURE_SEED, DEG40, &job->measure, &err);
	if (r != MLOD_OK)
		tool_die(tool_exit_code(r), job->input, "%s", err.message);
}

/* Builds the BGM of every triangle primitive and simplifies it down to
 * target_ratio of its triangles (0: as far as it goes). */
static void build_all(struct job *job, double target_ratio)
{
	mlod_error err = {0};
	mlod_character *c = &job->c;
	int unsupported = 0, morphs = 0, caps_total = 0;
	job->eta = calloc((size_t)c->skeleton.joint_count + 1, sizeof *job->eta);
	job->parts = calloc((size_t)c->instance_count + 1, sizeof *job->parts);
	if (!job->eta || !job->parts)
		tool_die(EXIT_INPUT, job->input, "out of memory");
	mlod_result r = mlod_joint_weight_average(c, job->eta, &err);
	if (r != MLOD_OK)
		tool_die(tool_exit_code(r), job->input, "%s", err.message);
	job->opt.eta = job->eta;
	job->opt.poses = &job->train;
	for (int i = 0; i < c->instance_count; i++) {
		const mlod_instance *in = &c->instances[i];
		const mlod_mesh *m = &c->meshes[in->mesh];
		job->parts[i] = calloc((size_t)m->primitive_count + 1, sizeof **job->parts);
		if (!job->parts[i])
			tool_die(EXIT_INPUT, job->input, "out of memory");
		for (int p = 0; p < m->primitive_count; p++) {
			const mlod_primitive *pr = &m->primitives[p];
			struct part *pt = &job->parts[i][p];
			pt->triangles = primitive_triangles(pr);
			job->triangles += pt->triangles;
			job->vertices += pr->vertex_count;
			if (pt->triangles < 4 || in->node < 0)
				continue;
			r = mlod_bgm_build(c, i, p, &job->opt, &pt->bgm, &err);
			if (r == MLOD_ERR_UNSUPPORTED) {
				unsupported++;
				continue;
			}
			if (r != MLOD_OK)
				tool_die(tool_exit_code(r), job->input, "%s", err.message);
			int target = target_ratio > 0.0 ? (int)ceil(target_ratio * pt->triangles) : 0;
			if ((r = mlod_bgm_simplify(pt->bgm, target, 0, &err)) != MLOD_OK)
				tool_die(tool_exit_code(r), job->input, "%s", err.message);
			mlod_bgm_info info;
			mlod_bgm_get_info(pt->bgm, &info);
			job->build_seconds += info.build_seconds;
			job->simplified++;
			job->statics += in->skin < 0 && in->joint < 0;
			morphs += pr->target_count > 0;
			caps_total += info.caps;
		}
	}
	/* A character budget may take any primitive further than the ratio. */
	for (int i = 0; job->budget == BUDGET_CHARACTER && target_ratio > 0.0 && i < c->instance_count; i++)
		for (int p = 0; p < c->meshes[c->instances[i].mesh].primitive_count; p++)
			if (job->parts[i][p].bgm && (r = mlod_bgm_simplify(job->parts[i][p].bgm, 0, 0, &err)) != MLOD_OK)
				tool_die(tool_exit_code(r), job->input, "%s", err.message);
	if (job->statics)
		note(job, "%d primitive(s) of static meshes (no joint, no skin) simplified in world space", job->statics);
	if (unsupported)
		note(job, "%d primitive(s) that are not triangles left as they are", unsupported);
	if (morphs)
		note(job, "%d primitive(s) with morph targets: offsets interpolated like positions", morphs);
	(void)caps_total;
}

/* The character budget: ratio of all simplified triangles, shared among
 * the primitives by posed cost (mlod_bgm_share_budget). Sets each part's
 * k. */
static void character_prefixes(struct job *job, double ratio)
{
	const mlod_character *c = &job->c;
	int n = 0, at = 0;
	long total = 0;
	for (int i = 0; i < c->instance_count; i++)
		n += c->meshes[c->instances[i].mesh].primitive_count;
	mlod_bgm **bgms = calloc((size_t)n + 1, sizeof *bgms);
	int *prefix = calloc((size_t)n + 1, sizeof *prefix);
	if (!bgms || !prefix)
		tool_die(EXIT_INPUT, job->input, "out of memory");
	for (int i = 0; i < c->instance_count; i++)
		for (int p = 0; p < c->meshes[c->instances[i].mesh].primitive_count; p++) {
			struct part *pt = &job->parts[i][p];
			bgms[at++] = pt->bgm;
			total += mlod_bgm_triangles(pt->bgm, 0); /* 0 without a BGM; degenerate faces dropped */
		}
	mlod_bgm_share_budget(bgms, n, (long)ceil(ratio * (double)total), prefix);
	at = 0;
	for (int i = 0; i < c->instance_count; i++)
		for (int p = 0; p < c->meshes[c->instances[i].mesh].primitive_count; p++)
			job->parts[i][p].k = prefix[at++];
	free(bgms);
	free(prefix);
}

/* Extracts level lv at ratio (with the primitive budget, per primitive
 * the shortest prefix within ratio of its triangles; with the character
 * budget, character_prefixes) and measures it. */
static void make_level(struct job *job, struct level *lv, double ratio)
{
	mlod_error err = {0};
	mlod_character *c = &job->c;
	lv->ratio = ratio;
	lv->meshes = calloc((size_t)c->instance_count + 1, sizeof *lv->meshes);
	lv->owned = calloc((size_t)c->instance_count + 1, sizeof *lv->owned);
	lv->skins = calloc((size_t)c->instance_count + 1, sizeof *lv->skins);
	if (!lv->meshes || !lv->owned || !lv->skins)
		tool_die(EXIT_INPUT, job->input, "out of memory");
	double seconds = 0.0;
	if (job->budget == BUDGET_CHARACTER)
		character_prefixes(job, ratio);
	for (int i = 0; i < c->instance_count; i++) {
		const mlod_mesh *m = &c->meshes[c->instances[i].mesh];
		mlod_mesh *lm = &lv->meshes[i];
		lm->name = m->name;
		lm->gltf_index = m->gltf_index;
		lm->primitive_count = m->primitive_count;
		lm->primitives = calloc((size_t)m->primitive_count + 1, sizeof *lm->primitives);
		lv->owned[i] = calloc((size_t)m->primitive_count + 1, 1);
		if (!lm->primitives || !lv->owned[i])
			tool_die(EXIT_INPUT, job->input, "out of memory");
		for (int p = 0; p < m->primitive_count; p++) {
			struct part *pt = &job->parts[i][p];
			if (!pt->bgm) {
				lm->primitives[p] = m->primitives[p];
				lv->triangles += pt->triangles;
				lv->vertices += m->primitives[p].vertex_count;
				continue;
			}
			int k = job->budget == BUDGET_CHARACTER ? pt->k : mlod_bgm_prefix_for(pt->bgm, (int)ceil(ratio * pt->triangles));
			mlod_result r = mlod_bgm_extract(pt->bgm, k, c->instances[i].skin < 0, &lm->primitives[p], &err);
			if (r != MLOD_OK)
				tool_die(tool_exit_code(r), job->input, "%s", err.message);
			lv->owned[i][p] = 1;
			lv->triangles += lm->primitives[p].index_count / 3;
			lv->vertices += lm->primitives[p].vertex_count;
			int count;
			const mlod_vsplit *seq = mlod_bgm_sequence(pt->bgm, &count);
			for (int s = 0; s < k; s++)
				lv->caps += seq[s].capped;
			lv->collapses += k;
			if (k > 0)
				seconds += seq[k - 1].seconds;
		}
	}
	lv->collapse_seconds = seconds;
	lv->view = *c;
	lv->view.meshes = lv->meshes;
	lv->view.mesh_count = c->instance_count;
	lv->view.instances = malloc(sizeof *lv->view.instances * ((size_t)c->instance_count + 1));
	if (!lv->view.instances)
		tool_die(EXIT_INPUT, job->input, "out of memory");
	for (int i = 0; i < c->instance_count; i++) {
		lv->view.instances[i] = c->instances[i];
		lv->view.instances[i].mesh = i;
	}
	mlod_result r = mlod_posed_error(c, &lv->view, &job->measure, &lv->error, &err);
	if (r != MLOD_OK)
		tool_die(tool_exit_code(r), job->input, "%s", err.message);
}

static void free_level(struct job *job, struct level *lv)
{
	for (int i = 0; lv->meshes && i < job->c.instance_count; i++) {
		for (int p = 0; p < lv->meshes[i].primitive_count; p++)
			if (lv->owned[i][p])
				mlod_primitive_free(&lv->meshes[i].primitives[p]);
		free(lv->meshes[i].primitives);
		free(lv->owned[i]);
	}
	free(lv->meshes);
	free(lv->owned);
	free(lv->skins);
	free(lv->view.instances);
	memset(lv, 0, sizeof *lv);
}

/* --max-error: halve the triangles while the error stays within bound;
 * past it, bisect for the coarsest ratio within it and stop. */
static void error_levels(struct job *job, double bound)
{
	double accepted = 1.0;
	for (double ratio = 0.5; ratio >= 1.0 / 256 && job->level_count < MAX_LEVELS; ratio /= 2) {
		struct level lv = {0};
		make_level(job, &lv, ratio);
		if (job->level_count > 0 && lv.triangles >= job->levels[job->level_count - 1].triangles) {
			free_level(job, &lv); /* nothing more comes off */
			break;
		}
		if (lv.error.max <= bound) {
			job->levels[job->level_count++] = lv;
			accepted = ratio;
			continue;
		}
		free_level(job, &lv);
		double lo = ratio, hi = accepted; /* lo fails, hi passes */
		struct level best = {0};
		for (int it = 0; it < 6; it++) {
			double mid = 0.5 * (lo + hi);
			struct level trial = {0};
			make_level(job, &trial, mid);
			if (trial.error.max <= bound) {
				free_level(job, &best);
				best = trial;
				hi = mid;
			} else {
				free_level(job, &trial);
				lo = mid;
			}
		}
		if (best.meshes && (job->level_count == 0 || best.triangles < job->levels[job->level_count - 1].triangles))
			job->levels[job->level_count++] = best;
		else
			free_level(job, &best);
		break;
	}
}

/* ---------------------------------------------------------------- */
/* glb output                                                        */
/* ---------------------------------------------------------------- */

/* Skeleton levels written by mlod-skelgraph: per level, the glTF skin
 * standing for each character skin and the removed-node -> stand-in-node
 * table. */
struct skel_levels {
	int count;
	int *skins;   /* count * skin_count glTF skin indices (-1: none) */
	int *remap;   /* count * node_count: stand-in node of each node */
	int nodes;
};

static void read_skeleton_levels(struct job *job, mlod_gltf *doc, struct skel_levels *out)
{
	memset(out, 0, sizeof *out);
	char *text = NULL;
	mlod_error err = {0};
	if (mlod_gltf_count(doc, MLOD_GLTF_SCENE) == 0 ||
	    mlod_gltf_get_extra(doc, MLOD_GLTF_SCENE, -1, "mlod", &text, &err) != MLOD_OK || !text)
		return;
	jv root;
	const char *end = parse_value(text, &root, 0);
	mlod_free(text);
	if (!end) {
		note(job, "scene extras.mlod is not JSON: skeleton levels ignored");
		return;
	}
	const jv *levels = member(&root, "skeleton_levels");
	int skins = job->c.skeleton.skin_count, nodes = mlod_gltf_count(doc, MLOD_GLTF_NODE);
	if (levels && levels->type == 'a' && levels->count > 0) {
		out->count = levels->count;
		out->nodes = nodes;
		out->skins = malloc(sizeof(int) * (size_t)(levels->count * skins + 1));
		out->remap = malloc(sizeof(int) * (size_t)levels->count * (size_t)(nodes + 1));
		if (!out->skins || !out->remap)
			tool_die(EXIT_INPUT, job->input, "out of memory");
		for (int k = 0; k < levels->count; k++) {
			const jv *sk = member(&levels->items[k], "skins"), *rm = member(&levels->items[k], "remap");
			for (int n = 0; n < nodes; n++)
				out->remap[k * nodes + n] = n;
			for (int s = 0; s < skins; s++) {
				int v = sk && sk->type == 'a' && s < sk->count && sk->items[s].type == 'n' ? (int)sk->items[s].number : -1;
				out->skins[k * skins + s] = v >= 0 && v < mlod_gltf_count(doc, MLOD_GLTF_SKIN) ? v : -1;
			}
			for (int i = 0; rm && rm->type == 'o' && i < rm->count; i++) {
				int from = atoi(rm->items[i].key), to = rm->items[i].type == 'n' ? (int)rm->items[i].number : -1;
				if (from >= 0 && from < nodes && to >= 0 && to < nodes)
					out->remap[k * nodes + from] = to;
			}
		}
	}
	jv_free(&root);
}

/* The character skin whose glTF index is gltf, or -1. */
static int skin_of_gltf(const mlod_skeleton *s, int gltf)
{
	for (int i = 0; i < s->skin_count; i++)
		if (s->skins[i].gltf_index == gltf)
			return i;
	return -1;
}

/* Remaps the level mesh of a skinned instance to skeleton level k's skin:
 * every primitive must be one the level made (an unsimplified primitive
 * shares the input's accessors) and every weighted joint must have a
 * stand-in in that skin. Returns the skin's glTF index, or -1 when that
 * is not so (then nothing changed). */
static int remap_to_skeleton_level(struct job *job, const struct skel_levels *sl, int k, int skin, mlod_mesh *m,
                                   const unsigned char *owned)
{
	const mlod_skeleton *s = &job->c.skeleton;
	int target = sl->skins[k * s->skin_count + skin], ts = skin_of_gltf(s, target);
	if (target < 0 || ts < 0)
		return -1;
	const mlod_skin *from = &s->skins[skin], *to = &s->skins[ts];
	int *map = malloc(sizeof(int) * ((size_t)from->joint_count + 1));
	if (!map)
		tool_die(EXIT_INPUT, job->input, "out of memory");
	for (int j = 0; j < from->joint_count; j++) {
		int node = s->joints[from->joints[j]].node;
		int stand = node >= 0 && node < sl->nodes ? sl->remap[k * sl->nodes + node] : node;
		map[j] = -1;
		for (int t = 0; t < to->joint_count; t++)
			if (s->joints[to->joints[t]].node == stand)
				map[j] = t;
	}
	/* Check everything first, so a failure leaves the mesh as it was. */
	int ok = 1;
	for (int p = 0; ok && p < m->primitive_count; p++) {
		const mlod_primitive *q = &m->primitives[p];
		ok = owned[p] != 0;
		for (int set = 0; ok && set < q->weight_set_count; set++)
			for (long v = 0; ok && v < 4L * q->vertex_count; v++)
				ok = !(q->weights[set][v] > 0.0f) || (q->joints[set][v] < from->joint_count && map[q->joints[set][v]] >= 0);
	}
	for (int p = 0; ok && p < m->primitive_count; p++) {
		mlod_error err = {0};
		if (mlod_primitive_remap_joints(&m->primitives[p], map, from->joint_count, &err) != MLOD_OK)
			tool_die(EXIT_OUTPUT, NULL, "%s", err.message); /* cannot happen after the check */
	}
	free(map);
	return ok ? target : -1;
}

/* A skin of one joint for a rigid instance: world = W_joint * offset * p.
 * With skeleton level k, the joint's stand-in carries it with the rest
 * transform between them. Returns its glTF index. */
static int rigid_skin(struct job *job, mlod_gltf *doc, const mlod_instance *in, int stand_joint)
{
	const mlod_skeleton *s = &job->c.skeleton;
	mlod_mat4 ibm = in->offset;
	if (stand_joint != in->joint) {
		mlod_trs *local = malloc(sizeof *local * (size_t)s->joint_count);
		mlod_mat4 *world = malloc(sizeof *world * (size_t)s->joint_count), inv;
		if (!local || !world)
			tool_die(EXIT_INPUT, job->input, "out of memory");
		mlod_pose_rest(s, local);
		mlod_pose_world(s, local, world);
		if (mlod_mat4_invert(&world[stand_joint], &inv) == 0) {
			mlod_mat4 rel = mlod_mat4_mul(&inv, &world[in->joint]);
			ibm = mlod_mat4_mul(&rel, &in->offset);
		} else {
			stand_joint = in->joint;
		}
		free(local);
		free(world);
	}
	int joints[1] = {stand_joint};
	mlod_skin skin = {0};
	skin.name = "mlod rigid part";
	skin.joint_count = 1;
	skin.joints = joints;
	skin.inverse_bind = &ibm;
	skin.gltf_index = -1;
	int index = -1;
	mlod_error err = {0};
	if (mlod_gltf_add_skin(doc, s, &skin, &index, &err) != MLOD_OK)
		tool_die(EXIT_OUTPUT, NULL, "%s", err.message);
	return index;
}

/* The joint standing for j in skeleton level k (j itself without levels). */
static int stand_in_joint(const struct job *job, const struct skel_levels *sl, int k, int j)
{
	const mlod_skeleton *s = &job->c.skeleton;
	if (k < 0 || sl->count == 0 || s->joints[j].node < 0 || s->joints[j].node >= sl->nodes)
		return j;
	int node = sl->remap[k * sl->nodes + s->joints[j].node];
	for (int t = 0; t < s->joint_count; t++)
		if (s->joints[t].node == node)
			return t;
	return j;
}

/* Does instance i get levels (a node, and a primitive with a BGM)? */
static int has_levels(const struct job *job, int i)
{
	const mlod_instance *in = &job->c.instances[i];
	if (in->node < 0)
		return 0;
	for (int p = 0; p < job->c.meshes[in->mesh].primitive_count; p++)
		if (job->parts[i][p].bgm)
			return 1;
	return 0;
}

/* The skeleton level matching mesh level k, or -1 without any. */
static int skeleton_level(const struct skel_levels *sl, int k)
{
	return sl->count > 0 ? (k < sl->count ? k : sl->count - 1) : -1;
}

/* The glTF skin of each skinned level mesh: the instance's own, or the
 * matching skeleton level's when mlod-skelgraph ran before (the level
 * mesh's joints are then remapped to it, once for every output). */
static void level_skins(struct job *job, const struct skel_levels *sl)
{
	const mlod_character *c = &job->c;
	int fallback = 0;
	for (int k = 0; k < job->level_count; k++) {
		struct level *lv = &job->levels[k];
		int sk = skeleton_level(sl, k);
		for (int i = 0; i < c->instance_count; i++) {
			const mlod_instance *in = &c->instances[i];
			lv->skins[i] = -1;
			if (in->skin < 0 || !has_levels(job, i))
				continue;
			lv->skins[i] = c->skeleton.skins[in->skin].gltf_index;
			if (sk < 0)
				continue;
			int target = remap_to_skeleton_level(job, sl, sk, in->skin, &lv->meshes[i], lv->owned[i]);
			if (target >= 0)
				lv->skins[i] = target;
			else
				fallback++;
		}
	}
	if (sl->count > 0)
		note(job, "skeleton levels found: mesh level k uses skeleton level k's skins%s",
		     fallback ? " (some fell back to the full skin)" : "");
}

/* Sets extras.mlod[key] of the default scene to value (JSON), next to the
 * keys already there (the skeleton levels, say). */
static void set_scene_mlod(mlod_gltf *doc, const char *key, const char *value)
{
	mlod_error err = {0};
	if (mlod_gltf_count(doc, MLOD_GLTF_SCENE) == 0)
		return;
	char *old = NULL;
	if (mlod_gltf_get_extra(doc, MLOD_GLTF_SCENE, -1, "mlod", &old, &err) != MLOD_OK)
		tool_die(EXIT_OUTPUT, NULL, "%s", err.message);
	size_t len = old ? strlen(old) : 0, size = len + strlen(key) + strlen(value) + 64;
	char *json = malloc(size);
	if (!json)
		tool_die(EXIT_OUTPUT, NULL, "out of memory");
	jv parsed;
	int parsed_ok = old && parse_value(old, &parsed, 0), object = parsed_ok && parsed.type == 'o';
	const jv *prev = object ? member(&parsed, key) : NULL;
	if (prev) /* from an earlier run: replaced */
		snprintf(json, size, "%.*s%s%s", (int)(prev->start - old), old, value, prev->end);
	else if (object && parsed.count > 0)
		snprintf(json, size, "%.*s,\"%s\":%s}", (int)(parsed.end - 1 - old), old, key, value);
	else
		snprintf(json, size, "{\"%s\":%s}", key, value);
	if (parsed_ok)
		jv_free(&parsed);
	mlod_free(old);
	if (mlod_gltf_set_extra(doc, MLOD_GLTF_SCENE, -1, "mlod", json, &err) != MLOD_OK)
		tool_die(EXIT_OUTPUT, NULL, "%s", err.message);
	free(json);
}

/* A level's summary as JSON into buf. */
static void level_json(const struct level *lv, int k, char *buf, size_t size)
{
	snprintf(buf, size,
	         "{\"level\":%d,\"ratio\":%.6g,\"triangles\":%d,\"vertices\":%d,"
	         "\"error_percent\":{\"mean\":%.9g,\"max\":%.9g}}",
	         k + 1, lv->ratio, lv->triangles, lv->vertices, lv->error.mean, lv->error.max);
}

static int has_targets(const mlod_mesh *m)
{
	for (int p = 0; p < m->primitive_count; p++)
		if (m->primitives[p].target_count > 0)
			return 1;
	return 0;
}

/* Adds level mesh m of instance i like its glTF mesh (name, morph weights,
 * extras); returns its index. */
static int add_level_mesh(const struct job *job, mlod_gltf *doc, int i, const mlod_mesh *m)
{
	mlod_error err = {0};
	int like = job->c.meshes[job->c.instances[i].mesh].gltf_index, mesh = -1;
	mlod_result r = like >= 0 && like < mlod_gltf_count(doc, MLOD_GLTF_MESH)
	                    ? mlod_gltf_add_mesh_like(doc, like, m, &mesh, &err)
	                    : mlod_gltf_add_mesh(doc, m, &mesh, &err);
	if (r != MLOD_OK)
		tool_die(EXIT_OUTPUT, NULL, "%s", err.message);
	return mesh;
}

static void write_glb(struct job *job, mlod_gltf *doc, const char *output, const struct skel_levels *sl)
{
	mlod_error err = {0};
	mlod_character *c = &job->c;
	int morph_channels = 0, untransformable = 0;
	float coverage[MAX_LEVELS + 1];
	for (int k = 0; k < job->level_count; k++)
		coverage[k] = (float)mlod_error_coverage(job->levels[k].error.max, 1080.0, 1.0);
	coverage[job->level_count] = 0.0f;
	for (int k = 1; k <= job->level_count; k++)
		if (coverage[k] > coverage[k - 1])
			coverage[k] = coverage[k - 1];

	for (int i = 0; job->level_count > 0 && i < c->instance_count; i++) {
		const mlod_instance *in = &c->instances[i];
		if (!has_levels(job, i))
			continue;
		/* A static level node stands where the node stands: same local transform. */
		mlod_trs local, *trs = NULL;
		if (in->skin < 0 && in->joint < 0) {
			if (mlod_gltf_get_node_trs(doc, in->node, &local, &err) != MLOD_OK) {
				untransformable++;
				continue;
			}
			trs = &local;
		}
		int lod_nodes[MAX_LEVELS], rigid_joint = -1, rigid_index = -1;
		for (int k = 0; k < job->level_count; k++) {
			struct level *lv = &job->levels[k];
			int sk = skeleton_level(sl, k), skin = lv->skins[i], node = -1;
			if (in->skin < 0 && in->joint >= 0) { /* rigid: skinned to its joint's stand-in */
				int joint = stand_in_joint(job, sl, sk, in->joint);
				if (joint != rigid_joint) {
					rigid_joint = joint;
					rigid_index = rigid_skin(job, doc, in, joint);
				}
				skin = rigid_index;
			}
			int mesh = add_level_mesh(job, doc, i, &lv->meshes[i]);
			char name[96];
			snprintf(name, sizeof name, "mlod mesh level %d of node %d", k + 1, in->node);
			if (mlod_gltf_add_node(doc, name, MLOD_GLTF_DETACHED, mesh, skin, trs, &node, &err) != MLOD_OK)
				tool_die(EXIT_OUTPUT, NULL, "%s", err.message);
			if (has_targets(&lv->meshes[i])) {
				int added = 0;
				if (mlod_gltf_copy_morph_animation(doc, in->node, node, &added, &err) != MLOD_OK)
					tool_die(EXIT_OUTPUT, NULL, "%s", err.message);
				morph_channels += added;
			}
			char json[256];
			snprintf(json, sizeof json,
			         "{\"mesh_level\":%d,\"ratio\":%.6g,\"error_percent\":{\"mean\":%.9g,\"max\":%.9g}%s}", k + 1,
			         lv->ratio, lv->error.mean, lv->error.max, sk >= 0 && skin >= 0 ? ",\"skeleton_level\":true" : "");
			if (mlod_gltf_set_extra(doc, MLOD_GLTF_NODE, node, "mlod", json, &err) != MLOD_OK)
				tool_die(EXIT_OUTPUT, NULL, "%s", err.message);
			lod_nodes[k] = node;
		}
		if (mlod_gltf_set_lod(doc, in->node, lod_nodes, job->level_count, coverage, &err) != MLOD_OK)
			tool_die(EXIT_OUTPUT, NULL, "%s", err.message);
	}
	if (morph_channels)
		note(job, "%d morph weight channel(s) copied to the level nodes", morph_channels);
	if (untransformable)
		note(job, "%d static mesh node(s) with a sheared matrix: no MSFT_lod", untransformable);

	/* extras.mlod.mesh_levels on the scene, next to what is there. */
	if (job->level_count > 0) {
		char levels[4096];
		size_t n = (size_t)snprintf(levels, sizeof levels, "[");
		for (int k = 0; k < job->level_count && n < sizeof levels - 256; k++) {
			n += (size_t)snprintf(levels + n, sizeof levels - n, "%s", k ? "," : "");
			level_json(&job->levels[k], k, levels + n, sizeof levels - n);
			n = strlen(levels);
		}
		snprintf(levels + n, sizeof levels - n, "]");
		set_scene_mlod(doc, "mesh_levels", levels);
	}
	tool_write_gltf(output, doc);
}

/* One glb per level: the input document with each simplified node's mesh
 * replaced by its level (skinned ones on the matching skeleton level's
 * skin, rigid and static ones where they hang), the full meshes pruned. */
static void write_split(struct job *job, const mlod_gltf *input, const char *dir, const char *input_path)
{
	struct stat st;
	if (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode))
		tool_die(EXIT_OUTPUT, dir, "not a directory");
	const char *base = input_path && strcmp(input_path, "-") != 0 ? strrchr(input_path, '/') : NULL;
	base = base ? base + 1 : input_path && strcmp(input_path, "-") != 0 ? input_path : "stdin";
	size_t blen = strlen(base);
	const char *dot = strrchr(base, '.');
	if (dot && dot != base)
		blen = (size_t)(dot - base);
	const mlod_character *c = &job->c;
	int unpruned = 0;
	for (int k = 0; k < job->level_count; k++) {
		struct level *lv = &job->levels[k];
		mlod_gltf *doc = NULL;
		mlod_error err = {0};
		if (mlod_gltf_copy(input, &doc, &err) != MLOD_OK)
			tool_die(EXIT_OUTPUT, dir, "level %d: %s", k + 1, err.message);
		for (int i = 0; i < c->instance_count; i++) {
			const mlod_instance *in = &c->instances[i];
			if (!has_levels(job, i))
				continue;
			/* A rigid part stays under its joint: without the weights its level was given. */
			mlod_mesh m = lv->meshes[i];
			mlod_primitive *prims = malloc(sizeof *prims * ((size_t)m.primitive_count + 1));
			if (!prims)
				tool_die(EXIT_OUTPUT, dir, "out of memory");
			for (int p = 0; p < m.primitive_count; p++) {
				prims[p] = m.primitives[p];
				if (in->skin < 0 && lv->owned[i][p])
					prims[p].weight_set_count = 0;
			}
			m.primitives = prims;
			int mesh = add_level_mesh(job, doc, i, &m);
			free(prims);
			/* A level file holds one level: the node's earlier levels (the
			 * skeleton levels' nodes, say) go. */
			if (mlod_gltf_clear_lod(doc, in->node, &err) != MLOD_OK ||
			    mlod_gltf_set_node_mesh(doc, in->node, mesh, lv->skins[i], &err) != MLOD_OK)
				tool_die(EXIT_OUTPUT, dir, "level %d: %s", k + 1, err.message);
		}
		char json[512];
		level_json(lv, k, json, sizeof json);
		set_scene_mlod(doc, "mesh_level", json);
		mlod_result r = mlod_gltf_prune(doc, &err);
		if (r == MLOD_ERR_UNSUPPORTED)
			unpruned = 1;
		else if (r != MLOD_OK)
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
	if (unpruned)
		note(job, "the split glb keep the full meshes too: an extension may refer to them");
}

/* ---------------------------------------------------------------- */
/* Reports                                                           */
/* ---------------------------------------------------------------- */

static const char *cost_name(mlod_mesh_cost c)
{
	return c == MLOD_COST_COMPACTNESS ? "compactness" : "posed";
}

static const char *budget_name(enum budget b)
{
	return b == BUDGET_PRIMITIVE ? "primitive" : "character";
}

static const char *collapse_name(const mlod_bgm_options *o)
{
	mlod_collapse_op op = o->op;
	if (op == MLOD_OP_DEFAULT)
		op = o->cost == MLOD_COST_COMPACTNESS ? MLOD_OP_TRIANGLE : MLOD_OP_EDGE;
	return op == MLOD_OP_TRIANGLE ? "triangle" : op == MLOD_OP_EDGE ? "edge" : "mixed";
}

static const char *placement_name(mlod_placement p)
{
	return p == MLOD_PLACE_BARYCENTER ? "barycenter" : "optimal";
}

static const char *eligibility_name(const mlod_bgm_options *o)
{
	mlod_eligibility e = o->eligibility;
	if (e == MLOD_ELIGIBLE_DEFAULT)
		e = o->cost == MLOD_COST_COMPACTNESS ? MLOD_ELIGIBLE_BEND : MLOD_ELIGIBLE_ALL;
	return e == MLOD_ELIGIBLE_LITERAL ? "literal" : e == MLOD_ELIGIBLE_BEND ? "bend" : "all";
}

static void totals(const struct job *job, mlod_bgm_info *sum)
{
	memset(sum, 0, sizeof *sum);
	for (int i = 0; i < job->c.instance_count; i++)
		for (int p = 0; p < job->c.meshes[job->c.instances[i].mesh].primitive_count; p++) {
			const mlod_bgm *g = job->parts[i][p].bgm;
			if (!g)
				continue;
			mlod_bgm_info in;
			mlod_bgm_get_info(g, &in);
			sum->nodes += in.nodes;
			sum->seam_nodes += in.seam_nodes;
			sum->border_edges += in.border_edges;
			sum->nonmanifold_edges += in.nonmanifold_edges;
			sum->locked_nodes += in.locked_nodes;
			sum->eligible_nodes += in.eligible_nodes;
			sum->dropped += in.dropped;
			sum->refused += in.refused;
			sum->snaps += in.snaps;
		}
}

static void report_table(const struct job *job)
{
	mlod_bgm_info t;
	totals(job, &t);
	printf("# %s: %d triangles, %d vertices (%d welded nodes, %d on seams, %d eligible, %d locked); "
	       "%d border and %d non-manifold edges; %d primitives simplified; build %.1f ms\n",
	       job->input, job->triangles, job->vertices, t.nodes, t.seam_nodes, t.eligible_nodes, t.locked_nodes,
	       t.border_edges, t.nonmanifold_edges, job->simplified, 1e3 * job->build_seconds);
	printf("# cost %s, %s collapses, budget per %s, placement %s, eligibility %s (tau %g)%s; error over %d poses (rest, clip "
	       "frames, %d random up to 40 degrees)\n",
	       cost_name(job->opt.cost), collapse_name(&job->opt), budget_name(job->budget), placement_name(job->opt.placement),
	       eligibility_name(&job->opt), job->opt.tau > 0 ? job->opt.tau : 1.0,
	       job->opt.allow_border ? ", borders allowed" : "", job->measure.count, RANDOM_POSES);
	printf("%5s  %6s  %9s  %8s  %10s  %10s  %5s  %9s  %11s\n", "level", "ratio", "triangles", "vertices", "mean%",
	       "max%", "caps", "build ms", "collapse ms");
	printf("%5d  %6s  %9d  %8d  %10s  %10s  %5s  %9s  %11s\n", 0, "1", job->triangles, job->vertices, "0", "0", "-",
	       "-", "-");
	for (int k = 0; k < job->level_count; k++) {
		const struct level *lv = &job->levels[k];
		printf("%5d  %6.4g  %9d  %8d  %10.4f  %10.4f  %5d  %9.1f  %11.1f\n", k + 1, lv->ratio, lv->triangles,
		       lv->vertices, lv->error.mean, lv->error.max, lv->caps, 1e3 * job->build_seconds,
		       1e3 * lv->collapse_seconds);
	}
	printf("# mean%%, max%%: posed surface deviation (mean, Hausdorff) in %% of the bounding diagonal; caps: new "
	       "vertices whose influences were cut to 4\n");
	if (job->notes[0])
		printf("# note: %s\n", job->notes);
	if (job->c.notes && *job->c.notes)
		printf("# input: %s\n", job->c.notes);
}

static void report_json(const struct job *job)
{
	mlod_bgm_info t;
	totals(job, &t);
	printf("{\n  \"input\": ");
	tool_json_string(stdout, job->input);
	printf(",\n  \"triangles\": %d,\n  \"vertices\": %d,\n  \"nodes\": %d,\n  \"seam_nodes\": %d,\n", job->triangles,
	       job->vertices, t.nodes, t.seam_nodes);
	printf("  \"border_edges\": %d,\n  \"nonmanifold_edges\": %d,\n  \"locked_nodes\": %d,\n  \"eligible_nodes\": %d,\n",
	       t.border_edges, t.nonmanifold_edges, t.locked_nodes, t.eligible_nodes);
	printf("  \"simplified_primitives\": %d,\n  \"static_primitives\": %d,\n  \"build_ms\": %.6g,\n", job->simplified,
	       job->statics, 1e3 * job->build_seconds);
	printf("  \"options\": {\"cost\": \"%s\", \"collapse\": \"%s\", \"budget\": \"%s\", \"placement\": \"%s\", "
	       "\"eligibility\": \"%s\", \"tau\": %g, \"allow_border\": %s},\n",
	       cost_name(job->opt.cost), collapse_name(&job->opt), budget_name(job->budget), placement_name(job->opt.placement), eligibility_name(&job->opt),
	       job->opt.tau > 0 ? job->opt.tau : 1.0, job->opt.allow_border ? "true" : "false");
	printf("  \"measured_poses\": %d,\n  \"levels\": [\n", job->measure.count);
	for (int k = 0; k < job->level_count; k++) {
		const struct level *lv = &job->levels[k];
		printf("    {\"level\": %d, \"ratio\": %.6g, \"triangles\": %d, \"vertices\": %d, "
		       "\"error_percent\": {\"mean\": %.9g, \"max\": %.9g}, \"caps\": %d, \"collapses\": %d, "
		       "\"build_ms\": %.6g, \"collapse_ms\": %.6g}%s\n",
		       k + 1, lv->ratio, lv->triangles, lv->vertices, lv->error.mean, lv->error.max, lv->caps, lv->collapses,
		       1e3 * job->build_seconds, 1e3 * lv->collapse_seconds, k + 1 < job->level_count ? "," : "");
	}
	printf("  ],\n  \"notes\": ");
	tool_json_string(stdout, job->notes);
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
		{"split", required_argument, NULL, 's'},
		{"help", no_argument, NULL, 'h'},
		{"version", no_argument, NULL, 'V'},
		{NULL, 0, NULL, 0},
	};
	static const char *const costs[] = {"compactness", "posed"};
	static const char *const ops[] = {"triangle", "edge", "mixed"};
	static const char *const budgets[] = {"character", "primitive"};
	static const char *const placements[] = {"barycenter", "optimal"};
	static const char *const rules[] = {"literal", "bend", "all"};
	const char *output = NULL, *split = NULL;
	enum tool_report report = REPORT_NONE;
	double ratios[MAX_LEVELS] = {0.5, 0.25, 0.1}, max_error = -1.0;
	int ratio_count = 3, ratios_given = 0, ch;
	struct job job;
	memset(&job, 0, sizeof job);

	tool_name = "mlod-bgm";
	opterr = 0;
	while ((ch = getopt_long(argc, argv, ":o:r::R:e:c:C:B:p:E:t:bs:hV", longopts, NULL)) != -1) {
		switch (ch) {
		case 'o': output = optarg; break;
		case 'r': report = tool_parse_report(optarg); break;
		case 'R':
			ratio_count = tool_parse_list("--ratios", optarg, ratios, MAX_LEVELS, 1e-6, 1.0);
			ratios_given = 1;
			break;
		case 'e': max_error = tool_parse_double("--max-error", optarg, 0.0, 100.0); break;
		case 'c': job.opt.cost = (mlod_mesh_cost)(MLOD_COST_COMPACTNESS + parse_enum("--cost", optarg, costs, 2)); break;
		case 'C': job.opt.op = (mlod_collapse_op)(MLOD_OP_TRIANGLE + parse_enum("--collapse", optarg, ops, 3)); break;
		case 'B': job.budget = (enum budget)(BUDGET_CHARACTER + parse_enum("--budget", optarg, budgets, 2)); break;
		case 'p':
			job.opt.placement = (mlod_placement)(MLOD_PLACE_BARYCENTER + parse_enum("--placement", optarg, placements, 2));
			break;
		case 'E':
			job.opt.eligibility = (mlod_eligibility)(MLOD_ELIGIBLE_LITERAL + parse_enum("--eligibility", optarg, rules, 3));
			break;
		case 't': job.opt.tau = tool_parse_double("--tau", optarg, 1e-6, 1e6); break;
		case 'b': job.opt.allow_border = 1; break;
		case 's': split = optarg; break;
		case 'h': fputs(usage_text, stdout); return 0;
		case 'V': tool_version();
		case ':': tool_usage_error("option '%s' needs a value", argv[optind - 1]);
		default: tool_usage_error("unknown option '%s'", argv[optind - 1]);
		}
	}
	if (argc - optind > 1)
		tool_usage_error("too many inputs: one file, or stdin");
	if (ratios_given && max_error >= 0.0)
		tool_usage_error("--ratios and --max-error do not go together");
	if (report != REPORT_NONE && output)
		tool_usage_error("--report and --output do not go together");
	if (job.opt.cost == MLOD_COST_DEFAULT)
		job.opt.cost = MLOD_COST_POSED;
	if (job.opt.cost == MLOD_COST_COMPACTNESS && job.opt.op != MLOD_OP_DEFAULT && job.opt.op != MLOD_OP_TRIANGLE)
		tool_usage_error("--collapse %s needs --cost posed: compactness ranks triangles only", collapse_name(&job.opt));
	if (job.opt.cost == MLOD_COST_COMPACTNESS && job.budget == BUDGET_CHARACTER)
		tool_usage_error("--budget character needs --cost posed: compactness costs do not compare across primitives");
	if (job.budget == BUDGET_DEFAULT) /* measured: see the man page */
		job.budget = job.opt.cost == MLOD_COST_POSED ? BUDGET_CHARACTER : BUDGET_PRIMITIVE;
	if (job.opt.placement == MLOD_PLACE_DEFAULT)
		job.opt.placement = job.opt.cost == MLOD_COST_COMPACTNESS ? MLOD_PLACE_BARYCENTER : MLOD_PLACE_OPTIMAL;
	qsort(ratios, (size_t)ratio_count, sizeof *ratios, double_desc);

	mlod_gltf *doc = NULL;
	const char *input_path = optind < argc ? argv[optind] : NULL;
	job.input = tool_input_label(input_path);
	tool_load(input_path, &doc, &job.c, NULL);

	int meshes = 0;
	for (int i = 0; i < job.c.instance_count; i++)
		for (int p = 0; p < job.c.meshes[job.c.instances[i].mesh].primitive_count; p++)
			meshes += primitive_triangles(&job.c.meshes[job.c.instances[i].mesh].primitives[p]) > 0;
	if (meshes == 0) {
		/* Nothing to simplify (a BVH, a skeleton): pass it through. */
		note(&job, "no triangle mesh: nothing to simplify");
		if (report == REPORT_TABLE)
			report_table(&job);
		else if (report == REPORT_JSON)
			report_json(&job);
		else {
			fprintf(stderr, "%s: %s: no triangle mesh; written unchanged\n", tool_name, job.input);
			tool_write_gltf(output, doc);
		}
	} else {
		make_poses(&job);
		build_all(&job, max_error >= 0.0 ? 0.0 : ratios[ratio_count - 1]);
		if (max_error >= 0.0) {
			error_levels(&job, max_error);
			if (job.level_count == 0)
				fprintf(stderr, "%s: %s: no mesh level within --max-error %g%%\n", tool_name, job.input, max_error);
		} else {
			for (int k = 0; k < ratio_count; k++) {
				struct level lv = {0};
				make_level(&job, &lv, ratios[k]);
				if (job.level_count > 0 && lv.triangles >= job.levels[job.level_count - 1].triangles) {
					note(&job, "ratio %g gives no fewer triangles than %g: dropped", ratios[k],
					     job.levels[job.level_count - 1].ratio);
					free_level(&job, &lv);
					continue;
				}
				if (job.level_count == 0 && lv.triangles >= job.triangles) {
					note(&job, "ratio %g removes nothing: dropped", ratios[k]);
					free_level(&job, &lv);
					continue;
				}
				job.levels[job.level_count++] = lv;
			}
		}
		struct skel_levels sl;
		read_skeleton_levels(&job, doc, &sl);
		job.skeleton_levels = sl.count;
		level_skins(&job, &sl);
		if (split) /* first: write_glb changes doc */
			write_split(&job, doc, split, input_path);
		if (report == REPORT_NONE) {
			write_glb(&job, doc, output, &sl);
		} else {
			if (report == REPORT_TABLE)
				report_table(&job);
			else
				report_json(&job);
		}
		free(sl.skins);
		free(sl.remap);
	}
	if (fflush(stdout) != 0)
		tool_die(EXIT_OUTPUT, "<stdout>", "write error");
	for (int k = 0; k < job.level_count; k++)
		free_level(&job, &job.levels[k]);
	for (int i = 0; job.parts && i < job.c.instance_count; i++) {
		for (int p = 0; p < job.c.meshes[job.c.instances[i].mesh].primitive_count; p++)
			mlod_bgm_free(job.parts[i][p].bgm);
		free(job.parts[i]);
	}
	free(job.parts);
	free(job.eta);
	mlod_pose_set_free(&job.train);
	mlod_pose_set_free(&job.measure);
	mlod_character_free(&job.c);
	mlod_gltf_free(doc);
	(void)errno;
	return 0;
}
