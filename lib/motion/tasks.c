/*
 * tasks.c: a sequence of tasks on threads with the sequence's result
 * (motion_run_tasks).
 *
 * Task t may start once every earlier task that conflicts with it (the
 * caller says which: tasks that read or write what t writes, or write
 * what t reads) has finished. Tasks that do not conflict touch disjoint
 * data, so any order that keeps the conflicting pairs in sequence order
 * gives the sequence's result, bit for bit. A thread takes the first task
 * that may start; the lock orders a task's end before the start of the
 * tasks that wait for it.
 */
#include <pthread.h>
#include <stdlib.h>

#include "motion/motion_eval.h"

int motion_eval_generic_only = 0; /* motion_eval.h: for tests */

typedef struct runner {
	int n;
	motion_conflict_fn conflict;
	motion_task_fn run;
	void *ctx;
	unsigned char *state; /* per task: 0 waiting, 1 running, 2 done */
	int first_open;       /* every task before it is done */
	pthread_mutex_t lock;
	pthread_cond_t changed;
} runner;

/* Under the lock: may task t start? */
static int ready(const runner *q, int t)
{
	for (int u = q->first_open; u < t; u++)
		if (q->state[u] != 2 && q->conflict(q->ctx, u, t))
			return 0;
	return 1;
}

static mlod_result lane_item(void *ctx, int lane)
{
	runner *q = ctx;
	pthread_mutex_lock(&q->lock);
	for (;;) {
		while (q->first_open < q->n && q->state[q->first_open] == 2)
			q->first_open++;
		int t = -1, waiting = 0;
		for (int u = q->first_open; u < q->n && t < 0; u++)
			if (q->state[u] == 0) {
				waiting = 1;
				if (ready(q, u))
					t = u;
			}
		if (!waiting)
			break;
		if (t < 0) {
			pthread_cond_wait(&q->changed, &q->lock);
			continue;
		}
		q->state[t] = 1;
		pthread_mutex_unlock(&q->lock);
		q->run(q->ctx, lane, t);
		pthread_mutex_lock(&q->lock);
		q->state[t] = 2;
		pthread_cond_broadcast(&q->changed);
	}
	pthread_mutex_unlock(&q->lock);
	return MLOD_OK;
}

mlod_result motion_run_tasks(int n, int lanes, motion_conflict_fn conflict, motion_task_fn run, void *ctx)
{
	if (lanes <= 1 || n <= 1) {
		for (int t = 0; t < n; t++)
			run(ctx, 0, t);
		return MLOD_OK;
	}
	runner q = { n, conflict, run, ctx, calloc((size_t)n, 1), 0, PTHREAD_MUTEX_INITIALIZER, PTHREAD_COND_INITIALIZER };
	if (!q.state)
		return MLOD_ERR_NOMEM;
	/* Lane i is item i: one thread at a time runs it (a thread that could
	 * not be started runs its item after the others, finding nothing
	 * left). */
	mlod_parallel_for(lanes, lanes, lane_item, &q);
	pthread_cond_destroy(&q.changed);
	pthread_mutex_destroy(&q.lock);
	free(q.state);
	return MLOD_OK;
}
