/*
 * gen_tubeman.c: generates "tubeman", the procedural skinned character of
 * the test suite (samples/tubeman.glb).
 *
 *   gen_tubeman in.bvh out.glb [--segments N] [--rings N]
 *
 * It reads a BVH skeleton and clip (the CMU walk) and sweeps a capsule
 * around every bone: joint -> child joint and joint -> End Site. Each
 * capsule is a closed manifold (a tube with hemispherical ends), its radius
 * proportional to the bone's length and clamped to a range that depends on
 * the body part the joint's name suggests (thick torso, thin fingers).
 * Bones of zero length are skipped.
 *
 * Each capsule follows the joint at its proximal end; around that end its
 * vertices blend with the parent joint through a smoothstep that is 50/50
 * at the joint and reaches the bone's own joint a quarter of the bone's
 * length along it. Vertices carry normals and one UV set (u around the
 * bone, v along it) with duplicated seam and pole vertices, as real assets
 * have. Everything goes into one mesh with one primitive and a plain
 * material, skinned by one skin over all joints whose inverse bind matrices
 * invert the rest pose; the BVH clip becomes the animation "walk". The
 * output is deterministic (byte-identical on every run) and is written
 * atomically (out.glb.tmp.PID, then renamed).
 *
 * --segments is the number of vertices around each ring (default 12), and
 * --rings the number of rings along each bone's straight part, both ends
 * included (default 8); each hemispherical end gets segments / 4 latitude
 * steps. The defaults give about 7,800 triangles on the CMU skeleton.
 */
#define _POSIX_C_SOURCE 200809L

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "mlod.h"

#define PI 3.14159265358979323846

/* ------------------------------------------------------------------ */
/* Bones and their radii                                               */
/* ------------------------------------------------------------------ */

typedef struct bone {
	int joint;       /* the joint at the proximal end, which drives the bone */
	int parent;      /* its parent joint (blended near the proximal end), or -1 */
	double a[3];     /* proximal end (the joint's rest position) */
	double b[3];     /* distal end (child joint or End Site) */
	double length;
	double radius;
} bone;

/* Body parts, told apart by the joint's name; each has a radius rule. */
typedef struct part_rule {
	const char *const *keys; /* name substrings, lower case; NULL: the default */
	double k;                /* radius = k * bone length ... */
	double lo, hi;           /* ... clamped to [lo, hi] * skeleton extent */
} part_rule;

static const char *const extremity_keys[] = { "finger", "thumb", "index", "middle", "ring",
					      "pinky", "toe", "hand", NULL };
static const char *const head_keys[] = { "head", NULL };
static const char *const neck_keys[] = { "neck", NULL };
static const char *const torso_keys[] = { "spine", "back", "chest", "torso", "abdomen",
					  "pelvis", NULL };
static const char *const hip_keys[] = { "hip", NULL };
static const char *const thigh_keys[] = { "upleg", "thigh", NULL };
static const char *const foot_keys[] = { "foot", NULL };

/* Checked in this order; the last rule (limbs) catches everything else. */
static const part_rule part_rules[] = {
	{ extremity_keys, 0.30, 0.008, 0.020 },
	{ head_keys, 0.90, 0.050, 0.075 },
	{ neck_keys, 0.40, 0.025, 0.035 },
	{ torso_keys, 0.90, 0.060, 0.080 },
	{ hip_keys, 0.50, 0.045, 0.065 },
	{ thigh_keys, 0.20, 0.030, 0.055 },
	{ foot_keys, 0.30, 0.020, 0.035 },
	{ NULL, 0.16, 0.020, 0.045 },
};

/* Does name contain key (lower case), ignoring case? */
static int name_has(const char *name, const char *key)
{
	size_t n = strlen(key);
	for (const char *p = name; *p; p++) {
		size_t i = 0;
		while (i < n && p[i] && tolower((unsigned char)p[i]) == key[i])
			i++;
		if (i == n)
			return 1;
	}
	return 0;
}

