/*
 * bake.c: a character's motion levels as mlod-motion makes them
 * (mlod_motion_bake_run): every clip's levels (levels.c), each level's
 * skinned-vertex error and morph weights channels, the messages to show,
 * and what is written of them: the report (table or JSON text), the glb's
 * level animations with their records, a BVH of one level. The library
 * returns the text; the tool prints it.
 */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "motion/mlod_motion.h"
#include "record/mlod_record.h"

/* A character with c's skeleton and meshes and one clip (shallow). */
static mlod_character with_clip(const mlod_character *c, const mlod_clip *clip)
{
	mlod_character s = *c;
	s.clip_count = 1;
	s.clips = (mlod_clip *)clip;
	s.notes = NULL;
	return s;
}

static const char *method_name(mlod_motion_method m)
{
	return m == MLOD_MOTION_KEYS ? "keys" : "frames";
}

static const char *target_name(mlod_motion_target t)
{
	return t == MLOD_MOTION_THRESHOLD ? "threshold" : t == MLOD_MOTION_FRACTION ? "keys" : "max_error";
}

/* ------------------------------------------------------------------ */
/* Text                                                                */
/* ------------------------------------------------------------------ */

static void sb_json_string(mlod_buf *b, const char *s)
{
	mlod_buf_printf(b, "\"");
	for (const unsigned char *p = (const unsigned char *)s; *p; p++) {
		switch (*p) {
		case '"': mlod_buf_printf(b, "\\\""); break;
		case '\\': mlod_buf_printf(b, "\\\\"); break;
		case '\n': mlod_buf_printf(b, "\\n"); break;
		case '\t': mlod_buf_printf(b, "\\t"); break;
		case '\r': mlod_buf_printf(b, "\\r"); break;
		default:
			if (*p < 0x20) {
				mlod_buf_printf(b, "\\u%04x", *p);
			} else if (*p < 0x80) {
				mlod_buf_printf(b, "%c", *p);
			} else { /* JSON text is UTF-8: a byte that does not start a well-formed sequence as U+FFFD */
				int n = mlod_utf8_length((const char *)p);
				if (n == 0)
					mlod_buf_printf(b, "\xEF\xBF\xBD");
				else
					mlod_buf_printf(b, "%.*s", n, (const char *)p), p += n - 1;
			}
		}
	}
	mlod_buf_printf(b, "\"");
}

/* A name in a table (mlod_name_text's C escapes), padded to width
 * columns, a UTF-8 character one column. */
static void sb_name(mlod_buf *b, const char *name, int width)
{
	char text[512];
	mlod_name_text(name, 0, text, sizeof text);
	int columns = 0;
	for (const unsigned char *p = (const unsigned char *)text; *p; p++)
		columns += (*p & 0xc0) != 0x80;
	mlod_buf_printf(b, "%s%*s", text, width > columns ? width - columns : 0, "");
}

/* A text in a table whole, however long (sb_name cuts at 512 bytes):
 * mlod_name_text's C escapes, into a buffer with room for every byte as
 * \xHH. */
static void sb_text(mlod_buf *b, const char *s)
{
	size_t size = 4 * strlen(s ? s : "") + 16;
	char *text = malloc(size);
	if (!text) {
		b->status = MLOD_ERR_NOMEM;
		return;
	}
	mlod_buf_printf(b, "%s", mlod_name_text(s, 0, text, size));
	free(text);
}

static int add_note(mlod_motion_bake *b, const char *fmt, ...)
#if defined(__GNUC__)
	__attribute__((format(printf, 2, 3)))
#endif
	;

static int add_note(mlod_motion_bake *b, const char *fmt, ...)
{
	char line[MLOD_ERROR_MESSAGE_SIZE + 64];
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(line, sizeof line, fmt, ap);
	va_end(ap);
	char **notes = realloc(b->notes, sizeof *notes * (size_t)(b->note_count + 1));
	if (!notes)
		return -1;
	b->notes = notes;
	if ((notes[b->note_count] = malloc(strlen(line) + 1)) == NULL)
		return -1;
	strcpy(notes[b->note_count++], line);
	return 0;
}

/* ------------------------------------------------------------------ */
/* The levels, their measures and morph weights                        */
/* ------------------------------------------------------------------ */

