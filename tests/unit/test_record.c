/*
 * test_record.c: the stage record (lib/record): its strict JSON, each
 * stage's reader and writer, merging, the version, and clear errors on
 * malformed or hostile records.
 */
#include "test.h"

#include "record/json.h"

/* ---------------------------------------------------------------- */
/* JSON                                                              */
/* ---------------------------------------------------------------- */

static int parses(const char *text)
{
	mj v;
	char why[128];
	int rc = mj_parse(text, strlen(text), &v, why, sizeof why);
	mj_free(&v);
	return rc == 0;
}

TEST(json_strict)
{
	static const char *const good[] = {
		"{}", "[]", "0", "-0.5e+3", "\"a\\u00e9\\ud83d\\ude00\"", "{\"a\":[1,true,false,null,{\"b\":\"\"}]}",
		" \t\n{ \"x\" : 1 } ",
	};
	static const char *const bad[] = {
		"", "{", "[1,]", "{\"a\":1,}", "01", "1.", ".5", "1e", "+1", "{'a':1}", "{\"a\" 1}", "[1 2]",
		"\"\\x\"", "\"\\ud800\"", "\"\\udc00x\"", "\"\\u12\"", "\"\\u0000\"", "\"a\nb\"", "tru", "nul", "1 2",
		"{\"a\":1,\"a\":2}", "1e999", "\"unterminated", "[\"\\", "{\"a\":}", "NaN", "[1]]",
	};
	for (size_t i = 0; i < sizeof good / sizeof *good; i++)
		CHECK_MSG(parses(good[i]), "refused %s", good[i]);
	for (size_t i = 0; i < sizeof bad / sizeof *bad; i++)
		CHECK_MSG(!parses(bad[i]), "accepted %s", bad[i]);
}

TEST(json_depth_and_roundtrip)
{
	/* Nesting: 64 levels parse, 65 do not, 100000 do not crash. */
	char deep[200001];
	for (int depth = 64; depth <= 65; depth++) {
		memset(deep, '[', (size_t)depth);
		memset(deep + depth, ']', (size_t)depth);
		deep[2 * depth] = '\0';
		CHECK(parses(deep) == (depth == 64));
	}
	memset(deep, '[', 100000);
	memset(deep + 100000, ']', 100000);
	deep[200000] = '\0';
	CHECK(!parses(deep));

	/* Written back, numbers keep their digits and strings their bytes. */
	const char *text = "{\"n\":[0.100000001,12345678901,-3e-7],\"s\":\"caf\xc3\xa9 \\\"q\\\" \\n\",\"t\":true}";
	mj v;
	char *out = NULL, why[128];
	CHECK(mj_parse(text, strlen(text), &v, why, sizeof why) == 0);
	CHECK(mj_write(&v, &out) == 0);
	CHECK_MSG(strcmp(out, text) == 0, "wrote %s", out);
	free(out);
	mj_free(&v);
}

/* Mutations of a valid record never crash (the sanitizer build checks
 * memory), and a rejected text always says why. */
TEST(json_hostile)
{
	const char *base = "{\"skeleton_levels\":[{\"level\":1,\"threshold\":0.5,\"kept\":[0,1],\"remap\":{\"2\":1},"
	                   "\"joint_error\":{\"max\":1,\"mean\":0.5}}],\"s\":\"\\u00e9\"}";
	size_t n = strlen(base);
	char buf[512];
	unsigned state = 12345u;
	for (int round = 0; round < 20000; round++) {
		memcpy(buf, base, n + 1);
		size_t len = n;
		for (int m = 0; m < 1 + round % 4; m++) {
			state = state * 1103515245u + 12345u;
			size_t at = (state >> 8) % len;
			switch ((state >> 4) % 3) {
			case 0: buf[at] = (char)(state >> 16); break;            /* change a byte */
			case 1: len = at; break;                                  /* truncate */
			case 2: memmove(buf + at, buf + at + 1, len - at); len--; break; /* drop one */
			}
			if (len == 0)
				len = 1;
		}
		mj v;
		char why[128] = "";
		if (mj_parse(buf, len, &v, why, sizeof why) != 0)
			CHECK_MSG(why[0] != '\0', "no message for a rejected text");
		mj_free(&v);
	}
}

/* ---------------------------------------------------------------- */
/* Records in a document                                             */
/* ---------------------------------------------------------------- */

