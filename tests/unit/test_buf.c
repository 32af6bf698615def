/* test_buf.c: the byte buffer (mlod_buf, mlod_core.h): growth, the
 * overflow check, printf-style text, the hand-over. */

#include "test.h"

/* Appends of 1 to 7 bytes up to 100000: every byte where it was put, the
 * NUL after the last, the allocation grown twofold (never more than twice
 * what it holds). */
TEST(growth)
{
	mlod_buf b = MLOD_BUF_INIT;
	size_t want = 0, grew = 0, last_cap = 0;
	unsigned k = 0;
	while (b.size < 100000) {
		unsigned char piece[7];
		size_t n = 1 + k % 7;
		for (size_t i = 0; i < n; i++)
			piece[i] = (unsigned char)((want + i) * 31u);
		CHECK(mlod_buf_append(&b, piece, n) == MLOD_OK);
		want += n, k++;
		CHECK(b.size == want);
		CHECK(b.cap >= b.size + 1);
		CHECK(b.data[b.size] == 0);
		if (b.cap != last_cap) {
			CHECK(last_cap == 0 || b.cap == 2 * last_cap);
			last_cap = b.cap, grew++;
		}
	}
	for (size_t i = 0; i < b.size; i++)
		CHECK_MSG(b.data[i] == (unsigned char)(i * 31u), "byte %zu", i);
	CHECK(b.cap < 2 * (b.size + 1));
	CHECK(grew < 20);
	/* zeros, and a single character */
	size_t at = b.size;
	CHECK(mlod_buf_append_zeros(&b, 1000) == MLOD_OK);
	CHECK(mlod_buf_append_char(&b, 'x') == MLOD_OK);
	CHECK(b.size == at + 1001);
	for (size_t i = at; i < at + 1000; i++)
		CHECK(b.data[i] == 0);
	CHECK(b.data[at + 1000] == 'x' && b.data[at + 1001] == 0);
	mlod_buf_free(&b);
	CHECK(b.data == NULL && b.size == 0 && b.cap == 0 && b.status == MLOD_OK);
}

/* A size that would pass SIZE_MAX fails as NOMEM without touching the
 * bytes, and every later append does nothing. */
TEST(overflow)
{
	mlod_buf b;
	mlod_buf_init(&b);
	CHECK(mlod_buf_append_str(&b, "0123456789") == MLOD_OK);
	unsigned char *data = b.data;
	size_t cap = b.cap;
	CHECK(mlod_buf_reserve(&b, SIZE_MAX - 10) == MLOD_ERR_NOMEM); /* size + extra + 1 wraps to 0 */
	CHECK(b.status == MLOD_ERR_NOMEM);
	CHECK(b.data == data && b.cap == cap && b.size == 10);
	CHECK(strcmp((const char *)b.data, "0123456789") == 0);
	CHECK(mlod_buf_append_str(&b, "more") == MLOD_ERR_NOMEM);
	CHECK(mlod_buf_printf(&b, "%d", 42) == MLOD_ERR_NOMEM);
	CHECK(mlod_buf_append_zeros(&b, 1) == MLOD_ERR_NOMEM);
	CHECK(b.size == 10 && b.data[10] == 0);
	char *text = (char *)1;
	size_t size = 1;
	mlod_error err = {0};
	CHECK(mlod_buf_take(&b, &text, &size, "the test", &err) == MLOD_ERR_NOMEM);
	CHECK(text == NULL && size == 0);
	CHECK(err.code == MLOD_ERR_NOMEM);
	CHECK_MSG(strcmp(err.message, "out of memory writing the test") == 0, "message: %s", err.message);
	CHECK(b.data == NULL && b.status == MLOD_OK); /* freed and empty */

	/* each edge of the check: SIZE_MAX - 1 - size is the most it takes */
	mlod_buf c = MLOD_BUF_INIT;
	CHECK(mlod_buf_append(&c, "ab", 2) == MLOD_OK);
	CHECK(mlod_buf_grow(&c, SIZE_MAX - 2) == MLOD_ERR_NOMEM);
	mlod_buf_free(&c);
	c.size = 5; /* no allocation at all: the check comes first */
	CHECK(mlod_buf_grow(&c, SIZE_MAX - 5) == MLOD_ERR_NOMEM);
	CHECK(c.data == NULL);
}

/* printf-style text, in the room there is and past it, the same as
 * snprintf's; mixed with bytes (a NUL among them). */
TEST(printf_append)
{
	mlod_buf b = MLOD_BUF_INIT;
	char want[4096], big[3000];
	memset(big, 'q', sizeof big - 1);
	big[sizeof big - 1] = 0;
	CHECK(mlod_buf_printf(&b, "%s=%d;", "a", 7) == MLOD_OK);
	CHECK(mlod_buf_append(&b, "\0z", 2) == MLOD_OK);
	CHECK(mlod_buf_printf(&b, "[%.9g|%-5s|%*s]", 0.1, "ab", 3, "") == MLOD_OK);
	size_t before = b.size;
	CHECK(mlod_buf_printf(&b, "<%s>", big) == MLOD_OK); /* past the room: formatted twice */
	CHECK(b.size == before + 2 + strlen(big));
	CHECK(mlod_buf_printf(&b, "%s", "") == MLOD_OK);
	CHECK(mlod_buf_printf(&b, "%.*s!", 2, "xyz") == MLOD_OK);
	int n = snprintf(want, sizeof want, "a=7;%cz[%.9g|%-5s|%*s]<%s>xy!", 0, 0.1, "ab", 3, "", big);
	CHECK(n > 0 && b.size == (size_t)n);
	CHECK(memcmp(b.data, want, (size_t)n) == 0);
	CHECK(b.data[b.size] == 0);
	char *text;
	size_t size;
	CHECK_OK(mlod_buf_take(&b, &text, &size, NULL, &terr));
	CHECK(size == (size_t)n && memcmp(text, want, size + 1) == 0);
	CHECK(b.data == NULL && b.size == 0);
	mlod_free(text);
}

/* Nothing appended: an empty text, not NULL. */
/* mlod_next_line, the one splitter of the reader's notes into lines:
 * each line without its '\n', an empty line between two '\n's, no line
 * after a final '\n', none at all for NULL or "". */
TEST(next_line)
{
	const char *w = "a\n\nbc\n", *l;
	size_t n = 99;
	char got[64] = "";
	int count = 0;
	while ((l = mlod_next_line(&w, &n)) && count < 8) {
		snprintf(got + strlen(got), sizeof got - strlen(got), "[%.*s]", (int)n, l);
		count++;
	}
	CHECK_MSG(count == 3 && strcmp(got, "[a][][bc]") == 0, "%d lines: %s", count, got);
	w = "x";
	CHECK(mlod_next_line(&w, &n) && n == 1 && *w == '\0' && !mlod_next_line(&w, &n));
	w = NULL;
	CHECK(!mlod_next_line(&w, &n));
	w = "";
	CHECK(!mlod_next_line(&w, &n));
}

TEST(take_empty)
{
	mlod_buf b = MLOD_BUF_INIT;
	char *text = NULL;
	size_t size = 1;
	CHECK_OK(mlod_buf_take(&b, &text, &size, "x", &terr));
	CHECK(text && text[0] == 0 && size == 0);
	mlod_free(text);
}

int main(void)
{
	RUN(growth);
	RUN(overflow);
	RUN(printf_append);
	RUN(take_empty);
	RUN(next_line);
	TEST_EXIT();
}
