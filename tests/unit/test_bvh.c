/* test_bvh.c: the BVH reader and writer: layouts, motion, round trips, malformed input. */
#define _POSIX_C_SOURCE 200809L /* strdup, opendir */
#include "test.h"

#include <dirent.h>

#define PI 3.14159265358979323846

/* ---------------------------------------------------------------- */
/* Helpers                                                           */
/* ---------------------------------------------------------------- */

static mlod_result read_text(const char *text, mlod_character *c)
{
	memset(&terr, 0, sizeof terr);
	return mlod_bvh_read(text, strlen(text), c, &terr);
}

static int joint_index(const mlod_character *c, const char *name)
{
	for (int j = 0; j < c->skeleton.joint_count; j++)
		if (strcmp(c->skeleton.joints[j].name, name) == 0)
			return j;
	return -1;
}

static const mlod_channel *find_channel(const mlod_clip *clip, int joint, mlod_path path)
{
	for (int i = 0; i < clip->channel_count; i++)
		if (clip->channels[i].joint == joint && clip->channels[i].path == path)
			return &clip->channels[i];
	return NULL;
}

static mlod_quat axis_deg(float x, float y, float z, double deg)
{
	mlod_v3 axis = { x, y, z };
	return mlod_quat_axis_angle(axis, (float)(deg * PI / 180.0));
}

static mlod_quat qx(double d) { return axis_deg(1, 0, 0, d); }
static mlod_quat qy(double d) { return axis_deg(0, 1, 0, d); }
static mlod_quat qz(double d) { return axis_deg(0, 0, 1, d); }

static mlod_quat mul3(mlod_quat a, mlod_quat b, mlod_quat c)
{
	return mlod_quat_mul(mlod_quat_mul(a, b), c);
}

static mlod_quat key_quat(const mlod_channel *ch, int k)
{
	mlod_quat q = { ch->values[4 * k], ch->values[4 * k + 1], ch->values[4 * k + 2], ch->values[4 * k + 3] };
	return q;
}

/* World positions of every joint of c for clip (or the rest pose when
 * clip < 0) at time t. */
static void world_positions(const mlod_character *c, int clip, float t, mlod_v3 *out)
{
	int n = c->skeleton.joint_count;
	mlod_trs *local = malloc((size_t)n * sizeof *local);
	mlod_mat4 *world = malloc((size_t)n * sizeof *world);
	mlod_pose_rest(&c->skeleton, local);
	if (clip >= 0)
		mlod_clip_sample(&c->clips[clip], t, local);
	mlod_pose_world(&c->skeleton, local, world);
	for (int j = 0; j < n; j++) {
		out[j].x = world[j].m[12];
		out[j].y = world[j].m[13];
		out[j].z = world[j].m[14];
	}
	free(local);
	free(world);
}

/* World positions of every End Site of c (zero for joints without). */
static void end_positions(const mlod_character *c, int clip, float t, mlod_v3 *out)
{
	int n = c->skeleton.joint_count;
	mlod_trs *local = malloc((size_t)n * sizeof *local);
	mlod_mat4 *world = malloc((size_t)n * sizeof *world);
	mlod_pose_rest(&c->skeleton, local);
	if (clip >= 0)
		mlod_clip_sample(&c->clips[clip], t, local);
	mlod_pose_world(&c->skeleton, local, world);
	for (int j = 0; j < n; j++) {
		mlod_v3 zero = { 0, 0, 0 };
		const mlod_joint *jt = &c->skeleton.joints[j];
		out[j] = jt->has_end_site ? mlod_mat4_point(&world[j], jt->end_site) : zero;
	}
	free(local);
	free(world);
}

static double dist(mlod_v3 a, mlod_v3 b)
{
	return mlod_v3_length(mlod_v3_sub(a, b));
}

/* Writes clip k of a (or its rest pose when it has no clip) as BVH, reads
 * it back into b and checks that every joint (matched by name), and every
 * End Site when end_sites is set, is where it was in every frame, within
 * 1e-4 of the skeleton height. */
static void check_clip_round_trip(const mlod_character *a, int k, float frame_time, int end_sites, const char *what)
{
	char *text = NULL;
	size_t size = 0;
	mlod_character b;
	memset(&b, 0, sizeof b);
	CHECK_OK(mlod_bvh_write(a, a->clip_count ? k : -1, frame_time, &text, &size, &terr));
	CHECK_MSG(text && size == strlen(text), "%s: bad text", what);
	CHECK_MSG(!strchr(text, ','), "%s: a comma in the BVH text", what);
	mlod_result r = mlod_bvh_read(text, size, &b, &terr);
	CHECK_MSG(r == MLOD_OK, "%.100s: reading the written BVH: %.200s\n%.300s", what, terr.message, text);
	mlod_free(text);
	CHECK_OK(mlod_character_validate(&b, &terr));

	int n = a->skeleton.joint_count;
	CHECK_MSG(b.skeleton.joint_count == n, "%s: %d joints, expected %d", what, b.skeleton.joint_count, n);
	int *map = malloc((size_t)n * sizeof *map);
	for (int j = 0; j < n; j++) {
		map[j] = joint_index(&b, a->skeleton.joints[j].name);
		if (map[j] < 0) {
			free(map);
			CHECK_MSG(0, "%s: joint %s lost", what, a->skeleton.joints[j].name);
		}
		if (end_sites && a->skeleton.joints[j].has_end_site != b.skeleton.joints[map[j]].has_end_site) {
			free(map);
			CHECK_MSG(0, "%s: End Site of %s lost", what, a->skeleton.joints[j].name);
		}
	}
	double tol = 1e-4 * mlod_skeleton_height(&a->skeleton);
	int frames = b.clip_count ? b.clips[0].frame_count : 1;
	float ft = b.clip_count ? b.clips[0].frame_time : 0.0f;
	mlod_v3 *pa = malloc((size_t)n * sizeof *pa), *pb = malloc((size_t)n * sizeof *pb);
	double worst = 0.0;
	int worst_joint = 0, worst_frame = 0, worst_end = 0;
	for (int f = 0; f < frames; f++) {
		float t = (float)(f * (double)ft);
		for (int pass = 0; pass < (end_sites ? 2 : 1); pass++) {
			if (pass == 0) {
				world_positions(a, a->clip_count ? k : -1, t, pa);
				world_positions(&b, b.clip_count ? 0 : -1, t, pb);
			} else {
				end_positions(a, a->clip_count ? k : -1, t, pa);
				end_positions(&b, b.clip_count ? 0 : -1, t, pb);
			}
			for (int j = 0; j < n; j++) {
				double d = dist(pa[j], pb[map[j]]);
				if (!(d <= worst)) {
					worst = d;
					worst_joint = j;
					worst_frame = f;
					worst_end = pass;
				}
			}
		}
	}
	free(pa);
	free(pb);
	free(map);
	mlod_character_free(&b);
	CHECK_MSG(worst <= tol, "%s: %s %s is %g away in frame %d (tolerance %g)", what,
	          worst_end ? "End Site of" : "joint", a->skeleton.joints[worst_joint].name, worst, worst_frame, tol);
}

static void check_round_trip(const mlod_character *a, float frame_time, int end_sites, const char *what)
{
	check_clip_round_trip(a, 0, frame_time, end_sites, what);
}

/* Round trip of a BVH file. */
static void check_file_round_trip(const char *path)
{
	size_t size = 0;
	char *data = test_read_file(path, &size);
	CHECK_MSG(data, "cannot read %.300s", path);
	mlod_character a;
	mlod_result r = mlod_bvh_read(data, size, &a, &terr);
	free(data);
	CHECK_MSG(r == MLOD_OK, "%.300s: %.300s", path, terr.message);
	CHECK_OK(mlod_character_validate(&a, &terr));
	check_round_trip(&a, 0.0f, 1, path);
	mlod_character_free(&a);
}

/* ---------------------------------------------------------------- */
/* Reading                                                           */
/* ---------------------------------------------------------------- */

