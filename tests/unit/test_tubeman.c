/*
 * test_tubeman.c: the committed procedural sample samples/tubeman.glb.
 *
 * It must load, have one skin over the CMU skeleton's joints with sound
 * weights and inverse bind matrices, be a closed, consistently oriented
 * manifold once coincident vertices are welded, carry the walk with one key
 * per BVH frame, skin to a plausible body, and be byte-identical to what
 * tests/helpers/gen_tubeman (next to this program, in helpers/) makes now.
 */
#define _POSIX_C_SOURCE 200809L /* strdup, opendir */
#include <stdint.h>

#include "test.h"

#define BVH_PATH "samples/cmu_12_01_walk.bvh"
#define GLB_PATH "samples/tubeman.glb"

static const char *self_path = "build/release/tests/test_tubeman";

/* The BVH and the sample, loaded once. */
static mlod_character bvh;
static mlod_character tm;
static int fixture_state; /* 0: not loaded, 1: loaded, -1: failed */
static char fixture_msg[600];

static int load_fixture(void)
{
	if (fixture_state)
		return fixture_state > 0;
	fixture_state = -1;
	mlod_error err = { MLOD_OK, "" };
	size_t size;
	void *data = test_read_file(BVH_PATH, &size);
	if (!data) {
		snprintf(fixture_msg, sizeof fixture_msg, "cannot read %s", BVH_PATH);
		return 0;
	}
	mlod_result r = mlod_bvh_read(data, size, &bvh, &err);
	free(data);
	if (r != MLOD_OK) {
		snprintf(fixture_msg, sizeof fixture_msg, "%s: %s", BVH_PATH, err.message);
		return 0;
	}
	data = test_read_file(GLB_PATH, &size);
	if (!data) {
		snprintf(fixture_msg, sizeof fixture_msg, "cannot read %s", GLB_PATH);
		return 0;
	}
	mlod_gltf *doc = NULL;
	r = mlod_gltf_read(data, size, NULL, &doc, &err);
	free(data);
	if (r == MLOD_OK)
		r = mlod_gltf_to_character(doc, &tm, &err);
	mlod_gltf_free(doc);
	if (r != MLOD_OK) {
		snprintf(fixture_msg, sizeof fixture_msg, "%s: %s", GLB_PATH, err.message);
		return 0;
	}
	fixture_state = 1;
	return 1;
}

#define CHECK_FIXTURE() CHECK_MSG(load_fixture(), "%s", fixture_msg)

static const mlod_primitive *tube_primitive(void)
{
	return &tm.meshes[0].primitives[0];
}

static int bvh_joint_named(const char *name)
{
	for (int j = 0; j < bvh.skeleton.joint_count; j++)
		if (!strcmp(bvh.skeleton.joints[j].name, name))
			return j;
	return -1;
}

TEST(sample_loads)
{
	CHECK_FIXTURE();
	CHECK_OK(mlod_character_validate(&tm, &terr));
	CHECK(tm.skeleton.skin_count == 1);
	const mlod_skin *skin = &tm.skeleton.skins[0];
	CHECK_MSG(skin->joint_count == bvh.skeleton.joint_count, "skin has %d joints, BVH %d",
		  skin->joint_count, bvh.skeleton.joint_count);
	/* The skin's joints are the BVH's, each once. */
	char *seen = calloc((size_t)bvh.skeleton.joint_count, 1);
	CHECK(seen != NULL);
	int ok = 1;
	for (int k = 0; k < skin->joint_count && ok; k++) {
		int j = bvh_joint_named(tm.skeleton.joints[skin->joints[k]].name);
		ok = j >= 0 && !seen[j];
		if (ok)
			seen[j] = 1;
	}
	free(seen);
	CHECK_MSG(ok, "the skin's joints are not the BVH's joints");

	CHECK(tm.mesh_count == 1);
	CHECK(tm.meshes[0].primitive_count == 1);
	CHECK(tm.instance_count == 1);
	CHECK(tm.instances[0].mesh == 0 && tm.instances[0].skin == 0);
	const mlod_primitive *p = tube_primitive();
	CHECK(p->mode == 4);
	CHECK(p->material == 0);
	CHECK(p->index_count > 0 && p->index_count % 3 == 0);
	CHECK(p->normals != NULL);
	CHECK(p->uv_set_count >= 1);
	CHECK(p->weight_set_count == 1);
}

TEST(triangle_budget)
{
	CHECK_FIXTURE();
	int triangles = tube_primitive()->index_count / 3;
	CHECK_MSG(triangles >= 5000 && triangles <= 10000, "%d triangles", triangles);
}

