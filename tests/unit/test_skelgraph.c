/* test_skelgraph.c: the Multiresolution Skeletal Graph, level extraction,
 * motion folding and skin transfer. */
#include "test.h"

TEST(chain_closure)
{
	/* root 0 - 1 - 2 - 3 - leaf 4: one chain, 4 + 3 + 2 + 1 edges. */
	int parent[] = {-1, 0, 1, 2, 3};
	mlod_character c = test_skeleton(5, parent);
	mlod_joint_info info[5];
	mlod_skelgraph g;
	CHECK_OK(mlod_label_skeleton(&c, NULL, info, &terr));
	CHECK_OK(mlod_skelgraph_build(&c.skeleton, info, &g, &terr));
	CHECK(g.chain_count == 1);
	CHECK(g.chain_start[1] - g.chain_start[0] == 5);
	CHECK(g.edge_count == 10);
	for (int e = 0; e < g.edge_count; e++) {
		const mlod_skelgraph_edge *edge = &g.edges[e];
		CHECK_NEAR(edge->length, (double)(edge->b - edge->a), 1e-6);
	}
	/* Remove everything minor: the leaf hangs from the root. */
	mlod_skel_level l;
	CHECK_OK(mlod_skelgraph_extract(&g, info, 1e30, &l, &terr));
	CHECK(l.kept_count == 2);
	CHECK(l.parent[4] == 0);
	CHECK(l.remap[2] == 0 && l.remap[4] == 4);
	mlod_skel_level_free(&l);
	mlod_skelgraph_free(&g);
	mlod_character_free(&c);
}

TEST(star_has_one_chain_per_bone)
{
	int parent[] = {-1, 0, 0, 0, 0};
	mlod_character c = test_skeleton(5, parent);
	mlod_joint_info info[5];
	mlod_skelgraph g;
	CHECK_OK(mlod_label_skeleton(&c, NULL, info, &terr));
	CHECK_OK(mlod_skelgraph_build(&c.skeleton, info, &g, &terr));
	CHECK(g.chain_count == 4);
	CHECK(g.edge_count == 4);
	mlod_skelgraph_free(&g);
	mlod_character_free(&c);
}

TEST(two_roots)
{
	int parent[] = {-1, 0, 1, -1, 3, 4};
	mlod_character c = test_skeleton(6, parent);
	mlod_joint_info info[6];
	mlod_skelgraph g;
	mlod_skel_level l;
	CHECK_OK(mlod_label_skeleton(&c, NULL, info, &terr));
	CHECK_OK(mlod_skelgraph_build(&c.skeleton, info, &g, &terr));
	CHECK(g.chain_count == 2);
	CHECK_OK(mlod_skelgraph_extract(&g, info, 1.0, &l, &terr));
	CHECK(l.kept_count == 4);
	CHECK(l.parent[2] == 0 && l.parent[5] == 3 && l.parent[3] == -1);
	mlod_skel_level_free(&l);
	mlod_skelgraph_free(&g);
	mlod_character_free(&c);
}

/* Zero-length bones make equal closure lengths: the tie goes to the deeper
 * ancestor, so the level still reconnects to the nearest kept ancestor. */
TEST(zero_length_bones)
{
	int parent[] = {-1, 0, 1, 2, 3};
	mlod_character c = test_skeleton(5, parent);
	c.skeleton.joints[1].rest.t.y = 0.0f;
	c.skeleton.joints[2].rest.t.y = 0.0f;
	mlod_joint_info info[5];
	mlod_skelgraph g;
	mlod_skel_level l;
	CHECK_OK(mlod_label_skeleton(&c, NULL, info, &terr));
	info[1].energy = 1.0;
	info[2].energy = 1.0;
	info[3].energy = 0.0;
	CHECK_OK(mlod_skelgraph_build(&c.skeleton, info, &g, &terr));
	CHECK_OK(mlod_skelgraph_extract(&g, info, 0.5, &l, &terr));
	CHECK(l.parent[1] == 0 && l.parent[2] == 1 && l.parent[4] == 2);
	mlod_skel_level_free(&l);
	mlod_skelgraph_free(&g);
	mlod_character_free(&c);
}

/* Oracle: the MST extraction equals nearest-kept-ancestor reconnection, the
 * levels nest, and every threshold between two energies is tried. */
