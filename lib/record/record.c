/*
 * record.c: the one reader and writer of extras.mlod (mlod_record.h; the
 * schema is mlod-record(5)).
 *
 * Numbers are written as the stages always wrote them (%.9g, ratios
 * %.6g, counts as integers), so that records read and written again stay
 * the same to the digit.
 */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "json.h"
#include "record/mlod_record.h"

#define KEY "mlod"

/* ------------------------------------------------------------------ */
/* Access                                                              */
/* ------------------------------------------------------------------ */

static const char *kind_name(mlod_gltf_kind kind)
{
	switch (kind) {
	case MLOD_GLTF_NODE: return "node";
	case MLOD_GLTF_SKIN: return "skin";
	case MLOD_GLTF_SCENE: return "scene";
	case MLOD_GLTF_MESH: return "mesh";
	case MLOD_GLTF_ANIMATION: return "animation";
	case MLOD_GLTF_ASSET: return "asset";
	}
	return "object";
}

static void where(char *buf, size_t size, mlod_gltf_kind kind, int index)
{
	if (kind == MLOD_GLTF_SCENE && index < 0)
		snprintf(buf, size, "the scene's extras.mlod");
	else
		snprintf(buf, size, "%s %d: extras.mlod", kind_name(kind), index);
}

/* Reads extras.mlod of an object into *out (MJ_NULL when absent). */
static mlod_result get(const mlod_gltf *doc, mlod_gltf_kind kind, int index, mj *out, mlod_error *err)
{
	char *text = NULL, why[128], at[64];
	memset(out, 0, sizeof *out);
	mlod_result r = mlod_gltf_get_extra(doc, kind, index, KEY, &text, err);
	if (r != MLOD_OK || !text)
		return r;
	int rc = mj_parse(text, strlen(text), out, why, sizeof why);
	mlod_free(text);
	if (rc != 0) {
		where(at, sizeof at, kind, index);
		return mlod_fail(err, MLOD_ERR_PARSE, "%s: %s", at, why);
	}
	return MLOD_OK;
}

static mlod_result set(mlod_gltf *doc, mlod_gltf_kind kind, int index, const mj *v, mlod_error *err)
{
	char *text = NULL;
	if (mj_write(v, &text) != 0)
		return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory writing extras.mlod");
	mlod_result r = mlod_gltf_set_extra(doc, kind, index, KEY, text, err);
	free(text);
	return r;
}

static mlod_result nomem(mlod_error *err)
{
	return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory writing extras.mlod");
}

/* Sets key of an object's record to *value (taken over), keeping the
 * other keys; with key NULL, every member of the object *value (or
 * nothing, value NULL). The scene's record gets the version. */
static mlod_result merge(mlod_gltf *doc, mlod_gltf_kind kind, int index, const char *key, mj *value,
                         mlod_error *err)
{
	mj rec, version;
	char at[64];
	mlod_result r = get(doc, kind, index, &rec, err);
	if (r != MLOD_OK) {
		mj_free(value);
		return r;
	}
	if (rec.type == MJ_NULL) {
		rec = mj_object();
	} else if (rec.type != MJ_OBJECT) {
		mj_free(&rec);
		mj_free(value);
		where(at, sizeof at, kind, index);
		return mlod_fail(err, MLOD_ERR_UNSUPPORTED, "%s is not a JSON object: mlod does not add to it", at);
	}
	int bad = 0;
	if (key) {
		bad = mj_put(&rec, key, value) != 0;
	} else if (value) { /* every member of value */
		for (int i = 0; !bad && i < value->count; i++) {
			bad = mj_put(&rec, value->keys[i], &value->items[i]) != 0;
		}
		mj_free(value);
	}
	if (!bad && kind == MLOD_GLTF_SCENE)
		bad = mj_int(&version, MLOD_RECORD_VERSION) != 0 || mj_put(&rec, "version", &version) != 0;
	r = bad ? nomem(err) : set(doc, kind, index, &rec, err);
	mj_free(&rec);
	return r;
}

/* Stamps the version on the default scene, when there is one. */
static mlod_result stamp(mlod_gltf *doc, mlod_error *err)
{
	if (mlod_gltf_count(doc, MLOD_GLTF_SCENE) == 0)
		return MLOD_OK;
	return merge(doc, MLOD_GLTF_SCENE, -1, NULL, NULL, err);
}

/* The scene record's version (1 when it has none or it is not a whole
 * number: mlod_record_read reports that), for the readers of other
 * objects: a key optional since version 3 is required in older records. */
static int doc_version(const mlod_gltf *doc)
{
	mj o;
	mlod_error ignored = {0};
	int version = 1;
	if (mlod_gltf_count(doc, MLOD_GLTF_SCENE) == 0 || get(doc, MLOD_GLTF_SCENE, -1, &o, &ignored) != MLOD_OK)
		return version;
	const mj *v = mj_get(&o, "version");
	if (v && v->type == MJ_NUMBER && v->number >= 1.0 && v->number <= 1e9 && v->number == (double)(long)v->number)
		version = (int)v->number;
	mj_free(&o);
	return version;
}

/* Is an animation's record (read with get) a motion level's? The one test
 * of what a "<clip>@lod<k>" animation is: mlod_record_read_motion,
 * mlod_record_motion_level_count and the clips mlod_record_load leaves
 * out all ask it. */
static int is_motion_level(const mj *o)
{
	return o->type == MJ_OBJECT && mj_get(o, "motion_level") != NULL;
}

/* Is a key that version 3 made optional required in a record of this
 * version? */
#define REQUIRED_BEFORE_3(version) ((version) < 3)

/* ------------------------------------------------------------------ */
/* Typed reading with messages                                         */
/* ------------------------------------------------------------------ */

struct rd {
	char at[160];      /* the object and key path so far */
	mlod_error *err;
	mlod_result r;
};

static int rd_fail(struct rd *c, const char *key, const char *what)
{
	if (c->r == MLOD_OK)
		c->r = mlod_fail(c->err, MLOD_ERR_PARSE, "%s%s%s: %s", c->at, key ? "." : "", key ? key : "", what);
	return -1;
}

/* A member that must be there (required) or may be absent (returns 0
 * then); -1 on a wrong type. */
