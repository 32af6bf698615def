/* test_motion.c: the motion layer: common timelines, frame distance, the
 * multiresolution motion tree and per-channel key reduction. */
#include "test.h"
#include "motion/motion_eval.h"

#define PI_F 3.14159265358979323846f

/* A chain of n joints, bones of length 1 along y, and one clip of F
 * frames at 30 fps with a LINEAR rotation channel per joint (values
 * zeroed: the caller fills them). */
static mlod_character make_chain(int n, int F)
{
	mlod_character c = {0};
	c.skeleton.joint_count = n;
	c.skeleton.joints = calloc((size_t)n, sizeof(mlod_joint));
	for (int j = 0; j < n; j++) {
		mlod_joint *jt = &c.skeleton.joints[j];
		char name[16];
		snprintf(name, sizeof name, "j%d", j);
		jt->name = strdup(name);
		jt->parent = j - 1;
		jt->rest = mlod_trs_identity();
		jt->rest.t.y = j > 0 ? 1.0f : 0.0f;
		jt->base = mlod_mat4_identity();
		jt->node = -1;
	}
	c.clip_count = 1;
	c.clips = calloc(1, sizeof(mlod_clip));
	mlod_clip *cl = &c.clips[0];
	cl->name = strdup("test");
	cl->gltf_index = -1;
	cl->channel_count = n;
	cl->channels = calloc((size_t)n, sizeof(mlod_channel));
	cl->duration = (float)(F - 1) / 30.0f;
	for (int j = 0; j < n; j++) {
		mlod_channel *ch = &cl->channels[j];
		ch->joint = j;
		ch->path = MLOD_PATH_ROTATION;
		ch->interp = MLOD_INTERP_LINEAR;
		ch->key_count = F;
		ch->times = calloc((size_t)F, sizeof(float));
		ch->values = calloc((size_t)F * 4, sizeof(float));
		for (int f = 0; f < F; f++) {
			ch->times[f] = (float)f / 30.0f;
			ch->values[4 * f + 3] = 1.0f;
		}
	}
	return c;
}

static void set_rot(mlod_channel *ch, int f, mlod_quat q)
{
	float *v = ch->values + 4 * f;
	v[0] = q.x, v[1] = q.y, v[2] = q.z, v[3] = q.w;
}

static int load_sample(const char *path, mlod_character *c)
{
	size_t size;
	void *data = test_read_file(path, &size);
	if (!data)
		return -1;
	mlod_error e = {0};
	mlod_result r = mlod_load(data, size, "samples", NULL, c, NULL, &e);
	free(data);
	if (r != MLOD_OK)
		fprintf(stderr, "%s: %s\n", path, e.message);
	return r == MLOD_OK ? 0 : -1;
}

/* World positions of every joint of c posed by clip at t. */
static void positions(const mlod_character *c, const mlod_clip *clip, float t, mlod_v3 *out)
{
	int n = c->skeleton.joint_count;
	mlod_trs *l = malloc(sizeof *l * (size_t)n);
	mlod_mat4 *w = malloc(sizeof *w * (size_t)n);
	mlod_pose_rest(&c->skeleton, l);
	mlod_clip_sample(clip, t, l);
	mlod_pose_world(&c->skeleton, l, w);
	for (int j = 0; j < n; j++)
		out[j] = mlod_mat4_point(&w[j], (mlod_v3){0, 0, 0});
	free(l);
	free(w);
}

/* First and last key times over a clip's channels. */
static void clip_span(const mlod_clip *clip, float *first, float *last)
{
	*first = 1e30f, *last = -1e30f;
	for (int i = 0; i < clip->channel_count; i++) {
		const mlod_channel *ch = &clip->channels[i];
		if (ch->times[0] < *first)
			*first = ch->times[0];
		if (ch->times[ch->key_count - 1] > *last)
			*last = ch->times[ch->key_count - 1];
	}
}

/* Levels under bounds of 0.2%, 1% and 3% of the height, for one method:
 * each within its bound, ordered, keeping duration and end frames. */
static int check_levels(const mlod_character *c, int k, mlod_motion_method method, mlod_motion_precision precision,
                        char *why, size_t size)
{
	double h = mlod_skeleton_height(&c->skeleton), pct[3] = {0.2, 1.0, 3.0};
	/* Exact, but for rotations on the lattice of normalised shorts (auto
	 * precision), within 1/65534 per component: a few 1e-5 of the height. */
	double end_tol = precision == MLOD_MOTION_PRECISION_AUTO ? 2e-4 : 1e-6;
	mlod_motion *m = NULL;
	mlod_error e = {0};
	mlod_motion_options opt = {0};
	opt.precision = precision;
	const mlod_clip *src = &c->clips[k];
	long prev = mlod_clip_key_count(src);
	float f0, f1;
	clip_span(src, &f0, &f1);
	int n = c->skeleton.joint_count, bad = 0;
	mlod_v3 *a = malloc(sizeof *a * (size_t)n), *b = malloc(sizeof *b * (size_t)n);
	if (mlod_motion_create(c, k, &opt, &m, &e) != MLOD_OK) {
		snprintf(why, size, "create: %.400s", e.message);
		bad = 1;
	}
	for (int l = 0; l < 3 && !bad; l++) {
		mlod_motion_level lv;
		double bound = pct[l] * h / 100.0;
		if (mlod_motion_next_level(m, method, MLOD_MOTION_MAX_ERROR, bound, &lv, &e) != MLOD_OK) {
			snprintf(why, size, "clip %d level %d: %.400s", k, l + 1, e.message);
			bad = 1;
			break;
		}
		float g0, g1;
		clip_span(&lv.clip, &g0, &g1);
		if (!(lv.error.max <= bound))
			snprintf(why, size, "clip %d level %d: error %g over bound %g", k, l + 1, lv.error.max, bound), bad = 1;
		else if (lv.keys > prev)
			snprintf(why, size, "clip %d level %d: %ld keys after %ld", k, l + 1, lv.keys, prev), bad = 1;
		else if (g0 != f0 || g1 != f1 || lv.clip.duration != src->duration)
			snprintf(why, size, "clip %d level %d: span %g..%g (duration %g) for %g..%g (%g)", k, l + 1, g0, g1,
			         lv.clip.duration, f0, f1, src->duration), bad = 1;
		/* The first and last frames are kept exactly. */
		for (int end = 0; end < 2 && !bad; end++) {
			float t = end ? f1 : f0;
			positions(c, src, t, a);
			positions(c, &lv.clip, t, b);
			for (int j = 0; j < n && !bad; j++)
				if (mlod_v3_length(mlod_v3_sub(a[j], b[j])) > end_tol * h)
					snprintf(why, size, "clip %d level %d: joint %d moved by %g at t = %g", k, l + 1, j,
					         mlod_v3_length(mlod_v3_sub(a[j], b[j])), t), bad = 1;
		}
		prev = lv.keys;
		mlod_motion_level_free(&lv);
	}
	mlod_motion_free(m);
	free(a);
	free(b);
	return bad;
}

TEST(levels_within_bounds_cmu)
{
	mlod_character c;
	char why[512] = "";
	CHECK(load_sample("samples/cmu_12_01_walk.bvh", &c) == 0);
	for (int p = 0; p <= MLOD_MOTION_PRECISION_FULL; p++) {
		CHECK_MSG(!check_levels(&c, 0, MLOD_MOTION_FRAMES, (mlod_motion_precision)p, why, sizeof why), "frames: %s", why);
		CHECK_MSG(!check_levels(&c, 0, MLOD_MOTION_KEYS, (mlod_motion_precision)p, why, sizeof why), "keys: %s", why);
	}
	mlod_character_free(&c);
}

TEST(levels_within_bounds_robot)
{
	mlod_character c;
	char why[512] = "";
	CHECK(load_sample("samples/RobotExpressive.glb", &c) == 0);
	for (int k = 0; k < c.clip_count; k++)
		for (int p = 0; p <= MLOD_MOTION_PRECISION_FULL; p++) {
			mlod_motion_precision pr = (mlod_motion_precision)p;
			CHECK_MSG(!check_levels(&c, k, MLOD_MOTION_FRAMES, pr, why, sizeof why), "frames, precision %d: %s", p, why);
			CHECK_MSG(!check_levels(&c, k, MLOD_MOTION_KEYS, pr, why, sizeof why), "keys, precision %d: %s", p, why);
		}
	mlod_character_free(&c);
}

TEST(keys_method_beats_frames_on_cmu)
{
	/* The measurement behind the default: at 1% of the height. */
	mlod_character c;
	CHECK(load_sample("samples/cmu_12_01_walk.bvh", &c) == 0);
	double bound = 0.01 * mlod_skeleton_height(&c.skeleton);
	long bytes[2];
	for (int method = 0; method < 2; method++) {
		mlod_motion *m;
		mlod_motion_level lv;
		CHECK_OK(mlod_motion_create(&c, 0, NULL, &m, &terr));
		CHECK_OK(mlod_motion_next_level(m, (mlod_motion_method)method, MLOD_MOTION_MAX_ERROR, bound, &lv, &terr));
		bytes[method] = lv.bytes;
		CHECK(lv.bytes == mlod_clip_key_bytes(&lv.clip) && lv.keys == mlod_clip_key_count(&lv.clip));
		mlod_motion_level_free(&lv);
		mlod_motion_free(m);
	}
	CHECK_MSG(bytes[MLOD_MOTION_KEYS] < bytes[MLOD_MOTION_FRAMES], "keys %ld bytes, frames %ld", bytes[1], bytes[0]);
	mlod_character_free(&c);
}

/* The keys method's limit has one owner, mlod_motion_keys_fit: 30 joints
 * at 2 samples per interval take 16,667 frames (999,960 samples), not
 * 16,668 (1,000,080), and the message names the clip and says to split it
 * (the bake and the pack writer then note that the frames method alone
 * made the levels). */
TEST(keys_fit_limit)
{
	mlod_error e = { 0 };
	CHECK(mlod_motion_keys_fit(30, 16667, 2, "walk", &e) == MLOD_OK);
	CHECK(mlod_motion_keys_fit(30, 16668, 2, "walk", &e) == MLOD_ERR_LIMIT);
	CHECK(strstr(e.message, "clip \"walk\": 16668 frames (2 samples each) of 30 joints") != NULL);
	CHECK(strstr(e.message, "split the clip") != NULL);
	CHECK(mlod_motion_keys_fit(30, 8334, 4, "walk", &e) == MLOD_OK);
	CHECK(mlod_motion_keys_fit(30, 8335, 4, "walk", &e) == MLOD_ERR_LIMIT);
}

TEST(fraction_of_keys)
{
	mlod_character c;
	CHECK(load_sample("samples/cmu_12_01_walk.bvh", &c) == 0);
	long total = mlod_clip_key_count(&c.clips[0]);
	for (int method = 0; method < 2; method++) {
		mlod_motion *m;
		CHECK_OK(mlod_motion_create(&c, 0, NULL, &m, &terr));
		double fr[2] = {0.5, 0.1};
		for (int i = 0; i < 2; i++) {
			mlod_motion_level lv;
			CHECK_OK(mlod_motion_next_level(m, (mlod_motion_method)method, MLOD_MOTION_FRACTION, fr[i], &lv, &terr));
			CHECK_MSG(lv.keys <= (long)(fr[i] * (double)total), "method %d: %ld keys for %g of %ld", method, lv.keys,
			          fr[i], total);
			/* Not absurdly fewer: within 40% of the target. */
			CHECK_MSG(lv.keys >= (long)(0.6 * fr[i] * (double)total), "method %d: only %ld keys for %g of %ld", method,
			          lv.keys, fr[i], total);
			mlod_motion_level_free(&lv);
		}
		mlod_motion_free(m);
	}
	mlod_character_free(&c);
}

TEST(tree_levels_are_nested)
{
	mlod_character c;
	CHECK(load_sample("samples/cmu_12_01_walk.bvh", &c) == 0);
	mlod_motion *m;
	CHECK_OK(mlod_motion_create(&c, 0, NULL, &m, &terr));
	double T[3] = {0.1, 0.2, 0.5};
	mlod_motion_level prev = {0};
	for (int i = 0; i < 3; i++) {
		mlod_motion_level lv;
		CHECK_OK(mlod_motion_next_level(m, MLOD_MOTION_FRAMES, MLOD_MOTION_THRESHOLD, T[i], &lv, &terr));
		CHECK(lv.threshold == T[i]);
		/* Removal keeps original frames: each level's times are among the previous level's. */
		const mlod_channel *ch = &lv.clip.channels[0];
		const mlod_channel *pc = i ? &prev.clip.channels[0] : &c.clips[0].channels[0];
		CHECK(ch->key_count < pc->key_count);
		for (int k = 0, p = 0; k < ch->key_count; k++) {
			while (p < pc->key_count && pc->times[p] != ch->times[k])
				p++;
			CHECK_MSG(p < pc->key_count, "level %d: time %g is not in the previous level", i + 1, ch->times[k]);
		}
		mlod_motion_level_free(&prev);
		prev = lv;
	}
	mlod_motion_level_free(&prev);
	mlod_motion_free(m);
	CHECK_OK(mlod_motion_create(&c, 0, NULL, &m, &terr));
	mlod_motion_level lv;
	CHECK(mlod_motion_next_level(m, MLOD_MOTION_KEYS, MLOD_MOTION_THRESHOLD, 0.1, &lv, &terr) == MLOD_ERR_INVALID_ARG);
	CHECK(mlod_motion_next_level(m, MLOD_MOTION_KEYS, MLOD_MOTION_FRACTION, 1.5, &lv, &terr) == MLOD_ERR_INVALID_ARG);
	mlod_motion_free(m);
	mlod_character_free(&c);
}

