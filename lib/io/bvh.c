/*
 * bvh.c: reads and writes BVH (Biovision Hierarchy) motion capture text.
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
 *
 * Writing samples one clip at a uniform frame time. Each joint's BVH frame
 * is its rigid world frame: where the skeleton is rigid (unit scales) the
 * BVH local transform is the joint's local TRS itself (rest rotations and a
 * root's base are folded into the rotation channels), elsewhere it is
 * derived from the world matrices, so joint positions are reproduced even
 * under scale. A joint whose layout cannot express its motion (a translation
 * that differs from its OFFSET without position channels, a rotation about
 * an axis it has no channel for) is given the missing channels. Euler
 * angles continue across +-180 degrees from frame to frame. Positions are
 * written as the shortest decimal that reads back as the same float,
 * angles to 1e-5 degree; numbers are formatted by hand, without the
 * locale. Joint names get '_' for blanks and braces.
 */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/decimal.h"
#include "io/mlod_io.h"

#define BVH_MAX_FRAMES 10000000       /* more frames than this is absurd */
#define BVH_MAX_DEPTH 1000            /* deeper nesting than this is nonsense */
#define BVH_MAX_JOINTS (1 << 20)
#define BVH_MAX_WRITE_VALUES 200000000 /* values a written BVH may hold */