/* The rule for a joint's name: the first whose keys it contains. */
static const part_rule *part_of(const char *joint_name)
{
	size_t count = sizeof part_rules / sizeof part_rules[0];
	for (size_t i = 0; i + 1 < count; i++)
		for (const char *const *key = part_rules[i].keys; *key; key++)
			if (name_has(joint_name, *key))
				return &part_rules[i];
	return &part_rules[count - 1];
}

static double bone_radius(const char *joint_name, double length, double size)
{
	const part_rule *rule = part_of(joint_name);
	double r = rule->k * length;
	if (r < rule->lo * size)
		r = rule->lo * size;
	if (r > rule->hi * size)
		r = rule->hi * size;
	return r;
}

/* Appends the bone a -> b of joint j unless it is (nearly) zero-length. */
static void add_bone(bone *bones, int *count, const mlod_skeleton *s, int j,
		     const double a[3], const double b[3], double size)
{
	double d[3] = { b[0] - a[0], b[1] - a[1], b[2] - a[2] };
	double length = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
	if (!(length > 1e-3 * size))
		return;
	bone *bn = &bones[(*count)++];
	bn->joint = j;
	bn->parent = s->joints[j].parent;
	memcpy(bn->a, a, sizeof bn->a);
	memcpy(bn->b, b, sizeof bn->b);
	bn->length = length;
	bn->radius = bone_radius(s->joints[j].name, length, size);
}

/* Every bone of the skeleton in joint order (children, then the End Site).
 * bones must hold joint_count * 2 entries (each joint is at most once a
 * child, plus at most one End Site). Returns the number of bones. */
static int collect_bones(const mlod_skeleton *s, const mlod_mat4 *world, double size,
			 bone *bones)
{
	int count = 0;
	for (int j = 0; j < s->joint_count; j++) {
		const float *m = world[j].m;
		double a[3] = { m[12], m[13], m[14] };
		for (int c = j + 1; c < s->joint_count; c++) {
			if (s->joints[c].parent != j)
				continue;
			const float *mc = world[c].m;
			double b[3] = { mc[12], mc[13], mc[14] };
			add_bone(bones, &count, s, j, a, b, size);
		}
		if (s->joints[j].has_end_site) {
			mlod_v3 e = mlod_mat4_point(&world[j], s->joints[j].end_site);
			double b[3] = { e.x, e.y, e.z };
			add_bone(bones, &count, s, j, a, b, size);
		}
	}
	return count;
}

/* ------------------------------------------------------------------ */
/* Capsules                                                            */
/* ------------------------------------------------------------------ */

typedef struct tube_shape {
	int segments;    /* vertices around a ring (plus one duplicated seam vertex) */
	int rings;       /* rings along the straight part, both ends included */
	int cap_steps;   /* latitude steps of a hemispherical end */
} tube_shape;

/* One latitude of a capsule: where along the bone and how far out. */
typedef struct latitude {
	double s;        /* distance along the bone from its proximal end */
	double radius;   /* ring radius */
	double axial;    /* axial component of the normal */
	double radial;   /* radial component of the normal */
	double v;        /* texture coordinate along the capsule */
} latitude;

static int tube_ring_count(const tube_shape *sh)
{
	return 2 * (sh->cap_steps - 1) + sh->rings;
}

static int tube_vertex_count(const tube_shape *sh)
{
	return tube_ring_count(sh) * (sh->segments + 1) + 2 * sh->segments;
}

static int tube_triangle_count(const tube_shape *sh)
{
	return 2 * sh->segments * tube_ring_count(sh);
}

/* The rings of a capsule from its proximal to its distal pole (poles
 * excluded): the proximal hemisphere, the straight part, the distal one. */
static void tube_latitudes(const tube_shape *sh, double length, double r, latitude *lat)
{
	int n = 0;
	double arc = PI * r + length;
	for (int i = 1; i < sh->cap_steps; i++) {
		double t = 0.5 * PI * i / sh->cap_steps; /* angle from the pole */
		lat[n++] = (latitude){ -r * cos(t), r * sin(t), -cos(t), sin(t), r * t / arc };
	}
	for (int i = 0; i < sh->rings; i++) {
		double s = length * i / (sh->rings - 1);
		lat[n++] = (latitude){ s, r, 0.0, 1.0, (0.5 * PI * r + s) / arc };
	}
	for (int i = sh->cap_steps - 1; i >= 1; i--) {
		double t = 0.5 * PI * i / sh->cap_steps;
		lat[n++] = (latitude){ length + r * cos(t), r * sin(t), cos(t), sin(t),
				       1.0 - r * t / arc };
	}
}

