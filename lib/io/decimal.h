/*
 * decimal.h: decimal text to double for the BVH reader, locale-independent
 * and correctly rounded: the value is the one strtod gives in the "C"
 * locale, bit for bit.
 */
#ifndef MLOD_IO_DECIMAL_H
#define MLOD_IO_DECIMAL_H

#include <stddef.h>
#include <stdint.h>

enum { MLOD_DEC_OK, MLOD_DEC_SYNTAX, MLOD_DEC_NONFINITE };

/* 10^0 .. 10^22, each exact in a double. */
extern const double mlod_decimal_pow10[23];

/* Parses a whole token: [+-] digits [. digits] [(e|E) [+-] digits], or
 * [+-] . digits ...; NaN, Inf and MSVC's 1.#INF / 1.#QNAN (any '#') give
 * MLOD_DEC_NONFINITE, anything else that is not the grammar
 * MLOD_DEC_SYNTAX. A mantissa of at most 2^53 with at most 22 decimals
 * or a power of ten up to 10^22 is one exact multiply or divide (Clinger's
 * fast path); anything else goes to strtod on the digits rewritten without
 * a decimal point (so no locale's separator is read). Values too large
 * for a double give +-HUGE_VAL (the caller checks the range). */
int mlod_decimal_parse(const char *s, size_t len, double *out);

#endif