static void check_oracle(const mlod_character *c)
{
	int n = c->skeleton.joint_count;
	mlod_joint_info *info = calloc((size_t)n, sizeof *info);
	mlod_skelgraph g;
	CHECK_OK(mlod_label_skeleton(c, NULL, info, &terr));
	CHECK_OK(mlod_skelgraph_build(&c->skeleton, info, &g, &terr));
	unsigned char *prev = calloc((size_t)n, 1);
	memset(prev, 1, (size_t)n);
	int *order = malloc(sizeof(int) * (size_t)n);
	int minors = mlod_skel_removal_order(&c->skeleton, info, order);
	for (int removed = 0; removed <= minors; removed++) {
		mlod_skel_level l;
		CHECK_OK(mlod_skelgraph_extract_first(&g, info, order, removed, &l, &terr));
		CHECK(l.kept_count == n - removed);
		/* The same level by threshold when the energies do not tie. */
		if (removed > 0 && (removed == minors || info[order[removed]].energy > info[order[removed - 1]].energy)) {
			mlod_skel_level lt;
			double th = removed == minors ? 1e300 : 0.5 * (info[order[removed]].energy + info[order[removed - 1]].energy);
			CHECK_OK(mlod_skelgraph_extract(&g, info, th, &lt, &terr));
			CHECK(memcmp(lt.kept, l.kept, (size_t)n) == 0);
			mlod_skel_level_free(&lt);
		}
		double t = l.threshold;
		for (int j = 0; j < n; j++) {
			CHECK_MSG(!l.kept[j] || prev[j], "level at %g keeps %s removed earlier", t, c->skeleton.joints[j].name);
			if (!l.kept[j])
				continue;
			int a = c->skeleton.joints[j].parent;
			while (a >= 0 && !l.kept[a])
				a = c->skeleton.joints[a].parent;
			CHECK_MSG(l.parent[j] == a, "joint %s: MST parent %d, nearest kept ancestor %d",
			          c->skeleton.joints[j].name, l.parent[j], a);
		}
		memcpy(prev, l.kept, (size_t)n);
		mlod_skel_level_free(&l);
	}
	free(prev);
	free(order);
	free(info);
	mlod_skelgraph_free(&g);
}

/* The oracle and the folding check on every file of ../shared/data too,
 * under make test-extended (the caller checks it is there). The folder's
 * contents change from machine to machine: a file of the list that is not
 * there is named on stdout and left out; the characters, at least one of
 * which is always there, must be. */
static void for_shared(void (*check)(const mlod_character *))
{
	static const char *files[] = {"Ely.glb", "RobotExpressive.glb", "bvh_test3.bvh", "cmu_12_01_walk.bvh"};
	static const int required[] = {1, 1, 0, 0};
	for (size_t i = 0; i < sizeof files / sizeof *files; i++) {
		char path[1024];
		mlod_character c = {0};
		snprintf(path, sizeof path, "%.900s/%s", getenv("MLOD_SHARED_DATA"), files[i]);
		struct stat st;
		if (!required[i] && stat(path, &st) != 0) {
			printf("note: %s is not in ../shared/data on this machine; left out\n", files[i]);
			continue;
		}
		CHECK_MSG(test_load(path, &c) == 0, "cannot load %.300s", path);
		check(&c);
		mlod_character_free(&c);
		if (test_failed_)
			return;
	}
}

static void check_folding_39(const mlod_character *c);
static void check_vertex_deviation(const mlod_character *c);

TEST(shared_data)
{
	NEED_SHARED();
	for_shared(check_oracle);
	if (!test_failed_)
		for_shared(check_folding_39);
	if (!test_failed_)
		for_shared(check_vertex_deviation);
}

TEST(mst_equals_nearest_kept_ancestor)
{
	const char *samples[] = {"samples/cmu_12_01_walk.bvh", "samples/RobotExpressive.glb", "samples/tubeman.glb",
	                         "tests/data/mixed_channels.bvh", "tests/data/two_roots.bvh"};
	for (size_t i = 0; i < sizeof samples / sizeof *samples; i++) {
		mlod_character c = {0};
		CHECK_MSG(test_load(samples[i], &c) == 0, "cannot load %s", samples[i]);
		check_oracle(&c);
		mlod_character_free(&c);
		if (test_failed_)
			return;
	}
}

