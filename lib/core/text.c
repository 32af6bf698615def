/*
 * text.c: UTF-8 well-formedness, for the writers of JSON text (the stage
 * record, glTF names, the tools' reports), which must be UTF-8 while names
 * from files and callers may be Latin-1.
 */
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
