/* test_bvh_number.c: the BVH reader's numbers (lib/io/decimal.c and the
 * frame lines' one-scan path in bvhread.c) against strtod in the C locale. */
#include "test.h"

#include <stdint.h>

#include "io/decimal.h"

static uint64_t rng = 0x9E3779B97F4A7C15ull;

static unsigned rnd(unsigned n)
{
	rng ^= rng << 13;
	rng ^= rng >> 7;
	rng ^= rng << 17;
	return (unsigned)((rng >> 11) % n);
}

/* A decimal of the reader's grammar: sign, integer digits (leading zeros
 * now and then), decimals, an exponent; digits up to maxd in each part,
 * exponents within +-maxe. */
static void gen(char *b, int maxd, int maxe)
{
	size_t k = 0;
	unsigned s = rnd(4);
	if (s == 1)
		b[k++] = '-';
	else if (s == 2)
		b[k++] = '+';
	int ni = (int)rnd((unsigned)maxd + 1), nf = rnd(4) ? (int)rnd((unsigned)maxd + 1) : 0;
	if (ni == 0 && nf == 0)
		ni = 1;
	int zeros = rnd(5) == 0 ? (int)rnd(4) : 0;
	for (int i = 0; i < ni; i++)
		b[k++] = (char)(i < zeros ? '0' : '0' + rnd(10));
	if (nf || rnd(8) == 0) {
		b[k++] = '.';
		for (int i = 0; i < nf; i++)
			b[k++] = (char)('0' + (rnd(6) == 0 ? 0 : rnd(10)));
	}
	if (maxe > 0 && rnd(3) == 0) {
		b[k++] = rnd(2) ? 'e' : 'E';
		unsigned es = rnd(3);
		if (es == 1)
			b[k++] = '-';
		else if (es == 2)
			b[k++] = '+';
		k += (size_t)sprintf(b + k, "%u", rnd((unsigned)maxe + 1));
	}
	b[k] = 0;
}

static int same_bits(double a, double b)
{
	return memcmp(&a, &b, sizeof a) == 0;
}

/* Parses s both ways; 1 when the doubles are the same bits. */
static int agrees(const char *s, double *got, double *want)
{
	*want = strtod(s, NULL);
	*got = -12345.0;
	return mlod_decimal_parse(s, strlen(s), got) == MLOD_DEC_OK && same_bits(*got, *want);
}

TEST(edge_cases)
{
	static char big[4096];
	const char *fixed[] = {
		"0", "-0", "+0", "-0.0", "0e0", "-0e-999", ".5", "5.", "-.125", "00000000000000000000000001",
		"0.000000000000000000000000000000000000000001", "9007199254740992", "9007199254740993",
		"9007199254740994", "9007199254740995", "9007199254740993.0000000001", "18014398509481985",
		"1e22", "1e23", "-1e-22", "1e-23", "123456789012345678901234567890", "0.1", "0.2", "0.3",
		"3.141592653589793238462643383279", "2.2250738585072011e-308", "2.2250738585072012e-308",
		"4.9406564584124654e-324", "2.4703282292062327e-324", "2.4703282292062328e-324",
		"1.7976931348623157e308", "1.7976931348623158e308", "1.7976931348623159e308", "1e-400", "1e400",
		"-1e400", "1e999999", "1e-999999", "0.1e-99999999", "340282346638528859811704183484516925440",
		"3.4028235677973366e38", "1.40129846e-45", "7.0064923216240854e-46", "12.5e-1", "1E+2", "1e+0",
	};
	for (size_t i = 0; i < sizeof fixed / sizeof fixed[0]; i++) {
		double got, want;
		CHECK_MSG(agrees(fixed[i], &got, &want), "%s: %.17g, strtod %.17g", fixed[i], got, want);
	}
	/* 2^53 + 1 is halfway: what lies past the 800 digits given to strtod
	 * decides it. */
	for (int tail = 0; tail < 2; tail++) {
		size_t k = (size_t)sprintf(big, "9007199254740993.");
		for (int i = 0; i < 1200; i++)
			big[k++] = '0';
		big[k++] = tail ? '1' : '0';
		big[k] = 0;
		double got, want;
		CHECK_MSG(agrees(big, &got, &want), "2^53+1 and a tail %d: %.17g, strtod %.17g", tail, got, want);
		CHECK(got == (tail ? 9007199254740994.0 : 9007199254740992.0));
	}
	/* Long runs of digits around the exponent's range. */
	for (int n = 700; n < 900; n += 7) {
		size_t k = 0;
		for (int i = 0; i < n; i++)
			big[k++] = (char)('1' + (i * 7) % 9);
		k += (size_t)sprintf(big + k, "e-%d", n + 300);
		big[k] = 0;
		double got, want;
		CHECK_MSG(agrees(big, &got, &want), "%d digits: %.17g, strtod %.17g", n, got, want);
	}
	/* Tokens of about a million digits whose exponent makes up for them
	 * (the exponent once saturated at 999,999 before the digits were
	 * counted: 0 and inf came back for 10000 and 1). */
	{
		const size_t zeros = 1100000;
		char *huge = malloc(zeros + 64);
		CHECK(huge != NULL);
		for (int form = 0; huge && form < 4; form++) {
			size_t k = 0;
			if (form == 0 || form == 2)
				k += (size_t)sprintf(huge, "0.");
			else
				huge[k++] = '1';
			memset(huge + k, '0', zeros);
			k += zeros;
			if (form == 0)
				k += (size_t)sprintf(huge + k, "1e1100005");
			else if (form == 1)
				k += (size_t)sprintf(huge + k, "e-1100000");
			else if (form == 2)
				k += (size_t)sprintf(huge + k, "1e1100400");
			else
				k += (size_t)sprintf(huge + k, "e-1100400");
			huge[k] = 0;
			double got, want;
			CHECK_MSG(agrees(huge, &got, &want), "form %d, %zu digits: %.17g, strtod %.17g", form, zeros, got, want);
		}
		free(huge);
	}
	/* Not numbers. */
	const char *bad[] = { "", "+", "-", ".", "-.", "e5", "1e", "1e+", "1.2.3", "1x", "--1", "1 ", " 1", "0x10" };
	for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
		double v;
		CHECK_MSG(mlod_decimal_parse(bad[i], strlen(bad[i]), &v) == MLOD_DEC_SYNTAX, "'%s' accepted", bad[i]);
	}
	const char *nonfinite[] = { "nan", "-NaN", "inf", "+Infinity", "1.#INF", "-1.#QNAN", "1#" };
	for (size_t i = 0; i < sizeof nonfinite / sizeof nonfinite[0]; i++) {
		double v;
		CHECK_MSG(mlod_decimal_parse(nonfinite[i], strlen(nonfinite[i]), &v) == MLOD_DEC_NONFINITE, "'%s'",
		          nonfinite[i]);
	}
}