static double smoothstep(double e0, double e1, double x)
{
	double t = (x - e0) / (e1 - e0);
	t = t < 0.0 ? 0.0 : t > 1.0 ? 1.0 : t;
	return t * t * (3.0 - 2.0 * t);
}

/* The mesh being built: one primitive's arrays and fill counters. */
typedef struct builder {
	mlod_primitive *p;
	int vertices;
	int indices;
} builder;

/* Appends one vertex; w is the weight of the bone's own joint, the rest
 * going to its parent. Influences are listed heaviest first; unused slots
 * are joint 0 with weight 0. */
static void put_vertex(builder *bd, const bone *bn, const double pos[3], const double nrm[3],
		       double u, double v, double w)
{
	mlod_primitive *p = bd->p;
	int i = bd->vertices++;
	for (int c = 0; c < 3; c++) {
		p->positions[3 * i + c] = (float)pos[c];
		p->normals[3 * i + c] = (float)nrm[c];
	}
	p->uvs[0][2 * i] = (float)u;
	p->uvs[0][2 * i + 1] = (float)v;
	uint16_t *jt = &p->joints[0][4 * i];
	float *wt = &p->weights[0][4 * i];
	memset(jt, 0, 4 * sizeof *jt);
	memset(wt, 0, 4 * sizeof *wt);
	float wj = (float)w;
	if (bn->parent < 0 || wj >= 1.0f) {
		jt[0] = (uint16_t)bn->joint;
		wt[0] = 1.0f;
	} else if (wj <= 0.0f) {
		jt[0] = (uint16_t)bn->parent;
		wt[0] = 1.0f;
	} else {
		float wp = 1.0f - wj;
		int own_first = wj >= wp;
		jt[0] = (uint16_t)(own_first ? bn->joint : bn->parent);
		jt[1] = (uint16_t)(own_first ? bn->parent : bn->joint);
		wt[0] = own_first ? wj : wp;
		wt[1] = own_first ? wp : wj;
	}
}

static void put_triangle(builder *bd, int a, int b, int c)
{
	uint32_t *t = &bd->p->indices[bd->indices];
	t[0] = (uint32_t)a;
	t[1] = (uint32_t)b;
	t[2] = (uint32_t)c;
	bd->indices += 3;
}

/* Emits the capsule of one bone: seam-duplicated rings between two poles
 * whose vertex is repeated once per segment (each copy with its own u).
 * Triangles wind counter-clockwise seen from outside. */