TEST(cmu_walk)
{
	size_t size = 0;
	char *data = test_read_file("samples/cmu_12_01_walk.bvh", &size);
	CHECK(data);
	mlod_character c;
	mlod_result r = mlod_bvh_read(data, size, &c, &terr);
	free(data);
	CHECK_MSG(r == MLOD_OK, "%s", terr.message);
	CHECK_OK(mlod_character_validate(&c, &terr));

	/* 1 ROOT + 30 JOINTs, 7 End Sites, 524 frames of 96 values. */
	const mlod_skeleton *s = &c.skeleton;
	CHECK(s->joint_count == 31);
	int ends = 0, values = 0;
	for (int j = 0; j < s->joint_count; j++) {
		ends += s->joints[j].has_end_site;
		values += s->joints[j].channel_count;
		CHECK(s->joints[j].node == -1);
		CHECK(s->joints[j].parent < j);
		CHECK(s->joints[j].euler == MLOD_EULER_ZYX);
	}
	CHECK(ends == 7);
	CHECK(values == 96);
	CHECK(strcmp(s->joints[0].name, "Hips") == 0 && s->joints[0].parent == -1);
	CHECK(s->joints[0].channel_count == 6);
	CHECK(s->joints[0].channels[0] == MLOD_BVH_XPOS && s->joints[0].channels[3] == MLOD_BVH_ZROT &&
	      s->joints[0].channels[5] == MLOD_BVH_XROT);
	int leg = joint_index(&c, "LeftUpLeg");
	CHECK(leg == 2 && s->joints[leg].parent == 1);
	CHECK_NEAR(s->joints[leg].rest.t.x, 2.10660, 1e-6);
	CHECK_NEAR(s->joints[leg].rest.t.y, -1.59283, 1e-6);
	CHECK_NEAR(s->joints[leg].rest.t.z, 1.11709, 1e-6);
	CHECK(s->joints[leg].rest.r.w == 1.0f && s->joints[leg].rest.s.x == 1.0f);
	int toe = joint_index(&c, "LeftToeBase");
	CHECK(toe >= 0 && s->joints[toe].has_end_site);
	CHECK_NEAR(s->joints[toe].end_site.z, 1.01710, 1e-6);

	CHECK(c.clip_count == 1);
	const mlod_clip *clip = &c.clips[0];
	CHECK(strcmp(clip->name, "bvh") == 0);
	CHECK(clip->frame_count == 524);
	CHECK_NEAR(clip->frame_time, 0.0083333, 1e-9);
	CHECK_NEAR(clip->duration, 523 * 0.0083333, 1e-5);
	CHECK(clip->channel_count == 32); /* the hips' translation, 31 rotations */
	const mlod_channel *ht = find_channel(clip, 0, MLOD_PATH_TRANSLATION);
	CHECK(ht && ht->key_count == 524 && ht->interp == MLOD_INTERP_LINEAR);
	CHECK_NEAR(ht->values[0], 0.0265, 1e-6);
	CHECK_NEAR(ht->values[1], 16.2134, 1e-5);
	CHECK_NEAR(ht->values[2], -25.4911, 1e-5);
	CHECK_NEAR(ht->times[523], 523 * 0.0083333, 1e-5);
	/* Frame 1: LeftUpLeg's Zrotation is -21 degrees. */
	const mlod_channel *lr = find_channel(clip, leg, MLOD_PATH_ROTATION);
	CHECK(lr);
	CHECK_NEAR(mlod_quat_angle(key_quat(lr, 0), qz(-21)), 0, 1e-5);
	/* Sign-continuous quaternions, every key time i * frame time. */
	for (int i = 0; i < clip->channel_count; i++) {
		const mlod_channel *ch = &clip->channels[i];
		CHECK(ch->key_count == 524);
		for (int k = 0; k < ch->key_count; k++)
			CHECK_NEAR(ch->times[k], (float)(k * 0.0083333), 1e-6);
		if (ch->path != MLOD_PATH_ROTATION)
			continue;
		for (int k = 1; k < ch->key_count; k++) {
			mlod_quat p = key_quat(ch, k - 1), q = key_quat(ch, k);
			CHECK_MSG(p.x * q.x + p.y * q.y + p.z * q.z + p.w * q.w >= 0.0f, "channel %d flips at key %d", i, k);
		}
	}
	mlod_character_free(&c);
}

TEST(mixed_channel_orders)
{
	size_t size = 0;
	char *data = test_read_file("tests/data/mixed_channels.bvh", &size);
	CHECK(data);
	mlod_character c;
	mlod_result r = mlod_bvh_read(data, size, &c, &terr);
	free(data);
	CHECK_MSG(r == MLOD_OK, "%s", terr.message);
	CHECK_OK(mlod_character_validate(&c, &terr));
	CHECK(c.skeleton.joint_count == 8);
	const mlod_joint *J = c.skeleton.joints;
	const mlod_clip *clip = &c.clips[0];
	CHECK(clip->frame_count == 4);
	CHECK_NEAR(clip->frame_time, 0.04, 1e-9);
	CHECK_NEAR(clip->duration, 0.12, 1e-7);

	int hips = joint_index(&c, "Hips"), spine = joint_index(&c, "Spine"), neck = joint_index(&c, "Neck");
	int head = joint_index(&c, "Head"), hand = joint_index(&c, "LeftHand"), foot = joint_index(&c, "LeftFoot");
	int leg = joint_index(&c, "LeftLeg");
	CHECK(hips == 0 && spine == 1 && neck == 2 && head == 3 && hand == 5 && leg == 6 && foot == 7);
	CHECK(J[neck].parent == spine && J[leg].parent == hips && J[foot].parent == leg);
	CHECK(J[hips].euler == MLOD_EULER_ZXY);
	CHECK(J[spine].euler == MLOD_EULER_XYZ);
	CHECK(J[neck].euler == MLOD_EULER_YZX);
	CHECK(J[head].euler == MLOD_EULER_YZX);
	CHECK(J[leg].euler == MLOD_EULER_YXZ);
	CHECK(J[hand].euler == MLOD_EULER_ZXY);
	/* A 6-channel non-root joint keeps its interleaved layout. */
	static const unsigned char neck_layout[6] = { MLOD_BVH_YROT, MLOD_BVH_XPOS, MLOD_BVH_ZROT,
	                                              MLOD_BVH_YPOS, MLOD_BVH_XROT, MLOD_BVH_ZPOS };
	CHECK(J[neck].channel_count == 6 && memcmp(J[neck].channels, neck_layout, 6) == 0);
	/* Partial layouts are completed: "Zrotation Xrotation" and "Yposition". */
	CHECK(J[hand].channel_count == 3 && J[hand].channels[0] == MLOD_BVH_ZROT &&
	      J[hand].channels[1] == MLOD_BVH_XROT && J[hand].channels[2] == MLOD_BVH_YROT);
	CHECK(J[foot].channel_count == 3 && J[foot].channels[0] == MLOD_BVH_YPOS);
	CHECK(J[head].has_end_site && J[hand].has_end_site && J[foot].has_end_site && !J[neck].has_end_site);
	CHECK_NEAR(J[foot].end_site.z, 5.0, 0);

	/* Frame 1 values, against R built from the axes in file order. */
	const mlod_channel *ch;
	ch = find_channel(clip, hips, MLOD_PATH_ROTATION);
	CHECK(ch && mlod_quat_angle(key_quat(ch, 0), mul3(qz(10), qx(20), qy(30))) < 1e-5);
	ch = find_channel(clip, hips, MLOD_PATH_TRANSLATION);
	CHECK(ch && ch->values[0] == 1.0f && ch->values[1] == 91.0f && ch->values[2] == -2.0f);
	ch = find_channel(clip, spine, MLOD_PATH_ROTATION);
	CHECK(ch && mlod_quat_angle(key_quat(ch, 0), mul3(qx(5), qy(-15), qz(25))) < 1e-5);
	CHECK(!find_channel(clip, spine, MLOD_PATH_TRANSLATION));
	ch = find_channel(clip, neck, MLOD_PATH_ROTATION);
	CHECK(ch && mlod_quat_angle(key_quat(ch, 0), mul3(qy(40), qz(-60), qx(70))) < 1e-5);
	ch = find_channel(clip, neck, MLOD_PATH_TRANSLATION);
	CHECK(ch && ch->values[0] == 0.5f && ch->values[1] == 19.0f && ch->values[2] == -1.5f);
	ch = find_channel(clip, head, MLOD_PATH_ROTATION);
	CHECK(ch && mlod_quat_angle(key_quat(ch, 0), mul3(qy(-30), qz(45), qx(60))) < 1e-5);
	ch = find_channel(clip, hand, MLOD_PATH_ROTATION);
	CHECK(ch && mlod_quat_angle(key_quat(ch, 0), mlod_quat_mul(qz(35), qx(-45))) < 1e-5);
	ch = find_channel(clip, leg, MLOD_PATH_ROTATION);
	CHECK(ch && mlod_quat_angle(key_quat(ch, 0), mul3(qy(12), qx(-70), qz(15))) < 1e-5);
	/* Position channels replace their OFFSET component, keep the others. */
	ch = find_channel(clip, foot, MLOD_PATH_TRANSLATION);
	CHECK(ch && ch->values[0] == 0.0f && ch->values[1] == -38.0f && ch->values[2] == 0.0f);
	CHECK(ch->values[4] == -39.0f);
	CHECK(!find_channel(clip, foot, MLOD_PATH_ROTATION));
	/* Frame 3 crosses +-180 degrees: still sign-continuous. */
	for (int i = 0; i < clip->channel_count; i++) {
		ch = &clip->channels[i];
		if (ch->path != MLOD_PATH_ROTATION)
			continue;
		for (int k = 1; k < ch->key_count; k++) {
			mlod_quat p = key_quat(ch, k - 1), q = key_quat(ch, k);
			CHECK(p.x * q.x + p.y * q.y + p.z * q.z + p.w * q.w >= 0.0f);
		}
	}
	mlod_character_free(&c);
}

