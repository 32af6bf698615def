/* json.c: the record module's strict JSON reader and compact writer (json.h). */
#include "json.h"
#include "mlod_core.h"

#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------------------ */
/* Reading                                                             */
/* ------------------------------------------------------------------ */

struct reader {
	const char *s, *end;
	char *why;
	size_t why_size;
	int failed;
};

static int bad(struct reader *r, const char *fmt, ...)
{
	if (!r->failed) {
		va_list ap;
		va_start(ap, fmt);
		vsnprintf(r->why, r->why_size, fmt, ap);
		va_end(ap);
		r->failed = 1;
	}
	return -1;
}

static void ws(struct reader *r)
{
	while (r->s < r->end && (*r->s == ' ' || *r->s == '\t' || *r->s == '\n' || *r->s == '\r'))
		r->s++;
}

static int grow(mj *v)
{
	if (v->count < v->cap)
		return 0;
	int cap = v->cap ? 2 * v->cap : 4;
	mj *items = realloc(v->items, sizeof *items * (size_t)cap);
	if (!items)
		return -1;
	v->items = items;
	if (v->type == MJ_OBJECT) {
		char **keys = realloc(v->keys, sizeof *keys * (size_t)cap);
		if (!keys)
			return -1;
		v->keys = keys;
	}
	v->cap = cap;
	return 0;
}

static int hex4(struct reader *r, unsigned *out)
{
	unsigned u = 0;
	if (r->end - r->s < 4)
		return bad(r, "truncated \\u escape");
	for (int i = 0; i < 4; i++) {
		char c = *r->s++;
		u <<= 4;
		if (c >= '0' && c <= '9')
			u |= (unsigned)(c - '0');
		else if (c >= 'a' && c <= 'f')
			u |= (unsigned)(c - 'a' + 10);
		else if (c >= 'A' && c <= 'F')
			u |= (unsigned)(c - 'A' + 10);
		else
			return bad(r, "bad \\u escape");
	}
	*out = u;
	return 0;
}

/* Appends code point u as UTF-8. buf has room (see string()). */
static size_t utf8(char *buf, unsigned u)
{
	if (u < 0x80) {
		buf[0] = (char)u;
		return 1;
	}
	if (u < 0x800) {
		buf[0] = (char)(0xC0 | (u >> 6));
		buf[1] = (char)(0x80 | (u & 0x3F));
		return 2;
	}
	if (u < 0x10000) {
		buf[0] = (char)(0xE0 | (u >> 12));
		buf[1] = (char)(0x80 | ((u >> 6) & 0x3F));
		buf[2] = (char)(0x80 | (u & 0x3F));
		return 3;
	}
	buf[0] = (char)(0xF0 | (u >> 18));
	buf[1] = (char)(0x80 | ((u >> 12) & 0x3F));
	buf[2] = (char)(0x80 | ((u >> 6) & 0x3F));
	buf[3] = (char)(0x80 | (u & 0x3F));
	return 4;
}

/* Reads a string at its opening quote into a malloc'd UTF-8 text. Escapes
 * never make the text longer than its source, so the source length bounds
 * the buffer. */
