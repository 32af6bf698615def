/*
 * bvhread.c: reads BVH (Biovision Hierarchy) motion capture text.
 *
 * Reading builds a character with one joint per ROOT/JOINT (rest = OFFSET,
 * identity rotation, unit scale), the channel layout of each joint, its End
 * Site, and one uniformly sampled clip "bvh": a LINEAR rotation channel for
 * every joint with rotation channels (quaternions from the Euler angles,
 * kept sign-continuous from frame to frame) and a LINEAR translation channel
 * for every joint with position channels (the channel values replace the
 * matching OFFSET components; the others keep the OFFSET). Key i is at
 * i * frame time. A partial layout ("CHANNELS 2 Zrotation Xrotation") is
 * read as such and then completed to 3 or 6 channels, as the character
 * model keeps them. Frames: 0, or no channels at all, gives no clip.
 *
 * The reader trusts nothing: every error names its line (frames are
 * counted from 1 in messages), sizes claimed by the file are checked
 * against the bytes actually present before anything is allocated, and
 * the hierarchy is parsed without recursion. It accepts CR LF, LF or CR
 * line ends, a UTF-8 byte order mark, keywords in any case, names with
 * spaces, and braces on the line of what they open. Numbers get the
 * value strtod gives them in the C locale, whatever the locale (decimal.c);
 * NaN and infinities are refused.
 */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/bvh_internal.h"
#include "io/decimal.h"
#include "io/mlod_io.h"

const char *const bvh_channel_names[6] = {
	"Xposition", "Yposition", "Zposition", "Xrotation", "Yrotation", "Zrotation"
};

/* The Euler order whose axes are a, b, c. */
static mlod_euler_order euler_from_axes(int a, int b, int c)
{
	for (int o = 0; o < 6; o++) {
		const int *ax = mlod_euler_axes((mlod_euler_order)o);
		if (ax[0] == a && ax[1] == b && ax[2] == c)
			return (mlod_euler_order)o;
	}
	return MLOD_EULER_XYZ;
}

/* The Euler order of a channel layout: the order in which its rotation
 * channels appear, the missing axes appended in x, y, z order (their angle
 * is always 0, so where they go does not matter). *fallback when there is
 * no rotation channel. */
mlod_euler_order bvh_layout_euler(const unsigned char *ch, int n, mlod_euler_order fallback)
{
	int axes[3], k = 0, seen[3] = { 0, 0, 0 };
	for (int i = 0; i < n; i++)
		if (ch[i] >= MLOD_BVH_XROT && ch[i] <= MLOD_BVH_ZROT && !seen[ch[i] - 3]) {
			seen[ch[i] - 3] = 1;
			axes[k++] = ch[i] - 3;
		}
	if (k == 0)
		return fallback;
	for (int a = 0; a < 3; a++)
		if (!seen[a])
			axes[k++] = a;
	return euler_from_axes(axes[0], axes[1], axes[2]);
}

/* ================================================================== */
/* Numbers                                                             */
/* ================================================================== */

static int ascii_lower(int c)
{
	return c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c;
}

static int is_digit(int c)
{
	return c >= '0' && c <= '9';
}

/* 10^e for 0 <= e <= 22, exactly. */
double bvh_pow10_exact(int e)
{
	double r = 1.0;
	while (e-- > 0)
		r *= 10.0;
	return r;
}

/* Parses a whole token as a decimal number (mlod_decimal_parse: strtod's
 * value, without the locale); BVH_NUM_RANGE beyond the float range. */
int bvh_parse_number(const char *s, size_t len, double *out)
{
	double v;
	switch (mlod_decimal_parse(s, len, &v)) {
	case MLOD_DEC_OK: break;
	case MLOD_DEC_NONFINITE: return BVH_NUM_NONFINITE;
	default: return BVH_NUM_SYNTAX;
	}
	if (!isfinite(v) || fabs(v) > FLT_MAX)
		return BVH_NUM_RANGE;
	*out = v;
	return BVH_NUM_OK;
}

/* ================================================================== */
/* Lexer                                                               */
/* ================================================================== */

typedef struct lexer {
	const char *p, *end;
	int line;
} lexer;

typedef struct token {
	const char *s;
	size_t len; /* 0 at the end of the input (or of the line, for line tokens) */
	int line;
} token;

static int is_space(int c)
{
	return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v';
}

/* A byte that has no place in BVH text. */
static int is_binary(int c)
{
	return (c < 0x20 && !is_space(c)) || c == 0x7f;
}

/* Skips blanks; crosses line breaks only when newlines is set. CR LF, LF
 * and a lone CR each end one line. */
static void skip_space(lexer *lx, int newlines)
{
	while (lx->p < lx->end) {
		char c = *lx->p;
		if (c == '\n' || c == '\r') {
			if (!newlines)
				return;
			if (c == '\r' && lx->p + 1 < lx->end && lx->p[1] == '\n')
				lx->p++;
			lx->line++;
		} else if (!is_space((unsigned char)c)) {
			return;
		}
		lx->p++;
	}
}