TEST(several_roots)
{
	size_t size = 0;
	char *data = test_read_file("tests/data/two_roots.bvh", &size);
	CHECK(data);
	mlod_character c;
	mlod_result r = mlod_bvh_read(data, size, &c, &terr);
	free(data);
	CHECK_MSG(r == MLOD_OK, "%s", terr.message);
	CHECK(c.skeleton.joint_count == 3);
	int prop = joint_index(&c, "Prop");
	CHECK(prop == 2 && c.skeleton.joints[prop].parent == -1 && c.skeleton.joints[0].parent == -1);
	CHECK(c.skeleton.joints[prop].rest.t.x == 5.0f && c.skeleton.joints[prop].has_end_site);
	CHECK(c.skeleton.joints[prop].channel_count == 3 && c.skeleton.joints[prop].euler == MLOD_EULER_XYZ);
	const mlod_channel *ch = find_channel(&c.clips[0], prop, MLOD_PATH_ROTATION);
	CHECK(ch && mlod_quat_angle(key_quat(ch, 2), qy(90)) < 1e-5);
	CHECK(mlod_quat_angle(key_quat(ch, 1), qx(90)) < 1e-5);
	mlod_v3 p[3];
	world_positions(&c, 0, c.clips[0].frame_time * 2, p);
	CHECK_NEAR(p[prop].x, 5, 1e-6);
	CHECK_NEAR(p[0].x, 1, 1e-6);
	mlod_character_free(&c);
}

/* Names with spaces, '{' on the name line, CR LF and lone CR line ends,
 * a byte order mark, tabs, "Frames:N", exponents, leading '+' and '.5'. */
TEST(lenient_syntax)
{
	const char *text = "\xEF\xBB\xBFHIERARCHY\r\nROOT Left Hip {\r\n OFFSET +1 .5 -2.5e-1\r"
	                   "CHANNELS 3 zrotation XROTATION Yrotation\n\tEnd Site { OFFSET 0 1 0 }\n}\n"
	                   "MOTION\nFrames:2\nFrame Time:\t0.5\n\n1e1 0 0\n\n-1E+1 0 .0\n\n";
	mlod_character c;
	CHECK_MSG(read_text(text, &c) == MLOD_OK, "%s", terr.message);
	CHECK(strcmp(c.skeleton.joints[0].name, "Left Hip") == 0);
	CHECK(c.skeleton.joints[0].rest.t.x == 1.0f && c.skeleton.joints[0].rest.t.y == 0.5f &&
	      c.skeleton.joints[0].rest.t.z == -0.25f);
	CHECK(c.skeleton.joints[0].euler == MLOD_EULER_ZXY);
	CHECK(c.clips[0].frame_count == 2 && c.clips[0].frame_time == 0.5f);
	CHECK(mlod_quat_angle(key_quat(&c.clips[0].channels[0], 1), qz(-10)) < 1e-5);
	mlod_character_free(&c);

	/* No frames, or no channels: a skeleton without a clip. */
	CHECK_MSG(read_text("HIERARCHY\nROOT A\n{\nOFFSET 0 0 0\nCHANNELS 3 Xrotation Yrotation Zrotation\n}\n"
	                    "MOTION\nFrames: 0\nFrame Time: 0.1\n", &c) == MLOD_OK, "%s", terr.message);
	CHECK(c.clip_count == 0 && c.skeleton.joint_count == 1);
	mlod_character_free(&c);
	CHECK_MSG(read_text("HIERARCHY\nROOT A\n{\nOFFSET 0 0 0\nCHANNELS 0\n}\nMOTION\nFrames: 3\nFrame Time: 0.1\n\n\n\n",
	                    &c) == MLOD_OK, "%s", terr.message);
	CHECK(c.clip_count == 0 && c.skeleton.joints[0].channel_count == 0);
	mlod_character_free(&c);
}

/* Huge and tiny numbers are written so that they read back as the same
 * floats. */
TEST(extreme_values)
{
	const char *text = "HIERARCHY\nROOT A\n{\nOFFSET 1e30 -3.4e38 1e-30\n"
	                   "CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n"
	                   "End Site\n{\nOFFSET 123456789 0.000001 -1e-7\n}\n}\n"
	                   "MOTION\nFrames: 2\nFrame Time: 1e-3\n3e38 -1e20 1e-38 1000 -720 3600\n1 2 3 4 5 6\n";
	mlod_character a, b;
	CHECK_MSG(read_text(text, &a) == MLOD_OK, "%s", terr.message);
	char *out = NULL;
	CHECK_OK(mlod_bvh_write(&a, 0, 0.0f, &out, NULL, &terr));
	CHECK(strstr(out, "Frame Time: 0.001\n"));
	CHECK_MSG(read_text(out, &b) == MLOD_OK, "%s\n%s", terr.message, out);
	mlod_free(out);
	const mlod_joint *ja = &a.skeleton.joints[0], *jb = &b.skeleton.joints[0];
	CHECK(memcmp(&ja->rest.t, &jb->rest.t, sizeof ja->rest.t) == 0);
	CHECK(memcmp(&ja->end_site, &jb->end_site, sizeof ja->end_site) == 0);
	const mlod_channel *ca = find_channel(&a.clips[0], 0, MLOD_PATH_TRANSLATION);
	const mlod_channel *cb = find_channel(&b.clips[0], 0, MLOD_PATH_TRANSLATION);
	CHECK(ca && cb && memcmp(ca->values, cb->values, 6 * sizeof(float)) == 0);
	ca = find_channel(&a.clips[0], 0, MLOD_PATH_ROTATION);
	cb = find_channel(&b.clips[0], 0, MLOD_PATH_ROTATION);
	CHECK(ca && cb && mlod_quat_angle(key_quat(ca, 0), key_quat(cb, 0)) < 1e-5);
	mlod_character_free(&a);
	mlod_character_free(&b);
}

/* ---------------------------------------------------------------- */
/* Malformed input                                                   */
/* ---------------------------------------------------------------- */

#define H1_5 "HIERARCHY\nROOT Hips\n{\n\tOFFSET 0 0 0\n\tCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n"
#define SPINE_HEAD "\tJOINT Spine\n\t{\n\t\tOFFSET 0 1 0\n"                             /* lines 6-8 */
#define SPINE_CH "\t\tCHANNELS 3 Zrotation Xrotation Yrotation\n"                     /* line 9 */
#define SPINE_END "\t\tEnd Site\n\t\t{\n\t\t\tOFFSET 0 1 0\n\t\t}\n\t}\n"             /* lines 10-14 */
#define SPINE SPINE_HEAD SPINE_CH SPINE_END
#define CLOSE "}\n"                                                                  /* line 15 */
#define HIER H1_5 SPINE CLOSE
#define MOTION2 "MOTION\nFrames: 2\nFrame Time: 0.1\n"                               /* lines 16-18 */
#define F1 "0 1 2 3 4 5 6 7 8\n"                                                     /* line 19 */
#define F2 "1 2 3 4 5 6 7 8 9\n"                                                     /* line 20 */
#define SMALL HIER MOTION2 F1 F2

typedef struct bad_case {
	const char *text;
	int line;            /* the line the message must name */
	const char *expect;  /* a part of the message, or NULL */
	mlod_result code;    /* MLOD_ERR_PARSE unless given */
} bad_case;