static int load(const char *path, mlod_gltf **doc, mlod_character *c)
{
	size_t size;
	void *data = test_read_file(path, &size);
	if (!data)
		return -1;
	mlod_result r = mlod_load(data, size, "samples", doc, c, NULL, &terr);
	free(data);
	return r == MLOD_OK ? 0 : -1;
}

/* Two skeleton levels of the tubeman as records. */
static mlod_record_skel_level skel_level(int level, int kept_node, int from, int to, int skin)
{
	static int kept[2][1], rf[2][1], rt[2][1], skins[2][1];
	int k = level - 1;
	kept[k][0] = kept_node;
	rf[k][0] = from;
	rt[k][0] = to;
	skins[k][0] = skin;
	mlod_record_skel_level l = {0};
	l.level = level;
	l.threshold = 0.25 * level;
	l.joints = 1;
	l.kept_count = 1;
	l.kept = kept[k];
	l.remap_count = 1;
	l.remap_from = rf[k];
	l.remap_to = rt[k];
	l.skin_count = 1;
	l.skins = skins[k];
	l.joint_error = (mlod_deviation){.max = 0.125, .mean = 0.5};
	l.has_vertex_error = level == 2;
	l.vertex_error = (mlod_deviation){.max = 0.01, .mean = 0.02};
	return l;
}

TEST(stages_merge_and_version)
{
	mlod_gltf *doc = NULL;
	mlod_character c = {0};
	CHECK(load("samples/tubeman.glb", &doc, &c) == 0);
	CHECK(c.skeleton.skin_count == 1);
	int full = c.skeleton.skins[0].gltf_index;

	/* Labels: written, read back, and found only when every joint has one. */
	mlod_joint_info *info = calloc((size_t)c.skeleton.joint_count, sizeof *info), *back;
	back = calloc((size_t)c.skeleton.joint_count, sizeof *back);
	CHECK_OK(mlod_label_skeleton(&c, NULL, info, &terr));
	int found = -1;
	CHECK_OK(mlod_record_read_joints(doc, &c, back, &found, &terr));
	CHECK(found == 0);
	CHECK_OK(mlod_record_write_joints(doc, &c, info, &terr));
	CHECK_OK(mlod_record_read_joints(doc, &c, back, &found, &terr));
	CHECK(found == 1);
	for (int j = 0; j < c.skeleton.joint_count; j++) {
		CHECK(back[j].label == info[j].label);
		CHECK_NEAR(back[j].energy, info[j].energy, 1e-8 * (1 + info[j].energy));
	}

	/* Mesh levels, then skeleton levels: both stay (the merge fix), and
	 * the version is stamped. */
	mlod_record_mesh_level mesh[2] = {{.level = 1, .ratio = 0.5, .triangles = 100, .vertices = 80, .error = {0.1, 1.5, 0}},
	                                  {.level = 2, .ratio = 0.25, .triangles = 50, .vertices = 40, .error = {0.3, 3.0, 0}}};
	CHECK_OK(mlod_record_write_mesh_levels(doc, mesh, 2, &terr));
	mlod_record_skel_level skel[2] = {skel_level(1, 0, 2, 1, full), skel_level(2, 0, 3, 0, full)};
	int fulls[1] = {full};
	CHECK_OK(mlod_record_write_skeleton(doc, skel, 2, fulls, 1, &terr));
	mlod_record rec;
	CHECK_OK(mlod_record_read(doc, &rec, &terr));
	CHECK(rec.version == MLOD_RECORD_VERSION);
	CHECK(rec.mesh_level_count == 2 && rec.skel_level_count == 2);
	CHECK(rec.mesh_levels[1].triangles == 50 && rec.mesh_levels[1].vertices == 40);
	CHECK_NEAR(rec.mesh_levels[0].error.max, 1.5, 0);
	/* Coverage as MSFT_screencoverage: 100 / (1.5 * 1080), then less. */
	CHECK_NEAR(rec.mesh_levels[0].coverage, (float)(100.0 / (1.5 * 1080.0)), 1e-7);
	CHECK(rec.mesh_levels[1].coverage <= rec.mesh_levels[0].coverage);
	CHECK(rec.skel_levels[1].remap_from[0] == 3 && rec.skel_levels[1].remap_to[0] == 0);
	CHECK(rec.skel_levels[0].skins[0] == full && !rec.skel_levels[0].has_vertex_error);
	CHECK(rec.skel_levels[1].has_vertex_error);
	CHECK_NEAR(rec.skel_levels[1].vertex_error.mean, 0.02, 0);
	CHECK(rec.skin_count == 1 && rec.skins[0].skin == full && rec.skins[0].level_count == 2);
	mlod_record_free(&rec);

	/* The other order, and labels again: nothing is lost. */
	CHECK_OK(mlod_record_write_mesh_levels(doc, mesh, 1, &terr));
	CHECK_OK(mlod_record_write_joints(doc, &c, info, &terr));
	CHECK_OK(mlod_record_read(doc, &rec, &terr));
	CHECK(rec.mesh_level_count == 1 && rec.skel_level_count == 2);
	mlod_record_free(&rec);
	CHECK_OK(mlod_record_read_joints(doc, &c, back, &found, &terr));
	CHECK(found == 1);

	/* A split file's one level sits beside the rest. */
	CHECK_OK(mlod_record_write_mesh_split(doc, &mesh[1], &terr));
	CHECK_OK(mlod_record_read(doc, &rec, &terr));
	CHECK(rec.has_mesh_level && rec.mesh_level.level == 2 && rec.skel_level_count == 2);
	mlod_record_free(&rec);

	free(info);
	free(back);
	mlod_character_free(&c);
	mlod_gltf_free(doc);
}