/* Reads one token: a brace, or a run of other non-blank bytes. Returns -1
 * (with the offending byte left at lx->p) on a binary byte. */
static int lex(lexer *lx, token *t, int newlines)
{
	skip_space(lx, newlines);
	t->line = lx->line;
	t->s = lx->p;
	t->len = 0;
	if (lx->p >= lx->end || *lx->p == '\n' || *lx->p == '\r')
		return 0;
	if (is_binary((unsigned char)*lx->p))
		return -1;
	if (*lx->p == '{' || *lx->p == '}') {
		lx->p++;
		t->len = 1;
		return 0;
	}
	while (lx->p < lx->end) {
		unsigned char c = (unsigned char)*lx->p;
		if (is_space(c) || is_binary(c) || c == '{' || c == '}')
			break;
		lx->p++;
	}
	t->len = (size_t)(lx->p - t->s);
	return 0;
}

static int tok_is(const token *t, const char *kw)
{
	size_t n = strlen(kw);
	if (t->len != n)
		return 0;
	for (size_t i = 0; i < n; i++)
		if (ascii_lower((unsigned char)t->s[i]) != ascii_lower((unsigned char)kw[i]))
			return 0;
	return 1;
}

/* When t starts with the keyword kw (as in "Frames:" or "Frames:524"),
 * leaves the rest of it in t and returns 1. An empty rest has its line. */
static int split_prefix(token *t, const char *kw)
{
	size_t n = strlen(kw);
	if (t->len < n)
		return 0;
	token head = *t;
	head.len = n;
	if (!tok_is(&head, kw))
		return 0;
	t->s += n;
	t->len -= n;
	return 1;
}

/* The token quoted for a message, shortened and with odd bytes replaced. */
static const char *show(const token *t, char buf[64])
{
	if (t->len == 0)
		return "the end of the file";
	size_t n = t->len > 40 ? 40 : t->len, k = 0;
	buf[k++] = '\'';
	for (size_t i = 0; i < n; i++) {
		unsigned char c = (unsigned char)t->s[i];
		buf[k++] = c < 0x20 || c >= 0x7f ? '?' : (char)c;
	}
	if (n < t->len) {
		memcpy(buf + k, "...", 3);
		k += 3;
	}
	buf[k++] = '\'';
	buf[k] = 0;
	return buf;
}

/* A frame value in its common form, read in one scan: [+-] digits
 * [. digits] with at most 19 digits in all, a mantissa of at most 2^53,
 * and a blank or the end after it. Its value is mant / 10^decimals, one
 * exact division: mlod_decimal_parse's fast path, so the same double.
 * Returns 1 and moves lx past it, or 0 with lx untouched (anything else
 * goes through lex and bvh_parse_number). */
static int frame_number(lexer *lx, double *out)
{
	const char *p = lx->p, *end = lx->end;
	int neg = 0, digits = 0, decimals = 0;
	uint64_t mant = 0;
	if (p < end && (*p == '-' || *p == '+'))
		neg = *p++ == '-';
	while (p < end && is_digit(*p)) {
		mant = mant * 10 + (uint64_t)(*p++ - '0');
		digits++;
	}
	if (p < end && *p == '.') {
		p++;
		while (p < end && is_digit(*p)) {
			mant = mant * 10 + (uint64_t)(*p++ - '0');
			digits++;
			decimals++;
		}
	}
	if (digits == 0 || digits > 19 || mant > (uint64_t)1 << 53 || (p < end && !is_space((unsigned char)*p)))
		return 0;
	double v = (double)mant;
	if (decimals)
		v /= mlod_decimal_pow10[decimals];
	*out = neg ? -v : v;
	lx->p = p;
	return 1;
}

/* Channel code of a channel name, or -1. */
static int channel_code(const token *t)
{
	for (int c = 0; c < 6; c++)
		if (tok_is(t, bvh_channel_names[c]))
			return c;
	return -1;
}

static int is_keyword(const token *t)
{
	static const char *const kws[] = { "HIERARCHY", "ROOT", "JOINT", "End", "Site", "OFFSET",
	                                   "CHANNELS", "MOTION", "Frames:", "{", "}" };
	for (size_t i = 0; i < sizeof kws / sizeof kws[0]; i++)
		if (tok_is(t, kws[i]))
			return 1;
	return 0;
}

/* ================================================================== */
/* Reader                                                              */
/* ================================================================== */

typedef struct open_joint {
	int joint;
	int has_offset, has_channels, has_children;
} open_joint;

typedef struct reader {
	lexer lx;
	mlod_error *err;
	mlod_joint *joints;
	int count, cap;
	open_joint stack[MLOD_MAX_HIERARCHY_DEPTH];
	int depth;
} reader;

#define TRY(x)                                  \
	do {                                    \
		mlod_result r_ = (x);           \
		if (r_ != MLOD_OK)              \
			return r_;              \
	} while (0)