static const bad_case bad_cases[] = {
	{ "", 1, "empty input", 0 },
	{ "  \n\t\n  ", 3, "empty input", 0 },
	{ "hello world\n", 1, "expected HIERARCHY", 0 },
	{ "{\"asset\":{}}", 1, "expected HIERARCHY", 0 },
	{ H1_5 "\tJOINT Spine\n\t\tOFFSET 0 1 0\n" SPINE_CH SPINE_END CLOSE MOTION2 F1 F2, 7,
	  "line 7: expected '{' after JOINT Spine, found 'OFFSET'", 0 },
	{ "HIERARCHY\nROOT Hips\nOFFSET 0 0 0\n", 3, "expected '{' after ROOT Hips", 0 },
	{ H1_5 SPINE_HEAD SPINE_CH "\t\tEnd Site\n\t\t{\n\t\t\tOFFSET 0 1 0\n\t\t}\n" CLOSE MOTION2 F1 F2, 15,
	  "'MOTION' inside ROOT Hips (missing '}')", 0 },
	{ HIER "}\n" MOTION2 F1 F2, 16, "unexpected '}'", 0 },
	{ H1_5 SPINE, 15, "ends inside ROOT Hips (missing '}')", 0 },
	{ HIER, 16, "ends before MOTION", 0 },
	{ "HIERARCHY\nMOTION\nFrames: 1\nFrame Time: 0.1\n\n", 2, "no joints", 0 },
	{ "HIERARCHY\n", 2, "ends before MOTION", 0 },
	/* More than 6 channels (scale channels, 9) is BVH mlod does not read, not malformed BVH. */
	{ "HIERARCHY\nROOT Hips\n{\n\tOFFSET 0 0 0\n\tCHANNELS 7 Xposition\n", 5, "count from 0 to 6", MLOD_ERR_UNSUPPORTED },
	{ "HIERARCHY\nROOT Hips\n{\n\tOFFSET 0 0 0\n\tCHANNELS 9 Xposition Yposition Zposition Zrotation Xrotation "
	  "Yrotation Xscale Yscale Zscale\n", 5, "count from 0 to 6, found '9'", MLOD_ERR_UNSUPPORTED },
	{ "HIERARCHY\nROOT Hips\n{\n\tOFFSET 0 0 0\n\tCHANNELS -3\n", 5, "count from 0 to 6", 0 },
	{ "HIERARCHY\nROOT Hips\n{\n\tOFFSET 0 0 0\n\tCHANNELS 6 Xposition Yposition Zposition\n" SPINE CLOSE, 5,
	  "CHANNELS 6 of ROOT Hips lists only 3 channel names", 0 },
	{ H1_5 SPINE_HEAD "\t\tCHANNELS 3 Zrotation Wrotation Yrotation\n" SPINE_END CLOSE, 9,
	  "unknown channel 'Wrotation' in JOINT Spine", 0 },
	{ H1_5 SPINE_HEAD "\t\tCHANNELS 3 Zrotation Zrotation Yrotation\n" SPINE_END CLOSE, 9, "listed twice", 0 },
	{ H1_5 SPINE_HEAD "\t\tCHANNELS 3 Zrotation Xrotation Yrotation Xposition\n" SPINE_END CLOSE, 9,
	  "outside CHANNELS", 0 },
	{ H1_5 "\tJOINT Spine\n\t{\n\t\tOFFSET 0 1\n" SPINE_CH SPINE_END CLOSE, 9,
	  "expected a number in OFFSET of JOINT Spine, found 'CHANNELS'", 0 },
	{ H1_5 "\tJOINT Spine\n\t{\n\t\tOFFSET 0 nan 0\n" SPINE_CH SPINE_END CLOSE, 8, "not a finite number", 0 },
	{ H1_5 "\tJOINT Spine\n\t{\n\t\tOFFSET 0 -INF 0\n" SPINE_CH SPINE_END CLOSE, 8, "not a finite number", 0 },
	{ H1_5 "\tJOINT Spine\n\t{\n\t\tOFFSET 0 1,5 0\n" SPINE_CH SPINE_END CLOSE, 8, "expected a number", 0 },
	{ H1_5 "\tJOINT Spine\n\t{\n\t\tOFFSET 0 1 0 5\n" SPINE_CH SPINE_END CLOSE, 8, "unexpected number '5'", 0 },
	{ H1_5 "\tJOINT Spine\n\t{\n\t\tOFFSET 0 1e40 0\n" SPINE_CH SPINE_END CLOSE, 8, "out of range", 0 },
	{ H1_5 "\tJOINT\n\t{\n", 6, "JOINT without a name", 0 },
	{ H1_5 "\tJOINT Spine\n\t{\n" SPINE_CH SPINE_END CLOSE, 9, "JOINT Spine has no OFFSET before its End Site", 0 },
	{ H1_5 "\tJOINT Spine\n\t{\n" SPINE_CH "\t}\n" CLOSE, 9, "JOINT Spine has no OFFSET", 0 },
	{ H1_5 SPINE_HEAD "\t\tOFFSET 0 2 0\n", 9, "second OFFSET", 0 },
	{ H1_5 SPINE_HEAD SPINE_CH SPINE_CH, 10, "second CHANNELS", 0 },
	{ H1_5 SPINE_HEAD SPINE_CH "\t\tEnd Site\n\t\t{\n\t\t\tOFFSET 0 1 0\n\t\t}\n" SPINE_CH, 14,
	  "CHANNELS of JOINT Spine after its child joints", 0 },
	{ H1_5 SPINE_HEAD SPINE_CH "\t\tEnd\n\t\t{\n", 11, "expected 'Site' after 'End'", 0 },
	{ H1_5 SPINE_HEAD SPINE_CH "\t\tEnd Site\n\t\t{\n\t\t}\n", 12, "expected OFFSET in End Site of JOINT Spine", 0 },
	{ H1_5 SPINE_HEAD SPINE_CH "\t\tEnd Site\n\t\t\tOFFSET 0 1 0\n", 11, "expected '{' after End Site", 0 },
	{ H1_5 SPINE_HEAD SPINE_CH "\t\tEnd Site\n\t\t{\n\t\t\tOFFSET 0 1 0\n\t\tEnd Site\n", 13,
	  "expected '}' to close End Site", 0 },
	{ H1_5 SPINE_HEAD SPINE_CH "\t\tEnd Site\n\t\t{\n\t\t\tOFFSET 0 1 0\n\t\t}\n\t\tEnd Site\n", 14,
	  "a second End Site", 0 },
	{ H1_5 SPINE_HEAD SPINE_CH "\t\tROOT Other\n", 10, "'ROOT' inside JOINT Spine", 0 },
	{ H1_5 SPINE_HEAD SPINE_CH "\t\t{\n", 10, "unexpected '{' in JOINT Spine", 0 },
	{ H1_5 SPINE_HEAD SPINE_CH "\t\tBONE Other\n", 10, "unexpected 'BONE' in JOINT Spine", 0 },
	{ "HIERARCHY\nROOT Hips\x01\n", 2, "unexpected byte 0x01", 0 },
	{ HIER "MOTION\nFrame: 2\n", 17, "expected 'Frames:'", 0 },
	{ HIER "MOTION\nFrames: -1\nFrame Time: 0.1\n", 17, "negative frame count", 0 },
	{ HIER "MOTION\nFrames: 1.5\nFrame Time: 0.1\n", 17, "whole frame count", 0 },
	{ HIER "MOTION\nFrames: many\nFrame Time: 0.1\n", 17, "whole frame count", 0 },
	{ HIER "MOTION\nFrames:\nFrame Time: 0.1\n", 18, "whole frame count", 0 },
	{ HIER "MOTION\nFrames: 99999999999\nFrame Time: 0.1\n" F1, 17, "absurd frame count", MLOD_ERR_NOMEM },
	{ HIER "MOTION\nFrames: 10000000\nFrame Time: 0.1\n" F1 F2, 17, "needs 90000000 values", 0 },
	{ HIER "MOTION\nFrames: 2\nTime: 0.1\n" F1 F2, 18, "expected 'Frame Time:'", 0 },
	{ HIER "MOTION\nFrames: 2\nFrame Time: 0\n" F1 F2, 18, "Frame Time must be positive", 0 },
	{ HIER "MOTION\nFrames: 2\nFrame Time: -0.1\n" F1 F2, 18, "Frame Time must be positive", 0 },
	{ HIER "MOTION\nFrames: 2\nFrame Time: 1e-50\n" F1 F2, 18, "Frame Time must be positive", 0 },
	{ HIER "MOTION\nFrames: 2\nFrame Time: nan\n" F1 F2, 18, "not a finite number", 0 },
	{ HIER "MOTION\nFrames: 2\nFrame Time:nan\n" F1 F2, 18, "not a finite number", 0 },
	{ HIER "MOTION\nFrames: 2\nFrame Time: fast\n" F1 F2, 18, "expected a number", 0 },
	{ HIER "MOTION\nFrames: 2\nFrame Time: 0.1 0.2\n" F1 F2, 18, "after Frame Time", 0 },
	{ HIER "MOTION\nFrames: 3000000\nFrame Time: 1e-9\n", 17, "needs", 0 },
	{ HIER MOTION2 F1 "1 2 3 4 5 6 7 8\n", 20, "line 20: frame 2 has 8 values, expected 9", 0 },
	{ HIER MOTION2 F1 "1 2 3 4 5 6 7 8 9 10\n", 20, "line 20: frame 2 has 10 values, expected 9", 0 },
	{ HIER MOTION2 F1, 17, "'Frames: 2' needs 18 values", 0 },
	{ HIER MOTION2 F1 "\n\n\n\n\n\n\n\n\n\n\n\n\n\n\n\n\n\n\n\n", 40, "ends after 1 of 2 frames", 0 },
	{ HIER MOTION2 F1 "1 2 3 4 5 6 7 8", 20, "frame 2 has 8 values", 0 },
	{ HIER MOTION2 F1 F2 "1 2 3 4 5 6 7 8\n", 21, "extra data", 0 },
	{ HIER MOTION2 F1 F2 "\n\n}\n", 23, "extra data", 0 },
	{ HIER MOTION2 F1 F2 F1 F2, 17, "line 17: 'Frames: 2' but 4 frames follow (2 more from line 21)", 0 },
	{ HIER MOTION2 F1 F2 F1 F2 "1 2 3\n", 21, "extra data '0' after the last of 2 frames", 0 },
	{ HIER MOTION2 "0 1 2 3 x 5 6 7 8\n" F2, 19, "'x' (frame 1, value 5) is not a number", 0 },
	{ HIER MOTION2 "0 1 2 3 nan 5 6 7 8\n" F2, 19, "not a finite number", 0 },
	{ HIER MOTION2 "0 1 2 3 NaN 5 6 7 8\n" F2, 19, "not a finite number", 0 },
	{ HIER MOTION2 "0 1 2 3 -nan(ind) 5 6 7 8\n" F2, 19, "not a finite number", 0 },
	{ HIER MOTION2 "0 1 2 3 inf 5 6 7 8\n" F2, 19, "not a finite number", 0 },
	{ HIER MOTION2 "0 1 2 3 1.#INF 5 6 7 8\n" F2, 19, "not a finite number", 0 },
	{ HIER MOTION2 "0 1 2 3 4e38 5 6 7 8\n" F2, 19, "out of range", 0 },
	{ HIER MOTION2 "0 1 2 3 1e 5 6 7 8\n" F2, 19, "not a number", 0 },
	{ HIER MOTION2 "0 1 2 3 - 5 6 7 8\n" F2, 19, "not a number", 0 },
	{ HIER MOTION2 "0 1 2 3 . 5 6 7 8\n" F2, 19, "not a number", 0 },
	{ HIER MOTION2 "0 1 2 3 4.5.6 5 6 7 8\n" F2, 19, "not a number", 0 },
	{ HIER MOTION2 F1 "1 2 3 4 5\x7f 6 7 8 9\n", 20, "unexpected byte 0x7F", 0 },
	{ HIER "MOTION\nFrames: 0\nFrame Time: 0.1\n" F1, 19, "announces no frames", 0 },
	{ "HIERARCHY\nROOT A\n{\nOFFSET 0 0 0\nCHANNELS 0\n}\nMOTION\nFrames: 1\nFrame Time: 0.1\n1\n", 10,
	  "no joint has channels", 0 },
};

