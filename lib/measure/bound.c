/*
 * bound.c: levels within an error bound: the chain-and-bisect search the
 * skeleton and mesh layers share, and screen coverage from an error
 * (mlod_measure.h).
 */
#include "measure/mlod_measure.h"

double mlod_error_coverage(double error_percent, double screen_pixels, double pixel_budget)
{
	if (error_percent <= 0.0)
		return 0.0;
	double c = 100.0 * pixel_budget / (error_percent * screen_pixels);
	return c > 1.0 ? 1.0 : c;
}

void mlod_lod_coverage(const double *error_percent, int count, float *coverage)
{
	for (int k = 0; k < count; k++)
		coverage[k] = (float)mlod_error_coverage(error_percent[k], MLOD_COVERAGE_LINES, MLOD_COVERAGE_PIXELS);
	coverage[count] = 0.0f;
	for (int k = 1; k <= count; k++)
		if (coverage[k] > coverage[k - 1])
			coverage[k] = coverage[k - 1];
}

mlod_result mlod_level_search_run(const mlod_level_search *s, mlod_error *err)
{
	double kept = s->start;
	for (int i = 0; i < s->count; i++) {
		void *level = NULL;
		double error = 0.0;
		mlod_result r = s->make(s->ctx, s->candidates[i], 1, &level, &error, err);
		if ((int)r == 1)
			return MLOD_OK; /* nothing more comes off */
		if (r != MLOD_OK)
			return r;
		if (error <= s->bound) {
			if (!s->keep(s->ctx, level))
				return MLOD_OK;
			kept = s->candidates[i];
			continue;
		}
		s->drop(s->ctx, level);
		/* pass is within the bound, fail beyond it. */
		double pass = kept, fail = s->candidates[i];
		void *best = NULL;
		for (int it = 0; s->whole ? (fail - pass > 1.0 || pass - fail > 1.0) : it < s->bisections; it++) {
			double mid = s->whole ? (double)(long)((pass + fail) / 2) : 0.5 * (pass + fail);
			void *trial = NULL;
			r = s->make(s->ctx, mid, 0, &trial, &error, err);
			if (r != MLOD_OK) {
				if (best)
					s->drop(s->ctx, best);
				return r;
			}
			if (error <= s->bound) {
				if (best)
					s->drop(s->ctx, best);
				best = trial;
				pass = mid;
			} else {
				s->drop(s->ctx, trial);
				fail = mid;
			}
		}
		if (best)
			s->keep(s->ctx, best);
		return MLOD_OK;
	}
	return MLOD_OK;
}
