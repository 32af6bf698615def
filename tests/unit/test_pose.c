/* test_pose.c: character validation, clip sampling, forward kinematics, skinning, posing. */
#include "test.h"

#define PI 3.14159265358979323846

static float *floats(int n, const float *v)
{
	float *p = malloc((size_t)n * sizeof *p);
	memcpy(p, v, (size_t)n * sizeof *p);
	return p;
}

static char *str(const char *s)
{
	char *p = malloc(strlen(s) + 1);
	strcpy(p, s);
	return p;
}

static mlod_v3 v3(float x, float y, float z)
{
	mlod_v3 v = { x, y, z };
	return v;
}

/* A chain root -> a -> b along +y, 1 unit apart, one skin over all three,
 * a skinned mesh (one triangle, indexed), a rigid mesh on joint b (one
 * triangle, not indexed, plus a line primitive that must be ignored) and a
 * clip turning joint a about z. Everything heap-allocated, as readers do. */
static void build_chain(mlod_character *c)
{
	memset(c, 0, sizeof *c);
	const char *names[3] = { "Root", "A", "B" };
	c->skeleton.joint_count = 3;
	c->skeleton.joints = calloc(3, sizeof(mlod_joint));
	for (int i = 0; i < 3; i++) {
		mlod_joint *j = &c->skeleton.joints[i];
		j->name = str(names[i]);
		j->parent = i - 1;
		j->rest = mlod_trs_identity();
		j->rest.t.y = i == 0 ? 0.0f : 1.0f;
		j->base = mlod_mat4_identity();
		j->node = i;
	}
	c->skeleton.joints[0].base.m[12] = 10.0f; /* the root sits under a node at x = 10 */
	c->skeleton.skin_count = 1;
	mlod_skin *sk = c->skeleton.skins = calloc(1, sizeof(mlod_skin));
	sk->name = str("skin");
	sk->joint_count = 3;
	sk->joints = malloc(3 * sizeof(int));
	sk->inverse_bind = malloc(3 * sizeof(mlod_mat4));
	for (int k = 0; k < 3; k++) {
		sk->joints[k] = k;
		sk->inverse_bind[k] = mlod_mat4_identity();
		sk->inverse_bind[k].m[12] = -10.0f;
		sk->inverse_bind[k].m[13] = -(float)k; /* joint k at (10, k, 0) in bind */
	}

	c->mesh_count = 2;
	c->meshes = calloc(2, sizeof(mlod_mesh));
	mlod_mesh *m = &c->meshes[0];
	m->name = str("body");
	m->primitive_count = 1;
	m->primitives = calloc(1, sizeof(mlod_primitive));
	mlod_primitive *p = &m->primitives[0];
	const float pos[9] = { 10, 1, 0, 11, 2, 0, 10, 2, 1 };
	p->vertex_count = 3;
	p->positions = floats(9, pos);
	const float nrm[9] = { 0, 0, 1, 0, 0, 1, 0, 0, 1 };
	p->normals = floats(9, nrm);
	p->weight_set_count = 1;
	p->joints[0] = calloc(12, sizeof(uint16_t));
	p->weights[0] = calloc(12, sizeof(float));
	p->joints[0][0] = 1, p->weights[0][0] = 1.0f;                                        /* v0: A */
	p->joints[0][4] = 1, p->weights[0][4] = 0.5f, p->joints[0][5] = 2, p->weights[0][5] = 0.5f; /* v1: A+B */
	p->joints[0][8] = 2, p->weights[0][8] = 1.0f;                                        /* v2: B */
	p->index_count = 3;
	p->indices = malloc(3 * sizeof(uint32_t));
	p->indices[0] = 0, p->indices[1] = 1, p->indices[2] = 2;
	p->mode = 4;
	p->material = -1;
	p->uv_set_count = 1;
	const float uv[6] = { 0 };
	p->uvs[0] = floats(6, uv);
	p->target_count = 1;
	p->targets = calloc(1, sizeof(mlod_morph_target));
	p->targets[0].positions = floats(9, pos);

	m = &c->meshes[1];
	m->name = str("hat");
	m->primitive_count = 2;
	m->primitives = calloc(2, sizeof(mlod_primitive));
	const float hat[9] = { 0, 0, 0, 1, 0, 0, 0, 0, 1 };
	m->primitives[0].vertex_count = 3;
	m->primitives[0].positions = floats(9, hat);
	m->primitives[0].mode = 4;
	m->primitives[1].vertex_count = 2;
	m->primitives[1].positions = floats(6, hat);
	m->primitives[1].mode = 1; /* lines */

	c->instance_count = 2;
	c->instances = calloc(2, sizeof(mlod_instance));
	c->instances[0].mesh = 0, c->instances[0].skin = 0, c->instances[0].joint = -1;
	c->instances[0].offset = mlod_mat4_identity();
	c->instances[1].mesh = 1, c->instances[1].skin = -1, c->instances[1].joint = 2;
	c->instances[1].offset = mlod_mat4_identity();
	c->instances[1].offset.m[13] = 0.5f; /* half a unit above B */

	c->clip_count = 1;
	mlod_clip *clip = c->clips = calloc(1, sizeof(mlod_clip));
	clip->name = str("bend");
	clip->duration = 1.0f;
	clip->channel_count = 1;
	clip->channels = calloc(1, sizeof(mlod_channel));
	mlod_quat q0 = mlod_quat_identity(), q1 = mlod_quat_axis_angle(v3(0, 0, 1), (float)(PI / 2));
	const float t[2] = { 0, 1 }, r[8] = { q0.x, q0.y, q0.z, q0.w, q1.x, q1.y, q1.z, q1.w };
	clip->channels[0].joint = 1;
	clip->channels[0].path = MLOD_PATH_ROTATION;
	clip->channels[0].interp = MLOD_INTERP_LINEAR;
	clip->channels[0].key_count = 2;
	clip->channels[0].times = floats(2, t);
	clip->channels[0].values = floats(8, r);
	c->notes = str("nothing skipped");
}