static mlod_result fail_binary(reader *r)
{
	return mlod_fail(r->err, MLOD_ERR_PARSE, "line %d: unexpected byte 0x%02X (binary data in BVH text?)",
	                 r->lx.line, (unsigned)(unsigned char)*r->lx.p);
}

static mlod_result next(reader *r, token *t)
{
	if (lex(&r->lx, t, 1) < 0)
		return fail_binary(r);
	return MLOD_OK;
}

/* The current joint as "JOINT Spine" for messages. */
static const char *joint_desc(const reader *r, int j, char buf[160])
{
	const mlod_joint *jt = &r->joints[j];
	const char *kind = jt->parent < 0 ? "ROOT" : "JOINT";
	size_t n = strlen(jt->name);
	if (n > 100)
		n = 100;
	memcpy(buf, kind, strlen(kind));
	size_t k = strlen(kind);
	buf[k++] = ' ';
	memcpy(buf + k, jt->name, n);
	buf[k + n] = 0;
	return buf;
}

/* Reads a number token; what names the context for messages. */
static mlod_result read_number(reader *r, const char *what, double *out)
{
	token t;
	char b[64];
	TRY(next(r, &t));
	int rc = t.len ? bvh_parse_number(t.s, t.len, out) : BVH_NUM_SYNTAX;
	switch (rc) {
	case BVH_NUM_OK:
		return MLOD_OK;
	case BVH_NUM_NONFINITE:
		return mlod_fail(r->err, MLOD_ERR_PARSE, "line %d: %s in %s is not a finite number", t.line,
		                 show(&t, b), what);
	case BVH_NUM_RANGE:
		return mlod_fail(r->err, MLOD_ERR_PARSE, "line %d: %s in %s is out of range", t.line,
		                 show(&t, b), what);
	default:
		return mlod_fail(r->err, MLOD_ERR_PARSE, "line %d: expected a number in %s, found %s", t.line,
		                 what, show(&t, b));
	}
}

static mlod_result read_offset(reader *r, const char *what, mlod_v3 *out)
{
	double v[3];
	for (int i = 0; i < 3; i++)
		TRY(read_number(r, what, &v[i]));
	out->x = (float)v[0];
	out->y = (float)v[1];
	out->z = (float)v[2];
	return MLOD_OK;
}

/* Reads the name after ROOT or JOINT: the rest of the line up to a '{',
 * trimmed (names with inner spaces are kept whole). */
static mlod_result read_name(reader *r, const char *kind, char **out)
{
	lexer *lx = &r->lx;
	skip_space(lx, 0);
	const char *s = lx->p;
	while (lx->p < lx->end && *lx->p != '\n' && *lx->p != '\r' && *lx->p != '{') {
		if (is_binary((unsigned char)*lx->p))
			return fail_binary(r);
		lx->p++;
	}
	const char *e = lx->p;
	while (e > s && is_space((unsigned char)e[-1]))
		e--;
	if (e == s)
		return mlod_fail(r->err, MLOD_ERR_PARSE, "line %d: %s without a name", lx->line, kind);
	size_t n = (size_t)(e - s);
	char *name = malloc(n + 1);
	if (!name)
		return mlod_fail(r->err, MLOD_ERR_NOMEM, "out of memory");
	memcpy(name, s, n);
	name[n] = 0;
	*out = name;
	return MLOD_OK;
}

/* Reads "NAME {" after ROOT or JOINT and opens the joint. */
static mlod_result begin_joint(reader *r, int parent, const char *kind)
{
	char b[64], d[160];
	if (r->depth >= MLOD_MAX_HIERARCHY_DEPTH)
		return mlod_fail(r->err, MLOD_ERR_UNSUPPORTED, "line %d: joints nested deeper than %d levels",
		                 r->lx.line, MLOD_MAX_HIERARCHY_DEPTH);
	if (r->count >= BVH_MAX_JOINTS)
		return mlod_fail(r->err, MLOD_ERR_NOMEM, "line %d: more than %d joints", r->lx.line,
		                 BVH_MAX_JOINTS);
	if (r->count == r->cap) {
		int cap = r->cap ? r->cap * 2 : 32;
		mlod_joint *j = realloc(r->joints, (size_t)cap * sizeof *j);
		if (!j)
			return mlod_fail(r->err, MLOD_ERR_NOMEM, "out of memory");
		r->joints = j;
		r->cap = cap;
	}
	mlod_joint *j = &r->joints[r->count];
	memset(j, 0, sizeof *j);
	j->name = NULL;
	j->parent = parent;
	j->rest = mlod_trs_identity();
	j->base = mlod_mat4_identity();
	j->node = -1;
	j->euler = MLOD_EULER_XYZ;
	TRY(read_name(r, kind, &j->name));
	r->count++; /* owned from here on */

	token t;
	TRY(next(r, &t));
	if (!tok_is(&t, "{"))
		return mlod_fail(r->err, MLOD_ERR_PARSE, "line %d: expected '{' after %s, found %s", t.line,
		                 joint_desc(r, r->count - 1, d), show(&t, b));
	open_joint *o = &r->stack[r->depth++];
	memset(o, 0, sizeof *o);
	o->joint = r->count - 1;
	return MLOD_OK;
}