static int rd_number(struct rd *c, const mj *o, const char *key, int required, double *out)
{
	const mj *v = mj_get(o, key);
	if (!v)
		return required ? rd_fail(c, key, "missing") : 0;
	if (v->type != MJ_NUMBER)
		return rd_fail(c, key, "not a number");
	*out = v->number;
	return 1;
}

/* Is d a whole number within [lo, hi] (both within the range of long)?
 * The range comes first: converting a double past the range of long is
 * undefined. */
static int whole_in(double d, double lo, double hi)
{
	return d >= lo && d <= hi && d == (double)(long)d;
}

static int rd_int(struct rd *c, const mj *o, const char *key, int required, double lo, double hi, long *out)
{
	double d = 0.0;
	int got = rd_number(c, o, key, required, &d);
	if (got <= 0)
		return got;
	if (!whole_in(d, lo, hi))
		return rd_fail(c, key, "not a whole number in range");
	*out = (long)d;
	return 1;
}

static int rd_deviation(struct rd *c, const mj *o, const char *key, int required, mlod_deviation *out)
{
	const mj *v = mj_get(o, key);
	memset(out, 0, sizeof *out);
	if (!v)
		return required ? rd_fail(c, key, "missing") : 0;
	if (v->type != MJ_OBJECT)
		return rd_fail(c, key, "not an object");
	size_t n = strlen(c->at);
	snprintf(c->at + n, sizeof c->at - n, ".%s", key);
	int ok = rd_number(c, v, "max", 1, &out->max) > 0 && rd_number(c, v, "mean", 1, &out->mean) > 0;
	c->at[n] = '\0';
	return ok ? 1 : -1;
}

/* An array of whole numbers within [lo, hi]; *items is malloc'd. */
static int rd_ints(struct rd *c, const mj *o, const char *key, double lo, double hi, int **items, int *count)
{
	const mj *v = mj_get(o, key);
	*items = NULL;
	*count = 0;
	if (!v)
		return rd_fail(c, key, "missing");
	if (v->type != MJ_ARRAY)
		return rd_fail(c, key, "not an array");
	*items = malloc(sizeof(int) * ((size_t)v->count + 1));
	if (!*items) {
		c->r = mlod_fail(c->err, MLOD_ERR_NOMEM, "out of memory reading extras.mlod");
		return -1;
	}
	for (int i = 0; i < v->count; i++) {
		const mj *x = &v->items[i];
		if (x->type != MJ_NUMBER || !whole_in(x->number, lo, hi))
			return rd_fail(c, key, "holds something other than an index in range");
		(*items)[i] = (int)x->number;
	}
	*count = v->count;
	return 1;
}

static void rd_at(struct rd *c, const char *fmt, ...)
#if defined(__GNUC__)
	__attribute__((format(printf, 2, 3)))
#endif
	;

static void rd_at(struct rd *c, const char *fmt, ...)
{
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(c->at, sizeof c->at, fmt, ap);
	va_end(ap);
}

/* ------------------------------------------------------------------ */
/* Typed writing                                                       */
/* ------------------------------------------------------------------ */

/* Builders that remember running out of memory. */
struct wr {
	int failed;
};

static void w_num(struct wr *w, mj *o, const char *key, const char *fmt, double v)
{
	mj x;
	if (!w->failed && (mj_double(&x, fmt, v) != 0 || mj_put(o, key, &x) != 0))
		w->failed = 1;
}

static void w_int(struct wr *w, mj *o, const char *key, long v)
{
	mj x;
	if (!w->failed && (mj_int(&x, v) != 0 || mj_put(o, key, &x) != 0))
		w->failed = 1;
}

static void w_str(struct wr *w, mj *o, const char *key, const char *s)
{
	mj x;
	if (!w->failed && (mj_string(&x, s) != 0 || mj_put(o, key, &x) != 0))
		w->failed = 1;
}

/* Ends a writer: out of memory when a step failed, else merges *value
 * (taken over) into the object's record as merge() does. */
static mlod_result finish(const struct wr *w, mlod_gltf *doc, mlod_gltf_kind kind, int index, const char *key,
                          mj *value, mlod_error *err)
{
	if (w->failed) {
		mj_free(value);
		return nomem(err);
	}
	return merge(doc, kind, index, key, value, err);
}

/* finish() on the scene's record under key; a document without a scene
 * has no scene record, and the value is dropped. */
static mlod_result finish_scene(const struct wr *w, mlod_gltf *doc, const char *key, mj *value, mlod_error *err)
{
	if (!w->failed && mlod_gltf_count(doc, MLOD_GLTF_SCENE) == 0) {
		mj_free(value);
		return MLOD_OK;
	}
	return finish(w, doc, MLOD_GLTF_SCENE, -1, key, value, err);
}

static void w_put(struct wr *w, mj *o, const char *key, mj *v)
{
	if (w->failed || mj_put(o, key, v) != 0) {
		mj_free(v);
		w->failed = 1;
	}
}

static void w_push(struct wr *w, mj *a, mj *v)
{
	if (w->failed || mj_push(a, v) != 0) {
		mj_free(v);
		w->failed = 1;
	}
}

static void w_deviation(struct wr *w, mj *o, const char *key, const mlod_deviation *d)
{
	mj x = mj_object();
	w_num(w, &x, "max", "%.9g", d->max);
	w_num(w, &x, "mean", "%.9g", d->mean);
	w_put(w, o, key, &x);
}

static mj w_ints(struct wr *w, const int *v, int n)
{
	mj a = mj_array();
	for (int i = 0; i < n; i++) {
		mj x;
		if (w->failed || mj_int(&x, v[i]) != 0)
			w->failed = 1;
		else
			w_push(w, &a, &x);
	}
	return a;
}

/* ------------------------------------------------------------------ */
/* Joint nodes                                                         */
/* ------------------------------------------------------------------ */

mlod_result mlod_record_write_joints(mlod_gltf *doc, const mlod_character *c, const mlod_joint_info *info,
                                     mlod_error *err)
{
	const mlod_skeleton *s = &c->skeleton;
	for (int j = 0; j < s->joint_count; j++) {
		if (s->joints[j].node < 0)
			continue;
		struct wr w = {0};
		mj o = mj_object();
		w_str(&w, &o, "label", mlod_label_name(info[j].label));
		w_int(&w, &o, "depth", info[j].depth);
		w_int(&w, &o, "children", info[j].children);
		w_int(&w, &o, "neighbors", info[j].neighbors);
		w_num(&w, &o, "weight", "%.9g", info[j].weight);
		w_num(&w, &o, "energy", "%.9g", info[j].energy);
		mlod_result r = finish(&w, doc, MLOD_GLTF_NODE, s->joints[j].node, NULL, &o, err);
		if (r != MLOD_OK)
			return r;
	}
	return stamp(doc, err);
}