static void check_bad(const char *text, size_t size, int line, const char *expect, mlod_result code, int index)
{
	mlod_character c;
	memset(&c, 0x5a, sizeof c);
	memset(&terr, 0, sizeof terr);
	mlod_result r = mlod_bvh_read(text, size, &c, &terr);
	if (r == MLOD_OK)
		mlod_character_free(&c);
	CHECK_MSG(r == (code ? code : MLOD_ERR_PARSE), "case %d: returned %d (%s)", index, (int)r, terr.message);
	CHECK_MSG(terr.code == r, "case %d: err.code %d", index, (int)terr.code);
	CHECK_MSG(c.skeleton.joints == NULL && c.clips == NULL && c.skeleton.joint_count == 0,
	          "case %d: the character is not left empty", index);
	char want[32];
	snprintf(want, sizeof want, "line %d: ", line);
	CHECK_MSG(strncmp(terr.message, want, strlen(want)) == 0, "case %d: message \"%s\" does not start with \"%s\"",
	          index, terr.message, want);
	CHECK_MSG(!expect || strstr(terr.message, expect), "case %d: message \"%s\" lacks \"%s\"", index, terr.message,
	          expect);
}

TEST(malformed)
{
	for (size_t i = 0; i < sizeof bad_cases / sizeof bad_cases[0]; i++) {
		const bad_case *b = &bad_cases[i];
		check_bad(b->text, strlen(b->text), b->line, b->expect, b->code, (int)i);
		if (test_failed_)
			return;
	}
	/* Binary garbage, with NUL bytes, anywhere. */
	static const char nul1[] = "\x00\x01\x02\x03glTF\xff\xfe";
	check_bad(nul1, sizeof nul1 - 1, 1, "unexpected byte 0x00", 0, 100);
	if (test_failed_)
		return;
	static const char nul2[] = "HIERARCHY\nROOT Hips\n{\n\tOFFSET 0 0\x00 0\n";
	check_bad(nul2, sizeof nul2 - 1, 4, "unexpected byte 0x00", 0, 101);
	if (test_failed_)
		return;
	static const char nul3[] = HIER MOTION2 F1 "1 2 3 4 5\x00 6 7 8 9\n";
	check_bad(nul3, sizeof nul3 - 1, 20, "unexpected byte 0x00", 0, 102);
	if (test_failed_)
		return;
	/* NULL data, NULL output. */
	mlod_character c;
	CHECK(mlod_bvh_read(NULL, 10, &c, &terr) == MLOD_ERR_INVALID_ARG);
	CHECK(mlod_bvh_read(SMALL, strlen(SMALL), NULL, &terr) == MLOD_ERR_INVALID_ARG);
	CHECK(mlod_bvh_read(NULL, 0, &c, NULL) == MLOD_ERR_PARSE);
	/* The valid base of all of the above. */
	CHECK_MSG(read_text(SMALL, &c) == MLOD_OK, "%s", terr.message);
	CHECK(c.skeleton.joint_count == 2 && c.clips[0].frame_count == 2);
	mlod_character_free(&c);
}

/* Absurd depth is refused, without recursion. */
TEST(deep_nesting)
{
	int depth = 5000;
	size_t cap = (size_t)depth * 40 + 200, n = 0;
	char *text = malloc(cap);
	n += (size_t)sprintf(text + n, "HIERARCHY\n");
	for (int i = 0; i < depth; i++)
		n += (size_t)sprintf(text + n, "%s J%d\n{\nOFFSET 0 1 0\n", i ? "JOINT" : "ROOT", i);
	mlod_character c;
	mlod_result r = mlod_bvh_read(text, n, &c, &terr);
	free(text);
	CHECK(r == MLOD_ERR_UNSUPPORTED); /* a limit of mlod's, as for glTF nodes (exit 3) */
	CHECK_MSG(strstr(terr.message, "nested deeper than") && strncmp(terr.message, "line 3002: ", 11) == 0, "%s",
	          terr.message);
}

/* Truncated at every byte, the reader fails cleanly or reads a valid
 * character; it never crashes. */
static void check_prefixes(const char *data, size_t size, size_t step)
{
	for (size_t n = 0; n < size; n += step) {
		char *copy = malloc(n + 1); /* exactly n bytes visible to ASan */
		memcpy(copy, data, n);
		mlod_character c;
		mlod_result r = mlod_bvh_read(copy, n, &c, &terr);
		free(copy);
		if (r == MLOD_OK) {
			mlod_result v = mlod_character_validate(&c, &terr);
			mlod_character_free(&c);
			CHECK_MSG(v == MLOD_OK, "prefix %zu: %s", n, terr.message);
			continue;
		}
		CHECK_MSG(r == MLOD_ERR_PARSE || r == MLOD_ERR_NOMEM, "prefix %zu: returned %d", n, (int)r);
		CHECK_MSG(strncmp(terr.message, "line ", 5) == 0, "prefix %zu: message \"%s\"", n, terr.message);
	}
}

TEST(truncation)
{
	check_prefixes(SMALL, strlen(SMALL), 1);
	if (test_failed_)
		return;
	size_t size = 0;
	char *data = test_read_file("tests/data/mixed_channels.bvh", &size);
	CHECK(data);
	check_prefixes(data, size, 1);
	free(data);
	if (test_failed_)
		return;
	data = test_read_file("samples/cmu_12_01_walk.bvh", &size);
	CHECK(data);
	check_prefixes(data, size, 1009);
	free(data);
}

/* Random byte changes: never a crash, always a message with a line. */
TEST(mutations)
{
	static const char alphabet[] = "0123456789-+.eE{}\n\r\t #xnaNIf\x00\x01\xff";
	unsigned state = 2024u;
	size_t size = 0;
	char *base = test_read_file("tests/data/mixed_channels.bvh", &size);
	CHECK(base);
	char *data = malloc(size);
	for (int iter = 0; iter < 3000; iter++) {
		memcpy(data, base, size);
		int edits = 1 + iter % 4;
		for (int e = 0; e < edits; e++) {
			state = state * 1664525u + 1013904223u;
			size_t at = (state >> 8) % size;
			state = state * 1664525u + 1013904223u;
			data[at] = alphabet[(state >> 8) % (sizeof alphabet - 1)];
		}
		mlod_character c;
		mlod_result r = mlod_bvh_read(data, size, &c, &terr);
		if (r == MLOD_OK) {
			mlod_result v = mlod_character_validate(&c, &terr);
			mlod_character_free(&c);
			if (v != MLOD_OK) {
				free(data);
				free(base);
				CHECK_MSG(0, "iteration %d: invalid character: %s", iter, terr.message);
			}
			continue;
		}
		/* UNSUPPORTED: a channel count of 7 to 9. */
		if (strncmp(terr.message, "line ", 5) != 0 ||
		    (r != MLOD_ERR_PARSE && r != MLOD_ERR_NOMEM && r != MLOD_ERR_UNSUPPORTED)) {
			free(data);
			free(base);
			CHECK_MSG(0, "iteration %d: returned %d, \"%s\"", iter, (int)r, terr.message);
		}
	}
	free(data);
	free(base);
}

/* The files the CLI tests use are malformed, the valid ones read. */
TEST(data_files)
{
	DIR *d = opendir("tests/data/bad");
	CHECK(d);
	struct dirent *e;
	int count = 0;
	char path[512];
	while ((e = readdir(d))) {
		size_t n = strlen(e->d_name);
		/* motion_* files are bad for the motion layer, not for the parser. */
		if (n < 4 || strcmp(e->d_name + n - 4, ".bvh") != 0 || strncmp(e->d_name, "motion_", 7) == 0)
			continue;
		snprintf(path, sizeof path, "tests/data/bad/%s", e->d_name);
		size_t size = 0;
		char *data = test_read_file(path, &size);
		if (!data)
			break;
		mlod_character c;
		mlod_result r = mlod_bvh_read(data, size, &c, &terr);
		free(data);
		if (r == MLOD_OK)
			mlod_character_free(&c);
		/* bad_channel_count.bvh's CHANNELS 7 is unsupported (a count mlod does not read). */
		int unsupported = r == MLOD_ERR_UNSUPPORTED && strstr(terr.message, "count from 0 to 6") != NULL;
		if ((r != MLOD_ERR_PARSE && r != MLOD_ERR_NOMEM && !unsupported) || strncmp(terr.message, "line ", 5) != 0) {
			closedir(d);
			CHECK_MSG(0, "%.200s: returned %d, \"%.300s\"", path, (int)r, terr.message);
		}
		count++;
	}
	closedir(d);
	CHECK(count >= 5);
}

