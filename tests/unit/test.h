/*
 * test.h: a minimal unit test harness for mlod.
 *
 * Each tests/unit/test_*.c is one program. It defines test functions with
 * TEST(name) and runs them from main with RUN(name). Each test prints one
 * line, "PASS name", "FAIL name: file:line: what" or "SKIP name: why",
 * which tests/run.sh counts. A failing CHECK stops only its own test.
 * A test that needs ../shared/data starts with NEED_SHARED(): without the
 * data it is reported as SKIP with the reason, not as PASS (tests/run.sh
 * counts a SKIP as a failure when the data is there).
 *
 * Tests that need sample files find them through test_path("samples/x"),
 * relative to the repository root (the runner's working directory).
 */
#ifndef MLOD_TEST_H
#define MLOD_TEST_H

#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L /* strdup, mkstemp in tests */
#endif

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "mlod.h"

static int test_failed_;
static int test_skipped_;
static char test_msg_[1024];
static int test_total_fail_;

#define TEST(name) static void test_##name(void)

#define RUN(name)                                                              \
	do {                                                                   \
		test_failed_ = 0;                                              \
		test_skipped_ = 0;                                             \
		test_##name();                                                 \
		if (test_failed_) {                                            \
			printf("FAIL %s: %s\n", #name, test_msg_);             \
			test_total_fail_++;                                    \
		} else if (test_skipped_) {                                    \
			printf("SKIP %s: %s\n", #name, test_msg_);             \
		} else {                                                       \
			printf("PASS %s\n", #name);                            \
		}                                                              \
		fflush(stdout);                                                \
	} while (0)

#define TEST_EXIT() return test_total_fail_ ? 1 : 0

#define CHECK_MSG(cond, ...)                                                   \
	do {                                                                   \
		if (!(cond)) {                                                 \
			int n_ = snprintf(test_msg_, sizeof test_msg_, "%s:%d: ", __FILE__, __LINE__); \
			snprintf(test_msg_ + n_, sizeof test_msg_ - (size_t)n_, __VA_ARGS__); \
			test_failed_ = 1;                                      \
			return;                                                \
		}                                                              \
	} while (0)

#define CHECK(cond) CHECK_MSG(cond, "%s", #cond)

#define CHECK_NEAR(a, b, tol)                                                  \
	do {                                                                   \
		double a_ = (double)(a), b_ = (double)(b);                     \
		CHECK_MSG(fabs(a_ - b_) <= (tol), "%s = %.9g, expected %s = %.9g (tol %g)", #a, a_, #b, b_, (double)(tol)); \
	} while (0)

/* Checks an mlod call returned MLOD_OK; prints the library's message otherwise. */
/* Pass &terr as the call's error argument so the message can be shown. */
#if defined(__GNUC__)
__attribute__((unused))
#endif
static mlod_error terr;
#define CHECK_OK(call)                                                         \
	do {                                                                   \
		memset(&terr, 0, sizeof terr);                                 \
		mlod_result r_ = (call);                                       \
		CHECK_MSG(r_ == MLOD_OK, "%s returned %d: %s", #call, (int)r_, terr.message); \
	} while (0)

/* Reads a whole file; returns NULL if it cannot. *size gets its length. */
static inline void *test_read_file(const char *path, size_t *size)
{
	FILE *f = fopen(path, "rb");
	if (!f)
		return NULL;
	size_t cap = 1 << 16, n = 0;
	char *buf = malloc(cap);
	for (;;) {
		if (n == cap) {
			cap *= 2;
			buf = realloc(buf, cap);
		}
		size_t got = fread(buf + n, 1, cap - n, f);
		if (got == 0)
			break;
		n += got;
	}
	fclose(f);
	*size = n;
	return buf;
}

/* Ends the current test as SKIP with a reason (printf-like): it could not
 * run. Only for absent ../shared/data (see NEED_SHARED). */
#define SKIP(...)                                                              \
	do {                                                                   \
		snprintf(test_msg_, sizeof test_msg_, __VA_ARGS__);            \
		test_skipped_ = 1;                                             \
		return;                                                        \
	} while (0)

/* The development data in ../shared/data, as tests/run.sh --extended
 * (make test-extended) names it in MLOD_SHARED_DATA: its directory, or
 * NULL when it is absent, with the reason in why. */
static inline const char *test_shared_dir(char *why, size_t size)
{
	const char *e = getenv("MLOD_SHARED_DATA");
	struct stat st;
	if (!e || !*e) {
		snprintf(why, size, "needs ../shared/data: MLOD_SHARED_DATA is not set "
		                    "(make test-extended sets it when ../shared/data exists)");
		return NULL;
	}
	if (stat(e, &st) != 0 || !S_ISDIR(st.st_mode)) {
		snprintf(why, size, "needs ../shared/data: MLOD_SHARED_DATA=%.900s is not a directory", e);
		return NULL;
	}
	return e;
}

/* Skips the current test when ../shared/data is absent. */
#define NEED_SHARED()                                                          \
	do {                                                                   \
		if (!test_shared_dir(test_msg_, sizeof test_msg_)) {          \
			test_skipped_ = 1;                                     \
			return;                                                \
		}                                                              \
	} while (0)


/* A skeleton from a parent array (parents before children), joints named
 * j0, j1, ..., bones of length 1 along y. Free with mlod_character_free. */
static inline mlod_character test_skeleton(int n, const int *parent)
{
	mlod_character c = {0};
	c.skeleton.joint_count = n;
	c.skeleton.joints = calloc((size_t)n, sizeof(mlod_joint));
	for (int j = 0; j < n; j++) {
		mlod_joint *jt = &c.skeleton.joints[j];
		char name[16];
		snprintf(name, sizeof name, "j%d", j);
		jt->name = strdup(name);
		jt->parent = parent[j];
		jt->rest = mlod_trs_identity();
		jt->rest.t.y = parent[j] >= 0 ? 1.0f : 0.0f;
		jt->base = mlod_mat4_identity();
		jt->node = -1;
		jt->euler = MLOD_EULER_XYZ;
	}
	return c;
}

/* Loads a glb, glTF or BVH file into c; returns 0, or -1 after printing
 * why to stderr. */
static inline int test_load(const char *path, mlod_character *c)
{
	size_t size;
	void *data = test_read_file(path, &size);
	if (!data) {
		fprintf(stderr, "%s: cannot read\n", path);
		return -1;
	}
	mlod_error e = {0};
	mlod_result r = mlod_load(data, size, NULL, NULL, c, NULL, &e);
	free(data);
	if (r != MLOD_OK)
		fprintf(stderr, "%s: %s\n", path, e.message);
	return r == MLOD_OK ? 0 : -1;
}

#endif