mlod_result mlod_record_read_joints(const mlod_gltf *doc, const mlod_character *c, mlod_joint_info *info,
                                    int *found, mlod_error *err)
{
	const mlod_skeleton *s = &c->skeleton;
	mlod_joint_info *read = calloc((size_t)s->joint_count + 1, sizeof *read);
	mlod_result r = MLOD_OK;
	*found = 0;
	if (!read)
		return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory reading extras.mlod");
	int all = s->joint_count > 0;
	for (int j = 0; all && r == MLOD_OK && j < s->joint_count; j++) {
		mj o;
		int node = s->joints[j].node;
		if (node < 0) {
			all = 0;
			break;
		}
		if ((r = get(doc, MLOD_GLTF_NODE, node, &o, err)) != MLOD_OK)
			break;
		const mj *label = mj_get(&o, "label");
		if (o.type != MJ_OBJECT || !label) {
			all = 0; /* no label record on this joint */
			mj_free(&o);
			break;
		}
		struct rd rc = {{0}, err, MLOD_OK};
		rd_at(&rc, "node %d: extras.mlod", node);
		long depth = 0, children = 0, neighbors = 0;
		double weight = 0.0;
		if (label->type != MJ_STRING || mlod_label_parse(label->text, &read[j].label) != 0)
			rd_fail(&rc, "label", "not a joint label");
		else if (rd_number(&rc, &o, "energy", 1, &read[j].energy) > 0 && !(read[j].energy >= 0.0))
			rd_fail(&rc, "energy", "negative");
		if (rc.r == MLOD_OK && rd_int(&rc, &o, "depth", 1, 0, 1e9, &depth) > 0 &&
		    rd_int(&rc, &o, "children", 0, 0, 1e9, &children) >= 0 &&
		    rd_int(&rc, &o, "neighbors", 0, 0, 1e9, &neighbors) >= 0)
			rd_number(&rc, &o, "weight", 0, &weight);
		read[j].depth = (int)depth;
		read[j].children = (int)children;
		read[j].neighbors = (int)neighbors;
		read[j].weight = weight;
		r = rc.r;
		mj_free(&o);
	}
	if (r == MLOD_OK && all) {
		/* Labels and energies are the record's; the tree figures are the
		 * skeleton's own. */
		for (int j = 0; j < s->joint_count; j++) {
			info[j].label = read[j].label;
			info[j].energy = read[j].energy;
		}
		*found = 1;
	}
	free(read);
	return r;
}

/* ------------------------------------------------------------------ */
/* The scene                                                           */
/* ------------------------------------------------------------------ */

void mlod_record_skel_level_free(mlod_record_skel_level *l)
{
	free(l->kept);
	free(l->remap_from);
	free(l->remap_to);
	free(l->skins);
	memset(l, 0, sizeof *l);
}

void mlod_record_free(mlod_record *r)
{
	for (int k = 0; k < r->skel_level_count; k++)
		mlod_record_skel_level_free(&r->skel_levels[k]);
	free(r->skel_levels);
	for (int i = 0; i < r->skin_count; i++)
		free(r->skins[i].levels);
	free(r->skins);
	free(r->mesh_levels);
	free(r->pack_name);
	memset(r, 0, sizeof *r);
}

static int read_skel_level(struct rd *c, const mj *o, int nodes, int skins, int version, mlod_record_skel_level *l)
{
	long level = 0, joints = 0;
	const mj *remap;
	int req = REQUIRED_BEFORE_3(version), got_threshold = 0, got_joint_error = 0;
	if (o->type != MJ_OBJECT)
		return rd_fail(c, NULL, "not an object");
	if (rd_int(c, o, "level", 1, 1, 1e6, &level) < 0 || (got_threshold = rd_number(c, o, "threshold", req, &l->threshold)) < 0 ||
	    rd_int(c, o, "joints", 1, 0, 1e9, &joints) < 0 || rd_ints(c, o, "kept", -1, nodes - 1, &l->kept, &l->kept_count) < 0 ||
	    rd_ints(c, o, "skins", -1, skins - 1, &l->skins, &l->skin_count) < 0 ||
	    (got_joint_error = rd_deviation(c, o, "joint_error", req, &l->joint_error)) < 0 ||
	    (l->has_vertex_error = rd_deviation(c, o, "vertex_error_percent", 0, &l->vertex_error)) < 0 ||
	    (l->has_pack_error = rd_number(c, o, "pack_error", 0, &l->pack_error)) < 0)
		return -1;
	l->missing_threshold = !got_threshold;
	l->missing_joint_error = !got_joint_error;
	l->level = (int)level;
	l->joints = (int)joints;
	if (!(remap = mj_get(o, "remap")))
		return rd_fail(c, "remap", "missing");
	if (remap->type != MJ_OBJECT)
		return rd_fail(c, "remap", "not an object");
	l->remap_from = malloc(sizeof(int) * ((size_t)remap->count + 1));
	l->remap_to = malloc(sizeof(int) * ((size_t)remap->count + 1));
	if (!l->remap_from || !l->remap_to) {
		c->r = mlod_fail(c->err, MLOD_ERR_NOMEM, "out of memory reading extras.mlod");
		return -1;
	}
	for (int i = 0; i < remap->count; i++) {
		char *end;
		long from = strtol(remap->keys[i], &end, 10);
		const mj *to = &remap->items[i];
		if (end == remap->keys[i] || *end || from < 0 || from >= nodes || to->type != MJ_NUMBER ||
		    !whole_in(to->number, -1, nodes - 1))
			return rd_fail(c, "remap", "holds something other than node -> node");
		l->remap_from[i] = (int)from;
		l->remap_to[i] = (int)to->number;
	}
	l->remap_count = remap->count;
	return 0;
}