TEST(motion_and_node_records)
{
	mlod_gltf *doc = NULL;
	mlod_character c = {0};
	CHECK(load("samples/tubeman.glb", &doc, &c) == 0);
	CHECK(mlod_gltf_count(doc, MLOD_GLTF_ANIMATION) >= 1);
	mlod_record_motion_level m = {0}, back;
	m.level = 2;
	m.source_animation = 0;
	m.method = MLOD_MOTION_KEYS;
	m.threshold = 0.01;
	m.has_bound = 1;
	m.bound = 0.02;
	m.keys = 1000;
	m.source_keys = 5000;
	m.bytes = 12345;
	m.joint_error = (mlod_deviation){.max = 0.019, .mean = 0.004};
	m.joint_error_max_percent_height = 0.9;
	m.point_error = 0.0195;
	m.grid = 0.001;
	m.subdivide = 2;
	m.has_morph_weights = 1;
	m.morph_weights = (mlod_record_morph_weights){2, 30, 90, 360, 0.02, 0.015, 1};
	int found = 0;
	CHECK_OK(mlod_record_read_motion(doc, 0, &back, &found, &terr));
	CHECK(found == 0);
	CHECK_OK(mlod_record_write_motion(doc, 0, &m, &terr));
	CHECK_OK(mlod_record_read_motion(doc, 0, &back, &found, &terr));
	CHECK(found == 1);
	CHECK(back.level == 2 && back.method == MLOD_MOTION_KEYS && back.has_bound && back.keys == 1000);
	CHECK(back.source_keys == 5000 && back.bytes == 12345 && back.subdivide == 2 && !back.has_vertex_error);
	CHECK_NEAR(back.joint_error.max, 0.019, 0);
	CHECK(back.has_morph_weights && back.morph_weights.channels == 2 && back.morph_weights.copied == 1);
	mlod_record rec;
	CHECK_OK(mlod_record_read(doc, &rec, &terr));
	CHECK(rec.version == MLOD_RECORD_VERSION);
	mlod_record_free(&rec);

	/* A level node's record. */
	mlod_record_mesh_node node;
	CHECK_OK(mlod_gltf_set_extra(doc, MLOD_GLTF_NODE, 1, "mlod",
	                             "{\"mesh_level\":1,\"ratio\":0.5,\"error_percent\":{\"mean\":0.1,\"max\":1},"
	                             "\"skeleton_level\":true}",
	                             &terr));
	CHECK_OK(mlod_record_read_mesh_node(doc, 1, &node, &found, &terr));
	CHECK(found && node.level == 1 && node.skeleton_level);
	CHECK_NEAR(node.error.max, 1.0, 0);
	mlod_character_free(&c);
	mlod_gltf_free(doc);
}

/* Version 3 (what mlod-pack -x writes): the measures a pack does not
 * store may be missing, the pack errors are read, a full clip may be a
 * pack's motion level 0; in a version 2 record the same keys are still
 * required. */
static mlod_result read_scene(mlod_gltf *doc, const char *text, mlod_error *err);

