/* test_label.c: skeleton labels and joint energy on hand-built skeletons. */
#include "test.h"

#define PI 3.14159265358979323846

/* Adds a clip rotating joint j about x through the given angles (degrees),
 * one key per angle at 1/30 s. */
static void add_x_rotation_clip(mlod_character *c, int j, const float *deg, int keys)
{
	c->clips = realloc(c->clips, sizeof(mlod_clip) * (size_t)(c->clip_count + 1));
	mlod_clip *clip = &c->clips[c->clip_count++];
	memset(clip, 0, sizeof *clip);
	clip->name = strdup("x");
	clip->gltf_index = -1;
	clip->channel_count = 1;
	clip->channels = calloc(1, sizeof(mlod_channel));
	mlod_channel *ch = &clip->channels[0];
	ch->joint = j;
	ch->path = MLOD_PATH_ROTATION;
	ch->interp = MLOD_INTERP_LINEAR;
	ch->key_count = keys;
	ch->times = malloc(sizeof(float) * (size_t)keys);
	ch->values = malloc(sizeof(float) * 4 * (size_t)keys);
	for (int k = 0; k < keys; k++) {
		float a[3] = {(float)(deg[k] * PI / 180.0), 0, 0};
		mlod_quat q = mlod_quat_from_euler(MLOD_EULER_XYZ, a);
		ch->times[k] = (float)k / 30.0f;
		memcpy(&ch->values[4 * k], &q, sizeof q);
	}
	clip->duration = ch->times[keys - 1];
}

TEST(single_chain)
{
	int parent[] = {-1, 0, 1, 2, 3};
	mlod_character c = test_skeleton(5, parent);
	mlod_joint_info info[5];
	CHECK_OK(mlod_label_skeleton(&c, NULL, info, &terr));
	CHECK(info[0].label == MLOD_LABEL_ROOT);
	for (int j = 1; j < 4; j++) {
		CHECK(info[j].label == MLOD_LABEL_MINOR);
		CHECK(info[j].depth == j);
		CHECK(info[j].neighbors == 2);
		CHECK(info[j].children == 1);
	}
	CHECK(info[4].label == MLOD_LABEL_END_EFFECTOR);
	CHECK(info[4].neighbors == 1);
	CHECK_NEAR(info[0].weight, 1.0, 1e-12);
	CHECK_NEAR(info[4].weight, 1.0 / 5.0, 1e-12); /* h = max depth + 1 = 5 */
	CHECK_NEAR(info[2].energy, 0.0, 0.0);         /* no motion */
	mlod_character_free(&c);
}

/* A humanoid-like tree: the chest (4 neighbours) is a hub above the average
 * depth, so it is extreme; the pelvis is the root. */
TEST(humanoid_hubs)
{
	/* 0 pelvis; 1-2 left leg; 3-4 right leg; 5 spine; 6 chest; 7 neck 8 head;
	 * 9-10 left arm; 11-12 right arm */
	int parent[] = {-1, 0, 1, 0, 3, 0, 5, 6, 7, 6, 9, 6, 11};
	mlod_character c = test_skeleton(13, parent);
	mlod_joint_info info[13];
	CHECK_OK(mlod_label_skeleton(&c, NULL, info, &terr));
	CHECK(info[0].label == MLOD_LABEL_ROOT);
	CHECK(info[6].neighbors == 4);
	/* average neighbours = 2 * 12 / 13 = 1.846; 1.9 * that = 3.51 < 4 */
	/* average depth = (0+1+2+1+2+1+2+3+4+3+4+3+4)/13 = 30/13 = 2.31 > 2 */
	CHECK(info[6].label == MLOD_LABEL_MAJOR);
	CHECK(info[5].label == MLOD_LABEL_MINOR);
	CHECK(info[8].label == MLOD_LABEL_END_EFFECTOR);
	CHECK(info[2].label == MLOD_LABEL_END_EFFECTOR);
	/* A lower hub factor makes the spine-level joints with 2 neighbours hubs too. */
	mlod_label_options opt = {1.0, 0};
	CHECK_OK(mlod_label_skeleton(&c, &opt, info, &terr));
	CHECK(info[1].label == MLOD_LABEL_MAJOR);   /* depth 1 < 2.31, 2 > 1.846 */
	CHECK(info[9].label == MLOD_LABEL_EXTREME); /* depth 3 > 2.31 */
	mlod_character_free(&c);
}