/* Reads "n name..." after CHANNELS. */
static mlod_result read_channels(reader *r, mlod_joint *j, const char *desc)
{
	token t;
	char b[64];
	TRY(next(r, &t));
	int line = t.line;
	if (t.len != 1 || !is_digit(t.s[0]) || t.s[0] > '6')
		return mlod_fail(r->err, t.len == 1 && t.s[0] > '6' && t.s[0] <= '9' ? MLOD_ERR_UNSUPPORTED : MLOD_ERR_PARSE,
		                 "line %d: CHANNELS of %s must be a count from 0 to 6, found %s", t.line, desc, show(&t, b));
	int n = t.s[0] - '0';
	int seen = 0;
	for (int i = 0; i < n; i++) {
		TRY(next(r, &t));
		int c = channel_code(&t);
		if (c < 0) {
			if (t.len == 0 || is_keyword(&t))
				return mlod_fail(r->err, MLOD_ERR_PARSE, "line %d: CHANNELS %d of %s lists only %d channel names",
				                 line, n, desc, i);
			return mlod_fail(r->err, MLOD_ERR_PARSE,
			                 "line %d: unknown channel %s in %s (expected Xposition, Yposition, Zposition, "
			                 "Xrotation, Yrotation or Zrotation)", t.line, show(&t, b), desc);
		}
		if (seen & (1 << c))
			return mlod_fail(r->err, MLOD_ERR_PARSE, "line %d: channel %s listed twice in %s", t.line,
			                 bvh_channel_names[c], desc);
		seen |= 1 << c;
		j->channels[i] = (unsigned char)c;
	}
	j->channel_count = n;
	j->euler = bvh_layout_euler(j->channels, n, MLOD_EULER_XYZ);
	return MLOD_OK;
}

/* Reads "Site { OFFSET x y z }" after End. */
static mlod_result read_end_site(reader *r, mlod_joint *j, const char *desc)
{
	token t;
	char b[64];
	TRY(next(r, &t));
	if (!tok_is(&t, "Site"))
		return mlod_fail(r->err, MLOD_ERR_PARSE, "line %d: expected 'Site' after 'End' in %s, found %s",
		                 t.line, desc, show(&t, b));
	if (j->has_end_site)
		return mlod_fail(r->err, MLOD_ERR_PARSE, "line %d: a second End Site in %s", t.line, desc);
	TRY(next(r, &t));
	if (!tok_is(&t, "{"))
		return mlod_fail(r->err, MLOD_ERR_PARSE, "line %d: expected '{' after End Site of %s, found %s",
		                 t.line, desc, show(&t, b));
	TRY(next(r, &t));
	if (!tok_is(&t, "OFFSET"))
		return mlod_fail(r->err, MLOD_ERR_PARSE, "line %d: expected OFFSET in End Site of %s, found %s",
		                 t.line, desc, show(&t, b));
	char what[200];
	strcpy(what, "End Site of ");
	strcat(what, desc);
	TRY(read_offset(r, what, &j->end_site));
	TRY(next(r, &t));
	if (!tok_is(&t, "}"))
		return mlod_fail(r->err, MLOD_ERR_PARSE, "line %d: expected '}' to close End Site of %s, found %s",
		                 t.line, desc, show(&t, b));
	j->has_end_site = 1;
	return MLOD_OK;
}

/* Parses one ROOT (its keyword already read) and all joints below it,
 * iteratively, with the open joints on r->stack. */