TEST(average_merge_keeps_ends)
{
	mlod_character c;
	CHECK(load_sample("samples/cmu_12_01_walk.bvh", &c) == 0);
	mlod_motion *m;
	mlod_motion_options opt = {0};
	opt.merge = MLOD_MOTION_AVERAGE;
	CHECK_OK(mlod_motion_create(&c, 0, &opt, &m, &terr));
	mlod_motion_level lv;
	CHECK_OK(mlod_motion_next_level(m, MLOD_MOTION_FRAMES, MLOD_MOTION_THRESHOLD, 0.05, &lv, &terr));
	const mlod_channel *ch = &lv.clip.channels[0], *src = &c.clips[0].channels[0];
	CHECK(ch->key_count < src->key_count);
	CHECK(ch->times[0] == src->times[0] && ch->times[ch->key_count - 1] == src->times[src->key_count - 1]);
	CHECK(memcmp(ch->values, src->values, 3 * sizeof(float)) == 0);
	/* Averaged frames sit at times that no original frame has. */
	int off_grid = 0;
	for (int k = 0; k < ch->key_count; k++) {
		double f = ch->times[k] / c.clips[0].frame_time;
		off_grid += fabs(f - floor(f + 0.5)) > 1e-3;
	}
	CHECK(off_grid > 0);
	mlod_motion_level_free(&lv);
	mlod_motion_free(m);
	mlod_character_free(&c);
}

TEST(sign_flips_are_not_motion)
{
	/* One joint holding the same rotation, stored as q and -q in turn. */
	mlod_character c = make_chain(2, 20);
	mlod_quat q = mlod_quat_axis_angle((mlod_v3){0.3f, 1, 0.2f}, 1.1f);
	mlod_quat nq = {-q.x, -q.y, -q.z, -q.w};
	for (int f = 0; f < 20; f++)
		set_rot(&c.clips[0].channels[0], f, f % 2 ? nq : q);
	mlod_trs a[2], b[2];
	mlod_pose_rest(&c.skeleton, a);
	mlod_pose_rest(&c.skeleton, b);
	a[0].r = q;
	b[0].r = nq;
	CHECK(mlod_motion_frame_distance(&c.skeleton, a, b) < 1e-6);
	for (int method = 0; method < 2; method++) {
		mlod_motion *m;
		mlod_motion_level lv;
		CHECK_OK(mlod_motion_create(&c, 0, NULL, &m, &terr));
		if (method == MLOD_MOTION_FRAMES)
			CHECK_OK(mlod_motion_next_level(m, MLOD_MOTION_FRAMES, MLOD_MOTION_THRESHOLD, 1e-6, &lv, &terr));
		else
			CHECK_OK(mlod_motion_next_level(m, MLOD_MOTION_KEYS, MLOD_MOTION_MAX_ERROR, 1e-6, &lv, &terr));
		/* Nothing moves: one key per channel, and one more to keep the duration. */
		CHECK_MSG(lv.keys <= 3, "method %d: %ld keys", method, lv.keys);
		CHECK(lv.clip.duration == c.clips[0].duration);
		mlod_motion_level_free(&lv);
		mlod_motion_free(m);
	}
	mlod_character_free(&c);
}

TEST(angle_wrap_is_not_motion)
{
	/* A BVH-like joint turning 170, 179, -179, -170 degrees about z: the
	 * steps are 9, 2 and 9 degrees, not 358. */
	mlod_character c = make_chain(2, 4);
	c.skeleton.joints[0].euler = MLOD_EULER_ZXY;
	float deg[4] = {170, 179, -179, -170};
	mlod_trs p[4][2];
	for (int f = 0; f < 4; f++) {
		float e[3] = {0, 0, deg[f] * PI_F / 180.0f};
		mlod_pose_rest(&c.skeleton, p[f]);
		p[f][0].r = mlod_quat_from_euler(MLOD_EULER_ZXY, e);
	}
	double d01 = mlod_motion_frame_distance(&c.skeleton, p[0], p[1]);
	double d12 = mlod_motion_frame_distance(&c.skeleton, p[1], p[2]);
	double d23 = mlod_motion_frame_distance(&c.skeleton, p[2], p[3]);
	/* Weight of the root: (h - 0) / h = 1; distance = angle / pi. */
	CHECK_NEAR(d12, 2.0 / 180.0, 1e-5);
	CHECK_NEAR(d01, 9.0 / 180.0, 1e-5);
	CHECK_NEAR(d23, d01, 1e-5);
	/* A joint one level down weighs (2 - 1) / 2. */
	mlod_trs q0[2], q1[2];
	mlod_pose_rest(&c.skeleton, q0);
	mlod_pose_rest(&c.skeleton, q1);
	q0[1].r = p[1][0].r;
	q1[1].r = p[2][0].r;
	CHECK_NEAR(mlod_motion_frame_distance(&c.skeleton, q0, q1), 0.5 * 2.0 / 180.0, 1e-5);
	/* Near gimbal lock the two Euler triples of a rotation are both valid:
	 * the distance between a pose and itself through either is 0. */
	float g[3] = {0.4f, PI_F / 2 - 1e-4f, -0.7f};
	mlod_trs r0[2], r1[2];
	mlod_pose_rest(&c.skeleton, r0);
	mlod_pose_rest(&c.skeleton, r1);
	r0[0].r = mlod_quat_from_euler(MLOD_EULER_XYZ, g);
	float g2[3] = {g[0] + PI_F, PI_F - g[1], g[2] + PI_F};
	r1[0].r = mlod_quat_from_euler(MLOD_EULER_XYZ, g2);
	CHECK(mlod_quat_angle(r0[0].r, r1[0].r) < 1e-3f);
	CHECK(mlod_motion_frame_distance(&c.skeleton, r0, r1) < 1e-2);
	mlod_character_free(&c);
}

TEST(points_out_from_leaves_are_kept)
{
	/* Only the leaf turns: no joint position moves, yet both methods keep
	 * the leaf's rotation, so that points point_distance out from it stay
	 * within the bound (the skin around a hand, say). */
	int F = 61;
	mlod_character c = make_chain(3, F);
	for (int f = 0; f < F; f++)
		set_rot(&c.clips[0].channels[2], f, mlod_quat_axis_angle((mlod_v3){1, 0, 0}, 0.8f * sinf(0.3f * (float)f)));
	double bound = 0.01, r = 0.1;
	mlod_motion_options opt = {0};
	opt.point_distance = r;
	for (int method = 0; method < 2; method++) {
		mlod_motion *m;
		mlod_motion_level lv;
		CHECK_OK(mlod_motion_create(&c, 0, &opt, &m, &terr));
		CHECK_OK(mlod_motion_next_level(m, (mlod_motion_method)method, MLOD_MOTION_MAX_ERROR, bound, &lv, &terr));
		const mlod_channel *ch = &lv.clip.channels[2];
		CHECK_MSG(ch->key_count > 2 && ch->key_count < F, "method %d: %d keys", method, ch->key_count);
		CHECK(lv.error.max <= bound && lv.point_error <= bound);
		/* Constant channels collapse to one key (and one more for the duration). */
		CHECK(lv.clip.channels[0].key_count <= 2 && lv.clip.channels[1].key_count <= 2);
		double max_angle = 2.0 * asin(bound / (2.0 * r)), worst = 0.0;
		for (int f = 0; f < F; f++) {
			float t = c.clips[0].channels[0].times[f];
			mlod_trs a[3], b[3];
			mlod_pose_rest(&c.skeleton, a);
			mlod_pose_rest(&c.skeleton, b);
			mlod_clip_sample(&c.clips[0], t, a);
			mlod_clip_sample(&lv.clip, t, b);
			if (mlod_quat_angle(a[2].r, b[2].r) > worst)
				worst = mlod_quat_angle(a[2].r, b[2].r);
		}
		CHECK_MSG(worst <= max_angle * 1.0001, "method %d: leaf rotation error %g rad over %g", method, worst, max_angle);
		mlod_motion_level_free(&lv);
		mlod_motion_free(m);
	}
	mlod_character_free(&c);
}

TEST(hierarchy_error_is_bounded)
{
	/* The root's rotation swings a long chain: removing root keys moves the
	 * far joints most. Every joint stays within the bound at every frame. */
	int F = 90, n = 6;
	mlod_character c = make_chain(n, F);
	for (int j = 0; j < n; j++)
		for (int f = 0; f < F; f++)
			set_rot(&c.clips[0].channels[j], f,
			        mlod_quat_axis_angle((mlod_v3){0, 0, 1}, 0.3f * sinf(0.1f * (float)(f + 7 * j))));
	double bound = 0.05;
	mlod_motion *m;
	mlod_motion_level lv;
	CHECK_OK(mlod_motion_create(&c, 0, NULL, &m, &terr));
	CHECK_OK(mlod_motion_next_level(m, MLOD_MOTION_KEYS, MLOD_MOTION_MAX_ERROR, bound, &lv, &terr));
	CHECK(lv.keys < mlod_clip_key_count(&c.clips[0]));
	mlod_v3 a[6], b[6];
	for (int f = 0; f < F; f++) {
		positions(&c, &c.clips[0], c.clips[0].channels[0].times[f], a);
		positions(&c, &lv.clip, c.clips[0].channels[0].times[f], b);
		for (int j = 0; j < n; j++)
			CHECK_MSG(mlod_v3_length(mlod_v3_sub(a[j], b[j])) <= bound, "frame %d joint %d: %g", f, j,
			          mlod_v3_length(mlod_v3_sub(a[j], b[j])));
	}
	/* The root, which moves everything, keeps more keys than a leaf-side joint. */
	CHECK(lv.clip.channels[0].key_count >= lv.clip.channels[n - 2].key_count);
	mlod_motion_level_free(&lv);
	mlod_motion_free(m);
	mlod_character_free(&c);
}

/* Largest joint position error of level against clip 0 of c at 16
 * samples per frame interval. */
static double dense_error(const mlod_character *c, const mlod_clip *level)
{
	const mlod_channel *ch = &c->clips[0].channels[0];
	int n = (ch->key_count - 1) * 16 + 1;
	float *st = malloc(sizeof(float) * (size_t)n);
	mlod_motion_sample_times(ch->times, ch->key_count, 16, st);
	mlod_character a = *c, b = *c;
	b.clips = (mlod_clip *)level;
	mlod_deviation d = {0, 0, 0};
	mlod_result r = mlod_joint_deviation_at(&a, &b, st, n, &d, &terr);
	free(st);
	return r == MLOD_OK ? d.max : HUGE_VAL;
}

TEST(level_error_same_as_joint_deviation)
{
	/* A level's error (level_measure_of: the point distances inline,
	 * point_gap) is mlod_joint_deviation_at's at the level's samples, bit
	 * for bit: the keys and the frames method's, rounded. */
	mlod_character c;
	CHECK(load_sample("samples/cmu_12_01_walk.bvh", &c) == 0);
	double h = mlod_skeleton_height(&c.skeleton);
	const mlod_channel *ch = &c.clips[0].channels[0];
	int n = (ch->key_count - 1) * MLOD_DEFAULT_SUBDIVIDE + 1;
	float *st = malloc(sizeof(float) * (size_t)n);
	CHECK(st != NULL);
	mlod_motion_sample_times(ch->times, ch->key_count, MLOD_DEFAULT_SUBDIVIDE, st);
	mlod_motion_method methods[2] = { MLOD_MOTION_KEYS, MLOD_MOTION_FRAMES };
	for (int i = 0; i < 2; i++) {
		mlod_motion *m;
		CHECK_OK(mlod_motion_create(&c, 0, NULL, &m, &terr));
		CHECK(mlod_motion_timeline_info(m)->frames == ch->key_count);
		for (int k = 0; k < 2; k++) {
			mlod_motion_level lv;
			CHECK_OK(mlod_motion_next_level(m, methods[i], MLOD_MOTION_MAX_ERROR, (k ? 0.02 : 0.005) * h, &lv, &terr));
			mlod_character b = c;
			b.clips = &lv.clip;
			mlod_deviation d = { 0, 0, 0 };
			CHECK_OK(mlod_joint_deviation_at(&c, &b, st, n, &d, &terr));
			CHECK_MSG(d.max == lv.error.max && d.mean == lv.error.mean && d.max > 0.0,
			          "method %d, level %d: %.17g %.17g, measured %.17g %.17g", i, k + 1, lv.error.max,
			          lv.error.mean, d.max, d.mean);
			mlod_motion_level_free(&lv);
		}
		mlod_motion_free(m);
	}
	free(st);
	mlod_character_free(&c);
}