static const char *const channel_names[6] = {
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
static mlod_euler_order layout_euler(const unsigned char *ch, int n, mlod_euler_order fallback)
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
static double pow10_exact(int e)
{
	double r = 1.0;
	while (e-- > 0)
		r *= 10.0;
	return r;
}

enum { NUM_OK, NUM_SYNTAX, NUM_NONFINITE, NUM_RANGE };

/* Parses a whole token as a decimal number (mlod_decimal_parse: strtod's
 * value, without the locale); NUM_RANGE beyond the float range. */
static int parse_number(const char *s, size_t len, double *out)
{
	double v;
	switch (mlod_decimal_parse(s, len, &v)) {
	case MLOD_DEC_OK: break;
	case MLOD_DEC_NONFINITE: return NUM_NONFINITE;
	default: return NUM_SYNTAX;
	}
	if (!isfinite(v) || fabs(v) > FLT_MAX)
		return NUM_RANGE;
	*out = v;
	return NUM_OK;
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
 * goes through lex and parse_number). */
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
		if (tok_is(t, channel_names[c]))
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
	open_joint stack[BVH_MAX_DEPTH];
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
	int rc = t.len ? parse_number(t.s, t.len, out) : NUM_SYNTAX;
	switch (rc) {
	case NUM_OK:
		return MLOD_OK;
	case NUM_NONFINITE:
		return mlod_fail(r->err, MLOD_ERR_PARSE, "line %d: %s in %s is not a finite number", t.line,
		                 show(&t, b), what);
	case NUM_RANGE:
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
	if (r->depth >= BVH_MAX_DEPTH)
		return mlod_fail(r->err, MLOD_ERR_PARSE, "line %d: joints nested deeper than %d levels",
		                 r->lx.line, BVH_MAX_DEPTH);
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
			                 channel_names[c], desc);
		seen |= 1 << c;
		j->channels[i] = (unsigned char)c;
	}
	j->channel_count = n;
	j->euler = layout_euler(j->channels, n, MLOD_EULER_XYZ);
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
			if (parse_number(t.s, t.len, &v) != NUM_SYNTAX)
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
		int rc = parse_number(t.s, t.len, frame_time);
		if (rc != NUM_OK)
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
				int rc = parse_number(t.s, t.len, &v);
				if (rc != NUM_OK) {
					res = mlod_fail(r->err, MLOD_ERR_PARSE, "line %d: %s (frame %ld, value %zu) is %s", line,
					                show(&t, b), f + 1, got + 1,
					                rc == NUM_NONFINITE ? "not a finite number" :
					                rc == NUM_RANGE ? "out of range" : "not a number");
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
			if (parse_number(t.s, t.len, &v) != NUM_OK) {
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

/* ================================================================== */
/* Writer                                                              */
/* ================================================================== */

typedef struct strbuf {
	char *s;
	size_t len, cap;
	int oom;
} strbuf;

static void sb_put(strbuf *b, const char *s, size_t n)
{
	if (b->oom)
		return;
	if (b->len + n + 1 > b->cap) {
		size_t cap = b->cap ? b->cap : 4096;
		while (cap < b->len + n + 1)
			cap *= 2;
		char *p = realloc(b->s, cap);
		if (!p) {
			b->oom = 1;
			return;
		}
		b->s = p;
		b->cap = cap;
	}
	memcpy(b->s + b->len, s, n);
	b->len += n;
	b->s[b->len] = 0;
}

static void sb_puts(strbuf *b, const char *s)
{
	sb_put(b, s, strlen(s));
}

static void sb_char(strbuf *b, char c)
{
	sb_put(b, &c, 1);
}

/* Decimal digits of v into buf (no sign); returns the length. */
static size_t utoa(unsigned long long v, char *buf)
{
	char tmp[24];
	size_t n = 0;
	do {
		tmp[n++] = (char)('0' + v % 10);
		v /= 10;
	} while (v);
	for (size_t i = 0; i < n; i++)
		buf[i] = tmp[n - 1 - i];
	return n;
}

/* Formats v with at most dec decimals, trailing zeros trimmed, "-0" as
 * "0", without the C library (so without its locale). Values too large for
 * fixed notation, and tiny ones asked for many decimals, get an exponent.
 * buf holds at least 48 bytes. */
static void format_number(double v, int dec, char *buf)
{
	size_t k = 0;
	if (!isfinite(v))
		v = 0.0;
	if (dec > 18)
		dec = 18;
	while (dec > 0 && fabs(v) * pow10_exact(dec) >= 9.0e15)
		dec--;
	double a = fabs(v);
	if (a >= 9.0e15 || (a > 0.0 && a < 1e-9 && dec > 9)) {
		/* Scientific: 9 significant digits. */
		int e = (int)floor(log10(a));
		double m = a / pow(10.0, e);
		if (m >= 10.0) {
			m /= 10.0;
			e++;
		} else if (m < 1.0) {
			m *= 10.0;
			e--;
		}
		format_number(v < 0 ? -m : m, 8, buf);
		k = strlen(buf);
		buf[k++] = 'e';
		if (e < 0)
			buf[k++] = '-';
		k += utoa((unsigned long long)(e < 0 ? -e : e), buf + k);
		buf[k] = 0;
		return;
	}
	unsigned long long p = 1;
	for (int i = 0; i < dec; i++)
		p *= 10;
	unsigned long long r = (unsigned long long)(a * (double)p + 0.5);
	unsigned long long ip = r / p, fp = r % p;
	if (v < 0 && r != 0)
		buf[k++] = '-';
	k += utoa(ip, buf + k);
	if (fp) {
		buf[k++] = '.';
		for (int i = dec - 1; i >= 0; i--) {
			buf[k + (size_t)i] = (char)('0' + fp % 10);
			fp /= 10;
		}
		k += (size_t)dec;
		while (buf[k - 1] == '0')
			k--;
	}
	buf[k] = 0;
}

/* The shortest decimal that reads back as the same float. */
static void format_float_exact(float f, char *buf)
{
	double a = fabs((double)f);
	int lead = a > 0.0 ? (int)floor(log10(a)) : 0;
	for (int sig = 6; sig <= 9; sig++) {
		int dec = sig - 1 - lead;
		format_number(f, dec < 0 ? 0 : dec, buf);
		double back;
		if (parse_number(buf, strlen(buf), &back) == NUM_OK && (float)back == f)
			return;
	}
}

/* A joint's channel layout while writing. */
typedef struct layout {
	unsigned char ch[6];
	int n;
	int pos_mask, rot_mask;   /* bit a: the layout has the channel for axis a */
	mlod_euler_order euler;
	int need_pos, need_rot;   /* the motion needs the missing channels */
} layout;

static void layout_masks(layout *l)
{
	l->pos_mask = l->rot_mask = 0;
	for (int i = 0; i < l->n; i++) {
		if (l->ch[i] < MLOD_BVH_XROT)
			l->pos_mask |= 1 << l->ch[i];
		else
			l->rot_mask |= 1 << (l->ch[i] - MLOD_BVH_XROT);
	}
}

/* Gives the layout every channel its motion needs: all three positions
 * first, then the rotations in the Euler order (present ones stay). */
static void layout_complete(layout *l)
{
	layout o = *l;
	l->n = 0;
	if (o.need_pos || o.pos_mask) {
		for (int i = 0; i < o.n; i++)
			if (!o.need_pos && o.ch[i] < MLOD_BVH_XROT)
				l->ch[l->n++] = o.ch[i];
		if (o.need_pos)
			for (int a = 0; a < 3; a++)
				l->ch[l->n++] = (unsigned char)(MLOD_BVH_XPOS + a);
	}
	if (o.need_rot) {
		for (int a = 0; a < 3; a++)
			l->ch[l->n++] = (unsigned char)(MLOD_BVH_XROT + mlod_euler_axes(l->euler)[a]);
	} else {
		for (int i = 0; i < o.n; i++)
			if (o.ch[i] >= MLOD_BVH_XROT)
				l->ch[l->n++] = o.ch[i];
	}
	layout_masks(l);
}

/* The two Euler solutions of q in the layout's order: the principal one
 * and (a + pi, pi - b, c + pi). */
static void euler_solutions(const layout *l, mlod_quat q, double sol[2][3])
{
	float a[3];
	mlod_quat_to_euler(l->euler, q, a);
	const int *ax = mlod_euler_axes(l->euler);
	for (int i = 0; i < 3; i++)
		sol[0][i] = a[i];
	sol[1][ax[0]] = mlod_wrap_angle(a[ax[0]] + MLOD_PI);
	sol[1][ax[1]] = mlod_wrap_angle(MLOD_PI - a[ax[1]]);
	sol[1][ax[2]] = mlod_wrap_angle(a[ax[2]] + MLOD_PI);
}

#define ANGLE_TOL 1e-5

/* Does solution s leave the axes the layout has no channel for at 0? */
static int fits_layout(const layout *l, const double s[3])
{
	for (int a = 0; a < 3; a++)
		if (!(l->rot_mask & (1 << a)) && fabs(mlod_wrap_angle(s[a])) > ANGLE_TOL)
			return 0;
	return 1;
}

/* The Euler angles to write for q: a solution that fits the layout,
 * continued from the previous frame (each angle within 2 pi of the
 * principal value) so that players interpolating angles do not spin. */
static void euler_pick(const layout *l, mlod_quat q, const double *prev, double out[3])
{
	double sol[2][3], best = HUGE_VAL;
	euler_solutions(l, q, sol);
	/* With a partial layout only solutions that fit it are candidates
	 * (both when neither fits, which pass 1 has ruled out). */
	int fit[2] = { 1, 1 };
	if (l->rot_mask != 7) {
		fit[0] = fits_layout(l, sol[0]);
		fit[1] = fits_layout(l, sol[1]);
		if (!fit[0] && !fit[1])
			fit[0] = fit[1] = 1;
	}
	memcpy(out, sol[0], sizeof sol[0]);
	for (int s = 0; s < 2; s++) {
		if (!fit[s])
			continue;
		double cand[3], cost = 0.0;
		for (int a = 0; a < 3; a++) {
			cand[a] = sol[s][a];
			if (!prev)
				continue;
			/* The 2 pi turn of the angle nearest to the previous frame. */
			double bestd = HUGE_VAL;
			for (int k = -1; k <= 1; k++) {
				double x = sol[s][a] + k * 2.0 * MLOD_PI, dd = fabs(x - prev[a]);
				if (dd < bestd) {
					bestd = dd;
					cand[a] = x;
				}
			}
			cost += bestd * bestd;
		}
		if (cost < best) {
			best = cost;
			memcpy(out, cand, sizeof cand);
		}
	}
	for (int a = 0; a < 3; a++)
		if (!(l->rot_mask & (1 << a)))
			out[a] = 0.0;
}

/* The writer's state: the layouts and rest values, and one posed frame. */
typedef struct writer {
	const mlod_character *c;
	const mlod_clip *clip;
	int n;
	double ft;           /* seconds per frame */
	long frames;
	layout *lay;
	mlod_v3 *offset;     /* BVH OFFSETs */
	mlod_v3 *end;        /* End Site OFFSETs */
	double pos_tol;      /* a translation this far from its OFFSET needs channels */
	int *base_rigid;     /* roots: base is a rigid transform */
	mlod_quat *base_q;   /* roots: rotation of the base */
	/* The current pose. */
	mlod_trs *local;
	mlod_mat4 *world;
	int *rigid;          /* the joint's world transform is rigid (unit scales above and at it) */
	int *have_frame;     /* fw_q / fw_p computed for this pose */
	mlod_quat *fw_q;     /* rotation of the world matrix */
	mlod_v3 *fw_p;       /* position of the world matrix */
	mlod_v3 *t;          /* BVH local translation */
	mlod_quat *q;        /* BVH local rotation */
	/* Output. */
	int *order;          /* joints in file order (depth first) */
	double *prev;        /* last frame's Euler angles, 3 per joint */
	strbuf b;
} writer;

static int unit_scale(mlod_v3 s)
{
	return fabsf(s.x - 1.0f) <= 1e-6f && fabsf(s.y - 1.0f) <= 1e-6f && fabsf(s.z - 1.0f) <= 1e-6f;
}

static int finite_v3(mlod_v3 v)
{
	return isfinite(v.x) && isfinite(v.y) && isfinite(v.z);
}

/* The rigid frame (rotation, position) of joint j's world matrix. */
static void world_frame(writer *w, int j)
{
	if (w->have_frame[j])
		return;
	mlod_trs trs;
	const mlod_mat4 *m = &w->world[j];
	if (mlod_mat4_to_trs(m, &trs, 1e-4f) < 0) {
		/* Singular: keep the parent's orientation. */
		int p = w->c->skeleton.joints[j].parent;
		if (p >= 0) {
			world_frame(w, p);
			trs.r = w->fw_q[p];
		} else {
			trs.r = mlod_quat_identity();
		}
	}
	w->fw_q[j] = mlod_quat_normalize(trs.r);
	w->fw_p[j].x = m->m[12];
	w->fw_p[j].y = m->m[13];
	w->fw_p[j].z = m->m[14];
	w->have_frame[j] = 1;
}

/* Computes the BVH local transforms (w->t, w->q) of the pose in w->local.
 * A joint's BVH frame is the rigid part of its world transform. */
static void bvh_locals(writer *w)
{
	const mlod_skeleton *s = &w->c->skeleton;
	mlod_pose_world(s, w->local, w->world);
	memset(w->have_frame, 0, (size_t)w->n * sizeof *w->have_frame);
	for (int j = 0; j < w->n; j++) {
		const mlod_joint *jt = &s->joints[j];
		const mlod_trs *l = &w->local[j];
		int p = jt->parent;
		int parent_rigid = p < 0 ? w->base_rigid[j] : w->rigid[p];
		w->rigid[j] = parent_rigid && unit_scale(l->s);
		if (parent_rigid && p >= 0) {
			/* The BVH frame of the parent is its world frame. */
			w->t[j] = l->t;
			w->q[j] = l->r;
		} else if (parent_rigid) {
			/* A root below a rigid base: fold the base in. */
			w->t[j] = mlod_mat4_point(&jt->base, l->t);
			w->q[j] = mlod_quat_mul(w->base_q[j], l->r);
		} else {
			/* Scale above: go through the world matrices. */
			world_frame(w, j);
			mlod_quat pq = mlod_quat_identity();
			mlod_v3 pp = { 0.0f, 0.0f, 0.0f };
			if (p >= 0) {
				world_frame(w, p);
				pq = w->fw_q[p];
				pp = w->fw_p[p];
			}
			mlod_quat inv = mlod_quat_conjugate(pq);
			w->t[j] = mlod_quat_rotate(inv, mlod_v3_sub(w->fw_p[j], pp));
			w->q[j] = mlod_quat_mul(inv, w->fw_q[j]);
		}
		w->q[j] = mlod_quat_normalize(w->q[j]);
	}
}

/* Poses frame f (or the rest pose when f < 0) and computes its BVH locals. */
static void pose_frame(writer *w, long f)
{
	mlod_pose_rest(&w->c->skeleton, w->local);
	if (f >= 0 && w->clip)
		mlod_clip_sample(w->clip, (float)((double)f * w->ft), w->local);
	bvh_locals(w);
}

static int writer_alloc(writer *w)
{
	size_t n = (size_t)w->n;
	w->lay = calloc(n, sizeof *w->lay);
	w->offset = malloc(n * sizeof *w->offset);
	w->end = malloc(n * sizeof *w->end);
	w->base_rigid = calloc(n, sizeof *w->base_rigid);
	w->base_q = malloc(n * sizeof *w->base_q);
	w->local = malloc(n * sizeof *w->local);
	w->world = malloc(n * sizeof *w->world);
	w->rigid = malloc(n * sizeof *w->rigid);
	w->have_frame = malloc(n * sizeof *w->have_frame);
	w->fw_q = malloc(n * sizeof *w->fw_q);
	w->fw_p = malloc(n * sizeof *w->fw_p);
	w->t = malloc(n * sizeof *w->t);
	w->q = malloc(n * sizeof *w->q);
	w->order = malloc(n * sizeof *w->order);
	w->prev = malloc(n * 3 * sizeof *w->prev);
	return w->lay && w->offset && w->end && w->base_rigid && w->base_q && w->local && w->world && w->rigid &&
	       w->have_frame && w->fw_q && w->fw_p && w->t && w->q && w->order && w->prev;
}

static void writer_free(writer *w)
{
	free(w->lay);
	free(w->offset);
	free(w->end);
	free(w->base_rigid);
	free(w->base_q);
	free(w->local);
	free(w->world);
	free(w->rigid);
	free(w->have_frame);
	free(w->fw_q);
	free(w->fw_p);
	free(w->t);
	free(w->q);
	free(w->order);
	free(w->prev);
	free(w->b.s);
}

/* Each joint's layout as the character gives it (or the default), and the
 * bases of roots. */
static mlod_result writer_layouts(writer *w, mlod_error *err)
{
	static const unsigned char root6[6] = { MLOD_BVH_XPOS, MLOD_BVH_YPOS, MLOD_BVH_ZPOS,
	                                        MLOD_BVH_ZROT, MLOD_BVH_XROT, MLOD_BVH_YROT };
	for (int j = 0; j < w->n; j++) {
		const mlod_joint *jt = &w->c->skeleton.joints[j];
		layout *l = &w->lay[j];
		if (jt->channel_count < 0 || jt->channel_count > 6)
			return mlod_fail(err, MLOD_ERR_INVALID_ARG, "joint '%s' has %d BVH channels", jt->name,
			                 jt->channel_count);
		if (jt->channel_count > 0) {
			int seen = 0;
			for (int k = 0; k < jt->channel_count; k++) {
				int code = jt->channels[k];
				if (code > MLOD_BVH_ZROT || (seen & (1 << code)))
					return mlod_fail(err, MLOD_ERR_INVALID_ARG, "joint '%s' has an invalid BVH channel layout",
					                 jt->name);
				seen |= 1 << code;
				l->ch[l->n++] = (unsigned char)code;
			}
			mlod_euler_order fb = (int)jt->euler >= 0 && (int)jt->euler < 6 ? jt->euler : MLOD_EULER_ZXY;
			l->euler = layout_euler(l->ch, l->n, fb);
		} else {
			/* No layout: positions and ZXY on roots, ZXY elsewhere. */
			l->n = jt->parent < 0 ? 6 : 3;
			memcpy(l->ch, jt->parent < 0 ? root6 : root6 + 3, (size_t)l->n);
			l->euler = MLOD_EULER_ZXY;
		}
		layout_masks(l);
		w->base_q[j] = mlod_quat_identity();
		if (jt->parent < 0) {
			mlod_trs bt;
			if (mlod_mat4_to_trs(&jt->base, &bt, 1e-5f) == 0 && unit_scale(bt.s)) {
				w->base_rigid[j] = 1;
				w->base_q[j] = mlod_quat_normalize(bt.r);
			}
		}
	}
	return MLOD_OK;
}

/* The rest pose gives the OFFSETs, the End Sites and the skeleton's extent. */
static mlod_result writer_rest(writer *w, mlod_error *err)
{
	pose_frame(w, -1);
	for (int j = 0; j < w->n; j++) {
		const mlod_joint *jt = &w->c->skeleton.joints[j];
		w->offset[j] = w->t[j];
		w->end[j] = jt->end_site;
		if (jt->has_end_site && !w->rigid[j]) {
			/* Scaled: the End Site's place in the joint's rigid frame. */
			world_frame(w, j);
			mlod_v3 e = mlod_mat4_point(&w->world[j], jt->end_site);
			w->end[j] = mlod_quat_rotate(mlod_quat_conjugate(w->fw_q[j]), mlod_v3_sub(e, w->fw_p[j]));
		}
		if (!finite_v3(w->offset[j]) || !finite_v3(w->end[j]))
			return mlod_fail(err, MLOD_ERR_INVALID_ARG, "joint '%s' has a non-finite rest transform", jt->name);
	}
	/* A numeric tolerance: the largest extent, not the height. */
	double extent = mlod_skeleton_extent(&w->c->skeleton);
	if (!(extent > 0.0) || !isfinite(extent))
		extent = 1.0;
	w->pos_tol = 1e-6 * extent;
	return MLOD_OK;
}

/* Pass 1 over the frames: a joint whose translation leaves its OFFSET on
 * an axis it has no position channel for, or that turns about an axis it
 * has no rotation channel for, gets the missing channels. */
static mlod_result writer_widen(writer *w, mlod_error *err)
{
	for (long f = 0; f < w->frames; f++) {
		pose_frame(w, f);
		for (int j = 0; j < w->n; j++) {
			layout *l = &w->lay[j];
			mlod_quat q = w->q[j];
			if (!finite_v3(w->t[j]) || !isfinite(q.x) || !isfinite(q.y) || !isfinite(q.z) || !isfinite(q.w))
				return mlod_fail(err, MLOD_ERR_INVALID_ARG, "joint '%s' has a non-finite transform in frame %ld",
				                 w->c->skeleton.joints[j].name, f + 1);
			float d[3] = { w->t[j].x - w->offset[j].x, w->t[j].y - w->offset[j].y, w->t[j].z - w->offset[j].z };
			for (int a = 0; a < 3; a++)
				if (!(l->pos_mask & (1 << a)) && fabs(d[a]) > w->pos_tol)
					l->need_pos = 1;
			if (l->rot_mask != 7 && !l->need_rot) {
				double sol[2][3];
				euler_solutions(l, q, sol);
				if (!fits_layout(l, sol[0]) && !fits_layout(l, sol[1]))
					l->need_rot = 1;
			}
		}
	}
	for (int j = 0; j < w->n; j++)
		if (w->lay[j].need_pos || w->lay[j].need_rot)
			layout_complete(&w->lay[j]);
	return MLOD_OK;
}

/* A joint name safe for BVH: no blanks, braces or control bytes. */
static void put_name(strbuf *b, const char *name, int index)
{
	if (!name || !*name) {
		char num[24];
		num[utoa((unsigned long long)index, num)] = 0;
		sb_puts(b, "joint");
		sb_puts(b, num);
		return;
	}
	for (const char *p = name; *p; p++) {
		unsigned char c = (unsigned char)*p;
		sb_char(b, c <= 0x20 || c == 0x7f || c == '{' || c == '}' ? '_' : (char)c);
	}
}

static void put_indent(strbuf *b, int depth)
{
	for (int i = 0; i < depth && i < 64; i++)
		sb_char(b, '\t');
}

static void put_offset(strbuf *b, int depth, mlod_v3 v)
{
	char num[64];
	float c[3] = { v.x, v.y, v.z };
	put_indent(b, depth);
	sb_puts(b, "OFFSET");
	for (int i = 0; i < 3; i++) {
		format_float_exact(c[i], num);
		sb_char(b, ' ');
		sb_puts(b, num);
	}
	sb_char(b, '\n');
}

/* Opens joint j at the given depth: name, brace, OFFSET, CHANNELS. */
static void put_joint_head(writer *w, int j, int depth)
{
	const mlod_joint *jt = &w->c->skeleton.joints[j];
	const layout *l = &w->lay[j];
	strbuf *b = &w->b;
	put_indent(b, depth);
	sb_puts(b, jt->parent < 0 ? "ROOT " : "JOINT ");
	put_name(b, jt->name, j);
	sb_char(b, '\n');
	put_indent(b, depth);
	sb_puts(b, "{\n");
	put_offset(b, depth + 1, w->offset[j]);
	put_indent(b, depth + 1);
	sb_puts(b, "CHANNELS ");
	sb_char(b, (char)('0' + l->n));
	for (int k = 0; k < l->n; k++) {
		sb_char(b, ' ');
		sb_puts(b, channel_names[l->ch[k]]);
	}
	sb_char(b, '\n');
}

/* Closes joint j: its End Site, then the brace. */
static void put_joint_tail(writer *w, int j, int depth)
{
	strbuf *b = &w->b;
	if (w->c->skeleton.joints[j].has_end_site) {
		put_indent(b, depth + 1);
		sb_puts(b, "End Site\n");
		put_indent(b, depth + 1);
		sb_puts(b, "{\n");
		put_offset(b, depth + 2, w->end[j]);
		put_indent(b, depth + 1);
		sb_puts(b, "}\n");
	}
	put_indent(b, depth);
	sb_puts(b, "}\n");
}

/* The HIERARCHY, depth first without recursion; fills w->order. */
static mlod_result write_hierarchy(writer *w, mlod_error *err)
{
	const mlod_skeleton *s = &w->c->skeleton;
	size_t n = (size_t)w->n;
	int *first_child = malloc(n * sizeof(int)), *next_sib = malloc(n * sizeof(int));
	int *stack = malloc(n * sizeof(int)), *cursor = malloc(n * sizeof(int));
	if (!first_child || !next_sib || !stack || !cursor) {
		free(first_child);
		free(next_sib);
		free(stack);
		free(cursor);
		return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
	}
	/* Children lists in index order. */
	for (int j = 0; j < w->n; j++)
		first_child[j] = next_sib[j] = -1;
	for (int j = w->n - 1; j >= 0; j--) {
		int p = s->joints[j].parent;
		if (p >= 0) {
			next_sib[j] = first_child[p];
			first_child[p] = j;
		}
	}
	sb_puts(&w->b, "HIERARCHY\n");
	int count = 0;
	for (int root = 0; root < w->n; root++) {
		if (s->joints[root].parent >= 0)
			continue;
		int depth = 1;
		stack[0] = root;
		w->order[count++] = root;
		put_joint_head(w, root, 0);
		cursor[root] = first_child[root];
		while (depth > 0) {
			int j = stack[depth - 1];
			if (cursor[j] >= 0) {
				int ch = cursor[j];
				cursor[j] = next_sib[ch];
				w->order[count++] = ch;
				put_joint_head(w, ch, depth);
				cursor[ch] = first_child[ch];
				stack[depth++] = ch;
			} else {
				depth--;
				put_joint_tail(w, j, depth);
			}
		}
	}
	free(first_child);
	free(next_sib);
	free(stack);
	free(cursor);
	return MLOD_OK;
}

/* Pass 2 over the frames: the MOTION. Positions are written as the
 * shortest decimal of their float, angles to 1e-5 degree (2e-7 radian). */
static void write_motion(writer *w)
{
	strbuf *b = &w->b;
	char num[64];
	sb_puts(b, "MOTION\nFrames: ");
	num[utoa((unsigned long long)w->frames, num)] = 0;
	sb_puts(b, num);
	sb_puts(b, "\nFrame Time: ");
	format_float_exact((float)w->ft, num);
	sb_puts(b, num);
	sb_char(b, '\n');
	for (long f = 0; f < w->frames && !b->oom; f++) {
		pose_frame(w, f);
		int sep = 0;
		for (int i = 0; i < w->n; i++) {
			int j = w->order[i];
			const layout *l = &w->lay[j];
			double ang[3] = { 0.0, 0.0, 0.0 };
			if (l->rot_mask) {
				euler_pick(l, w->q[j], f > 0 ? w->prev + 3 * j : NULL, ang);
				memcpy(w->prev + 3 * j, ang, sizeof ang);
			}
			float pos[3] = { w->t[j].x, w->t[j].y, w->t[j].z };
			for (int k = 0; k < l->n; k++) {
				int code = l->ch[k];
				if (code < MLOD_BVH_XROT)
					format_float_exact(pos[code], num);
				else
					format_number(ang[code - MLOD_BVH_XROT] * (180.0 / MLOD_PI), 5, num);
				if (sep)
					sb_char(b, ' ');
				sep = 1;
				sb_puts(b, num);
			}
		}
		sb_char(b, '\n');
	}
}

mlod_result mlod_bvh_write(const mlod_character *c, int clip, float frame_time, char **text, size_t *size,
                           mlod_error *err)
{
	if (text)
		*text = NULL;
	if (size)
		*size = 0;
	if (!c || !text)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_bvh_write: NULL argument");
	const mlod_skeleton *s = &c->skeleton;
	int n = s->joint_count;
	if (n <= 0 || !s->joints)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "the character has no joints to write as BVH");
	for (int j = 0; j < n; j++)
		if (s->joints[j].parent < -1 || s->joints[j].parent >= j)
			return mlod_fail(err, MLOD_ERR_INVALID_ARG, "joint %d: its parent %d does not come before it", j,
			                 s->joints[j].parent);
	if (!(frame_time >= 0.0f) || !isfinite(frame_time))
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "frame time %g must be positive (or 0 for the clip's own)",
		                 (double)frame_time);

	/* The clip; a character without clips (or clip < 0) gives the rest pose. */
	const mlod_clip *cl = NULL;
	if (clip >= 0 && clip < c->clip_count)
		cl = &c->clips[clip];
	else if (clip >= 0 && !(clip == 0 && c->clip_count == 0))
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "no clip %d (the character has %d)", clip, c->clip_count);

	/* Frames at ft from 0 until the frame that reaches the clip's end. */
	double ft = frame_time > 0.0f ? frame_time : cl && cl->frame_time > 0.0f ? cl->frame_time : 1.0 / 30.0;
	long frames = 1;
	if (cl && frame_time == 0.0f && cl->frame_time > 0.0f && cl->frame_count > 0) {
		frames = cl->frame_count;
	} else if (cl && cl->duration > 0.0f) {
		double f = ceil((double)cl->duration / ft - 1e-3) + 1.0;
		if (!(f <= BVH_MAX_FRAMES))
			return mlod_fail(err, MLOD_ERR_NOMEM, "clip '%s' at %g s per frame needs more than %d frames",
			                 cl->name ? cl->name : "", ft, BVH_MAX_FRAMES);
		frames = (long)f;
	}
	if (frames > BVH_MAX_FRAMES || (double)frames * n * 6 > BVH_MAX_WRITE_VALUES)
		return mlod_fail(err, MLOD_ERR_NOMEM, "%ld frames of %d joints is too much motion for one BVH file",
		                 frames, n);

	writer w;
	memset(&w, 0, sizeof w);
	w.c = c;
	w.clip = cl;
	w.n = n;
	w.ft = ft;
	w.frames = frames;
	mlod_result res = MLOD_OK;
	if (!writer_alloc(&w))
		res = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
	if (res == MLOD_OK)
		res = writer_layouts(&w, err);
	if (res == MLOD_OK)
		res = writer_rest(&w, err);
	if (res == MLOD_OK)
		res = writer_widen(&w, err);
	if (res == MLOD_OK)
		res = write_hierarchy(&w, err);
	if (res == MLOD_OK)
		write_motion(&w);
	if (res == MLOD_OK && w.b.oom)
		res = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory writing BVH");
	if (res == MLOD_OK) {
		*text = w.b.s;
		if (size)
			*size = w.b.len;
		w.b.s = NULL;
	}
	writer_free(&w);
	return res;
}