static void emit_tube(builder *bd, const tube_shape *sh, const bone *bn, latitude *lat)
{
	int seg = sh->segments;
	int nrings = tube_ring_count(sh);
	double d[3], e1[3], e2[3];
	for (int c = 0; c < 3; c++)
		d[c] = (bn->b[c] - bn->a[c]) / bn->length;

	/* e1: the world axis least aligned with the bone, made perpendicular
	 * to it; e2 = d x e1, so that (e1, e2, d) is right-handed. */
	int axis = 0;
	for (int c = 1; c < 3; c++)
		if (fabs(d[c]) < fabs(d[axis]))
			axis = c;
	for (int c = 0; c < 3; c++)
		e1[c] = (c == axis ? 1.0 : 0.0) - d[c] * d[axis];
	double len1 = sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
	for (int c = 0; c < 3; c++)
		e1[c] /= len1;
	e2[0] = d[1] * e1[2] - d[2] * e1[1];
	e2[1] = d[2] * e1[0] - d[0] * e1[2];
	e2[2] = d[0] * e1[1] - d[1] * e1[0];

	tube_latitudes(sh, bn->length, bn->radius, lat);
	double blend = 0.25 * bn->length;

	/* The copies of the proximal pole, then of the distal one, then the rings. */
	int first = bd->vertices;
	for (int pole = 0; pole < 2; pole++) {
		double s = pole ? bn->length + bn->radius : -bn->radius;
		double sign = pole ? 1.0 : -1.0;
		double pos[3], nrm[3];
		for (int c = 0; c < 3; c++) {
			pos[c] = bn->a[c] + d[c] * s;
			nrm[c] = d[c] * sign;
		}
		double w = smoothstep(-blend, blend, s);
		for (int k = 0; k < seg; k++)
			put_vertex(bd, bn, pos, nrm, (k + 0.5) / seg, pole ? 1.0 : 0.0, w);
	}
	int ring0 = bd->vertices;
	for (int i = 0; i < nrings; i++) {
		const latitude *l = &lat[i];
		double w = smoothstep(-blend, blend, l->s);
		for (int k = 0; k <= seg; k++) {
			/* The seam column k == seg repeats the position of k == 0. */
			double phi = 2.0 * PI * (k % seg) / seg;
			double cp = cos(phi), sp = sin(phi);
			double pos[3], nrm[3];
			for (int c = 0; c < 3; c++) {
				double out = e1[c] * cp + e2[c] * sp;
				pos[c] = bn->a[c] + d[c] * l->s + out * l->radius;
				nrm[c] = d[c] * l->axial + out * l->radial;
			}
			put_vertex(bd, bn, pos, nrm, (double)k / seg, l->v, w);
		}
	}

	int row = seg + 1;
	int last = ring0 + (nrings - 1) * row;
	for (int k = 0; k < seg; k++) {
		put_triangle(bd, first + k, ring0 + k + 1, ring0 + k);
		put_triangle(bd, last + k, last + k + 1, first + seg + k);
	}
	for (int i = 0; i + 1 < nrings; i++)
		for (int k = 0; k < seg; k++) {
			int a = ring0 + i * row + k, b = a + 1;
			int c = b + row, e = a + row;
			put_triangle(bd, a, b, c);
			put_triangle(bd, a, c, e);
		}
}

/* ------------------------------------------------------------------ */
/* The character                                                       */
/* ------------------------------------------------------------------ */

static char *copy_string(const char *s)
{
	size_t n = strlen(s) + 1;
	char *d = malloc(n);
	if (d)
		memcpy(d, s, n);
	return d;
}

/* Adds the tube mesh, its skin and its instance to a character read from
 * BVH. */