/* ---------------------------------------------------------------- */
/* Writing                                                           */
/* ---------------------------------------------------------------- */

TEST(round_trip_cmu)
{
	check_file_round_trip("samples/cmu_12_01_walk.bvh");
	if (test_failed_)
		return;
	/* The layout survives, and the text is stable after one trip. */
	size_t size = 0;
	char *data = test_read_file("samples/cmu_12_01_walk.bvh", &size);
	mlod_character a, b;
	CHECK_OK(mlod_bvh_read(data, size, &a, &terr));
	free(data);
	char *t1 = NULL, *t2 = NULL;
	size_t n1 = 0, n2 = 0;
	CHECK_OK(mlod_bvh_write(&a, 0, 0.0f, &t1, &n1, &terr));
	CHECK(strstr(t1, "Frames: 524\nFrame Time: 0.0083333\n"));
	CHECK(strstr(t1, "\tOFFSET 2.1066 -1.59283 1.11709\n"));
	CHECK(strstr(t1, "\nMOTION\nFrames: 524\nFrame Time: 0.0083333\n0.0265 16.2134 -25.4911 0 0 0 0 0 0 -21 0 0 "));
	CHECK_OK(mlod_bvh_read(t1, n1, &b, &terr));
	for (int j = 0; j < a.skeleton.joint_count; j++) {
		const mlod_joint *ja = &a.skeleton.joints[j], *jb = &b.skeleton.joints[j];
		CHECK(strcmp(ja->name, jb->name) == 0 && ja->parent == jb->parent);
		CHECK(ja->channel_count == jb->channel_count && memcmp(ja->channels, jb->channels, 6) == 0);
		CHECK(ja->euler == jb->euler && ja->has_end_site == jb->has_end_site);
		/* Exactly, but for the sign of zero ("-0.00000" is written "0"). */
		CHECK(ja->rest.t.x == jb->rest.t.x && ja->rest.t.y == jb->rest.t.y && ja->rest.t.z == jb->rest.t.z);
		CHECK(ja->end_site.x == jb->end_site.x && ja->end_site.y == jb->end_site.y &&
		      ja->end_site.z == jb->end_site.z);
	}
	CHECK_OK(mlod_bvh_write(&b, 0, 0.0f, &t2, &n2, &terr));
	/* The hierarchy is identical; the motion within float noise. */
	CHECK(memcmp(t1, t2, (size_t)(strstr(t1, "MOTION") - t1)) == 0);
	mlod_free(t1);
	mlod_free(t2);
	mlod_character_free(&a);
	mlod_character_free(&b);
}

TEST(round_trip_files)
{
	check_file_round_trip("tests/data/mixed_channels.bvh");
	if (test_failed_)
		return;
	check_file_round_trip("tests/data/two_roots.bvh");
	if (test_failed_)
		return;
	mlod_character c;
	CHECK_OK(mlod_bvh_read(SMALL, strlen(SMALL), &c, &terr));
	check_round_trip(&c, 0.0f, 1, "SMALL");
	mlod_character_free(&c);
}

/* Round trips of every clip of a glb as BVH. */
static void check_glb_round_trip(const char *path)
{
	size_t size = 0;
	char *data = test_read_file(path, &size);
	CHECK_MSG(data, "cannot read %.300s", path);
	mlod_character c;
	mlod_result r = mlod_load(data, size, NULL, NULL, &c, NULL, &terr);
	free(data);
	CHECK_MSG(r == MLOD_OK, "%.300s: %.300s", path, terr.message);
	for (int k = 0; k < (c.clip_count ? c.clip_count : 1) && !test_failed_; k++) {
		char what[600];
		snprintf(what, sizeof what, "%.500s clip %d", path, k);
		check_clip_round_trip(&c, k, 0.0f, 1, what);
	}
	mlod_character_free(&c);
}

/* Round trips of every .bvh and .glb in a directory, if it exists. */
static void round_trip_dir(const char *dir, int *count)
{
	DIR *d = opendir(dir);
	if (!d)
		return;
	struct dirent *e;
	char path[1024];
	while ((e = readdir(d))) {
		size_t n = strlen(e->d_name);
		snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
		if (n >= 4 && strcmp(e->d_name + n - 4, ".glb") == 0)
			check_glb_round_trip(path);
		else if (n >= 4 && (strcmp(e->d_name + n - 4, ".bvh") == 0 || strcmp(e->d_name + n - 4, ".BVH") == 0))
			check_file_round_trip(path);
		else
			continue;
		(*count)++;
		if (test_failed_)
			break;
	}
	closedir(d);
}

TEST(round_trip_shared)
{
	NEED_SHARED();
	int count = 0;
	round_trip_dir(getenv("MLOD_SHARED_DATA"), &count);
	if (test_failed_)
		return;
	CHECK_MSG(count > 0, "no .bvh or .glb in %.300s", getenv("MLOD_SHARED_DATA"));
}

/* The BVH files of Debian's assimp-testmodels (a dependency that
 * scripts/install-deps installs): a missing folder fails, it does not
 * pass untested. */
TEST(round_trip_assimp)
{
	static const char dir[] = "/usr/share/assimp/models/BVH";
	int count = 0;
	round_trip_dir(dir, &count);
	if (test_failed_)
		return;
	CHECK_MSG(count > 0, "no .bvh in %s: install assimp-testmodels (scripts/install-deps)", dir);
}

/* A glTF-like character: rest rotations, a rigid base on the root, a
 * uniformly scaled joint with an animated scale, translation animated on
 * a non-root joint, joints not in depth-first order, no BVH layout. */
static void build_gltf_like(mlod_character *c, int scaled_base)
{
	static const char *names[7] = { "Root", "Spine", "LegL", "Head", "FootL", "Hat", "Prop" };
	static const int parents[7] = { -1, 0, 0, 1, 2, 3, -1 };
	memset(c, 0, sizeof *c);
	c->skeleton.joint_count = 7;
	c->skeleton.joints = calloc(7, sizeof(mlod_joint));
	for (int i = 0; i < 7; i++) {
		mlod_joint *j = &c->skeleton.joints[i];
		j->name = malloc(strlen(names[i]) + 1);
		strcpy(j->name, names[i]);
		j->parent = parents[i];
		j->rest = mlod_trs_identity();
		j->base = mlod_mat4_identity();
		j->node = i;
	}
	mlod_joint *J = c->skeleton.joints;
	J[0].rest.t = (mlod_v3){ 0, 1, 0 };
	J[0].rest.r = axis_deg(1, 0, 0, 30);
	mlod_trs base = mlod_trs_identity();
	base.t = (mlod_v3){ 10, 0, 5 };
	base.r = qy(90);
	if (scaled_base) {
		base.t = (mlod_v3){ 0.1f, 0, 0.05f };
		base.s = (mlod_v3){ 0.01f, 0.01f, 0.01f };
	}
	J[0].base = mlod_mat4_from_trs(&base);
	J[1].rest.t = (mlod_v3){ 0, 2, 0 };
	J[1].rest.r = qz(20);
	J[2].rest.t = (mlod_v3){ 1, -1, 0 };
	J[2].rest.r = axis_deg(1, 1, 0, -40);
	J[3].rest.t = (mlod_v3){ 0, 1.5f, 0 };
	J[3].rest.s = (mlod_v3){ 2, 2, 2 };
	J[4].rest.t = (mlod_v3){ 0, -2, 0 };
	J[4].rest.r = axis_deg(0, 1, 1, 10);
	J[4].has_end_site = 1;
	J[4].end_site = (mlod_v3){ 0, 0, 0.5f };
	J[5].rest.t = (mlod_v3){ 0, 0.5f, 0 };
	J[5].rest.r = qy(45);
	J[5].has_end_site = 1;
	J[5].end_site = (mlod_v3){ 0, 0.25f, 0 };
	J[6].rest.t = (mlod_v3){ 3, 0, 0 };

	c->clip_count = 1;
	mlod_clip *clip = c->clips = calloc(1, sizeof *clip);
	clip->name = malloc(5);
	strcpy(clip->name, "walk");
	clip->duration = 1.0f;
	clip->gltf_index = 0;
	clip->channel_count = 6;
	clip->channels = calloc(6, sizeof(mlod_channel));
	static const float times[3] = { 0, 0.5f, 1.0f };
	const mlod_quat rots[4][3] = {
		{ J[0].rest.r, mlod_quat_mul(qy(120), J[0].rest.r), mlod_quat_mul(qz(-60), J[0].rest.r) },
		{ J[1].rest.r, mlod_quat_mul(J[1].rest.r, qx(50)), mlod_quat_mul(J[1].rest.r, qy(-170)) },
		{ J[2].rest.r, mlod_quat_mul(J[2].rest.r, qx(-90)), mlod_quat_mul(J[2].rest.r, qz(89)) },
		{ J[3].rest.r, qx(30), qy(-30) },
	};
	static const int rot_joints[4] = { 0, 1, 2, 3 };
	for (int k = 0; k < 6; k++) {
		mlod_channel *ch = &clip->channels[k];
		ch->interp = MLOD_INTERP_LINEAR;
		ch->key_count = 3;
		ch->times = malloc(sizeof times);
		memcpy(ch->times, times, sizeof times);
		if (k < 4) {
			ch->joint = rot_joints[k];
			ch->path = MLOD_PATH_ROTATION;
			ch->values = malloc(12 * sizeof(float));
			for (int i = 0; i < 3; i++)
				memcpy(ch->values + 4 * i, &rots[k][i], 4 * sizeof(float));
		} else {
			ch->joint = k == 4 ? 1 : 3;
			ch->path = k == 4 ? MLOD_PATH_TRANSLATION : MLOD_PATH_SCALE;
			const float tv[9] = { 0, 2, 0, 0.3f, 2.2f, 0, -0.3f, 1.8f, 0.1f };
			const float sv[9] = { 2, 2, 2, 1.5f, 1.5f, 1.5f, 2.5f, 2.5f, 2.5f };
			ch->values = malloc(sizeof tv);
			memcpy(ch->values, k == 4 ? tv : sv, sizeof tv);
		}
	}
}