static mlod_result read_root(reader *r)
{
	char b[64], d[160];
	TRY(begin_joint(r, -1, "ROOT"));
	while (r->depth > 0) {
		open_joint *o = &r->stack[r->depth - 1];
		mlod_joint *j = &r->joints[o->joint];
		const char *desc = joint_desc(r, o->joint, d);
		token t;
		TRY(next(r, &t));
		if (t.len == 0) {
			return mlod_fail(r->err, MLOD_ERR_PARSE, "line %d: the file ends inside %s (missing '}')",
			                 t.line, desc);
		} else if (tok_is(&t, "OFFSET")) {
			if (o->has_children)
				return mlod_fail(r->err, MLOD_ERR_PARSE, "line %d: OFFSET of %s after its child joints",
				                 t.line, desc);
			if (o->has_offset)
				return mlod_fail(r->err, MLOD_ERR_PARSE, "line %d: a second OFFSET in %s", t.line, desc);
			char what[200];
			strcpy(what, "OFFSET of ");
			strcat(what, desc);
			TRY(read_offset(r, what, &j->rest.t));
			o->has_offset = 1;
		} else if (tok_is(&t, "CHANNELS")) {
			if (o->has_children)
				return mlod_fail(r->err, MLOD_ERR_PARSE, "line %d: CHANNELS of %s after its child joints",
				                 t.line, desc);
			if (o->has_channels)
				return mlod_fail(r->err, MLOD_ERR_PARSE, "line %d: a second CHANNELS in %s", t.line, desc);
			TRY(read_channels(r, j, desc));
			o->has_channels = 1;
		} else if (tok_is(&t, "JOINT")) {
			if (!o->has_offset)
				return mlod_fail(r->err, MLOD_ERR_PARSE, "line %d: %s has no OFFSET before its child joints",
				                 t.line, desc);
			o->has_children = 1;
			TRY(begin_joint(r, o->joint, "JOINT")); /* may move r->joints */
		} else if (tok_is(&t, "End")) {
			if (!o->has_offset)
				return mlod_fail(r->err, MLOD_ERR_PARSE, "line %d: %s has no OFFSET before its End Site",
				                 t.line, desc);
			o->has_children = 1;
			TRY(read_end_site(r, j, desc));
		} else if (tok_is(&t, "}")) {
			if (!o->has_offset)
				return mlod_fail(r->err, MLOD_ERR_PARSE, "line %d: %s has no OFFSET", t.line, desc);
			r->depth--;
		} else if (tok_is(&t, "ROOT") || tok_is(&t, "MOTION") || tok_is(&t, "HIERARCHY")) {
			return mlod_fail(r->err, MLOD_ERR_PARSE, "line %d: %s inside %s (missing '}')", t.line,
			                 show(&t, b), desc);
		} else if (channel_code(&t) >= 0) {
			return mlod_fail(r->err, MLOD_ERR_PARSE,
			                 "line %d: channel name %s in %s outside CHANNELS (more names than its count?)",
			                 t.line, show(&t, b), desc);
		} else {
			double v;
			if (bvh_parse_number(t.s, t.len, &v) != BVH_NUM_SYNTAX)
				return mlod_fail(r->err, MLOD_ERR_PARSE, "line %d: unexpected number %s in %s (too many OFFSET values?)",
				                 t.line, show(&t, b), desc);
			return mlod_fail(r->err, MLOD_ERR_PARSE, "line %d: unexpected %s in %s", t.line,
			                 show(&t, b), desc);
		}
	}
	return MLOD_OK;
}

static mlod_result read_hierarchy(reader *r)
{
	token t;
	char b[64];
	/* A UTF-8 byte order mark may precede the text. */
	if (r->lx.end - r->lx.p >= 3 && memcmp(r->lx.p, "\xEF\xBB\xBF", 3) == 0)
		r->lx.p += 3;
	TRY(next(r, &t));
	if (t.len == 0)
		return mlod_fail(r->err, MLOD_ERR_PARSE, "line %d: empty input (expected HIERARCHY)", t.line);
	if (!tok_is(&t, "HIERARCHY"))
		return mlod_fail(r->err, MLOD_ERR_PARSE, "line %d: expected HIERARCHY at the start of a BVH file, found %s",
		                 t.line, show(&t, b));
	for (;;) {
		TRY(next(r, &t));
		if (tok_is(&t, "ROOT"))
			TRY(read_root(r));
		else if (tok_is(&t, "MOTION"))
			break;
		else if (t.len == 0)
			return mlod_fail(r->err, MLOD_ERR_PARSE, "line %d: the file ends before MOTION", t.line);
		else if (tok_is(&t, "}"))
			return mlod_fail(r->err, MLOD_ERR_PARSE, "line %d: unexpected '}' outside any joint (one too many?)",
			                 t.line);
		else
			return mlod_fail(r->err, MLOD_ERR_PARSE, "line %d: expected ROOT or MOTION, found %s", t.line,
			                 show(&t, b));
	}
	if (r->count == 0)
		return mlod_fail(r->err, MLOD_ERR_PARSE, "line %d: no joints: the HIERARCHY has no ROOT", t.line);
	return MLOD_OK;
}