static int read_mesh_level(struct rd *c, const mj *o, int version, mlod_record_mesh_level *l)
{
	long level = 0, triangles = 0, vertices = 0;
	int req = REQUIRED_BEFORE_3(version), got_ratio = 0, got_error = 0;
	if (o->type != MJ_OBJECT)
		return rd_fail(c, NULL, "not an object");
	if (rd_int(c, o, "level", 1, 1, 1e6, &level) < 0 || (got_ratio = rd_number(c, o, "ratio", req, &l->ratio)) < 0 ||
	    rd_int(c, o, "triangles", 1, 0, 2e9, &triangles) < 0 || rd_int(c, o, "vertices", 1, 0, 2e9, &vertices) < 0 ||
	    (got_error = rd_deviation(c, o, "error_percent", req, &l->error)) < 0 ||
	    (l->has_pack_error = rd_number(c, o, "pack_error", 0, &l->pack_error)) < 0)
		return -1;
	l->missing_ratio = !got_ratio;
	l->missing_error = !got_error;
	l->level = (int)level;
	l->triangles = (int)triangles;
	l->vertices = (int)vertices;
	return 0;
}

/* The scene record's version (refused when newer than this mlod's) and
 * source (version 4): MLOD_FORMAT_BVH for "bvh", else
 * MLOD_FORMAT_UNKNOWN. */
static void read_scene_head(struct rd *c, const mj *o, int *version, mlod_format *source)
{
	long v = 1;
	*version = 1;
	*source = MLOD_FORMAT_UNKNOWN;
	rd_at(c, "the scene's extras.mlod");
	if (o->type != MJ_NULL && o->type != MJ_OBJECT)
		rd_fail(c, NULL, "not an object");
	if (c->r != MLOD_OK || o->type != MJ_OBJECT)
		return;
	if (rd_int(c, o, "version", 0, 1, 1e9, &v) > 0 && v > MLOD_RECORD_VERSION)
		c->r = mlod_fail(c->err, MLOD_ERR_UNSUPPORTED,
		                 "the scene's extras.mlod is version %ld: this mlod reads up to version %d", v,
		                 MLOD_RECORD_VERSION);
	*version = (int)v;
	const mj *src = mj_get(o, "source");
	if (c->r == MLOD_OK && src) {
		if (src->type != MJ_STRING || strcmp(src->text, "bvh") != 0)
			rd_fail(c, "source", "not \"bvh\"");
		else
			*source = MLOD_FORMAT_BVH;
	}
}

mlod_result mlod_record_read(const mlod_gltf *doc, mlod_record *out, mlod_error *err)
{
	memset(out, 0, sizeof *out);
	out->version = 1;
	int nodes = mlod_gltf_count(doc, MLOD_GLTF_NODE), skins = mlod_gltf_count(doc, MLOD_GLTF_SKIN);
	mj o = {0};
	struct rd c = {{0}, err, MLOD_OK};
	mlod_result r = MLOD_OK;
	if (mlod_gltf_count(doc, MLOD_GLTF_SCENE) > 0 && (r = get(doc, MLOD_GLTF_SCENE, -1, &o, err)) != MLOD_OK)
		return r;
	read_scene_head(&c, &o, &out->version, &out->source);
	const mj *a = mj_get(&o, "skeleton_levels");
	out->has_skel_levels = a != NULL;
	if (c.r == MLOD_OK && a) {
		if (a->type != MJ_ARRAY)
			rd_fail(&c, "skeleton_levels", "not an array");
		else if (!(out->skel_levels = calloc((size_t)a->count + 1, sizeof *out->skel_levels)))
			c.r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory reading extras.mlod");
		for (int k = 0; c.r == MLOD_OK && k < a->count; k++) {
			rd_at(&c, "the scene's extras.mlod.skeleton_levels[%d]", k);
			out->skel_level_count = k + 1;
			read_skel_level(&c, &a->items[k], nodes, skins, out->version, &out->skel_levels[k]);
		}
	}
	rd_at(&c, "the scene's extras.mlod");
	a = mj_get(&o, "mesh_levels");
	out->has_mesh_levels = a != NULL;
	if (c.r == MLOD_OK && a) {
		if (a->type != MJ_ARRAY)
			rd_fail(&c, "mesh_levels", "not an array");
		else if (!(out->mesh_levels = calloc((size_t)a->count + 1, sizeof *out->mesh_levels)))
			c.r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory reading extras.mlod");
		for (int k = 0; c.r == MLOD_OK && k < a->count; k++) {
			rd_at(&c, "the scene's extras.mlod.mesh_levels[%d]", k);
			out->mesh_level_count = k + 1;
			read_mesh_level(&c, &a->items[k], out->version, &out->mesh_levels[k]);
		}
		if (c.r == MLOD_OK) {
			double *errors = malloc(sizeof(double) * ((size_t)out->mesh_level_count + 1));
			float *coverage = malloc(sizeof(float) * ((size_t)out->mesh_level_count + 2));
			if (!errors || !coverage)
				c.r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory reading extras.mlod");
			for (int k = 0; c.r == MLOD_OK && k < out->mesh_level_count; k++)
				errors[k] = out->mesh_levels[k].error.max;
			if (c.r == MLOD_OK) {
				mlod_lod_coverage(errors, out->mesh_level_count, coverage);
				for (int k = 0; k < out->mesh_level_count; k++)
					out->mesh_levels[k].coverage = coverage[k];
			}
			free(errors);
			free(coverage);
		}
	}
	rd_at(&c, "the scene's extras.mlod.pack");
	a = mj_get(&o, "pack");
	if (c.r == MLOD_OK && a) {
		const mj *name = mj_get(a, "name"), *b = mj_get(a, "bounds");
		const mj *lo = mj_get(b, "min"), *hi = mj_get(b, "max");
		if (a->type != MJ_OBJECT)
			rd_fail(&c, NULL, "not an object");
		else if (!name || name->type != MJ_STRING)
			rd_fail(&c, "name", "not a string");
		else if (!b || b->type != MJ_OBJECT || !lo || !hi || lo->type != MJ_ARRAY || hi->type != MJ_ARRAY ||
		         lo->count != 3 || hi->count != 3)
			rd_fail(&c, "bounds", "not an object of min and max, 3 numbers each");
		for (int i = 0; c.r == MLOD_OK && i < 3; i++) {
			if (lo->items[i].type != MJ_NUMBER || hi->items[i].type != MJ_NUMBER ||
			    !(lo->items[i].number <= hi->items[i].number))
				rd_fail(&c, "bounds", "not an object of min and max, 3 numbers each");
			out->pack_bounds_min[i] = lo->items[i].number;
			out->pack_bounds_max[i] = hi->items[i].number;
		}
		if (c.r == MLOD_OK) {
			size_t n = strlen(name->text);
			if (!(out->pack_name = malloc(n + 1)))
				c.r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory reading extras.mlod");
			else
				memcpy(out->pack_name, name->text, n + 1);
			out->has_pack = c.r == MLOD_OK;
		}
	}
	rd_at(&c, "the scene's extras.mlod");
	a = mj_get(&o, "mesh_level");
	if (c.r == MLOD_OK && a) {
		rd_at(&c, "the scene's extras.mlod.mesh_level");
		if (read_mesh_level(&c, a, out->version, &out->mesh_level) == 0) {
			out->has_mesh_level = 1;
			out->mesh_level.coverage = mlod_error_coverage(out->mesh_level.error.max, MLOD_COVERAGE_LINES,
			                                               MLOD_COVERAGE_PIXELS);
		}
	}
	mj_free(&o);

	/* Skins: the skins standing for each. */
	for (int s = 0; c.r == MLOD_OK && s < skins; s++) {
		if ((c.r = get(doc, MLOD_GLTF_SKIN, s, &o, err)) != MLOD_OK)
			break;
		a = mj_get(&o, "skeleton_levels");
		if (a) {
			mlod_record_skin *grown = realloc(out->skins, sizeof *grown * (size_t)(out->skin_count + 1));
			if (!grown) {
				c.r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory reading extras.mlod");
			} else {
				out->skins = grown;
				mlod_record_skin *sk = &out->skins[out->skin_count++];
				sk->skin = s;
				rd_at(&c, "skin %d: extras.mlod", s);
				rd_ints(&c, &o, "skeleton_levels", 0, skins - 1, &sk->levels, &sk->level_count);
			}
		}
		mj_free(&o);
	}
	if (c.r != MLOD_OK)
		mlod_record_free(out);
	return c.r;
}

