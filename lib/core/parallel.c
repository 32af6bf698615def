/*
 * parallel.c: mlod_parallel_for, the one place mlod starts threads.
 *
 * Work items are handed out in index order from a shared counter; each
 * item writes only its own results, so what a caller computes does not
 * depend on the number of threads or on their timing (mlod's output is
 * byte-identical at any thread count). The first failing item in index
 * order decides the result, as it would in a plain loop.
 */
#define _POSIX_C_SOURCE 200809L
#if defined(__linux__)
#define _GNU_SOURCE /* sched_getaffinity, CPU_COUNT */
#include <sched.h>
#endif

#include <pthread.h>
#include <stdlib.h>
#include <unistd.h>

#include "mlod_core.h"

typedef struct job {
	int n;
	mlod_parallel_fn fn;
	void *ctx;
	pthread_mutex_t lock;
	int next;          /* the next item to hand out */
	int failed_at;     /* the smallest failing item, or n */
	mlod_result failed;
} job;

static void *worker(void *arg)
{
	job *j = arg;
	for (;;) {
		pthread_mutex_lock(&j->lock);
		/* items past a failure are not started: a plain loop would not reach them */
		int i = j->next < j->failed_at ? j->next++ : j->n;
		pthread_mutex_unlock(&j->lock);
		if (i >= j->n)
			return NULL;
		mlod_result r = j->fn(j->ctx, i);
		if (r != MLOD_OK) {
			pthread_mutex_lock(&j->lock);
			if (i < j->failed_at)
				j->failed_at = i, j->failed = r;
			pthread_mutex_unlock(&j->lock);
		}
	}
}

/* The processors this process may run on (taskset, cgroup cpusets: its
 * CPU affinity, where the system tells it), else those online. */
int mlod_thread_count(void)
{
	long n = sysconf(_SC_NPROCESSORS_ONLN);
#if defined(__linux__) && defined(CPU_COUNT)
	cpu_set_t set;
	if (sched_getaffinity(0, sizeof set, &set) == 0) {
		int a = CPU_COUNT(&set);
		if (a >= 1 && (n < 1 || a < n))
			n = a;
	}
#endif
	return n < 1 ? 1 : n > MLOD_MAX_THREADS ? MLOD_MAX_THREADS : (int)n;
}

mlod_result mlod_parallel_for(int n, int threads, mlod_parallel_fn fn, void *ctx)
{
	if (n <= 0)
		return MLOD_OK;
	if (threads > n)
		threads = n;
	if (threads > MLOD_MAX_THREADS)
		threads = MLOD_MAX_THREADS;
	if (threads <= 1) {
		for (int i = 0; i < n; i++) {
			mlod_result r = fn(ctx, i);
			if (r != MLOD_OK)
				return r;
		}
		return MLOD_OK;
	}
	job j = { n, fn, ctx, PTHREAD_MUTEX_INITIALIZER, 0, n, MLOD_OK };
	pthread_t tid[MLOD_MAX_THREADS];
	int started = 0;
	for (int t = 1; t < threads; t++) {
		if (pthread_create(&tid[started], NULL, worker, &j) != 0)
			break; /* fewer threads: the same result, later */
		started++;
	}
	worker(&j);
	for (int t = 0; t < started; t++)
		pthread_join(tid[t], NULL);
	pthread_mutex_destroy(&j.lock);
	return j.failed_at < n ? j.failed : MLOD_OK;
}