/* A copy of a weight track. */
static mlod_result copy_track(const mlod_weight_track *in, mlod_weight_track *out)
{
	size_t n = (size_t)in->key_count, v = n * (size_t)in->targets * (in->interp == MLOD_INTERP_CUBICSPLINE ? 3 : 1);
	*out = *in;
	out->times = malloc(sizeof(float) * (n ? n : 1));
	out->values = malloc(sizeof(float) * (v ? v : 1));
	if (!out->times || !out->values)
		return MLOD_ERR_NOMEM;
	memcpy(out->times, in->times, sizeof(float) * n);
	memcpy(out->values, in->values, sizeof(float) * v);
	return MLOD_OK;
}

/* A level's skinned-vertex error and morph weights: each track reduced
 * within the level's bound (or, for a level chosen by keys or threshold,
 * its joint error); tracks that cannot be reduced (CUBICSPLINE, no mesh
 * to measure) are copied. Fills only lv. */
static mlod_result level_extras(const mlod_character *c, const mlod_motion_bake_options *o,
                                const mlod_motion_bake_clip *cl, mlod_motion_bake_level *lv, mlod_error *err)
{
	if (c->instance_count > 0) {
		mlod_character a = with_clip(c, &c->clips[cl->index]), b = with_clip(c, &lv->l.clip);
		mlod_error why = { 0 };
		char q[MLOD_NAME_TEXT_SIZE];
		mlod_result r = mlod_vertex_deviation(&a, &b, o->vertex_samples, &lv->vertex, &why);
		if (r != MLOD_OK)
			return mlod_fail(err, r, "clip %s: %s", mlod_name_text(c->clips[cl->index].name, 1, q, sizeof q),
			                 why.message);
		lv->has_vertex = 1;
	}
	if (cl->w_count == 0)
		return MLOD_OK;
	lv->w = calloc((size_t)cl->w_count, sizeof *lv->w);
	if (!lv->w)
		return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
	lv->w_count = cl->w_count;
	lv->w_bound = lv->bound >= 0.0 ? lv->bound : lv->l.error.max;
	int sub = o->motion.subdivide > 0 ? o->motion.subdivide : MLOD_DEFAULT_SUBDIVIDE;
	for (int i = 0; i < cl->w_count; i++) {
		const mlod_weight_track *t = &cl->w[i];
		double *reach = malloc(sizeof(double) * (size_t)(t->targets > 0 ? t->targets : 1)), e = 0.0;
		if (!reach)
			return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
		mlod_error why = { 0 };
		mlod_result r = t->interp == MLOD_INTERP_CUBICSPLINE ? MLOD_ERR_UNSUPPORTED
		                                                     : mlod_morph_target_reach(c, t->node, t->targets, reach, &why);
		if (r == MLOD_OK)
			r = mlod_weight_track_reduce(t, reach, lv->w_bound, sub, &lv->w[i], &e, &why);
		free(reach);
		if (r == MLOD_ERR_NOMEM) {
			if (err)
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

typedef struct extras_ctx {
	const mlod_character *c;
	const mlod_motion_bake_options *o;
	mlod_motion_bake *b;
	int *item_clip, *item_level;
	mlod_result *result; /* per clip and level (MLOD_MAX_SUBDIVIDE apart) */
	mlod_error *error;
	int per_clip;
} extras_ctx;

static mlod_result extras_item(void *ctx, int i)
{
	extras_ctx *x = ctx;
	int k = x->item_clip[i], s = x->item_level[i];
	mlod_motion_bake_clip *cl = &x->b->clips[k];
	size_t at = (size_t)k * (size_t)x->per_clip + (size_t)s;
	x->result[at] = level_extras(x->c, x->o, cl, &cl->levels[s], &x->error[at]);
	return MLOD_OK;
}

mlod_result mlod_motion_bake_run(const mlod_character *c, const mlod_gltf *doc, const int *clips, int clip_count,
                                 const mlod_motion_bake_options *o, mlod_motion_bake *out, mlod_error *err)
{
	if (!out)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_motion_bake_run: NULL argument");
	memset(out, 0, sizeof *out);
	if (!c || !o || clip_count < 0 || (clip_count > 0 && !clips) || o->spec_count < 0 ||
	    (o->spec_count > 0 && !o->specs))
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_motion_bake_run: bad arguments");
	int n = clip_count, per = o->spec_count > 0 ? o->spec_count : 1;
	out->clips = calloc((size_t)n + 1, sizeof *out->clips);
	mlod_result *w_result = calloc((size_t)n + 1, sizeof *w_result);
	mlod_error *w_error = calloc((size_t)n + 1, sizeof *w_error);
	mlod_motion_clip_levels *built = calloc((size_t)n + 1, sizeof *built);
	int *item_clip = malloc(sizeof(int) * ((size_t)n * (size_t)per + 1));
	int *item_level = malloc(sizeof(int) * ((size_t)n * (size_t)per + 1));
	mlod_result *x_result = calloc((size_t)n * (size_t)per + 1, sizeof *x_result);
	mlod_error *x_error = calloc((size_t)n * (size_t)per + 1, sizeof *x_error);
	mlod_result r = MLOD_OK;
	if (!out->clips || !w_result || !w_error || !built || !item_clip || !item_level || !x_result || !x_error) {
		r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
		goto done;
	}
	out->clip_count = n;
	for (int k = 0; k < n; k++) {
		mlod_motion_bake_clip *cl = &out->clips[k];
		const mlod_clip *src = &c->clips[clips[k]];
		cl->index = clips[k];
		cl->keys = mlod_clip_key_count(src);
		cl->bytes = mlod_clip_key_bytes(src);
		if (doc && src->gltf_index >= 0) {
			w_result[k] = mlod_gltf_weight_tracks(doc, src->gltf_index, &cl->w, &cl->w_count, &w_error[k]);
			cl->w_keys = mlod_weight_tracks_keys(cl->w, cl->w_count);
			cl->keys += cl->w_keys;
			cl->bytes += mlod_weight_tracks_bytes(cl->w, cl->w_count);
		}
		if ((cl->levels = calloc((size_t)per, sizeof *cl->levels)) == NULL) {
			r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
			goto done;
		}
	}
	r = mlod_motion_build_levels(c, clips, n, &o->motion, o->methods, o->method_count, o->specs, o->spec_count,
	                             o->threads, built, err);
	if (r != MLOD_OK)
		goto done;
	int items = 0;
	for (int k = 0; k < n; k++) {
		mlod_motion_bake_clip *cl = &out->clips[k];
		cl->timeline = built[k].timeline;
		cl->frames = cl->timeline.frames;
		if (w_result[k] != MLOD_OK || built[k].result != MLOD_OK)
			continue;
		for (int s = 0; s < built[k].level_count; s++) {
			mlod_motion_bake_level *lv = &cl->levels[cl->level_count++];
			lv->target = o->specs[s].target;
			lv->value = o->specs[s].value;
			lv->bound = lv->target == MLOD_MOTION_MAX_ERROR ? lv->value : -1.0;
			lv->ok = built[k].results[s] == MLOD_OK;
			if (lv->ok) {
				lv->l = built[k].levels[s];
				memset(&built[k].levels[s], 0, sizeof built[k].levels[s]);
				item_clip[items] = k;
				item_level[items++] = s;
			}
		}
	}
	extras_ctx x = { c, o, out, item_clip, item_level, x_result, x_error, per };
	mlod_parallel_for(items, o->threads, extras_item, &x);
	/* What is said, in the order of a run one clip and level after
	 * another: its notes, then the first failure. */
	for (int k = 0; k < n && r == MLOD_OK; k++) {
		const mlod_motion_bake_clip *cl = &out->clips[k];
		const mlod_clip *src = &c->clips[cl->index];
		char q[MLOD_NAME_TEXT_SIZE];
		const char *name = mlod_name_text(src->name, 1, q, sizeof q);
		if (w_result[k] != MLOD_OK) {
			r = w_result[k];
			if (err)
				*err = w_error[k];
			break;
		}
		if (built[k].result != MLOD_OK) {
			r = built[k].result;
			if (err)
				*err = built[k].error;
			break;
		}
		if (src->channel_count == 0) {
			/* A camera's or another node's animation, or morph weights
			 * alone: mlod_gltf_add_animation writes joint channels, so
			 * a level of it could not be written. */
			int fail = cl->w_count == 0
			               ? add_note(out, "clip %s animates no joint and no morph weights: nothing to reduce, no "
			                               "levels (the animation is kept as it is)", name)
			               : add_note(out, "clip %s animates no joint, only morph weights (%d channel%s): no levels "
			                               "(the animation is kept as it is)", name, cl->w_count,
			                          cl->w_count == 1 ? "" : "s");
			if (fail != 0)
				r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
			continue;
		}
		if (cl->frames < 3) {
			if (add_note(out, "clip %s has %d frame%s: nothing to reduce, no levels", name, cl->frames,
			             cl->frames == 1 ? "" : "s") != 0)
				r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
			continue;
		}
		int keys = 0, frames_method = 0;
		for (int i = 0; i < o->method_count; i++)
			keys |= o->methods[i] == MLOD_MOTION_KEYS, frames_method |= o->methods[i] == MLOD_MOTION_FRAMES;
		mlod_error why = { 0 };
		if (keys && frames_method &&
		    mlod_motion_keys_fit(c->skeleton.joint_count, cl->frames,
		                         o->motion.subdivide > 0 ? o->motion.subdivide : MLOD_DEFAULT_SUBDIVIDE, src->name, &why) != MLOD_OK &&
		    add_note(out, "the keys method is left out, the levels come from the frames method alone: %s", why.message) != 0)
			r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
		for (int s = 0; s < built[k].level_count && r == MLOD_OK; s++) {
			mlod_result rs = built[k].results[s];
			size_t at = (size_t)k * (size_t)per + (size_t)s;
			if (rs == MLOD_ERR_LIMIT) {
				if (add_note(out, "%s", built[k].errors[s].message) != 0)
					r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
			} else if (rs != MLOD_OK) {
				r = rs;
				if (err)
					*err = built[k].errors[s];
			} else if (x_result[at] != MLOD_OK) {
				r = x_result[at];
				if (err)
					*err = x_error[at];
			}
		}
	}
done:
	mlod_motion_clip_levels_free(built, n);
	free(built);
	free(w_result);
	free(w_error);
	free(item_clip);
	free(item_level);
	free(x_result);
	free(x_error);
	return r;
}

void mlod_motion_bake_free(mlod_motion_bake *b)
{
	if (!b)
		return;
	for (int k = 0; b->clips && k < b->clip_count; k++) {
		mlod_motion_bake_clip *cl = &b->clips[k];
		for (int i = 0; cl->levels && i < cl->level_count; i++) {
			if (cl->levels[i].ok)
				mlod_motion_level_free(&cl->levels[i].l);
			mlod_weight_tracks_free(cl->levels[i].w, cl->levels[i].w_count);
		}
		free(cl->levels);
		mlod_weight_tracks_free(cl->w, cl->w_count);
	}
	free(b->clips);
	for (int i = 0; i < b->note_count; i++)
		free(b->notes[i]);
	free(b->notes);
	memset(b, 0, sizeof *b);
}

/* ------------------------------------------------------------------ */
/* Reports                                                             */
/* ------------------------------------------------------------------ */

static void timeline_note(char *buf, size_t size, const mlod_motion_bake_clip *cl)
{
	if (!cl->timeline.resampled)
		snprintf(buf, size, "own keys");
	else
		snprintf(buf, size, "resampled to %d common frames (%d channels on other times, %d CUBICSPLINE)", cl->frames,
		         cl->timeline.mismatched_channels, cl->timeline.cubic_channels);
}

int mlod_motion_bake_timeline_note(const mlod_motion_bake *b, int k, char *buf, size_t size)
{
	if (!b || k < 0 || k >= b->clip_count || !b->clips[k].timeline.resampled)
		return 0;
	timeline_note(buf, size, &b->clips[k]);
	return 1;
}

mlod_result mlod_motion_bake_table(const mlod_motion_bake *b, const mlod_character *c,
                                   const mlod_motion_report_info *info, char **text, mlod_error *err)
{
	mlod_buf sb = MLOD_BUF_INIT;
	double height = info->height;
	mlod_buf_printf(&sb, "# ");
	sb_text(&sb, info->input);
	mlod_buf_printf(&sb, ": %d joints, height %.4g, %d clips; point distance %.4g\n", c->skeleton.joint_count, height, c->clip_count, info->point_distance);
	mlod_buf_printf(&sb, "%-16s %5s %6s %10s %7s %7s %8s %10s %8s %10s %8s %10s %8s\n", "clip", "level", "method",
	          "threshold", "keys", "keys%", "bytes", "jnt max", "max%", "jnt mean", "mean%", "pt max", "vtx max%");
	for (int k = 0; k < b->clip_count; k++) {
		const mlod_motion_bake_clip *cl = &b->clips[k];
		const char *name = c->clips[cl->index].name;
		sb_name(&sb, name, 16);
		mlod_buf_printf(&sb, " %5d %6s %10s %7ld %6.1f%% %8ld %10s %8s %10s %8s %10s %8s\n", 0, "-", "-",
		          cl->keys, 100.0, cl->bytes, "0", "0", "0", "0", "0", c->instance_count ? "0" : "-");
		for (int i = 0; i < cl->level_count; i++) {
			const mlod_motion_bake_level *lv = &cl->levels[i];
			if (!lv->ok) {
				sb_name(&sb, name, 16);
				mlod_buf_printf(&sb, " %5d %6s (no level within %.4g)\n", i + 1, "-", lv->bound);
				continue;
			}
			char vtx[32] = "-";
			if (lv->has_vertex)
				snprintf(vtx, sizeof vtx, "%.4f", lv->vertex.max);
			long keys = lv->l.keys + lv->w_keys;
			sb_name(&sb, name, 16);
			mlod_buf_printf(&sb, " %5d %6s %10.4g %7ld %6.1f%% %8ld %10.4g %8.4f %10.4g %8.4f %10.4g %8s\n", i + 1, method_name(lv->l.method), lv->l.threshold, keys, 100.0 * (double)keys / (double)cl->keys,
			          lv->l.bytes + lv->w_bytes, lv->l.error.max, 100.0 * lv->l.error.max / height, lv->l.error.mean,
			          100.0 * lv->l.error.mean / height, lv->l.point_error, vtx);
		}
	}
	for (int k = 0; k < b->clip_count; k++) {
		char note[256];
		if (mlod_motion_bake_timeline_note(b, k, note, sizeof note)) {
			mlod_buf_printf(&sb, "# clip ");
			sb_name(&sb, c->clips[b->clips[k].index].name, 0);
			mlod_buf_printf(&sb, ": %s\n", note);
		}
	}
	for (int k = 0; k < b->clip_count; k++) {
		const mlod_motion_bake_clip *cl = &b->clips[k];
		if (cl->w_count == 0)
			continue;
		mlod_buf_printf(&sb, "# clip ");
		sb_name(&sb, c->clips[cl->index].name, 0);
		mlod_buf_printf(&sb, ": %d morph weights channels, %ld keys; per level kept keys (vertex error bound, scene units):",
		          cl->w_count, cl->w_keys);
		for (int i = 0; i < cl->level_count; i++)
			if (cl->levels[i].ok)
				mlod_buf_printf(&sb, " %d: %ld (%.4g%s)", i + 1, cl->levels[i].w_keys, cl->levels[i].w_error,
				          cl->levels[i].w_copied ? ", some copied" : "");
		mlod_buf_printf(&sb, "\n");
	}
	mlod_buf_printf(&sb, "# threshold: frame distance (frames) or error budget in scene units (keys); jnt: world joint\n"
	               "# position error against the clip as read, scene units and %% of the height; pt: point error (joint\n"
	               "# origins and points within the point distance), scene units; vtx: skinned-vertex error, %% of the\n"
	               "# bounding diagonal\n");
	int sub = info->subdivide;
	if (sub == 1)
		mlod_buf_printf(&sb, "# jnt and pt measured at the frames of each clip's common timeline (--subdivide 1)\n");
	else
		mlod_buf_printf(&sb,
		          "# jnt and pt measured at the frames of each clip's common timeline and %d time%s between each two "
		          "(--subdivide %d)\n",
		          sub - 1, sub == 2 ? "" : "s", sub);
	if (info->precision != MLOD_MOTION_PRECISION_FULL)
		mlod_buf_printf(&sb, "# key values rounded within each level's bound (--precision %s)\n",
		          info->precision == MLOD_MOTION_PRECISION_AUTO ? "auto" : "float");
	size_t len; /* one "# note:" line per line of the reader's notes */
	for (const char *w = c->notes, *l; (l = mlod_next_line(&w, &len));)
		if (len > 0)
			mlod_buf_printf(&sb, "# note: %.*s\n", (int)len, l);
	return mlod_buf_take(&sb, text, NULL, NULL, err);
}

mlod_result mlod_motion_bake_json(const mlod_motion_bake *b, const mlod_character *c,
                                  const mlod_motion_report_info *info, char **text, mlod_error *err)
{
	mlod_buf sb = MLOD_BUF_INIT;
	double height = info->height;
	mlod_buf_printf(&sb, "{\n  \"input\": ");
	sb_json_string(&sb, info->input);
	mlod_buf_printf(&sb, ",\n  \"joints\": %d,\n  \"height\": %.9g,\n  \"point_distance\": %.9g,\n  \"subdivide\": %d,\n  \"clips\": [\n",
	          c->skeleton.joint_count, height, info->point_distance, info->subdivide);
	for (int k = 0; k < b->clip_count; k++) {
		const mlod_motion_bake_clip *cl = &b->clips[k];
		mlod_buf_printf(&sb, "    {\"name\": ");
		sb_json_string(&sb, c->clips[cl->index].name);
		mlod_buf_printf(&sb,
		          ", \"index\": %d, \"duration\": %.9g, \"frames\": %d, \"resampled\": %s, "
		          "\"mismatched_channels\": %d, \"cubic_channels\": %d, \"keys\": %ld, \"bytes\": %ld,\n     \"levels\": [",
		          cl->index, (double)c->clips[cl->index].duration, cl->frames, cl->timeline.resampled ? "true" : "false",
		          cl->timeline.mismatched_channels, cl->timeline.cubic_channels, cl->keys, cl->bytes);
		for (int i = 0; i < cl->level_count; i++) {
			const mlod_motion_bake_level *lv = &cl->levels[i];
			mlod_buf_printf(&sb, "%s\n       {\"level\": %d, \"target\": \"%s\", \"value\": %.9g, ", i ? "," : "", i + 1,
			          target_name(lv->target), lv->value);
			if (lv->bound >= 0.0)
				mlod_buf_printf(&sb, "\"bound\": %.9g, \"bound_percent_height\": %.9g, ", lv->bound,
				          100.0 * lv->bound / height);
			if (!lv->ok) {
				mlod_buf_printf(&sb, "\"ok\": false}");
				continue;
			}
			long keys = lv->l.keys + lv->w_keys;
			mlod_buf_printf(&sb,
			          "\"ok\": true, \"method\": \"%s\", \"threshold\": %.9g, \"keys\": %ld, \"keys_percent\": %.6g, "
			          "\"bytes\": %ld,\n        \"joint_error\": {\"max\": %.9g, \"mean\": %.9g, \"max_percent_height\": %.9g, "
			          "\"mean_percent_height\": %.9g},\n        \"point_error\": %.9g, \"grid\": %.9g",
			          method_name(lv->l.method), lv->l.threshold, keys, 100.0 * (double)keys / (double)cl->keys,
			          lv->l.bytes + lv->w_bytes, lv->l.error.max, lv->l.error.mean, 100.0 * lv->l.error.max / height,
			          100.0 * lv->l.error.mean / height, lv->l.point_error, lv->l.grid);
			if (lv->has_vertex)
				mlod_buf_printf(&sb,
				          ",\n        \"vertex_error\": {\"max\": %.9g, \"max_percent_diagonal\": %.9g, "
				          "\"mean_percent_diagonal\": %.9g}",
				          lv->vertex.max * lv->vertex.scale / 100.0, lv->vertex.max, lv->vertex.mean);
			if (lv->w_count)
				mlod_buf_printf(&sb,
				          ",\n        \"morph_weights\": {\"channels\": %d, \"keys\": %ld, \"source_keys\": %ld, \"bytes\": %ld, "
				          "\"bound\": %.9g, \"error\": %.9g, \"copied\": %d, \"error_measure\": \"sum over targets of "
				          "|weight error| times the target's largest vertex offset in the rest pose, scene units\"}",
				          lv->w_count, lv->w_keys, cl->w_keys, lv->w_bytes, lv->w_bound, lv->w_error, lv->w_copied);
			mlod_buf_printf(&sb, "}");
		}
		mlod_buf_printf(&sb, "]}%s\n", k + 1 < b->clip_count ? "," : "");
	}
	mlod_buf_printf(&sb, "  ]\n}\n");
	return mlod_buf_take(&sb, text, NULL, NULL, err);
}

/* ------------------------------------------------------------------ */
/* Output                                                              */
/* ------------------------------------------------------------------ */

mlod_result mlod_motion_bake_to_gltf(mlod_motion_bake *b, const mlod_character *c, mlod_gltf *doc, double height,
                                     int subdivide, mlod_error *err)
{
	for (int k = 0; k < b->clip_count; k++) {
		mlod_motion_bake_clip *cl = &b->clips[k];
		const mlod_clip *src = &c->clips[cl->index];
		for (int i = 0; i < cl->level_count; i++) {
			mlod_motion_bake_level *lv = &cl->levels[i];
			if (!lv->ok)
				continue;
			/* An unnamed clip's levels are named as three.js names
			 * the clip itself: animation_<its glTF index>. */
			char unnamed[32];
			snprintf(unnamed, sizeof unnamed, "animation_%d", src->gltf_index >= 0 ? src->gltf_index : cl->index);
			const char *base = src->name && src->name[0] ? src->name : unnamed;
			char q[MLOD_NAME_TEXT_SIZE];
			char *name = malloc(strlen(base) + 32);
			if (!name)
				return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
			sprintf(name, "%s@lod%d", base, i + 1);
			free(lv->l.clip.name);
			lv->l.clip.name = name;
			int index;
			mlod_error why = { 0 };
			mlod_result r = mlod_gltf_add_animation(doc, &c->skeleton, &lv->l.clip, &index, &why);
			if (r != MLOD_OK)
				return mlod_fail(err, r, "clip %s: %s", mlod_name_text(base, 1, q, sizeof q), why.message);
			/* The level's stage record (mlod-record(5)). */
			mlod_record_motion_level rec;
			memset(&rec, 0, sizeof rec);
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
			rec.joint_error_max_percent_height = 100.0 * lv->l.error.max / height;
			rec.point_error = lv->l.point_error;
			rec.grid = lv->l.grid;
			rec.subdivide = subdivide;
			rec.has_vertex_error = lv->has_vertex;
			rec.vertex_error_percent_diagonal = lv->vertex.max;
			if (lv->w_count) {
				rec.has_morph_weights = 1;
				rec.morph_weights = (mlod_record_morph_weights){ lv->w_count, lv->w_keys, cl->w_keys, lv->w_bytes,
				                                                 lv->w_bound, lv->w_error, lv->w_copied };
				r = mlod_gltf_add_weight_tracks(doc, index, lv->w, lv->w_count, &why);
				if (r != MLOD_OK)
					return mlod_fail(err, r, "clip %s: %s", mlod_name_text(base, 1, q, sizeof q), why.message);
			}
			r = mlod_record_write_motion(doc, index, &rec, err);
			if (r != MLOD_OK)
				return r;
		}
	}
	return MLOD_OK;
}

/* The frame time a BVH of the clip plays at: its own, else the mean
 * spacing of its common timeline (frames; 0: of its key times). */
static float bvh_frame_time(const mlod_clip *src, int frames)
{
	if (src->frame_time > 0.0f)
		return 0.0f; /* the clip's own */
	float *times = NULL;
	if (frames == 0) { /* level 0 alone: the clip's key times */
		frames = mlod_clip_times(src, 0, &times);
		mlod_free(times);
	}
	if (frames > 1 && src->duration > 0.0f)
		return src->duration / (float)(frames - 1);
	return 0.0f;
}

mlod_result mlod_motion_bvh(const mlod_character *c, int clip, const mlod_clip *use, int frames, char **text,
                            size_t *size, mlod_error *err)
{
	if (!c || clip < 0 || clip >= c->clip_count || !text || !size)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_motion_bvh: bad arguments");
	const mlod_clip *src = &c->clips[clip];
	mlod_character one = with_clip(c, use ? use : src);
	return mlod_bvh_write(&one, 0, bvh_frame_time(src, frames), text, size, err);
}