/* inverse_bind[k] * rest world of joint k = identity. */
TEST(inverse_bind_is_rest_pose)
{
	CHECK_FIXTURE();
	const mlod_skeleton *s = &tm.skeleton;
	const mlod_skin *skin = &s->skins[0];
	mlod_trs *local = malloc((size_t)s->joint_count * sizeof *local);
	mlod_mat4 *world = malloc((size_t)s->joint_count * sizeof *world);
	CHECK(local && world);
	mlod_pose_rest(s, local);
	mlod_pose_world(s, local, world);
	double worst = 0.0;
	for (int k = 0; k < skin->joint_count; k++) {
		mlod_mat4 m = mlod_mat4_mul(&skin->inverse_bind[k], &world[skin->joints[k]]);
		mlod_mat4 id = mlod_mat4_identity();
		for (int i = 0; i < 16; i++)
			worst = fmax(worst, fabs((double)m.m[i] - id.m[i]));
	}
	free(local);
	free(world);
	CHECK_MSG(worst < 1e-4, "inverse bind * rest world differs from identity by %g", worst);
}

TEST(weights)
{
	CHECK_FIXTURE();
	const mlod_primitive *p = tube_primitive();
	int joints = tm.skeleton.skins[0].joint_count;
	for (int v = 0; v < p->vertex_count; v++) {
		const uint16_t *j = &p->joints[0][4 * v];
		const float *w = &p->weights[0][4 * v];
		double sum = 0.0;
		for (int i = 0; i < 4; i++) {
			CHECK_MSG(w[i] >= 0.0f && w[i] <= 1.0f, "vertex %d weight %g", v, w[i]);
			CHECK_MSG(j[i] < joints, "vertex %d joint %d of %d", v, j[i], joints);
			for (int k = 0; k < i; k++)
				CHECK_MSG(!(w[i] > 0 && w[k] > 0 && j[i] == j[k]),
					  "vertex %d lists joint %d twice", v, j[i]);
			sum += w[i];
		}
		CHECK_MSG(fabs(sum - 1.0) <= 1e-6, "vertex %d weights sum to %.9g", v, sum);
	}
}

TEST(normals_and_uvs)
{
	CHECK_FIXTURE();
	const mlod_primitive *p = tube_primitive();
	for (int v = 0; v < p->vertex_count; v++) {
		const float *n = &p->normals[3 * v];
		double len = sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
		CHECK_MSG(fabs(len - 1.0) < 1e-4, "vertex %d normal length %g", v, len);
		const float *uv = &p->uvs[0][2 * v];
		CHECK_MSG(uv[0] >= 0 && uv[0] <= 1 && uv[1] >= 0 && uv[1] <= 1,
			  "vertex %d uv (%g, %g)", v, uv[0], uv[1]);
	}
}

/* Orders vertex indices by position, for welding. */
static const float *sort_positions;
static int cmp_position(const void *a, const void *b)
{
	const float *p = &sort_positions[3 * *(const int *)a];
	const float *q = &sort_positions[3 * *(const int *)b];
	for (int c = 0; c < 3; c++)
		if (p[c] != q[c])
			return p[c] < q[c] ? -1 : 1;
	return 0;
}

static int cmp_u64(const void *a, const void *b)
{
	uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
	return x < y ? -1 : x > y;
}

/* Welded by position, every edge belongs to exactly two triangles that use
 * it in opposite directions, no triangle is degenerate, and the enclosed
 * volume is positive (the triangles face outwards). */