/* Many generated strings: short ones (the fast path, mostly), long
 * mantissas, wide exponents. */
TEST(generated_against_strtod)
{
	char b[256];
	long checked = 0;
	const int maxd[] = { 8, 12, 20, 40 }, maxe[] = { 0, 25, 330, 400 };
	for (int set = 0; set < 4; set++)
		for (int i = 0; i < 250000; i++) {
			gen(b, maxd[set], maxe[set]);
			double got, want;
			CHECK_MSG(agrees(b, &got, &want), "%s: %.17g, strtod %.17g", b, got, want);
			checked++;
		}
	CHECK(checked == 1000000);
}

/* The frame lines: values in every form, read by mlod_bvh_read, are the
 * floats of strtod's doubles. */
TEST(frame_values_against_strtod)
{
	enum { FRAMES = 4000 };
	char *text = malloc((size_t)FRAMES * 3 * 64 + 512);
	float *want = malloc(sizeof(float) * FRAMES * 3);
	CHECK(text && want);
	size_t k = (size_t)sprintf(text, "HIERARCHY\nROOT A\n{\nOFFSET 0 0 0\nCHANNELS 3 Xposition Yposition Zposition\n"
	                                 "End Site\n{\nOFFSET 0 1 0\n}\n}\nMOTION\nFrames: %d\nFrame Time: 0.01\n",
	                           FRAMES);
	char b[128];
	for (int f = 0; f < FRAMES; f++) {
		for (int c = 0; c < 3; c++) {
			if (c == 0 && f % 4 == 1) {
				/* Halfway between two floats (an odd integer from 2^24
				 * to 2^25) with decimal zeros: one rounding off in the
				 * double shows in the float. */
				long n = (1L << 24) + 2L * (long)rnd(1u << 22) + 1;
				int z = 1 + (int)rnd(9);
				sprintf(b, "%s%ld.%.*s", rnd(2) ? "-" : "", n, z, "000000000");
			} else {
				gen(b, f % 3 == 0 ? 24 : 9, f % 5 == 0 && f % 3 != 0 ? 25 : 0);
			}
			want[3 * f + c] = (float)strtod(b, NULL);
			k += (size_t)sprintf(text + k, c ? (f % 7 ? " %s" : "\t%s") : "%s", b);
		}
		k += (size_t)sprintf(text + k, f % 11 ? "\n" : " \r\n");
	}
	text[k] = 0;
	mlod_character ch;
	mlod_error err = {0};
	mlod_result r = mlod_bvh_read(text, k, &ch, &err);
	CHECK_MSG(r == MLOD_OK, "%s", err.message);
	CHECK(ch.clip_count == 1 && ch.clips[0].channel_count == 1);
	const mlod_channel *t = &ch.clips[0].channels[0];
	CHECK(t->path == MLOD_PATH_TRANSLATION && t->key_count == FRAMES);
	int differ = 0;
	for (int i = 0; i < FRAMES * 3; i++)
		if (memcmp(&t->values[i], &want[i], sizeof(float)) != 0) {
			if (!differ)
				CHECK_MSG(0, "value %d: %.9g, want %.9g", i, t->values[i], want[i]);
			differ++;
		}
	mlod_character_free(&ch);
	free(text);
	free(want);
}

int main(void)
{
	RUN(edge_cases);
	RUN(generated_against_strtod);
	RUN(frame_values_against_strtod);
	TEST_EXIT();
}
