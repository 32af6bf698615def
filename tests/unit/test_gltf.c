/*
 * test_gltf.c: the glTF shim (lib/io/gltf_*.cpp): reading the sample, lossless
 * round trips, extras, the add_* calls, character <-> glTF, and hostile
 * input (empty, truncated, garbage, bad references, cycles, mutations).
 * With MLOD_SHARED_DATA set, every .glb there is round-tripped too.
 */
#define _POSIX_C_SOURCE 200809L /* opendir */
#include <dirent.h>

#include "test.h"

#define ROBOT "samples/RobotExpressive.glb"

/* ---------------------------------------------------------------- */
/* Helpers                                                           */
/* ---------------------------------------------------------------- */

/* The document as .gltf text (NUL-terminated), or NULL. */
static char *gltf_text(const mlod_gltf *doc)
{
	void *data = NULL;
	size_t size = 0;
	if (mlod_gltf_write(doc, 0, &data, &size, &terr) != MLOD_OK)
		return NULL;
	char *text = malloc(size + 1);
	memcpy(text, data, size);
	text[size] = 0;
	mlod_free(data);
	return text;
}

/* Writes doc as glb and reads it back. */
static mlod_result reread(const mlod_gltf *doc, mlod_gltf **out)
{
	void *data = NULL;
	size_t size = 0;
	mlod_result r = mlod_gltf_write(doc, 1, &data, &size, &terr);
	if (r == MLOD_OK)
		r = mlod_gltf_read(data, size, NULL, out, &terr);
	mlod_free(data);
	return r;
}

/* Reads a JSON text given in the test. */
static mlod_result read_text(const char *text, mlod_gltf **doc, mlod_error *err)
{
	return mlod_gltf_read(text, strlen(text), NULL, doc, err);
}

static char diff_msg[256];

static int differs(const float *a, const float *b, long n, float tol)
{
	if (!a || !b)
		return a != b;
	for (long i = 0; i < n; i++)
		if (!(fabsf(a[i] - b[i]) <= tol))
			return 1;
	return 0;
}

#define DIFF(cond, ...)                                                        \
	do {                                                                   \
		if (cond) {                                                    \
			snprintf(diff_msg, sizeof diff_msg, __VA_ARGS__);      \
			return diff_msg;                                       \
		}                                                              \
	} while (0)

static const char *primitive_diff(const mlod_primitive *a, const mlod_primitive *b, float tol)
{
	long n = a->vertex_count;
	DIFF(a->vertex_count != b->vertex_count, "vertex count %d != %d", a->vertex_count, b->vertex_count);
	DIFF(differs(a->positions, b->positions, 3 * n, tol), "positions differ");
	DIFF(differs(a->normals, b->normals, 3 * n, tol), "normals differ");
	DIFF(differs(a->tangents, b->tangents, 4 * n, tol), "tangents differ");
	DIFF(a->uv_set_count != b->uv_set_count || a->color_set_count != b->color_set_count ||
	     a->weight_set_count != b->weight_set_count, "attribute set counts differ");
	for (int s = 0; s < a->uv_set_count; s++)
		DIFF(differs(a->uvs[s], b->uvs[s], 2 * n, tol), "uv set %d differs", s);
	for (int s = 0; s < a->color_set_count; s++)
		DIFF(differs(a->colors[s], b->colors[s], 4 * n, tol), "color set %d differs", s);
	for (int s = 0; s < a->weight_set_count; s++) {
		DIFF(memcmp(a->joints[s], b->joints[s], 4 * (size_t)n * sizeof(uint16_t)) != 0, "joint set %d differs", s);
		DIFF(differs(a->weights[s], b->weights[s], 4 * n, tol), "weight set %d differs", s);
	}
	DIFF(a->index_count != b->index_count || (a->index_count &&
	     memcmp(a->indices, b->indices, (size_t)a->index_count * sizeof(uint32_t)) != 0), "indices differ");
	DIFF(a->mode != b->mode, "mode %d != %d", a->mode, b->mode);
	DIFF(a->target_count != b->target_count, "morph target counts differ");
	for (int t = 0; t < a->target_count; t++)
		DIFF(differs(a->targets[t].positions, b->targets[t].positions, 3 * n, tol) ||
		     differs(a->targets[t].normals, b->targets[t].normals, 3 * n, tol) ||
		     differs(a->targets[t].tangents, b->targets[t].tangents, 3 * n, tol), "morph target %d differs", t);
	return NULL;
}

/* The first difference between two characters, or NULL. With same_doc,
 * glTF node and object indices must match too. */
static const char *character_diff(const mlod_character *a, const mlod_character *b, int same_doc, float tol)
{
	const mlod_skeleton *sa = &a->skeleton, *sb = &b->skeleton;
	DIFF(sa->joint_count != sb->joint_count, "joint count %d != %d", sa->joint_count, sb->joint_count);
	for (int i = 0; i < sa->joint_count; i++) {
		const mlod_joint *x = &sa->joints[i], *y = &sb->joints[i];
		DIFF(strcmp(x->name, y->name) != 0, "joint %d: name %s != %s", i, x->name, y->name);
		DIFF(x->parent != y->parent, "joint %d: parent %d != %d", i, x->parent, y->parent);
		DIFF(differs(&x->rest.t.x, &y->rest.t.x, 10, tol), "joint %d: rest differs", i);
		DIFF(differs(x->base.m, y->base.m, 16, tol), "joint %d: base differs", i);
		DIFF(x->has_end_site != y->has_end_site || differs(&x->end_site.x, &y->end_site.x, 3, tol),
		     "joint %d: end site differs", i);
		DIFF(same_doc && x->node != y->node, "joint %d: node %d != %d", i, x->node, y->node);
	}
	DIFF(sa->skin_count != sb->skin_count, "skin count %d != %d", sa->skin_count, sb->skin_count);
	for (int k = 0; k < sa->skin_count; k++) {
		const mlod_skin *x = &sa->skins[k], *y = &sb->skins[k];
		DIFF(strcmp(x->name, y->name) != 0 || x->joint_count != y->joint_count, "skin %d differs", k);
		DIFF(memcmp(x->joints, y->joints, (size_t)x->joint_count * sizeof(int)) != 0, "skin %d: joints differ", k);
		DIFF(differs(x->inverse_bind[0].m, y->inverse_bind[0].m, 16L * x->joint_count, tol), "skin %d: matrices differ", k);
	}
	DIFF(a->mesh_count != b->mesh_count, "mesh count %d != %d", a->mesh_count, b->mesh_count);
	for (int m = 0; m < a->mesh_count; m++) {
		DIFF(strcmp(a->meshes[m].name, b->meshes[m].name) != 0, "mesh %d: name differs", m);
		DIFF(a->meshes[m].primitive_count != b->meshes[m].primitive_count, "mesh %d: primitive count differs", m);
		for (int p = 0; p < a->meshes[m].primitive_count; p++) {
			const char *d = primitive_diff(&a->meshes[m].primitives[p], &b->meshes[m].primitives[p], tol);
			DIFF(d != NULL, "mesh %d primitive %d: %s", m, p, d);
			DIFF(same_doc && a->meshes[m].primitives[p].material != b->meshes[m].primitives[p].material,
			     "mesh %d primitive %d: material differs", m, p);
		}
	}
	DIFF(a->instance_count != b->instance_count, "instance count %d != %d", a->instance_count, b->instance_count);
	for (int i = 0; i < a->instance_count; i++) {
		const mlod_instance *x = &a->instances[i], *y = &b->instances[i];
		DIFF(x->mesh != y->mesh || x->skin != y->skin || x->joint != y->joint, "instance %d differs", i);
		DIFF(differs(x->offset.m, y->offset.m, 16, tol), "instance %d: offset differs", i);
	}
	DIFF(a->clip_count != b->clip_count, "clip count %d != %d", a->clip_count, b->clip_count);
	for (int k = 0; k < a->clip_count; k++) {
		const mlod_clip *x = &a->clips[k], *y = &b->clips[k];
		DIFF(strcmp(x->name, y->name) != 0 || x->channel_count != y->channel_count, "clip %d differs", k);
		DIFF(fabsf(x->duration - y->duration) > tol, "clip %d: duration %g != %g", k, x->duration, y->duration);
		for (int c = 0; c < x->channel_count; c++) {
			const mlod_channel *p = &x->channels[c], *q = &y->channels[c];
			long per = (p->path == MLOD_PATH_ROTATION ? 4 : 3) * (p->interp == MLOD_INTERP_CUBICSPLINE ? 3 : 1);
			DIFF(p->joint != q->joint || p->path != q->path || p->interp != q->interp || p->key_count != q->key_count,
			     "clip %d channel %d differs", k, c);
			DIFF(differs(p->times, q->times, p->key_count, tol) || differs(p->values, q->values, per * p->key_count, tol),
			     "clip %d channel %d: keys differ", k, c);
		}
	}
	return NULL;
}

/* Round-trips the glb at path: read, write glb, read, and compares the two
 * documents as .gltf text and as characters. */
static const char *roundtrip_file(const char *path)
{
	static char msg[600];
	size_t size;
	void *bytes = test_read_file(path, &size);
	mlod_gltf *a = NULL, *b = NULL;
	mlod_character ca = {0}, cb = {0};
	char *ta = NULL, *tb = NULL;
	const char *d = NULL;
	msg[0] = 0;
	if (!bytes)
		snprintf(msg, sizeof msg, "%s: cannot read", path);
	else if (mlod_gltf_read(bytes, size, NULL, &a, &terr) || reread(a, &b))
		snprintf(msg, sizeof msg, "%s: %s", path, terr.message);
	else if (!(ta = gltf_text(a)) || !(tb = gltf_text(b)))
		snprintf(msg, sizeof msg, "%s: write failed: %s", path, terr.message);
	else if (strcmp(ta, tb) != 0)
		snprintf(msg, sizeof msg, "%s: the document changed in the round trip", path);
	else if (mlod_gltf_to_character(a, &ca, &terr) || mlod_gltf_to_character(b, &cb, &terr) ||
	         mlod_character_validate(&ca, &terr))
		snprintf(msg, sizeof msg, "%s: character: %s", path, terr.message);
	else if ((d = character_diff(&ca, &cb, 1, 0.0f)) != NULL)
		snprintf(msg, sizeof msg, "%s: the character changed: %s", path, d);
	free(bytes);
	free(ta);
	free(tb);
	mlod_character_free(&ca);
	mlod_character_free(&cb);
	mlod_gltf_free(a);
	mlod_gltf_free(b);
	return msg[0] ? msg : NULL;
}

static mlod_gltf *read_robot(void)
{
	size_t size;
	void *bytes = test_read_file(ROBOT, &size);
	mlod_gltf *doc = NULL;
	if (bytes)
		mlod_gltf_read(bytes, size, NULL, &doc, &terr);
	free(bytes);
	return doc;
}

/* ---------------------------------------------------------------- */
/* The sample                                                        */
/* ---------------------------------------------------------------- */

