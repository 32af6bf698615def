/*
 * test_unpack.c: pack then unpack (mlod_pack_write, mlod_pack_unpack) on
 * every sample, measured independently of both: the input and the
 * unpacked glb are loaded with the bake library (mlod_load) and compared.
 *
 *   lossless   joint names, parents and rest TRS, skins' joints and
 *              inverse binds, materials of the primitives, index lists;
 *              with lossless_motion, clip key times and values (ROTQ
 *              within its lattice bound)
 *   bounded    every motion level (level 0 by default, and the coarser
 *              ones as <clip>@lod<k>): at the input clip's common
 *              timeline frames and midpoints, every joint's point error
 *              within the level's bound, and its position error within
 *              the level's TOC error, each plus the ROTQ lattice's share,
 *              both clips sampled and posed with the bake library
 *   quantised  (mlod(5)) positions within half a step of position_bits
 *              of the part's box per axis, normals within
 *              3 sqrt(2) 2^(15 - normal_bits) / 32767 radians, UVs within
 *              half a step of uv_bits of their box (the defaults, and
 *              tubeman at 16 and at the smallest bits too),
 *              weights (the 4 largest influences, renormalised) within
 *              1/255 each
 *   coarse     (mlod(5) QUANTISATION, coarse levels) every MESH level
 *              k >= 1 decoded against the input's level k, vertex by
 *              vertex and posed, within level 0's bounds or the share of
 *              level k's TOC error (coarse_levels below)
 *
 * The writer keeps the vertex order, so vertices are compared in order.
 * The largest position error relative to its bound is printed on stderr.
 */
#include "test.h"

static double worst_pos_ratio, worst_pos_err, worst_nrm, worst_uv_ratio, worst_w;
static long degenerate_dropped; /* input triangles the pack dropped as degenerate (compare_primitive) */
/* The writer's bits (mlod_pack_options) for the pack being checked. */
static int pos_bits = 16, nrm_bits = 16, uv_bits = 16;

/* mlod(5) QUANTISATION, computed here: half a step of 2^bits - 1 over
 * [lo, hi], with f32 slack; the octahedral angle at nrm_bits. */
static double half_step(float lo, float hi, int bits)
{
	return ((double)hi - lo) / (ldexp(1.0, bits) - 1.0) / 2 * (1 + 1e-4) + 1e-6 * (fabs(lo) + fabs(hi));
}

static double oct_bound(void)
{
	return 3.0 * sqrt(2.0) * ldexp(1.0, 15 - nrm_bits) / 32767.0 + 2e-6;
}

static const mlod_instance *instance_of_node(const mlod_character *c, int node)
{
	for (int i = 0; i < c->instance_count; i++)
		if (c->instances[i].node == node)
			return &c->instances[i];
	return NULL;
}

static const mlod_clip *clip_named(const mlod_character *c, const char *name)
{
	for (int i = 0; i < c->clip_count; i++)
		if (strcmp(c->clips[i].name, name) == 0)
			return &c->clips[i];
	return NULL;
}

static const mlod_channel *channel_of(const mlod_clip *k, int joint, mlod_path path)
{
	for (int i = 0; i < k->channel_count; i++)
		if (k->channels[i].joint == joint && k->channels[i].path == path)
			return &k->channels[i];
	return NULL;
}

/* Checks one primitive; returns a message or NULL. */
/* Positions quantised on the writer's grid for a part (its box, pos_bits). */
typedef struct qgrid {
	float lo[3], scale[3];
} qgrid;

static void qgrid_make(qgrid *g, const mlod_primitive *a)
{
	float hi[3] = {-INFINITY, -INFINITY, -INFINITY};
	for (int d = 0; d < 3; d++)
		g->lo[d] = INFINITY;
	for (int v = 0; v < a->vertex_count; v++)
		for (int d = 0; d < 3; d++) {
			g->lo[d] = fminf(g->lo[d], a->positions[3 * v + d]);
			hi[d] = fmaxf(hi[d], a->positions[3 * v + d]);
		}
	for (int d = 0; d < 3; d++)
		g->scale[d] = mlod_pack_range_scale_bits(g->lo[d], hi[d], pos_bits);
}

static void qpos(const qgrid *g, const float *p, long *out)
{
	for (int d = 0; d < 3; d++)
		out[d] = mlod_pack_qu16(p[d], g->lo[d], g->scale[d]); /* the writer's rounding */
}

static int cmp_long3(const long *x, const long *y)
{
	for (int d = 0; d < 3; d++)
		if (x[d] != y[d])
			return x[d] < y[d] ? -1 : 1;
	return 0;
}

static int cmp_tri(const void *x, const void *y)
{
	const long *a = x, *b = y;
	for (int d = 0; d < 9; d++)
		if (a[d] != b[d])
			return a[d] < b[d] ? -1 : 1;
	return 0;
}

/* Each triangle as 9 quantised coordinates, in the rotation that sorts
 * first (winding kept), the list sorted. */
static long *tri_keys(const qgrid *g, const mlod_primitive *p, int count)
{
	long *k = malloc(sizeof *k * 9 * (size_t)(count / 3 + 1));
	if (!k)
		return NULL;
	for (int t = 0; t + 2 < count; t += 3) {
		long c[3][3];
		for (int i = 0; i < 3; i++) {
			uint32_t v = p->index_count ? p->indices[t + i] : (uint32_t)(t + i);
			qpos(g, p->positions + 3 * (size_t)v, c[i]);
		}
		/* the smallest of the three rotations (two equal corners tie) */
		long rot[3][9];
		int r = 0;
		for (int o = 0; o < 3; o++) {
			for (int i = 0; i < 3; i++)
				memcpy(rot[o] + 3 * i, c[(o + i) % 3], sizeof c[0]);
			if (o > 0 && cmp_tri(rot[o], rot[r]) < 0)
				r = o;
		}
		memcpy(k + 9 * (size_t)(t / 3), rot[r], sizeof rot[r]);
	}
	qsort(k, (size_t)(count / 3), sizeof *k * 9, cmp_tri);
	return k;
}

static double attr_distance(const mlod_primitive *a, int u, const mlod_primitive *b, int v)
{
	double d = 0;
	for (int i = 0; a->normals && b->normals && i < 3; i++)
		d += fabs((double)a->normals[3 * u + i] - b->normals[3 * v + i]);
	for (int s = 0; s < a->uv_set_count && s < b->uv_set_count && s < MLOD_PACK_MAX_UV; s++)
		for (int i = 0; i < 2; i++)
			d += fabs((double)a->uvs[s][2 * u + i] - b->uvs[s][2 * v + i]);
	for (int i = 0; a->weight_set_count && b->weight_set_count && i < 4; i++)
		d += fabs((double)a->weights[0][4 * u + i] - b->weights[0][4 * v + i]) +
		     (a->joints[0][4 * u + i] != b->joints[0][4 * v + i]);
	return d;
}

static void permuted_free(mlod_primitive *p)
{
	free(p->positions);
	free(p->normals);
	for (int s = 0; s < MLOD_MAX_SETS; s++) {
		free(p->uvs[s]);
		free(p->joints[s]);
		free(p->weights[s]);
	}
	memset(p, 0, sizeof *p);
}

/* out: a copy of a's vertex attributes in b's vertex order, each unpacked
 * vertex given the input vertex at its quantised position that is nearest
 * in its other attributes. 0 when some vertex has none. */
static int permuted(const qgrid *g, const mlod_primitive *a, const mlod_primitive *b, mlod_primitive *out)
{
	int n = b->vertex_count, ok = 1;
	memset(out, 0, sizeof *out);
	out->vertex_count = n;
	out->uv_set_count = a->uv_set_count;
	out->weight_set_count = a->weight_set_count;
	out->material = a->material;
	long *qa = malloc(sizeof *qa * 3 * (size_t)a->vertex_count + 1);
	out->positions = malloc(sizeof(float) * 3 * (size_t)n + 1);
	if (a->normals)
		out->normals = malloc(sizeof(float) * 3 * (size_t)n + 1);
	for (int s = 0; s < a->uv_set_count && s < MLOD_MAX_SETS; s++)
		out->uvs[s] = malloc(sizeof(float) * 2 * (size_t)n + 1);
	for (int s = 0; s < a->weight_set_count; s++) {
		out->joints[s] = malloc(sizeof(uint16_t) * 4 * (size_t)n + 1);
		out->weights[s] = malloc(sizeof(float) * 4 * (size_t)n + 1);
	}
	if (!qa || !out->positions)
		ok = 0;
	for (int u = 0; ok && u < a->vertex_count; u++)
		qpos(g, a->positions + 3 * (size_t)u, qa + 3 * (size_t)u);
	for (int v = 0; ok && v < n; v++) {
		long q[3];
		qpos(g, b->positions + 3 * (size_t)v, q);
		int best = -1;
		double bd = INFINITY;
		for (int u = 0; u < a->vertex_count; u++)
			if (cmp_long3(qa + 3 * (size_t)u, q) == 0) {
				double d = attr_distance(a, u, b, v);
				if (d < bd)
					bd = d, best = u;
			}
		if (best < 0) {
			ok = 0;
			break;
		}
		memcpy(out->positions + 3 * (size_t)v, a->positions + 3 * (size_t)best, sizeof(float) * 3);
		if (a->normals)
			memcpy(out->normals + 3 * (size_t)v, a->normals + 3 * (size_t)best, sizeof(float) * 3);
		for (int s = 0; s < a->uv_set_count && s < MLOD_MAX_SETS; s++)
			memcpy(out->uvs[s] + 2 * (size_t)v, a->uvs[s] + 2 * (size_t)best, sizeof(float) * 2);
		for (int s = 0; s < a->weight_set_count; s++) {
			memcpy(out->joints[s] + 4 * (size_t)v, a->joints[s] + 4 * (size_t)best, sizeof(uint16_t) * 4);
			memcpy(out->weights[s] + 4 * (size_t)v, a->weights[s] + 4 * (size_t)best, sizeof(float) * 4);
		}
	}
	free(qa);
	if (!ok)
		permuted_free(out);
	return ok;
}