TEST(write_gltf_like)
{
	mlod_character c;
	build_gltf_like(&c, 0);
	CHECK_OK(mlod_character_validate(&c, &terr));
	char *text = NULL;
	size_t size = 0;
	CHECK_OK(mlod_bvh_write(&c, 0, 1.0f / 30.0f, &text, &size, &terr));
	CHECK(strstr(text, "Frames: 31\nFrame Time: 0.033333335\n"));
	mlod_character b;
	mlod_result r = mlod_bvh_read(text, size, &b, &terr);
	mlod_free(text);
	CHECK_MSG(r == MLOD_OK, "%s", terr.message);
	/* Depth first: FootL is written under LegL, after Hat. */
	static const char *order[7] = { "Root", "Spine", "Head", "Hat", "LegL", "FootL", "Prop" };
	for (int i = 0; i < 7; i++)
		CHECK_MSG(strcmp(b.skeleton.joints[i].name, order[i]) == 0, "joint %d is %s", i, b.skeleton.joints[i].name);
	/* Default layouts, widened where the motion needs it: Spine's
	 * translation is animated, Hat hangs below Head's animated scale. */
	static const unsigned char six[6] = { MLOD_BVH_XPOS, MLOD_BVH_YPOS, MLOD_BVH_ZPOS,
	                                      MLOD_BVH_ZROT, MLOD_BVH_XROT, MLOD_BVH_YROT };
	static const int counts[7] = { 6, 6, 3, 6, 3, 3, 6 };
	for (int i = 0; i < 7; i++) {
		const mlod_joint *j = &b.skeleton.joints[i];
		CHECK_MSG(j->channel_count == counts[i], "%s has %d channels", j->name, j->channel_count);
		CHECK(memcmp(j->channels, counts[i] == 6 ? six : six + 3, (size_t)counts[i]) == 0);
		CHECK(j->euler == MLOD_EULER_ZXY);
	}
	const mlod_joint *J = b.skeleton.joints;
	CHECK(J[4].rest.t.x == 1.0f && J[4].rest.t.y == -1.0f && J[4].rest.t.z == 0.0f);
	CHECK(J[6].rest.t.x == 3.0f && J[6].rest.t.y == 0.0f);
	/* The root's base is folded in; Hat's OFFSET is scaled by Head's 2. */
	CHECK_NEAR(J[0].rest.t.x, 10, 1e-5);
	CHECK_NEAR(J[0].rest.t.y, 1, 1e-5);
	CHECK_NEAR(J[0].rest.t.z, 5, 1e-5);
	CHECK_NEAR(J[3].rest.t.x, 0, 1e-5);
	CHECK_NEAR(J[3].rest.t.y, 1, 1e-5);
	CHECK_NEAR(J[3].rest.t.z, 0, 1e-5);
	CHECK(J[5].has_end_site && J[3].has_end_site && !J[2].has_end_site);
	CHECK_NEAR(J[3].end_site.y, 0.5, 1e-5);
	mlod_character_free(&b);
	check_round_trip(&c, 1.0f / 30.0f, 0, "gltf-like");
	mlod_character_free(&c);
	if (test_failed_)
		return;

	/* End Sites of a character without animated scale follow too. */
	build_gltf_like(&c, 0);
	c.clips[0].channel_count = 5;
	free(c.clips[0].channels[5].times);
	free(c.clips[0].channels[5].values);
	check_round_trip(&c, 0.1f, 1, "gltf-like, no scale animation");
	mlod_character_free(&c);
	if (test_failed_)
		return;

	/* A root under a scaled node (as exported in centimetres). */
	build_gltf_like(&c, 1);
	check_round_trip(&c, 0.05f, 0, "gltf-like, scaled base");
	mlod_character_free(&c);
}

TEST(write_rest_and_arguments)
{
	mlod_character c;
	build_gltf_like(&c, 0);
	char *text = NULL;
	size_t size = 0;
	/* clip -1: the rest pose, one frame at 1/30 s. */
	CHECK_OK(mlod_bvh_write(&c, -1, 0.0f, &text, &size, &terr));
	CHECK(strstr(text, "Frames: 1\nFrame Time: 0.033333335\n"));
	/* In the rest pose only the root needs its translation. */
	CHECK(strstr(text, "JOINT Spine\n\t{\n\t\tOFFSET 0 2 0\n\t\tCHANNELS 3 Zrotation Xrotation Yrotation\n"));
	mlod_free(text);
	CHECK(mlod_bvh_write(&c, 1, 0.0f, &text, &size, &terr) == MLOD_ERR_INVALID_ARG && !text);
	CHECK(mlod_bvh_write(&c, 0, -1.0f, &text, &size, &terr) == MLOD_ERR_INVALID_ARG);
	CHECK(mlod_bvh_write(&c, 0, NAN, &text, &size, &terr) == MLOD_ERR_INVALID_ARG);
	CHECK(mlod_bvh_write(&c, 0, 1e-9f, &text, &size, &terr) == MLOD_ERR_NOMEM);
	CHECK(mlod_bvh_write(NULL, 0, 0.0f, &text, &size, &terr) == MLOD_ERR_INVALID_ARG);
	CHECK(mlod_bvh_write(&c, 0, 0.0f, NULL, &size, &terr) == MLOD_ERR_INVALID_ARG);
	/* A bad layout is the caller's error. */
	c.skeleton.joints[1].channel_count = 3;
	memset(c.skeleton.joints[1].channels, MLOD_BVH_XROT, 3);
	CHECK(mlod_bvh_write(&c, 0, 0.0f, &text, &size, &terr) == MLOD_ERR_INVALID_ARG);
	CHECK(strstr(terr.message, "Spine"));
	c.skeleton.joints[1].channel_count = 0;
	/* Names are made safe; size may be NULL. */
	free(c.skeleton.joints[6].name);
	c.skeleton.joints[6].name = malloc(16);
	strcpy(c.skeleton.joints[6].name, "my prop {1}");
	free(c.skeleton.joints[5].name);
	c.skeleton.joints[5].name = calloc(1, 1);
	CHECK_OK(mlod_bvh_write(&c, 0, 0.0f, &text, NULL, &terr));
	CHECK(strstr(text, "ROOT my_prop__1_\n") && strstr(text, "JOINT joint5\n"));
	mlod_character b;
	CHECK_OK(mlod_bvh_read(text, strlen(text), &b, &terr));
	mlod_free(text);
	mlod_character_free(&b);
	mlod_character_free(&c);
}

/* Euler angles are written continuous across +-180 degrees, and a joint
 * whose layout lacks an axis it turns about gets all three. */