mlod_result mlod_record_skel_levels_make(const mlod_character *full, const mlod_skel_level_record *levels, int count,
                                         const int *skins, mlod_record_skel_level *out, mlod_error *err)
{
	const mlod_skeleton *s = &full->skeleton;
	int n = s->joint_count, sc = s->skin_count;
	memset(out, 0, sizeof *out * (size_t)count);
	for (int k = 0; k < count; k++) {
		const mlod_skel_level *l = levels[k].level;
		mlod_record_skel_level *o = &out[k];
		o->level = k + 1;
		o->threshold = l->threshold;
		o->joints = l->kept_count;
		o->kept = malloc(sizeof(int) * ((size_t)n + 1));
		o->remap_from = malloc(sizeof(int) * ((size_t)n + 1));
		o->remap_to = malloc(sizeof(int) * ((size_t)n + 1));
		o->skins = malloc(sizeof(int) * ((size_t)sc + 1));
		if (!o->kept || !o->remap_from || !o->remap_to || !o->skins) {
			for (int i = 0; i <= k; i++)
				mlod_record_skel_level_free(&out[i]);
			return nomem(err);
		}
		for (int j = 0; j < n; j++) {
			if (l->kept[j])
				o->kept[o->kept_count++] = s->joints[j].node;
			else if (s->joints[j].node >= 0) {
				o->remap_from[o->remap_count] = s->joints[j].node;
				o->remap_to[o->remap_count++] = s->joints[l->remap[j]].node;
			}
		}
		o->skin_count = sc;
		memcpy(o->skins, skins + (size_t)k * (size_t)sc, sizeof(int) * (size_t)sc);
		o->joint_error = levels[k].joint;
		o->has_vertex_error = levels[k].vertex.scale > 0.0;
		o->vertex_error = levels[k].vertex;
		/* threshold and joint_error given: missing_* 0 (memset) */
	}
	return MLOD_OK;
}

mlod_result mlod_record_write_skeleton(mlod_gltf *doc, const mlod_record_skel_level *levels, int count,
                                       const int *full_skins, int skin_count, mlod_error *err)
{
	struct wr w = {0};
	mj list = mj_array();
	for (int k = 0; k < count; k++) {
		const mlod_record_skel_level *l = &levels[k];
		mj o = mj_object(), remap = mj_object(), a;
		w_int(&w, &o, "level", l->level);
		if (!l->missing_threshold)
			w_num(&w, &o, "threshold", "%.9g", l->threshold);
		w_int(&w, &o, "joints", l->joints);
		a = w_ints(&w, l->kept, l->kept_count);
		w_put(&w, &o, "kept", &a);
		for (int i = 0; i < l->remap_count; i++) {
			char key[16];
			snprintf(key, sizeof key, "%d", l->remap_from[i]);
			w_int(&w, &remap, key, l->remap_to[i]);
		}
		w_put(&w, &o, "remap", &remap);
		a = w_ints(&w, l->skins, l->skin_count);
		w_put(&w, &o, "skins", &a);
		if (!l->missing_joint_error)
			w_deviation(&w, &o, "joint_error", &l->joint_error);
		if (l->has_vertex_error)
			w_deviation(&w, &o, "vertex_error_percent", &l->vertex_error);
		if (l->has_pack_error)
			w_num(&w, &o, "pack_error", "%.9g", l->pack_error);
		w_push(&w, &list, &o);
	}
	mlod_result r = finish_scene(&w, doc, "skeleton_levels", &list, err);
	for (int s = 0; r == MLOD_OK && s < skin_count; s++) {
		if (full_skins[s] < 0)
			continue;
		mj a = mj_array();
		for (int k = 0; k < count; k++) {
			mj x;
			if (w.failed || mj_int(&x, levels[k].skins[s]) != 0)
				w.failed = 1;
			else
				w_push(&w, &a, &x);
		}
		r = finish(&w, doc, MLOD_GLTF_SKIN, full_skins[s], "skeleton_levels", &a, err);
	}
	return r;
}

static mj mesh_level_json(struct wr *w, const mlod_record_mesh_level *l)
{
	mj o = mj_object();
	w_int(w, &o, "level", l->level);
	if (!l->missing_ratio)
		w_num(w, &o, "ratio", "%.6g", l->ratio);
	w_int(w, &o, "triangles", l->triangles);
	w_int(w, &o, "vertices", l->vertices);
	if (!l->missing_error)
		w_deviation(w, &o, "error_percent", &l->error);
	if (l->has_pack_error)
		w_num(w, &o, "pack_error", "%.9g", l->pack_error);
	return o;
}

