/*
 * buf.c: the growable byte buffer (mlod_buf, mlod_core.h) that the BVH
 * writer, the record's JSON writer, the motion report and the pack writer
 * build their output in. The appends of a few bytes are inline in the
 * header; what grows, formats or hands over is here.
 */
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mlod_core.h"

/* The first allocation: small outputs (a record, a string table) fit it
 * whole, and larger ones double from it. */
#define BUF_FIRST 256

void mlod_buf_init(mlod_buf *b)
{
	*b = (mlod_buf)MLOD_BUF_INIT;
}

mlod_result mlod_buf_grow(mlod_buf *b, size_t extra)
{
	if (b->status != MLOD_OK)
		return b->status;
	if (extra > SIZE_MAX - 1 - b->size) /* size + extra + the NUL */
		return b->status = MLOD_ERR_NOMEM;
	size_t need = b->size + extra + 1;
	if (need <= b->cap)
		return MLOD_OK;
	size_t cap = b->cap ? b->cap : BUF_FIRST;
	while (cap < need)
		cap = cap > SIZE_MAX / 2 ? need : 2 * cap;
	unsigned char *p = realloc(b->data, cap);
	if (!p)
		return b->status = MLOD_ERR_NOMEM;
	if (!b->data)
		p[0] = 0;
	b->data = p;
	b->cap = cap;
	return MLOD_OK;
}

mlod_result mlod_buf_append_zeros(mlod_buf *b, size_t n)
{
	if (mlod_buf_reserve(b, n) != MLOD_OK)
		return b->status;
	memset(b->data + b->size, 0, n + 1); /* and the NUL */
	b->size += n;
	return MLOD_OK;
}

mlod_result mlod_buf_vprintf(mlod_buf *b, const char *fmt, va_list ap)
{
	if (b->status != MLOD_OK)
		return b->status;
	/* Formatted into the room there is; when it does not fit, once more
	 * into room made for it. */
	va_list again;
	va_copy(again, ap);
	size_t room = b->cap - b->size;
	int n = vsnprintf(room ? (char *)b->data + b->size : NULL, room, fmt, ap);
	if (n >= 0 && (size_t)n >= room && mlod_buf_reserve(b, (size_t)n) == MLOD_OK)
		n = vsnprintf((char *)b->data + b->size, b->cap - b->size, fmt, again);
	va_end(again);
	if (n < 0 && b->status == MLOD_OK) /* an encoding error */
		b->status = MLOD_ERR_INVALID_ARG;
	if (b->status != MLOD_OK) { /* the NUL back where a cut text put a byte */
		if (b->data)
			b->data[b->size] = 0;
		return b->status;
	}
	b->size += (size_t)n;
	return MLOD_OK;
}

mlod_result mlod_buf_printf(mlod_buf *b, const char *fmt, ...)
{
	va_list ap;
	va_start(ap, fmt);
	mlod_result r = mlod_buf_vprintf(b, fmt, ap);
	va_end(ap);
	return r;
}

mlod_result mlod_buf_take(mlod_buf *b, char **data, size_t *size, const char *what, mlod_error *err)
{
	mlod_result r = b->status;
	if (r == MLOD_OK)
		r = mlod_buf_reserve(b, 0); /* nothing appended: an empty text */
	*data = NULL;
	if (size)
		*size = 0;
	if (r != MLOD_OK) {
		mlod_buf_free(b);
		return mlod_fail(err, r, "%s%s%s", r == MLOD_ERR_NOMEM ? "out of memory" : "a text could not be formatted",
		                 what ? " writing " : "", what ? what : "");
	}
	*data = (char *)b->data;
	if (size)
		*size = b->size;
	*b = (mlod_buf)MLOD_BUF_INIT;
	return MLOD_OK;
}

void mlod_buf_free(mlod_buf *b)
{
	free(b->data);
	*b = (mlod_buf)MLOD_BUF_INIT;
}