static mlod_result build_tubeman(mlod_character *c, const tube_shape *sh, int *out_bones,
				 mlod_error *err)
{
	mlod_skeleton *s = &c->skeleton;
	int n = s->joint_count;
	if (n <= 0 || n > 65535)
		return mlod_fail(err, MLOD_ERR_UNSUPPORTED, "skeleton has %d joints", n);
	if (c->mesh_count || s->skin_count)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "the input already has meshes or skins");

	mlod_result rc = MLOD_ERR_NOMEM;
	mlod_trs *local = malloc((size_t)n * sizeof *local);
	mlod_mat4 *world = malloc((size_t)n * sizeof *world);
	bone *bones = malloc((size_t)n * 2 * sizeof *bones);
	latitude *lat = malloc((size_t)tube_ring_count(sh) * sizeof *lat);
	if (!local || !world || !bones || !lat)
		goto done;
	mlod_pose_rest(s, local);
	mlod_pose_world(s, local, world);

	/* Proportions against the largest extent (the arm span of the T-pose),
	 * which the committed sample was generated with. */
	double size = mlod_skeleton_extent(s);
	int nbones = collect_bones(s, world, size, bones);
	if (nbones == 0) {
		rc = mlod_fail(err, MLOD_ERR_UNSUPPORTED, "the skeleton has no bone of non-zero length");
		goto done;
	}

	/* The skin: every joint, bound in the rest pose. */
	s->skins = calloc(1, sizeof *s->skins);
	if (!s->skins)
		goto done;
	s->skin_count = 1;
	mlod_skin *skin = &s->skins[0];
	skin->gltf_index = -1;
	skin->name = copy_string("tubeman");
	skin->joints = malloc((size_t)n * sizeof *skin->joints);
	skin->inverse_bind = malloc((size_t)n * sizeof *skin->inverse_bind);
	if (!skin->name || !skin->joints || !skin->inverse_bind)
		goto done;
	skin->joint_count = n;
	for (int j = 0; j < n; j++) {
		skin->joints[j] = j;
		if (mlod_mat4_invert(&world[j], &skin->inverse_bind[j]) != 0) {
			rc = mlod_fail(err, MLOD_ERR_PARSE, "joint %d has a singular rest matrix", j);
			goto done;
		}
	}

	/* The mesh: one primitive of capsules. */
	long vertices = (long)nbones * tube_vertex_count(sh);
	long triangles = (long)nbones * tube_triangle_count(sh);
	if (vertices > 10000000 || triangles > 20000000) {
		rc = mlod_fail(err, MLOD_ERR_LIMIT, "%ld vertices is too many", vertices);
		goto done;
	}
	c->meshes = calloc(1, sizeof *c->meshes);
	if (!c->meshes)
		goto done;
	c->mesh_count = 1;
	mlod_mesh *mesh = &c->meshes[0];
	mesh->gltf_index = -1;
	mesh->name = copy_string("tubeman");
	mesh->primitives = calloc(1, sizeof *mesh->primitives);
	if (!mesh->name || !mesh->primitives)
		goto done;
	mesh->primitive_count = 1;
	mlod_primitive *p = &mesh->primitives[0];
	p->mode = 4;
	p->material = -1;
	p->vertex_count = (int)vertices;
	p->index_count = (int)(3 * triangles);
	p->uv_set_count = 1;
	p->weight_set_count = 1;
	p->positions = malloc((size_t)vertices * 3 * sizeof(float));
	p->normals = malloc((size_t)vertices * 3 * sizeof(float));
	p->uvs[0] = malloc((size_t)vertices * 2 * sizeof(float));
	p->joints[0] = malloc((size_t)vertices * 4 * sizeof(uint16_t));
	p->weights[0] = malloc((size_t)vertices * 4 * sizeof(float));
	p->indices = malloc((size_t)triangles * 3 * sizeof(uint32_t));
	if (!p->positions || !p->normals || !p->uvs[0] || !p->joints[0] || !p->weights[0] ||
	    !p->indices)
		goto done;
	builder bd = { p, 0, 0 };
	for (int i = 0; i < nbones; i++)
		emit_tube(&bd, sh, &bones[i], lat);

	/* One skinned instance of it. */
	c->instances = calloc(1, sizeof *c->instances);
	if (!c->instances)
		goto done;
	c->instance_count = 1;
	c->instances[0] = (mlod_instance){ 0, -1, 0, -1, mlod_mat4_identity() };

	if (c->clip_count > 0) {
		char *name = copy_string("walk");
		if (!name)
			goto done;
		free(c->clips[0].name);
		c->clips[0].name = name;
	}
	*out_bones = nbones;
	rc = mlod_character_validate(c, err);
done:
	if (rc == MLOD_ERR_NOMEM)
		mlod_fail(err, rc, "out of memory");
	free(local);
	free(world);
	free(bones);
	free(lat);
	return rc;
}

/* ------------------------------------------------------------------ */
/* The material                                                        */
/* ------------------------------------------------------------------ */

/* A plain clay-coloured PBR material. */
static const char material_json[] =
	"\"materials\":[{\"name\":\"tubeman\",\"pbrMetallicRoughness\":{"
	"\"baseColorFactor\":[0.8,0.62,0.45,1],\"metallicFactor\":0,\"roughnessFactor\":0.6}}],";
static const char material_ref[] = "\"material\":0,";