TEST(read_robot)
{
	mlod_gltf *doc = read_robot();
	CHECK_MSG(doc != NULL, "%s", terr.message);
	CHECK(mlod_gltf_count(doc, MLOD_GLTF_SKIN) == 4);
	CHECK(mlod_gltf_count(doc, MLOD_GLTF_MESH) == 19);
	CHECK(mlod_gltf_count(doc, MLOD_GLTF_ANIMATION) == 14);
	CHECK(mlod_gltf_count(doc, MLOD_GLTF_SCENE) == 1);
	CHECK(mlod_gltf_count(doc, MLOD_GLTF_ASSET) == 1);

	mlod_character c = {0};
	CHECK_OK(mlod_gltf_to_character(doc, &c, &terr));
	mlod_gltf_free(doc);
	mlod_result valid = mlod_character_validate(&c, &terr);
	int joints = c.skeleton.joint_count, skins = c.skeleton.skin_count, clips = c.clip_count;
	int meshes = c.mesh_count, instances = c.instance_count, rigid = 0, skinned = 0, dance = -1;
	for (int i = 0; i < c.instance_count; i++) {
		rigid += c.instances[i].skin < 0 && c.instances[i].joint >= 0;
		skinned += c.instances[i].skin >= 0;
	}
	for (int k = 0; k < c.clip_count; k++)
		if (strcmp(c.clips[k].name, "Dance") == 0)
			dance = k;
	int ordered = 1;
	for (int i = 0; i < joints; i++)
		ordered &= c.skeleton.joints[i].parent < i;
	float duration = dance >= 0 ? c.clips[dance].duration : 0;
	int channels = dance >= 0 ? c.clips[dance].channel_count : 0;
	mlod_character_free(&c);
	CHECK_MSG(valid == MLOD_OK, "%s", terr.message);
	CHECK(joints == 43);
	CHECK(skins == 4);
	CHECK(clips == 14);
	CHECK(meshes == 19);
	CHECK(instances == 19);
	CHECK(skinned == 4);
	CHECK(rigid == 15); /* the head, hands and other parts hang under bones */
	CHECK(ordered);
	CHECK(dance >= 0 && channels > 0 && duration > 1.0f);
}

TEST(roundtrip_robot)
{
	const char *d = roundtrip_file(ROBOT);
	CHECK_MSG(d == NULL, "%s", d);
}

static int count_of(const char *text, const char *what)
{
	int n = 0;
	for (const char *p = text; (p = strstr(p, what)) != NULL; p++)
		n++;
	return n;
}

/* What tinygltf 2.7 changes on its own is undone: an empty object in
 * extras comes back, buffer view targets it adds (the sample has 74 of
 * 520) go. */
TEST(write_is_faithful)
{
	mlod_gltf *doc = read_robot();
	CHECK_MSG(doc != NULL, "%s", terr.message);
	char *text = gltf_text(doc);
	char *variant = NULL;
	mlod_result r = mlod_gltf_get_extra(doc, MLOD_GLTF_NODE, 0, "variantData", &variant, &terr);
	mlod_gltf_free(doc);
	CHECK(text != NULL);
	int variants = count_of(text, "\"variantData\": {}"), targets = count_of(text, "\"target\": 349");
	free(text);
	CHECK(r == MLOD_OK && variant && strcmp(variant, "{}") == 0);
	mlod_free(variant);
	CHECK(variants == 19);
	CHECK(targets == 74);
}

/* .gltf with embedded buffers reads back to the same document. */
TEST(gltf_text_roundtrip)
{
	mlod_gltf *doc = read_robot(), *again = NULL;
	CHECK_MSG(doc != NULL, "%s", terr.message);
	char *text = gltf_text(doc), *text2 = NULL;
	mlod_gltf_free(doc);
	CHECK(text != NULL);
	mlod_result r = read_text(text, &again, &terr);
	if (r == MLOD_OK)
		text2 = gltf_text(again);
	mlod_gltf_free(again);
	int same = text2 && strcmp(text, text2) == 0;
	free(text);
	free(text2);
	CHECK_MSG(r == MLOD_OK, "%s", terr.message);
	CHECK(same);
}

/* ---------------------------------------------------------------- */
/* Images                                                            */
/* ---------------------------------------------------------------- */

/* Two "images" that are not valid PNGs (so decoding would fail): one in a
 * data: URI, one in a buffer view. Both must come back byte for byte: the
 * first, through a glb, in a buffer view of the BIN chunk (a glb holds no
 * data: URI), and again as the same data: URI in .gltf text. */
static const char images_gltf[] =
	"{\"asset\":{\"version\":\"2.0\"},"
	"\"buffers\":[{\"byteLength\":12,\"uri\":\"data:application/octet-stream;base64,iVBORwABAgMEBQYH\"}],"
	"\"bufferViews\":[{\"buffer\":0,\"byteLength\":12}],"
	"\"images\":[{\"uri\":\"data:image/png;base64,iVBORw0KGgoAAAAAAAAAAA==\"},"
	"{\"bufferView\":0,\"mimeType\":\"image/png\",\"name\":\"in a view\"}],"
	"\"textures\":[{\"source\":0},{\"source\":1}],"
	"\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0}},"
	"\"emissiveTexture\":{\"index\":1}}]}";

TEST(images_kept)
{
	mlod_gltf *doc = NULL, *again = NULL;
	CHECK_OK(read_text(images_gltf, &doc, &terr));
	mlod_result r = reread(doc, &again);
	char *text = gltf_text(doc), *text2 = r == MLOD_OK ? gltf_text(again) : NULL;
	/* the glb's JSON: the first image in a view of its own */
	void *glb = NULL;
	size_t size = 0;
	CHECK_OK(mlod_gltf_write(doc, 1, &glb, &size, &terr));
	const unsigned char *g = glb;
	size_t jl = g && size >= 20 ? (size_t)g[12] | (size_t)g[13] << 8 | (size_t)g[14] << 16 | (size_t)g[15] << 24 : 0;
	char *json = g && size >= 20 ? strndup((const char *)g + 20, jl) : NULL;
	/* the data: URI's 16 bytes, at the view's offset 12 in the BIN chunk */
	static const unsigned char png[16] = {0x89, 'P', 'N', 'G', 0x0d, 0x0a, 0x1a, 0x0a};
	int bytes = g && size >= 20 + jl + 8 + 28 && memcmp(g + 20 + jl + 8 + 12, png, 16) == 0;
	mlod_free(glb);
	mlod_gltf_free(doc);
	mlod_gltf_free(again);
	int same = text && text2 && strstr(text2, "\"bufferView\": 1,\n      \"mimeType\": \"image/png\"") != NULL;
	int uri = text && strstr(text, "\"uri\": \"data:image/png;base64,iVBORw0KGgoAAAAAAAAAAA==\"") != NULL;
	int view = text && strstr(text, "\"bufferView\": 0,\n      \"mimeType\": \"image/png\"") != NULL;
	int in_bin = json && !strstr(json, "data:image") && strstr(json, "{\"bufferView\":1,\"mimeType\":\"image/png\"}");
	CHECK_MSG(in_bin, "the glb's JSON: %s", json ? json : "(none)");
	CHECK(bytes);
	free(json);
	free(text);
	free(text2);
	CHECK_MSG(r == MLOD_OK, "%s", terr.message);
	CHECK(same);
	CHECK(uri);
	CHECK(view);
}

/* ---------------------------------------------------------------- */
/* Extras                                                            */
/* ---------------------------------------------------------------- */

TEST(extras)
{
	mlod_gltf *doc = read_robot(), *again = NULL;
	CHECK_MSG(doc != NULL, "%s", terr.message);
	char *v = NULL;
	CHECK_OK(mlod_gltf_set_extra(doc, MLOD_GLTF_NODE, 0, "mlod", "{\"label\": \"root\", \"energy\": [1, 2.5, null]}", &terr));
	CHECK_OK(mlod_gltf_set_extra(doc, MLOD_GLTF_SCENE, -1, "note", "\"caf\xc3\xa9\"", &terr));
	CHECK_OK(mlod_gltf_set_extra(doc, MLOD_GLTF_ASSET, 0, "n", "12345678901", &terr));
	CHECK(mlod_gltf_set_extra(doc, MLOD_GLTF_NODE, 0, "bad", "{nope", &terr) == MLOD_ERR_INVALID_ARG);
	CHECK(mlod_gltf_set_extra(doc, MLOD_GLTF_NODE, 1000, "k", "1", &terr) == MLOD_ERR_INVALID_ARG);
	CHECK(mlod_gltf_set_extra(doc, MLOD_GLTF_SKIN, -1, "k", "1", &terr) == MLOD_ERR_INVALID_ARG);
	CHECK_OK(reread(doc, &again));
	mlod_gltf_free(doc);

	CHECK_OK(mlod_gltf_get_extra(again, MLOD_GLTF_NODE, 0, "mlod", &v, &terr));
	int label = v && strcmp(v, "{\"energy\":[1,2.5,null],\"label\":\"root\"}") == 0;
	mlod_free(v);
	CHECK_OK(mlod_gltf_get_extra(again, MLOD_GLTF_NODE, 0, "name", &v, &terr)); /* kept from the file */
	int kept = v && strcmp(v, "\"Foot.L\"") == 0;
	mlod_free(v);
	CHECK_OK(mlod_gltf_get_extra(again, MLOD_GLTF_SCENE, 0, "note", &v, &terr));
	int scene = v && strcmp(v, "\"caf\xc3\xa9\"") == 0;
	mlod_free(v);
	CHECK_OK(mlod_gltf_get_extra(again, MLOD_GLTF_ASSET, 0, "n", &v, &terr));
	int big = v && strcmp(v, "12345678901") == 0;
	mlod_free(v);
	CHECK_OK(mlod_gltf_get_extra(again, MLOD_GLTF_NODE, 1, "absent", &v, &terr));
	int absent = v == NULL;
	mlod_gltf_free(again);
	CHECK(label);
	CHECK(kept);
	CHECK(scene);
	CHECK(big);
	CHECK(absent);
}

/* The pack's DOC edits (mlod_gltf_remove_extra, _drop_tail,
 * _drop/_set_inverse_binds, _drop/_fill_node_trs): each undone gives the
 * document back. */