TEST(bound_holds_between_frames)
{
	/* A root A with a rotation and a translation, and a child C carried
	 * 1 out along x by its own translation. A holds -90 degrees about z,
	 * sweeps to +90 between frames 1 and 2 and holds. Both translations
	 * step out by d at frames 1 and 2 and back. Dropping the two
	 * translation keys leaves C off by d sqrt 2 at frames 1 and 2 (the two
	 * errors at right angles) but by 2 d halfway between them, where A's
	 * rotation lines them up: within a bound of 1.6 d at the frames, over
	 * it between them. */
	const float d = 0.01f;
	const double bound = 1.6 * d;
	mlod_character c = {0};
	c.skeleton.joint_count = 2;
	c.skeleton.joints = calloc(2, sizeof(mlod_joint));
	for (int j = 0; j < 2; j++) {
		mlod_joint *jt = &c.skeleton.joints[j];
		jt->name = strdup(j ? "C" : "A");
		jt->parent = j - 1;
		jt->rest = mlod_trs_identity();
		jt->rest.t.x = j ? 1.0f : 0.0f;
		jt->base = mlod_mat4_identity();
		jt->node = -1;
	}
	c.clip_count = 1;
	c.clips = calloc(1, sizeof(mlod_clip));
	mlod_clip *cl = &c.clips[0];
	cl->name = strdup("sweep");
	cl->gltf_index = -1;
	cl->channel_count = 3;
	cl->channels = calloc(3, sizeof(mlod_channel));
	cl->duration = 3.0f / 30.0f;
	static const float angle[4] = {-90.0f, -90.0f, 90.0f, 90.0f};
	for (int i = 0; i < 3; i++) {
		mlod_channel *ch = &cl->channels[i];
		int comps = i == 0 ? 4 : 3;
		ch->joint = i == 2 ? 1 : 0;
		ch->path = i == 0 ? MLOD_PATH_ROTATION : MLOD_PATH_TRANSLATION;
		ch->interp = MLOD_INTERP_LINEAR;
		ch->key_count = 4;
		ch->times = calloc(4, sizeof(float));
		ch->values = calloc(4 * (size_t)comps, sizeof(float));
		for (int f = 0; f < 4; f++) {
			float *v = ch->values + comps * f, out = f == 1 || f == 2 ? d : 0.0f;
			ch->times[f] = (float)f / 30.0f;
			if (i == 0)
				set_rot(ch, f, mlod_quat_axis_angle((mlod_v3){0, 0, 1}, angle[f] * PI_F / 180.0f));
			else
				v[0] = (i == 2 ? 1.0f : 0.0f) + out;
		}
	}
	mlod_motion_options opt = {0};
	opt.precision = MLOD_MOTION_PRECISION_FULL;
	opt.point_distance = 1e-3;
	for (int sub = 1; sub <= 2; sub++) {
		mlod_motion *m;
		mlod_motion_level lv;
		opt.subdivide = sub == 1 ? 1 : 0; /* frames only; the default (midpoints) */
		CHECK_OK(mlod_motion_create(&c, 0, &opt, &m, &terr));
		CHECK_OK(mlod_motion_next_level(m, MLOD_MOTION_KEYS, MLOD_MOTION_MAX_ERROR, bound, &lv, &terr));
		double dense = dense_error(&c, &lv.clip);
		if (sub == 1) {
			/* Checked at the frames only: the level passes there, not between. */
			CHECK_MSG(lv.clip.channels[2].key_count == 1, "C keys %d", lv.clip.channels[2].key_count);
			CHECK_MSG(lv.error.max <= bound && dense > 1.2 * bound, "frames %g, between %g", lv.error.max, dense);
		} else {
			/* Checked at the midpoints too: C keeps keys, the bound holds. */
			CHECK_MSG(lv.clip.channels[2].key_count > 2, "C keys %d", lv.clip.channels[2].key_count);
			CHECK_MSG(lv.clip.channels[1].key_count == 1, "A translation keys %d", lv.clip.channels[1].key_count);
			CHECK_MSG(dense <= bound && lv.error.max <= bound && lv.point_error <= bound, "between %g, reported %g",
			          dense, lv.error.max);
		}
		mlod_motion_level_free(&lv);
		mlod_motion_free(m);
		/* The frames method drops nothing here (the sweep needs every frame). */
		CHECK_OK(mlod_motion_create(&c, 0, &opt, &m, &terr));
		CHECK_OK(mlod_motion_next_level(m, MLOD_MOTION_FRAMES, MLOD_MOTION_MAX_ERROR, bound, &lv, &terr));
		CHECK(dense_error(&c, &lv.clip) <= bound);
		mlod_motion_level_free(&lv);
		mlod_motion_free(m);
	}
	mlod_character_free(&c);
}

TEST(morph_weights_reduced_within_bound)
{
	/* Two targets over 11 keys: target 0 ramps 0 -> 1 (a line: its inner
	 * keys go), target 1 has a bump of h at key 5 with reach 2, so it
	 * costs 2 h there: it stays under a bound below 2 h and goes above. */
	const float h = 0.05f;
	mlod_weight_track t = {0};
	t.node = 3;
	t.targets = 2;
	t.interp = MLOD_INTERP_LINEAR;
	t.key_count = 11;
	t.times = malloc(sizeof(float) * 11);
	t.values = calloc(22, sizeof(float));
	for (int k = 0; k < 11; k++) {
		t.times[k] = (float)k / 10.0f;
		t.values[2 * k] = (float)k / 10.0f;
	}
	t.values[2 * 5 + 1] = h;
	const double reach[2] = {1.0, 2.0};
	mlod_weight_track out;
	double e;
	CHECK_OK(mlod_weight_track_reduce(&t, reach, 1.5 * h, 2, &out, &e, &terr));
	CHECK_MSG(out.key_count >= 3 && out.key_count < 11 && e <= 1.5 * h, "keys %d error %g", out.key_count, e);
	int has5 = 0;
	for (int k = 0; k < out.key_count; k++)
		has5 |= out.times[k] == t.times[5];
	CHECK(has5 && out.times[0] == t.times[0] && out.times[out.key_count - 1] == t.times[10]);
	free(out.times), free(out.values);
	CHECK_OK(mlod_weight_track_reduce(&t, reach, 2.5 * h, 2, &out, &e, &terr));
	CHECK_MSG(out.key_count == 2 && e <= 2.5 * h && e >= 1.9 * h, "keys %d error %g", out.key_count, e);
	free(out.times), free(out.values);
	/* A constant track keeps one key. */
	for (int k = 0; k < 22; k++)
		t.values[k] = 0.25f;
	CHECK_OK(mlod_weight_track_reduce(&t, reach, 0.0, 2, &out, &e, &terr));
	CHECK(out.key_count == 1 && out.values[0] == 0.25f && e == 0.0);
	free(out.times), free(out.values);
	t.interp = MLOD_INTERP_CUBICSPLINE;
	CHECK(mlod_weight_track_reduce(&t, reach, 0.1, 2, &out, &e, &terr) == MLOD_ERR_UNSUPPORTED);
	free(t.times), free(t.values);
}

TEST(morph_target_reach_in_scene_units)
{
	/* One rigid mesh on node 4, scaled by 2 in the scene: its target moves
	 * vertices by 0.1 and 0.3, so 0.6 in scene units. */
	mlod_character c = make_chain(1, 3);
	c.mesh_count = 1;
	c.meshes = calloc(1, sizeof(mlod_mesh));
	c.meshes[0].name = strdup("face");
	c.meshes[0].gltf_index = -1;
	c.meshes[0].primitive_count = 1;
	c.meshes[0].primitives = calloc(1, sizeof(mlod_primitive));
	mlod_primitive *p = &c.meshes[0].primitives[0];
	p->vertex_count = 2;
	p->positions = calloc(6, sizeof(float));
	p->mode = 4;
	p->material = -1;
	p->target_count = 1;
	p->targets = calloc(1, sizeof(mlod_morph_target));
	p->targets[0].positions = calloc(6, sizeof(float));
	p->targets[0].positions[0] = 0.1f;
	p->targets[0].positions[4] = 0.3f;
	c.instance_count = 1;
	c.instances = calloc(1, sizeof(mlod_instance));
	c.instances[0].mesh = 0;
	c.instances[0].node = 4;
	c.instances[0].skin = -1;
	c.instances[0].joint = -1;
	mlod_trs tr = mlod_trs_identity();
	tr.s = (mlod_v3){2, 2, 2};
	c.instances[0].offset = mlod_mat4_from_trs(&tr);
	double reach[2];
	CHECK_OK(mlod_morph_target_reach(&c, 4, 1, reach, &terr));
	CHECK_MSG(fabs(reach[0] - 0.6) < 1e-6, "reach %g", reach[0]);
	CHECK(mlod_morph_target_reach(&c, 5, 1, reach, &terr) == MLOD_ERR_INVALID_ARG);
	CHECK(mlod_morph_target_reach(&c, 4, 2, reach, &terr) == MLOD_ERR_INVALID_ARG);
	mlod_character_free(&c);
}

TEST(common_timeline)
{
	/* Two channels on different times: the union, exact at every key. */
	mlod_character c = make_chain(2, 5);
	mlod_channel *a = &c.clips[0].channels[0], *b = &c.clips[0].channels[1];
	for (int f = 0; f < 5; f++) {
		set_rot(a, f, mlod_quat_axis_angle((mlod_v3){0, 0, 1}, 0.2f * (float)f));
		set_rot(b, f, mlod_quat_axis_angle((mlod_v3){1, 0, 0}, 0.1f * (float)(f * f)));
		b->times[f] = (float)f / 30.0f + 0.01f;
	}
	c.clips[0].duration = b->times[4];
	mlod_clip common;
	mlod_motion_timeline info;
	CHECK_OK(mlod_motion_common_clip(&c.clips[0], NULL, &common, &info, &terr));
	CHECK(info.resampled == 1 && info.mismatched_channels == 2 && info.frames == 10 && info.cubic_channels == 0);
	CHECK(common.channels[0].key_count == 10 && common.channels[1].key_count == 10);
	for (int k = 0; k < 10; k++) {
		mlod_trs x[2], y[2];
		float t = common.channels[0].times[k];
		mlod_pose_rest(&c.skeleton, x);
		mlod_pose_rest(&c.skeleton, y);
		mlod_clip_sample(&c.clips[0], t, x);
		mlod_clip_sample(&common, t, y);
		CHECK(mlod_quat_angle(x[0].r, y[0].r) < 1e-5f && mlod_quat_angle(x[1].r, y[1].r) < 1e-5f);
	}
	mlod_clip_free(&common);

	/* Shared times and LINEAR: kept as they are. */
	for (int f = 0; f < 5; f++)
		b->times[f] = a->times[f];
	c.clips[0].duration = a->times[4];
	CHECK_OK(mlod_motion_common_clip(&c.clips[0], NULL, &common, &info, &terr));
	CHECK(info.resampled == 0 && info.frames == 5);
	mlod_clip_free(&common);

	/* CUBICSPLINE: resampled at the rate given, and LINEAR afterwards. */
	mlod_channel cubic = *a;
	float *cv = calloc(5 * 12, sizeof(float));
	for (int f = 0; f < 5; f++)
		memcpy(cv + 12 * f + 4, a->values + 4 * f, 4 * sizeof(float));
	float *saved = a->values;
	a->values = cv;
	a->interp = MLOD_INTERP_CUBICSPLINE;
	mlod_motion_options opt = {0};
	opt.cubic_rate = 120.0;
	CHECK_OK(mlod_motion_common_clip(&c.clips[0], &opt, &common, &info, &terr));
	CHECK(info.resampled == 1 && info.cubic_channels == 1);
	CHECK_MSG(info.frames == 17, "%d frames", info.frames); /* 4 intervals of 1/30 s at 120/s */
	CHECK(common.channels[0].interp == MLOD_INTERP_LINEAR);
	mlod_clip_free(&common);
	a->values = saved;
	a->interp = MLOD_INTERP_LINEAR;
	(void)cubic;
	free(cv);
	mlod_character_free(&c);
}