/* grid: the writer's grid of the part (its MESH record), or NULL for the
 * input's box. The unpacked primitive may have fewer vertices: the pack
 * (layout b2) stores vertices whose quantised attributes are bit-identical
 * once, and a level gets the vertices its triangles use. */
static const char *compare_primitive(const mlod_primitive *a, const mlod_primitive *b, const qgrid *grid, char *msg,
                                     size_t cap)
{
	if (b->vertex_count > a->vertex_count) {
		snprintf(msg, cap, "vertex count %d, unpacked %d", a->vertex_count, b->vertex_count);
		return msg;
	}
	if (a->material != b->material) {
		snprintf(msg, cap, "material %d, unpacked %d", a->material, b->material);
		return msg;
	}
	int n = b->vertex_count;
	/* Indices: the same triangles (an unindexed input gets 0..n-1), less
	 * the ones quantisation made degenerate (the writer drops a triangle
	 * two of whose corners have bit-identical quantised attributes, and so
	 * the same quantised position). */
	int ia = a->index_count ? a->index_count : a->vertex_count;
	if (b->index_count > ia || b->index_count % 3) {
		snprintf(msg, cap, "index count %d, unpacked %d", ia, b->index_count);
		return msg;
	}
	/* The writer may reorder a part's vertices and triangles (the codecs
	 * gain from it), and meshopt's index codec may rotate a triangle's
	 * corners: the same triangles as a multiset, compared by their
	 * corners' quantised positions, winding kept. Then each unpacked
	 * vertex is matched with an input vertex at the same quantised
	 * position (the one nearest in normal, UV and weights), and the
	 * attribute bounds below are checked against that one. */
	qgrid g;
	qgrid_make(&g, a);
	if (grid)
		g = *grid;
	long *ka = tri_keys(&g, a, ia), *kb = tri_keys(&g, b, b->index_count);
	int tri_ok = ka && kb, ta = 0, tb = 0, dropped = 0;
	while (tri_ok && ta < ia / 3) { /* both sorted: b's must be a's, a's others degenerate */
		const long *x = ka + 9 * (size_t)ta, *y = kb + 9 * (size_t)tb;
		if (tb < b->index_count / 3 && cmp_tri(x, y) == 0) {
			ta++, tb++;
			continue;
		}
		tri_ok = cmp_long3(x, x + 3) == 0 || cmp_long3(x + 3, x + 6) == 0 || cmp_long3(x, x + 6) == 0;
		ta++, dropped++;
	}
	tri_ok = tri_ok && tb == b->index_count / 3;
	free(ka);
	free(kb);
	if (!tri_ok) {
		snprintf(msg, cap, "the triangles differ (compared by quantised corner positions; %d of %d dropped as "
		         "degenerate)", dropped, ia / 3);
		return msg;
	}
	degenerate_dropped += dropped;
	mlod_primitive pa;
	if (!permuted(&g, a, b, &pa)) {
		snprintf(msg, cap, "an unpacked vertex has no input vertex at its quantised position");
		return msg;
	}
	a = &pa;
	float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
	for (int v = 0; v < n; v++)
		for (int d = 0; d < 3; d++) {
			lo[d] = fminf(lo[d], a->positions[3 * v + d]);
			hi[d] = fmaxf(hi[d], a->positions[3 * v + d]);
		}
	for (int d = 0; d < 3; d++) {
		double bound = half_step(lo[d], hi[d], pos_bits);
		for (int v = 0; v < n; v++) {
			double e = fabs((double)a->positions[3 * v + d] - b->positions[3 * v + d]);
			if (e > worst_pos_err)
				worst_pos_err = e;
			if (bound > 0 && e / bound > worst_pos_ratio)
				worst_pos_ratio = e / bound;
			if (e > bound) {
				snprintf(msg, cap, "vertex %d axis %d: position off by %g, bound %g", v, d, e, bound);
				return permuted_free(&pa), msg;
			}
		}
	}
	if ((a->normals != NULL) != (b->normals != NULL)) {
		snprintf(msg, cap, "normals present %d, unpacked %d", a->normals != NULL, b->normals != NULL);
		return permuted_free(&pa), msg;
	}
	for (int v = 0; a->normals && v < n; v++) {
		const float *x = a->normals + 3 * v, *y = b->normals + 3 * v;
		double X[3] = {x[0], x[1], x[2]}, Y[3] = {y[0], y[1], y[2]};
		double lx = sqrt(X[0] * X[0] + X[1] * X[1] + X[2] * X[2]);
		if (!(lx > 0.5))
			continue; /* not a unit normal in the input */
		double dot = X[0] * Y[0] + X[1] * Y[1] + X[2] * Y[2];
		double cr[3] = {X[1] * Y[2] - X[2] * Y[1], X[2] * Y[0] - X[0] * Y[2], X[0] * Y[1] - X[1] * Y[0]};
		double ang = atan2(sqrt(cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]), dot);
		if (ang > worst_nrm)
			worst_nrm = ang;
		if (ang > oct_bound()) {
			snprintf(msg, cap, "vertex %d: normal off by %g rad (%.9g %.9g %.9g, unpacked %.9g %.9g %.9g)", v, ang, x[0], x[1], x[2], y[0], y[1], y[2]);
			return permuted_free(&pa), msg;
		}
	}
	int sets = a->uv_set_count < MLOD_PACK_MAX_UV ? a->uv_set_count : MLOD_PACK_MAX_UV;
	if (b->uv_set_count != sets) {
		snprintf(msg, cap, "uv sets %d, unpacked %d", a->uv_set_count, b->uv_set_count);
		return permuted_free(&pa), msg;
	}
	for (int s = 0; s < sets; s++)
		for (int d = 0; d < 2; d++) {
			float ul = INFINITY, uh = -INFINITY;
			for (int v = 0; v < n; v++) {
				ul = fminf(ul, a->uvs[s][2 * v + d]);
				uh = fmaxf(uh, a->uvs[s][2 * v + d]);
			}
			double bound = half_step(ul, uh, uv_bits);
			for (int v = 0; v < n; v++) {
				double e = fabs((double)a->uvs[s][2 * v + d] - b->uvs[s][2 * v + d]);
				if (bound > 0 && e / bound > worst_uv_ratio)
					worst_uv_ratio = e / bound;
				if (e > bound) {
					snprintf(msg, cap, "vertex %d uv %d.%d off by %g, bound %g", v, s, d, e, bound);
					return permuted_free(&pa), msg;
				}
			}
		}
	if ((a->weight_set_count > 0) != (b->weight_set_count > 0)) {
		snprintf(msg, cap, "weights present %d, unpacked %d", a->weight_set_count, b->weight_set_count);
		return permuted_free(&pa), msg;
	}
	for (int v = 0; a->weight_set_count && v < n; v++) {
		/* The input's 4 largest influences, renormalised. */
		int jt[4 * MLOD_MAX_SETS];
		float wt[4 * MLOD_MAX_SETS];
		int m = 0;
		for (int s = 0; s < a->weight_set_count; s++)
			for (int i = 0; i < 4; i++)
				if (a->weights[s][4 * v + i] > 0) {
					jt[m] = a->joints[s][4 * v + i];
					wt[m++] = a->weights[s][4 * v + i];
				}
		for (int i = 0; i < m; i++) /* sort by weight, decreasing */
			for (int j = i + 1; j < m; j++)
				if (wt[j] > wt[i]) {
					float tw = wt[i];
					int tj = jt[i];
					wt[i] = wt[j];
					jt[i] = jt[j];
					wt[j] = tw;
					jt[j] = tj;
				}
		if (m > 4)
			m = 4;
		double sum = 0;
		for (int i = 0; i < m; i++)
			sum += wt[i];
		for (int i = 0; i < m; i++) {
			double w = 0;
			for (int s = 0; s < b->weight_set_count; s++)
				for (int k = 0; k < 4; k++)
					if (b->joints[s][4 * v + k] == jt[i])
						w += b->weights[s][4 * v + k];
			double e = fabs(w - wt[i] / sum);
			if (e > worst_w)
				worst_w = e;
			if (e > 1.0 / 255 + 1e-6) {
				snprintf(msg, cap, "vertex %d joint %d: weight %g, input %g", v, jt[i], w, wt[i] / sum);
				return permuted_free(&pa), msg;
			}
		}
	}
	permuted_free(&pa);
	return NULL;
}