TEST(pack_doc_edits)
{
	mlod_gltf *doc = read_robot(), *again = NULL;
	CHECK_MSG(doc != NULL, "%s", terr.message);
	char *before = gltf_text(doc), *v = NULL;
	mlod_character c = {0}, c2 = {0};
	CHECK_OK(mlod_gltf_to_character(doc, &c, &terr));
	/* extras: "end_site" stays alone, the rest of "mlod" goes */
	CHECK_OK(mlod_gltf_set_extra(doc, MLOD_GLTF_NODE, 0, "mlod", "{\"end_site\": true, \"label\": \"x\"}", &terr));
	CHECK_OK(mlod_gltf_remove_extra(doc, MLOD_GLTF_NODE, 0, "mlod", "end_site", &terr));
	CHECK_OK(mlod_gltf_get_extra(doc, MLOD_GLTF_NODE, 0, "mlod", &v, &terr));
	CHECK(v && strcmp(v, "{\"end_site\":true}") == 0);
	mlod_free(v);
	CHECK_OK(mlod_gltf_remove_extra(doc, MLOD_GLTF_NODE, 0, "mlod", NULL, &terr));
	CHECK_OK(mlod_gltf_get_extra(doc, MLOD_GLTF_NODE, 0, "mlod", &v, &terr));
	CHECK(v == NULL);
	/* a tail: refused while a kept node refers to it, else dropped */
	int nodes = mlod_gltf_count(doc, MLOD_GLTF_NODE), skins = mlod_gltf_count(doc, MLOD_GLTF_SKIN),
	    meshes = mlod_gltf_count(doc, MLOD_GLTF_MESH), added = -1;
	CHECK(mlod_gltf_drop_tail(doc, 1, skins, meshes, &terr) == MLOD_ERR_UNSUPPORTED);
	CHECK(mlod_gltf_count(doc, MLOD_GLTF_NODE) == nodes);
	CHECK(mlod_gltf_drop_tail(doc, nodes, skins, meshes - 1, &terr) == MLOD_ERR_UNSUPPORTED);
	CHECK_OK(mlod_gltf_add_node(doc, "level", MLOD_GLTF_DETACHED, -1, -1, NULL, &added, &terr));
	CHECK(added == nodes && mlod_gltf_count(doc, MLOD_GLTF_NODE) == nodes + 1);
	CHECK_OK(mlod_gltf_drop_tail(doc, nodes, skins, meshes, &terr));
	CHECK(mlod_gltf_count(doc, MLOD_GLTF_NODE) == nodes);
	/* inverse binds: gone (identities), back (the same matrices) */
	CHECK_OK(mlod_gltf_drop_inverse_binds(doc, 0, &terr));
	CHECK_OK(reread(doc, &again));
	CHECK_OK(mlod_gltf_to_character(again, &c2, &terr));
	mlod_mat4 id = mlod_mat4_identity();
	CHECK(memcmp(&c2.skeleton.skins[0].inverse_bind[0], &id, sizeof id) == 0);
	CHECK(memcmp(&c.skeleton.skins[0].inverse_bind[0], &id, sizeof id) != 0);
	mlod_character_free(&c2);
	mlod_gltf_free(again);
	again = NULL;
	CHECK_OK(mlod_gltf_set_inverse_binds(doc, 0, c.skeleton.skins[0].inverse_bind, c.skeleton.skins[0].joint_count,
	                                     &terr));
	CHECK(mlod_gltf_set_inverse_binds(doc, 0, c.skeleton.skins[0].inverse_bind, 1, &terr) == MLOD_ERR_INVALID_ARG);
	CHECK_OK(reread(doc, &again));
	CHECK_OK(mlod_gltf_to_character(again, &c2, &terr));
	CHECK(memcmp(c2.skeleton.skins[0].inverse_bind, c.skeleton.skins[0].inverse_bind,
	             sizeof(mlod_mat4) * (size_t)c.skeleton.skins[0].joint_count) == 0);
	mlod_character_free(&c2);
	mlod_gltf_free(again);
	mlod_gltf_free(doc);
	/* rest TRS: the robot writes 15 digits (style 2); dropped then filled,
	 * the document's text is the same */
	doc = read_robot();
	CHECK(doc != NULL);
	int dropped_parts = 0, other = 0;
	for (int j = 0; j < c.skeleton.joint_count; j++) {
		int d = 0, d0 = 0;
		CHECK_OK(mlod_gltf_drop_node_trs(doc, c.skeleton.joints[j].node, &c.skeleton.joints[j].rest, 0, 0, &d0, &terr));
		CHECK_OK(mlod_gltf_drop_node_trs(doc, c.skeleton.joints[j].node, &c.skeleton.joints[j].rest, 2, 1, &d, &terr));
		dropped_parts += (d & 1) + (d >> 1 & 1) + (d >> 2 & 1);
		other += (d0 & 1) + (d0 >> 1 & 1) + (d0 >> 2 & 1);
	}
	CHECK_MSG(dropped_parts > other, "style 2 drops %d parts, style 0 %d", dropped_parts, other);
	char *stripped = gltf_text(doc);
	CHECK(stripped && before && strlen(stripped) < strlen(before));
	for (int j = 0; j < c.skeleton.joint_count; j++)
		CHECK_OK(mlod_gltf_fill_node_trs(doc, c.skeleton.joints[j].node, &c.skeleton.joints[j].rest, 2, &terr));
	char *after = gltf_text(doc);
	CHECK(after && before && strcmp(after, before) == 0);
	free(stripped);
	free(after);
	free(before);
	mlod_character_free(&c);
	mlod_gltf_free(doc);
}

/* ---------------------------------------------------------------- */
/* Adding to a document                                              */
/* ---------------------------------------------------------------- */

TEST(add_objects)
{
	mlod_gltf *doc = read_robot(), *again = NULL;
	CHECK_MSG(doc != NULL, "%s", terr.message);
	mlod_character c = {0}, c2 = {0};
	CHECK_OK(mlod_gltf_to_character(doc, &c, &terr));
	int nodes = mlod_gltf_count(doc, MLOD_GLTF_NODE);
	int mesh = -1, skin = -1, anim = -1, lod1 = -1, lod2 = -1, base = -1;
	int skinned = -1;
	for (int i = 0; i < c.instance_count && skinned < 0; i++)
		if (c.instances[i].skin >= 0)
			skinned = i;
	const mlod_instance *in = &c.instances[skinned];
	mlod_trs trs = mlod_trs_identity();
	trs.t.x = 0.5f;
	mlod_result r = mlod_gltf_add_mesh(doc, &c.meshes[in->mesh], &mesh, &terr);
	if (!r) r = mlod_gltf_add_skin(doc, &c.skeleton, &c.skeleton.skins[in->skin], &skin, &terr);
	if (!r) r = mlod_gltf_add_node(doc, "lod1", MLOD_GLTF_DETACHED, mesh, skin, NULL, &lod1, &terr);
	if (!r) r = mlod_gltf_add_node(doc, "lod2", MLOD_GLTF_DETACHED, mesh, skin, NULL, &lod2, &terr);
	if (!r) r = mlod_gltf_add_node(doc, "child", 0, -1, -1, &trs, &base, &terr);
	if (!r) r = mlod_gltf_add_animation(doc, &c.skeleton, &c.clips[0], &anim, &terr);
	const int lods[2] = { lod1, lod2 };
	const float coverage[3] = { 0.5f, 0.2f, 0.1f };
	if (!r) r = mlod_gltf_set_lod(doc, in->node, lods, 2, coverage, &terr);
	CHECK_MSG(r == MLOD_OK, "%s", terr.message);
	CHECK(mlod_gltf_add_node(doc, "x", nodes + 100, -1, -1, NULL, NULL, &terr) == MLOD_ERR_INVALID_ARG);
	CHECK(mlod_gltf_set_lod(doc, in->node, lods, 2, (const float[3]){ 0.1f, 0.5f, 0.2f }, &terr) == MLOD_ERR_INVALID_ARG);
	CHECK(mesh == 19 && skin == 4 && anim == 14 && lod1 == nodes && base == nodes + 2);

	r = reread(doc, &again);
	mlod_gltf_free(doc);
	CHECK_MSG(r == MLOD_OK, "%s", terr.message);
	char *cov = NULL;
	r = mlod_gltf_get_extra(again, MLOD_GLTF_NODE, in->node, "MSFT_screencoverage", &cov, &terr);
	int counts = mlod_gltf_count(again, MLOD_GLTF_NODE) == nodes + 3 && mlod_gltf_count(again, MLOD_GLTF_MESH) == 20 &&
	             mlod_gltf_count(again, MLOD_GLTF_SKIN) == 5 && mlod_gltf_count(again, MLOD_GLTF_ANIMATION) == 15;
	char *text = gltf_text(again);
	mlod_result rc = mlod_gltf_to_character(again, &c2, &terr);
	mlod_gltf_free(again);
	int lod_ext = text && count_of(text, "\"MSFT_lod\"") == 2; /* extensionsUsed and the node */
	free(text);
	int cov_ok = r == MLOD_OK && cov && strcmp(cov, "[0.5,0.2,0.1]") == 0;
	mlod_free(cov);
	const char *d = NULL;
	if (rc == MLOD_OK) {
		/* The new mesh decodes to the one it was made from; the new
		 * clip to the first clip; the LOD nodes are out of the scene, so
		 * not instances. */
		d = primitive_diff(&c.meshes[in->mesh].primitives[0], &c2.meshes[mesh].primitives[0], 0.0f);
		if (!d && (c2.clip_count != 15 || c2.clips[14].channel_count != c.clips[0].channel_count))
			d = "the added animation differs";
		if (!d && (c2.instance_count != c.instance_count || !c2.notes || !strstr(c2.notes, "not in the default scene")))
			d = "the detached LOD nodes became instances, or the child node did not";
	}
	mlod_character_free(&c);
	mlod_character_free(&c2);
	CHECK(counts);
	CHECK(lod_ext);
	CHECK(cov_ok);
	CHECK_MSG(rc == MLOD_OK, "%s", terr.message);
	CHECK_MSG(d == NULL, "%s", d);
}

/* A reskinned copy of a mesh: new joints and weights, the rest shared. */
TEST(reskinned_mesh)
{
	mlod_gltf *doc = read_robot(), *again = NULL;
	CHECK_MSG(doc != NULL, "%s", terr.message);
	mlod_character c = {0}, c2 = {0};
	CHECK_OK(mlod_gltf_to_character(doc, &c, &terr));
	int m = -1;
	for (int i = 0; i < c.instance_count && m < 0; i++)
		if (c.instances[i].skin >= 0)
			m = c.instances[i].mesh;
	mlod_primitive *p = &c.meshes[m].primitives[0];
	for (int i = 0; i < p->vertex_count; i++) {
		memset(&p->joints[0][4 * i], 0, 4 * sizeof(uint16_t));
		p->weights[0][4 * i] = 1;
		memset(&p->weights[0][4 * i + 1], 0, 3 * sizeof(float));
	}
	char *before = gltf_text(doc), *after = NULL;
	int index = -1;
	mlod_result r = mlod_gltf_add_mesh_reskinned(doc, c.meshes[m].gltf_index, &c.meshes[m], &index, &terr);
	if (r == MLOD_OK) {
		after = gltf_text(doc);
		r = reread(doc, &again);
	}
	if (r == MLOD_OK)
		r = mlod_gltf_to_character(again, &c2, &terr);
	mlod_gltf_free(doc);
	mlod_gltf_free(again);
	/* Two new accessors: JOINTS_0 and WEIGHTS_0 of its one primitive. */
	int shared = before && after && count_of(after, "\"componentType\"") == count_of(before, "\"componentType\"") + 2;
	free(before);
	free(after);
	const char *d = NULL;
	if (r == MLOD_OK)
		d = index != 19 || c2.mesh_count != 20 ? "not appended" : primitive_diff(p, &c2.meshes[index].primitives[0], 0.0f);
	CHECK(mlod_gltf_add_mesh_reskinned(NULL, 0, &c.meshes[m], NULL, &terr) == MLOD_ERR_INVALID_ARG);
	mlod_character_free(&c);
	mlod_character_free(&c2);
	CHECK_MSG(r == MLOD_OK, "%s", terr.message);
	CHECK(shared);
	CHECK_MSG(d == NULL, "%s", d);
}