TEST(bad_clips)
{
	mlod_character c = make_chain(2, 4);
	mlod_clip common;
	mlod_channel *ch = &c.clips[0].channels[1];
	/* Decreasing key times. */
	ch->times[2] = ch->times[1] - 0.01f;
	CHECK(mlod_motion_common_clip(&c.clips[0], NULL, &common, NULL, &terr) == MLOD_ERR_PARSE);
	CHECK(strstr(terr.message, "times must increase") != NULL);
	ch->times[2] = 2.0f / 30.0f;
	/* NaN and infinity in a track. */
	ch->values[5] = NAN;
	CHECK(mlod_motion_common_clip(&c.clips[0], NULL, &common, NULL, &terr) == MLOD_ERR_PARSE);
	CHECK(strstr(terr.message, "not finite") != NULL);
	ch->values[5] = INFINITY;
	CHECK(mlod_motion_common_clip(&c.clips[0], NULL, &common, NULL, &terr) == MLOD_ERR_PARSE);
	ch->values[5] = 0.0f;
	/* A zero quaternion. */
	ch->values[7] = 0.0f;
	CHECK(mlod_motion_common_clip(&c.clips[0], NULL, &common, NULL, &terr) == MLOD_ERR_PARSE);
	CHECK(strstr(terr.message, "zero quaternion") != NULL);
	ch->values[7] = 1.0f;
	/* A negative first time. */
	ch->times[0] = -0.5f;
	CHECK(mlod_motion_common_clip(&c.clips[0], NULL, &common, NULL, &terr) == MLOD_ERR_PARSE);
	ch->times[0] = 0.0f;
	/* No keys. */
	ch->key_count = 0;
	CHECK(mlod_motion_common_clip(&c.clips[0], NULL, &common, NULL, &terr) == MLOD_ERR_PARSE);
	ch->key_count = 4;
	CHECK_OK(mlod_motion_common_clip(&c.clips[0], NULL, &common, NULL, &terr));
	mlod_clip_free(&common);
	/* No clip at all (a BVH with "Frames: 0" has none). */
	mlod_motion *m = NULL;
	CHECK(mlod_motion_create(&c, 1, NULL, &m, &terr) == MLOD_ERR_INVALID_ARG && m == NULL);
	mlod_motion_free(NULL);
	mlod_clip_free(NULL);
	mlod_motion_level_free(NULL);
	mlod_character_free(&c);
}

TEST(one_frame_clip)
{
	/* Nothing to reduce: every level is the single frame. */
	mlod_character c = make_chain(3, 1);
	c.clips[0].duration = 0.0f;
	for (int method = 0; method < 2; method++) {
		mlod_motion *m;
		mlod_motion_level lv;
		CHECK_OK(mlod_motion_create(&c, 0, NULL, &m, &terr));
		CHECK(mlod_motion_timeline_info(m)->frames == 1);
		CHECK_OK(mlod_motion_next_level(m, (mlod_motion_method)method, MLOD_MOTION_MAX_ERROR, 0.1, &lv, &terr));
		CHECK(lv.keys == 3 && lv.error.max == 0.0);
		mlod_motion_level_free(&lv);
		CHECK_OK(mlod_motion_next_level(m, (mlod_motion_method)method, MLOD_MOTION_FRACTION, 0.1, &lv, &terr));
		CHECK(lv.keys == 3);
		mlod_motion_level_free(&lv);
		mlod_motion_free(m);
	}
	mlod_character_free(&c);
}

TEST(clip_without_joint_channels)
{
	/* An animation of a camera or of morph weights alone reads as a clip
	 * with no channels: a timeline of no frames, and every level the
	 * empty clip (mlod_motion_common_clip failed it as MLOD_ERR_PARSE,
	 * "no channels to reduce", so mlod-motion and mlod-pack exited 2). */
	mlod_character c = make_chain(3, 10);
	mlod_clip *cl = &c.clips[0];
	for (int i = 0; i < cl->channel_count; i++) {
		free(cl->channels[i].times);
		free(cl->channels[i].values);
	}
	free(cl->channels);
	cl->channels = NULL;
	cl->channel_count = 0;
	mlod_clip common;
	mlod_motion_timeline info;
	CHECK_OK(mlod_motion_common_clip(cl, NULL, &common, &info, &terr));
	CHECK(info.frames == 0 && common.channel_count == 0 && strcmp(common.name, "test") == 0);
	mlod_clip_free(&common);
	for (int method = 0; method < 2; method++) {
		mlod_motion *m;
		mlod_motion_level lv;
		CHECK_OK(mlod_motion_create(&c, 0, NULL, &m, &terr));
		CHECK(mlod_motion_timeline_info(m)->frames == 0);
		CHECK_OK(mlod_motion_next_level(m, (mlod_motion_method)method, MLOD_MOTION_MAX_ERROR, 0.1, &lv, &terr));
		CHECK(lv.keys == 0 && lv.bytes == 0 && lv.error.max == 0.0 && lv.clip.channel_count == 0);
		CHECK(strcmp(lv.clip.name, "test") == 0);
		mlod_motion_level_free(&lv);
		mlod_motion_free(m);
	}
	/* The levels of several clips: none for it, and no failure. */
	mlod_motion_method methods[2] = {MLOD_MOTION_FRAMES, MLOD_MOTION_KEYS};
	mlod_motion_spec spec = {MLOD_MOTION_MAX_ERROR, 0.1};
	int clips[1] = {0};
	mlod_motion_clip_levels out[1];
	CHECK_OK(mlod_motion_build_levels(&c, clips, 1, NULL, methods, 2, &spec, 1, 2, out, &terr));
	CHECK(out[0].result == MLOD_OK && out[0].level_count == 0 && out[0].timeline.frames == 0);
	mlod_motion_clip_levels_free(out, 1);
	/* A channel count without channels is still refused. */
	cl->channel_count = 2;
	CHECK(mlod_motion_common_clip(cl, NULL, &common, NULL, &terr) == MLOD_ERR_PARSE);
	cl->channel_count = 0;
	mlod_character_free(&c);
}

TEST(names_escaped_in_messages)
{
	/* A clip name with a newline and an ANSI escape reaches stderr
	 * through the library's messages escaped (it was printed raw). */
	mlod_character c = make_chain(3, 10);
	free(c.clips[0].name);
	c.clips[0].name = strdup("w\nalk\x1b[31mRED\"");
	c.clips[0].channels[1].times[3] = c.clips[0].channels[1].times[2];
	mlod_clip common;
	CHECK(mlod_motion_common_clip(&c.clips[0], NULL, &common, NULL, &terr) == MLOD_ERR_PARSE);
	CHECK(strstr(terr.message, "clip \"w\\nalk\\u001b[31mRED\\\"\" channel 1: key 3") == terr.message);
	/* The helper: quoted for messages, C escapes for tables, cut to fit. */
	char b[MLOD_NAME_TEXT_SIZE];
	CHECK(strcmp(mlod_name_text("a\tb\x7f\\", 1, b, sizeof b), "\"a\\tb\\u007f\\\\\"") == 0);
	CHECK(strcmp(mlod_name_text("a\tb\x7f\xff\xc3\xa9", 0, b, sizeof b), "a\\tb\\x7f\\xff\xc3\xa9") == 0);
	CHECK(strcmp(mlod_name_text(NULL, 1, b, sizeof b), "\"\"") == 0);
	char small[16];
	CHECK(strcmp(mlod_name_text("abcdefghijklmnopqrstuvwxyz", 1, small, sizeof small), "\"abcdefghij...\"") == 0);
	CHECK(strcmp(mlod_name_text("\x1b\x1b\x1b\x1b", 0, small, sizeof small), "\\x1b\\x1b\\x1b...") == 0);
	CHECK(strcmp(mlod_name_text("abcdefghijklmno", 0, small, sizeof small), "abcdefghijklmno") == 0);
	CHECK(strcmp(mlod_name_text("abcdefghijklmnop", 0, small, sizeof small), "abcdefghijkl...") == 0);
	CHECK(strcmp(mlod_name_text("abcdefghijklm", 1, small, sizeof small), "\"abcdefghijklm\"") == 0);
	mlod_character_free(&c);
}

TEST(step_channels_stay_step)
{
	mlod_character c = make_chain(2, 30);
	mlod_channel *ch = &c.clips[0].channels[1];
	ch->interp = MLOD_INTERP_STEP;
	for (int f = 0; f < 30; f++)
		set_rot(ch, f, mlod_quat_axis_angle((mlod_v3){0, 0, 1}, (float)(f / 10)));
	for (int method = 0; method < 2; method++) {
		mlod_motion *m;
		mlod_motion_level lv;
		CHECK_OK(mlod_motion_create(&c, 0, NULL, &m, &terr));
		CHECK_OK(mlod_motion_next_level(m, (mlod_motion_method)method, MLOD_MOTION_MAX_ERROR, 1e-4, &lv, &terr));
		CHECK(lv.clip.channels[1].interp == MLOD_INTERP_STEP);
		CHECK(lv.error.max <= 1e-4);
		if (method == MLOD_MOTION_KEYS) /* the three steps, the last frame */
			CHECK_MSG(lv.clip.channels[1].key_count == 4, "%d keys", lv.clip.channels[1].key_count);
		mlod_motion_level_free(&lv);
		mlod_motion_free(m);
	}
	mlod_character_free(&c);
}

TEST(key_bytes)
{
	mlod_character c = make_chain(2, 10);
	/* Two channels sharing times: 2 * 10 * 16 value bytes + 10 * 4 time bytes. */
	CHECK(mlod_clip_key_bytes(&c.clips[0]) == 2 * 10 * 16 + 40);
	CHECK(mlod_clip_key_count(&c.clips[0]) == 20);
	c.clips[0].channels[1].times[9] += 0.01f;
	CHECK(mlod_clip_key_bytes(&c.clips[0]) == 2 * 10 * 16 + 80);
	mlod_character_free(&c);
}

/* Trailing zero bits of a float's mantissa (23 for 0 and powers of two). */
static int zero_bits(float v)
{
	uint32_t u;
	memcpy(&u, &v, sizeof u);
	u &= 0x7fffffu;
	int z = 0;
	if (!u)
		return 23;
	while (!(u & 1u))
		u >>= 1, z++;
	return z;
}

/* The keys levels of every robot clip at 1% of the height, with the given
 * precision; returns the values with at least 8 trailing zero bits. */
static long robot_levels(const mlod_character *c, mlod_motion_precision precision, mlod_motion_level *out)
{
	mlod_motion_options opt = {0};
	opt.precision = precision;
	double bound = 0.01 * mlod_skeleton_height(&c->skeleton);
	long zeros = 0;
	for (int k = 0; k < c->clip_count; k++) {
		mlod_motion *m;
		if (mlod_motion_create(c, k, &opt, &m, &terr) != MLOD_OK)
			return -1;
		mlod_result r = mlod_motion_next_level(m, MLOD_MOTION_KEYS, MLOD_MOTION_MAX_ERROR, bound, &out[k], &terr);
		mlod_motion_free(m);
		if (r != MLOD_OK)
			return -1;
		const mlod_clip *cl = &out[k].clip;
		for (int i = 0; i < cl->channel_count; i++) {
			const mlod_channel *ch = &cl->channels[i];
			int comps = ch->path == MLOD_PATH_ROTATION ? 4 : 3;
			for (int v = 0; v < ch->key_count * comps; v++)
				zeros += zero_bits(ch->values[v]) >= 8;
		}
	}
	return zeros;
}

/* Is v the value of channel i of clip (its own keys, not resampled) at
 * key time t, bit for bit (a rotation's sign aside: levels keep their
 * quaternions on one hemisphere)? */
static int value_at(const mlod_clip *clip, int i, float t, const float *v)
{
	const mlod_channel *ch = &clip->channels[i];
	int comps = ch->path == MLOD_PATH_ROTATION ? 4 : 3;
	for (int k = 0; k < ch->key_count; k++)
		if (ch->times[k] == t) {
			const float *w = ch->values + (size_t)k * (size_t)comps;
			int same = 1, neg = comps == 4;
			for (int c = 0; c < comps; c++) {
				same = same && w[c] == v[c];
				neg = neg && w[c] == -v[c];
			}
			return same || neg;
		}
	return 0;
}