/* Motion level 0 against the input clip, by the point error
 * (mlod_motion_point_error, radius pd) of every joint at the input's
 * common timeline frames and midpoints, each clip sampled and posed by the
 * bake library (not lib/motion's own evaluator): at most e0 plus the ROTQ
 * lattice's share (mlod(5): each rotation key within MLOD_PACK_ROTQ_ANGLE,
 * plus MLOD_PACK_ROTQ_SHARE of the level's TOC error for format 4.0's
 * coarser lattices;
 * a rotation of the joint or an ancestor g off by that angle moves the
 * joint's origin by at most the angle times |o_joint - o_g| and turns its
 * world 3x3 part M by that angle, which the point error weighs by pd
 * sigma_max(M): RobotExpressive's joints carry a world scale of 100),
 * plus 1e-6 of the height for the ticks and float sums. *worst gets the
 * largest error / bound. */
/* The largest singular value of w's 3x3 part (power iteration on M^T M). */
static double sigma_max3(const mlod_mat4 *w)
{
	double v[3] = {1, 0.7, 0.3}, lam = 0;
	for (int it = 0; it < 64; it++) {
		double u[3], x[3], n = 0;
		for (int r = 0; r < 3; r++)
			u[r] = w->m[r] * v[0] + w->m[4 + r] * v[1] + w->m[8 + r] * v[2];
		for (int c = 0; c < 3; c++)
			x[c] = w->m[4 * c] * u[0] + w->m[4 * c + 1] * u[1] + w->m[4 * c + 2] * u[2];
		for (int c = 0; c < 3; c++)
			n += x[c] * x[c];
		n = sqrt(n);
		if (!(n > 0))
			return 0;
		lam = n / sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
		for (int c = 0; c < 3; c++)
			v[c] = x[c] / n;
	}
	return sqrt(lam);
}

static const char *level_within(const mlod_character *c, const mlod_clip *a, const mlod_clip *b, double e0,
                                 double toc, double pd, double height, double *worst, char *msg, size_t cap)
{
	mlod_motion_options mo = {0};
	mlod_clip common;
	mlod_error err = {0};
	if (mlod_motion_common_clip(a, &mo, &common, NULL, &err) != MLOD_OK) {
		snprintf(msg, cap, "clip '%s': %s", a->name, err.message);
		return msg;
	}
	int nj = c->skeleton.joint_count, frames = common.channels[0].key_count, n = 2 * (frames - 1) + 1;
	float *t = malloc(sizeof *t * (size_t)n);
	mlod_trs *la = malloc(sizeof *la * (size_t)nj), *lb = malloc(sizeof *lb * (size_t)nj);
	mlod_mat4 *wa = malloc(sizeof *wa * (size_t)nj), *wb = malloc(sizeof *wb * (size_t)nj);
	unsigned char *rotq = calloc((size_t)nj, 1);
	const char *fail = NULL;
	mlod_motion_sample_times(common.channels[0].times, frames, 2, t);
	for (int i = 0; i < b->channel_count; i++)
		if (b->channels[i].path == MLOD_PATH_ROTATION && b->channels[i].interp != MLOD_INTERP_CUBICSPLINE)
			rotq[b->channels[i].joint] = 1;
	const double angle = MLOD_PACK_ROTQ_ANGLE;
	/* format 4.0: the coarser lattices may add this much more (mlod(5)
	 * QUANTISATION; the writer's shifts are not consulted) */
	const double share = toc > 0 ? MLOD_PACK_ROTQ_SHARE * toc : 0.0;
	for (int i = 0; i < n && !fail; i++) {
		mlod_pose_rest(&c->skeleton, la);
		mlod_pose_rest(&c->skeleton, lb);
		mlod_clip_sample(a, t[i], la);
		mlod_clip_sample(b, t[i], lb);
		mlod_pose_world(&c->skeleton, la, wa);
		mlod_pose_world(&c->skeleton, lb, wb);
		for (int j = 0; j < nj && !fail; j++) {
			double lattice = 0, origin = 0, radius = pd * sigma_max3(&wa[j]);
			for (int g = j; g >= 0; g = c->skeleton.joints[g].parent)
				if (rotq[g]) {
					double d = 0;
					for (int r = 0; r < 3; r++)
						d += ((double)wa[j].m[12 + r] - wa[g].m[12 + r]) * ((double)wa[j].m[12 + r] - wa[g].m[12 + r]);
					lattice += angle * (sqrt(d) + radius);
					origin += angle * sqrt(d);
				}
			/* the TOC's joint position error, honest up to the lattice */
			double jp = 0;
			for (int r = 0; r < 3; r++)
				jp += ((double)wa[j].m[12 + r] - wb[j].m[12 + r]) * ((double)wa[j].m[12 + r] - wb[j].m[12 + r]);
			jp = sqrt(jp);
			if (toc >= 0 && jp > toc + origin + share + 1e-6 * height) {
				snprintf(msg, cap,
				         "clip '%s' joint %d at %.5g s: position error %.6g, TOC error %.6g + lattice %.6g + share %.6g",
				         a->name, j, (double)t[i], jp, toc, origin, share);
				fail = msg;
			}
			double e = mlod_motion_point_error(&wa[j], &wb[j], pd), bound = e0 + lattice + share + 1e-6 * height;
			if (e / bound > *worst)
				*worst = e / bound;
			if (e > bound) {
				snprintf(msg, cap,
				         "clip '%s' joint %d at %.5g s: point error %.6g, bound %.6g (level %.6g + lattice %.6g + share %.6g)",
				         a->name, j, (double)t[i], e, bound, e0, lattice, share);
				fail = msg;
			}
		}
	}
	free(t), free(la), free(lb), free(wa), free(wb), free(rotq);
	mlod_clip_free(&common);
	return fail;
}

static double worst_level0, worst_level[4];

/* The TOC error of MOTION level l of clip q, or -1. */
static double toc_error(const void *pack, size_t size, int l, int q)
{
	mlod_pack p;
	mlod_error e = {0};
	if (mlod_pack_open(pack, size, &p, &e) != MLOD_OK)
		return -1;
	int ci = mlod_pack_find(&p, MLOD_CHUNK_MOTION, (unsigned)l, (unsigned)q);
	double r = ci >= 0 ? p.chunks[ci].error : -1;
	mlod_pack_close(&p);
	return r;
}
static int level0_fewer_keys; /* the sample's level 0 must have fewer keys than its input */