/* ---------------------------------------------------------------- */
/* Character -> glTF -> character                                    */
/* ---------------------------------------------------------------- */

static char *dup(const char *s)
{
	char *p = malloc(strlen(s) + 1);
	strcpy(p, s);
	return p;
}

static float *floats(const float *v, size_t n)
{
	float *p = malloc(n * sizeof *p);
	memcpy(p, v, n * sizeof *p);
	return p;
}

/* Three joints in a chain under a moved root, an End Site, a skin, one
 * mesh placed three ways, and clips with every interpolation. */
static void build_character(mlod_character *c)
{
	memset(c, 0, sizeof *c);
	mlod_skeleton *s = &c->skeleton;
	s->joint_count = 3;
	s->joints = calloc(3, sizeof *s->joints);
	const char *names[3] = { "hips", "spine", "head" };
	for (int i = 0; i < 3; i++) {
		mlod_joint *j = &s->joints[i];
		j->name = dup(names[i]);
		j->parent = i - 1;
		j->rest = mlod_trs_identity();
		j->rest.t.y = i ? 0.25f : 1.0f;
		j->base = mlod_mat4_identity();
		j->node = -1;
	}
	s->joints[1].rest.r = mlod_quat_axis_angle((mlod_v3){ 1, 0, 0 }, 0.3f);
	s->joints[2].rest.s = (mlod_v3){ 2, 2, 2 };
	s->joints[2].has_end_site = 1;
	s->joints[2].end_site = (mlod_v3){ 0, 0.1f, 0 };
	mlod_trs up = mlod_trs_identity();
	up.t.z = 3;
	s->joints[0].base = mlod_mat4_from_trs(&up);

	s->skin_count = 1;
	s->skins = calloc(1, sizeof *s->skins);
	s->skins[0].name = dup("body");
	s->skins[0].joint_count = 3;
	s->skins[0].joints = malloc(3 * sizeof(int));
	s->skins[0].inverse_bind = malloc(3 * sizeof(mlod_mat4));
	for (int i = 0; i < 3; i++) {
		s->skins[0].joints[i] = i;
		mlod_trs t = mlod_trs_identity();
		t.t.y = -0.5f * (float)i;
		s->skins[0].inverse_bind[i] = mlod_mat4_from_trs(&t);
	}

	c->mesh_count = 1;
	c->meshes = calloc(1, sizeof *c->meshes);
	c->meshes[0].name = dup("quad");
	c->meshes[0].gltf_index = -1;
	c->meshes[0].primitive_count = 1;
	c->meshes[0].primitives = calloc(1, sizeof(mlod_primitive));
	mlod_primitive *p = &c->meshes[0].primitives[0];
	const float pos[12] = { 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0 };
	const float nrm[12] = { 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1 };
	const float uv[8] = { 0, 0, 1, 0, 1, 1, 0, 1 };
	const float col[16] = { 1, 0, 0, 1, 0, 1, 0, 1, 0, 0, 1, 0.5f, 1, 1, 1, 1 };
	const float w[16] = { 1, 0, 0, 0, 0.5f, 0.5f, 0, 0, 0.25f, 0.75f, 0, 0, 1, 0, 0, 0 };
	const uint16_t jn[16] = { 0, 0, 0, 0, 0, 1, 0, 0, 1, 2, 0, 0, 2, 0, 0, 0 };
	const uint32_t idx[6] = { 0, 1, 2, 0, 2, 3 };
	const float delta[12] = { 0, 0, 0.1f, 0, 0, 0.2f, 0, 0, 0.3f, 0, 0, 0.4f };
	p->vertex_count = 4;
	p->positions = floats(pos, 12);
	p->normals = floats(nrm, 12);
	p->uv_set_count = 1;
	p->uvs[0] = floats(uv, 8);
	p->color_set_count = 1;
	p->colors[0] = floats(col, 16);
	p->weight_set_count = 1;
	p->weights[0] = floats(w, 16);
	p->joints[0] = malloc(sizeof jn);
	memcpy(p->joints[0], jn, sizeof jn);
	p->index_count = 6;
	p->indices = malloc(sizeof idx);
	memcpy(p->indices, idx, sizeof idx);
	p->mode = 4;
	p->material = -1;
	p->target_count = 1;
	p->targets = calloc(1, sizeof *p->targets);
	p->targets[0].positions = floats(delta, 12);

	c->instance_count = 3;
	c->instances = calloc(3, sizeof *c->instances);
	mlod_trs off = mlod_trs_identity();
	off.t.x = 0.1f;
	off.r = mlod_quat_axis_angle((mlod_v3){ 0, 1, 0 }, 0.5f);
	for (int i = 0; i < 3; i++) {
		c->instances[i].mesh = 0;
		c->instances[i].node = -1;
		c->instances[i].skin = i == 0 ? 0 : -1;
		c->instances[i].joint = i == 1 ? 1 : -1;
		c->instances[i].offset = i == 0 ? mlod_mat4_identity() : mlod_mat4_from_trs(&off);
	}

	c->clip_count = 2;
	c->clips = calloc(2, sizeof *c->clips);
	const float times[3] = { 0, 0.5f, 1 };
	const float tv[9] = { 0, 1, 0, 0, 1.5f, 0, 0, 1, 0 };
	mlod_quat q0 = mlod_quat_identity(), q1 = mlod_quat_axis_angle((mlod_v3){ 0, 0, 1 }, 1.0f);
	const float rv[8] = { q0.x, q0.y, q0.z, q0.w, q1.x, q1.y, q1.z, q1.w };
	const float cubic[18] = { 0, 0, 0, 1, 1, 1, 0.5f, 0, 0, 0, 0, 0, 2, 2, 2, 0, 0, 0 };
	for (int k = 0; k < 2; k++) {
		mlod_clip *clip = &c->clips[k];
		clip->name = dup(k ? "cubic" : "walk");
		clip->gltf_index = -1;
		clip->channel_count = 2;
		clip->channels = calloc(2, sizeof *clip->channels);
		mlod_channel *a = &clip->channels[0], *b = &clip->channels[1];
		a->joint = 0;
		b->joint = 1;
		if (k == 0) {
			a->path = MLOD_PATH_TRANSLATION;
			a->interp = MLOD_INTERP_LINEAR;
			a->key_count = 3;
			a->times = floats(times, 3);
			a->values = floats(tv, 9);
			b->path = MLOD_PATH_ROTATION;
			b->interp = MLOD_INTERP_STEP;
			b->key_count = 2;
			b->times = floats(times, 2);
			b->values = floats(rv, 8);
			clip->duration = 1;
		} else {
			a->path = MLOD_PATH_SCALE;
			a->interp = MLOD_INTERP_CUBICSPLINE;
			a->key_count = 2;
			a->times = floats(times + 1, 2);
			a->values = floats(cubic, 18);
			b->path = MLOD_PATH_ROTATION;
			b->interp = MLOD_INTERP_LINEAR;
			b->key_count = 2;
			b->times = floats(times + 1, 2);
			b->values = floats(rv, 8);
			clip->duration = 1;
		}
	}
}

/* A level in place: a copy of the document with one node's mesh replaced
 * by a coarser one, pruned: the full mesh and its accessors go, the rest
 * (other meshes, materials, the original document) stays as it was. */
TEST(level_in_place)
{
	mlod_gltf *doc = read_robot(), *copy = NULL, *again = NULL;
	CHECK_MSG(doc != NULL, "%s", terr.message);
	mlod_character c = {0}, c2 = {0};
	CHECK_OK(mlod_gltf_to_character(doc, &c, &terr));
	char *before = gltf_text(doc);
	const mlod_instance *in = &c.instances[1];
	mlod_mesh m = c.meshes[in->mesh];
	mlod_primitive half = m.primitives[0];
	half.index_count = half.index_count / 6 * 3;
	m.primitives = &half;
	int mesh = -1, meshes = mlod_gltf_count(doc, MLOD_GLTF_MESH);
	mlod_result r = mlod_gltf_copy(doc, &copy, &terr);
	if (r == MLOD_OK)
		r = mlod_gltf_add_mesh_like(copy, m.gltf_index, &m, &mesh, &terr);
	if (r == MLOD_OK)
		r = mlod_gltf_set_node_mesh(copy, in->node, mesh, -1, &terr);
	if (r == MLOD_OK)
		r = mlod_gltf_prune(copy, &terr);
	int pruned = mlod_gltf_count(copy, MLOD_GLTF_MESH);
	if (r == MLOD_OK)
		r = reread(copy, &again);
	if (r == MLOD_OK)
		r = mlod_gltf_to_character(again, &c2, &terr);
	char *after = gltf_text(doc), *text = gltf_text(copy);
	int same_original = before && after && strcmp(before, after) == 0;
	int materials = text && count_of(text, "\"pbrMetallicRoughness\"") == count_of(before, "\"pbrMetallicRoughness\"");
	free(before);
	free(after);
	free(text);
	CHECK(mlod_gltf_set_node_mesh(copy, in->node, meshes + 5, -1, &terr) == MLOD_ERR_INVALID_ARG);
	CHECK(mlod_gltf_clear_lod(copy, in->node, &terr) == MLOD_OK); /* no MSFT_lod: nothing to do */
	mlod_gltf_free(copy);
	mlod_gltf_free(again);
	mlod_gltf_free(doc);
	const char *d = "not read back";
	if (r == MLOD_OK && c2.instance_count == c.instance_count) {
		const mlod_mesh *m1 = &c2.meshes[c2.instances[1].mesh], *m0 = &c2.meshes[c2.instances[0].mesh];
		d = m1->primitives[0].index_count != half.index_count ? "the level is not in place"
		    : primitive_diff(&c.meshes[c.instances[0].mesh].primitives[0], &m0->primitives[0], 0.0f);
	}
	mlod_character_free(&c);
	mlod_character_free(&c2);
	CHECK_MSG(r == MLOD_OK, "%s", terr.message);
	CHECK(same_original);
	CHECK(materials);
	CHECK_MSG(pruned == meshes, "%d meshes after pruning, %d before", pruned, meshes);
	CHECK_MSG(d == NULL, "%s", d);
}

/* Level nodes morph like their node; pruning refuses unknown extensions;
 * a static node's transform. */