mlod_result mlod_record_write_mesh_levels(mlod_gltf *doc, const mlod_record_mesh_level *levels, int count,
                                          mlod_error *err)
{
	struct wr w = {0};
	mj list = mj_array();
	for (int k = 0; k < count; k++) {
		mj o = mesh_level_json(&w, &levels[k]);
		w_push(&w, &list, &o);
	}
	return finish_scene(&w, doc, "mesh_levels", &list, err);
}

mlod_result mlod_record_write_pack(mlod_gltf *doc, const char *name, const float bounds_min[3],
                                   const float bounds_max[3], mlod_error *err)
{
	struct wr w = {0};
	mj o = mj_object(), b = mj_object(), lo = mj_array(), hi = mj_array();
	w_str(&w, &o, "name", name ? name : "");
	for (int i = 0; i < 3; i++) {
		mj x, y;
		if (w.failed || mj_double(&x, "%.9g", bounds_min[i]) != 0)
			w.failed = 1;
		else
			w_push(&w, &lo, &x);
		if (w.failed || mj_double(&y, "%.9g", bounds_max[i]) != 0)
			w.failed = 1;
		else
			w_push(&w, &hi, &y);
	}
	w_put(&w, &b, "min", &lo);
	w_put(&w, &b, "max", &hi);
	w_put(&w, &o, "bounds", &b);
	return finish_scene(&w, doc, "pack", &o, err);
}

mlod_result mlod_record_write_mesh_split(mlod_gltf *doc, const mlod_record_mesh_level *level, mlod_error *err)
{
	struct wr w = {0};
	mj o = mesh_level_json(&w, level);
	return finish_scene(&w, doc, "mesh_level", &o, err);
}

void mlod_record_mesh_skeleton(const mlod_record_skel_level *l, mlod_mesh_skeleton *out)
{
	out->skin_count = l->skin_count;
	out->skins = l->skins;
	out->remap_count = l->remap_count;
	out->remap_from = l->remap_from;
	out->remap_to = l->remap_to;
}

/* ------------------------------------------------------------------ */
/* Level nodes                                                         */
/* ------------------------------------------------------------------ */

mlod_result mlod_record_write_mesh_node(mlod_gltf *doc, int node, const mlod_record_mesh_node *n, mlod_error *err)
{
	struct wr w = {0};
	mj o = mj_object();
	w_int(&w, &o, "mesh_level", n->level);
	if (!n->missing_ratio)
		w_num(&w, &o, "ratio", "%.6g", n->ratio);
	if (!n->missing_error)
		w_deviation(&w, &o, "error_percent", &n->error);
	if (n->skeleton_level) {
		mj t = mj_bool(1);
		w_put(&w, &o, "skeleton_level", &t);
	}
	if (n->has_pack_error)
		w_num(&w, &o, "pack_error", "%.9g", n->pack_error);
	return finish(&w, doc, MLOD_GLTF_NODE, node, NULL, &o, err);
}

mlod_result mlod_record_write_mesh_nodes(mlod_gltf *doc, const mlod_mesh_levels *levels, const mlod_mesh_lod *lod,
                                         mlod_error *err)
{
	for (int i = 0; i < lod->count; i++) {
		const mlod_mesh_level *lv = &levels->levels[lod->level[i]];
		mlod_record_mesh_node n;
		memset(&n, 0, sizeof n);
		n.level = lod->level[i] + 1;
		n.ratio = lv->ratio;
		n.error = lv->error;
		n.skeleton_level = lod->skeleton_level[i];
		mlod_result r = mlod_record_write_mesh_node(doc, lod->node[i], &n, err);
		if (r != MLOD_OK)
			return r;
	}
	return MLOD_OK;
}

mlod_result mlod_record_read_mesh_node(const mlod_gltf *doc, int node, mlod_record_mesh_node *out, int *found,
                                       mlod_error *err)
{
	mj o;
	long level = 0;
	struct rd c = {{0}, err, MLOD_OK};
	memset(out, 0, sizeof *out);
	*found = 0;
	mlod_result r = get(doc, MLOD_GLTF_NODE, node, &o, err);
	if (r != MLOD_OK)
		return r;
	if (mj_get(&o, "mesh_level")) {
		rd_at(&c, "node %d: extras.mlod", node);
		const mj *t = mj_get(&o, "skeleton_level");
		int req = REQUIRED_BEFORE_3(doc_version(doc)), got_ratio = 0, got_error = 0;
		if (rd_int(&c, &o, "mesh_level", 1, 1, 1e6, &level) > 0 &&
		    (got_ratio = rd_number(&c, &o, "ratio", req, &out->ratio)) >= 0 &&
		    (got_error = rd_deviation(&c, &o, "error_percent", req, &out->error)) >= 0 &&
		    (out->has_pack_error = rd_number(&c, &o, "pack_error", 0, &out->pack_error)) >= 0 && t &&
		    t->type != MJ_TRUE && t->type != MJ_FALSE)
			rd_fail(&c, "skeleton_level", "not true or false");
		out->missing_ratio = got_ratio <= 0;
		out->missing_error = got_error <= 0;
		out->level = (int)level;
		out->skeleton_level = t && t->type == MJ_TRUE;
		*found = c.r == MLOD_OK;
	}
	mj_free(&o);
	return c.r;
}

/* ------------------------------------------------------------------ */
/* Motion levels                                                       */
/* ------------------------------------------------------------------ */

#define MORPH_ERROR_MEASURE                                                                                        \
	"sum over targets of |weight error| times the target's largest vertex offset in the rest pose, scene units"

const char *mlod_record_method_name(mlod_motion_method m)
{
	return m == MLOD_MOTION_KEYS ? "keys" : "frames";
}