/* The world transform of every kept joint at every key time or frame
 * matches the full skeleton within 1e-5 of the skeleton height. */
static void check_folding(const mlod_character *c, double fraction)
{
	const mlod_skeleton *s = &c->skeleton;
	int n = s->joint_count;
	mlod_joint_info *info = calloc((size_t)n, sizeof *info);
	mlod_skelgraph g;
	mlod_skel_level l;
	mlod_character r = {0};
	mlod_fold_stats st;
	CHECK_OK(mlod_label_skeleton(c, NULL, info, &terr));
	CHECK_OK(mlod_skelgraph_build(s, info, &g, &terr));
	int *order = malloc(sizeof(int) * (size_t)n);
	int minors = mlod_skel_removal_order(s, info, order);
	int removed = (int)(fraction * n) < minors ? (int)(fraction * n) : minors;
	CHECK_OK(mlod_skelgraph_extract_first(&g, info, order, removed, &l, &terr));
	free(order);
	CHECK_OK(mlod_skel_level_apply(c, &l, &r, &st, &terr));
	CHECK_OK(mlod_character_validate(&r, &terr));
	CHECK(r.skeleton.joint_count == l.kept_count);
	CHECK(st.shear_samples == 0);
	double size = mlod_skeleton_height(s);
	mlod_trs *pa = malloc(sizeof *pa * (size_t)n), *pb = malloc(sizeof *pb * (size_t)n);
	mlod_mat4 *wa = malloc(sizeof *wa * (size_t)n), *wb = malloc(sizeof *wb * (size_t)n);
	for (int k = 0; k < c->clip_count; k++) {
		const mlod_clip *clip = &c->clips[k];
		/* Every frame of a sampled clip, or every key time of every channel. */
		int frames = clip->frame_count;
		for (int i = 0; i < clip->channel_count && clip->frame_count <= 0; i++)
			frames += clip->channels[i].key_count;
		for (int f = 0, ci = 0, key = 0; f < frames; f++) {
			float t;
			if (clip->frame_count > 0) {
				t = (float)f * clip->frame_time;
			} else {
				while (key >= clip->channels[ci].key_count)
					ci++, key = 0;
				t = clip->channels[ci].times[key++];
			}
			mlod_pose_rest(s, pa);
			mlod_clip_sample(clip, t, pa);
			mlod_pose_world(s, pa, wa);
			mlod_pose_rest(&r.skeleton, pb);
			mlod_clip_sample(&r.clips[k], t, pb);
			mlod_pose_world(&r.skeleton, pb, wb);
			for (int j = 0, nj = 0; j < n; j++) {
				if (!l.kept[j])
					continue;
				for (int e = 0; e < 16; e++) {
					/* relative to the column's length (world matrices carry
					 * the armature's scale) or to the skeleton height */
					const float *col = &wa[j].m[4 * (e / 4)];
					double norm = sqrt((double)col[0] * col[0] + (double)col[1] * col[1] + (double)col[2] * col[2]);
					double tol = 1e-5 * (e >= 12 ? size : norm);
					CHECK_MSG(fabs(wa[j].m[e] - wb[nj].m[e]) <= tol,
					          "clip %d t=%g joint %s m[%d]: %g vs %g", k, t, s->joints[j].name, e,
					          wa[j].m[e], wb[nj].m[e]);
				}
				nj++;
			}
		}
	}
	/* Weights: sum 1, at most 4 per set, indices inside the reduced skin. */
	for (int m = 0; m < r.mesh_count; m++) {
		for (int p = 0; p < r.meshes[m].primitive_count; p++) {
			const mlod_primitive *q = &r.meshes[m].primitives[p];
			int skin = -1;
			for (int i = 0; i < r.instance_count; i++)
				if (r.instances[i].mesh == m && r.instances[i].skin >= 0)
					skin = r.instances[i].skin;
			if (skin < 0 || q->weight_set_count == 0)
				continue;
			for (int v = 0; v < q->vertex_count; v++) {
				double sum = 0;
				for (int ws = 0; ws < q->weight_set_count; ws++) {
					for (int i = 0; i < 4; i++) {
						sum += q->weights[ws][4 * v + i];
						CHECK(q->joints[ws][4 * v + i] < r.skeleton.skins[skin].joint_count);
					}
				}
				CHECK_MSG(fabs(sum - 1.0) <= 1e-6 || sum == 0.0, "mesh %d vertex %d: weights sum to %.9g", m, v, sum);
			}
		}
	}
	free(pa), free(pb), free(wa), free(wb), free(info);
	mlod_character_free(&r);
	mlod_skel_level_free(&l);
	mlod_skelgraph_free(&g);
}