TEST(pack_records_version3)
{
	mlod_gltf *doc = NULL;
	mlod_character c = {0};
	mlod_error e;
	int found = 0;
	CHECK(load("samples/tubeman.glb", &doc, &c) == 0);
	/* Written by the writers with the missing_* flags: the keys left out. */
	mlod_record_motion_level m = {0}, back;
	m.level = 1;
	m.missing_method = m.missing_keys = m.missing_joint_error = m.missing_point_error = 1;
	m.has_pack_error = 1;
	m.pack_error = 0.0443900004;
	CHECK_OK(mlod_record_write_motion(doc, 0, &m, &terr));
	char *text = NULL;
	CHECK_OK(mlod_gltf_get_extra(doc, MLOD_GLTF_ANIMATION, 0, "mlod", &text, &terr));
	CHECK_MSG(text && strcmp(text, "{\"motion_level\":1,\"pack_error\":0.0443900004,\"source_animation\":0}") == 0,
	          "%s", text ? text : "(none)");
	mlod_free(text);
	CHECK_OK(mlod_record_read_motion(doc, 0, &back, &found, &terr));
	CHECK(found && back.level == 1 && back.missing_method && back.missing_keys && back.missing_joint_error &&
	      back.missing_point_error && back.has_pack_error && back.pack_error == 0.0443900004);
	/* The same in a version 2 record is refused, naming the first key. */
	CHECK_OK(mlod_gltf_set_extra(doc, MLOD_GLTF_SCENE, -1, "mlod", "{\"version\":2}", &terr));
	CHECK(mlod_record_read_motion(doc, 0, &back, &found, &e) == MLOD_ERR_PARSE);
	CHECK_MSG(strstr(e.message, "animation 0: extras.mlod.threshold: missing"), "%s", e.message);
	/* A version 2 record with every key reads as before (no flag set). */
	CHECK_OK(mlod_gltf_set_extra(doc, MLOD_GLTF_ANIMATION, 0, "mlod",
	                             "{\"motion_level\":1,\"source_animation\":0,\"method\":\"frames\",\"threshold\":0.5,"
	                             "\"keys\":10,\"source_keys\":20,\"bytes\":40,\"joint_error\":{\"max\":0.1,\"mean\":0.05},"
	                             "\"point_error\":0.1}",
	                             &terr));
	CHECK_OK(mlod_record_read_motion(doc, 0, &back, &found, &terr));
	CHECK(found && !back.missing_method && !back.missing_keys && !back.missing_joint_error && !back.missing_point_error &&
	      !back.has_pack_error && back.keys == 10 && back.joint_error.max == 0.1);

	/* A level node: ratio and error_percent may be missing in version 3. */
	CHECK_OK(mlod_gltf_set_extra(doc, MLOD_GLTF_SCENE, -1, "mlod", "{\"version\":3}", &terr));
	mlod_record_mesh_node n = {0}, nb;
	n.level = 2;
	n.missing_ratio = n.missing_error = 1;
	n.has_pack_error = 1;
	n.pack_error = 0.174;
	CHECK_OK(mlod_record_write_mesh_node(doc, 1, &n, &terr));
	CHECK_OK(mlod_record_read_mesh_node(doc, 1, &nb, &found, &terr));
	CHECK(found && nb.level == 2 && nb.missing_ratio && nb.missing_error && nb.has_pack_error && nb.pack_error == 0.174);
	CHECK_OK(mlod_gltf_set_extra(doc, MLOD_GLTF_SCENE, -1, "mlod", "{\"version\":2}", &terr));
	CHECK(mlod_record_read_mesh_node(doc, 1, &nb, &found, &e) == MLOD_ERR_PARSE);
	CHECK_MSG(strstr(e.message, "node 1: extras.mlod.ratio: missing"), "%s", e.message);

	/* Motion level 0. */
	double pe = -1.0;
	CHECK_OK(mlod_record_read_motion0(doc, 0, &pe, &found, &terr));
	CHECK(!found && pe == 0.0);
	CHECK_OK(mlod_record_write_motion0(doc, 0, 0.0111500002, &terr));
	CHECK_OK(mlod_record_read_motion0(doc, 0, &pe, &found, &terr));
	CHECK(found && pe == 0.0111500002);
	CHECK_OK(mlod_gltf_set_extra(doc, MLOD_GLTF_ANIMATION, 0, "mlod", "{\"motion_level0\":{\"pack_error\":-1}}", &terr));
	CHECK(mlod_record_read_motion0(doc, 0, &pe, &found, &e) == MLOD_ERR_PARSE);
	CHECK_MSG(strstr(e.message, "animation 0: extras.mlod.motion_level0.pack_error: negative"), "%s", e.message);

	/* The scene: skeleton and mesh levels with only what a pack stores. */
	CHECK(read_scene(doc,
	                 "{\"version\":3,\"skeleton_levels\":[{\"level\":1,\"joints\":1,\"kept\":[0],\"skins\":[0],"
	                 "\"remap\":{},\"pack_error\":0.5}],\"mesh_levels\":[{\"level\":1,\"triangles\":1,\"vertices\":3,"
	                 "\"pack_error\":0.25}]}",
	                 &e) == MLOD_OK);
	mlod_record rec;
	CHECK_OK(mlod_record_read(doc, &rec, &terr));
	CHECK(rec.version == 3 && rec.skel_level_count == 1 && rec.skel_levels[0].missing_threshold &&
	      rec.skel_levels[0].missing_joint_error && rec.skel_levels[0].has_pack_error &&
	      rec.skel_levels[0].pack_error == 0.5);
	CHECK(rec.mesh_level_count == 1 && rec.mesh_levels[0].missing_ratio && rec.mesh_levels[0].missing_error &&
	      rec.mesh_levels[0].has_pack_error && rec.mesh_levels[0].pack_error == 0.25 &&
	      rec.mesh_levels[0].coverage == 0.0);
	/* Written back: the same keys, nothing invented. */
	CHECK_OK(mlod_record_write_mesh_levels(doc, rec.mesh_levels, 1, &terr));
	CHECK_OK(mlod_gltf_get_extra(doc, MLOD_GLTF_SCENE, -1, "mlod", &text, &terr));
	CHECK_MSG(text && strstr(text, "\"mesh_levels\":[{\"level\":1,\"pack_error\":0.25,\"triangles\":1,\"vertices\":3}]"),
	          "%s", text ? text : "(none)");
	mlod_free(text);
	mlod_record_free(&rec);
	mlod_character_free(&c);
	mlod_gltf_free(doc);
}