static char *string(struct reader *r)
{
	const char *start = ++r->s;
	while (r->s < r->end && *r->s != '"') {
		if (*r->s == '\\' && r->s + 1 < r->end)
			r->s++;
		r->s++;
	}
	if (r->s >= r->end) {
		bad(r, "unterminated string");
		return NULL;
	}
	const char *stop = r->s;
	char *out = malloc((size_t)(stop - start) + 1);
	if (!out) {
		bad(r, "out of memory");
		return NULL;
	}
	size_t n = 0;
	r->s = start;
	while (r->s < stop) {
		unsigned char c = (unsigned char)*r->s;
		if (c < 0x20) {
			free(out);
			bad(r, "control character in a string");
			return NULL;
		}
		if (c != '\\') {
			out[n++] = (char)c;
			r->s++;
			continue;
		}
		r->s++;
		char e = *r->s++;
		unsigned u;
		switch (e) {
		case '"': out[n++] = '"'; break;
		case '\\': out[n++] = '\\'; break;
		case '/': out[n++] = '/'; break;
		case 'b': out[n++] = '\b'; break;
		case 'f': out[n++] = '\f'; break;
		case 'n': out[n++] = '\n'; break;
		case 'r': out[n++] = '\r'; break;
		case 't': out[n++] = '\t'; break;
		case 'u':
			if (hex4(r, &u) != 0)
				break;
			if (u >= 0xD800 && u < 0xDC00) {
				unsigned lo;
				if (stop - r->s < 6 || r->s[0] != '\\' || r->s[1] != 'u') {
					bad(r, "unpaired surrogate in a string");
					break;
				}
				r->s += 2;
				if (hex4(r, &lo) != 0)
					break;
				if (lo < 0xDC00 || lo > 0xDFFF) {
					bad(r, "unpaired surrogate in a string");
					break;
				}
				u = 0x10000 + ((u - 0xD800) << 10) + (lo - 0xDC00);
			} else if (u >= 0xDC00 && u < 0xE000) {
				bad(r, "unpaired surrogate in a string");
				break;
			} else if (u == 0) {
				bad(r, "NUL in a string");
				break;
			}
			n += utf8(out + n, u);
			break;
		default: bad(r, "bad escape '\\%c'", e >= 0x20 && e < 0x7F ? e : '?');
		}
		if (r->failed) {
			free(out);
			return NULL;
		}
	}
	out[n] = '\0';
	r->s = stop + 1;
	return out;
}

static int number(struct reader *r, mj *v)
{
	const char *p = r->s;
	if (p < r->end && *p == '-')
		p++;
	if (p >= r->end || !(*p >= '0' && *p <= '9'))
		return bad(r, "unexpected character");
	if (*p == '0')
		p++;
	else
		while (p < r->end && *p >= '0' && *p <= '9')
			p++;
	if (p < r->end && *p == '.') {
		p++;
		if (p >= r->end || !(*p >= '0' && *p <= '9'))
			return bad(r, "bad number");
		while (p < r->end && *p >= '0' && *p <= '9')
			p++;
	}
	if (p < r->end && (*p == 'e' || *p == 'E')) {
		p++;
		if (p < r->end && (*p == '+' || *p == '-'))
			p++;
		if (p >= r->end || !(*p >= '0' && *p <= '9'))
			return bad(r, "bad number");
		while (p < r->end && *p >= '0' && *p <= '9')
			p++;
	}
	size_t n = (size_t)(p - r->s);
	if (n > 400)
		return bad(r, "number too long");
	v->text = malloc(n + 1);
	if (!v->text)
		return bad(r, "out of memory");
	memcpy(v->text, r->s, n);
	v->text[n] = '\0';
	v->number = strtod(v->text, NULL);
	if (!isfinite(v->number))
		return bad(r, "number out of range");
	v->type = MJ_NUMBER;
	r->s = p;
	return 0;
}