mlod_result mlod_record_write_motion(mlod_gltf *doc, int animation, const mlod_record_motion_level *l,
                                     mlod_error *err)
{
	struct wr w = {0};
	mj o = mj_object(), je = mj_object();
	w_int(&w, &o, "motion_level", l->level);
	w_int(&w, &o, "source_animation", l->source_animation);
	if (!l->missing_method) {
		w_str(&w, &o, "method", mlod_record_method_name(l->method));
		w_num(&w, &o, "threshold", "%.9g", l->threshold);
	}
	if (l->has_bound)
		w_num(&w, &o, "bound", "%.9g", l->bound);
	if (!l->missing_keys) {
		w_int(&w, &o, "keys", l->keys);
		w_int(&w, &o, "source_keys", l->source_keys);
		w_int(&w, &o, "bytes", l->bytes);
	}
	w_num(&w, &je, "max", "%.9g", l->joint_error.max);
	w_num(&w, &je, "mean", "%.9g", l->joint_error.mean);
	w_num(&w, &je, "max_percent_height", "%.9g", l->joint_error_max_percent_height);
	if (!l->missing_joint_error)
		w_put(&w, &o, "joint_error", &je);
	else
		mj_free(&je);
	if (!l->missing_point_error) {
		w_num(&w, &o, "point_error", "%.9g", l->point_error);
		w_num(&w, &o, "grid", "%.9g", l->grid);
		w_int(&w, &o, "subdivide", l->subdivide);
	}
	if (l->has_vertex_error)
		w_num(&w, &o, "vertex_error_percent_diagonal", "%.9g", l->vertex_error_percent_diagonal);
	if (l->has_morph_weights) {
		const mlod_record_morph_weights *m = &l->morph_weights;
		mj x = mj_object();
		w_int(&w, &x, "channels", m->channels);
		w_int(&w, &x, "keys", m->keys);
		w_int(&w, &x, "source_keys", m->source_keys);
		w_int(&w, &x, "bytes", m->bytes);
		w_num(&w, &x, "bound", "%.9g", m->bound);
		w_num(&w, &x, "error", "%.9g", m->error);
		w_int(&w, &x, "copied", m->copied);
		w_str(&w, &x, "error_measure", MORPH_ERROR_MEASURE);
		w_put(&w, &o, "morph_weights", &x);
	}
	if (l->has_pack_error)
		w_num(&w, &o, "pack_error", "%.9g", l->pack_error);
	mlod_result r = finish(&w, doc, MLOD_GLTF_ANIMATION, animation, NULL, &o, err);
	return r == MLOD_OK ? stamp(doc, err) : r;
}

mlod_result mlod_record_read_motion(const mlod_gltf *doc, int animation, mlod_record_motion_level *out, int *found,
                                    mlod_error *err)
{
	mj o;
	struct rd c = {{0}, err, MLOD_OK};
	memset(out, 0, sizeof *out);
	*found = 0;
	mlod_result r = get(doc, MLOD_GLTF_ANIMATION, animation, &o, err);
	if (r != MLOD_OK)
		return r;
	if (!is_motion_level(&o)) {
		mj_free(&o);
		return MLOD_OK;
	}
	rd_at(&c, "animation %d: extras.mlod", animation);
	long level = 0, source = 0, subdivide = 0;
	const mj *method = mj_get(&o, "method"), *je = mj_get(&o, "joint_error"), *mw = mj_get(&o, "morph_weights");
	int anims = mlod_gltf_count(doc, MLOD_GLTF_ANIMATION);
	/* Version 3: method with threshold, keys with source_keys and bytes,
	 * joint_error and point_error may each be missing (as a group). */
	int req = REQUIRED_BEFORE_3(doc_version(doc)), got_threshold = 0, got_keys = 0, got_je = 0, got_pe = 0;
	if (rd_int(&c, &o, "motion_level", 1, 1, 1e6, &level) > 0 &&
	    rd_int(&c, &o, "source_animation", 1, 0, anims - 1, &source) > 0 &&
	    (got_threshold = rd_number(&c, &o, "threshold", req || method, &out->threshold)) >= 0 &&
	    (out->has_bound = rd_number(&c, &o, "bound", 0, &out->bound)) >= 0 &&
	    (got_keys = rd_int(&c, &o, "keys", req, 0, 9e15, &out->keys)) >= 0 &&
	    rd_int(&c, &o, "source_keys", req || got_keys, 0, 9e15, &out->source_keys) >= 0 &&
	    rd_int(&c, &o, "bytes", req || got_keys, 0, 9e15, &out->bytes) >= 0 &&
	    (got_je = rd_deviation(&c, &o, "joint_error", req, &out->joint_error)) >= 0 &&
	    (!je || rd_number(&c, je, "max_percent_height", 0, &out->joint_error_max_percent_height) >= 0) &&
	    (got_pe = rd_number(&c, &o, "point_error", req, &out->point_error)) >= 0 &&
	    rd_number(&c, &o, "grid", 0, &out->grid) >= 0 && rd_int(&c, &o, "subdivide", 0, 1, 1e6, &subdivide) >= 0 &&
	    (out->has_vertex_error = rd_number(&c, &o, "vertex_error_percent_diagonal", 0,
	                                       &out->vertex_error_percent_diagonal)) >= 0 &&
	    (out->has_pack_error = rd_number(&c, &o, "pack_error", 0, &out->pack_error)) >= 0) {
		if (!method && !req)
			out->missing_method = 1;
		else if (!method || method->type != MJ_STRING ||
		         (strcmp(method->text, "frames") != 0 && strcmp(method->text, "keys") != 0))
			rd_fail(&c, "method", "not frames or keys");
		else
			out->method = strcmp(method->text, "keys") == 0 ? MLOD_MOTION_KEYS : MLOD_MOTION_FRAMES;
		out->missing_keys = !got_keys;
		out->missing_joint_error = !got_je;
		out->missing_point_error = !got_pe;
		(void)got_threshold;
	}
	if (c.r == MLOD_OK && mw) {
		mlod_record_morph_weights *m = &out->morph_weights;
		long channels = 0, copied = 0;
		rd_at(&c, "animation %d: extras.mlod.morph_weights", animation);
		if (mw->type != MJ_OBJECT)
			rd_fail(&c, NULL, "not an object");
		else if (rd_int(&c, mw, "channels", 1, 0, 1e9, &channels) > 0 && rd_int(&c, mw, "keys", 1, 0, 9e15, &m->keys) > 0 &&
		         rd_int(&c, mw, "source_keys", 1, 0, 9e15, &m->source_keys) > 0 &&
		         rd_int(&c, mw, "bytes", 1, 0, 9e15, &m->bytes) > 0 && rd_number(&c, mw, "bound", 1, &m->bound) > 0 &&
		         rd_number(&c, mw, "error", 1, &m->error) > 0 && rd_int(&c, mw, "copied", 0, 0, 1e9, &copied) >= 0) {
			m->channels = (int)channels;
			m->copied = (int)copied;
			out->has_morph_weights = 1;
		}
	}
	out->level = (int)level;
	out->source_animation = (int)source;
	out->subdivide = (int)subdivide;
	*found = c.r == MLOD_OK;
	mj_free(&o);
	return c.r;
}

