/*
 * test_rt_threads.c: evaluation only reads the context, so threads with
 * their own scratch may pose and skin different instances at once (the
 * threading rule of mlod_rt.h): four threads give the same bytes as one.
 */
#include <threads.h>

#include "rt_test.h"

enum { N = 64, T = 4, V = 7 };
static mlod_rt_ctx *ctx;
static uint32_t ids[N];
static float expect[N][2 * 3 * V], got[N][2 * 3 * V];
static int failures[T];

typedef struct job {
	int t;
	mlod_rt_scratch *s;
} job;

static int worker(void *arg)
{
	job *j = arg;
	for (int rep = 0; rep < 50; rep++)
		for (int i = j->t; i < N; i += T) {
			uint32_t n;
			if (mlod_rt_skin(ctx, j->s, ids[i], got[i], 12, got[i] + 3 * V, 12, V, &n, NULL) != MLOD_OK)
				failures[j->t]++;
		}
	return 0;
}

TEST(threads_match_one_thread)
{
	mlod_error e;
	CHECK_OK(mlod_rt_open_views(&fx_views, NULL, &ctx, &e), e);
	CHECK(fx_load_all(ctx) == 0, "load");
	mlod_rt_select sel;
	mlod_rt_select_default(&sel);
	float d[N];
	for (int i = 0; i < N; i++) {
		CHECK_OK(mlod_rt_instance_create(ctx, (uint32_t)i % 2, 0.05f * (float)i, MLOD_RT_LOOP, &ids[i], &e), e);
		d[i] = 3.0f * (float)i;
	}
	CHECK_OK(mlod_rt_update(ctx, &sel, ids, d, N, 0.0f, &e), e);
	mlod_rt_scratch *one = mlod_rt_scratch_create(ctx);
	for (int i = 0; i < N; i++) {
		uint32_t n;
		memset(expect[i], 0, sizeof expect[i]);
		CHECK_OK(mlod_rt_skin(ctx, one, ids[i], expect[i], 12, expect[i] + 3 * V, 12, V, &n, &e), e);
	}
	mlod_rt_scratch_destroy(ctx, one);
	memset(got, 0, sizeof got);
	thrd_t th[T];
	job jobs[T];
	for (int t = 0; t < T; t++) {
		jobs[t].t = t;
		jobs[t].s = mlod_rt_scratch_create(ctx);
		CHECK(jobs[t].s && thrd_create(&th[t], worker, &jobs[t]) == thrd_success, "thread %d", t);
	}
	for (int t = 0; t < T; t++)
		thrd_join(th[t], NULL);
	for (int t = 0; t < T; t++) {
		mlod_rt_scratch_destroy(ctx, jobs[t].s);
		CHECK(failures[t] == 0, "thread %d: %d failed calls", t, failures[t]);
	}
	CHECK(memcmp(expect, got, sizeof got) == 0, "threads gave other results than one thread");
	mlod_rt_close(ctx);
}

int main(void)
{
	fx_build(0);
	RUN(threads_match_one_thread);
	TEST_EXIT();
}