static int value(struct reader *r, mj *v, int depth)
{
	memset(v, 0, sizeof *v);
	ws(r);
	if (r->s >= r->end)
		return bad(r, "unexpected end");
	char c = *r->s;
	if (c == '{' || c == '[') {
		if (depth >= MJ_MAX_DEPTH)
			return bad(r, "nested deeper than %d levels", MJ_MAX_DEPTH);
		char close = c == '{' ? '}' : ']';
		v->type = c == '{' ? MJ_OBJECT : MJ_ARRAY;
		r->s++;
		ws(r);
		if (r->s < r->end && *r->s == close) {
			r->s++;
			return 0;
		}
		for (;;) {
			char *key = NULL;
			ws(r);
			if (v->type == MJ_OBJECT) {
				if (r->s >= r->end || *r->s != '"')
					return bad(r, "expected a member name");
				if (!(key = string(r)))
					return -1;
				for (int i = 0; i < v->count; i++)
					if (strcmp(v->keys[i], key) == 0) {
						free(key);
						return bad(r, "duplicate member name");
					}
				ws(r);
				if (r->s >= r->end || *r->s != ':') {
					free(key);
					return bad(r, "expected ':'");
				}
				r->s++;
			}
			if (grow(v) != 0) {
				free(key);
				return bad(r, "out of memory");
			}
			if (v->type == MJ_OBJECT)
				v->keys[v->count] = key;
			int rc = value(r, &v->items[v->count], depth + 1);
			v->count++; /* freed by mj_free even when incomplete */
			if (rc != 0)
				return -1;
			ws(r);
			if (r->s < r->end && *r->s == ',') {
				r->s++;
				continue;
			}
			if (r->s < r->end && *r->s == close) {
				r->s++;
				return 0;
			}
			return bad(r, "expected ',' or '%c'", close);
		}
	}
	if (c == '"') {
		v->type = MJ_STRING;
		return (v->text = string(r)) ? 0 : -1;
	}
	static const struct {
		const char *word;
		mj_type type;
	} words[] = {{"null", MJ_NULL}, {"true", MJ_TRUE}, {"false", MJ_FALSE}};
	for (size_t i = 0; i < sizeof words / sizeof *words; i++) {
		size_t n = strlen(words[i].word);
		if ((size_t)(r->end - r->s) >= n && memcmp(r->s, words[i].word, n) == 0) {
			v->type = words[i].type;
			r->s += n;
			return 0;
		}
	}
	return number(r, v);
}

int mj_parse(const char *text, size_t size, mj *out, char *why, size_t why_size)
{
	char scratch[8];
	struct reader r = {text, text + size, why ? why : scratch, why ? why_size : sizeof scratch, 0};
	memset(out, 0, sizeof *out);
	if (!text)
		return bad(&r, "no text");
	if (size > MJ_MAX_SIZE)
		return bad(&r, "larger than %zu bytes", MJ_MAX_SIZE);
	int rc = value(&r, out, 0);
	if (rc == 0) {
		ws(&r);
		if (r.s != r.end)
			rc = bad(&r, "text after the value");
	}
	if (rc != 0) {
		if (!r.failed)
			bad(&r, "malformed");
		mj_free(out);
		memset(out, 0, sizeof *out);
		return -1;
	}
	return 0;
}

void mj_free(mj *v)
{
	if (!v)
		return;
	for (int i = 0; i < v->count; i++) {
		mj_free(&v->items[i]);
		if (v->keys)
			free(v->keys[i]);
	}
	free(v->items);
	free(v->keys);
	free(v->text);
	memset(v, 0, sizeof *v);
}

const mj *mj_get(const mj *o, const char *key)
{
	if (!o || o->type != MJ_OBJECT)
		return NULL;
	for (int i = 0; i < o->count; i++)
		if (strcmp(o->keys[i], key) == 0)
			return &o->items[i];
	return NULL;
}

/* ------------------------------------------------------------------ */
/* Building                                                            */
/* ------------------------------------------------------------------ */

mj mj_object(void)
{
	mj v = {0};
	v.type = MJ_OBJECT;
	return v;
}

mj mj_array(void)
{
	mj v = {0};
	v.type = MJ_ARRAY;
	return v;
}

mj mj_bool(int b)
{
	mj v = {0};
	v.type = b ? MJ_TRUE : MJ_FALSE;
	return v;
}

int mj_put(mj *o, const char *key, mj *v)
{
	for (int i = 0; i < o->count; i++)
		if (strcmp(o->keys[i], key) == 0) {
			mj_free(&o->items[i]);
			o->items[i] = *v;
			memset(v, 0, sizeof *v);
			return 0;
		}
	char *k = malloc(strlen(key) + 1);
	if (!k || grow(o) != 0) {
		free(k);
		mj_free(v);
		return -1;
	}
	strcpy(k, key);
	o->keys[o->count] = k;
	o->items[o->count++] = *v;
	memset(v, 0, sizeof *v);
	return 0;
}

int mj_push(mj *a, mj *v)
{
	if (grow(a) != 0) {
		mj_free(v);
		return -1;
	}
	a->items[a->count++] = *v;
	memset(v, 0, sizeof *v);
	return 0;
}