mlod_result mlod_record_motion_level_count(const mlod_gltf *doc, int *count, mlod_error *err)
{
	*count = 0;
	for (int a = 0; a < mlod_gltf_count(doc, MLOD_GLTF_ANIMATION); a++) {
		mj o;
		mlod_result r = get(doc, MLOD_GLTF_ANIMATION, a, &o, err);
		if (r != MLOD_OK)
			return r;
		*count += is_motion_level(&o);
		mj_free(&o);
	}
	return MLOD_OK;
}

mlod_result mlod_record_write_motion0(mlod_gltf *doc, int animation, double pack_error, mlod_error *err)
{
	struct wr w = {0};
	mj o = mj_object(), x = mj_object();
	w_num(&w, &x, "pack_error", "%.9g", pack_error);
	w_put(&w, &o, "motion_level0", &x);
	mlod_result r = finish(&w, doc, MLOD_GLTF_ANIMATION, animation, NULL, &o, err);
	return r == MLOD_OK ? stamp(doc, err) : r;
}

mlod_result mlod_record_read_motion0(const mlod_gltf *doc, int animation, double *pack_error, int *found,
                                     mlod_error *err)
{
	mj o;
	struct rd c = {{0}, err, MLOD_OK};
	*found = 0;
	*pack_error = 0.0;
	mlod_result r = get(doc, MLOD_GLTF_ANIMATION, animation, &o, err);
	if (r != MLOD_OK)
		return r;
	const mj *z = mj_get(&o, "motion_level0");
	if (z) {
		rd_at(&c, "animation %d: extras.mlod.motion_level0", animation);
		if (z->type != MJ_OBJECT)
			rd_fail(&c, NULL, "not an object");
		else if (rd_number(&c, z, "pack_error", 1, pack_error) > 0 && !(*pack_error >= 0.0))
			rd_fail(&c, "pack_error", "negative");
		*found = c.r == MLOD_OK;
	}
	mj_free(&o);
	return c.r;
}

/* ------------------------------------------------------------------ */
/* The input: its source and its clips                                 */
/* ------------------------------------------------------------------ */

mlod_result mlod_record_write_source(mlod_gltf *doc, mlod_format source, mlod_error *err)
{
	if (source != MLOD_FORMAT_BVH)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_record_write_source: only a BVH source is recorded");
	struct wr w = {0};
	mj v;
	if (mj_string(&v, "bvh") != 0)
		return nomem(err);
	return finish_scene(&w, doc, "source", &v, err);
}

int mlod_record_from_bvh(const mlod_record *r, mlod_format format)
{
	return format == MLOD_FORMAT_BVH || (r && r->source == MLOD_FORMAT_BVH);
}

/* Releases a clip left out (what mlod_character_free would; lib/motion's
 * mlod_clip_free calls into this part, so not that). */
static void clip_release(mlod_clip *clip)
{
	for (int ch = 0; clip->channels && ch < clip->channel_count; ch++) {
		free(clip->channels[ch].times);
		free(clip->channels[ch].values);
	}
	free(clip->channels);
	free(clip->name);
	memset(clip, 0, sizeof *clip);
}

/* Leaves the motion level animations out of c's clips, in order. */
static mlod_result input_clips(const mlod_gltf *doc, mlod_character *c, int *removed, mlod_error *err)
{
	int kept = 0;
	*removed = 0;
	for (int i = 0; i < c->clip_count; i++) {
		mj o = {0};
		int level = 0;
		if (c->clips[i].gltf_index >= 0) {
			mlod_result r = get(doc, MLOD_GLTF_ANIMATION, c->clips[i].gltf_index, &o, err);
			if (r != MLOD_OK)
				return r;
			level = is_motion_level(&o);
			mj_free(&o);
		}
		if (level) {
			clip_release(&c->clips[i]);
			(*removed)++;
		} else {
			c->clips[kept++] = c->clips[i];
		}
	}
	c->clip_count = kept;
	return MLOD_OK;
}

mlod_result mlod_record_load(const void *data, size_t size, const char *base_dir, int flags, mlod_gltf **doc,
                             mlod_character *c, mlod_record_input *in, mlod_error *err)
{
	mlod_record_input local;
	in = in ? in : &local;
	memset(in, 0, sizeof *in);
	if (doc)
		*doc = NULL;
	/* A glTF input's document is read whatever the caller wants (mlod_load
	 * reads it anyway): its record says what the character is. */
	int want = doc != NULL || mlod_detect_format(data, size) != MLOD_FORMAT_BVH;
	mlod_gltf *d = NULL;
	mlod_result r = mlod_load(data, size, base_dir, want ? &d : NULL, c, &in->format, err);
	if (r != MLOD_OK)
		return r;
	in->from_bvh = in->format == MLOD_FORMAT_BVH;
	if (d && in->format == MLOD_FORMAT_BVH) {
		r = mlod_record_write_source(d, MLOD_FORMAT_BVH, err);
	} else if (d) {
		mj o = {0};
		struct rd rc = {{0}, err, MLOD_OK};
		int version;
		mlod_format source = MLOD_FORMAT_UNKNOWN;
		if (mlod_gltf_count(d, MLOD_GLTF_SCENE) > 0 && (r = get(d, MLOD_GLTF_SCENE, -1, &o, err)) == MLOD_OK) {
			read_scene_head(&rc, &o, &version, &source);
			r = rc.r;
		}
		mj_free(&o);
		in->from_bvh = source == MLOD_FORMAT_BVH;
	}
	if (r == MLOD_OK && d && (flags & MLOD_RECORD_INPUT_CLIPS))
		r = input_clips(d, c, &in->level_clips, err);
	if (r != MLOD_OK) {
		mlod_gltf_free(d);
		mlod_character_free(c);
		return r;
	}
	if (doc)
		*doc = d;
	else
		mlod_gltf_free(d);
	return MLOD_OK;
}