static uint32_t get_le32(const unsigned char *p)
{
	return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static void put_le32(unsigned char *p, uint32_t v)
{
	for (int i = 0; i < 4; i++)
		p[i] = (unsigned char)(v >> (8 * i));
}

/* Offset of the only occurrence of needle in hay, or -1 when it occurs
 * zero or several times. */
static long find_once(const char *hay, size_t n, const char *needle)
{
	size_t m = strlen(needle);
	long found = -1;
	for (size_t i = 0; i + m <= n; i++)
		if (!memcmp(hay + i, needle, m)) {
			if (found >= 0)
				return -1;
			found = (long)i;
		}
	return found;
}

/* mlod_gltf_from_character makes no materials (the character model has
 * none) and the API has no call to add one, so the material is spliced
 * into the compact JSON chunk of the document's glb: the "materials" array
 * before "meshes" and a reference in the only primitive. The result is
 * read back into *doc, which checks it and normalises its layout. */
static mlod_result add_material(mlod_gltf **doc, mlod_error *err)
{
	void *glb = NULL;
	size_t size = 0;
	mlod_result rc = mlod_gltf_write(*doc, 1, &glb, &size, err);
	if (rc != MLOD_OK)
		return rc;
	const unsigned char *in = glb;
	const char *json = (const char *)in + 20;
	size_t json_size = size >= 20 ? get_le32(in + 12) : 0;
	long meshes = -1, prims = -1;
	if (size >= 20 && !memcmp(in, "glTF", 4) && !memcmp(in + 16, "JSON", 4) &&
	    json_size <= size - 20) {
		meshes = find_once(json, json_size, "\"meshes\":[");
		prims = find_once(json, json_size, "\"primitives\":[{");
	}
	if (meshes < 0 || prims < meshes) {
		mlod_free(glb);
		return mlod_fail(err, MLOD_ERR_UNSUPPORTED,
				 "cannot place the material: the glb is not laid out as expected");
	}
	size_t at_ref = (size_t)prims + strlen("\"primitives\":[{");
	size_t grown = json_size + strlen(material_json) + strlen(material_ref);
	size_t padded = (grown + 3) / 4 * 4;
	size_t bin_size = size - 20 - json_size;
	size_t out_size = 20 + padded + bin_size;
	unsigned char *out = malloc(out_size);
	if (!out) {
		mlod_free(glb);
		return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
	}
	memcpy(out, in, 20);
	put_le32(out + 8, (uint32_t)out_size);
	put_le32(out + 12, (uint32_t)padded);
	char *o = (char *)out + 20;
	size_t k = 0;
	memcpy(o + k, json, (size_t)meshes);
	k += (size_t)meshes;
	memcpy(o + k, material_json, strlen(material_json));
	k += strlen(material_json);
	memcpy(o + k, json + meshes, at_ref - (size_t)meshes);
	k += at_ref - (size_t)meshes;
	memcpy(o + k, material_ref, strlen(material_ref));
	k += strlen(material_ref);
	memcpy(o + k, json + at_ref, json_size - at_ref);
	k += json_size - at_ref;
	/* The old chunk's trailing padding spaces stay inside; top up to 4. */
	memset(o + k, ' ', padded - k);
	memcpy(out + 20 + padded, in + 20 + json_size, bin_size);
	mlod_free(glb);

	mlod_gltf *with_material = NULL;
	rc = mlod_gltf_read(out, out_size, NULL, &with_material, err);
	free(out);
	if (rc != MLOD_OK)
		return rc;
	mlod_gltf_free(*doc);
	*doc = with_material;
	return MLOD_OK;
}

/* ------------------------------------------------------------------ */
/* Files                                                               */
/* ------------------------------------------------------------------ */

static void *read_file(const char *path, size_t *size)
{
	FILE *f = fopen(path, "rb");
	if (!f)
		return NULL;
	size_t cap = 1 << 16, n = 0;
	char *buf = malloc(cap);
	while (buf) {
		if (n == cap) {
			char *bigger = realloc(buf, cap * 2);
			if (!bigger) {
				free(buf);
				buf = NULL;
				break;
			}
			buf = bigger;
			cap *= 2;
		}
		size_t got = fread(buf + n, 1, cap - n, f);
		if (got == 0)
			break;
		n += got;
	}
	if (buf && ferror(f)) {
		free(buf);
		buf = NULL;
	}
	fclose(f);
	*size = n;
	return buf;
}

/* Writes to path.tmp.PID, then renames it over path. */
static int write_file_atomic(const char *path, const void *data, size_t size)
{
	size_t n = strlen(path) + 32;
	char *tmp = malloc(n);
	if (!tmp)
		return -1;
	snprintf(tmp, n, "%s.tmp.%ld", path, (long)getpid());
	FILE *f = fopen(tmp, "wb");
	int ok = f != NULL;
	if (ok) {
		ok = fwrite(data, 1, size, f) == size;
		ok = (fclose(f) == 0) && ok;
	}
	if (ok)
		ok = rename(tmp, path) == 0;
	if (!ok)
		remove(tmp);
	free(tmp);
	return ok ? 0 : -1;
}

static int parse_count(const char *s, int lo, int hi, int *out)
{
	char *end;
	long v = strtol(s, &end, 10);
	if (end == s || *end || v < lo || v > hi)
		return -1;
	*out = (int)v;
	return 0;
}

static void usage(void)
{
	fprintf(stderr, "usage: gen_tubeman in.bvh out.glb [--segments N] [--rings N]\n"
			"  --segments N  vertices around each ring, 3..256 (default 12)\n"
			"  --rings N     rings along each bone, ends included, 2..256 (default 8)\n");
}

int main(int argc, char **argv)
{
	const char *in = NULL, *out = NULL;
	tube_shape sh = { 12, 8, 0 };
	for (int i = 1; i < argc; i++) {
		if (!strcmp(argv[i], "--segments") || !strcmp(argv[i], "--rings")) {
			int *dst = argv[i][2] == 's' ? &sh.segments : &sh.rings;
			int lo = argv[i][2] == 's' ? 3 : 2;
			if (i + 1 >= argc || parse_count(argv[i + 1], lo, 256, dst) != 0) {
				fprintf(stderr, "gen_tubeman: %s needs a number from %d to 256\n",
					argv[i], lo);
				return 2;
			}
			i++;
		} else if (!strcmp(argv[i], "-h") || !strcmp(argv[i], "--help")) {
			usage();
			return 0;
		} else if (argv[i][0] == '-' && argv[i][1]) {
			fprintf(stderr, "gen_tubeman: unknown option %s\n", argv[i]);
			usage();
			return 2;
		} else if (!in) {
			in = argv[i];
		} else if (!out) {
			out = argv[i];
		} else {
			usage();
			return 2;
		}
	}
	if (!in || !out) {
		usage();
		return 2;
	}
	sh.cap_steps = sh.segments / 4 < 2 ? 2 : sh.segments / 4;

	size_t size;
	void *text = read_file(in, &size);
	if (!text) {
		fprintf(stderr, "gen_tubeman: cannot read %s\n", in);
		return 1;
	}
	mlod_error err = { MLOD_OK, "" };
	mlod_character c;
	memset(&c, 0, sizeof c);
	mlod_gltf *doc = NULL;
	void *glb = NULL;
	size_t glb_size = 0;
	int nbones = 0;
	mlod_result rc = mlod_bvh_read(text, size, &c, &err);
	free(text);
	if (rc == MLOD_OK)
		rc = build_tubeman(&c, &sh, &nbones, &err);
	if (rc == MLOD_OK)
		rc = mlod_gltf_from_character(&c, &doc, &err);
	if (rc == MLOD_OK)
		rc = add_material(&doc, &err);
	if (rc == MLOD_OK)
		rc = mlod_gltf_write(doc, 1, &glb, &glb_size, &err);
	if (rc != MLOD_OK) {
		fprintf(stderr, "gen_tubeman: %s: %s\n", in, err.message);
		mlod_gltf_free(doc);
		mlod_character_free(&c);
		return 1;
	}
	int status = 0;
	if (write_file_atomic(out, glb, glb_size) != 0) {
		fprintf(stderr, "gen_tubeman: cannot write %s\n", out);
		status = 1;
	} else {
		const mlod_primitive *p = &c.meshes[0].primitives[0];
		printf("%s: %d joints, %d bones, %d vertices, %d triangles, %d frames, %zu bytes\n",
		       out, c.skeleton.joint_count, nbones, p->vertex_count, p->index_count / 3,
		       c.clip_count ? c.clips[0].frame_count : 0, glb_size);
	}
	mlod_free(glb);
	mlod_gltf_free(doc);
	mlod_character_free(&c);
	return status;
}