TEST(closed_manifold)
{
	CHECK_FIXTURE();
	const mlod_primitive *p = tube_primitive();
	int nv = p->vertex_count, nt = p->index_count / 3;
	int *order = malloc((size_t)nv * sizeof *order);
	int *rep = malloc((size_t)nv * sizeof *rep);
	uint64_t *edges = malloc((size_t)nt * 3 * sizeof *edges);
	CHECK(order && rep && edges);
	for (int v = 0; v < nv; v++)
		order[v] = v;
	sort_positions = p->positions;
	qsort(order, (size_t)nv, sizeof *order, cmp_position);
	for (int i = 0; i < nv; i++)
		rep[order[i]] = i > 0 && cmp_position(&order[i - 1], &order[i]) == 0
					? rep[order[i - 1]] : order[i];

	double size = mlod_skeleton_height(&bvh.skeleton);
	double volume = 0.0;
	int bad_triangle = -1, ne = 0;
	for (int t = 0; t < nt && bad_triangle < 0; t++) {
		const uint32_t *tri = &p->indices[3 * t];
		int a = rep[tri[0]], b = rep[tri[1]], c = rep[tri[2]];
		const float *pa = &p->positions[3 * a], *pb = &p->positions[3 * b];
		const float *pc = &p->positions[3 * c];
		double u[3], w[3], x[3];
		for (int k = 0; k < 3; k++) {
			u[k] = (double)pb[k] - pa[k];
			w[k] = (double)pc[k] - pa[k];
		}
		x[0] = u[1] * w[2] - u[2] * w[1];
		x[1] = u[2] * w[0] - u[0] * w[2];
		x[2] = u[0] * w[1] - u[1] * w[0];
		double area = 0.5 * sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
		if (a == b || b == c || a == c || !(area > 1e-9 * size * size))
			bad_triangle = t;
		volume += (pa[0] * ((double)pb[1] * pc[2] - (double)pb[2] * pc[1]) +
			   pa[1] * ((double)pb[2] * pc[0] - (double)pb[0] * pc[2]) +
			   pa[2] * ((double)pb[0] * pc[1] - (double)pb[1] * pc[0])) / 6.0;
		edges[ne++] = (uint64_t)a << 32 | (uint32_t)b;
		edges[ne++] = (uint64_t)b << 32 | (uint32_t)c;
		edges[ne++] = (uint64_t)c << 32 | (uint32_t)a;
	}
	int duplicate = 0, unmatched = 0;
	if (bad_triangle < 0) {
		qsort(edges, (size_t)ne, sizeof *edges, cmp_u64);
		for (int i = 0; i < ne; i++) {
			if (i > 0 && edges[i] == edges[i - 1])
				duplicate++;
			uint64_t back = edges[i] << 32 | edges[i] >> 32;
			if (!bsearch(&back, edges, (size_t)ne, sizeof *edges, cmp_u64))
				unmatched++;
		}
	}
	free(order);
	free(rep);
	free(edges);
	CHECK_MSG(bad_triangle < 0, "triangle %d is degenerate", bad_triangle);
	CHECK_MSG(duplicate == 0, "%d directed edges used twice (non-manifold or flipped)", duplicate);
	CHECK_MSG(unmatched == 0, "%d edges without an opposite (open boundary)", unmatched);
	CHECK_MSG(volume > 0.0, "enclosed volume %g: triangles face inwards", volume);
}

TEST(clip_has_bvh_frames)
{
	CHECK_FIXTURE();
	CHECK(bvh.clip_count >= 1 && bvh.clips[0].frame_count > 1);
	CHECK(tm.clip_count == 1);
	const mlod_clip *clip = &tm.clips[0];
	CHECK(clip->channel_count > 0);
	for (int i = 0; i < clip->channel_count; i++)
		CHECK_MSG(clip->channels[i].key_count == bvh.clips[0].frame_count,
			  "channel %d has %d keys, the BVH %d frames", i,
			  clip->channels[i].key_count, bvh.clips[0].frame_count);
	CHECK_NEAR(clip->duration, bvh.clips[0].duration, 1e-4);
}

/* Bounding box of the BVH's joints and End Sites posed at time t. */
static void bvh_joint_box(float t, double lo[3], double hi[3])
{
	const mlod_skeleton *s = &bvh.skeleton;
	mlod_trs *local = malloc((size_t)s->joint_count * sizeof *local);
	mlod_mat4 *world = malloc((size_t)s->joint_count * sizeof *world);
	mlod_pose_rest(s, local);
	mlod_clip_sample(&bvh.clips[0], t, local);
	mlod_pose_world(s, local, world);
	for (int c = 0; c < 3; c++) {
		lo[c] = HUGE_VAL;
		hi[c] = -HUGE_VAL;
	}
	for (int j = 0; j < s->joint_count; j++) {
		mlod_v3 p[2] = { mlod_mat4_point(&world[j], (mlod_v3){ 0, 0, 0 }),
				 mlod_mat4_point(&world[j], s->joints[j].end_site) };
		for (int e = 0; e < 1 + s->joints[j].has_end_site; e++) {
			double q[3] = { p[e].x, p[e].y, p[e].z };
			for (int c = 0; c < 3; c++) {
				lo[c] = fmin(lo[c], q[c]);
				hi[c] = fmax(hi[c], q[c]);
			}
		}
	}
	free(local);
	free(world);
}

/* Skins the sample at time t; checks the positions are finite and enclose
 * the BVH's posed skeleton without straying far from it. */