/* mlod_skel_vertex_deviation gives mlod_vertex_deviation's numbers bit for
 * bit: on levels removing 13% and 39% of the joints, and on a level whose
 * kept joint's bind matrix and one vertex's weights were changed after
 * the fold (what it must not take as unchanged). */
static void check_vertex_deviation(const mlod_character *c)
{
	const mlod_skeleton *s = &c->skeleton;
	int n = s->joint_count;
	mlod_joint_info *info = calloc((size_t)n, sizeof *info);
	int *order = malloc(sizeof(int) * (size_t)n);
	mlod_skelgraph g;
	CHECK(info && order);
	CHECK_OK(mlod_label_skeleton(c, NULL, info, &terr));
	CHECK_OK(mlod_skelgraph_build(s, info, &g, &terr));
	int minors = mlod_skel_removal_order(s, info, order);
	mlod_skel_pose_cache *cache = mlod_skel_pose_cache_new(); /* passes 0 and 2 share it; 1 goes without */
	CHECK(cache);
	for (int pass = 0; pass < 3 && !test_failed_; pass++) {
		double fraction = pass == 0 ? 0.13 : 0.39;
		int removed = (int)(fraction * n) < minors ? (int)(fraction * n) : minors;
		mlod_skel_level l;
		mlod_character r = {0};
		CHECK_OK(mlod_skelgraph_extract_first(&g, info, order, removed, &l, &terr));
		CHECK_OK(mlod_skel_level_apply(c, &l, &r, NULL, &terr));
		if (pass == 2 && r.skeleton.skin_count > 0 && r.skeleton.skins[0].joint_count > 0) {
			r.skeleton.skins[0].inverse_bind[0].m[12] += 0.01f;
			for (int m = 0; m < r.mesh_count; m++)
				for (int p = 0; p < r.meshes[m].primitive_count; p++) {
					mlod_primitive *q = &r.meshes[m].primitives[p];
					if (q->weight_set_count > 0 && q->vertex_count > 1 && q->weights[0][4] > 0.0f &&
					    q->weights[0][4] < 1.0f)
						q->weights[0][4] *= 0.5f;
				}
		}
		mlod_deviation want, got;
		CHECK_OK(mlod_vertex_deviation(c, &r, MLOD_SKEL_SAMPLES, &want, &terr));
		CHECK_OK(mlod_skel_vertex_deviation(c, &r, MLOD_SKEL_SAMPLES, pass == 1 ? NULL : cache, &got, &terr));
		CHECK_MSG(memcmp(&want, &got, sizeof want) == 0, "removing %d of %d joints (pass %d): mean %.17g max %.17g "
		          "scale %.17g, want %.17g %.17g %.17g", removed, n, pass, got.mean, got.max, got.scale, want.mean,
		          want.max, want.scale);
		mlod_character_free(&r);
		mlod_skel_level_free(&l);
	}
	mlod_skel_pose_cache_free(cache);
	free(order);
	free(info);
	mlod_skelgraph_free(&g);
}

TEST(vertex_deviation_is_exact)
{
	const char *samples[] = {"samples/RobotExpressive.glb", "samples/tubeman.glb", "samples/cmu_12_01_walk.bvh"};
	for (size_t i = 0; i < sizeof samples / sizeof *samples && !test_failed_; i++) {
		mlod_character c = {0};
		CHECK_MSG(test_load(samples[i], &c) == 0, "cannot load %s", samples[i]);
		check_vertex_deviation(&c);
		mlod_character_free(&c);
	}
}

static void check_folding_39(const mlod_character *c)
{
	check_folding(c, 0.39);
}