/* Packs path with opt, unpacks, writes and reloads the glb, compares. */
static const char *round_trip(const char *path, const mlod_pack_options *opt, char *msg, size_t cap)
{
	size_t n = 0;
	void *in = test_read_file(path, &n);
	if (!in) {
		snprintf(msg, cap, "cannot read %s", path);
		return msg;
	}
	mlod_gltf *doc = NULL, *un = NULL, *doc2 = NULL;
	mlod_character c, c2;
	mlod_format fmt, fmt2;
	mlod_error err = {0};
	void *pack = NULL, *glb = NULL;
	size_t pack_size = 0, glb_size = 0;
	const char *fail = NULL;
	memset(&c, 0, sizeof c);
	memset(&c2, 0, sizeof c2);
#define STEP(call)                                                                                 \
	do {                                                                                       \
		if ((call) != MLOD_OK) {                                                           \
			snprintf(msg, cap, "%s: %s", #call, err.message);                          \
			fail = msg;                                                                \
			goto done;                                                                 \
		}                                                                                  \
	} while (0)
#define FAIL(...)                                                                                  \
	do {                                                                                       \
		snprintf(msg, cap, __VA_ARGS__);                                                   \
		fail = msg;                                                                        \
		goto done;                                                                         \
	} while (0)
	STEP(mlod_load(in, n, NULL, &doc, &c, &fmt, &err));
	mlod_pack_stats st;
	STEP(mlod_pack_write(doc, &c, fmt, in, n, opt, &pack, &pack_size, &st, &err));
	STEP(mlod_pack_unpack(pack, pack_size, &un, &err));
	STEP(mlod_gltf_write(un, 1, &glb, &glb_size, &err));
	STEP(mlod_load(glb, glb_size, NULL, &doc2, &c2, &fmt2, &err));
	fprintf(stderr, "%s: pack %zu bytes, unpacked glb %zu bytes; levels: skeleton %d, mesh %d, motion %d\n", path,
	        pack_size, glb_size, st.skeleton.levels, st.mesh.levels, st.motion.levels);

	/* Skeleton: names, parents, rest exact. */
	if (c.skeleton.joint_count != c2.skeleton.joint_count)
		FAIL("%d joints, unpacked %d", c.skeleton.joint_count, c2.skeleton.joint_count);
	for (int j = 0; j < c.skeleton.joint_count; j++) {
		const mlod_joint *a = &c.skeleton.joints[j], *b = &c2.skeleton.joints[j];
		if (strcmp(a->name, b->name) || a->parent != b->parent || memcmp(&a->rest, &b->rest, sizeof a->rest))
			FAIL("joint %d (%s): name, parent or rest differs", j, a->name);
	}
	/* Skins: the input's skins come back first, exact. */
	for (int s = 0; s < c.skeleton.skin_count; s++) {
		const mlod_skin *a = &c.skeleton.skins[s], *b = NULL;
		for (int t = 0; t < c2.skeleton.skin_count; t++)
			if (c2.skeleton.skins[t].gltf_index == a->gltf_index)
				b = &c2.skeleton.skins[t];
		if (!b || a->joint_count != b->joint_count ||
		    memcmp(a->joints, b->joints, sizeof(int) * (size_t)a->joint_count) ||
		    memcmp(a->inverse_bind, b->inverse_bind, sizeof(mlod_mat4) * (size_t)a->joint_count))
			FAIL("skin %d differs", s);
	}
	/* The writer's grids: MESH level 0's part records. */
	mlod_pack pk = {0};
	mlod_pack_skeleton psk = {0};
	mlod_pack_mesh pm = {0};
	if (mlod_pack_open(pack, pack_size, &pk, &err) == MLOD_OK && mlod_pack_find(&pk, MLOD_CHUNK_MESH, 0, 0) >= 0 &&
	    (mlod_pack_decode_skeleton(&pk, pack, pack_size, &psk, &err) != MLOD_OK ||
	     mlod_pack_decode_mesh(&pk, (uint32_t)mlod_pack_find(&pk, MLOD_CHUNK_MESH, 0, 0), pack, pack_size, &psk, &pm,
	                           &err) != MLOD_OK)) {
		mlod_pack_skeleton_free(&psk);
		mlod_pack_close(&pk);
		FAIL("decoding MESH level 0: %s", err.message);
	}
	/* Meshes, per instance node. */
	if (c.instance_count != c2.instance_count)
		FAIL("%d instances, unpacked %d", c.instance_count, c2.instance_count);
	for (int i = 0; i < c.instance_count; i++) {
		const mlod_instance *a = &c.instances[i], *b = instance_of_node(&c2, a->node);
		if (!b)
			FAIL("instance of node %d missing", a->node);
		const mlod_mesh *ma = &c.meshes[a->mesh], *mb = &c2.meshes[b->mesh];
		int pb = 0;
		for (int p = 0; p < ma->primitive_count; p++) {
			if (ma->primitives[p].mode != 4)
				continue; /* the pack holds triangle primitives */
			if (pb >= mb->primitive_count)
				FAIL("node %d: primitive %d missing", a->node, p);
			char sub[512];
			qgrid pg, *grid = NULL;
			for (uint32_t q = 0; q < pm.part_count; q++)
				if (pm.parts[q].rec.node == a->node && pm.parts[q].rec.primitive == (uint32_t)p) {
					memcpy(pg.lo, pm.parts[q].rec.pos_min, sizeof pg.lo);
					memcpy(pg.scale, pm.parts[q].rec.pos_scale, sizeof pg.scale);
					grid = &pg;
				}
			const char *why = compare_primitive(&ma->primitives[p], &mb->primitives[pb++], grid, sub, sizeof sub);
			if (why) {
				mlod_pack_mesh_free(&pm), mlod_pack_skeleton_free(&psk), mlod_pack_close(&pk);
				FAIL("node %d primitive %d: %s", a->node, p, why);
			}
		}
	}
	mlod_pack_mesh_free(&pm), mlod_pack_skeleton_free(&psk), mlod_pack_close(&pk);
	/* Clips: level 0 under the clip's name, within mlod(5)'s bounds: key
	 * times exact or within MLOD_PACK_TICK_TOLERANCE of the clip's span,
	 * int16 rotations within MLOD_PACK_ROTQ_BOUND per component of the
	 * normalised key (q and -q
	 * are one rotation: the writer keeps signs continuous), other values
	 * exact; a channel whose keys are all equal may come back as one key
	 * at its last time. */
	double e0 = opt->motion_level0_percent ? opt->motion_level0_error * st.height / 100.0 : opt->motion_level0_error;
	double pd = opt->point_distance > 0 ? opt->point_distance
	                                    : mlod_motion_point_distance(&c.skeleton, fmt != MLOD_FORMAT_BVH);
	for (int k = 0; k < c.clip_count; k++) {
		const mlod_clip *a = &c.clips[k], *b = clip_named(&c2, a->name);
		if (!b)
			FAIL("clip '%s' missing", a->name);
		if (!opt->lossless_motion) {
			const char *why = level_within(&c, a, b, e0, toc_error(pack, pack_size, 0, k), pd, st.height, &worst_level0,
			                               msg, cap);
			if (why) {
				fail = why;
				goto done;
			}
			if (level0_fewer_keys && mlod_clip_key_count(b) >= mlod_clip_key_count(a))
				FAIL("clip '%s': level 0 keeps %ld of %ld keys", a->name, mlod_clip_key_count(b),
				     mlod_clip_key_count(a));
		}
		for (int ch = 0; opt->lossless_motion && ch < a->channel_count; ch++) {
			const mlod_channel *x = &a->channels[ch], *y = channel_of(b, x->joint, x->path);
			if (!y || y->interp != x->interp || (y->key_count != x->key_count && y->key_count != 1))
				FAIL("clip '%s' channel %d: missing or different keys", a->name, ch);
			int rot = x->path == MLOD_PATH_ROTATION && x->interp != MLOD_INTERP_CUBICSPLINE;
			int comps = (x->path == MLOD_PATH_ROTATION ? 4 : 3) * (x->interp == MLOD_INTERP_CUBICSPLINE ? 3 : 1);
			double span = fmax(fabs(x->times[x->key_count - 1]), fabs(x->times[0]));
			double ttol = MLOD_PACK_TICK_TOLERANCE * span + 1e-9;
			double vtol = rot ? MLOD_PACK_ROTQ_BOUND + 1e-7 : 0.0;
			for (int i = 0; i < x->key_count; i++) {
				int j = y->key_count == 1 ? 0 : i;
				if (y->key_count == x->key_count || i == x->key_count - 1)
					if (fabs((double)x->times[i] - y->times[j]) > ttol)
						FAIL("clip '%s' channel %d key %d: time %.9g, unpacked %.9g", a->name, ch, i, x->times[i],
						     y->times[j]);
				const float *xv = x->values + (size_t)comps * (size_t)i, *yv = y->values + (size_t)comps * (size_t)j;
				double e_pos = 0, e_neg = 0, len = 0;
				for (int v = 0; v < comps; v++)
					len += (double)xv[v] * xv[v];
				len = rot && len > 0 ? sqrt(len) : 1.0; /* ROTQ: against the normalised key */
				for (int v = 0; v < comps; v++) {
					e_pos = fmax(e_pos, fabs((double)xv[v] / len - yv[v]));
					e_neg = fmax(e_neg, fabs((double)xv[v] / len + yv[v]));
				}
				double e = rot ? fmin(e_pos, e_neg) : e_pos;
				if (e > vtol)
					FAIL("clip '%s' channel %d key %d: values off by %.3g (bound %.3g)", a->name, ch, i, e, vtol);
			}
		}
		/* Coarser levels are there too, each within its bound (the
		 * default bounds, which every level of the samples meets) and its
		 * TOC error, plus the ROTQ lattice's share. */
		for (int l = 1; l < st.motion.levels; l++) {
			char name[300];
			snprintf(name, sizeof name, "%s@lod%d", a->name, l);
			const mlod_clip *bl = clip_named(&c2, name);
			if (!bl)
				FAIL("clip '%s' missing", name);
			if (l > opt->motion_bound_count)
				continue;
			double bound = opt->motion_percent[l - 1] ? opt->motion_bounds[l - 1] * st.height / 100.0
			                                          : opt->motion_bounds[l - 1];
			const char *why = level_within(&c, a, bl, bound, toc_error(pack, pack_size, l, k), pd, st.height,
			                               &worst_level[l < 4 ? l : 3], msg, cap);
			if (why) {
				fail = why;
				goto done;
			}
		}
	}
done:
	mlod_character_free(&c);
	mlod_character_free(&c2);
	mlod_gltf_free(doc);
	mlod_gltf_free(doc2);
	mlod_gltf_free(un);
	mlod_free(pack);
	mlod_free(glb);
	free(in);
	return fail;
}

/* The pack at the given bits (0: the defaults) with motion level 0 within
 * its bound, then, motion only, with lossless_motion (keys exact). fewer:
 * level 0 must drop keys. */
static void sample_bits(const char *path, int pb, int nb, int ub, int fewer)
{
	char msg[1024];
	mlod_pack_options opt;
	mlod_pack_options_default(&opt);
	if (pb)
		opt.position_bits = pb, opt.normal_bits = nb, opt.uv_bits = ub;
	pos_bits = opt.position_bits, nrm_bits = opt.normal_bits, uv_bits = opt.uv_bits;
	worst_pos_ratio = worst_pos_err = worst_nrm = worst_uv_ratio = worst_w = worst_level0 = 0;
	degenerate_dropped = 0;
	memset(worst_level, 0, sizeof worst_level);
	level0_fewer_keys = fewer;
	const char *why = round_trip(path, &opt, msg, sizeof msg - 64);
	fprintf(stderr, "%s (bits %d %d %d): max position error %.3g (%.3f of the half-step bound), normal %.3g rad, uv %.3f of bound, "
	        "weight %.4f; motion level 0 point error %.3f of its bound, levels 1-3 %.3f %.3f %.3f; %ld level-0 triangles "
	        "dropped as degenerate\n", path, pos_bits, nrm_bits, uv_bits, worst_pos_err, worst_pos_ratio, worst_nrm,
	        worst_uv_ratio, worst_w, worst_level0, worst_level[1], worst_level[2], worst_level[3], degenerate_dropped);
	CHECK_MSG(!why, "%.200s: %.700s", path, why);
	opt.lossless_motion = 1;
	opt.no_skeleton_levels = opt.no_mesh_levels = 1;
	why = round_trip(path, &opt, msg, sizeof msg - 64);
	CHECK_MSG(!why, "%.200s (lossless motion): %.700s", path, why);
}

static void sample(const char *path, int fewer)
{
	sample_bits(path, 0, 0, 0, fewer);
}

/* Posed positions (mlod(5) QUANTISATION): at each pose, the unpacked
 * level 0 (mlod_posed_error, which takes the full character's diagonal
 * in that pose) is within the largest over the input's vertices of
 *   s |pos_scale| / 2 + (2 d + 4 * 3/1020) r
 * where s bounds the scale of the vertex's skinning matrices (the
 * Frobenius norm of their 3x3 part), d is the weight the pack drops past
 * the 4 largest influences, and r the largest distance between the
 * vertex carried by two of its joints; computed here, skinning the input
 * with the pose's matrices. Level 0's own measured error is 0. */
static double frob3(const mlod_mat4 *m)
{
	double f = 0;
	for (int c = 0; c < 3; c++)
		for (int r = 0; r < 3; r++)
			f += (double)m->m[4 * c + r] * m->m[4 * c + r];
	return sqrt(f);
}

/* hd_fixed > 0: that position bound (scene units through the skinning
 * scale, as the coarse levels' check gives it) for every vertex, instead
 * of half a step of bits of the primitive's box. */
static double pose_bound_bits(const mlod_character *c, const mlod_mat4 *world, int bits, double hd_fixed);
static double pose_bound(const mlod_character *c, const mlod_mat4 *world, int bits)
{
	return pose_bound_bits(c, world, bits, 0.0);
}

static double pose_bound_hd(const mlod_character *c, const mlod_mat4 *world, double hd_fixed)
{
	return pose_bound_bits(c, world, 16, hd_fixed);
}

static double pose_bound_bits(const mlod_character *c, const mlod_mat4 *world, int bits, double hd_fixed)
{
	double bound = 0;
	const mlod_skeleton *sk = &c->skeleton;
	for (int i = 0; i < c->instance_count; i++) {
		const mlod_instance *in = &c->instances[i];
		const mlod_skin *skin = in->skin >= 0 ? &sk->skins[in->skin] : NULL;
		mlod_mat4 rigid = in->joint >= 0 ? mlod_mat4_mul(&world[in->joint], &in->offset) : in->offset;
		const mlod_mesh *m = &c->meshes[in->mesh];
		for (int q = 0; q < m->primitive_count; q++) {
			const mlod_primitive *p = &m->primitives[q];
			if (p->mode != 4 || p->vertex_count <= 0)
				continue;
			double hd = 0;
			for (int a = 0; a < 3; a++) {
				float lo = INFINITY, hi = -INFINITY;
				for (int v = 0; v < p->vertex_count; v++)
					lo = fminf(lo, p->positions[3 * v + a]), hi = fmaxf(hi, p->positions[3 * v + a]);
				double step = ((double)hi - lo) / (ldexp(1.0, bits) - 1.0);
				hd += step * step;
			}
			hd = hd_fixed > 0 ? hd_fixed : sqrt(hd) / 2;
			for (int v = 0; v < p->vertex_count; v++) {
				mlod_v3 pos = {p->positions[3 * v], p->positions[3 * v + 1], p->positions[3 * v + 2]};
				if (!skin || p->weight_set_count == 0) {
					bound = fmax(bound, frob3(&rigid) * hd);
					continue;
				}
				mlod_v3 carried[4 * MLOD_MAX_SETS];
				float w[4 * MLOD_MAX_SETS];
				double s = 0, total = 0;
				int n = 0;
				for (int set = 0; set < p->weight_set_count; set++)
					for (int k = 0; k < 4; k++) {
						float wt = p->weights[set][4 * v + k];
						int jt = p->joints[set][4 * v + k];
						if (!(wt > 0) || jt >= skin->joint_count)
							continue;
						mlod_mat4 J = mlod_mat4_mul(&world[skin->joints[jt]], &skin->inverse_bind[jt]);
						s = fmax(s, frob3(&J));
						carried[n] = mlod_mat4_point(&J, pos);
						w[n++] = wt;
						total += wt;
					}
				for (int a = 0; a < n; a++) /* the 4 largest first */
					for (int b = a + 1; b < n; b++)
						if (w[b] > w[a]) {
							float t = w[a];
							w[a] = w[b], w[b] = t;
						}
				double dropped = 0, r = 0;
				for (int a = 4; a < n; a++)
					dropped += w[a] / total;
				for (int a = 0; a < n; a++)
					for (int b = a + 1; b < n; b++) {
						double dx = carried[a].x - carried[b].x, dy = carried[a].y - carried[b].y,
						       dz = carried[a].z - carried[b].z;
						r = fmax(r, sqrt(dx * dx + dy * dy + dz * dz));
					}
				bound = fmax(bound, s * hd + (2 * dropped + 4 * 3.0 / 1020) * r);
			}
		}
	}
	return bound;
}

static void posed_level0(const char *path)
{
	size_t n = 0, pack_size = 0, glb_size = 0;
	void *in = test_read_file(path, &n), *pack = NULL, *glb = NULL;
	mlod_gltf *doc = NULL, *un = NULL, *doc2 = NULL;
	mlod_character c, c2;
	mlod_format fmt, fmt2;
	mlod_pack_options opt;
	mlod_pose_set poses = {0};
	memset(&c, 0, sizeof c);
	memset(&c2, 0, sizeof c2);
	mlod_pack_options_default(&opt);
	opt.no_skeleton_levels = opt.no_motion_levels = 1;
	opt.ratio_count = 1, opt.ratios[0] = 0.5;
	CHECK(in);
	CHECK_OK(mlod_load(in, n, NULL, &doc, &c, &fmt, &terr));
	CHECK_OK(mlod_pack_write(doc, &c, fmt, in, n, &opt, &pack, &pack_size, NULL, &terr));
	CHECK_OK(mlod_pack_unpack(pack, pack_size, &un, &terr));
	CHECK_OK(mlod_gltf_write(un, 1, &glb, &glb_size, &terr));
	CHECK_OK(mlod_load(glb, glb_size, NULL, &doc2, &c2, &fmt2, &terr));
	CHECK_OK(mlod_pose_set_make(&c, 1, 8, 4, 7, 0.5f, &poses, &terr));
	double worst = 0, worst_err = 0;
	for (int k = 0; k < poses.count; k++) {
		const mlod_mat4 *world = poses.world + (size_t)k * (size_t)poses.joint_count;
		mlod_pose_set one = {1, poses.joint_count, (mlod_mat4 *)world, 0, NULL};
		mlod_deviation d;
		CHECK_OK(mlod_posed_error(&c, &c2, &one, &d, &terr));
		double got = d.max / 100 * d.scale, bound = pose_bound(&c, world, opt.position_bits);
		CHECK_MSG(got <= bound + 1e-6 * d.scale, "%s pose %d: posed error %g, bound %g", path, k, got, bound);
		worst = fmax(worst, bound > 0 ? got / bound : 0);
		worst_err = fmax(worst_err, d.max);
	}
	fprintf(stderr, "%s: level 0 posed, %d poses: max %.5f%% of the diagonal, %.3f of the bound at worst\n", path,
	        poses.count, worst_err, worst);
	mlod_pose_set_free(&poses);
	mlod_character_free(&c);
	mlod_character_free(&c2);
	mlod_gltf_free(doc);
	mlod_gltf_free(doc2);
	mlod_gltf_free(un);
	mlod_free(pack);
	mlod_free(glb);
	free(in);
}

/* Coarse levels (mlod(5) QUANTISATION, a vertex only coarse levels
 * have): the writer may round such a vertex, whose finest level is f,
 * within share times the smallest TOC error of levels f and coarser.
 * Checked here at each level k >= 1 against the level's own TOC error E
 * (at least that smallest one), computed without the writer's code: the
 * test makes the input's levels as mlod-pack does (mlod_mesh_levels with
 * the defaults) and decodes MESH level k with the reader. Every decoded
 * vertex of a part must have a vertex of the input level, and every
 * vertex the input level's triangles use a decoded one, within
 *   positions  half a step of the grid per axis, or share E / sigma as a
 *              distance (sigma: the largest singular value bound,
 *              lib/core's mlod_mat4_sigma_bound, of the part's rest
 *              skinning matrices);
 *   normals    the lattice bound at normal_bits (level 0's);
 *   UVs        half a step per axis, or share E rho / sigma as a
 *              distance, rho the 10% quantile over level 0's edges of UV
 *              length over length.
 * Then posed (the pose set of posed_level0): each level with its part
 * attributes swapped for the decoded ones has a Hausdorff error within
 * the input level's (measured here at the same poses) plus, over the
 * level's vertices, s d + (2 dropped + 4 * 3/1020) r, d the larger of
 * the two position bounds (pose_bound's terms). */
static int dcmp(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return x < y ? -1 : x > y;
}

/* The q quantile of UV (set) over 3D edge length over p's triangles. */
static double edge_stat(const mlod_primitive *p, int set, double q)
{
	int ni = p->index_count ? p->index_count : p->vertex_count;
	double *v = malloc(sizeof *v * (3 * (size_t)ni + 1));
	size_t n = 0;
	for (int t = 0; v && t + 3 <= ni; t += 3)
		for (int e = 0; e < 3; e++) {
			int a = p->index_count ? (int)p->indices[t + e] : t + e;
			int b = p->index_count ? (int)p->indices[t + (e + 1) % 3] : t + (e + 1) % 3;
			double d = 0, u = 0;
			for (int c = 0; c < 3; c++)
				d += pow((double)p->positions[3 * a + c] - p->positions[3 * b + c], 2);
			for (int c = 0; c < 2; c++)
				u += pow((double)p->uvs[set][2 * a + c] - p->uvs[set][2 * b + c], 2);
			if (d > 0 && u > 0)
				v[n++] = sqrt(u / d);
		}
	double r = 0;
	if (n) {
		qsort(v, n, sizeof *v, dcmp);
		r = v[(size_t)(q * (double)(n - 1))];
	}
	free(v);
	return r;
}

struct cbounds {
	double pos[3], pos_far, nrm, uv[MLOD_PACK_MAX_UV][2], uv_far[MLOD_PACK_MAX_UV];
	int sets;
};

/* Whether vertex u of a is within the bounds of vertex v of b; *far set
 * when only the coarse level's bounds hold. */
static int within(const mlod_primitive *a, int u, const float *bp, const float *bn, float *const *buv, int v,
                  const struct cbounds *B, int *far)
{
	double d2 = 0;
	int fine = 1;
	for (int c = 0; c < 3; c++) {
		double d = fabs((double)a->positions[3 * u + c] - bp[3 * v + c]);
		fine &= d <= B->pos[c];
		d2 += d * d;
	}
	int f = !fine;
	if (!fine && !(sqrt(d2) <= B->pos_far))
		return 0;
	if (a->normals && bn) {
		const float *x = a->normals + 3 * u, *y = bn + 3 * v;
		double cr[3] = {(double)x[1] * y[2] - (double)x[2] * y[1], (double)x[2] * y[0] - (double)x[0] * y[2],
		                (double)x[0] * y[1] - (double)x[1] * y[0]};
		double ang = atan2(sqrt(cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]),
		                   (double)x[0] * y[0] + (double)x[1] * y[1] + (double)x[2] * y[2]);
		double lx = sqrt((double)x[0] * x[0] + (double)x[1] * x[1] + (double)x[2] * x[2]);
		if (lx > 0.5 && ang > B->nrm)
			return 0;
	}
	for (int s = 0; s < B->sets; s++) {
		double e2 = 0;
		int ufine = 1;
		for (int c = 0; c < 2; c++) {
			double d = fabs((double)a->uvs[s][2 * u + c] - buv[s][2 * v + c]);
			ufine &= d <= B->uv[s][c];
			e2 += d * d;
		}
		if (!ufine) {
			if (!(sqrt(e2) <= B->uv_far[s]))
				return 0;
			f = 1;
		}
	}
	*far |= f;
	return 1;
}