/* A hub at exactly the average depth matches neither rule 3 nor 4. */
TEST(hub_at_average_depth_is_minor)
{
	/* root 0 - 1 - hub 2 with three leaves 3, 4, 5; plus a leaf 6 off the
	 * root. depths 0 1 2 3 3 3 1 -> average 13/7; make it exactly 2 by
	 * adding leaf 7 at depth 3: 0+1+2+3+3+3+1+3 = 16/8 = 2. */
	int parent[] = {-1, 0, 1, 2, 2, 2, 0, 2};
	mlod_character c = test_skeleton(8, parent);
	mlod_joint_info info[8];
	CHECK_OK(mlod_label_skeleton(&c, NULL, info, &terr));
	CHECK(info[2].depth == 2);
	CHECK(info[2].neighbors == 5); /* > 1.9 * 14/8 = 3.325 */
	CHECK(info[2].label == MLOD_LABEL_MINOR);
	mlod_character_free(&c);
}

TEST(star_and_two_roots)
{
	int star[] = {-1, 0, 0, 0, 0, 0};
	mlod_character c = test_skeleton(6, star);
	mlod_joint_info info[8];
	CHECK_OK(mlod_label_skeleton(&c, NULL, info, &terr));
	CHECK(info[0].label == MLOD_LABEL_ROOT);
	for (int j = 1; j < 6; j++)
		CHECK(info[j].label == MLOD_LABEL_END_EFFECTOR);
	mlod_character_free(&c);

	int two[] = {-1, 0, 1, -1, 3, 4};
	c = test_skeleton(6, two);
	CHECK_OK(mlod_label_skeleton(&c, NULL, info, &terr));
	CHECK(info[0].label == MLOD_LABEL_ROOT && info[3].label == MLOD_LABEL_ROOT);
	CHECK(info[4].depth == 1 && info[5].depth == 2);
	CHECK(info[1].label == MLOD_LABEL_MINOR && info[5].label == MLOD_LABEL_END_EFFECTOR);
	mlod_character_free(&c);
}

/* Energy is the weighted total variation over pi: there and back counts twice. */
TEST(energy_total_variation)
{
	int parent[] = {-1, 0, 1};
	mlod_character c = test_skeleton(3, parent);
	float there_and_back[] = {0, 45, 90, 45, 0};
	add_x_rotation_clip(&c, 1, there_and_back, 5);
	mlod_joint_info info[3];
	CHECK_OK(mlod_label_skeleton(&c, NULL, info, &terr));
	/* variation pi about x, weight (3 - 1) / 3 */
	CHECK_NEAR(info[1].energy, 2.0 / 3.0 * 1.0, 1e-5);
	CHECK_NEAR(info[0].energy, 0.0, 1e-9);
	/* With a 90 degree range it doubles. */
	mlod_label_options opt = {0, PI / 2};
	CHECK_OK(mlod_label_skeleton(&c, &opt, info, &terr));
	CHECK_NEAR(info[1].energy, 4.0 / 3.0, 1e-5);
	mlod_character_free(&c);
}

/* 170 -> 179 -> -179 -> -170 is 20 degrees of motion, not 358. */
TEST(energy_unwraps_angles)
{
	int parent[] = {-1, 0, 1};
	mlod_character c = test_skeleton(3, parent);
	float wrap[] = {170, 179, -179, -170};
	add_x_rotation_clip(&c, 1, wrap, 4);
	mlod_joint_info info[3];
	CHECK_OK(mlod_label_skeleton(&c, NULL, info, &terr));
	CHECK_NEAR(info[1].energy, 2.0 / 3.0 * (20.0 / 180.0), 1e-4);
	mlod_character_free(&c);
}