TEST(precision_float_and_full)
{
	mlod_character c;
	CHECK(load_sample("samples/RobotExpressive.glb", &c) == 0);
	int n = c.clip_count;
	double bound = 0.01 * mlod_skeleton_height(&c.skeleton);
	mlod_motion_level *full = calloc((size_t)n, sizeof *full), *a = calloc((size_t)n, sizeof *a),
	                  *b = calloc((size_t)n, sizeof *b);
	long zeros_full = robot_levels(&c, MLOD_MOTION_PRECISION_FULL, full);
	long zeros_auto = robot_levels(&c, MLOD_MOTION_PRECISION_FLOAT, a);
	robot_levels(&c, MLOD_MOTION_PRECISION_FLOAT, b);
	CHECK(zeros_full >= 0 && zeros_auto >= 0);
	/* Rounding zeroes low bits: many more values end in a zero byte. */
	CHECK_MSG(zeros_auto > 4 * zeros_full, "values with 8 zero bits: auto %ld, full %ld", zeros_auto, zeros_full);
	for (int k = 0; k < n; k++) {
		const mlod_clip *src = &c.clips[k];
		/* Full precision: every kept key as read, bit for bit. */
		for (int i = 0; i < full[k].clip.channel_count; i++) {
			const mlod_channel *ch = &full[k].clip.channels[i];
			int comps = ch->path == MLOD_PATH_ROTATION ? 4 : 3;
			for (int key = 0; key < ch->key_count; key++) {
				CHECK_MSG(value_at(src, i, ch->times[key], ch->values + key * comps),
				          "clip %d channel %d key %d changed at full precision", k, i, key);
			}
		}
		CHECK(full[k].grid == 0.0);
		/* Float: within the bound, measured after rounding, and rounded. */
		CHECK_MSG(a[k].error.max <= bound && a[k].point_error <= bound, "clip %d: error %g, point %g, bound %g", k,
		          a[k].error.max, a[k].point_error, bound);
		CHECK(a[k].grid > 0.0 && a[k].grid <= 2.0 * bound);
		for (int i = 0; i < a[k].clip.channel_count; i++) {
			const mlod_channel *ch = &a[k].clip.channels[i];
			int comps = ch->path == MLOD_PATH_ROTATION ? 4 : 3;
			/* Deterministic: a second run gives the same values, bit for bit. */
			CHECK(b[k].clip.channels[i].key_count == ch->key_count &&
			      memcmp(b[k].clip.channels[i].values, ch->values, sizeof(float) * (size_t)(ch->key_count * comps)) == 0);
			/* The first and last keys stay exact. */
			for (int end = 0; end < 2; end++) {
				int key = end ? ch->key_count - 1 : 0;
				CHECK(value_at(src, i, ch->times[key], ch->values + key * comps));
			}
			CHECK(!ch->short_values);
			/* Rotations stay unit: the glTF writer's normalisation keeps them bit for bit. */
			for (int key = 0; comps == 4 && key < ch->key_count; key++) {
				const float *q = ch->values + 4 * key;
				mlod_quat u = mlod_quat_normalize((mlod_quat){q[0], q[1], q[2], q[3]});
				double len = sqrt((double)q[0] * q[0] + (double)q[1] * q[1] + (double)q[2] * q[2] + (double)q[3] * q[3]);
				CHECK_MSG(fabs(len - 1.0) < 1e-6, "clip %d channel %d key %d: |q| = %.9g", k, i, key, len);
				if (key > 0 && key + 1 < ch->key_count)
					CHECK_MSG(u.x == q[0] && u.y == q[1] && u.z == q[2] && u.w == q[3],
					          "clip %d channel %d key %d: normalising changes it", k, i, key);
			}
		}
		mlod_motion_level_free(&full[k]);
		mlod_motion_level_free(&a[k]);
		mlod_motion_level_free(&b[k]);
	}
	free(full);
	free(a);
	free(b);
	mlod_character_free(&c);
}

TEST(precision_auto_shorts)
{
	/* Auto: rotations on the lattice of normalised shorts, about unit; the
	 * bound holds after rounding; the same values from run to run. */
	mlod_character c;
	CHECK(load_sample("samples/RobotExpressive.glb", &c) == 0);
	int n = c.clip_count;
	double bound = 0.01 * mlod_skeleton_height(&c.skeleton);
	mlod_motion_level *a = calloc((size_t)n, sizeof *a), *b = calloc((size_t)n, sizeof *b);
	CHECK(robot_levels(&c, MLOD_MOTION_PRECISION_AUTO, a) >= 0);
	CHECK(robot_levels(&c, MLOD_MOTION_PRECISION_AUTO, b) >= 0);
	long rot_keys = 0;
	for (int k = 0; k < n; k++) {
		CHECK_MSG(a[k].error.max <= bound && a[k].point_error <= bound, "clip %d: error %g, point %g, bound %g", k,
		          a[k].error.max, a[k].point_error, bound);
		/* Bytes as stored: 8 a rotation key (shorts), 12 a translation or
		 * scale key, plus 4 a key time for each distinct time array. */
		long want = 0;
		for (int i = 0; i < a[k].clip.channel_count; i++) {
			const mlod_channel *ch = &a[k].clip.channels[i];
			CHECK(ch->interp != MLOD_INTERP_CUBICSPLINE);
			want += (long)ch->key_count * (ch->path == MLOD_PATH_ROTATION ? 8 : 12);
			int shared = 0;
			for (int j = 0; j < i && !shared; j++) {
				const mlod_channel *o = &a[k].clip.channels[j];
				shared = o->key_count == ch->key_count &&
				         memcmp(o->times, ch->times, sizeof(float) * (size_t)ch->key_count) == 0;
			}
			want += shared ? 0 : 4L * ch->key_count;
		}
		CHECK_MSG(a[k].bytes == want, "clip %d: %ld bytes counted, %ld stored", k, a[k].bytes, want);
		for (int i = 0; i < a[k].clip.channel_count; i++) {
			const mlod_channel *ch = &a[k].clip.channels[i];
			int comps = ch->path == MLOD_PATH_ROTATION ? 4 : 3;
			CHECK(b[k].clip.channels[i].key_count == ch->key_count &&
			      memcmp(b[k].clip.channels[i].values, ch->values, sizeof(float) * (size_t)(ch->key_count * comps)) == 0);
			CHECK(ch->short_values == (comps == 4));
			for (int key = 0; comps == 4 && key < ch->key_count; key++, rot_keys++) {
				const float *q = ch->values + 4 * key;
				double len = 0.0;
				for (int x = 0; x < 4; x++) {
					long s16 = lrint((double)q[x] * 32767.0);
					CHECK_MSG((float)((double)s16 / 32767.0) == q[x], "clip %d channel %d key %d: off the lattice", k, i, key);
					len += (double)q[x] * q[x];
				}
				/* The validator allows 0.00769; the lattice gets within a few 1e-5. */
				CHECK_MSG(fabs(sqrt(len) - 1.0) < 1e-4, "clip %d channel %d key %d: |q| = %.9g", k, i, key, sqrt(len));
			}
		}
		mlod_motion_level_free(&a[k]);
		mlod_motion_level_free(&b[k]);
	}
	CHECK(rot_keys > 1000);
	free(a);
	free(b);
	mlod_character_free(&c);
}

TEST(precision_rounds_within_own_error)
{
	/* --keys levels have no bound: rounding may add to the error the level
	 * has before rounding what a bound leaves it (share 0.1: e / 0.9). */
	mlod_character c;
	CHECK(load_sample("samples/cmu_12_01_walk.bvh", &c) == 0);
	double pe[3];
	for (int p = 0; p <= MLOD_MOTION_PRECISION_FULL; p++) {
		mlod_motion_options opt = {0};
		opt.precision = (mlod_motion_precision)p;
		mlod_motion *m;
		mlod_motion_level lv;
		CHECK_OK(mlod_motion_create(&c, 0, &opt, &m, &terr));
		CHECK_OK(mlod_motion_next_level(m, MLOD_MOTION_KEYS, MLOD_MOTION_FRACTION, 0.1, &lv, &terr));
		pe[p] = lv.point_error;
		CHECK_MSG(p == MLOD_MOTION_PRECISION_FULL ? lv.grid == 0.0 : lv.grid > 0.0, "precision %d: grid %g", p, lv.grid);
		mlod_motion_level_free(&lv);
		mlod_motion_free(m);
	}
	for (int p = 0; p < MLOD_MOTION_PRECISION_FULL; p++)
		CHECK_MSG(pe[p] <= pe[MLOD_MOTION_PRECISION_FULL] / 0.9, "precision %d: rounded %g, full %g", p, pe[p],
		          pe[MLOD_MOTION_PRECISION_FULL]);
	mlod_character_free(&c);
}

/* motion_eval.h's fast forms give the library's answers: the point error
 * checks accept and reject as the exact error does (random matrix pairs,
 * limits at, just above and just below the error), the float bound is
 * never below it, and the affine product, the local matrix and the
 * cursor sampling are bit for bit the library's. */
static unsigned long long rng_state = 88172645463325252ull;
static double urand(void)
{
	rng_state ^= rng_state << 13, rng_state ^= rng_state >> 7, rng_state ^= rng_state << 17;
	return (double)(rng_state >> 11) / 9007199254740992.0;
}

static mlod_trs random_trs(int scaled)
{
	mlod_trs l = mlod_trs_identity();
	mlod_v3 axis = { (float)(urand() - 0.5), (float)(urand() - 0.5), (float)(urand() - 0.5) };
	l.r = mlod_quat_axis_angle(axis, (float)(urand() * 6.0 - 3.0));
	l.t = (mlod_v3){ (float)(urand() * 100 - 50), (float)(urand() * 100 - 50), (float)(urand() * 100 - 50) };
	if (scaled)
		l.s = (mlod_v3){ (float)(0.5 + urand() * 1.5), (float)(0.5 + urand() * 1.5), (float)(0.5 + urand() * 1.5) };
	return l;
}