/* Reads "Frames: n" and "Frame Time: t". */
static mlod_result read_motion_header(reader *r, long *frames, int *frames_line, double *frame_time,
                                      int *time_line)
{
	token t;
	char b[64];
	TRY(next(r, &t));
	if (!split_prefix(&t, "Frames:"))
		return mlod_fail(r->err, MLOD_ERR_PARSE, "line %d: expected 'Frames:' after MOTION, found %s", t.line,
		                 show(&t, b));
	if (t.len == 0)
		TRY(next(r, &t));
	*frames_line = t.line;
	if (t.len > 0 && t.s[0] == '-')
		return mlod_fail(r->err, MLOD_ERR_PARSE, "line %d: negative frame count %s", t.line, show(&t, b));
	long n = 0;
	size_t i = t.len && t.s[0] == '+' ? 1 : 0;
	if (i == t.len)
		return mlod_fail(r->err, MLOD_ERR_PARSE, "line %d: expected a frame count after 'Frames:', found %s",
		                 t.line, show(&t, b));
	for (; i < t.len; i++) {
		if (!is_digit(t.s[i]))
			return mlod_fail(r->err, MLOD_ERR_PARSE, "line %d: expected a whole frame count after 'Frames:', found %s",
			                 t.line, show(&t, b));
		n = n * 10 + (t.s[i] - '0');
		if (n > BVH_MAX_FRAMES)
			return mlod_fail(r->err, MLOD_ERR_NOMEM, "line %d: absurd frame count %s (at most %d)", t.line,
			                 show(&t, b), BVH_MAX_FRAMES);
	}
	*frames = n;

	TRY(next(r, &t));
	if (!tok_is(&t, "Frame"))
		return mlod_fail(r->err, MLOD_ERR_PARSE, "line %d: expected 'Frame Time:', found %s", t.line, show(&t, b));
	TRY(next(r, &t));
	if (!split_prefix(&t, "Time:"))
		return mlod_fail(r->err, MLOD_ERR_PARSE, "line %d: expected 'Frame Time:', found %s", t.line, show(&t, b));
	*time_line = t.line;
	if (t.len == 0) {
		TRY(read_number(r, "Frame Time", frame_time));
	} else {
		int rc = bvh_parse_number(t.s, t.len, frame_time);
		if (rc != BVH_NUM_OK)
			return mlod_fail(r->err, MLOD_ERR_PARSE, "line %d: Frame Time %s is not a finite number", t.line,
			                 show(&t, b));
	}
	if (!((float)*frame_time > 0.0f))
		return mlod_fail(r->err, MLOD_ERR_PARSE, "line %d: Frame Time must be positive, found %g", t.line,
		                 *frame_time);
	if (lex(&r->lx, &t, 0) < 0)
		return fail_binary(r);
	if (t.len)
		return mlod_fail(r->err, MLOD_ERR_PARSE, "line %d: unexpected %s after Frame Time", t.line, show(&t, b));
	return MLOD_OK;
}

/* Does the joint have position channels, rotation channels? */
static void joint_kinds(const mlod_joint *j, int *pos, int *rot)
{
	*pos = *rot = 0;
	for (int k = 0; k < j->channel_count; k++) {
		if (j->channels[k] < MLOD_BVH_XROT)
			*pos = 1;
		else
			*rot = 1;
	}
}

/* Where a joint's animation goes in the clip. */
typedef struct joint_anim {
	int first;       /* index of its first value in a frame */
	float *t, *tv;   /* translation channel times and values, or NULL */
	float *r, *rv;   /* rotation channel times and values, or NULL */
} joint_anim;