/* The energy of a joint is its maximum over clips. */
TEST(energy_max_over_clips)
{
	int parent[] = {-1, 0, 1};
	mlod_character c = test_skeleton(3, parent);
	float small[] = {0, 10}, big[] = {0, 60, 0};
	add_x_rotation_clip(&c, 1, small, 2);
	add_x_rotation_clip(&c, 1, big, 3);
	mlod_joint_info info[3];
	CHECK_OK(mlod_label_skeleton(&c, NULL, info, &terr));
	CHECK_NEAR(info[1].energy, 2.0 / 3.0 * (120.0 / 180.0), 1e-4);
	mlod_character_free(&c);
}

TEST(bad_skeleton)
{
	int parent[] = {-1, 2, 0};
	mlod_character c = test_skeleton(3, parent);
	mlod_joint_info info[3];
	CHECK(mlod_label_skeleton(&c, NULL, info, &terr) == MLOD_ERR_PARSE);
	CHECK(strstr(terr.message, "j1") != NULL);
	mlod_character_free(&c);
	mlod_character empty = {0};
	CHECK(mlod_label_skeleton(&empty, NULL, info, &terr) == MLOD_ERR_PARSE);
}

TEST(names)
{
	mlod_label l;
	CHECK(mlod_label_parse("extreme", &l) == 0 && l == MLOD_LABEL_EXTREME);
	CHECK(mlod_label_parse("\xce\xba", &l) == 0 && l == MLOD_LABEL_MINOR);
	CHECK(mlod_label_parse("hub", &l) == -1);
	CHECK(strcmp(mlod_label_name(MLOD_LABEL_END_EFFECTOR), "end-effector") == 0);
}

/* A BVH converted to glb keeps each joint's Euler order (extras.mlod_bvh),
 * so its energies do not change. */
TEST(bvh_energy_survives_glb)
{
	size_t size;
	void *data = test_read_file("samples/cmu_12_01_walk.bvh", &size);
	CHECK(data != NULL);
	mlod_character a = {0}, b = {0};
	mlod_gltf *doc = NULL, *back = NULL;
	void *glb = NULL;
	size_t glb_size = 0;
	CHECK_OK(mlod_load(data, size, NULL, &doc, &a, NULL, &terr));
	free(data);
	CHECK_OK(mlod_gltf_write(doc, 1, &glb, &glb_size, &terr));
	CHECK_OK(mlod_load(glb, glb_size, NULL, &back, &b, NULL, &terr));
	CHECK(a.skeleton.joint_count == b.skeleton.joint_count);
	mlod_joint_info *ia = calloc((size_t)a.skeleton.joint_count, sizeof *ia);
	mlod_joint_info *ib = calloc((size_t)b.skeleton.joint_count, sizeof *ib);
	CHECK_OK(mlod_label_skeleton(&a, NULL, ia, &terr));
	CHECK_OK(mlod_label_skeleton(&b, NULL, ib, &terr));
	for (int j = 0; j < a.skeleton.joint_count; j++) {
		CHECK(a.skeleton.joints[j].euler == b.skeleton.joints[j].euler);
		CHECK(ia[j].label == ib[j].label);
		CHECK_NEAR(ia[j].energy, ib[j].energy, 1e-4 * (1.0 + ia[j].energy));
	}
	free(ia);
	free(ib);
	mlod_free(glb);
	mlod_gltf_free(doc);
	mlod_gltf_free(back);
	mlod_character_free(&a);
	mlod_character_free(&b);
}

int main(void)
{
	RUN(single_chain);
	RUN(humanoid_hubs);
	RUN(hub_at_average_depth_is_minor);
	RUN(star_and_two_roots);
	RUN(energy_total_variation);
	RUN(energy_unwraps_angles);
	RUN(energy_max_over_clips);
	RUN(names);
	RUN(bad_skeleton);
	RUN(bvh_energy_survives_glb);
	TEST_EXIT();
}