TEST(fast_checks_match_exact)
{
	long wrong_within = 0, wrong_over = 0, low_bound = 0, pairs = 0, wrong_point = 0;
	for (int i = 0; i < 200000; i++) {
		mlod_trs a = random_trs(i % 4 == 0), b = a;
		double size = i % 3 == 0 ? 1e-6 : i % 3 == 1 ? 1e-3 : 0.1;
		if (i % 7) {
			mlod_v3 axis = { (float)(urand() - 0.5), (float)(urand() - 0.5), (float)(urand() - 0.5) };
			b.r = mlod_quat_normalize(mlod_quat_mul(a.r, mlod_quat_axis_angle(axis, (float)(urand() * size))));
			b.t.x += (float)((urand() - 0.5) * size);
			b.t.z += (float)((urand() - 0.5) * size);
		}
		mlod_mat4 parent = mlod_mat4_from_trs(&(mlod_trs){ random_trs(0).t, random_trs(0).r, { 1, 1, 1 } });
		mlod_mat4 la = mlod_mat4_from_trs(&a), lb = mlod_mat4_from_trs(&b);
		mlod_mat4 w0 = mlod_mat4_mul(&parent, &la), w = mlod_mat4_mul(&parent, &lb);
		double r = urand() * 3.0, e = mlod_motion_point_error(&w, &w0, r);
		if (eval_error_bound(&w, &w0, r) < e)
			low_bound++;
		double limits[7] = { e, nextafter(e, HUGE_VAL), nextafter(e, -HUGE_VAL), e * (1 + 1e-7), e * (1 - 1e-7),
		                     e * 2.0, urand() * 0.2 };
		for (int k = 0; k < 7; k++) {
			int exact = e <= limits[k];
			pairs++;
			if (eval_within(&w, &w0, r, limits[k]) != exact || eval_point_error_within(&w, &w0, r, limits[k]) != exact)
				wrong_within++;
			/* mlod_motion_point_within compares within the budget left by
			 * the origin's error: the same answer away from rounding. */
			if ((k == 3 && !mlod_motion_point_within(&w, &w0, r, limits[k])) ||
			    (k == 4 && e > 1e-300 && mlod_motion_point_within(&w, &w0, r, limits[k])))
				wrong_point++;
			double o = eval_error_over(&w, &w0, r, limits[k]);
			if (o < 0.0 ? !exact : memcmp(&o, &e, sizeof o) != 0)
				wrong_over++;
		}
	}
	CHECK_MSG(low_bound == 0, "float bound below the exact error %ld times", low_bound);
	CHECK_MSG(wrong_within == 0, "eval_within differs from the exact check %ld times in %ld", wrong_within, pairs);
	CHECK_MSG(wrong_over == 0, "eval_error_over differs from the exact error %ld times in %ld", wrong_over, pairs);
	CHECK_MSG(wrong_point == 0, "mlod_motion_point_within wrong %ld times 1e-7 off the error", wrong_point);

	/* eval_wrap_angle: mlod_wrap_angle's doubles, at the edges of its
	 * shortcuts (multiples of pi, -0) and at random. */
	long wrong_wrap = 0;
	for (int i = 0; i < 400000; i++) {
		double a;
		if (i < 64) {
			double edge = (double)(i / 8 - 4) * MLOD_PI; /* -4 pi .. 3 pi */
			int m = i % 8;
			a = m == 0 ? edge : m == 1 ? nextafter(edge, HUGE_VAL) : m == 2 ? nextafter(edge, -HUGE_VAL)
			  : m == 3 ? -0.0 : m == 4 ? edge - MLOD_PI : m == 5 ? 2.0 * MLOD_PI * (i / 8 - 4) + MLOD_PI
			  : m == 6 ? nextafter(3.0 * MLOD_PI, 0.0) : nextafter(-3.0 * MLOD_PI, 0.0);
		} else {
			a = (urand() - 0.5) * (i % 2 ? 14.0 : 40.0);
		}
		double x = eval_wrap_angle(a), y = mlod_wrap_angle(a);
		if (memcmp(&x, &y, sizeof x) != 0)
			wrong_wrap++;
	}
	CHECK_MSG(wrong_wrap == 0, "eval_wrap_angle differs from mlod_wrap_angle %ld times", wrong_wrap);

	long wrong_mul = 0, wrong_trs = 0;
	for (int i = 0; i < 100000; i++) {
		mlod_trs pa = random_trs(i % 2), lo = random_trs(i % 3 == 0);
		mlod_mat4 p = mlod_mat4_from_trs(&pa), l = mlod_mat4_from_trs(&lo), l2 = eval_from_trs(&lo);
		if (memcmp(&l, &l2, sizeof l) != 0)
			wrong_trs++;
		mlod_mat4 x = mlod_mat4_mul(&p, &l), y = eval_mul_affine(&p, &l);
		for (int c = 0; c < 4; c++)
			for (int row = 0; row < 3; row++)
				if (!(x.m[c * 4 + row] == y.m[c * 4 + row]))
					wrong_mul++;
	}
	CHECK_MSG(wrong_trs == 0, "eval_from_trs differs from mlod_mat4_from_trs %ld times", wrong_trs);
	long wrong_norm = 0;
	for (int i = 0; i < 100000; i++) {
		double k = i % 3 == 0 ? 1.0 : i % 3 == 1 ? 1e-3 : 37.0;
		mlod_quat q = { (float)((urand() - 0.5) * k), (float)((urand() - 0.5) * k), (float)((urand() - 0.5) * k),
		                (float)((urand() - 0.5) * k) };
		mlod_quat a = mlod_quat_normalize(q), b = eval_normalize(q);
		if (memcmp(&a, &b, sizeof a) != 0)
			wrong_norm++;
	}
	CHECK_MSG(wrong_norm == 0, "eval_normalize differs from mlod_quat_normalize %ld times", wrong_norm);
	CHECK_MSG(wrong_mul == 0, "eval_mul_affine differs from mlod_mat4_mul in %ld entries", wrong_mul);

	/* Cursor sampling: a chain clip with random keys, LINEAR and STEP,
	 * rotations and a translation, at increasing times (key times, times
	 * between, outside the clip) and a few jumps back. */
	mlod_character c = make_chain(5, 40);
	mlod_clip *clip = &c.clips[0];
	for (int j = 0; j < 5; j++)
		for (int f = 0; f < 40; f++)
			set_rot(&clip->channels[j], f, random_trs(0).r);
	clip->channels[3].interp = MLOD_INTERP_STEP;
	mlod_channel *t = &clip->channels[1];
	t->path = MLOD_PATH_TRANSLATION;
	for (int f = 0; f < 40; f++)
		for (int k = 0; k < 3; k++)
			t->values[3 * f + k] = (float)(urand() * 4 - 2);
	eval_seg segs[5];
	for (int j = 0; j < 5; j++)
		segs[j].k = -1, segs[j].ready = 0;
	mlod_trs *l1 = malloc(sizeof *l1 * 5), *l2 = malloc(sizeof *l2 * 5);
	mlod_pose_rest(&c.skeleton, l2);
	long wrong_sample = 0;
	float time = -0.1f;
	for (int i = 0; i < 3000; i++) {
		if (i % 5 == 0)
			time = clip->channels[0].times[(i / 5) % 40]; /* on a key */
		else if (i % 97 == 0)
			time -= 0.3f; /* back */
		else
			time += (float)(urand() * 0.01);
		if (time > clip->duration + 0.2f)
			time = -0.05f;
		mlod_pose_rest(&c.skeleton, l1);
		mlod_clip_sample(clip, time, l1);
		eval_sample(clip, segs, time, l2);
		if (memcmp(l1, l2, sizeof *l1 * 5) != 0)
			wrong_sample++;
	}
	CHECK_MSG(wrong_sample == 0, "eval_sample differs from mlod_clip_sample %ld times", wrong_sample);
	free(l1);
	free(l2);
	mlod_character_free(&c);
}

/* Two levels are the same: method, counts, errors and every key. */
static int same_level(const mlod_motion_level *a, const mlod_motion_level *b)
{
	if (a->method != b->method || a->keys != b->keys || a->bytes != b->bytes || a->threshold != b->threshold ||
	    a->error.max != b->error.max || a->error.mean != b->error.mean || a->point_error != b->point_error ||
	    a->grid != b->grid || a->clip.channel_count != b->clip.channel_count)
		return 0;
	for (int i = 0; i < a->clip.channel_count; i++) {
		const mlod_channel *x = &a->clip.channels[i], *y = &b->clip.channels[i];
		int comps = x->path == MLOD_PATH_ROTATION ? 4 : 3;
		if (x->key_count != y->key_count || x->interp != y->interp ||
		    memcmp(x->times, y->times, sizeof(float) * (size_t)x->key_count) != 0 ||
		    memcmp(x->values, y->values, sizeof(float) * (size_t)x->key_count * (size_t)comps) != 0)
			return 0;
	}
	return 1;
}

TEST(frames_level_after_threshold_level_same)
{
	/* The frames method keeps its tree's sum of neighbour distances (the
	 * bisection's top) while the tree stays: after a finished level the
	 * tree is that level's line and the sum must be made again. Motion a
	 * reaches level 1's line by its error bound (the sum made and kept),
	 * motion b by that level's threshold (no sum made); their level 2
	 * must be the same. It failed with the sum kept across a finished
	 * level. */
	mlod_character c;
	CHECK(load_sample("samples/cmu_12_01_walk.bvh", &c) == 0);
	double h = mlod_skeleton_height(&c.skeleton);
	mlod_motion *a, *b;
	CHECK_OK(mlod_motion_create(&c, 0, NULL, &a, &terr));
	CHECK_OK(mlod_motion_create(&c, 0, NULL, &b, &terr));
	mlod_motion_level la1, lb1, la2, lb2;
	CHECK_OK(mlod_motion_next_level(a, MLOD_MOTION_FRAMES, MLOD_MOTION_MAX_ERROR, 0.005 * h, &la1, &terr));
	CHECK(la1.threshold > 0.0);
	CHECK_OK(mlod_motion_next_level(b, MLOD_MOTION_FRAMES, MLOD_MOTION_THRESHOLD, la1.threshold, &lb1, &terr));
	CHECK(lb1.keys == la1.keys);
	CHECK_OK(mlod_motion_next_level(a, MLOD_MOTION_FRAMES, MLOD_MOTION_MAX_ERROR, 0.02 * h, &la2, &terr));
	CHECK_OK(mlod_motion_next_level(b, MLOD_MOTION_FRAMES, MLOD_MOTION_MAX_ERROR, 0.02 * h, &lb2, &terr));
	CHECK(la2.keys < la1.keys);
	CHECK(same_level(&la2, &lb2));
	mlod_motion_level_free(&la1);
	mlod_motion_level_free(&lb1);
	mlod_motion_level_free(&la2);
	mlod_motion_level_free(&lb2);
	mlod_motion_free(a);
	mlod_motion_free(b);
	mlod_character_free(&c);
}

TEST(build_levels_same_at_any_thread_count)
{
	/* One clip and two methods (the keys method's choice of keys on
	 * threads of its own, its rounding and the frames method's levels on
	 * another), thresholds (the keys method skipped), the keys method
	 * alone with bounds and with fractions of the keys, and two clips
	 * (at 3 threads, fewer clips than threads): the levels are
	 * mlod_motion_next_level_best's, at 1, 2 and 3 threads. */
	mlod_character c;
	CHECK(load_sample("samples/cmu_12_01_walk.bvh", &c) == 0);
	double h = mlod_skeleton_height(&c.skeleton);
	mlod_motion_method methods[2] = { MLOD_MOTION_FRAMES, MLOD_MOTION_KEYS };
	mlod_motion_spec specs[4][3] = {
		{ { MLOD_MOTION_MAX_ERROR, 0.002 * h }, { MLOD_MOTION_MAX_ERROR, 0.01 * h }, { MLOD_MOTION_MAX_ERROR, 0.03 * h } },
		{ { MLOD_MOTION_THRESHOLD, 0.5 }, { MLOD_MOTION_THRESHOLD, 2.0 }, { MLOD_MOTION_THRESHOLD, 8.0 } },
		{ { MLOD_MOTION_MAX_ERROR, 0.003 * h }, { MLOD_MOTION_MAX_ERROR, 0.01 * h }, { MLOD_MOTION_MAX_ERROR, 0.02 * h } },
		{ { MLOD_MOTION_FRACTION, 0.5 }, { MLOD_MOTION_FRACTION, 0.2 }, { MLOD_MOTION_FRACTION, 0.05 } },
	};
	int clips[2] = { 0, 0 };
	for (int set = 0; set < 4; set++) {
		/* Sets 2 and 3: the keys method alone. */
		const mlod_motion_method *ms = set < 2 ? methods : methods + 1;
		int n = set < 2 ? 2 : 1, clip_count = set == 0 ? 2 : 1;
		mlod_motion *m[2] = { NULL, NULL };
		mlod_motion_level seq[3];
		for (int i = 0; i < n; i++)
			CHECK_OK(mlod_motion_create(&c, 0, NULL, &m[i], &terr));
		for (int s = 0; s < 3; s++)
			CHECK_OK(mlod_motion_next_level_best(m, ms, n, specs[set][s].target, specs[set][s].value, &seq[s], &terr));
		for (int i = 0; i < n; i++)
			mlod_motion_free(m[i]);
		for (int threads = 1; threads <= 3; threads++) {
			mlod_motion_clip_levels out[2];
			CHECK_OK(mlod_motion_build_levels(&c, clips, clip_count, NULL, ms, n, specs[set], 3, threads, out, &terr));
			for (int k = 0; k < clip_count; k++) {
				CHECK(out[k].result == MLOD_OK && out[k].level_count == 3);
				for (int s = 0; s < 3; s++) {
					CHECK(out[k].results[s] == MLOD_OK);
					CHECK_MSG(same_level(&out[k].levels[s], &seq[s]), "set %d, clip %d, level %d, %d threads", set, k, s,
					          threads);
				}
			}
			mlod_motion_clip_levels_free(out, clip_count);
		}
		for (int s = 0; s < 3; s++)
			mlod_motion_level_free(&seq[s]);
	}
	mlod_character_free(&c);
}

TEST(frames_item_levels_same)
{
	/* One clip at 2 and 3 threads: the frames method's levels on an item
	 * of their own, each with the limit the finisher hands over after
	 * rounding the keys level. The robot's Punch and Running have frames
	 * levels that win (Running: all three), so a limit handed over wrong
	 * or too early changes the chosen levels. */
	mlod_character c;
	CHECK(load_sample("samples/RobotExpressive.glb", &c) == 0);
	double h = mlod_skeleton_height(&c.skeleton);
	mlod_motion_method methods[2] = { MLOD_MOTION_FRAMES, MLOD_MOTION_KEYS };
	mlod_motion_spec specs[3] = { { MLOD_MOTION_MAX_ERROR, 0.002 * h }, { MLOD_MOTION_MAX_ERROR, 0.01 * h },
	                              { MLOD_MOTION_MAX_ERROR, 0.03 * h } };
	const char *names[2] = { "Punch", "Running" };
	int frames_won = 0;
	for (int w = 0; w < 2; w++) {
		int k = -1;
		for (int i = 0; i < c.clip_count; i++)
			if (c.clips[i].name && strcmp(c.clips[i].name, names[w]) == 0)
				k = i;
		CHECK_MSG(k >= 0, "no clip %s", names[w]);
		mlod_motion *m[2] = { NULL, NULL };
		mlod_motion_level seq[3];
		for (int i = 0; i < 2; i++)
			CHECK_OK(mlod_motion_create(&c, k, NULL, &m[i], &terr));
		for (int s = 0; s < 3; s++) {
			CHECK_OK(mlod_motion_next_level_best(m, methods, 2, specs[s].target, specs[s].value, &seq[s], &terr));
			frames_won += seq[s].method == MLOD_MOTION_FRAMES;
		}
		for (int i = 0; i < 2; i++)
			mlod_motion_free(m[i]);
		for (int threads = 2; threads <= 3; threads++) {
			mlod_motion_clip_levels out;
			CHECK_OK(mlod_motion_build_levels(&c, &k, 1, NULL, methods, 2, specs, 3, threads, &out, &terr));
			CHECK(out.result == MLOD_OK && out.level_count == 3);
			for (int s = 0; s < 3; s++) {
				CHECK(out.results[s] == MLOD_OK);
				CHECK_MSG(same_level(&out.levels[s], &seq[s]), "%s, level %d, %d threads", names[w], s, threads);
			}
			mlod_motion_clip_levels_free(&out, 1);
		}
		for (int s = 0; s < 3; s++)
			mlod_motion_level_free(&seq[s]);
	}
	CHECK_MSG(frames_won >= 4, "only %d frames levels won", frames_won);
	mlod_character_free(&c);
}