/* Packs path at coarse_share write_share and checks every coarse level
 * against check_share; returns NULL or what failed. *coarse counts the
 * decoded vertices only the coarse bounds hold. */
static const char *coarse_levels(const char *path, double write_share, double check_share, long *coarse, char *msg,
                                 size_t cap)
{
	size_t n = 0, pack_size = 0;
	void *in = test_read_file(path, &n), *pack = NULL;
	mlod_gltf *doc = NULL;
	mlod_character c;
	mlod_format fmt;
	mlod_pack_options opt;
	mlod_mesh_levels ML;
	mlod_pose_set poses = {0};
	mlod_pack pk = {0};
	mlod_pack_skeleton psk = {0};
	const char *fail = NULL;
	memset(&c, 0, sizeof c);
	memset(&ML, 0, sizeof ML);
	*coarse = 0;
	mlod_pack_options_default(&opt);
	opt.coarse_share = write_share;
	if (!in || mlod_load(in, n, NULL, &doc, &c, &fmt, &terr) != MLOD_OK ||
	    mlod_pack_write(doc, &c, fmt, in, n, &opt, &pack, &pack_size, NULL, &terr) != MLOD_OK ||
	    mlod_pack_open(pack, pack_size, &pk, &terr) != MLOD_OK ||
	    mlod_pack_decode_skeleton(&pk, pack, pack_size, &psk, &terr) != MLOD_OK) {
		snprintf(msg, cap, "%s: load, pack or open: %s", path, terr.message);
		fail = msg;
		goto done;
	}
	/* The levels as mlod-pack makes them with its defaults. */
	double ratios[MLOD_MESH_MAX_LEVELS];
	memcpy(ratios, opt.ratios, sizeof ratios);
	qsort(ratios, (size_t)opt.ratio_count, sizeof *ratios, dcmp); /* increasing: the smallest first */
	mlod_bgm_options bo = opt.bgm;
	mlod_mesh_budget budget = opt.budget;
	mlod_mesh_resolve(&bo, &budget);
	for (int i = 0; i < opt.ratio_count / 2; i++) {
		double t = ratios[i];
		ratios[i] = ratios[opt.ratio_count - 1 - i], ratios[opt.ratio_count - 1 - i] = t;
	}
	if (mlod_mesh_levels_init(&ML, &c, &bo, budget, ratios[opt.ratio_count - 1], &terr) != MLOD_OK ||
	    mlod_mesh_levels_by_ratio(&ML, ratios, opt.ratio_count, &terr) != MLOD_OK ||
	    mlod_pose_set_make(&c, 1, 8, 4, 7, 0.5f, &poses, &terr) != MLOD_OK) {
		snprintf(msg, cap, "%s: levels: %s", path, terr.message);
		fail = msg;
		goto done;
	}
	mlod_mat4 *world = malloc(sizeof *world * ((size_t)c.skeleton.joint_count + 1));
	mlod_trs *local = malloc(sizeof *local * ((size_t)c.skeleton.joint_count + 1));
	mlod_pose_rest(&c.skeleton, local);
	mlod_pose_world(&c.skeleton, local, world);
	free(local);
	for (int k = 1; !fail && k <= ML.count; k++) {
		int ci = mlod_pack_find(&pk, MLOD_CHUNK_MESH, (unsigned)k, 0);
		mlod_pack_mesh pm = {0};
		if (ci < 0 || mlod_pack_decode_mesh(&pk, (uint32_t)ci, pack, pack_size, &psk, &pm, &terr) != MLOD_OK) {
			snprintf(msg, cap, "%s: MESH level %d: %s", path, k, ci < 0 ? "missing" : terr.message);
			fail = msg;
			break;
		}
		double E = pk.chunks[ci].error, hd_max = 0;
		mlod_mesh_level *L = &ML.levels[k - 1];
		mlod_primitive saved[64];
		int nsaved = 0, swapped[64][2];
		for (uint32_t q = 0; !fail && q < pm.part_count; q++) {
			const mlod_pack_part *pp = &pm.parts[q];
			int i = (int)pp->rec.instance, pr = (int)pp->rec.primitive;
			if (i >= c.instance_count || c.instances[i].node != pp->rec.node ||
			    pr >= L->meshes[i].primitive_count) {
				snprintf(msg, cap, "%s: level %d part %u: no input primitive", path, k, q);
				fail = msg;
				break;
			}
			mlod_primitive *A = &L->meshes[i].primitives[pr];
			const mlod_instance *inst = &c.instances[i];
			const mlod_primitive *A0 = &c.meshes[inst->mesh].primitives[pr];
			double sigma = 0;
			if (inst->skin >= 0 && A->weight_set_count > 0) {
				const mlod_skin *sk = &c.skeleton.skins[inst->skin];
				for (int j = 0; j < sk->joint_count; j++) {
					mlod_mat4 J = mlod_mat4_mul(&world[sk->joints[j]], &sk->inverse_bind[j]);
					sigma = fmax(sigma, mlod_mat4_sigma_bound(&J));
				}
			} else {
				mlod_mat4 R = inst->joint >= 0 ? mlod_mat4_mul(&world[inst->joint], &inst->offset) : inst->offset;
				sigma = mlod_mat4_sigma_bound(&R);
			}
			double far = sigma > 0 ? check_share * E / sigma : 0;
			struct cbounds B = {{0}, far, oct_bound(), {{0}}, {0}, (int)pp->rec.uv_sets};
			double hd = 0;
			for (int a = 0; a < 3; a++) {
				B.pos[a] = pp->rec.pos_scale[a] / 2.0 * (1 + 1e-4) + 1e-6 * fabs(pp->rec.pos_min[a]);
				hd += (double)pp->rec.pos_scale[a] * pp->rec.pos_scale[a];
			}
			hd_max = fmax(hd_max, fmax(sqrt(hd) / 2, far)); /* mesh units */
			B.pos_far = far * (1 + 1e-5) + 1e-6 * sqrt(hd) * 65535;
			for (int s = 0; s < B.sets; s++) {
				double rho = edge_stat(A0, s, 0.1), h2 = 0;
				for (int a = 0; a < 2; a++) {
					B.uv[s][a] = pp->rec.uv_scale[s][a] / 2.0 * (1 + 1e-4) + 1e-6 * fabs(pp->rec.uv_min[s][a]);
					h2 += (double)pp->rec.uv_scale[s][a] * pp->rec.uv_scale[s][a];
				}
				B.uv_far[s] = (sigma > 0 ? far * rho : 0) * (1 + 1e-5) + 1e-6 * sqrt(h2) * 65535;
			}
			/* decoded -> input */
			uint32_t nv = pp->rec.vertex_count;
			for (uint32_t u = 0; !fail && u < nv; u++) {
				int ok = 0, f = 0, fbest = 1;
				mlod_primitive D = {0};
				D.positions = pp->positions, D.normals = pp->normals;
				for (int s = 0; s < B.sets; s++)
					D.uvs[s] = pp->uvs[s];
				for (int v = 0; v < A->vertex_count && !(ok && !fbest); v++) {
					f = 0;
					if (within(&D, (int)u, A->positions, A->normals, A->uvs, v, &B, &f))
						ok = 1, fbest = fbest && f;
				}
				if (!ok) {
					snprintf(msg, cap, "%s: level %d part %u: decoded vertex %u (%g %g %g) has no input vertex within its bounds",
					         path, k, q, u, pp->positions[3 * u], pp->positions[3 * u + 1], pp->positions[3 * u + 2]);
					fail = msg;
				}
				*coarse += ok && fbest;
			}
			/* input -> decoded, the vertices its triangles use, but for the
			 * triangles quantisation may have made degenerate (two corners
			 * within a step on every axis: the writer drops them) */
			int ni = A->index_count ? A->index_count : A->vertex_count;
			unsigned char *used = calloc((size_t)A->vertex_count + 1, 1);
			for (int t = 0; used && t + 2 < ni; t += 3) {
				uint32_t c3[3];
				int near = 0;
				for (int i = 0; i < 3; i++)
					c3[i] = A->index_count ? A->indices[t + i] : (uint32_t)(t + i);
				for (int i = 0; i < 3; i++) {
					const float *x = A->positions + 3 * (size_t)c3[i], *y = A->positions + 3 * (size_t)c3[(i + 1) % 3];
					int close = 1;
					for (int a = 0; a < 3; a++)
						close = close && fabs((double)x[a] - y[a]) <= 2 * fmax(B.pos[a], B.pos_far);
					near |= close;
				}
				for (int i = 0; !near && i < 3; i++)
					used[c3[i]] = 1;
			}
			for (int v = 0; !fail && used && v < A->vertex_count; v++) {
				if (!used[v])
					continue;
				int ok = 0, f = 0;
				for (uint32_t u = 0; !ok && u < nv; u++) {
					mlod_primitive D = {0};
					D.positions = pp->positions, D.normals = pp->normals;
					for (int s = 0; s < B.sets; s++)
						D.uvs[s] = pp->uvs[s];
					ok = within(&D, (int)u, A->positions, A->normals, A->uvs, v, &B, &f);
				}
				if (!ok) {
					snprintf(msg, cap, "%s: level %d part %u: input vertex %d has no decoded vertex within its bounds", path,
					         k, q, v);
					fail = msg;
				}
			}
			free(used);
			/* swap the decoded attributes in for the posed check (a
			 * level primitive of its own only) */
			if (!fail && nsaved < 64 && A != A0 && (uint32_t)A->target_count == 0 && A->color_set_count == 0 &&
			    (!A->weight_set_count || pp->weights)) {
				saved[nsaved] = *A;
				swapped[nsaved][0] = i, swapped[nsaved][1] = pr;
				nsaved++;
				A->vertex_count = (int)nv, A->positions = pp->positions, A->normals = pp->normals;
				A->tangents = pp->tangents;
				for (int s = 0; s < B.sets; s++)
					A->uvs[s] = pp->uvs[s];
				if (A->weight_set_count)
					A->weight_set_count = 1, A->joints[0] = pp->joints, A->weights[0] = pp->weights;
				A->index_count = (int)pp->rec.index_count, A->indices = pp->indices;
			}
		}
		if (!fail) {
			/* posed: the level as decoded against the level as input */
			mlod_deviation dd, di;
			double qb = 0;
			int okp = mlod_posed_error(&c, &L->view, &poses, &dd, &terr) == MLOD_OK;
			for (int j = nsaved - 1; j >= 0; j--)
				L->meshes[swapped[j][0]].primitives[swapped[j][1]] = saved[j];
			nsaved = 0;
			okp = okp && mlod_posed_error(&c, &L->view, &poses, &di, &terr) == MLOD_OK;
			for (int pz = 0; okp && pz < poses.count; pz++)
				qb = fmax(qb, pose_bound_hd(&L->view, poses.world + (size_t)pz * (size_t)poses.joint_count, hd_max));
			double got = dd.max / 100 * dd.scale, base = di.max / 100 * di.scale;
			fprintf(stderr, "%s share %.3g (checked at %.3g) level %d: TOC error %.4g; posed max %.5g (input %.5g; %+.3f of the bound %.4g), as %% of the diagonal max %.5f (input %.5f), mean %.5f (input %.5f)\n",
			        path, write_share, check_share, k, E, got, base, qb > 0 ? (got - base) / qb : 0.0, qb, dd.max, di.max,
			        dd.mean, di.mean);
			if (!okp) {
				snprintf(msg, cap, "%s: level %d posed: %s", path, k, terr.message);
				fail = msg;
			} else if (got > base + qb + 1e-6 * dd.scale) {
				snprintf(msg, cap, "%s: level %d posed error %g, input level %g + bound %g", path, k, got, base, qb);
				fail = msg;
			}
		}
		for (int j = nsaved - 1; j >= 0; j--)
			L->meshes[swapped[j][0]].primitives[swapped[j][1]] = saved[j];
		mlod_pack_mesh_free(&pm);
	}
	free(world);
done:
	mlod_pose_set_free(&poses);
	mlod_mesh_levels_free(&ML);
	mlod_pack_skeleton_free(&psk);
	mlod_pack_close(&pk);
	mlod_character_free(&c);
	mlod_gltf_free(doc);
	mlod_free(pack);
	free(in);
	return fail;
}