static mlod_result read_motion(reader *r, mlod_character *c)
{
	long frames = 0;
	double ft = 0.0;
	int frames_line = 0, time_line = 0;
	token t;
	char b[64];
	TRY(read_motion_header(r, &frames, &frames_line, &ft, &time_line));

	int n = r->count;
	long vpf = 0;
	for (int j = 0; j < n; j++)
		vpf += r->joints[j].channel_count;

	if (vpf == 0 || frames == 0) {
		/* Nothing to animate: only blanks may follow. */
		skip_space(&r->lx, 1);
		if (r->lx.p < r->lx.end) {
			TRY(next(r, &t));
			return mlod_fail(r->err, MLOD_ERR_PARSE, "line %d: unexpected %s: %s", t.line, show(&t, b),
			                 frames == 0 ? "'Frames: 0' announces no frames" : "no joint has channels");
		}
		return MLOD_OK;
	}

	/* Every value takes at least one byte and one separator: check the
	 * claim against the data before allocating for it. */
	uint64_t need = (uint64_t)frames * (uint64_t)vpf;
	uint64_t avail = (uint64_t)(r->lx.end - r->lx.p);
	if (need > avail / 2 + 1)
		return mlod_fail(r->err, MLOD_ERR_PARSE,
		                 "line %d: 'Frames: %ld' needs %llu values of %ld per frame but only %llu bytes follow (truncated file?)",
		                 frames_line, frames, (unsigned long long)need, vpf, (unsigned long long)avail);
	/* Key times must stay distinct in single precision. */
	float last = (float)((double)(frames - 1) * ft), before = (float)((double)(frames - 2) * ft);
	if (!isfinite(last) || (frames > 1 && !(last > before)))
		return mlod_fail(r->err, MLOD_ERR_PARSE, "line %d: Frame Time %g cannot time %ld frames in single precision",
		                 time_line, ft, frames);

	/* The clip: a translation channel for joints with position channels,
	 * a rotation channel for joints with rotation channels. */
	int nch = 0;
	for (int j = 0; j < n; j++) {
		const mlod_joint *jt = &r->joints[j];
		int pos, rot;
		joint_kinds(jt, &pos, &rot);
		nch += pos + rot;
	}
	joint_anim *anim = calloc((size_t)n, sizeof *anim);
	float *vals = malloc((size_t)vpf * sizeof *vals);
	mlod_clip *clip = calloc(1, sizeof *clip);
	c->clips = clip;
	if (clip) {
		c->clip_count = 1;
		clip->gltf_index = -1;
		clip->name = malloc(4);
		clip->channels = calloc((size_t)nch, sizeof *clip->channels);
	}
	if (!anim || !vals || !clip || !clip->name || !clip->channels) {
		free(anim);
		free(vals);
		return mlod_fail(r->err, MLOD_ERR_NOMEM, "out of memory");
	}
	memcpy(clip->name, "bvh", 4);
	clip->frame_time = (float)ft;
	clip->frame_count = (int)frames;
	clip->duration = last;

	mlod_result res = MLOD_OK;
	int first = 0;
	size_t fcount = (size_t)frames;
	for (int j = 0; j < n && res == MLOD_OK; j++) {
		const mlod_joint *jt = &r->joints[j];
		anim[j].first = first;
		first += jt->channel_count;
		int pos, rot;
		joint_kinds(jt, &pos, &rot);
		for (int kind = 0; kind < 2; kind++) {
			if (!(kind == 0 ? pos : rot))
				continue;
			mlod_channel *ch = &clip->channels[clip->channel_count++];
			ch->joint = j;
			ch->path = kind == 0 ? MLOD_PATH_TRANSLATION : MLOD_PATH_ROTATION;
			ch->interp = MLOD_INTERP_LINEAR;
			ch->key_count = (int)frames;
			ch->times = malloc(fcount * sizeof(float));
			ch->values = malloc(fcount * (kind == 0 ? 3 : 4) * sizeof(float));
			if (!ch->times || !ch->values) {
				res = mlod_fail(r->err, MLOD_ERR_NOMEM, "out of memory");
				break;
			}
			for (size_t f = 0; f < fcount; f++)
				ch->times[f] = (float)((double)f * ft);
			if (kind == 0) {
				anim[j].t = ch->times;
				anim[j].tv = ch->values;
			} else {
				anim[j].r = ch->times;
				anim[j].rv = ch->values;
			}
		}
	}

	/* One frame per line; blank lines are skipped. */
	for (long f = 0; f < frames && res == MLOD_OK; f++) {
		skip_space(&r->lx, 1);
		if (r->lx.p >= r->lx.end) {
			res = mlod_fail(r->err, MLOD_ERR_PARSE, "line %d: the file ends after %ld of %ld frames",
			                r->lx.line, f, frames);
			break;
		}
		int line = r->lx.line;
		size_t got = 0;
		for (;;) {
			if (got < (size_t)vpf) {
				double v;
				skip_space(&r->lx, 0);
				if (frame_number(&r->lx, &v)) {
					vals[got++] = (float)v;
					continue;
				}
			}
			if (lex(&r->lx, &t, 0) < 0) {
				res = fail_binary(r);
				break;
			}
			if (t.len == 0)
				break;
			if (got < (size_t)vpf) {
				double v = 0.0;
				int rc = bvh_parse_number(t.s, t.len, &v);
				if (rc != BVH_NUM_OK) {
					res = mlod_fail(r->err, MLOD_ERR_PARSE, "line %d: %s (frame %ld, value %zu) is %s", line,
					                show(&t, b), f + 1, got + 1,
					                rc == BVH_NUM_NONFINITE ? "not a finite number" :
					                rc == BVH_NUM_RANGE ? "out of range" : "not a number");
					break;
				}
				vals[got] = (float)v;
			}
			got++;
		}
		if (res != MLOD_OK)
			break;
		if (got != (size_t)vpf) {
			res = mlod_fail(r->err, MLOD_ERR_PARSE, "line %d: frame %ld has %zu values, expected %ld", line,
			                f + 1, got, vpf);
			break;
		}
		for (int j = 0; j < n; j++) {
			const mlod_joint *jt = &r->joints[j];
			if (!jt->channel_count)
				continue;
			const float *v = vals + anim[j].first;
			float pos[3] = { jt->rest.t.x, jt->rest.t.y, jt->rest.t.z };
			float ang[3] = { 0.0f, 0.0f, 0.0f };
			for (int k = 0; k < jt->channel_count; k++) {
				int code = jt->channels[k];
				if (code < MLOD_BVH_XROT)
					pos[code] = v[k];
				else
					ang[code - MLOD_BVH_XROT] = (float)(v[k] * (MLOD_PI / 180.0));
			}
			if (anim[j].tv)
				memcpy(anim[j].tv + 3 * f, pos, sizeof pos);
			if (anim[j].rv) {
				/* Normalised once more, as a glb write normalised every
				 * rotation key until it kept those unit to single
				 * precision as given (mlod_gltf_from_character): the glb
				 * a stage makes of the BVH holds these very keys, so the
				 * two reads give the same pack at any motion bound
				 * (cli/pack_bvh_stages; 84 of the walk's 16,244 keys
				 * moved by a last bit), and that glb, tubeman.glb
				 * included, is what it was. */
				mlod_quat q = mlod_quat_normalize(mlod_quat_from_euler(jt->euler, ang));
				if (f > 0) {
					const float *p = anim[j].rv + 4 * (f - 1);
					if (p[0] * q.x + p[1] * q.y + p[2] * q.z + p[3] * q.w < 0.0f) {
						q.x = -q.x;
						q.y = -q.y;
						q.z = -q.z;
						q.w = -q.w;
					}
				}
				float *d = anim[j].rv + 4 * f;
				d[0] = q.x;
				d[1] = q.y;
				d[2] = q.z;
				d[3] = q.w;
			}
		}
	}
	free(anim);
	free(vals);
	if (res != MLOD_OK)
		return res;

	/* One whole frame past the declared count (an off-by-one real files
	 * have: one of Debian's assimp test files says 3069 frames and holds
	 * 3070) is ignored with a note, as common readers do. More than one
	 * means the count is wrong, not off by one, and which of the two the
	 * writer meant is unknown: an error, as too few frames are, rather
	 * than motion dropped ('Frames: 3' over 524 rows kept 3). Anything
	 * else after the last frame is an error too. */
	skip_space(&r->lx, 1);
	if (r->lx.p < r->lx.end) {
		lexer start = r->lx;
		long values = 0;
		int first_line = 0, ok = 1;
		double v;
		for (;;) {
			TRY(next(r, &t));
			if (t.len == 0)
				break;
			if (!first_line)
				first_line = t.line;
			if (bvh_parse_number(t.s, t.len, &v) != BVH_NUM_OK) {
				ok = 0;
				break;
			}
			values++;
		}
		if (!ok || values % vpf != 0) {
			r->lx = start;
			TRY(next(r, &t));
			return mlod_fail(r->err, MLOD_ERR_PARSE, "line %d: extra data %s after the last of %ld frames",
			                 t.line, show(&t, b), frames);
		}
		if (values / vpf > 1)
			return mlod_fail(r->err, MLOD_ERR_PARSE,
			                 "line %d: 'Frames: %ld' but %ld frames follow (%ld more from line %d)", frames_line,
			                 frames, frames + values / vpf, values / vpf, first_line);
		char note[160];
		snprintf(note, sizeof note, "1 frame after the %ld that 'Frames:' announces (from line %d) ignored", frames,
		         first_line);
		c->notes = mlod_strdup(note);
		c->warnings = mlod_strdup(note);
		if (!c->notes || !c->warnings)
			return mlod_fail(r->err, MLOD_ERR_NOMEM, "out of memory");
	}
	return MLOD_OK;
}