TEST(folding_is_exact)
{
	const char *samples[] = {"samples/cmu_12_01_walk.bvh", "samples/RobotExpressive.glb", "samples/tubeman.glb",
	                         "tests/data/mixed_channels.bvh"};
	for (size_t i = 0; i < sizeof samples / sizeof *samples; i++) {
		mlod_character c = {0};
		CHECK_MSG(test_load(samples[i], &c) == 0, "cannot load %s", samples[i]);
		check_folding(&c, 0.39);
		check_folding(&c, 0.2);
		mlod_character_free(&c);
		if (test_failed_)
			return;
	}
}

/* A removed joint with non-uniform scale under a rotated child shears:
 * the fold reports it. */
TEST(shear_is_detected)
{
	int parent[] = {-1, 0, 1, 2};
	mlod_character c = test_skeleton(4, parent);
	c.skeleton.joints[1].rest.s = (mlod_v3){1.0f, 3.0f, 1.0f};
	mlod_v3 z = {0, 0, 1};
	c.skeleton.joints[2].rest.r = mlod_quat_axis_angle(z, 0.7f);
	mlod_joint_info info[4];
	mlod_skelgraph g;
	mlod_skel_level l;
	mlod_character r;
	mlod_fold_stats st;
	CHECK_OK(mlod_label_skeleton(&c, NULL, info, &terr));
	CHECK_OK(mlod_skelgraph_build(&c.skeleton, info, &g, &terr));
	info[1].energy = 0.0;
	info[2].energy = 1.0;
	CHECK_OK(mlod_skelgraph_extract(&g, info, 0.5, &l, &terr));
	CHECK(!l.kept[1] && l.kept[2]);
	CHECK_OK(mlod_skel_level_apply(&c, &l, &r, &st, &terr));
	CHECK(st.shear_samples > 0);
	mlod_character_free(&r);
	mlod_skel_level_free(&l);
	mlod_skelgraph_free(&g);
	mlod_character_free(&c);
}

/* Weight on a removed joint moves to its stand-in and merges. */
/* The End Sites of BVH text against c's, joints matched by name, at the
 * BVH's frames: the largest distance. */
static double bvh_end_site_distance(const mlod_character *c, const char *text, size_t size)
{
	mlod_character b;
	if (mlod_bvh_read(text, size, &b, &terr) != MLOD_OK)
		return -1.0;
	int n = c->skeleton.joint_count, m = b.skeleton.joint_count;
	mlod_trs *la = malloc(sizeof *la * (size_t)n), *lb = malloc(sizeof *lb * (size_t)m);
	mlod_mat4 *wa = malloc(sizeof *wa * (size_t)n), *wb = malloc(sizeof *wb * (size_t)m);
	double worst = 0.0;
	for (int f = 0; f < b.clips[0].frame_count; f++) {
		float t = (float)f * b.clips[0].frame_time;
		mlod_pose_rest(&c->skeleton, la);
		mlod_clip_sample(&c->clips[0], t, la);
		mlod_pose_world(&c->skeleton, la, wa);
		mlod_pose_rest(&b.skeleton, lb);
		mlod_clip_sample(&b.clips[0], t, lb);
		mlod_pose_world(&b.skeleton, lb, wb);
		for (int j = 0; j < m; j++)
			for (int k = 0; k < n; k++)
				if (b.skeleton.joints[j].has_end_site && strcmp(b.skeleton.joints[j].name, c->skeleton.joints[k].name) == 0) {
					mlod_v3 pa = mlod_mat4_point(&wa[k], c->skeleton.joints[k].end_site);
					mlod_v3 pb = mlod_mat4_point(&wb[j], b.skeleton.joints[j].end_site);
					double d = mlod_v3_length(mlod_v3_sub(pa, pb));
					worst = d > worst ? d : worst;
				}
	}
	free(la);
	free(lb);
	free(wa);
	free(wb);
	mlod_character_free(&b);
	return worst;
}