/* Sets the scene's record to text and reads it: the result, and the
 * message in err. */
static mlod_result read_scene(mlod_gltf *doc, const char *text, mlod_error *err)
{
	mlod_record rec;
	memset(err, 0, sizeof *err);
	if (mlod_gltf_set_extra(doc, MLOD_GLTF_SCENE, -1, "mlod", text, err) != MLOD_OK)
		return MLOD_ERR_INVALID_ARG;
	mlod_result r = mlod_record_read(doc, &rec, err);
	if (r == MLOD_OK)
		mlod_record_free(&rec);
	return r;
}

TEST(old_new_and_malformed)
{
	mlod_gltf *doc = NULL;
	mlod_character c = {0};
	mlod_error e;
	CHECK(load("samples/tubeman.glb", &doc, &c) == 0);
	/* Without a version: what mlod wrote before it had one (version 1). */
	CHECK(read_scene(doc,
	                 "{\"skeleton_levels\":[{\"level\":1,\"threshold\":0.5,\"joints\":3,\"kept\":[0,1,2],"
	                 "\"remap\":{\"3\":2},\"skins\":[0],\"joint_error\":{\"max\":0.1,\"mean\":0.01}}]}",
	                 &e) == MLOD_OK);
	CHECK(read_scene(doc, "{\"version\":1}", &e) == MLOD_OK);
	CHECK(read_scene(doc, "{\"version\":2}", &e) == MLOD_OK);
	CHECK(read_scene(doc, "{\"version\":3}", &e) == MLOD_OK);
	CHECK(read_scene(doc, "{\"version\":4}", &e) == MLOD_OK);
	CHECK(read_scene(doc, "{\"version\":5}", &e) == MLOD_ERR_UNSUPPORTED);
	CHECK_MSG(strstr(e.message, "version 5") && strstr(e.message, "up to version 4"), "%s", e.message);
	static const struct {
		const char *text, *says;
	} bad[] = {
		{"[1]", "the scene's extras.mlod: not an object"},
		{"{\"version\":\"1\"}", "extras.mlod.version: not a number"},
		{"{\"version\":1.5}", "extras.mlod.version: not a whole number"},
		{"{\"skeleton_levels\":{}}", "extras.mlod.skeleton_levels: not an array"},
		{"{\"skeleton_levels\":[{\"level\":1}]}", "skeleton_levels[0].threshold: missing"},
		/* Version 3: threshold, joint_error, ratio and error_percent may be
		 * missing; the rest is required as before. */
		{"{\"version\":3,\"skeleton_levels\":[{\"level\":1}]}", "skeleton_levels[0].joints: missing"},
		{"{\"version\":3,\"skeleton_levels\":[{\"level\":1,\"joints\":1,\"kept\":[0],\"skins\":[0],\"remap\":{},"
		 "\"pack_error\":\"1\"}]}",
		 "skeleton_levels[0].pack_error: not a number"},
		{"{\"version\":3,\"mesh_levels\":[{\"level\":1,\"triangles\":1}]}", "mesh_levels[0].vertices: missing"},
		{"{\"version\":3,\"mesh_levels\":[{\"level\":1,\"triangles\":1,\"vertices\":3,\"error_percent\":{}}]}",
		 "mesh_levels[0].error_percent.max: missing"},
		{"{\"version\":2,\"mesh_levels\":[{\"level\":1,\"triangles\":1,\"vertices\":3}]}",
		 "mesh_levels[0].ratio: missing"},
		{"{\"skeleton_levels\":[{\"level\":1,\"threshold\":0,\"joints\":1,\"kept\":[99999],\"skins\":[0],"
		 "\"joint_error\":{\"max\":0,\"mean\":0},\"remap\":{}}]}",
		 "skeleton_levels[0].kept: holds something other than an index in range"},
		{"{\"skeleton_levels\":[{\"level\":1,\"threshold\":0,\"joints\":1,\"kept\":[0],\"skins\":[0],"
		 "\"joint_error\":{\"max\":0,\"mean\":0},\"remap\":{\"x\":1}}]}",
		 "skeleton_levels[0].remap: holds something other than node -> node"},
		{"{\"skeleton_levels\":[{\"level\":1,\"threshold\":0,\"joints\":1,\"kept\":[0],\"skins\":[5],"
		 "\"joint_error\":{\"max\":0,\"mean\":0},\"remap\":{}}]}",
		 "skeleton_levels[0].skins: holds something"},
		{"{\"mesh_levels\":[{\"level\":1,\"ratio\":0.5,\"triangles\":-1,\"vertices\":3,\"error_percent\":{}}]}",
		 "mesh_levels[0].triangles: not a whole number in range"},
		{"{\"mesh_levels\":[{\"level\":1,\"ratio\":0.5,\"triangles\":1,\"vertices\":3,\"error_percent\":{}}]}",
		 "mesh_levels[0].error_percent.max: missing"},
		/* Numbers past the range of long (found by make fuzz-io: converting
		 * them was undefined behaviour before the range check). */
		/* Version 4: the source is "bvh" or absent. */
		{"{\"version\":4,\"source\":\"fbx\"}", "the scene's extras.mlod.source: not \"bvh\""},
		{"{\"version\":4,\"source\":1}", "the scene's extras.mlod.source: not \"bvh\""},
		{"{\"version\":1e88}", "extras.mlod.version: not a whole number in range"},
		{"{\"version\":-1e300}", "extras.mlod.version: not a whole number in range"},
		{"{\"skeleton_levels\":[{\"level\":1,\"threshold\":0,\"joints\":1,\"kept\":[1e88],\"skins\":[0],"
		 "\"joint_error\":{\"max\":0,\"mean\":0},\"remap\":{}}]}",
		 "skeleton_levels[0].kept: holds something other than an index in range"},
		{"{\"skeleton_levels\":[{\"level\":1,\"threshold\":0,\"joints\":1,\"kept\":[0],\"skins\":[0],"
		 "\"joint_error\":{\"max\":0,\"mean\":0},\"remap\":{\"1\":-1e88}}]}",
		 "skeleton_levels[0].remap: holds something other than node -> node"},
	};
	for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
		mlod_result r = read_scene(doc, bad[i].text, &e);
		CHECK_MSG(r == MLOD_ERR_PARSE, "%s: result %d", bad[i].text, (int)r);
		CHECK_MSG(strstr(e.message, bad[i].says), "%s: says \"%s\"", bad[i].text, e.message);
	}
	/* A writer does not add to a record that is not an object. */
	CHECK_OK(mlod_gltf_set_extra(doc, MLOD_GLTF_SCENE, -1, "mlod", "\"text\"", &terr));
	mlod_record_mesh_level m = {.level = 1, .ratio = 0.5, .triangles = 1, .vertices = 3};
	CHECK(mlod_record_write_mesh_levels(doc, &m, 1, &e) == MLOD_ERR_UNSUPPORTED);
	CHECK_MSG(strstr(e.message, "not a JSON object"), "%s", e.message);

	/* Labels: a malformed one is an error naming its node. */
	CHECK_OK(mlod_gltf_set_extra(doc, MLOD_GLTF_SCENE, -1, "mlod", "{}", &terr));
	mlod_joint_info *info = calloc((size_t)c.skeleton.joint_count, sizeof *info);
	int found;
	CHECK_OK(mlod_label_skeleton(&c, NULL, info, &terr));
	CHECK_OK(mlod_record_write_joints(doc, &c, info, &terr));
	int node = c.skeleton.joints[0].node;
	CHECK_OK(mlod_gltf_set_extra(doc, MLOD_GLTF_NODE, node, "mlod", "{\"label\":\"chief\",\"depth\":0,\"energy\":1}",
	                             &terr));
	CHECK(mlod_record_read_joints(doc, &c, info, &found, &e) == MLOD_ERR_PARSE);
	char want[64];
	snprintf(want, sizeof want, "node %d: extras.mlod.label: not a joint label", node);
	CHECK_MSG(strstr(e.message, want), "%s", e.message);
	CHECK_OK(mlod_gltf_set_extra(doc, MLOD_GLTF_NODE, node, "mlod", "{\"label\":\"root\",\"depth\":0,\"energy\":-1}",
	                             &terr));
	CHECK(mlod_record_read_joints(doc, &c, info, &found, &e) == MLOD_ERR_PARSE);
	CHECK_MSG(strstr(e.message, "energy: negative"), "%s", e.message);
	free(info);
	mlod_character_free(&c);
	mlod_gltf_free(doc);
}