TEST(keys_split_same_as_next_level)
{
	/* mlod_motion_keys_reduce, then mlod_motion_keys_finish on another
	 * motion of the clip (made by mlod_motion_create_like, as the threaded
	 * builder does): the levels of mlod_motion_next_level; and the choice
	 * of keys and the rounding's per-channel refinement on 1, 2, 3 and 8
	 * threads (mlod_motion_set_threads) give the same levels. Walk (rotations below a translated root) and the robot
	 * (translations and scales on several joints). */
	const char *files[2] = { "samples/cmu_12_01_walk.bvh", "samples/RobotExpressive.glb" };
	for (int file = 0; file < 2; file++) {
		mlod_character c;
		CHECK(load_sample(files[file], &c) == 0);
		double h = mlod_skeleton_height(&c.skeleton);
		int clip = file ? 2 : 0;
		CHECK(clip < c.clip_count);
		mlod_motion *seq = NULL;
		mlod_motion_level want[2];
		CHECK_OK(mlod_motion_create(&c, clip, NULL, &seq, &terr));
		for (int s = 0; s < 2; s++)
			CHECK_OK(mlod_motion_next_level(seq, MLOD_MOTION_KEYS, MLOD_MOTION_MAX_ERROR, (s ? 0.02 : 0.004) * h, &want[s],
			                                &terr));
		mlod_motion_free(seq);
		const int counts[4] = { 1, 2, 3, 8 };
		for (int t = 0; t < 4; t++) {
			mlod_motion *m = NULL, *fin = NULL;
			CHECK_OK(mlod_motion_create(&c, clip, NULL, &m, &terr));
			CHECK_OK(mlod_motion_create_like(m, &fin, &terr));
			mlod_motion_set_threads(m, counts[t]);
			mlod_motion_set_threads(fin, counts[t]);
			for (int s = 0; s < 2; s++) {
				mlod_motion_level l;
				double known = -2.0, bound = (s ? 0.02 : 0.004) * h;
				CHECK_OK(mlod_motion_keys_reduce(m, MLOD_MOTION_MAX_ERROR, bound, &l, &known, &terr));
				CHECK(known >= 0.0 && known <= bound);
				CHECK_OK(mlod_motion_keys_finish(fin, MLOD_MOTION_MAX_ERROR, bound, -1, known, &l, &terr));
				CHECK_MSG(same_level(&l, &want[s]), "%s, level %d, %d threads", files[file], s, counts[t]);
				mlod_motion_level_free(&l);
			}
			mlod_motion_level l;
			double known;
			CHECK(mlod_motion_keys_reduce(m, MLOD_MOTION_MAX_ERROR, 0.01, &l, NULL, &terr) == MLOD_ERR_INVALID_ARG);
			CHECK(mlod_motion_keys_reduce(m, MLOD_MOTION_MAX_ERROR, -1.0, &l, &known, &terr) == MLOD_ERR_INVALID_ARG);
			memset(&l, 0, sizeof l);
			CHECK(mlod_motion_keys_finish(fin, MLOD_MOTION_MAX_ERROR, 0.01, -1, -1.0, &l, &terr) == MLOD_ERR_INVALID_ARG);
			mlod_motion_free(m);
			mlod_motion_free(fin);
		}
		for (int s = 0; s < 2; s++)
			mlod_motion_level_free(&want[s]);
		mlod_character_free(&c);
	}
}

TEST(create_like_same_as_create)
{
	/* mlod_motion_create_like: the same levels (each method) as a motion
	 * made by mlod_motion_create, and independent of the first (freed
	 * before the copy is used). */
	mlod_character c;
	CHECK(load_sample("samples/cmu_12_01_walk.bvh", &c) == 0);
	double h = mlod_skeleton_height(&c.skeleton);
	mlod_motion *like = NULL, *fresh = NULL, *first = NULL;
	CHECK(mlod_motion_create_like(NULL, &like, &terr) == MLOD_ERR_INVALID_ARG && like == NULL);
	for (int method = 0; method < 2; method++) {
		mlod_motion_method mm = method ? MLOD_MOTION_KEYS : MLOD_MOTION_FRAMES;
		CHECK_OK(mlod_motion_create(&c, 0, NULL, &first, &terr));
		CHECK_OK(mlod_motion_create_like(first, &like, &terr));
		mlod_motion_free(first);
		CHECK_OK(mlod_motion_create(&c, 0, NULL, &fresh, &terr));
		CHECK(mlod_motion_timeline_info(like)->frames == mlod_motion_timeline_info(fresh)->frames);
		for (int s = 0; s < 2; s++) {
			mlod_motion_level a, b;
			double bound = (s ? 0.01 : 0.002) * h;
			CHECK_OK(mlod_motion_next_level(like, mm, MLOD_MOTION_MAX_ERROR, bound, &a, &terr));
			CHECK_OK(mlod_motion_next_level(fresh, mm, MLOD_MOTION_MAX_ERROR, bound, &b, &terr));
			CHECK_MSG(same_level(&a, &b), "method %d, level %d", method, s);
			mlod_motion_level_free(&a);
			mlod_motion_level_free(&b);
		}
		mlod_motion_free(like);
		mlod_motion_free(fresh);
	}
	mlod_character_free(&c);
}

TEST(create_on_threads_same_as_create)
{
	/* motion_create_on: the clip as read at every sample made on 1, 2 and
	 * 3 threads gives the same levels; and a motion made like one made
	 * like the first, the first and the second freed before it is used
	 * (the shared setup lives until its last motion is freed). */
	mlod_character c;
	CHECK(load_sample("samples/cmu_12_01_walk.bvh", &c) == 0);
	double h = mlod_skeleton_height(&c.skeleton);
	mlod_motion_level ref[2];
	for (int threads = 1; threads <= 3; threads++) {
		mlod_motion *m = NULL, *like = NULL, *like2 = NULL;
		CHECK_OK(motion_create_on(&c, 0, NULL, threads, &m, &terr));
		CHECK_OK(mlod_motion_create_like(m, &like, &terr));
		CHECK_OK(mlod_motion_create_like(like, &like2, &terr));
		mlod_motion_free(m);
		mlod_motion_free(like);
		for (int s = 0; s < 2; s++) {
			mlod_motion_level a;
			CHECK_OK(mlod_motion_next_level(like2, MLOD_MOTION_KEYS, MLOD_MOTION_MAX_ERROR, (s ? 0.01 : 0.002) * h, &a,
			                                &terr));
			if (threads == 1) {
				ref[s] = a;
			} else {
				CHECK_MSG(same_level(&a, &ref[s]), "%d threads, level %d", threads, s);
				mlod_motion_level_free(&a);
			}
		}
		mlod_motion_free(like2);
	}
	for (int s = 0; s < 2; s++)
		mlod_motion_level_free(&ref[s]);
	mlod_character_free(&c);
}

TEST(bake_report_same_at_any_thread_count)
{
	/* mlod_motion_bake_run and its JSON report: the same text at 1 and 3
	 * threads, every level made, and the notes empty. */
	mlod_character c;
	CHECK(load_sample("samples/cmu_12_01_walk.bvh", &c) == 0);
	double h = mlod_skeleton_height(&c.skeleton);
	mlod_motion_method methods[2] = { MLOD_MOTION_FRAMES, MLOD_MOTION_KEYS };
	mlod_motion_spec specs[2] = { { MLOD_MOTION_MAX_ERROR, 0.005 * h }, { MLOD_MOTION_MAX_ERROR, 0.02 * h } };
	mlod_motion_bake_options o;
	memset(&o, 0, sizeof o);
	o.methods = methods;
	o.method_count = 2;
	o.specs = specs;
	o.spec_count = 2;
	o.vertex_samples = 10;
	mlod_motion_report_info info = { "walk", h, mlod_motion_point_distance(&c.skeleton, 0), 2, MLOD_MOTION_PRECISION_AUTO };
	char *text[2] = { NULL, NULL };
	int clip = 0;
	for (int t = 0; t < 2; t++) {
		mlod_motion_bake b;
		o.threads = t ? 3 : 1;
		CHECK_OK(mlod_motion_bake_run(&c, NULL, &clip, 1, &o, &b, &terr));
		CHECK(b.clip_count == 1 && b.note_count == 0 && b.clips[0].level_count == 2);
		CHECK(b.clips[0].levels[0].ok && b.clips[0].levels[1].ok && !b.clips[0].levels[0].has_vertex);
		CHECK(b.clips[0].levels[1].l.point_error <= specs[1].value);
		CHECK_OK(mlod_motion_bake_json(&b, &c, &info, &text[t], &terr));
		mlod_motion_bake_free(&b);
	}
	CHECK(text[0] && text[1] && strcmp(text[0], text[1]) == 0);
	CHECK(text[0] && strstr(text[0], "\"ok\": true") != NULL);
	free(text[0]);
	free(text[1]);
	mlod_character_free(&c);
}

/* The key reduction's end state (keyreduce_state), taken by the next run
 * that starts from its keys: the same keys and error as a run that sets
 * up from scratch; and a state that is not what the setup would compute
 * at a kept key's sample is not taken. */
/* On the walk (a real clip, where the next level does take the state):
 * two levels from one state give the keys and errors of fresh runs, and
 * the second level took the state. */
TEST(keys_state_reused_on_the_walk)
{
	mlod_character c;
	CHECK(load_sample("samples/cmu_12_01_walk.bvh", &c) == 0);
	const mlod_clip *clip = &c.clips[0];
	const mlod_skeleton *s = &c.skeleton;
	int n = s->joint_count, F = clip->channels[0].key_count, per = 2, S = (F - 1) * per + 1;
	size_t CF = (size_t)clip->channel_count * (size_t)F;
	float *st = malloc(sizeof(float) * (size_t)S);
	mlod_mat4 *w0 = malloc(sizeof(mlod_mat4) * (size_t)S * (size_t)n);
	mlod_trs *l = malloc(sizeof(mlod_trs) * (size_t)n);
	unsigned char *ka = malloc(CF), *kb = malloc(CF);
	mlod_motion_sample_times(clip->channels[0].times, F, per, st);
	for (int f = 0; f < S; f++) {
		mlod_pose_rest(s, l);
		mlod_clip_sample(clip, st[f], l);
		mlod_pose_world(s, l, w0 + (size_t)f * (size_t)n);
	}
	keyreduce_state state;
	memset(&state, 0, sizeof state);
	const double bounds[3] = {0.05, 0.2, 0.6};
	int reused = 0;
	memset(ka, 1, CF);
	memset(kb, 1, CF);
	for (int b = 0; b < 3; b++) {
		double ea, eb;
		CHECK_OK(keyreduce_run(s, clip, clip, bounds[b], 1.0, per, ka, w0, &ea, NULL, &state, 1, &terr));
		reused += state.reused;
		CHECK_OK(keyreduce_run(s, clip, clip, bounds[b], 1.0, per, kb, w0, &eb, NULL, NULL, 1, &terr));
		CHECK_MSG(memcmp(ka, kb, CF) == 0, "bound %g: other keys with the state", bounds[b]);
		CHECK(memcmp(&ea, &eb, sizeof ea) == 0);
	}
	CHECK_MSG(reused > 0, "no level took the state: the comparison says nothing");
	keyreduce_state_free(&state);
	free(st), free(w0), free(l), free(ka), free(kb);
	mlod_character_free(&c);
}

/* A synthetic chain: a level that starts from the last one's state gives
 * the keys and error of a fresh run, whether it takes the state or (as
 * here, a kept key's sample differing from what its setup computes)
 * refuses it; and it refuses a tampered state. */