TEST(bvh_end_sites_under_scale)
{
	/* BVH has no scale channel: mlod_bvh_write keeps the joints in place
	 * but not the End Sites below a scale channel's joint (tubeman with
	 * LeftLeg scaled by 1 + 0.3 sin: 0.3051 off, written with exit 0 and
	 * no word). mlod_skel_bvh_end_sites says how far, as the BVH read back
	 * shows. */
	mlod_character c;
	CHECK(test_load("samples/tubeman.glb", &c) == 0);
	double max = -1.0;
	int joint = -2;
	char note[MLOD_SKEL_BVH_NOTE_SIZE];
	CHECK_OK(mlod_skel_bvh_end_sites(&c, 0, &max, &joint, note, sizeof note, &terr));
	CHECK(max < 1e-4 && note[0] == '\0');
	int leg = -1;
	for (int j = 0; j < c.skeleton.joint_count; j++)
		if (strcmp(c.skeleton.joints[j].name, "LeftLeg") == 0)
			leg = j;
	CHECK(leg >= 0);
	mlod_clip *cl = &c.clips[0];
	mlod_channel *chs = realloc(cl->channels, sizeof *chs * (size_t)(cl->channel_count + 1));
	CHECK(chs);
	cl->channels = chs;
	const mlod_channel *first = &cl->channels[0];
	mlod_channel *ch = &cl->channels[cl->channel_count++];
	memset(ch, 0, sizeof *ch);
	ch->joint = leg;
	ch->path = MLOD_PATH_SCALE;
	ch->interp = MLOD_INTERP_LINEAR;
	ch->key_count = first->key_count;
	ch->times = malloc(sizeof(float) * (size_t)ch->key_count);
	ch->values = malloc(sizeof(float) * 3 * (size_t)ch->key_count);
	memcpy(ch->times, first->times, sizeof(float) * (size_t)ch->key_count);
	for (int k = 0; k < ch->key_count; k++)
		for (int a = 0; a < 3; a++)
			ch->values[3 * k + a] = 1.0f + 0.3f * sinf((float)k * 0.05f);
	CHECK_OK(mlod_skel_bvh_end_sites(&c, 0, &max, &joint, note, sizeof note, &terr));
	CHECK(joint >= 0 && strcmp(c.skeleton.joints[joint].name, "LeftToeBase") == 0);
	CHECK_MSG(fabs(max - 0.3051) < 1e-3, "%g", max);
	CHECK(strstr(note, "clip \"walk\": BVH has no scale channel") == note);
	char *text = NULL;
	size_t size = 0;
	CHECK_OK(mlod_bvh_write(&c, 0, 0.0f, &text, &size, &terr));
	double back = bvh_end_site_distance(&c, text, size);
	mlod_free(text);
	CHECK_MSG(fabs(back - max) < 1e-3 * max, "read back %g, said %g", back, max);
	/* At the rest scale, nothing moves. */
	for (int k = 0; k < ch->key_count; k++)
		for (int a = 0; a < 3; a++)
			ch->values[3 * k + a] = 1.0f;
	CHECK_OK(mlod_skel_bvh_end_sites(&c, 0, &max, &joint, note, sizeof note, &terr));
	CHECK(max < 1e-4 && note[0] == '\0');
	mlod_character_free(&c);
}

/* Writing no skeleton level (none within the bound, as on the robot at
 * the default 2%) touches no level's mesh: before, the instance loop read
 * mesh_index, allocated for one int, at every mesh (ASan: heap overflow
 * in mlod_gltf_add_skel_levels on samples/RobotExpressive.glb). */
TEST(no_levels_written)
{
	size_t size;
	void *bytes = test_read_file("samples/RobotExpressive.glb", &size);
	CHECK_MSG(bytes, "samples/RobotExpressive.glb: cannot read");
	mlod_error e = {0};
	mlod_gltf *doc = NULL;
	mlod_character c = {0};
	CHECK_MSG(mlod_gltf_read(bytes, size, NULL, &doc, &e) == MLOD_OK && mlod_gltf_to_character(doc, &c, &e) == MLOD_OK,
	      "%s", e.message);
	CHECK_MSG(c.mesh_count > 1 && c.instance_count > 1, "the robot has %d meshes", c.mesh_count);
	int skins[1];
	CHECK_MSG(mlod_gltf_add_skel_levels(doc, &c, NULL, 0, skins, 1, &e) == MLOD_OK, "%s", e.message);
	mlod_character_free(&c);
	mlod_gltf_free(doc);
	free(bytes);
}