TEST(morph_channels_and_transforms)
{
	mlod_gltf *doc = read_robot();
	CHECK_MSG(doc != NULL, "%s", terr.message);
	int node = -1, added = -1;
	mlod_trs t;
	mlod_result r = mlod_gltf_add_node(doc, "level", MLOD_GLTF_DETACHED, 3, -1, NULL, &node, &terr);
	if (r == MLOD_OK) /* node 6 (Head_2) has 14 weight channels over the clips */
		r = mlod_gltf_copy_morph_animation(doc, 6, node, &added, &terr);
	char *text = r == MLOD_OK ? gltf_text(doc) : NULL;
	int weights = text ? count_of(text, "\"path\": \"weights\"") : -1;
	free(text);
	mlod_result bad = mlod_gltf_copy_morph_animation(doc, 6, node + 1, NULL, &terr);
	mlod_result trs = mlod_gltf_get_node_trs(doc, 6, &t, &terr);
	mlod_result bad_trs = mlod_gltf_get_node_trs(doc, -1, &t, &terr);
	mlod_gltf_free(doc);
	mlod_gltf *ext = NULL;
	mlod_result with_ext = read_text("{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"EXT_mesh_gpu_instancing\"]}",
	                                 &ext, &terr);
	mlod_result pruned = with_ext == MLOD_OK ? mlod_gltf_prune(ext, &terr) : with_ext;
	mlod_gltf_free(ext);
	CHECK_MSG(r == MLOD_OK, "%s", terr.message);
	CHECK_MSG(added == 14, "%d channels added", added);
	CHECK_MSG(weights == 42 + 14, "%d weight channels", weights);
	CHECK(bad == MLOD_ERR_INVALID_ARG);
	CHECK(trs == MLOD_OK && bad_trs == MLOD_ERR_INVALID_ARG);
	CHECK(pruned == MLOD_ERR_UNSUPPORTED);
}

TEST(from_character)
{
	mlod_character c, back = {0};
	build_character(&c);
	CHECK_OK(mlod_character_validate(&c, &terr));
	mlod_gltf *doc = NULL, *again = NULL;
	mlod_result r = mlod_gltf_from_character(&c, &doc, &terr);
	if (r == MLOD_OK)
		r = reread(doc, &again);
	if (r == MLOD_OK)
		r = mlod_gltf_to_character(again, &back, &terr);
	char *text = again ? gltf_text(again) : NULL;
	const char *d = r == MLOD_OK ? character_diff(&c, &back, 0, 1e-6f) : NULL;
	int end_site_node = text && strstr(text, "\"name\": \"head_end\"") && strstr(text, "\"end_site\": true");
	int generator = text && strstr(text, "\"generator\": \"mlod\"");
	int notes = back.notes == NULL;
	free(text);
	mlod_gltf_free(doc);
	mlod_gltf_free(again);
	mlod_character_free(&c);
	mlod_character_free(&back);
	CHECK_MSG(r == MLOD_OK, "%s", terr.message);
	CHECK_MSG(d == NULL, "%s", d);
	CHECK(end_site_node);
	CHECK(generator);
	CHECK(notes);
}

/* Objects with only default properties (an empty scene, an unnamed joint
 * at the origin) are written as {}, not null. */
TEST(empty_objects)
{
	mlod_character c = {0};
	mlod_gltf *doc = NULL, *again = NULL;
	CHECK_OK(mlod_gltf_from_character(&c, &doc, &terr));
	char *empty = gltf_text(doc);
	mlod_gltf_free(doc);
	c.skeleton.joint_count = 1;
	c.skeleton.joints = calloc(1, sizeof(mlod_joint));
	c.skeleton.joints[0].name = dup("");
	c.skeleton.joints[0].parent = -1;
	c.skeleton.joints[0].rest = mlod_trs_identity();
	c.skeleton.joints[0].base = mlod_mat4_identity();
	mlod_result r = mlod_gltf_from_character(&c, &doc, &terr);
	mlod_character_free(&c);
	char *one = r == MLOD_OK ? gltf_text(doc) : NULL;
	if (r == MLOD_OK)
		r = reread(doc, &again);
	int nodes = mlod_gltf_count(again, MLOD_GLTF_NODE);
	mlod_gltf_free(doc);
	mlod_gltf_free(again);
	int no_null = empty && one && !strstr(empty, "null") && !strstr(one, "null");
	free(empty);
	free(one);
	CHECK_MSG(r == MLOD_OK, "%s", terr.message);
	CHECK(no_null);
	CHECK(nodes == 1);
}

/* A BVH skeleton in glTF (no skins) comes back from its animated nodes,
 * End Sites included. */
TEST(bvh_via_gltf)
{
	size_t size;
	void *text = test_read_file("samples/cmu_12_01_walk.bvh", &size);
	CHECK(text != NULL);
	mlod_character c = {0}, back = {0};
	mlod_gltf *doc = NULL, *again = NULL;
	mlod_result r = mlod_bvh_read(text, size, &c, &terr);
	free(text);
	if (r == MLOD_OK)
		r = mlod_gltf_from_character(&c, &doc, &terr);
	if (r == MLOD_OK)
		r = reread(doc, &again);
	if (r == MLOD_OK)
		r = mlod_gltf_to_character(again, &back, &terr);
	int ends = 0;
	for (int i = 0; r == MLOD_OK && i < back.skeleton.joint_count; i++)
		ends += back.skeleton.joints[i].has_end_site;
	const char *d = r == MLOD_OK ? character_diff(&c, &back, 0, 1e-6f) : NULL; /* quaternions are renormalised */
	mlod_gltf_free(doc);
	mlod_gltf_free(again);
	mlod_character_free(&c);
	mlod_character_free(&back);
	CHECK_MSG(r == MLOD_OK, "%s", terr.message);
	CHECK_MSG(d == NULL, "%s", d);
	CHECK(ends == 7); /* the End Sites of the file: toes, head, fingers and thumbs */
}

/* The sample through from_character comes back as the same character. */
TEST(robot_via_character)
{
	mlod_gltf *doc = read_robot(), *built = NULL, *again = NULL;
	CHECK_MSG(doc != NULL, "%s", terr.message);
	mlod_character c = {0}, back = {0};
	mlod_result r = mlod_gltf_to_character(doc, &c, &terr);
	mlod_gltf_free(doc);
	if (r == MLOD_OK)
		r = mlod_gltf_from_character(&c, &built, &terr);
	if (r == MLOD_OK)
		r = reread(built, &again);
	if (r == MLOD_OK)
		r = mlod_gltf_to_character(again, &back, &terr);
	const char *d = r == MLOD_OK ? character_diff(&c, &back, 0, 1e-6f) : NULL;
	mlod_gltf_free(built);
	mlod_gltf_free(again);
	mlod_character_free(&c);
	mlod_character_free(&back);
	CHECK_MSG(r == MLOD_OK, "%s", terr.message);
	CHECK_MSG(d == NULL, "%s", d);
}

/* ---------------------------------------------------------------- */
/* Decoding                                                          */
/* ---------------------------------------------------------------- */

static void put32(unsigned char *p, uint32_t v)
{
	for (int k = 0; k < 4; k++)
		p[k] = (unsigned char)(v >> (8 * k));
}

static void put_floats(unsigned char *p, const float *v, int n)
{
	memcpy(p, v, (size_t)n * sizeof(float));
}

/* A glb of json and bin (padded as the format wants); free() it. */
static unsigned char *make_glb(const char *json, const unsigned char *bin, size_t bin_size, size_t *size)
{
	size_t jn = (strlen(json) + 3) / 4 * 4, bn = (bin_size + 3) / 4 * 4;
	*size = 12 + 8 + jn + (bn ? 8 + bn : 0);
	unsigned char *g = calloc(1, *size);
	memcpy(g, "glTF", 4);
	put32(g + 4, 2);
	put32(g + 8, (uint32_t)*size);
	put32(g + 12, (uint32_t)jn);
	put32(g + 16, 0x4E4F534A);
	memset(g + 20, ' ', jn);
	memcpy(g + 20, json, strlen(json));
	if (bn) {
		put32(g + 20 + jn, (uint32_t)bn);
		put32(g + 24 + jn, 0x004E4942);
		memcpy(g + 28 + jn, bin, bin_size);
	}
	return g;
}

/* Interleaved positions and normals (stride 24), normalised ushort UVs,
 * normalised ubyte RGB colors (stride 4), ubyte joints, normalised ubyte
 * weights, ubyte indices, a sparse morph target without buffer view, a
 * sparse UV set over a buffer view, a quantised rotation track. Node 1
 * sits between the skin joints 0 and 2; node 5 is an End Site; node 4 a
 * rigid part; node 6 a non-joint parent of the root. */
static const char decode_json[] =
	"{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"KHR_mesh_quantization\"],\"extensionsRequired\":[\"KHR_mesh_quantization\"],"
	"\"buffers\":[{\"byteLength\":232}],"
	"\"bufferViews\":["
	"{\"buffer\":0,\"byteOffset\":0,\"byteLength\":72,\"byteStride\":24},"
	"{\"buffer\":0,\"byteOffset\":72,\"byteLength\":12},"
	"{\"buffer\":0,\"byteOffset\":84,\"byteLength\":12,\"byteStride\":4},"
	"{\"buffer\":0,\"byteOffset\":96,\"byteLength\":12},"
	"{\"buffer\":0,\"byteOffset\":108,\"byteLength\":12},"
	"{\"buffer\":0,\"byteOffset\":120,\"byteLength\":3},"
	"{\"buffer\":0,\"byteOffset\":124,\"byteLength\":2},"
	"{\"buffer\":0,\"byteOffset\":128,\"byteLength\":12},"
	"{\"buffer\":0,\"byteOffset\":140,\"byteLength\":24},"
	"{\"buffer\":0,\"byteOffset\":164,\"byteLength\":1},"
	"{\"buffer\":0,\"byteOffset\":168,\"byteLength\":8},"
	"{\"buffer\":0,\"byteOffset\":176,\"byteLength\":8},"
	"{\"buffer\":0,\"byteOffset\":184,\"byteLength\":16},"
	"{\"buffer\":0,\"byteOffset\":200,\"byteLength\":24},"
	"{\"buffer\":0,\"byteOffset\":224,\"byteLength\":8}],"
	"\"accessors\":["
	"{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\",\"min\":[0,0,0],\"max\":[1,1,0]},"
	"{\"bufferView\":0,\"byteOffset\":12,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
	"{\"bufferView\":1,\"componentType\":5123,\"normalized\":true,\"count\":3,\"type\":\"VEC2\"},"
	"{\"bufferView\":2,\"componentType\":5121,\"normalized\":true,\"count\":3,\"type\":\"VEC3\"},"
	"{\"bufferView\":3,\"componentType\":5121,\"count\":3,\"type\":\"VEC4\"},"
	"{\"bufferView\":4,\"componentType\":5121,\"normalized\":true,\"count\":3,\"type\":\"VEC4\"},"
	"{\"bufferView\":5,\"componentType\":5121,\"count\":3,\"type\":\"SCALAR\"},"
	"{\"componentType\":5126,\"count\":3,\"type\":\"VEC3\",\"min\":[0,0,0],\"max\":[0,0,1],\"sparse\":{\"count\":1,"
	"\"indices\":{\"bufferView\":6,\"componentType\":5123},\"values\":{\"bufferView\":7}}},"
	"{\"bufferView\":8,\"componentType\":5126,\"count\":3,\"type\":\"VEC2\",\"sparse\":{\"count\":1,"
	"\"indices\":{\"bufferView\":9,\"componentType\":5121},\"values\":{\"bufferView\":10}}},"
	"{\"bufferView\":11,\"componentType\":5126,\"count\":2,\"type\":\"SCALAR\",\"min\":[0],\"max\":[1]},"
	"{\"bufferView\":12,\"componentType\":5122,\"normalized\":true,\"count\":2,\"type\":\"VEC4\"},"
	"{\"bufferView\":13,\"componentType\":5126,\"count\":2,\"type\":\"VEC3\"},"
	"{\"bufferView\":14,\"componentType\":5126,\"count\":2,\"type\":\"SCALAR\"}],"
	"\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1,\"TEXCOORD_0\":2,\"TEXCOORD_1\":8,"
	"\"COLOR_0\":3,\"JOINTS_0\":4,\"WEIGHTS_0\":5},\"indices\":6,\"targets\":[{\"POSITION\":7}]}],\"weights\":[0]}],"
	"\"nodes\":[{\"name\":\"root\",\"children\":[1]},{\"name\":\"link\",\"children\":[2],\"translation\":[0,1,0]},"
	"{\"name\":\"tip\",\"children\":[4,5],\"translation\":[0,1,0]},{\"name\":\"body\",\"mesh\":0,\"skin\":0},"
	"{\"name\":\"prop\",\"mesh\":0,\"translation\":[1,0,0]},"
	"{\"name\":\"tip_end\",\"translation\":[0,0.5,0],\"extras\":{\"mlod\":{\"end_site\":true}}},"
	"{\"name\":\"world\",\"translation\":[0,0,5],\"children\":[0]}],"
	"\"scenes\":[{\"nodes\":[6,3]}],\"scene\":0,\"skins\":[{\"joints\":[0,2]}],"
	"\"animations\":[{\"name\":\"a\",\"samplers\":[{\"input\":9,\"output\":10},"
	"{\"input\":9,\"output\":11,\"interpolation\":\"STEP\"},{\"input\":9,\"output\":12}],"
	"\"channels\":[{\"sampler\":0,\"target\":{\"node\":2,\"path\":\"rotation\"}},"
	"{\"sampler\":1,\"target\":{\"node\":4,\"path\":\"translation\"}},"
	"{\"sampler\":2,\"target\":{\"node\":3,\"path\":\"weights\"}}]}]}";