int mj_double(mj *out, const char *fmt, double v)
{
	memset(out, 0, sizeof *out);
	if (!isfinite(v))
		return 0; /* null */
	char buf[64];
	snprintf(buf, sizeof buf, fmt, v);
	out->text = malloc(strlen(buf) + 1);
	if (!out->text)
		return -1;
	strcpy(out->text, buf);
	out->type = MJ_NUMBER;
	out->number = v;
	return 0;
}

int mj_int(mj *out, long v)
{
	char buf[32];
	memset(out, 0, sizeof *out);
	snprintf(buf, sizeof buf, "%ld", v);
	out->text = malloc(strlen(buf) + 1);
	if (!out->text)
		return -1;
	strcpy(out->text, buf);
	out->type = MJ_NUMBER;
	out->number = (double)v;
	return 0;
}

int mj_string(mj *out, const char *s)
{
	memset(out, 0, sizeof *out);
	out->text = malloc(strlen(s) + 1);
	if (!out->text)
		return -1;
	strcpy(out->text, s);
	out->type = MJ_STRING;
	return 0;
}

/* ------------------------------------------------------------------ */
/* Writing                                                             */
/* ------------------------------------------------------------------ */

static void put_string(mlod_buf *o, const char *s)
{
	mlod_buf_append(o, "\"", 1);
	for (const unsigned char *p = (const unsigned char *)s; *p; p++) {
		char esc[8];
		if (*p == '"' || *p == '\\') {
			esc[0] = '\\';
			esc[1] = (char)*p;
			mlod_buf_append(o, esc, 2);
		} else if (*p == '\n' || *p == '\t' || *p == '\r' || *p == '\b' || *p == '\f') {
			esc[0] = '\\';
			esc[1] = *p == '\n' ? 'n' : *p == '\t' ? 't' : *p == '\r' ? 'r' : *p == '\b' ? 'b' : 'f';
			mlod_buf_append(o, esc, 2);
		} else if (*p < 0x20) {
			snprintf(esc, sizeof esc, "\\u%04x", *p);
			mlod_buf_append(o, esc, 6);
		} else if (*p < 0x80) {
			mlod_buf_append(o, (const char *)p, 1);
		} else { /* JSON text is UTF-8: a byte that does not start a well-formed sequence as U+FFFD */
			int n = mlod_utf8_length((const char *)p);
			if (n == 0)
				mlod_buf_append(o, "\xEF\xBF\xBD", 3);
			else
				mlod_buf_append(o, (const char *)p, (size_t)n), p += n - 1;
		}
	}
	mlod_buf_append(o, "\"", 1);
}

static void write_value(mlod_buf *o, const mj *v)
{
	switch (v->type) {
	case MJ_NULL: mlod_buf_append(o, "null", 4); break;
	case MJ_TRUE: mlod_buf_append(o, "true", 4); break;
	case MJ_FALSE: mlod_buf_append(o, "false", 5); break;
	case MJ_NUMBER: mlod_buf_append(o, v->text, strlen(v->text)); break;
	case MJ_STRING: put_string(o, v->text); break;
	case MJ_ARRAY:
	case MJ_OBJECT:
		mlod_buf_append(o, v->type == MJ_OBJECT ? "{" : "[", 1);
		for (int i = 0; i < v->count; i++) {
			if (i)
				mlod_buf_append(o, ",", 1);
			if (v->type == MJ_OBJECT) {
				put_string(o, v->keys[i]);
				mlod_buf_append(o, ":", 1);
			}
			write_value(o, &v->items[i]);
		}
		mlod_buf_append(o, v->type == MJ_OBJECT ? "}" : "]", 1);
		break;
	}
}

/* Into an mlod_buf (mlod_core.h), which ignores the writes after a failed
 * growth: checked once, at the end. */
int mj_write(const mj *v, char **text)
{
	mlod_buf o = MLOD_BUF_INIT;
	write_value(&o, v);
	return mlod_buf_take(&o, text, NULL, NULL, NULL) == MLOD_OK ? 0 : -1;
}
