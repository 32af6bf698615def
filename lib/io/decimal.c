/*
 * decimal.c: decimal text to double, correctly rounded and without the
 * locale (decimal.h).
 */
#include <errno.h>
#include <stdlib.h>

#include "io/decimal.h"

const double mlod_decimal_pow10[23] = {
	1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
	1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
};

/* Significant digits given to strtod: every decimal midpoint between two
 * doubles has at most 768, so a longer run cut here and ended by a nonzero
 * digit when anything nonzero was cut rounds as the whole run does. */
#define KEEP_DIGITS 800

static int lower(int c)
{
	return c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c;
}

static int is_digit(int c)
{
	return c >= '0' && c <= '9';
}

int mlod_decimal_parse(const char *s, size_t len, double *out)
{
	size_t i = 0;
	int neg = 0;
	if (i < len && (s[i] == '+' || s[i] == '-'))
		neg = s[i++] == '-';
	if (len - i >= 3) {
		int a = lower((unsigned char)s[i]), b = lower((unsigned char)s[i + 1]), c = lower((unsigned char)s[i + 2]);
		if ((a == 'n' && b == 'a' && c == 'n') || (a == 'i' && b == 'n' && c == 'f'))
			return MLOD_DEC_NONFINITE;
	}
	for (size_t k = i; k < len; k++)
		if (s[k] == '#')
			return MLOD_DEC_NONFINITE;

	/* The digits: [i0, i1) before the point, [f0, f1) after it. */
	size_t i0 = i;
	while (i < len && is_digit(s[i]))
		i++;
	size_t i1 = i, f0 = i, f1 = i;
	if (i < len && s[i] == '.') {
		f0 = f1 = ++i;
		while (i < len && is_digit(s[i]))
			i++;
		f1 = i;
	}
	if (i1 == i0 && f1 == f0)
		return MLOD_DEC_SYNTAX;
	/* The exponent saturates at cap: the value, at least 10^(e - len) and
	 * below 10^(e + len), is then already beyond every double (infinite
	 * or zero) at e = cap and at any larger e, as strtod makes it. */
	const int64_t cap = (int64_t)(len < ((size_t)1 << 40) ? len : ((size_t)1 << 40)) + 400;
	int64_t e = 0;
	if (i < len && (s[i] == 'e' || s[i] == 'E')) {
		i++;
		int eneg = 0;
		if (i < len && (s[i] == '+' || s[i] == '-'))
			eneg = s[i++] == '-';
		if (i >= len || !is_digit(s[i]))
			return MLOD_DEC_SYNTAX;
		while (i < len && is_digit(s[i])) {
			e = e >= cap ? cap : e * 10 + (s[i] - '0');
			i++;
		}
		if (eneg)
			e = -e;
	}
	if (i != len)
		return MLOD_DEC_SYNTAX;

	/* value = (all the digits as one integer) * 10^exp10 */
	int64_t exp10 = e - (int64_t)(f1 - f0);
	/* The significant digits: from the first nonzero one. */
	size_t n = (i1 - i0) + (f1 - f0), first = 0;
#define DIGIT(k) (s[(k) < i1 - i0 ? i0 + (k) : f0 + ((k) - (i1 - i0))])
	while (first < n && DIGIT(first) == '0')
		first++;
	size_t nsig = n - first;
	double v;
	if (nsig == 0) {
		v = 0.0;
	} else {
		uint64_t mant = 0;
		if (nsig <= 19)
			for (size_t k = first; k < n; k++)
				mant = mant * 10 + (uint64_t)(DIGIT(k) - '0');
		if (nsig <= 19 && mant <= (uint64_t)1 << 53 && exp10 >= -22 && exp10 <= 22) {
			/* Clinger's fast path: both operands exact, one rounding. */
			v = (double)mant;
			if (exp10 >= 0)
				v *= mlod_decimal_pow10[exp10];
			else
				v /= mlod_decimal_pow10[-exp10];
		} else {
			/* strtod on "DIGITSeEXP": no decimal point, so no locale. */
			char buf[KEEP_DIGITS + 32];
			size_t k = 0, keep = nsig > KEEP_DIGITS ? KEEP_DIGITS : nsig;
			for (size_t d = 0; d < keep; d++)
				buf[k++] = DIGIT(first + d);
			int64_t x = exp10 + (int64_t)(nsig - keep);
			if (keep < nsig) {
				for (size_t d = first + keep; d < n; d++)
					if (DIGIT(d) != '0') {
						buf[k++] = '1'; /* sticky: something nonzero was cut */
						x--;
						break;
					}
			}
			buf[k++] = 'e';
			if (x < 0)
				buf[k++] = '-';
			uint64_t ux = x < 0 ? (uint64_t)0 - (uint64_t)x : (uint64_t)x;
			char tmp[24];
			size_t t = 0;
			do {
				tmp[t++] = (char)('0' + ux % 10);
				ux /= 10;
			} while (ux);
			while (t)
				buf[k++] = tmp[--t];
			buf[k] = 0;
			int saved = errno;
			v = strtod(buf, NULL);
			errno = saved;
		}
	}
#undef DIGIT
	*out = neg ? -v : v;
	return MLOD_DEC_OK;
}