static void coarse_sample(const char *path)
{
	char msg[1024];
	long coarse = 0, none = 0;
	nrm_bits = MLOD_PACK_NORMAL_BITS_DEFAULT;
	const char *why = coarse_levels(path, MLOD_PACK_COARSE_SHARE, MLOD_PACK_COARSE_SHARE, &coarse, msg, sizeof msg);
	CHECK_MSG(!why, "%.900s", why);
	fprintf(stderr, "%s: %ld decoded vertices of levels >= 1 within the coarse bounds only\n", path, coarse);
	CHECK_MSG(coarse > 0, "%s: no vertex rounded coarser than level 0's steps", path);
	/* The check fails on a pack rounded within four times the share. */
	why = coarse_levels(path, 4 * MLOD_PACK_COARSE_SHARE, MLOD_PACK_COARSE_SHARE, &coarse, msg, sizeof msg);
	CHECK_MSG(why != NULL, "%s: a pack at 4 times the share passed the check at the share", path);
	/* Share 0: every vertex on level 0's steps. */
	why = coarse_levels(path, 0.0, 0.0, &none, msg, sizeof msg);
	CHECK_MSG(!why, "%.900s", why);
	CHECK_MSG(none == 0, "%s: share 0: %ld vertices off level 0's steps", path, none);
}