TEST(keys_state_same_as_fresh)
{
	int F = 90, n = 6, per = 2;
	mlod_character c = make_chain(n, F);
	for (int j = 0; j < n; j++)
		for (int f = 0; f < F; f++)
			set_rot(&c.clips[0].channels[j], f,
			        mlod_quat_axis_angle((mlod_v3){0, 0, 1}, 0.3f * sinf(0.1f * (float)(f + 7 * j))));
	const mlod_clip *clip = &c.clips[0];
	const mlod_skeleton *s = &c.skeleton;
	int S = (F - 1) * per + 1;
	size_t CF = (size_t)n * (size_t)F;
	float *st = malloc(sizeof(float) * (size_t)S);
	mlod_mat4 *w0 = malloc(sizeof(mlod_mat4) * (size_t)S * (size_t)n);
	mlod_trs *l = malloc(sizeof(mlod_trs) * (size_t)n);
	unsigned char *k1 = malloc(CF), *ka = malloc(CF), *kb = malloc(CF);
	mlod_motion_sample_times(clip->channels[0].times, F, per, st);
	for (int f = 0; f < S; f++) {
		mlod_pose_rest(s, l);
		mlod_clip_sample(clip, st[f], l);
		mlod_pose_world(s, l, w0 + (size_t)f * (size_t)n);
	}
	keyreduce_state state;
	memset(&state, 0, sizeof state);
	double e1, ea, eb;
	memset(k1, 1, CF);
	CHECK_OK(keyreduce_run(s, clip, clip, 0.01, 0.1, per, k1, w0, &e1, NULL, &state, 1, &terr));
	CHECK(state.valid);
	memcpy(ka, k1, CF), memcpy(kb, k1, CF);
	CHECK_OK(keyreduce_run(s, clip, clip, 0.04, 0.1, per, ka, w0, &ea, NULL, &state, 1, &terr));
	CHECK_OK(keyreduce_run(s, clip, clip, 0.04, 0.1, per, kb, w0, &eb, NULL, NULL, 1, &terr));
	CHECK(memcmp(ka, kb, CF) == 0);
	CHECK(memcmp(&ea, &eb, sizeof ea) == 0);
	int kept1 = 0, kepta = 0;
	for (size_t i = 0; i < CF; i++)
		kept1 += k1[i], kepta += ka[i];
	CHECK_MSG(kepta < kept1 && kepta > n, "keys %d then %d", kept1, kepta);

	/* Again from k1, then the root's state at its kept keys' samples
	 * turned (their matrices with it): the next run must set up again. */
	memset(k1, 1, CF);
	CHECK_OK(keyreduce_run(s, clip, clip, 0.01, 0.1, per, k1, w0, &e1, NULL, &state, 1, &terr));
	int turned = 0;
	for (int key = 1; key < F - 1; key++) {
		if (!k1[key])
			continue;
		size_t base = (size_t)(key * per) * (size_t)n;
		state.lc[base].r = mlod_quat_axis_angle((mlod_v3){1, 0, 0}, 1.5f);
		for (int j = 0; j < n; j++)
			state.lm[base + (size_t)j] = eval_from_trs(&state.lc[base + (size_t)j]);
		eval_pose_world(s, state.lc + base, state.wc + base);
		turned++;
	}
	CHECK(turned > 0);
	{
		memcpy(ka, k1, CF), memcpy(kb, k1, CF);
		CHECK_OK(keyreduce_run(s, clip, clip, 0.04, 0.1, per, ka, w0, &ea, NULL, &state, 1, &terr));
		CHECK_MSG(!state.reused, "a tampered state was taken");
		CHECK_OK(keyreduce_run(s, clip, clip, 0.04, 0.1, per, kb, w0, &eb, NULL, NULL, 1, &terr));
		CHECK(memcmp(ka, kb, CF) == 0);
		CHECK(memcmp(&ea, &eb, sizeof ea) == 0);
	}
	keyreduce_state_free(&state);
	free(st), free(w0), free(l), free(k1), free(ka), free(kb);
	mlod_character_free(&c);
}

/* eval_mul: mlod_mat4_mul's floats, bit for bit, signed zeros included. */
TEST(eval_mul_same_as_mat4_mul)
{
	const float pick[8] = { 0.0f, -0.0f, 1.0f, -1.0f, 0.5f, 3.0e-20f, -7.25e3f, 1.0e30f };
	unsigned x = 12345u;
	int differ = 0;
	for (int n = 0; n < 200000; n++) {
		mlod_mat4 a, b;
		for (int i = 0; i < 16; i++) {
			x = x * 1664525u + 1013904223u;
			a.m[i] = (x >> 29) < 3 ? pick[(x >> 8) & 7] : (float)((int)(x >> 9) - (1 << 22)) / 1024.0f;
			x = x * 1664525u + 1013904223u;
			b.m[i] = (x >> 29) < 3 ? pick[(x >> 8) & 7] : (float)((int)(x >> 9) - (1 << 22)) / 4096.0f;
		}
		mlod_mat4 r = eval_mul(&a, &b), q = mlod_mat4_mul(&a, &b);
		differ += memcmp(&r, &q, sizeof r) != 0;
	}
	CHECK_MSG(differ == 0, "%d products differ", differ);
}

/* The frames method's residuals interpolate with eval_slerp (a fresh
 * segment) and eval_normalize where they took mlod_quat_slerp and
 * mlod_quat_normalize: the same floats, near-parallel, opposite,
 * unnormalised and zero keys included. */
TEST(eval_slerp_same_as_quat_slerp)
{
	const float pick[8] = { 0.0f, -0.0f, 1.0f, -1.0f, 0.5f, 3.0e-20f, -0.7071068f, 2.0f };
	unsigned x = 777u;
	int differ = 0;
	for (int n = 0; n < 200000; n++) {
		float ka[4], kb[4];
		for (int i = 0; i < 4; i++) {
			x = x * 1664525u + 1013904223u;
			ka[i] = (x >> 29) < 2 ? pick[(x >> 8) & 7] : (float)((int)(x >> 9) - (1 << 22)) / 4194304.0f;
			x = x * 1664525u + 1013904223u;
			/* a quarter near a (or -a): the linear blend's side */
			kb[i] = n % 4 == 0 ? (n % 8 ? 1.0f : -1.0f) * ka[i] + (float)((int)(x >> 20) - 2048) * 1e-7f
			      : (x >> 29) < 2 ? pick[(x >> 8) & 7] : (float)((int)(x >> 9) - (1 << 22)) / 4194304.0f;
		}
		x = x * 1664525u + 1013904223u;
		/* every float in [0, 1), small ones too (where 1 - u is not exact in floats) */
		float u = n % 16 == 0 ? (float)(n % 32 == 0) : (float)((double)x / 4294967296.0 * ((x & 7) ? 1.0 : 1e-3));
		eval_seg seg = { -1, 0, 0, { 0, 0, 0, 1 }, { 0, 0, 0, 1 }, 0.0, 0.0, 0.0 };
		mlod_quat r = eval_normalize(eval_slerp(&seg, ka, kb, u));
		mlod_quat q = mlod_quat_normalize(mlod_quat_slerp((mlod_quat){ ka[0], ka[1], ka[2], ka[3] },
		                                                  (mlod_quat){ kb[0], kb[1], kb[2], kb[3] }, u));
		differ += memcmp(&r, &q, sizeof r) != 0;
	}
	CHECK_MSG(differ == 0, "%d slerps differ", differ);
}

/* The AVX2 copies' 8-lane forms (eval_mul_affine8 through
 * eval_mul_affine_w, and eval_error_bound_w), compiled here for AVX2 as
 * in the copies, against the 4-lane ones: bit for bit, signed zeros,
 * tiny and huge entries included; every column of the product (its last
 * row too), and the bound's double. */
#if EVAL_HAVE_AVX2
EVAL_TARGET_AVX2 static int wide_differs(const mlod_mat4 *a, const mlod_mat4 *b, double radius)
{
	mlod_mat4 x = eval_mul_affine_w(a, b, 1), y = eval_mul_affine(a, b);
	double e = eval_error_bound_w(a, b, radius, 1), f = eval_error_bound(a, b, radius);
	return (memcmp(&x, &y, sizeof x) != 0) + 2 * (memcmp(&e, &f, sizeof e) != 0);
}
#endif

TEST(eval_wide_same_as_narrow)
{
#if EVAL_HAVE_AVX2
	if (!eval_avx2())
		return; /* no AVX2 here: the copies that use them never run */
	const float pick[8] = { 0.0f, -0.0f, 1.0f, -1.0f, 0.5f, 3.0e-20f, -7.25e3f, 1.0e30f };
	unsigned x = 54321u;
	long products = 0, bounds = 0;
	for (int n = 0; n < 200000; n++) {
		mlod_mat4 a, b;
		for (int i = 0; i < 16; i++) {
			x = x * 1664525u + 1013904223u;
			a.m[i] = (x >> 29) < 3 ? pick[(x >> 8) & 7] : (float)((int)(x >> 9) - (1 << 22)) / 1024.0f;
			x = x * 1664525u + 1013904223u;
			b.m[i] = (x >> 29) < 3 ? pick[(x >> 8) & 7] : (float)((int)(x >> 9) - (1 << 22)) / 4096.0f;
		}
		if (n % 2) /* b affine, as the local matrices are */
			b.m[3] = b.m[7] = b.m[11] = 0.0f, b.m[15] = 1.0f;
		if (n % 3 == 0) /* b near a, as a level's world matrix is near the original's */
			for (int i = 0; i < 16; i++) {
				x = x * 1664525u + 1013904223u;
				b.m[i] = a.m[i] * (1.0f + (float)((int)(x >> 9) - (1 << 22)) * 1e-12f);
			}
		int d = wide_differs(&a, &b, (double)(n % 5) * 0.37);
		products += d & 1;
		bounds += d >> 1;
	}
	CHECK_MSG(products == 0, "eval_mul_affine8 differs from eval_mul_affine in %ld products", products);
	CHECK_MSG(bounds == 0, "eval_error_bound_w's wide form differs in %ld bounds", bounds);
#endif
}

TEST(keys_avx2_same_as_generic)
{
	/* The hot loops' AVX2 copies (motion_eval.h: the key reduction's
	 * sample checks, the rounding's per-channel tries and walks) against
	 * the generic ones: the same levels, bit for bit, on the walk (both
	 * methods, three bounds, the rounding on; one and two threads).
	 * Without AVX2 both runs take the generic copies. */
	mlod_character c;
	CHECK(load_sample("samples/cmu_12_01_walk.bvh", &c) == 0);
#if EVAL_HAVE_AVX2
	CHECK(eval_avx2() == (__builtin_cpu_supports("avx2") != 0));
#else
	CHECK(eval_avx2() == 0);
#endif
	double h = mlod_skeleton_height(&c.skeleton);
	mlod_motion_method methods[2] = { MLOD_MOTION_FRAMES, MLOD_MOTION_KEYS };
	const double bounds[3] = { 0.002 * h, 0.01 * h, 0.03 * h };
	for (int threads = 1; threads <= 2; threads++) {
		mlod_motion_level lv[2][3];
		for (int generic = 0; generic < 2; generic++) {
			motion_eval_generic_only = generic;
			mlod_motion *m[2] = { NULL, NULL };
			for (int i = 0; i < 2; i++) {
				CHECK_OK(mlod_motion_create(&c, 0, NULL, &m[i], &terr));
				mlod_motion_set_threads(m[i], threads);
			}
			for (int s = 0; s < 3; s++)
				CHECK_OK(mlod_motion_next_level_best(m, methods, 2, MLOD_MOTION_MAX_ERROR, bounds[s], &lv[generic][s], &terr));
			for (int i = 0; i < 2; i++)
				mlod_motion_free(m[i]);
		}
		motion_eval_generic_only = 0;
		for (int s = 0; s < 3; s++) {
			CHECK_MSG(same_level(&lv[0][s], &lv[1][s]), "%d threads, level %d", threads, s);
			mlod_motion_level_free(&lv[0][s]);
			mlod_motion_level_free(&lv[1][s]);
		}
	}
	mlod_character_free(&c);
}

int main(void)
{
	RUN(levels_within_bounds_cmu);
	RUN(levels_within_bounds_robot);
	RUN(keys_method_beats_frames_on_cmu);
	RUN(keys_fit_limit);
	RUN(fraction_of_keys);
	RUN(tree_levels_are_nested);
	RUN(average_merge_keeps_ends);
	RUN(sign_flips_are_not_motion);
	RUN(angle_wrap_is_not_motion);
	RUN(points_out_from_leaves_are_kept);
	RUN(hierarchy_error_is_bounded);
	RUN(level_error_same_as_joint_deviation);
	RUN(bound_holds_between_frames);
	RUN(morph_weights_reduced_within_bound);
	RUN(morph_target_reach_in_scene_units);
	RUN(common_timeline);
	RUN(bad_clips);
	RUN(one_frame_clip);
	RUN(clip_without_joint_channels);
	RUN(names_escaped_in_messages);
	RUN(step_channels_stay_step);
	RUN(key_bytes);
	RUN(precision_float_and_full);
	RUN(precision_auto_shorts);
	RUN(precision_rounds_within_own_error);
	RUN(fast_checks_match_exact);
	RUN(frames_level_after_threshold_level_same);
	RUN(build_levels_same_at_any_thread_count);
	RUN(frames_item_levels_same);
	RUN(keys_split_same_as_next_level);
	RUN(bake_report_same_at_any_thread_count);
	RUN(keys_state_reused_on_the_walk);
	RUN(keys_avx2_same_as_generic);
	RUN(keys_state_same_as_fresh);
	RUN(eval_mul_same_as_mat4_mul);
	RUN(eval_slerp_same_as_quat_slerp);
	RUN(eval_wide_same_as_narrow);
	RUN(create_like_same_as_create);
	RUN(create_on_threads_same_as_create);
	TEST_EXIT();
}