/* The character model keeps 0, 3 or 6 channels per joint. A joint with a
 * partial layout (say "CHANNELS 2 Zrotation Xrotation") has its layout
 * completed once its motion is read: the positions and rotations it has
 * become all three, missing ones appended (positions in x, y, z order,
 * rotations in the joint's Euler order). The motion is unchanged: the
 * added positions hold the OFFSET, the added angles 0. */
static void complete_layouts(mlod_skeleton *s)
{
	for (int i = 0; i < s->joint_count; i++) {
		mlod_joint *j = &s->joints[i];
		if (j->channel_count == 0 || j->channel_count == 3 || j->channel_count == 6)
			continue;
		int pos, rot, n = 0;
		joint_kinds(j, &pos, &rot);
		unsigned char ch[6];
		if (pos) {
			int seen = 0;
			for (int k = 0; k < j->channel_count; k++)
				if (j->channels[k] < MLOD_BVH_XROT) {
					ch[n++] = j->channels[k];
					seen |= 1 << j->channels[k];
				}
			for (int a = 0; a < 3; a++)
				if (!(seen & (1 << a)))
					ch[n++] = (unsigned char)(MLOD_BVH_XPOS + a);
		}
		if (rot)
			for (int a = 0; a < 3; a++)
				ch[n++] = (unsigned char)(MLOD_BVH_XROT + mlod_euler_axes(j->euler)[a]);
		memcpy(j->channels, ch, (size_t)n);
		j->channel_count = n;
	}
}

mlod_result mlod_bvh_read(const void *data, size_t size, mlod_character *out, mlod_error *err)
{
	if (!out || (!data && size))
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_bvh_read: NULL argument");
	memset(out, 0, sizeof *out);
	reader *r = calloc(1, sizeof *r);
	if (!r)
		return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
	r->lx.p = data;
	r->lx.end = r->lx.p + size;
	r->lx.line = 1;
	r->err = err;

	mlod_character c;
	memset(&c, 0, sizeof c);
	mlod_result res = read_hierarchy(r);
	/* The joints go to the character, which owns them from now on. */
	c.skeleton.joints = r->joints;
	c.skeleton.joint_count = r->count;
	if (res == MLOD_OK)
		res = read_motion(r, &c);
	free(r);
	if (res != MLOD_OK) {
		mlod_character_free(&c);
		return res;
	}
	complete_layouts(&c.skeleton);
	*out = c;
	return MLOD_OK;
}