/* ---------------------------------------------------------------- */
/* Character                                                         */
/* ---------------------------------------------------------------- */

TEST(validate_accepts_and_free_zeroes)
{
	mlod_character c;
	build_chain(&c);
	CHECK_OK(mlod_character_validate(&c, &terr));
	mlod_character_free(&c);
	CHECK(c.skeleton.joints == NULL && c.meshes == NULL && c.notes == NULL && c.clip_count == 0);
	mlod_character_free(&c); /* twice is harmless once zeroed */
	mlod_character_free(NULL);
	CHECK_OK(mlod_character_validate(&c, &terr)); /* the empty character is valid */
}

/* Builds the chain, breaks it with a change, and expects validation to fail
 * with a message containing want. */
#define EXPECT_INVALID(change, want)                                                   \
	do {                                                                           \
		mlod_character c_;                                                     \
		mlod_error e_ = { 0 };                                                 \
		build_chain(&c_);                                                      \
		mlod_character *c = &c_;                                               \
		change;                                                                \
		mlod_result r_ = mlod_character_validate(c, &e_);                      \
		mlod_character_free(&c_);                                              \
		CHECK_MSG(r_ == MLOD_ERR_PARSE, "%s: returned %d", #change, (int)r_);  \
		CHECK_MSG(strstr(e_.message, want), "message \"%s\" lacks \"%s\"", e_.message, want); \
	} while (0)

TEST(validate_names_first_problem)
{
	EXPECT_INVALID(c->skeleton.joints[1].parent = 2, "joint 1 \"A\": parent 2 comes after it");
	EXPECT_INVALID(c->skeleton.joints[1].parent = 1, "parent 1 comes after it");
	EXPECT_INVALID(c->skeleton.joints[2].parent = 7, "joint 2 \"B\": parent 7 out of range");
	EXPECT_INVALID(c->skeleton.joints[2].rest.r.x = NAN, "joint 2 \"B\": rest");
	EXPECT_INVALID(c->skeleton.skins[0].joints[1] = 3, "skin 0: joint 1 is 3");
	EXPECT_INVALID(c->skeleton.skins[0].inverse_bind[2].m[5] = INFINITY, "inverse bind matrix 2");
	EXPECT_INVALID(c->meshes[0].primitives[0].positions[4] = NAN, "position of vertex 1");
	EXPECT_INVALID(c->meshes[0].primitives[0].indices[2] = 3, "index 2 is 3");
	EXPECT_INVALID(c->meshes[0].primitives[0].weights[0][5] = -0.5f, "vertex 1 has weight -0.5");
	EXPECT_INVALID(c->meshes[0].primitives[0].joints[0][8] = 3, "vertex 2 uses joint 3 of a skin with 3 joints");
	EXPECT_INVALID(c->instances[1].mesh = 2, "instance 1: mesh 2");
	EXPECT_INVALID(c->instances[0].skin = 1, "instance 0: skin 1");
	EXPECT_INVALID(c->instances[1].joint = 3, "instance 1: joint 3");
	EXPECT_INVALID(c->clips[0].channels[0].joint = 3, "channel 0: joint 3");
	EXPECT_INVALID(c->clips[0].channels[0].times[1] = 0.0f, "key 1 time 0 does not follow 0");
	EXPECT_INVALID(c->clips[0].channels[0].values[6] = NAN, "key 1 value");
	/* a zero-weight influence may name any joint: skinning ignores it */
	mlod_character c;
	build_chain(&c);
	c.meshes[0].primitives[0].joints[0][11] = 99;
	CHECK_OK(mlod_character_validate(&c, &terr));
	/* an unskinned instance of the skinned mesh does not check skin ranges */
	c.meshes[0].primitives[0].joints[0][8] = 99;
	c.instances[0].skin = -1;
	CHECK_OK(mlod_character_validate(&c, &terr));
	mlod_character_free(&c);
}

TEST(skeleton_height)
{
	mlod_character c;
	build_chain(&c);
	/* Root (10, 0, 0), A (10, 1, 0), B (10, 2, 0): 2 tall. */
	CHECK_NEAR(mlod_skeleton_height(&c.skeleton), 2.0, 1e-6);
	CHECK_NEAR(mlod_skeleton_extent(&c.skeleton), 2.0, 1e-6);
	/* An arm: B 3 out along x from A. The height is along +Y (1), not the
	 * span (3), while Y is at least a quarter of the largest extent. */
	c.skeleton.joints[2].rest.t = v3(3, 0, 0);
	CHECK_NEAR(mlod_skeleton_height(&c.skeleton), 1.0, 1e-6);
	CHECK_NEAR(mlod_skeleton_extent(&c.skeleton), 3.0, 1e-6);
	/* Lying down: B 5 out along z, Y (1) under a quarter of 5: the
	 * largest extent. */
	c.skeleton.joints[2].rest.t = v3(0, 0, 5);
	CHECK_NEAR(mlod_skeleton_height(&c.skeleton), 5.0, 1e-6);
	/* Modelled Z-up under a node turning it Y-up (-90 degrees about x):
	 * the root's base counts. A 1 up z, B 1.5 out along x. */
	c.skeleton.joints[1].rest.t = v3(0, 0, 1);
	c.skeleton.joints[2].rest.t = v3(1.5f, 0, 0);
	CHECK_NEAR(mlod_skeleton_height(&c.skeleton), 1.5, 1e-6); /* flat without the base */
	mlod_trs up = mlod_trs_identity();
	up.r = mlod_quat_axis_angle(v3(1, 0, 0), -1.5707963f);
	up.t = v3(10, 0, 0);
	c.skeleton.joints[0].base = mlod_mat4_from_trs(&up);
	CHECK_NEAR(mlod_skeleton_height(&c.skeleton), 1.0, 1e-5);
	CHECK_NEAR(mlod_skeleton_extent(&c.skeleton), 1.5, 1e-5);
	c.skeleton.joint_count = 1; /* one point: still a usable scale */
	CHECK(mlod_skeleton_height(&c.skeleton) > 0.0f);
	CHECK(mlod_skeleton_extent(&c.skeleton) > 0.0f);
	c.skeleton.joint_count = 0; /* nothing to measure */
	CHECK(mlod_skeleton_height(&c.skeleton) == 0.0f);
	c.skeleton.joint_count = 3;
	mlod_character_free(&c);
}

/* ---------------------------------------------------------------- */
/* Sampling                                                          */
/* ---------------------------------------------------------------- */

static mlod_channel channel(int joint, mlod_path path, mlod_interp interp, int keys, float *times, float *values)
{
	mlod_channel ch = { joint, path, interp, keys, times, values, 0 };
	return ch;
}

static mlod_clip clip_of(mlod_channel *ch, int n, float duration)
{
	mlod_clip c = { "test", duration, 0.0f, 0, n, ch, -1 };
	return c;
}

TEST(linear_and_step)
{
	float times[3] = { 0.5f, 1.0f, 2.0f };
	float tv[9] = { 0, 0, 0, 1, 2, 3, 3, 2, 1 };
	mlod_channel ch[2] = { channel(0, MLOD_PATH_TRANSLATION, MLOD_INTERP_LINEAR, 3, times, tv),
	                       channel(1, MLOD_PATH_SCALE, MLOD_INTERP_STEP, 3, times, tv) };
	mlod_clip clip = clip_of(ch, 2, 2.0f);
	mlod_trs pose[2];
	const float t[] = { 0.5f, 1.0f, 2.0f, 0.75f, 1.5f, 0.0f, -3.0f, 9.0f, 1.999f };
	const float lin_x[] = { 0, 1, 3, 0.5f, 2, 0, 0, 3, 2.998f };
	const float step_x[] = { 0, 1, 3, 0, 1, 0, 0, 3, 1 };
	for (size_t i = 0; i < sizeof t / sizeof t[0]; i++) {
		pose[0] = pose[1] = mlod_trs_identity();
		mlod_clip_sample(&clip, t[i], pose);
		CHECK_MSG(fabs(pose[0].t.x - lin_x[i]) < 1e-5, "linear at %g: %g", t[i], pose[0].t.x);
		CHECK_MSG(fabs(pose[1].s.x - step_x[i]) < 1e-6, "step at %g: %g", t[i], pose[1].s.x);
		CHECK(pose[0].r.w == 1.0f && pose[0].s.x == 1.0f); /* untouched paths keep the pose */
	}
	mlod_clip_sample(&clip, 1.25f, pose);
	CHECK_NEAR(pose[0].t.y, 2.0, 1e-6);
	CHECK_NEAR(pose[0].t.z, 2.5, 1e-6);
	CHECK_NEAR(pose[1].s.z, 3.0, 1e-6);
}

TEST(rotation_interpolation)
{
	mlod_quat q0 = mlod_quat_axis_angle(v3(0, 1, 0), 0.2f), q1 = mlod_quat_axis_angle(v3(0, 1, 0), 2.2f);
	/* the second key stored as -q1: the same rotation, must take the short way */
	float times[2] = { 0, 1 }, rv[8] = { q0.x, q0.y, q0.z, q0.w, -q1.x, -q1.y, -q1.z, -q1.w };
	mlod_channel ch = channel(0, MLOD_PATH_ROTATION, MLOD_INTERP_LINEAR, 2, times, rv);
	mlod_clip clip = clip_of(&ch, 1, 1.0f);
	mlod_trs pose = mlod_trs_identity();
	for (int i = 0; i <= 10; i++) {
		mlod_clip_sample(&clip, i / 10.0f, &pose);
		mlod_quat want = mlod_quat_axis_angle(v3(0, 1, 0), 0.2f + 2.0f * i / 10.0f);
		CHECK_MSG(mlod_quat_angle(pose.r, want) < 1e-4, "at %d: off by %g", i, mlod_quat_angle(pose.r, want));
		CHECK_NEAR(pose.r.x * pose.r.x + pose.r.y * pose.r.y + pose.r.z * pose.r.z + pose.r.w * pose.r.w, 1, 1e-5);
	}
	/* STEP rotations with non-unit keys come out normalised */
	float sv[8] = { 0, 0, 0, 2, 0, 3, 0, 0 };
	ch = channel(0, MLOD_PATH_ROTATION, MLOD_INTERP_STEP, 2, times, sv);
	mlod_clip_sample(&clip, 0.5f, &pose);
	CHECK_NEAR(pose.r.w, 1, 1e-6);
	mlod_clip_sample(&clip, 1.0f, &pose);
	CHECK_NEAR(pose.r.y, 1, 1e-6);
}

TEST(single_key_is_constant)
{
	float times[1] = { 0.7f }, tv[3] = { 4, 5, 6 }, cv[9] = { 9, 9, 9, 1, 2, 3, 9, 9, 9 };
	mlod_channel ch[2] = { channel(0, MLOD_PATH_TRANSLATION, MLOD_INTERP_LINEAR, 1, times, tv),
	                       channel(1, MLOD_PATH_TRANSLATION, MLOD_INTERP_CUBICSPLINE, 1, times, cv) };
	mlod_clip clip = clip_of(ch, 2, 2.0f);
	const float t[] = { 0, 0.7f, 1.5f };
	for (int i = 0; i < 3; i++) {
		mlod_trs pose[2] = { mlod_trs_identity(), mlod_trs_identity() };
		mlod_clip_sample(&clip, t[i], pose);
		CHECK(pose[0].t.x == 4.0f && pose[0].t.z == 6.0f);
		CHECK(pose[1].t.x == 1.0f && pose[1].t.z == 3.0f);
	}
}

TEST(cubic_spline_hand_computed)
{
	/* One component (x), keys at t = 1 and 3 (interval 2):
	 * key 0: value 0, out-tangent 1;  key 1: in-tangent -2, value 4.
	 * At t = 2, s = 0.5: h00 = 0.5, h10 = 0.125, h01 = 0.5, h11 = -0.125
	 * p = 0.5*0 + 0.125*2*1 + 0.5*4 + (-0.125)*2*(-2) = 0.25 + 2 + 0.5 = 2.75
	 * At t = 1.5, s = 0.25: h00 = 0.84375, h10 = 0.140625, h01 = 0.15625, h11 = -0.046875
	 * p = 0.140625*2*1 + 0.15625*4 + (-0.046875)*2*(-2) = 0.28125 + 0.625 + 0.1875 = 1.09375 */
	float times[2] = { 1, 3 };
	float v[18] = { 7, 7, 7, 0, 10, 0, 1, 0, 0, /* key 0: in, value, out */
	                -2, 0, 0, 4, 20, 0, 7, 7, 7 /* key 1 */ };
	mlod_channel ch = channel(0, MLOD_PATH_TRANSLATION, MLOD_INTERP_CUBICSPLINE, 2, times, v);
	mlod_clip clip = clip_of(&ch, 1, 3.0f);
	mlod_trs pose = mlod_trs_identity();
	mlod_clip_sample(&clip, 2.0f, &pose);
	CHECK_NEAR(pose.t.x, 2.75, 1e-6);
	CHECK_NEAR(pose.t.y, 15.0, 1e-5); /* zero tangents: the smoothstep midpoint */
	mlod_clip_sample(&clip, 1.5f, &pose);
	CHECK_NEAR(pose.t.x, 1.09375, 1e-6);
	mlod_clip_sample(&clip, 1.0f, &pose);
	CHECK_NEAR(pose.t.x, 0.0, 1e-6);
	mlod_clip_sample(&clip, 3.0f, &pose);
	CHECK_NEAR(pose.t.x, 4.0, 1e-6);
	mlod_clip_sample(&clip, 0.5f, &pose); /* before the first key */
	CHECK_NEAR(pose.t.y, 10.0, 1e-6);
}

TEST(cubic_spline_rotation_normalised)
{
	mlod_quat q0 = mlod_quat_identity(), q1 = mlod_quat_axis_angle(v3(1, 0, 0), 1.5f);
	float times[2] = { 0, 1 };
	float v[24] = { 0, 0, 0, 0, q0.x, q0.y, q0.z, q0.w, 0, 0, 0, 0,
	                0, 0, 0, 0, q1.x, q1.y, q1.z, q1.w, 0, 0, 0, 0 };
	mlod_channel ch = channel(0, MLOD_PATH_ROTATION, MLOD_INTERP_CUBICSPLINE, 2, times, v);
	mlod_clip clip = clip_of(&ch, 1, 1.0f);
	mlod_trs pose = mlod_trs_identity();
	mlod_clip_sample(&clip, 0.5f, &pose);
	CHECK_NEAR(pose.r.x * pose.r.x + pose.r.y * pose.r.y + pose.r.z * pose.r.z + pose.r.w * pose.r.w, 1, 1e-5);
	CHECK_NEAR(mlod_quat_angle(pose.r, mlod_quat_axis_angle(v3(1, 0, 0), 0.75f)), 0, 1e-5);
}

/* ---------------------------------------------------------------- */
/* Kinematics and skinning                                           */
/* ---------------------------------------------------------------- */

static int mat_near(const mlod_mat4 *a, const mlod_mat4 *b, double tol)
{
	for (int i = 0; i < 16; i++)
		if (fabs((double)a->m[i] - b->m[i]) > tol)
			return 0;
	return 1;
}

TEST(world_of_three_joint_chain)
{
	mlod_character c;
	build_chain(&c);
	mlod_trs local[3];
	mlod_mat4 world[3], skin[3];
	mlod_pose_rest(&c.skeleton, local);
	CHECK(local[2].t.y == 1.0f);
	mlod_pose_world(&c.skeleton, local, world);
	for (int i = 0; i < 3; i++) {
		CHECK_NEAR(world[i].m[12], 10, 1e-6); /* base puts everything at x = 10 */
		CHECK_NEAR(world[i].m[13], i, 1e-6);
	}
	/* at rest the skin matrices are identity */
	mlod_skin_matrices(&c.skeleton.skins[0], world, skin);
	mlod_mat4 id = mlod_mat4_identity();
	for (int i = 0; i < 3; i++)
		CHECK(mat_near(&skin[i], &id, 1e-6));

	/* root turned 90 degrees about z, A scaled by 2: by hand,
	 * world[0] = T(10,0,0) Rz(90); A at (10,0,0) + Rz(90)(0,1,0) = (9,0,0);
	 * B at A + Rz(90) * 2 * (0,1,0) = (7,0,0), with A's scale inherited. */
	local[0].r = mlod_quat_axis_angle(v3(0, 0, 1), (float)(PI / 2));
	local[1].s = v3(2, 2, 2);
	mlod_pose_world(&c.skeleton, local, world);
	CHECK_NEAR(world[1].m[12], 9, 1e-5);
	CHECK_NEAR(world[1].m[13], 0, 1e-5);
	CHECK_NEAR(world[2].m[12], 7, 1e-5);
	CHECK_NEAR(world[2].m[13], 0, 1e-5);
	mlod_v3 x = mlod_mat4_vector(&world[2], v3(1, 0, 0));
	CHECK_NEAR(x.x, 0, 1e-5);
	CHECK_NEAR(x.y, 2, 1e-5); /* x turned to y and doubled */
	mlod_character_free(&c);
}

TEST(linear_blend_skinning)
{
	mlod_character c;
	build_chain(&c);
	mlod_trs local[3];
	mlod_mat4 world[3], skin[3];
	mlod_pose_rest(&c.skeleton, local);
	/* A bends 90 degrees about z: B moves from (10,2,0) to (9,1,0) */
	local[1].r = mlod_quat_axis_angle(v3(0, 0, 1), (float)(PI / 2));
	mlod_pose_world(&c.skeleton, local, world);
	mlod_skin_matrices(&c.skeleton.skins[0], world, skin);
	const mlod_primitive *p = &c.meshes[0].primitives[0];
	float pos[9], nrm[9];
	mlod_skin_primitive(p, skin, pos, nrm);
	/* v0 (10,1,0) rides A: A's origin, unchanged */
	CHECK_NEAR(pos[0], 10, 1e-5);
	CHECK_NEAR(pos[1], 1, 1e-5);
	/* v2 (10,2,1) rides B: bind offset (0,0,1) from B, rotated about z: unchanged, so (9,1,1) */
	CHECK_NEAR(pos[6], 9, 1e-5);
	CHECK_NEAR(pos[7], 1, 1e-5);
	CHECK_NEAR(pos[8], 1, 1e-5);
	/* v1 (11,2,0), half A half B: offset from A (1,1,0) -> (-1,1,0) so A gives (9,2,0);
	 * offset from B (1,0,0) -> (0,1,0) so B gives (9,2,0). Blend (9,2,0). */
	CHECK_NEAR(pos[3], 9, 1e-5);
	CHECK_NEAR(pos[4], 2, 1e-5);
	CHECK_NEAR(pos[5], 0, 1e-5);
	/* normals along z are unaffected by a turn about z and stay unit */
	CHECK_NEAR(nrm[5], 1, 1e-6);

	/* scaling B's joint by 3 scales the normal's matrix but not the result */
	local[2].s = v3(1, 3, 1);
	local[1].r = mlod_quat_axis_angle(v3(1, 0, 0), (float)(PI / 4));
	mlod_pose_world(&c.skeleton, local, world);
	mlod_skin_matrices(&c.skeleton.skins[0], world, skin);
	mlod_skin_primitive(p, skin, pos, nrm);
	for (int v = 0; v < 3; v++)
		CHECK_NEAR(nrm[3 * v] * nrm[3 * v] + nrm[3 * v + 1] * nrm[3 * v + 1] + nrm[3 * v + 2] * nrm[3 * v + 2], 1, 1e-5);

	/* a vertex whose weights are all zero stays at its bind position */
	p = &c.meshes[0].primitives[0];
	c.meshes[0].primitives[0].weights[0][0] = 0.0f;
	mlod_skin_primitive(p, skin, pos, NULL);
	CHECK(pos[0] == 10.0f && pos[1] == 1.0f && pos[2] == 0.0f);
	mlod_character_free(&c);
}

TEST(skinning_uses_every_weight_set)
{
	/* one vertex, two sets: 0.25 on a joint moved by +4 x (set 0), 0.75 on a
	 * joint moved by +8 y (set 1): it lands at +1 x, +6 y. */
	float pos[3] = { 1, 1, 1 }, w0[4] = { 0.25f, 0, 0, 0 }, w1[4] = { 0, 0, 0.75f, 0 };
	uint16_t j0[4] = { 0, 0, 0, 0 }, j1[4] = { 0, 0, 1, 0 };
	mlod_primitive p = { 0 };
	p.vertex_count = 1;
	p.positions = pos;
	p.weight_set_count = 2;
	p.joints[0] = j0, p.joints[1] = j1, p.weights[0] = w0, p.weights[1] = w1;
	mlod_mat4 m[2] = { mlod_mat4_identity(), mlod_mat4_identity() };
	m[0].m[12] = 4;
	m[1].m[13] = 8;
	float out[3];
	mlod_skin_primitive(&p, m, out, NULL);
	CHECK_NEAR(out[0], 2, 1e-6);
	CHECK_NEAR(out[1], 7, 1e-6);
	CHECK_NEAR(out[2], 1, 1e-6);
}

TEST(pose_character_skinned_and_rigid)
{
	mlod_character c;
	build_chain(&c);
	mlod_trs local[3];
	mlod_mat4 world[3];
	mlod_posed posed = { 0 };
	mlod_pose_rest(&c.skeleton, local);
	mlod_pose_world(&c.skeleton, local, world);
	CHECK_OK(mlod_pose_character(&c, world, &posed, &terr));
	CHECK(posed.vertex_count == 6 && posed.triangle_count == 2); /* the line is skipped */
	CHECK(posed.indices[0] == 0 && posed.indices[2] == 2);
	CHECK(posed.indices[3] == 3 && posed.indices[5] == 5);
	CHECK_NEAR(posed.positions[0], 10, 1e-6); /* bind = rest */
	CHECK_NEAR(posed.positions[9], 10, 1e-6); /* hat vertex 0 at B (10,2,0) + (0,0.5,0) */
	CHECK_NEAR(posed.positions[10], 2.5, 1e-6);

	/* sample the clip at its end: A turned 90 degrees about z */
	float *before = posed.positions;
	mlod_clip_sample(&c.clips[0], 1.0f, local);
	mlod_pose_world(&c.skeleton, local, world);
	CHECK_OK(mlod_pose_character(&c, world, &posed, &terr));
	CHECK(posed.positions == before); /* same size: no reallocation */
	CHECK_NEAR(posed.positions[6], 9, 1e-5); /* skinned v2 as in the LBS test */
	CHECK_NEAR(posed.positions[8], 1, 1e-5);
	/* hat: B at (9,1,0), offset turned to (-0.5,0,0); hat vertex 1 (1,0,0) turned to (0,1,0) */
	CHECK_NEAR(posed.positions[9], 8.5, 1e-5);
	CHECK_NEAR(posed.positions[10], 1, 1e-5);
	CHECK_NEAR(posed.positions[12], 8.5, 1e-5);
	CHECK_NEAR(posed.positions[13], 2, 1e-5);

	/* a world-placed instance (no joint) uses its offset alone */
	c.instances[1].joint = -1;
	CHECK_OK(mlod_pose_character(&c, world, &posed, &terr));
	CHECK_NEAR(posed.positions[10], 0.5, 1e-6);

	c.instances[1].mesh = 5;
	mlod_error e;
	CHECK(mlod_pose_character(&c, world, &posed, &e) == MLOD_ERR_INVALID_ARG);
	mlod_posed_free(&posed);
	CHECK(posed.positions == NULL && posed.vertex_count == 0);
	mlod_posed_free(NULL);
	mlod_character_free(&c);
}

TEST(fix_weights_rule)
{
	/* Two sets, five vertices: v0 valid (untouched, bit for bit), v1 all 0
	 * (on the root, joint 2 here, alone), v2 summing to 0.5 over both sets
	 * (scaled), v3 with a negative weight (left: validate refuses it), v4
	 * 1e-7 over 1 with one weight (within the validator's 2e-7: kept). */
	float w0[20] = { 0.25f, 0.75f, 0, 0, 0, 0, 0, 0, 0.1f, 0.1f, 0, 0, -1, 0, 0, 0, 1.0000001f, 0, 0, 0 };
	float w1[20] = { 0, 0, 0, 0, 0, 0, 0, 0, 0.1f, 0.2f, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0 };
	uint16_t j0[20] = { 0, 1, 0, 0, 1, 1, 1, 1, 0, 1, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0 };
	uint16_t j1[20] = { 0, 0, 0, 0, 2, 2, 2, 2, 2, 3, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0 };
	float keep0[20], keep1[20];
	memcpy(keep0, w0, sizeof w0), memcpy(keep1, w1, sizeof w1);
	float pos[15] = { 0 };
	mlod_primitive p = { 0 };
	p.vertex_count = 5;
	p.positions = pos;
	p.weight_set_count = 2;
	p.joints[0] = j0, p.joints[1] = j1, p.weights[0] = w0, p.weights[1] = w1;
	mlod_weight_fix fix;
	mlod_primitive_fix_weights(&p, 2, &fix);
	CHECK(fix.unweighted == 1 && fix.first_unweighted == 1);
	CHECK(fix.rescaled == 1 && fix.first_rescaled == 2);
	CHECK(fix.merged == 0 && fix.first_merged == -1);
	CHECK_NEAR(fix.first_sum, 0.5, 1e-6);
	CHECK(memcmp(w0, keep0, 4 * sizeof(float)) == 0 && memcmp(w0 + 12, keep0 + 12, 8 * sizeof(float)) == 0);
	CHECK(j0[4] == 2 && w0[4] == 1.0f);
	for (int i = 1; i < 4; i++)
		CHECK(j0[4 + i] == 0 && w0[4 + i] == 0.0f);
	for (int i = 0; i < 4; i++)
		CHECK(j1[4 + i] == 0 && w1[4 + i] == 0.0f);
	float sum = 0.0f;
	for (int i = 0; i < 4; i++)
		sum += w0[8 + i], sum += w1[8 + i];
	CHECK_NEAR(sum, 1.0, 4e-7);
	CHECK_NEAR(w1[9], 0.4, 1e-6);
	/* no root: a vertex without weight stays so, counted */
	w0[4] = 0.0f;
	mlod_primitive_fix_weights(&p, -1, &fix);
	CHECK(fix.unweighted == 1 && fix.first_unweighted == 1 && fix.rescaled == 0 && w0[4] == 0.0f);

	/* A joint named twice with non-zero weights (the validator's
	 * ACCESSOR_JOINTS_INDEX_DUPLICATE): v0 names joint 5 in set 1's
	 * first influence and in set 0's second (read first: set 1's), v1 joint 4 three times and
	 * once more at weight 0 (not a repeat: left), v2 joint 6 twice at
	 * weights summing to 0.5 (merged, then scaled). In the order the
	 * validator reads them (influence by influence, set by set), the first
	 * keeps the sum; the others become joint 0 at weight 0. */
	float d0[12] = { 0.5f, 0.25f, 0, 0, 0.25f, 0.25f, 0, 0, 0.2f, 0, 0, 0 };
	float d1[12] = { 0.25f, 0, 0, 0, 0.25f, 0.25f, 0, 0, 0.3f, 0, 0, 0 };
	uint16_t dj0[12] = { 1, 5, 0, 0, 4, 4, 0, 4, 6, 0, 0, 0 };
	uint16_t dj1[12] = { 5, 0, 0, 0, 4, 1, 0, 0, 6, 0, 0, 0 };
	mlod_primitive q = { 0 };
	q.vertex_count = 3;
	q.positions = pos;
	q.weight_set_count = 2;
	q.joints[0] = dj0, q.joints[1] = dj1, q.weights[0] = d0, q.weights[1] = d1;
	mlod_primitive_fix_weights(&q, 0, &fix);
	CHECK(fix.merged == 3 && fix.first_merged == 0);
	CHECK(fix.unweighted == 0 && fix.rescaled == 1 && fix.first_rescaled == 2);
	CHECK(dj1[0] == 5 && d1[0] == 0.5f && dj0[1] == 0 && d0[1] == 0.0f && dj0[0] == 1 && d0[0] == 0.5f);
	CHECK(dj0[4] == 4 && d0[4] == 0.75f && dj1[4] == 0 && d1[4] == 0.0f && dj0[5] == 0 && d0[5] == 0.0f);
	CHECK(dj0[7] == 4 && d0[7] == 0.0f && dj1[5] == 1 && d1[5] == 0.25f);
	CHECK(dj0[8] == 6 && d0[8] == 1.0f && dj1[8] == 0 && d1[8] == 0.0f);
	/* nothing left to merge: a second pass changes nothing */
	mlod_primitive_fix_weights(&q, 0, &fix);
	CHECK(fix.merged == 0 && fix.rescaled == 0 && fix.unweighted == 0);

	/* the skin's root: of its joints, the one nearest the skeleton's root */
	mlod_character c;
	build_chain(&c);
	CHECK(mlod_skin_root(&c.skeleton, 0) == 0);
	c.skeleton.skins[0].joints[0] = 2, c.skeleton.skins[0].joints[2] = 0;
	CHECK(mlod_skin_root(&c.skeleton, 0) == 2);
	CHECK(mlod_skin_root(&c.skeleton, 1) == -1);
	mlod_character_free(&c);
}

int main(void)
{
	RUN(validate_accepts_and_free_zeroes);
	RUN(validate_names_first_problem);
	RUN(skeleton_height);
	RUN(linear_and_step);
	RUN(rotation_interpolation);
	RUN(single_key_is_constant);
	RUN(cubic_spline_hand_computed);
	RUN(cubic_spline_rotation_normalised);
	RUN(world_of_three_joint_chain);
	RUN(linear_blend_skinning);
	RUN(skinning_uses_every_weight_set);
	RUN(pose_character_skinned_and_rigid);
	RUN(fix_weights_rule);
	TEST_EXIT();
}