static void decode_bin(unsigned char bin[232])
{
	memset(bin, 0, 232);
	const float vertices[18] = { 0, 0, 0, 0, 0, 1, 1, 0, 0, 0, 0, 1, 0, 1, 0, 0, 0, 1 };
	put_floats(bin, vertices, 18);
	const uint16_t uv[6] = { 0, 0, 65535, 0, 0, 65535 };
	memcpy(bin + 72, uv, sizeof uv);
	const unsigned char rgb[12] = { 255, 0, 0, 9, 0, 255, 0, 9, 0, 0, 255, 9 };
	memcpy(bin + 84, rgb, 12);
	const unsigned char joints[12] = { 0, 1, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0 };
	memcpy(bin + 96, joints, 12);
	const unsigned char weights[12] = { 255, 0, 0, 0, 128, 127, 0, 0, 255, 0, 0, 0 };
	memcpy(bin + 108, weights, 12);
	const unsigned char idx[3] = { 0, 1, 2 };
	memcpy(bin + 120, idx, 3);
	const uint16_t sparse_index = 2;
	memcpy(bin + 124, &sparse_index, 2);
	const float delta[3] = { 0, 0, 1 };
	put_floats(bin + 128, delta, 3);
	const float uv1[6] = { 0.1f, 0.1f, 0.2f, 0.2f, 0.3f, 0.3f };
	put_floats(bin + 140, uv1, 6);
	bin[164] = 0;
	const float uv1_new[2] = { 0.25f, 0.75f };
	put_floats(bin + 168, uv1_new, 2);
	const float times[2] = { 0, 1 };
	put_floats(bin + 176, times, 2);
	const int16_t rot[8] = { 0, 0, 0, 32767, 0, 0, 32767, 0 };
	memcpy(bin + 184, rot, sizeof rot);
}

TEST(decode_layouts)
{
	unsigned char bin[232];
	decode_bin(bin);
	size_t size;
	unsigned char *glb = make_glb(decode_json, bin, sizeof bin, &size);
	mlod_gltf *doc = NULL;
	mlod_character c = {0};
	mlod_result r = mlod_gltf_read(glb, size, NULL, &doc, &terr);
	free(glb);
	if (r == MLOD_OK)
		r = mlod_gltf_to_character(doc, &c, &terr);
	mlod_gltf_free(doc);
	CHECK_MSG(r == MLOD_OK, "%s", terr.message);
	mlod_result valid = mlod_character_validate(&c, &terr);
	const mlod_skeleton *s = &c.skeleton;
	int skeleton = s->joint_count == 3 && strcmp(s->joints[0].name, "root") == 0 &&
	               strcmp(s->joints[1].name, "link") == 0 && strcmp(s->joints[2].name, "tip") == 0 &&
	               s->joints[0].parent == -1 && s->joints[1].parent == 0 && s->joints[2].parent == 1 &&
	               s->joints[0].base.m[14] == 5 && s->joints[1].base.m[14] == 0 &&
	               s->joints[2].has_end_site && s->joints[2].end_site.y == 0.5f && !s->joints[0].has_end_site;
	int skin = s->skin_count == 1 && s->skins[0].joint_count == 2 && s->skins[0].joints[0] == 0 &&
	           s->skins[0].joints[1] == 2 && s->skins[0].inverse_bind[1].m[0] == 1;
	const mlod_primitive *p = c.mesh_count == 1 ? &c.meshes[0].primitives[0] : NULL;
	int interleaved = p && p->vertex_count == 3 && p->positions[3] == 1 && p->positions[7] == 1 &&
	                  p->normals[2] == 1 && p->normals[8] == 1;
	int uvs = p && p->uv_set_count == 2 && p->uvs[0][2] == 1 && p->uvs[0][5] == 1 && p->uvs[0][0] == 0 &&
	          p->uvs[1][0] == 0.25f && p->uvs[1][1] == 0.75f && p->uvs[1][2] == 0.2f;
	int colors = p && p->color_set_count == 1 && p->colors[0][0] == 1 && p->colors[0][3] == 1 &&
	             p->colors[0][5] == 1 && p->colors[0][7] == 1 && p->colors[0][4] == 0;
	int skinning = p && p->weight_set_count == 1 && p->joints[0][1] == 1 && p->joints[0][4] == 1 &&
	               fabsf(p->weights[0][4] - 128.0f / 255) < 1e-7f && p->weights[0][0] == 1;
	int indexed = p && p->index_count == 3 && p->indices[2] == 2 && p->mode == 4;
	int morph = p && p->target_count == 1 && p->targets[0].positions[8] == 1 && p->targets[0].positions[5] == 0;
	int instances = c.instance_count == 2 && c.instances[0].skin == 0 && c.instances[0].joint == -1 &&
	                c.instances[1].skin == -1 && c.instances[1].joint == 2 && c.instances[1].offset.m[12] == 1;
	const mlod_clip *k = c.clip_count == 1 ? &c.clips[0] : NULL;
	int clip = k && k->channel_count == 1 && k->duration == 1 && k->channels[0].joint == 2 &&
	           k->channels[0].path == MLOD_PATH_ROTATION && k->channels[0].values[3] == 1 && k->channels[0].values[6] == 1;
	const char *notes = c.notes ? c.notes : "";
	int noted = strstr(notes, "1 joint nodes are in no skin") && strstr(notes, "\"link\"") &&
	            strstr(notes, "1 animation channels target nodes that are not joints") &&
	            strstr(notes, "1 animation channels animate morph target weights");
	mlod_character_free(&c);
	CHECK_MSG(valid == MLOD_OK, "%s", terr.message);
	CHECK(skeleton);
	CHECK(skin);
	CHECK(interleaved);
	CHECK(uvs);
	CHECK(colors);
	CHECK(skinning);
	CHECK(indexed);
	CHECK(morph);
	CHECK(instances);
	CHECK(clip);
	CHECK_MSG(noted, "notes: %s", notes);
}

/* ---------------------------------------------------------------- */
/* Bad input                                                         */
/* ---------------------------------------------------------------- */

/* Reading must fail with code (and a message), or, for mutated input,
 * may succeed: then everything else must work on the result. */
static mlod_result try_read(const void *data, size_t size)
{
	mlod_gltf *doc = NULL;
	mlod_error err = {0};
	mlod_result r = mlod_gltf_read(data, size, NULL, &doc, &err);
	if (r != MLOD_OK) {
		if (doc != NULL || err.code != r || err.message[0] == 0)
			return (mlod_result)-1;
		return r;
	}
	mlod_character c = {0};
	void *out = NULL;
	size_t out_size = 0;
	mlod_gltf_to_character(doc, &c, &err);
	mlod_gltf_write(doc, 1, &out, &out_size, &err);
	mlod_character_free(&c);
	mlod_free(out);
	mlod_gltf_free(doc);
	return r;
}

/* Two channels of one animation on the same node and path (the glTF
 * validator's ANIMATION_DUPLICATE_TARGETS) are refused as the file is read,
 * naming both (the animation's name escaped as in JSON); the same path on
 * two nodes is fine. */
TEST(duplicate_targets)
{
	static const char head[] =
		"{\"asset\":{\"version\":\"2.0\"},\"nodes\":[{},{}],"
		"\"buffers\":[{\"byteLength\":16,\"uri\":\"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAAAAAA==\"}],"
		"\"bufferViews\":[{\"buffer\":0,\"byteLength\":16}],"
		"\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":1,\"type\":\"SCALAR\",\"min\":[0],\"max\":[0]},"
		"{\"bufferView\":0,\"byteOffset\":4,\"componentType\":5126,\"count\":1,\"type\":\"VEC3\"}],"
		"\"animations\":[{\"name\":\"a\\\"b\\nc\",\"samplers\":[{\"input\":0,\"output\":1}],\"channels\":["
		"{\"sampler\":0,\"target\":{\"node\":0,\"path\":\"scale\"}},"
		"{\"sampler\":0,\"target\":{\"node\":1,\"path\":\"scale\"}},"
		"{\"sampler\":0,\"target\":{\"node\":0,\"path\":\"translation\"}}";
	char text[2048];
	mlod_gltf *doc = NULL;
	snprintf(text, sizeof text, "%s]}]}", head);
	mlod_result r = mlod_gltf_read(text, strlen(text), NULL, &doc, &terr);
	CHECK_MSG(r == MLOD_OK, "%s", terr.message);
	mlod_gltf_free(doc);
	doc = NULL;
	snprintf(text, sizeof text, "%s,{\"sampler\":0,\"target\":{\"node\":1,\"path\":\"scale\"}}]}]}", head);
	r = mlod_gltf_read(text, strlen(text), NULL, &doc, &terr);
	CHECK(r == MLOD_ERR_PARSE && doc == NULL);
	CHECK_MSG(strcmp(terr.message, "animation 0 \"a\\\"b\\u000ac\": channels 1 and 3 both target node 1's scale") == 0,
	          "%s", terr.message);
}