static void check_skinned_at(float t, const char *when)
{
	const mlod_skeleton *s = &tm.skeleton;
	const mlod_skin *skin = &s->skins[0];
	const mlod_primitive *p = tube_primitive();
	mlod_trs *local = malloc((size_t)s->joint_count * sizeof *local);
	mlod_mat4 *world = malloc((size_t)s->joint_count * sizeof *world);
	mlod_mat4 *mats = malloc((size_t)skin->joint_count * sizeof *mats);
	float *pos = malloc((size_t)p->vertex_count * 3 * sizeof *pos);
	CHECK(local && world && mats && pos);
	mlod_pose_rest(s, local);
	mlod_clip_sample(&tm.clips[0], t, local);
	mlod_pose_world(s, local, world);
	mlod_skin_matrices(skin, world, mats);
	mlod_skin_primitive(p, mats, pos, NULL);
	double lo[3] = { HUGE_VAL, HUGE_VAL, HUGE_VAL }, hi[3] = { -HUGE_VAL, -HUGE_VAL, -HUGE_VAL };
	int finite = 1;
	for (int i = 0; i < 3 * p->vertex_count; i++) {
		finite = finite && isfinite(pos[i]);
		lo[i % 3] = fmin(lo[i % 3], pos[i]);
		hi[i % 3] = fmax(hi[i % 3], pos[i]);
	}
	free(local);
	free(world);
	free(mats);
	free(pos);
	CHECK_MSG(finite, "%s: non-finite skinned positions", when);

	double jlo[3], jhi[3];
	bvh_joint_box(t, jlo, jhi);
	double size = mlod_skeleton_height(&bvh.skeleton);
	double mesh_extent = 0.0, joint_extent = 0.0;
	for (int c = 0; c < 3; c++) {
		/* Tubes surround the bones: the mesh box holds the joints, and
		 * exceeds them by at most about two tube radii. */
		CHECK_MSG(lo[c] <= jlo[c] + 1e-3 * size && hi[c] >= jhi[c] - 1e-3 * size,
			  "%s: axis %d: mesh [%g, %g] does not hold the joints [%g, %g]", when, c,
			  lo[c], hi[c], jlo[c], jhi[c]);
		CHECK_MSG(jlo[c] - lo[c] < 0.2 * size && hi[c] - jhi[c] < 0.2 * size,
			  "%s: axis %d: mesh [%g, %g] strays from the joints [%g, %g]", when, c,
			  lo[c], hi[c], jlo[c], jhi[c]);
		mesh_extent = fmax(mesh_extent, hi[c] - lo[c]);
		joint_extent = fmax(joint_extent, jhi[c] - jlo[c]);
	}
	double ratio = mesh_extent / joint_extent;
	CHECK_MSG(ratio >= 1.0 && ratio < 1.3, "%s: mesh height %g, skeleton %g", when,
		  mesh_extent, joint_extent);
}

TEST(skinned_frame_0)
{
	CHECK_FIXTURE();
	check_skinned_at(0.0f, "frame 0");
}

TEST(skinned_mid_clip)
{
	CHECK_FIXTURE();
	check_skinned_at(0.5f * tm.clips[0].duration, "mid-clip");
}

/* The generator next to this program remakes the committed sample exactly. */
TEST(regenerates_identically)
{
	char dir[1024], gen[1200], out[1200], cmd[3000];
	const char *slash = strrchr(self_path, '/');
	int n = slash ? (int)(slash - self_path) : 1;
	snprintf(dir, sizeof dir, "%.*s", n, slash ? self_path : ".");
	/* The generator of the same build; else the one tests/run.sh names. */
	snprintf(gen, sizeof gen, "%s/helpers/gen_tubeman", dir);
	FILE *f = fopen(gen, "rb");
	const char *helpers = getenv("HELPERS");
	if (!f && helpers && *helpers) {
		snprintf(gen, sizeof gen, "%s/gen_tubeman", helpers);
		f = fopen(gen, "rb");
	}
	CHECK_MSG(f != NULL, "cannot find the generator %.300s (make unit builds it)", gen);
	fclose(f);
	snprintf(out, sizeof out, "%s/tubeman-regenerated.glb", dir);
	remove(out);
	snprintf(cmd, sizeof cmd, "\"%s\" %s \"%s\" > /dev/null", gen, BVH_PATH, out);
	CHECK_MSG(system(cmd) == 0, "%.600s failed", cmd);

	size_t a_size, b_size;
	void *a = test_read_file(GLB_PATH, &a_size);
	void *b = test_read_file(out, &b_size);
	int same = a && b && a_size == b_size && !memcmp(a, b, a_size);
	free(a);
	free(b);
	CHECK_MSG(same, "%.300s (%zu bytes) differs from %s (%zu bytes): run make samples", out, b_size,
		  GLB_PATH, a_size);
	remove(out);
}

int main(int argc, char **argv)
{
	if (argc > 0 && argv[0] && strchr(argv[0], '/'))
		self_path = argv[0];
	RUN(sample_loads);
	RUN(triangle_budget);
	RUN(inverse_bind_is_rest_pose);
	RUN(weights);
	RUN(normals_and_uvs);
	RUN(closed_manifold);
	RUN(clip_has_bvh_frames);
	RUN(skinned_frame_0);
	RUN(skinned_mid_clip);
	RUN(regenerates_identically);
	mlod_character_free(&bvh);
	mlod_character_free(&tm);
	TEST_EXIT();
}