/* Issue 11: a pack unpacked (-x) and packed again gives back its levels:
 * the unpacked document's stage record (mlod-record(5) version 3) names
 * them with the pack's errors, and the packer takes them instead of
 * making new ones. The second pack has the first's INFO (name, counts,
 * levels, bounds, height, diagonal) and, chunk for chunk, the same type,
 * layer, level, item, error and switch distance (but for the coarse mesh
 * levels of a pack with skeleton levels: -x binds them to those levels'
 * skins, and their errors are measured again); a layer the first pack
 * left at level 0 stays there. Which chunks also keep their bytes goes to
 * stderr (mlod-pack(1) BUGS says why the others do not). */
static void repack(const char *path, int no_skel, int no_mesh, int no_motion)
{
	size_t n = 0, size1 = 0, size2 = 0, glb_size = 0;
	void *in = test_read_file(path, &n), *pack1 = NULL, *pack2 = NULL, *glb = NULL;
	mlod_gltf *doc = NULL, *un = NULL, *doc2 = NULL;
	mlod_character c, c2;
	mlod_format fmt, fmt2;
	memset(&c, 0, sizeof c);
	memset(&c2, 0, sizeof c2);
	CHECK(in != NULL);
	if (!in)
		return;
	mlod_pack_options opt;
	mlod_pack_options_default(&opt);
	opt.name = "sample";
	opt.no_skeleton_levels = no_skel;
	opt.no_mesh_levels = no_mesh;
	opt.no_motion_levels = no_motion;
	CHECK_OK(mlod_load(in, n, NULL, &doc, &c, &fmt, &terr));
	CHECK_OK(mlod_pack_write(doc, &c, fmt, in, n, &opt, &pack1, &size1, NULL, &terr));
	CHECK_OK(mlod_pack_unpack(pack1, size1, &un, &terr));
	CHECK_OK(mlod_gltf_write(un, 1, &glb, &glb_size, &terr));
	CHECK_OK(mlod_load(glb, glb_size, NULL, &doc2, &c2, &fmt2, &terr));
	mlod_pack_options_default(&opt); /* packed again with the defaults */
	opt.default_name = "other";
	CHECK_OK(mlod_pack_write(doc2, &c2, fmt2, glb, glb_size, &opt, &pack2, &size2, NULL, &terr));

	mlod_pack p1, p2;
	mlod_pack_info i1, i2;
	memset(&i1, 0, sizeof i1);
	memset(&i2, 0, sizeof i2);
	CHECK_OK(mlod_pack_open(pack1, size1, &p1, &terr));
	CHECK_OK(mlod_pack_open(pack2, size2, &p2, &terr));
	CHECK_OK(mlod_pack_decode_info(&p1, pack1, size1, &i1, &terr));
	CHECK_OK(mlod_pack_decode_info(&p2, pack2, size2, &i2, &terr));
	const mlod_pack_info_rec *a = &i1.rec, *b = &i2.rec;
	CHECK_MSG(strcmp(i2.name, "sample") == 0, "%s: name '%s'", path, i2.name);
	CHECK_MSG(a->joint_count == b->joint_count && a->skin_count == b->skin_count &&
	              a->instance_count == b->instance_count && a->clip_count == b->clip_count,
	          "%s: joints %u/%u, skins %u/%u, parts %u/%u, clips %u/%u", path, a->joint_count, b->joint_count,
	          a->skin_count, b->skin_count, a->instance_count, b->instance_count, a->clip_count, b->clip_count);
	CHECK_MSG(a->skeleton_levels == b->skeleton_levels && a->mesh_levels == b->mesh_levels &&
	              a->motion_levels == b->motion_levels,
	          "%s: levels %u %u %u, packed again %u %u %u", path, a->skeleton_levels, a->mesh_levels, a->motion_levels,
	          b->skeleton_levels, b->mesh_levels, b->motion_levels);
	CHECK(memcmp(a->bounds_min, b->bounds_min, sizeof a->bounds_min) == 0 &&
	      memcmp(a->bounds_max, b->bounds_max, sizeof a->bounds_max) == 0);
	CHECK(a->height == b->height && a->diagonal == b->diagonal);
	if (no_skel)
		CHECK(a->skeleton_levels <= 1);
	if (no_mesh)
		CHECK(a->mesh_levels <= 1);
	if (no_motion)
		CHECK(a->motion_levels <= 1);
	for (uint32_t q = 0; q < a->clip_count && q < b->clip_count; q++)
		CHECK_MSG(strcmp(i1.clip_names[q], i2.clip_names[q]) == 0, "%s: clip %u", path, q);
	CHECK_MSG(p1.chunk_count == p2.chunk_count, "%s: %u chunks, packed again %u", path, p1.chunk_count,
	          p2.chunk_count);
	int same = 0, grew = 0;
	char kinds[256] = "";
	for (uint32_t i = 0; i < p1.chunk_count; i++) {
		const mlod_pack_chunk *x = &p1.chunks[i];
		int at = -1;
		for (uint32_t k = 0; k < p2.chunk_count; k++)
			if (p2.chunks[k].type == x->type && p2.chunks[k].level == x->level && p2.chunks[k].item == x->item)
				at = (int)k;
		CHECK_MSG(at >= 0, "%s: chunk %u (type %u level %u item %u) not packed again", path, i, x->type, x->level,
		          x->item);
		if (at < 0)
			continue;
		const mlod_pack_chunk *y = &p2.chunks[at];
		/* Every level keeps its error and distance, the coarse mesh levels
		 * of a pack with skeleton levels too: -x writes them with the
		 * weights the pack stores (the full skin), and the packer keeps
		 * them. Before, -x wrote them on the skeleton levels' skins, the
		 * packer measured them again, and tubeman's four grew (issue 11). */
		CHECK_MSG(x->layer == y->layer && x->error == y->error && x->distance == y->distance,
		          "%s: chunk %u (type %u level %u item %u): error %.9g distance %.9g, packed again %.9g %.9g", path, i,
		          x->type, x->level, x->item, x->error, x->distance, y->error, y->distance);
		if (x->type == MLOD_CHUNK_MESH && y->error > x->error)
			grew++;
		if (x->stored_size == y->stored_size &&
		    memcmp((const char *)pack1 + x->offset, (const char *)pack2 + y->offset, x->stored_size) == 0)
			same++;
		else if (!strstr(kinds, mlod_pack_type_name(x->type)) && strlen(kinds) < sizeof kinds - 8)
			strcat(strcat(kinds, " "), mlod_pack_type_name(x->type));
	}
	fprintf(stderr, "%s%s%s%s: %zu bytes, packed again %zu; %d of %u chunks the same bytes; differ:%s; %d mesh "
	        "level errors grew\n", path, no_skel ? " --no-skeleton-levels" : "", no_mesh ? " --no-mesh-levels" : "",
	        no_motion ? " --no-motion-levels" : "", size1, size2, same, p1.chunk_count, kinds[0] ? kinds : " none",
	        grew);

	/* The record itself: version 3 with the pack's errors, nothing invented. */
	mlod_record rec;
	CHECK_OK(mlod_record_read(un, &rec, &terr));
	CHECK(rec.version == MLOD_RECORD_VERSION && rec.has_pack && strcmp(rec.pack_name, "sample") == 0);
	if (c.skeleton.joint_count > 0)
		CHECK(rec.has_skel_levels && rec.skel_level_count == (int)a->skeleton_levels - 1);
	for (int k = 0; k < rec.skel_level_count; k++) {
		const mlod_record_skel_level *l = &rec.skel_levels[k];
		int ch = mlod_pack_find(&p1, MLOD_CHUNK_SKELETON, (uint32_t)k + 1, 0);
		CHECK(ch >= 0 && l->has_pack_error && (float)l->pack_error == p1.chunks[ch].error);
		CHECK(l->missing_threshold && l->missing_joint_error && !l->has_vertex_error);
	}
	CHECK(rec.mesh_level_count == (a->mesh_levels > 0 ? (int)a->mesh_levels - 1 : 0));
	for (int k = 0; k < rec.mesh_level_count; k++) {
		int ch = mlod_pack_find(&p1, MLOD_CHUNK_MESH, (uint32_t)k + 1, 0);
		CHECK(ch >= 0 && rec.mesh_levels[k].has_pack_error &&
		      (float)rec.mesh_levels[k].pack_error == p1.chunks[ch].error && rec.mesh_levels[k].missing_ratio &&
		      rec.mesh_levels[k].missing_error);
	}
	mlod_record_free(&rec);
	int motion0 = 0;
	for (int q = 0; q < mlod_gltf_count(un, MLOD_GLTF_ANIMATION); q++) {
		double pe = 0.0;
		int found = 0;
		CHECK_OK(mlod_record_read_motion0(un, q, &pe, &found, &terr));
		motion0 += found;
	}
	CHECK_MSG(motion0 == (c.skeleton.joint_count > 0 ? (int)a->clip_count : 0), "%s: %d clips with motion_level0",
	          path, motion0);

	mlod_pack_info_free(&i1);
	mlod_pack_info_free(&i2);
	mlod_pack_close(&p1);
	mlod_pack_close(&p2);
	mlod_free(pack1);
	mlod_free(pack2);
	mlod_free(glb);
	mlod_character_free(&c);
	mlod_character_free(&c2);
	mlod_gltf_free(doc);
	mlod_gltf_free(doc2);
	mlod_gltf_free(un);
	free(in);
}