TEST(empty_and_garbage)
{
	CHECK(try_read("", 0) == MLOD_ERR_PARSE);
	CHECK(try_read("glTF", 4) == MLOD_ERR_PARSE);
	CHECK(try_read("   ", 3) == MLOD_ERR_PARSE);
	CHECK(try_read("[1, 2]", 6) == MLOD_ERR_PARSE);
	CHECK(try_read("{\"asset\": {}}", 13) == MLOD_ERR_PARSE);
	unsigned char junk[4096];
	unsigned x = 12345;
	for (size_t i = 0; i < sizeof junk; i++) {
		x = x * 1103515245u + 12345u;
		junk[i] = (unsigned char)(x >> 16);
	}
	CHECK(try_read(junk, sizeof junk) == MLOD_ERR_PARSE);
	memcpy(junk, "glTF\2\0\0\0", 8);
	CHECK(try_read(junk, sizeof junk) == MLOD_ERR_PARSE);
	mlod_gltf *doc = (mlod_gltf *)1;
	CHECK(mlod_gltf_read(NULL, 10, NULL, &doc, &terr) == MLOD_ERR_INVALID_ARG && doc == NULL);
	CHECK(mlod_gltf_read("x", 1, NULL, NULL, NULL) == MLOD_ERR_INVALID_ARG);
	CHECK(mlod_gltf_to_character(NULL, NULL, NULL) == MLOD_ERR_INVALID_ARG);
	CHECK(mlod_gltf_write(NULL, 1, NULL, NULL, NULL) == MLOD_ERR_INVALID_ARG);
	mlod_gltf_free(NULL);
	/* Too deep for tinygltf's recursive conversion: valid JSON that mlod
	 * does not handle (unsupported, exit 3), not malformed input. */
	char deep[1200] = "{\"asset\":{\"version\":\"2.0\"},\"extras\":";
	size_t n = strlen(deep);
	for (int i = 0; i < 500; i++)
		deep[n++] = '[';
	for (int i = 0; i < 500; i++)
		deep[n++] = ']';
	deep[n++] = '}';
	CHECK(try_read(deep, n) == MLOD_ERR_UNSUPPORTED);
	CHECK(mlod_gltf_read(deep, n, NULL, &doc, &terr) == MLOD_ERR_UNSUPPORTED && doc == NULL);
	CHECK_MSG(strcmp(terr.message, "JSON nested deeper than 100 levels") == 0, "%s", terr.message);
}

TEST(truncated_glb)
{
	size_t size;
	unsigned char *bytes = test_read_file(ROBOT, &size);
	CHECK(bytes != NULL);
	uint32_t json_len = (uint32_t)bytes[12] | (uint32_t)bytes[13] << 8 | (uint32_t)bytes[14] << 16 | (uint32_t)bytes[15] << 24;
	size_t cuts[] = { 1, 8, 12, 19, 20, 21, 100, 20 + json_len - 1, 20 + json_len, 20 + json_len + 4,
	                  20 + json_len + 8, 20 + json_len + 9, size / 2, size - 4, size - 1 };
	unsigned char *copy = malloc(size);
	for (size_t i = 0; i < sizeof cuts / sizeof cuts[0]; i++) {
		/* As cut, then with the header's length fixed to the cut. */
		CHECK_MSG(try_read(bytes, cuts[i]) == MLOD_ERR_PARSE, "cut at %zu", cuts[i]);
		memcpy(copy, bytes, cuts[i]);
		if (cuts[i] >= 12)
			put32(copy + 8, (uint32_t)cuts[i]);
		mlod_result r = try_read(copy, cuts[i]);
		CHECK_MSG(r == MLOD_ERR_PARSE, "cut at %zu, length fixed: %d", cuts[i], (int)r);
	}
	/* A BIN chunk claiming to end exactly at the end of the file (tinygltf
	 * would read its 8-byte header past it). */
	memcpy(copy, bytes, size);
	put32(copy + 20 + json_len, (uint32_t)(size - 20 - json_len));
	CHECK(try_read(copy, size) == MLOD_ERR_PARSE);
	/* Absurd length fields. */
	memcpy(copy, bytes, size);
	put32(copy + 12, 0xFFFFFFF0u);
	CHECK(try_read(copy, size) == MLOD_ERR_PARSE);
	memcpy(copy, bytes, size);
	put32(copy + 4, 1);
	CHECK(try_read(copy, size) == MLOD_ERR_UNSUPPORTED);
	free(copy);
	free(bytes);
}

/* Random byte changes in the sample's JSON chunk must never crash. */
TEST(mutated_glb)
{
	size_t size;
	unsigned char *bytes = test_read_file(ROBOT, &size);
	CHECK(bytes != NULL);
	uint32_t json_len = (uint32_t)bytes[12] | (uint32_t)bytes[13] << 8 | (uint32_t)bytes[14] << 16 | (uint32_t)bytes[15] << 24;
	unsigned char *copy = malloc(size);
	unsigned x = 42;
	int ok = 0;
	for (int round = 0; round < 150; round++) {
		memcpy(copy, bytes, size);
		for (int k = 0; k < 1 + round % 4; k++) {
			x = x * 1103515245u + 12345u;
			size_t at = 20 + (x >> 8) % json_len;
			x = x * 1103515245u + 12345u;
			/* Mostly digits, so that indices and sizes change. */
			copy[at] = (unsigned char)((x >> 16) % 4 ? '0' + (x >> 20) % 10 : (x >> 20) & 0xFF);
		}
		mlod_result r = try_read(copy, size);
		CHECK_MSG((int)r >= 0, "round %d: a failure without a proper error", round);
		ok += r == MLOD_OK;
	}
	free(copy);
	free(bytes);
	CHECK(ok > 0); /* some mutations are harmless */
}

static const char minimal_prefix[] = "{\"asset\":{\"version\":\"2.0\"},";

/* Reads minimal_prefix + body; returns the result code and the message. */
static mlod_result read_body(const char *body, mlod_error *err)
{
	char text[4096];
	snprintf(text, sizeof text, "%s%s", minimal_prefix, body);
	mlod_gltf *doc = NULL;
	mlod_result r = read_text(text, &doc, err);
	if (r == MLOD_OK) {
		mlod_character c = {0};
		r = mlod_gltf_to_character(doc, &c, err);
		mlod_character_free(&c);
	}
	mlod_gltf_free(doc);
	return r;
}

/* 3 vertices (36 bytes) and 3 16-bit indices in one buffer. */
#define TRIANGLE_BUFFER \
	"\"buffers\":[{\"byteLength\":44,\"uri\":\"data:application/octet-stream;base64," \
	"AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAABAAIAAAA=\"}],"

TEST(bad_references)
{
	mlod_error err;
	CHECK(read_body("\"nodes\":[{\"children\":[5]}]}", &err) == MLOD_ERR_PARSE);
	CHECK(strstr(err.message, "node 0") && strstr(err.message, "5"));
	CHECK(read_body("\"nodes\":[{\"children\":[1]},{\"children\":[2]},{\"children\":[0]}]}", &err) == MLOD_ERR_PARSE);
	CHECK(strstr(err.message, "cycle"));
	CHECK(read_body("\"nodes\":[{\"children\":[0]}]}", &err) == MLOD_ERR_PARSE);
	CHECK(read_body("\"nodes\":[{\"children\":[2]},{\"children\":[2]},{}]}", &err) == MLOD_ERR_PARSE);
	CHECK(strstr(err.message, "two parents"));
	CHECK(read_body("\"nodes\":[{\"mesh\":3}]}", &err) == MLOD_ERR_PARSE);
	CHECK(read_body("\"scenes\":[{\"nodes\":[7]}],\"nodes\":[{}]}", &err) == MLOD_ERR_PARSE);
	CHECK(read_body("\"skins\":[{\"joints\":[4]}],\"nodes\":[{}]}", &err) == MLOD_ERR_PARSE);
	/* An accessor past the end of its buffer view. */
	CHECK(read_body(TRIANGLE_BUFFER "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
	                "\"accessors\":[{\"bufferView\":0,\"byteOffset\":4,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}]}",
	                &err) == MLOD_ERR_PARSE);
	CHECK(strstr(err.message, "accessor 0: extends past the end of buffer view 0"));
	/* A buffer view past the end of its buffer. */
	CHECK(read_body(TRIANGLE_BUFFER "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":40,\"byteLength\":8}]}", &err) ==
	      MLOD_ERR_PARSE);
	CHECK(strstr(err.message, "buffer view 0: extends past the end of buffer 0"));
	/* An image in a buffer view past the end of its buffer. */
	CHECK(read_body(TRIANGLE_BUFFER "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":40,\"byteLength\":800}],"
	                "\"images\":[{\"bufferView\":0,\"mimeType\":\"image/png\"}]}", &err) == MLOD_ERR_PARSE);
	/* An index out of range, and a count mismatch. */
	CHECK(read_body(TRIANGLE_BUFFER "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":6}],"
	                "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":2,\"type\":\"VEC3\"},"
	                "{\"bufferView\":1,\"componentType\":5123,\"count\":3,\"type\":\"SCALAR\"}],"
	                "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1}]}]}", &err) == MLOD_ERR_PARSE);
	CHECK(strstr(err.message, "mesh 0 primitive 0: index 2 is 2, out of range"));
	CHECK(read_body(TRIANGLE_BUFFER "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
	                "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
	                "{\"bufferView\":0,\"componentType\":5126,\"count\":2,\"type\":\"VEC3\"}],"
	                "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1}}]}]}", &err) == MLOD_ERR_PARSE);
	CHECK(strstr(err.message, "NORMAL has 2 elements, POSITION has 3"));
	/* The same triangle, well formed, reads. */
	CHECK(read_body(TRIANGLE_BUFFER "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":6}],"
	                "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
	                "{\"bufferView\":1,\"componentType\":5123,\"count\":3,\"type\":\"SCALAR\"}],"
	                "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1}]}],"
	                "\"nodes\":[{\"mesh\":0}]}", &err) == MLOD_OK);
}

/* A channel without a target node (KHR_animation_pointer's), which
 * tinygltf drops as it reads, is read and written back in its place: the
 * stages and mlod-pack -x kept 1 of these 2 channels. */
