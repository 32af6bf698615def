/*
 * text.c: UTF-8 well-formedness, for the writers of JSON text (the stage
 * record, glTF names, the tools' reports), which must be UTF-8 while names
 * from files and callers may be Latin-1; and names made safe to show in a
 * message or a table (mlod_name_text).
 */
#include <stdio.h>
#include <string.h>

#include "mlod_core.h"

int mlod_utf8_length(const char *s)
{
	const unsigned char *p = (const unsigned char *)s;
	const unsigned c = p[0];
	const int n = c < 0x80 ? 1 : c >= 0xc2 && c <= 0xdf ? 2 : c >= 0xe0 && c <= 0xef ? 3 : c >= 0xf0 && c <= 0xf4 ? 4 : 0;
	if (n <= 1)
		return n;
	unsigned lo = 0x80, hi = 0xbf; /* the second byte's range */
	if (c == 0xe0)
		lo = 0xa0; /* no overlong form */
	else if (c == 0xed)
		hi = 0x9f; /* no surrogate */
	else if (c == 0xf0)
		lo = 0x90; /* no overlong form */
	else if (c == 0xf4)
		hi = 0x8f; /* nothing past U+10FFFF */
	if (p[1] < lo || p[1] > hi)
		return 0;
	for (int i = 2; i < n; i++) /* a NUL fails here, so the read stops at it */
		if (p[i] < 0x80 || p[i] > 0xbf)
			return 0;
	return n;
}

/* The escape of the character at p into esc (at most 7 bytes and a NUL);
 * returns the bytes it takes from p. */
static int name_char(const unsigned char *p, int quote, char esc[8])
{
	int len = mlod_utf8_length((const char *)p);
	unsigned c = *p;
	if (len > 1) {
		memcpy(esc, p, (size_t)len);
		esc[len] = '\0';
		return len;
	}
	if (c == '\\' || (quote && c == '"'))
		snprintf(esc, 8, "\\%c", (int)c);
	else if (len == 0)
		snprintf(esc, 8, "\\x%02x", c);
	else if (c == '\n' || c == '\t' || c == '\r')
		snprintf(esc, 8, "\\%c", c == '\n' ? 'n' : c == '\t' ? 't' : 'r');
	else if (c < 0x20 || c == 0x7f)
		snprintf(esc, 8, quote ? "\\u%04x" : "\\x%02x", c);
	else
		esc[0] = (char)c, esc[1] = '\0';
	return 1;
}

const char *mlod_name_text(const char *name, int quote, char *buf, size_t size)
{
	const unsigned char *s = (const unsigned char *)(name ? name : "");
	size_t n = 0, end = quote ? 2 : 0, total = 0; /* end: the quotes */
	char esc[8];
	if (!buf || size < 16)
		return buf && size ? (buf[0] = '\0', buf) : "";
	for (const unsigned char *p = s; *p;) {
		p += name_char(p, quote, esc);
		total += strlen(esc);
	}
	/* Cut: room for "..." where it stops. */
	size_t room = size - 1 - end - (total + end + 1 > size ? 3 : 0);
	if (quote)
		buf[n++] = '"';
	for (const unsigned char *p = s; *p;) {
		p += name_char(p, quote, esc);
		size_t e = strlen(esc);
		if (n - (quote ? 1 : 0) + e > room) {
			memcpy(buf + n, "...", 3);
			n += 3;
			break;
		}
		memcpy(buf + n, esc, e);
		n += e;
	}
	if (quote)
		buf[n++] = '"';
	buf[n] = '\0';
	return buf;
}

/* The tools' tables and JSON and lib/pack's --info text (mlod_core.h). */
int mlod_name_put(FILE *f, const char *name, int json, int width)
{
	const unsigned char *p = (const unsigned char *)(name ? name : "");
	int columns = 0;
	if (json && f)
		fputc('"', f);
	while (*p) {
		char esc[8];
		const char *out = esc;
		int n = mlod_utf8_length((const char *)p), cols;
		unsigned c = *p;
		size_t len;
		if (n > 1) { /* a character, one column */
			out = (const char *)p;
			len = (size_t)n;
			cols = 1;
			p += n;
		} else {
			p++;
			if (n == 0 && json)
				snprintf(esc, sizeof esc, "\\ufffd");
			else if (c == '\\' || (json && c == '"'))
				snprintf(esc, sizeof esc, "\\%c", (int)c);
			else if (c == '\n' || c == '\t' || c == '\r')
				snprintf(esc, sizeof esc, "\\%c", c == '\n' ? 'n' : c == '\t' ? 't' : 'r');
			else if (json && c < 0x20)
				snprintf(esc, sizeof esc, "\\u%04x", c);
			else if (!json && (n == 0 || c < 0x20 || c == 0x7f))
				snprintf(esc, sizeof esc, "\\x%02x", c);
			else
				esc[0] = (char)c, esc[1] = '\0';
			len = strlen(esc);
			cols = (int)len;
		}
		if (f)
			fwrite(out, 1, len, f);
		columns += cols;
	}
	if (json && f)
		fputc('"', f);
	for (; f && columns < width; columns++)
		fputc(' ', f);
	return columns;
}

void mlod_int_list(char *buf, size_t size, const int *v, int n, int most)
{
	size_t at = strlen(buf);
	for (int i = 0; i < n && i < most && at < size; i++) {
		int k = snprintf(buf + at, size - at, "%s%d", i ? ", " : "", v[i]);
		at = k < 0 ? size : at + (size_t)k;
	}
	if (n > most && at < size)
		snprintf(buf + at, size - at, ", ...");
}

const char *mlod_next_line(const char **at, size_t *len)
{
	const char *w = *at;
	if (!w || !*w)
		return NULL;
	size_t n = strcspn(w, "\n");
	*len = n;
	*at = w + n + (w[n] == '\n');
	return w;
}