TEST(write_angles)
{
	const char *text = "HIERARCHY\nROOT A\n{\nOFFSET 0 0 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n"
	                   "JOINT B\n{\nOFFSET 0 1 0\nCHANNELS 1 Yrotation\nEnd Site\n{\nOFFSET 1 0 0\n}\n}\n}\n"
	                   "MOTION\nFrames: 4\nFrame Time: 0.1\n"
	                   "170 0 0 100\n179 0 0 150\n-179 0 0 -170\n-170 0 0 -100\n";
	mlod_character c;
	CHECK_MSG(read_text(text, &c) == MLOD_OK, "%s", terr.message);
	char *out = NULL;
	CHECK_OK(mlod_bvh_write(&c, 0, 0.0f, &out, NULL, &terr));
	CHECK(strstr(out, "CHANNELS 3 Yrotation Xrotation Zrotation\n")); /* B's completed layout */
	/* A's Z and B's Y go on past 180 instead of jumping to -180. */
	static const double want[4][6] = {
		{ 170, 0, 0, 100, 0, 0 }, { 179, 0, 0, 150, 0, 0 }, { 181, 0, 0, 190, 0, 0 }, { 190, 0, 0, 260, 0, 0 }
	};
	char *p = strstr(out, "Frame Time: ");
	CHECK(p);
	p = strchr(p, '\n');
	for (int f = 0; f < 4; f++)
		for (int k = 0; k < 6; k++) {
			char *e;
			double v = strtod(p, &e);
			CHECK_MSG(e != p && fabs(v - want[f][k]) < 1e-3, "frame %d value %d is %g, expected %g\n%s", f, k, v,
			          want[f][k], out);
			p = e;
		}
	mlod_free(out);

	/* B turned about x too: its layout grows. */
	c.skeleton.joints[1].channel_count = 1;
	c.skeleton.joints[1].channels[0] = MLOD_BVH_YROT;
	mlod_channel *ch = (mlod_channel *)find_channel(&c.clips[0], 1, MLOD_PATH_ROTATION);
	mlod_quat q = mlod_quat_mul(qy(30), qx(10));
	memcpy(ch->values + 4, &q, sizeof q);
	CHECK_OK(mlod_bvh_write(&c, 0, 0.0f, &out, NULL, &terr));
	CHECK_MSG(strstr(out, "CHANNELS 3 Yrotation Xrotation Zrotation\n"), "%s", out);
	mlod_free(out);
	check_round_trip(&c, 0.0f, 1, "grown layout");
	mlod_character_free(&c);
}

/* ---------------------------------------------------------------- */
/* Format detection and loading                                      */
/* ---------------------------------------------------------------- */

TEST(detect_format)
{
	static const struct {
		const char *bytes;
		size_t size;
		mlod_format want;
	} cases[] = {
		{ "glTF\x02\0\0\0", 8, MLOD_FORMAT_GLB },
		{ "{\"asset\":{\"version\":\"2.0\"}}", 28, MLOD_FORMAT_GLTF },
		{ " \r\n\t{", 5, MLOD_FORMAT_GLTF },
		{ "\xEF\xBB\xBF{", 4, MLOD_FORMAT_GLTF },
		{ "HIERARCHY\nROOT", 15, MLOD_FORMAT_BVH },
		{ "\xEF\xBB\xBF\r\n hierarchy ", 16, MLOD_FORMAT_BVH },
		{ "HIERARCHY", 9, MLOD_FORMAT_BVH },
		{ "HIERARCHYX", 10, MLOD_FORMAT_UNKNOWN },
		{ "HIERARC", 7, MLOD_FORMAT_UNKNOWN },
		{ "glT", 3, MLOD_FORMAT_UNKNOWN },
		{ "hello, world\n", 13, MLOD_FORMAT_UNKNOWN },
		{ "\xEF\xBB\xBF", 3, MLOD_FORMAT_UNKNOWN },
		{ "", 0, MLOD_FORMAT_UNKNOWN },
	};
	for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++)
		CHECK_MSG(mlod_detect_format(cases[i].bytes, cases[i].size) == cases[i].want, "case %zu", i);
	CHECK(mlod_detect_format(NULL, 10) == MLOD_FORMAT_UNKNOWN);
}

TEST(load_bvh)
{
	size_t size = 0;
	char *data = test_read_file("samples/cmu_12_01_walk.bvh", &size);
	CHECK(data);
	mlod_gltf *doc = NULL;
	mlod_character c;
	mlod_format f = MLOD_FORMAT_UNKNOWN;
	mlod_result r = mlod_load(data, size, NULL, &doc, &c, &f, &terr);
	free(data);
	CHECK_MSG(r == MLOD_OK, "%s", terr.message);
	CHECK(f == MLOD_FORMAT_BVH && doc);
	CHECK(c.skeleton.joint_count == 31 && c.clip_count == 1 && c.clips[0].frame_count == 524);
	CHECK(mlod_gltf_count(doc, MLOD_GLTF_NODE) >= 31);
	void *glb = NULL;
	size_t glb_size = 0;
	CHECK_OK(mlod_gltf_write(doc, 1, &glb, &glb_size, &terr));
	CHECK(glb_size > 12 && mlod_detect_format(glb, glb_size) == MLOD_FORMAT_GLB);
	mlod_free(glb);
	mlod_gltf_free(doc);
	mlod_character_free(&c);

	/* Without a document. */
	data = test_read_file("tests/data/mixed_channels.bvh", &size);
	r = mlod_load(data, size, NULL, NULL, &c, NULL, &terr);
	free(data);
	CHECK_MSG(r == MLOD_OK, "%s", terr.message);
	CHECK(c.skeleton.joint_count == 8);
	mlod_character_free(&c);
}

TEST(load_glb)
{
	size_t size = 0;
	char *data = test_read_file("samples/RobotExpressive.glb", &size);
	CHECK(data);
	mlod_gltf *doc = NULL;
	mlod_character c;
	mlod_format f = MLOD_FORMAT_UNKNOWN;
	mlod_result r = mlod_load(data, size, "samples", &doc, &c, &f, &terr);
	CHECK_MSG(r == MLOD_OK, "%s", terr.message);
	CHECK(f == MLOD_FORMAT_GLB && doc);
	CHECK(c.skeleton.joint_count > 0 && c.clip_count > 0 && c.mesh_count > 0);
	mlod_gltf_free(doc);
	/* Its clips as BVH: rest rotations folded into the channels. */
	for (int k = 0; k < c.clip_count && !test_failed_; k++) {
		char what[160];
		snprintf(what, sizeof what, "RobotExpressive.glb clip %d (%.100s)", k, c.clips[k].name);
		check_clip_round_trip(&c, k, 0.0f, 1, what);
	}
	mlod_character_free(&c);
	if (test_failed_) {
		free(data);
		return;
	}

	/* Truncated: an error, and nothing left allocated. */
	doc = (mlod_gltf *)&c;
	r = mlod_load(data, size / 2, NULL, &doc, &c, NULL, &terr);
	free(data);
	CHECK(r != MLOD_OK && doc == NULL);
	CHECK(c.skeleton.joints == NULL && c.meshes == NULL && c.clips == NULL);
}

TEST(load_errors)
{
	mlod_gltf *doc = NULL;
	mlod_character c;
	mlod_format f;
	CHECK(mlod_load("", 0, NULL, &doc, &c, &f, &terr) == MLOD_ERR_PARSE);
	CHECK(strcmp(terr.message, "empty input") == 0 && !doc);
	CHECK(mlod_load(" \n\t\r\n", 5, NULL, &doc, &c, &f, &terr) == MLOD_ERR_PARSE);
	CHECK(strcmp(terr.message, "empty input") == 0);
	CHECK(mlod_load("hello, world\n", 13, NULL, &doc, &c, &f, &terr) == MLOD_ERR_UNSUPPORTED);
	CHECK(strcmp(terr.message, "not a glTF, glb or BVH file") == 0 && !doc && f == MLOD_FORMAT_UNKNOWN);
	CHECK(mlod_load("\x00\x01\x02\x03", 4, NULL, &doc, &c, &f, &terr) == MLOD_ERR_UNSUPPORTED);
	CHECK(mlod_load(NULL, 4, NULL, &doc, &c, &f, &terr) == MLOD_ERR_INVALID_ARG);
	CHECK(mlod_load("HIERARCHY", 9, NULL, &doc, NULL, &f, &terr) == MLOD_ERR_INVALID_ARG);

	size_t size = 0;
	char *data = test_read_file("tests/data/bad/missing_brace.bvh", &size);
	CHECK(data);
	memset(&c, 0x5a, sizeof c);
	mlod_result r = mlod_load(data, size, NULL, &doc, &c, &f, &terr);
	free(data);
	CHECK(r == MLOD_ERR_PARSE && f == MLOD_FORMAT_BVH && !doc);
	CHECK_MSG(strncmp(terr.message, "line 15: ", 9) == 0, "%s", terr.message);
	CHECK(c.skeleton.joints == NULL && c.clips == NULL && c.skeleton.joint_count == 0);

	CHECK(mlod_load("{\"asset\":", 10, NULL, &doc, &c, &f, &terr) != MLOD_OK);
	CHECK(f == MLOD_FORMAT_GLTF && !doc && c.skeleton.joints == NULL);
}

int main(void)
{
	RUN(cmu_walk);
	RUN(mixed_channel_orders);
	RUN(several_roots);
	RUN(lenient_syntax);
	RUN(extreme_values);
	RUN(malformed);
	RUN(deep_nesting);
	RUN(truncation);
	RUN(mutations);
	RUN(data_files);
	RUN(round_trip_cmu);
	RUN(round_trip_files);
	RUN(round_trip_shared);
	RUN(round_trip_assimp);
	RUN(write_gltf_like);
	RUN(write_rest_and_arguments);
	RUN(write_angles);
	RUN(detect_format);
	RUN(load_bvh);
	RUN(load_glb);
	RUN(load_errors);
	TEST_EXIT();
}