TEST(pointer_channel_kept)
{
	static const char text[] =
	    "{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"KHR_animation_pointer\"],"
	    "\"buffers\":[{\"byteLength\":16,\"uri\":\"data:application/octet-stream;base64,AAAAAAAAgD8AAAA/AACAPw==\"}],"
	    "\"bufferViews\":[{\"buffer\":0,\"byteLength\":8},{\"buffer\":0,\"byteOffset\":8,\"byteLength\":8}],"
	    "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":2,\"type\":\"SCALAR\",\"min\":[0],\"max\":[1]},"
	    "{\"bufferView\":1,\"componentType\":5126,\"count\":2,\"type\":\"SCALAR\"}],"
	    "\"materials\":[{}],\"nodes\":[{\"name\":\"n\"}],\"scenes\":[{\"nodes\":[0]}],"
	    "\"animations\":[{\"name\":\"a\",\"channels\":[{\"sampler\":0,\"target\":{\"path\":\"pointer\","
	    "\"extensions\":{\"KHR_animation_pointer\":{\"pointer\":\"/materials/0/alphaCutoff\"}}}},"
	    "{\"sampler\":0,\"target\":{\"node\":0,\"path\":\"scale\"}}],"
	    "\"samplers\":[{\"input\":0,\"output\":1}]}]}";
	mlod_gltf *doc = NULL;
	CHECK_OK(mlod_gltf_read(text, strlen(text), NULL, &doc, &terr));
	if (!doc)
		return;
	void *out = NULL;
	size_t size = 0;
	CHECK_OK(mlod_gltf_write(doc, 0, &out, &size, &terr));
	char *json = calloc(size + 1, 1);
	if (json && out) {
		memcpy(json, out, size);
		const char *p = strstr(json, "\"pointer\": \"/materials/0/alphaCutoff\"");
		CHECK_MSG(p != NULL, "the pointer channel is lost: %s", json);
		CHECK(p && strstr(p, "\"path\": \"scale\"")); /* in its place, before channel 1 */
		CHECK(!strstr(json, "\"node\": -1"));
	}
	free(json);
	mlod_free(out);
	mlod_gltf_free(doc);
}

/* A stripped document keeps no emptied buffer (byteLength 0, an empty
 * data: URI), which no reader takes back: its glb reads again; and a DOC
 * holding such buffers, with other members, as older packs do, reads
 * through mlod_gltf_read_doc. */
TEST(strip_drops_emptied_buffers)
{
	static const char two[] = "{\"asset\":{\"version\":\"2.0\"},"
	                          "\"buffers\":[{\"byteLength\":44,\"uri\":\"data:application/octet-stream;base64,"
	                          "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAABAAIAAAA=\"},"
	                          "{\"byteLength\":44,\"name\":\"second\",\"uri\":\"data:application/octet-stream;base64,"
	                          "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAABAAIAAAA=\"}],"
	                          "\"bufferViews\":[{\"buffer\":1,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":6}],"
	                          "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\","
	                          "\"min\":[0,0,0],\"max\":[1,1,0]},"
	                          "{\"bufferView\":1,\"componentType\":5123,\"count\":3,\"type\":\"SCALAR\"}],"
	                          "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1}]}],"
	                          "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]}";
	mlod_gltf *doc = NULL, *back = NULL;
	CHECK_OK(mlod_gltf_read(two, strlen(two), NULL, &doc, &terr));
	if (!doc)
		return;
	CHECK_OK(mlod_gltf_strip_levels(doc, NULL, 0, NULL, &terr));
	void *glb = NULL;
	size_t size = 0;
	CHECK_OK(mlod_gltf_write(doc, 1, &glb, &size, &terr));
	if (glb) {
		const char *json = (const char *)glb + 20;
		size_t n = size >= 20 ? ((const unsigned char *)glb)[12] | ((const unsigned char *)glb)[13] << 8 : 0;
		int empty = 0;
		for (size_t i = 0; i + 14 <= n; i++)
			empty |= memcmp(json + i, "\"byteLength\":0", 14) == 0;
		CHECK_MSG(!empty, "a buffer with byteLength 0 is written: %.*s", (int)n, json);
		CHECK_OK(mlod_gltf_read_doc(glb, size, &back, &terr));
		mlod_gltf_free(back);
		back = NULL;
	}
	mlod_free(glb);
	mlod_gltf_free(doc);
	/* Older DOCs: an emptied buffer 0 without a BIN chunk, one with a name
	 * and an empty data: URI after it. */
	static const char old_json[] = "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":0},"
	                               "{\"byteLength\":0,\"name\":\"b\",\"uri\":\"data:application/octet-stream;base64,\"}],"
	                               "\"nodes\":[{\"name\":\"n\"}]}";
	size_t jn = (strlen(old_json) + 3) / 4 * 4;
	unsigned char old[512];
	memset(old, ' ', sizeof old);
	uint32_t head[5] = {0x46546C67, 2, (uint32_t)(20 + jn), (uint32_t)jn, 0x4E4F534A};
	for (int i = 0; i < 5; i++)
		for (int k = 0; k < 4; k++)
			old[i * 4 + k] = (unsigned char)(head[i] >> (8 * k));
	memcpy(old + 20, old_json, strlen(old_json));
	mlod_error err;
	CHECK(mlod_gltf_read(old, 20 + jn, NULL, &back, &err) != MLOD_OK);
	CHECK_OK(mlod_gltf_read_doc(old, 20 + jn, &back, &terr));
	CHECK(back && mlod_gltf_count(back, MLOD_GLTF_NODE) == 1);
	mlod_gltf_free(back);
}

/* Properties of the wrong JSON type or range, which tinygltf skips or
 * reads as 0: MLOD_ERR_PARSE naming the property. */
TEST(wrong_types)
{
	static const struct {
		const char *body, *message;
	} cases[] = {
		{"\"meshes\":[{\"primitives\":{\"attributes\":{}}}]}", "meshes[0].primitives: not an array"},
		{"\"scenes\":[{\"name\":42}]}", "scenes[0].name: not a string"},
		{"\"nodes\":[{\"mesh\":-1}]}", "nodes[0].mesh: not an index (a non-negative integer)"},
		{"\"nodes\":[{\"translation\":[0,\"1\",0]}]}", "nodes[0].translation[1]: not a number"},
		{"\"nodes\":[{\"extensions\":{\"KHR_x\":\"no\"}}]}", "nodes[0].extensions.KHR_x: not an object"},
		{TRIANGLE_BUFFER "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
		 "\"accessors\":[{\"bufferView\":0,\"byteOffset\":-8,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}]}",
		 "accessors[0].byteOffset: not a non-negative integer"},
		{"\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":\"0\"}}]}]}",
		 "meshes[0].primitives[0].attributes.POSITION: not an index (a non-negative integer)"},
		{"\"meshes\":[{\"primitives\":[{\"attributes\":{},\"mode\":9}]}]}",
		 "meshes[0].primitives[0].mode: not a primitive mode (0 to 6)"},
	};
	for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
		mlod_error err = {0};
		mlod_result r = read_body(cases[i].body, &err);
		CHECK_MSG(r == MLOD_ERR_PARSE && strcmp(err.message, cases[i].message) == 0, "case %zu: %d \"%s\"", i,
		          (int)r, err.message);
	}
}

TEST(unsupported)
{
	mlod_error err;
	/* (Draco and meshopt compression are read: test_gltf_decompress.c) */
	CHECK(read_body("\"extensionsRequired\":[\"VENDOR_magic\"]}", &err) == MLOD_ERR_UNSUPPORTED);
	CHECK(strstr(err.message, "VENDOR_magic"));
	CHECK(read_body("\"extensionsRequired\":[\"KHR_materials_unlit\"]}", &err) == MLOD_OK);
	CHECK(mlod_gltf_read("{\"asset\":{\"version\":\"1.0\"}}", 27, NULL, &(mlod_gltf *){ NULL }, &err) ==
	      MLOD_ERR_UNSUPPORTED);
	/* External files need a base directory, and must stay inside it. */
	CHECK(read_body("\"buffers\":[{\"byteLength\":4,\"uri\":\"data.bin\"}]}", &err) == MLOD_ERR_IO);
	mlod_gltf *doc = NULL;
	const char *up = "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":4,\"uri\":\"../x.bin\"}]}";
	CHECK(mlod_gltf_read(up, strlen(up), "samples", &doc, &err) == MLOD_ERR_UNSUPPORTED && doc == NULL);
	const char *missing = "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":4,\"uri\":\"nope.bin\"}]}";
	CHECK(mlod_gltf_read(missing, strlen(missing), "samples", &doc, &err) == MLOD_ERR_IO && doc == NULL);
}

/* An external buffer next to a .gltf is read through base_dir. */
TEST(external_buffer)
{
	size_t size;
	void *robot = test_read_file(ROBOT, &size);
	CHECK(robot != NULL);
	free(robot);
	const char *text = "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":%zu,\"uri\":\"RobotExpressive.glb\"}],"
	                   "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":4}],"
	                   "\"accessors\":[{\"bufferView\":0,\"componentType\":5121,\"count\":4,\"type\":\"SCALAR\"}]}";
	char buf[512];
	snprintf(buf, sizeof buf, text, size);
	mlod_gltf *doc = NULL;
	CHECK_OK(mlod_gltf_read(buf, strlen(buf), "samples", &doc, &terr));
	void *glb = NULL;
	size_t glb_size = 0;
	mlod_result r = mlod_gltf_write(doc, 1, &glb, &glb_size, &terr);
	mlod_gltf_free(doc);
	int embedded = r == MLOD_OK && glb_size > size;
	mlod_free(glb);
	CHECK(embedded);
}

/* ---------------------------------------------------------------- */
/* Development data                                                  */
/* ---------------------------------------------------------------- */

TEST(shared_data)
{
	NEED_SHARED();
	const char *dir = getenv("MLOD_SHARED_DATA");
	DIR *d = opendir(dir);
	CHECK_MSG(d != NULL, "cannot open %s", dir);
	struct dirent *e;
	int files = 0;
	const char *problem = NULL;
	while (!problem && (e = readdir(d)) != NULL) {
		size_t n = strlen(e->d_name);
		if (n < 4 || strcmp(e->d_name + n - 4, ".glb") != 0)
			continue;
		char path[1024];
		snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
		problem = roundtrip_file(path);
		files++;
	}
	closedir(d);
	CHECK_MSG(problem == NULL, "%s", problem);
	CHECK(files > 0);
}

int main(void)
{
	RUN(read_robot);
	RUN(roundtrip_robot);
	RUN(write_is_faithful);
	RUN(gltf_text_roundtrip);
	RUN(images_kept);
	RUN(extras);
	RUN(pack_doc_edits);
	RUN(add_objects);
	RUN(from_character);
	RUN(robot_via_character);
	RUN(bvh_via_gltf);
	RUN(empty_objects);
	RUN(reskinned_mesh);
	RUN(level_in_place);
	RUN(morph_channels_and_transforms);
	RUN(decode_layouts);
	RUN(empty_and_garbage);
	RUN(truncated_glb);
	RUN(mutated_glb);
	RUN(bad_references);
	RUN(pointer_channel_kept);
	RUN(strip_drops_emptied_buffers);
	RUN(wrong_types);
	RUN(duplicate_targets);
	RUN(unsupported);
	RUN(external_buffer);
	RUN(shared_data);
	TEST_EXIT();
}
