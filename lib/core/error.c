/* error.c: result codes and their messages. */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

#include "mlod_core.h"

const char *mlod_strerror(mlod_result code)
{
	switch (code) {
	case MLOD_OK: return "success";
	case MLOD_ERR_INVALID_ARG: return "invalid argument";
	case MLOD_ERR_IO: return "input/output error";
	case MLOD_ERR_PARSE: return "malformed input";
	case MLOD_ERR_UNSUPPORTED: return "unsupported feature";
	case MLOD_ERR_NOMEM: return "out of memory or absurd size";
	case MLOD_ERR_LIMIT: return "limit cannot be met";
	}
	return "unknown error";
}

mlod_result mlod_fail(mlod_error *err, mlod_result code, const char *fmt, ...)
{
	if (err) {
		va_list ap;
		va_start(ap, fmt);
		err->code = code;
		vsnprintf(err->message, sizeof err->message, fmt, ap);
		va_end(ap);
	}
	return code;
}

void mlod_free(void *p)
{
	free(p);
}