TEST(skin_transfer_merges)
{
	int parent[] = {-1, 0, 1, 2};
	mlod_character c = test_skeleton(4, parent);
	c.skeleton.skin_count = 1;
	c.skeleton.skins = calloc(1, sizeof(mlod_skin));
	mlod_skin *sk = &c.skeleton.skins[0];
	sk->name = strdup("skin");
	sk->joint_count = 3;
	sk->joints = malloc(3 * sizeof(int));
	sk->inverse_bind = malloc(3 * sizeof(mlod_mat4));
	int joints[] = {0, 1, 2}; /* joint 3 (the leaf) is not in the skin */
	for (int k = 0; k < 3; k++) {
		sk->joints[k] = joints[k];
		mlod_mat4 m = mlod_mat4_identity();
		m.m[13] = -(float)joints[k];
		sk->inverse_bind[k] = m;
	}
	c.mesh_count = 1;
	c.meshes = calloc(1, sizeof(mlod_mesh));
	c.meshes[0].name = strdup("m");
	c.meshes[0].primitive_count = 1;
	c.meshes[0].primitives = calloc(1, sizeof(mlod_primitive));
	mlod_primitive *p = &c.meshes[0].primitives[0];
	p->vertex_count = 3;
	p->mode = 4;
	p->material = -1;
	p->positions = calloc(9, sizeof(float));
	p->positions[4] = 1.5f;
	p->index_count = 3;
	p->indices = malloc(3 * sizeof(uint32_t));
	for (int i = 0; i < 3; i++)
		p->indices[i] = (uint32_t)i;
	p->weight_set_count = 1;
	p->joints[0] = calloc(12, sizeof(uint16_t));
	p->weights[0] = calloc(12, sizeof(float));
	/* vertex 1: half on joint 0, half on joint 1 (to be removed) */
	p->joints[0][4] = 0, p->weights[0][4] = 0.5f;
	p->joints[0][5] = 1, p->weights[0][5] = 0.5f;
	p->weights[0][0] = 1.0f;
	p->joints[0][8] = 2, p->weights[0][8] = 1.0f;
	c.instance_count = 1;
	c.instances = calloc(1, sizeof(mlod_instance));
	c.instances[0] = (mlod_instance){0, -1, 0, -1, mlod_mat4_identity()};

	mlod_joint_info info[4];
	mlod_skelgraph g;
	mlod_skel_level l;
	mlod_character r;
	mlod_fold_stats st;
	CHECK_OK(mlod_label_skeleton(&c, NULL, info, &terr));
	info[1].energy = 0.0;
	info[2].energy = 1.0;
	CHECK_OK(mlod_skelgraph_build(&c.skeleton, info, &g, &terr));
	CHECK_OK(mlod_skelgraph_extract(&g, info, 0.5, &l, &terr));
	CHECK_OK(mlod_skel_level_apply(&c, &l, &r, &st, &terr));
	CHECK(st.weight_merges == 1);
	const mlod_skin *rs = &r.skeleton.skins[0];
	CHECK(rs->joint_count == 2);
	const mlod_primitive *q = &r.meshes[0].primitives[0];
	CHECK(rs->joints[q->joints[0][4]] == 0);
	CHECK_NEAR(q->weights[0][4], 1.0, 1e-7);
	CHECK_NEAR(q->weights[0][5], 0.0, 0.0);
	/* The rest pose still skins to the bind positions. */
	mlod_trs pose[3];
	mlod_mat4 world[3], mats[2];
	float out[9];
	mlod_pose_rest(&r.skeleton, pose);
	mlod_pose_world(&r.skeleton, pose, world);
	mlod_skin_matrices(rs, world, mats);
	mlod_skin_primitive(q, mats, out, NULL);
	for (int i = 0; i < 9; i++)
		CHECK_NEAR(out[i], p->positions[i], 1e-6);
	mlod_character_free(&r);
	mlod_skel_level_free(&l);
	mlod_skelgraph_free(&g);
	mlod_character_free(&c);
}

int main(void)
{
	RUN(chain_closure);
	RUN(star_has_one_chain_per_bone);
	RUN(two_roots);
	RUN(zero_length_bones);
	RUN(mst_equals_nearest_kept_ancestor);
	RUN(folding_is_exact);
	RUN(shear_is_detected);
	RUN(skin_transfer_merges);
	RUN(no_levels_written);
	RUN(bvh_end_sites_under_scale);
	RUN(vertex_deviation_is_exact);
	RUN(shared_data);
	TEST_EXIT();
}