/* Loads bytes through the record (mlod_record_load). */
static mlod_result record_load(const void *data, size_t size, int flags, mlod_gltf **doc, mlod_character *c,
                               mlod_record_input *in, mlod_error *e)
{
	return mlod_record_load(data, size, NULL, flags, doc, c, in, e);
}

/* A BVH's document says it is one (extras.mlod.source, version 4) and
 * keeps its clip's frames (extras.mlod_bvh.frame_time), so that the glb
 * a stage writes of it reads back as the same character under the same
 * rules; motion level animations are left out of the clips the stages
 * take, and kept for the pack. */
TEST(input_source_and_clips)
{
	size_t size;
	void *bvh = test_read_file("samples/cmu_12_01_walk.bvh", &size);
	CHECK(bvh != NULL);
	if (!bvh)
		return;
	mlod_gltf *doc = NULL, *back = NULL;
	mlod_character c = {0}, g = {0}, plain = {0};
	mlod_record_input in, gin;
	mlod_record rec;
	mlod_error e;
	CHECK_OK(record_load(bvh, size, MLOD_RECORD_INPUT_CLIPS, &doc, &c, &in, &terr));
	CHECK(in.format == MLOD_FORMAT_BVH && in.from_bvh && in.level_clips == 0);
	CHECK_OK(mlod_record_read(doc, &rec, &terr));
	CHECK(rec.version == MLOD_RECORD_VERSION && rec.source == MLOD_FORMAT_BVH && mlod_record_from_bvh(&rec, 0));
	mlod_record_free(&rec);
	/* Without a document: the same character and rule. */
	CHECK_OK(record_load(bvh, size, 0, NULL, &plain, &in, &terr));
	CHECK(in.from_bvh && plain.clip_count == 1 && plain.clips[0].frame_time == c.clips[0].frame_time);
	mlod_character_free(&plain);
	/* The glb of it: a glb, from a BVH, with the BVH's frames. */
	void *glb = NULL;
	size_t glb_size = 0;
	CHECK_OK(mlod_gltf_write(doc, 1, &glb, &glb_size, &terr));
	CHECK_OK(record_load(glb, glb_size, MLOD_RECORD_INPUT_CLIPS, &back, &g, &gin, &terr));
	CHECK(gin.format == MLOD_FORMAT_GLB && gin.from_bvh);
	CHECK(c.clip_count == 1 && g.clip_count == 1);
	if (c.clip_count == 1 && g.clip_count == 1) {
		const mlod_clip *a = &c.clips[0], *b = &g.clips[0];
		CHECK(a->frame_time > 0.0f && b->frame_time == a->frame_time && b->frame_count == a->frame_count);
		CHECK(b->duration == a->duration && b->channel_count == a->channel_count);
		for (int i = 0; i < a->channel_count && i < b->channel_count; i++)
			CHECK(a->channels[i].key_count == b->channels[i].key_count &&
			      memcmp(a->channels[i].times, b->channels[i].times,
			             sizeof(float) * (size_t)a->channels[i].key_count) == 0);
	}
	mlod_character_free(&g);
	mlod_gltf_free(back);
	/* A frame time the keys do not follow (an edited glb) is not taken. */
	CHECK_OK(mlod_gltf_set_extra(doc, MLOD_GLTF_ANIMATION, 0, "mlod_bvh", "{\"frame_time\":0.5}", &terr));
	mlod_free(glb);
	CHECK_OK(mlod_gltf_write(doc, 1, &glb, &glb_size, &terr));
	CHECK_OK(record_load(glb, glb_size, 0, NULL, &g, NULL, &terr));
	CHECK(g.clip_count == 1 && g.clips[0].frame_time == 0.0f && g.clips[0].frame_count == 0);
	mlod_character_free(&g);
	mlod_free(glb);
	mlod_gltf_free(doc);
	mlod_character_free(&c);
	free(bvh);

	/* The tubeman: glTF, and a motion level beside its clip. */
	void *tube = test_read_file("samples/tubeman.glb", &size);
	CHECK(tube != NULL);
	if (!tube)
		return;
	CHECK_OK(record_load(tube, size, MLOD_RECORD_INPUT_CLIPS, &doc, &c, &in, &terr));
	CHECK(in.format == MLOD_FORMAT_GLB && !in.from_bvh && c.clip_count == 1);
	int anim = -1;
	CHECK_OK(mlod_gltf_add_animation(doc, &c.skeleton, &c.clips[0], &anim, &terr));
	mlod_record_motion_level ml = {.level = 1, .source_animation = 0, .method = MLOD_MOTION_KEYS, .threshold = 1,
	                               .keys = 1, .source_keys = 2, .bytes = 4, .point_error = 0.1};
	CHECK_OK(mlod_record_write_motion(doc, anim, &ml, &terr));
	CHECK_OK(mlod_gltf_write(doc, 1, &glb, &glb_size, &terr));
	CHECK_OK(record_load(glb, glb_size, MLOD_RECORD_INPUT_CLIPS, NULL, &g, &gin, &terr));
	CHECK(g.clip_count == 1 && gin.level_clips == 1 && g.clips[0].gltf_index == 0);
	mlod_character_free(&g);
	CHECK_OK(record_load(glb, glb_size, 0, NULL, &g, &gin, &terr));
	CHECK(g.clip_count == 2 && gin.level_clips == 0 && g.clips[1].gltf_index == anim);
	mlod_character_free(&g);
	mlod_free(glb);
	/* A record this mlod cannot read is refused at load. */
	CHECK_OK(mlod_gltf_set_extra(doc, MLOD_GLTF_SCENE, -1, "mlod", "{\"version\":4,\"source\":\"fbx\"}", &terr));
	CHECK_OK(mlod_gltf_write(doc, 1, &glb, &glb_size, &terr));
	CHECK(record_load(glb, glb_size, 0, NULL, &g, NULL, &e) == MLOD_ERR_PARSE);
	CHECK_MSG(strstr(e.message, "the scene's extras.mlod.source: not \"bvh\""), "%s", e.message);
	CHECK(g.clip_count == 0 && g.clips == NULL);
	mlod_free(glb);
	mlod_gltf_free(doc);
	mlod_character_free(&c);
	free(tube);
}

int main(void)
{
	RUN(json_strict);
	RUN(json_depth_and_roundtrip);
	RUN(json_hostile);
	RUN(stages_merge_and_version);
	RUN(motion_and_node_records);
	RUN(old_new_and_malformed);
	RUN(pack_records_version3);
	RUN(input_source_and_clips);
	TEST_EXIT();
}