TEST(repack_tubeman) { repack("samples/tubeman.glb", 0, 0, 0); }
TEST(repack_robot) { repack("samples/RobotExpressive.glb", 0, 0, 0); }
TEST(repack_bvh) { repack("samples/cmu_12_01_walk.bvh", 0, 0, 0); }
TEST(repack_level0_layers)
{
	repack("samples/tubeman.glb", 1, 0, 0);
	repack("samples/tubeman.glb", 0, 1, 0);
	repack("samples/tubeman.glb", 0, 0, 1);
}

TEST(coarse_tubeman) { coarse_sample("samples/tubeman.glb"); }
TEST(coarse_robot) { coarse_sample("samples/RobotExpressive.glb"); }
TEST(coarse_shared_ely)
{
	NEED_SHARED();
	char path[1024];
	snprintf(path, sizeof path, "%s/Ely.glb", getenv("MLOD_SHARED_DATA"));
	coarse_sample(path);
}

TEST(posed_tubeman) { posed_level0("samples/tubeman.glb"); }
TEST(posed_robot) { posed_level0("samples/RobotExpressive.glb"); }
TEST(posed_shared_ely)
{
	NEED_SHARED();
	char path[1024];
	snprintf(path, sizeof path, "%s/Ely.glb", getenv("MLOD_SHARED_DATA"));
	posed_level0(path);
}

TEST(round_trip_tubeman) { sample("samples/tubeman.glb", 1); }
TEST(round_trip_tubeman_16_bits) { sample_bits("samples/tubeman.glb", 16, 16, 16, 1); }
TEST(round_trip_tubeman_fewest_bits)
{
	sample_bits("samples/tubeman.glb", MLOD_PACK_POSITION_BITS_MIN, MLOD_PACK_NORMAL_BITS_MIN, MLOD_PACK_UV_BITS_MIN, 1);
}
TEST(round_trip_robot) { sample("samples/RobotExpressive.glb", 0); }
TEST(round_trip_bvh) { sample("samples/cmu_12_01_walk.bvh", 1); }

TEST(round_trip_shared_ely)
{
	NEED_SHARED();
	const char *dir = getenv("MLOD_SHARED_DATA");
	char path[1024];
	snprintf(path, sizeof path, "%s/Ely.glb", dir);
	sample(path, 0);
}

int main(void)
{
	RUN(round_trip_tubeman);
	RUN(round_trip_tubeman_16_bits);
	RUN(round_trip_tubeman_fewest_bits);
	RUN(round_trip_robot);
	RUN(round_trip_bvh);
	RUN(round_trip_shared_ely);
	RUN(posed_tubeman);
	RUN(posed_robot);
	RUN(posed_shared_ely);
	RUN(repack_tubeman);
	RUN(repack_robot);
	RUN(repack_bvh);
	RUN(repack_level0_layers);
	RUN(coarse_tubeman);
	RUN(coarse_robot);
	RUN(coarse_shared_ely);
	TEST_EXIT();
}
