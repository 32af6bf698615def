/*
 * test_rt_bake.c: the runtime (libmlodrt) against the bake library
 * (libmlod) on the committed samples: the same character handed to the
 * runtime as decoded views (level 0 of every layer) must give the bake
 * side's pose (mlod_clip_sample + mlod_pose_world) and skinning
 * (mlod_skin_matrices + mlod_skin_primitive; rigid and static parts as
 * mlod_pose_character places them) within 1e-5 of the diagonal, at many
 * times of every clip. Primitives with more than one weight set are
 * outside the runtime's 4 influences and are counted, not compared.
 * With morph weights set per instance (mlod_rt_instance_set_morph_weights),
 * the runtime's output must equal the bake side's skinning of the
 * primitive whose positions carry the weighted morph target deltas; and
 * through a real pack (mlod_pack_write, codec none so level 0 keeps the
 * input's vertex order), within its quantisation, with the weights'
 * layout taken from the pack's coarsest level.
 */
#include "test.h"

#include "rt/mlod_rt.h"

/* The runtime's views of a bake-side character (level 0 only). */
typedef struct conv {
	mlod_pack_skeleton skel;
	mlod_pack_joint_rec *joints;
	const char **names;
	mlod_pack_skin_rec *skins;
	const char **skin_names;
	uint32_t **skin_joints;
	const float **ibm;
	mlod_pack_part *parts;
	const mlod_primitive **prims;
	float ***targets; /* per part: its targets' position deltas */
	mlod_pack_mesh mesh;
	mlod_pack_channel *chans;
	mlod_pack_motion *motions;
	mlod_rt_view_level skel_v, mesh_v, *mot_v;
	mlod_rt_views views;
	int skipped;
} conv;

static void conv_build(const mlod_character *c, conv *v)
{
	memset(v, 0, sizeof *v);
	const mlod_skeleton *s = &c->skeleton;
	v->joints = calloc((size_t)s->joint_count + 1, sizeof *v->joints);
	v->names = calloc((size_t)s->joint_count + 1, sizeof *v->names);
	for (int j = 0; j < s->joint_count; j++) {
		const mlod_joint *jt = &s->joints[j];
		mlod_pack_joint_rec *r = &v->joints[j];
		r->parent = jt->parent;
		r->t[0] = jt->rest.t.x, r->t[1] = jt->rest.t.y, r->t[2] = jt->rest.t.z;
		r->r[0] = jt->rest.r.x, r->r[1] = jt->rest.r.y, r->r[2] = jt->rest.r.z, r->r[3] = jt->rest.r.w;
		r->s[0] = jt->rest.s.x, r->s[1] = jt->rest.s.y, r->s[2] = jt->rest.s.z;
		memcpy(r->base, jt->base.m, sizeof r->base);
		r->node = jt->node;
		v->names[j] = jt->name;
	}
	v->skins = calloc((size_t)s->skin_count + 1, sizeof *v->skins);
	v->skin_names = calloc((size_t)s->skin_count + 1, sizeof *v->skin_names);
	v->skin_joints = calloc((size_t)s->skin_count + 1, sizeof *v->skin_joints);
	v->ibm = calloc((size_t)s->skin_count + 1, sizeof *v->ibm);
	for (int k = 0; k < s->skin_count; k++) {
		v->skins[k].joint_count = (uint32_t)s->skins[k].joint_count;
		v->skins[k].gltf_index = -1;
		v->skin_names[k] = s->skins[k].name;
		v->skin_joints[k] = calloc((size_t)s->skins[k].joint_count + 1, sizeof(uint32_t));
		for (int i = 0; i < s->skins[k].joint_count; i++)
			v->skin_joints[k][i] = (uint32_t)s->skins[k].joints[i];
		v->ibm[k] = s->skins[k].inverse_bind[0].m;
	}
	v->skel = (mlod_pack_skeleton){ (uint32_t)s->joint_count, v->joints, v->names, (uint32_t)s->skin_count,
	                                v->skins, v->skin_names, (const uint32_t **)v->skin_joints, v->ibm, NULL };
	/* Parts: instance then primitive order, triangles only. */
	int np = 0;
	for (int i = 0; i < c->instance_count; i++)
		np += c->meshes[c->instances[i].mesh].primitive_count;
	v->parts = calloc((size_t)np + 1, sizeof *v->parts);
	v->prims = calloc((size_t)np + 1, sizeof *v->prims);
	v->targets = calloc((size_t)np + 1, sizeof *v->targets);
	for (int i = 0; i < c->instance_count; i++) {
		const mlod_instance *in = &c->instances[i];
		const mlod_mesh *m = &c->meshes[in->mesh];
		for (int p = 0; p < m->primitive_count; p++) {
			const mlod_primitive *q = &m->primitives[p];
			if (q->mode != 4 || q->vertex_count <= 0)
				continue;
			if (in->skin >= 0 && q->weight_set_count != 1) {
				v->skipped++;
				continue;
			}
			mlod_pack_part *t = &v->parts[v->mesh.part_count];
			v->prims[v->mesh.part_count++] = q;
			t->rec.instance = (uint32_t)i;
			t->rec.skin = in->skin;
			t->rec.joint = in->skin >= 0 ? -1 : in->joint;
			memcpy(t->rec.offset, in->offset.m, sizeof t->rec.offset);
			t->rec.vertex_count = (uint32_t)q->vertex_count;
			t->positions = q->positions;
			t->normals = q->normals;
			if (in->skin >= 0)
				t->joints = q->joints[0], t->weights = q->weights[0];
			if (q->target_count > 0) {
				float **d = v->targets[v->mesh.part_count - 1] = calloc((size_t)q->target_count, sizeof *d);
				for (int k = 0; k < q->target_count; k++)
					d[k] = q->targets[k].positions;
				t->targets = d;
				t->rec.target_count = (uint32_t)q->target_count;
			}
		}
	}
	v->mesh.parts = v->parts;
	int nch = 0;
	for (int k = 0; k < c->clip_count; k++)
		nch += c->clips[k].channel_count;
	v->chans = calloc((size_t)nch + 1, sizeof *v->chans);
	v->motions = calloc((size_t)c->clip_count + 1, sizeof *v->motions);
	v->mot_v = calloc((size_t)c->clip_count + 1, sizeof *v->mot_v);
	nch = 0;
	for (int k = 0; k < c->clip_count; k++) {
		const mlod_clip *cl = &c->clips[k];
		v->motions[k].channels = v->chans + nch;
		v->motions[k].channel_count = (uint32_t)cl->channel_count;
		v->motions[k].duration = cl->duration;
		for (int i = 0; i < cl->channel_count; i++, nch++) {
			const mlod_channel *ch = &cl->channels[i];
			v->chans[nch].rec = (mlod_pack_channel_rec){ (uint32_t)ch->joint, (uint32_t)ch->path,
			                                             (uint32_t)ch->interp, (uint32_t)ch->key_count, 0 };
			v->chans[nch].times = ch->times;
			v->chans[nch].values = ch->values;
		}
		v->mot_v[k].data = &v->motions[k];
	}
	v->skel_v.data = NULL;
	v->mesh_v.data = &v->mesh;
	v->views = (mlod_rt_views){ &v->skel, 1, &v->skel_v, 1, &v->mesh_v, (uint32_t)c->clip_count,
	                            c->clip_count ? 1u : 0u, v->mot_v };
}

static void conv_free(conv *v)
{
	for (uint32_t k = 0; k < v->skel.skin_count; k++)
		free(v->skin_joints[k]);
	free(v->joints), free(v->names), free(v->skins), free(v->skin_names), free(v->skin_joints), free(v->ibm);
	for (uint32_t p = 0; p < v->mesh.part_count; p++)
		free(v->targets[p]);
	free(v->parts), free(v->prims), free(v->targets), free(v->chans), free(v->motions), free(v->mot_v);
}

/* The morph weight of target k at step of the comparison: every target
 * of a mesh instance gets a different one, some negative, some above 1. */
static float morph_weight(uint32_t instance, int k, int step)
{
	return (float)((int)(instance * 7 + (unsigned)k * 3 + (unsigned)step * 5) % 11 - 3) / 6.0f;
}

/* The bake side's placement of part pt (primitive q, which may carry
 * morphed positions) at world: skinned, rigid or static. */
static void bake_part(const mlod_skeleton *s, const mlod_pack_part *pt, const mlod_primitive *q,
                      const mlod_mat4 *world, mlod_mat4 *sm, float *bp, float *bn)
{
	const size_t m = pt->rec.vertex_count;
	if (pt->rec.skin >= 0) {
		mlod_skin_matrices(&s->skins[pt->rec.skin], world, sm);
		mlod_skin_primitive(q, sm, bp, q->normals ? bn : NULL);
	} else {
		mlod_mat4 off, R;
		memcpy(off.m, pt->rec.offset, sizeof off.m);
		R = pt->rec.joint >= 0 ? mlod_mat4_mul(&world[pt->rec.joint], &off) : off;
		for (size_t i = 0; i < m; i++) {
			mlod_v3 x = mlod_mat4_point(&R, (mlod_v3){ q->positions[3 * i], q->positions[3 * i + 1],
			                                          q->positions[3 * i + 2] });
			bp[3 * i] = x.x, bp[3 * i + 1] = x.y, bp[3 * i + 2] = x.z;
			if (!q->normals)
				continue;
			/* The normal by R's linear part, normalised (in double). */
			const float *nn = q->normals + 3 * i;
			double t[3], l = 0;
			for (int r = 0; r < 3; r++) {
				t[r] = (double)R.m[r] * nn[0] + (double)R.m[4 + r] * nn[1] + (double)R.m[8 + r] * nn[2];
				l += t[r] * t[r];
			}
			l = l > 0 ? 1 / sqrt(l) : 0;
			for (int r = 0; r < 3; r++)
				bn[3 * i + r] = (float)(t[r] * l);
		}
	}
}

/* q's positions plus its targets' deltas weighted by morph_weight(instance,
 * k, step), into mp; returns mp. */
static const float *bake_morph(const mlod_primitive *q, uint32_t instance, int step, float *mp)
{
	const size_t m = (size_t)q->vertex_count;
	memcpy(mp, q->positions, 12 * m);
	for (int k = 0; k < q->target_count; k++) {
		const float wk = morph_weight(instance, k, step);
		const float *d = q->targets[k].positions;
		for (size_t i = 0; d && wk != 0.0f && i < 3 * m; i++)
			mp[i] += wk * d[i];
	}
	return mp;
}

/* morph: set morph weights on every instance and compare with the bake
 * side's skinning of the morphed primitives. */
static void compare_sample(const char *path, int morph)
{
	size_t size;
	void *data = test_read_file(path, &size);
	CHECK_MSG(data, "cannot read %s", path);
	mlod_character c;
	CHECK_OK(mlod_load(data, size, "samples", NULL, &c, NULL, &terr));
	free(data);
	const mlod_skeleton *s = &c.skeleton;
	conv v;
	conv_build(&c, &v);
	mlod_rt_ctx *ctx = NULL;
	CHECK_OK(mlod_rt_open_views(&v.views, NULL, &ctx, &terr));
	mlod_rt_scratch *sc = mlod_rt_scratch_create(ctx);
	CHECK(sc != NULL);
	const uint32_t nv = mlod_rt_max_vertex_count(ctx);
	float *rp = malloc((size_t)nv * 12 + 12), *rn = malloc((size_t)nv * 12 + 12);
	float *bp = malloc((size_t)nv * 12 + 12), *bn = malloc((size_t)nv * 12 + 12);
	float *mp = malloc((size_t)nv * 12 + 12); /* a primitive's morphed positions */
	double worst_shift = 0;                   /* the largest morph displacement, of the diagonal */
	uint32_t morphed_parts = 0;
	mlod_trs *local = malloc(sizeof *local * (size_t)s->joint_count);
	mlod_mat4 *world = malloc(sizeof *world * (size_t)s->joint_count);
	int maxskin = 1;
	for (int k = 0; k < s->skin_count; k++)
		maxskin = s->skins[k].joint_count > maxskin ? s->skins[k].joint_count : maxskin;
	mlod_mat4 *sm = malloc(sizeof *sm * (size_t)maxskin);
	/* the diagonal of the rest bounds */
	float lo[3] = { 1e30f, 1e30f, 1e30f }, hi[3] = { -1e30f, -1e30f, -1e30f };
	for (uint32_t p = 0; p < v.mesh.part_count; p++)
		for (uint32_t i = 0; i < v.parts[p].rec.vertex_count; i++)
			for (int k = 0; k < 3; k++) {
				float x = v.parts[p].positions[3 * i + k];
				lo[k] = x < lo[k] ? x : lo[k], hi[k] = x > hi[k] ? x : hi[k];
			}
	const double diag = sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
	                         (hi[2] - lo[2]) * (hi[2] - lo[2]));
	double worst_pose = 0, worst_skin = 0, worst_nrm = 0, worst_rnrm = 0;
	size_t rigid_nrm = 0;
	const int clips = c.clip_count ? c.clip_count : 1;
	for (int k = 0; k < clips; k++) {
		const float dur = c.clip_count ? c.clips[k].duration : 0;
		for (int step = 0; step <= 12; step++) {
			const float t = dur * (float)step / 11.0f - 0.01f; /* also before 0 and after the end */
			uint32_t id;
			CHECK_OK(mlod_rt_instance_create(ctx, (uint32_t)k, t, 0, &id, &terr));
			for (uint32_t p = 0; morph && p < v.mesh.part_count; p++) {
				const uint32_t nt = mlod_rt_morph_target_count(ctx, p);
				CHECK_MSG(nt == v.parts[p].rec.target_count, "part %u: %u morph targets, the primitive has %u", p,
				          nt, v.parts[p].rec.target_count);
				float w[64];
				CHECK(nt <= 64);
				for (uint32_t i = 0; i < nt; i++)
					w[i] = morph_weight(v.parts[p].rec.instance, (int)i, step);
				CHECK_OK(mlod_rt_instance_set_morph_weights(ctx, id, p, w, nt, &terr));
			}
			const float *W;
			CHECK_OK(mlod_rt_pose(ctx, sc, id, &W, NULL, NULL, &terr));
			mlod_pose_rest(s, local);
			if (c.clip_count)
				mlod_clip_sample(&c.clips[k], t, local);
			mlod_pose_world(s, local, world);
			for (int j = 0; j < s->joint_count; j++)
				for (int q = 0; q < 16; q++) {
					double d = fabs((double)W[16 * j + q] - world[j].m[q]) / (q >= 12 ? diag : 1.0);
					worst_pose = d > worst_pose ? d : worst_pose;
				}
			uint32_t n;
			CHECK_OK(mlod_rt_skin(ctx, sc, id, rp, 12, rn, 12, nv, &n, &terr));
			size_t base = 0;
			for (uint32_t p = 0; p < v.mesh.part_count; p++) {
				const mlod_pack_part *pt = &v.parts[p];
				const mlod_primitive *q0 = v.prims[p];
				const size_t m = pt->rec.vertex_count;
				/* The bake side's primitive, morphed: a copy whose positions
				 * carry the weighted deltas. */
				mlod_primitive qm = *q0;
				if (morph && q0->target_count > 0) {
					bake_morph(q0, pt->rec.instance, step, mp);
					for (size_t i = 0; i < 3 * m; i++) {
						double d = fabs((double)mp[i] - q0->positions[i]) / diag;
						worst_shift = d > worst_shift ? d : worst_shift;
					}
					qm.positions = mp;
					morphed_parts += step == 0 && k == 0;
				}
				const mlod_primitive *q = &qm;
				bake_part(s, pt, q, world, sm, bp, bn);
				for (size_t i = 0; i < 3 * m; i++) {
					double d = fabs((double)rp[3 * base + i] - bp[i]) / diag;
					worst_skin = d > worst_skin ? d : worst_skin;
					if (pt->rec.skin >= 0 && q->normals) {
						d = fabs((double)rn[3 * base + i] - bn[i]);
						worst_nrm = d > worst_nrm ? d : worst_nrm;
					} else if (q->normals) { /* rigid and static parts */
						d = fabs((double)rn[3 * base + i] - bn[i]);
						worst_rnrm = d > worst_rnrm ? d : worst_rnrm;
						rigid_nrm++;
					}
				}
				base += m;
			}
			CHECK_MSG(base == n, "%zu vertices compared, the runtime wrote %u", base, n);
			mlod_rt_instance_destroy(ctx, id);
		}
	}
	printf("# %s: %u parts (%d skipped: several weight sets), %u vertices; worst: pose %.3g, positions %.3g "
	       "of the diagonal, normals %.3g\n",
	       path, v.mesh.part_count, v.skipped, nv, worst_pose, worst_skin, worst_nrm);
	CHECK_MSG(worst_pose <= 1e-5, "%s: pose differs by %g", path, worst_pose);
	CHECK_MSG(worst_skin <= 1e-5, "%s: skinned positions differ by %g of the diagonal", path, worst_skin);
	CHECK_MSG(worst_nrm <= 1e-4, "%s: skinned normals differ by %g", path, worst_nrm);
	/* Rigid and static parts' normals: mlod_rt_skin skips renormalising
	 * them when the matrix is a rotation times a scale (rigid_unit in
	 * rt_eval.c, a bound of 3e-6 on the length plus rounding). */
	printf("# %s: rigid and static normals (%zu floats) differ by %.3g\n", path, rigid_nrm, worst_rnrm);
	CHECK_MSG(worst_rnrm <= 1e-5, "%s: rigid normals differ by %g", path, worst_rnrm);
	if (morph) {
		/* The comparison means something only if the morph moves vertices
		 * well beyond the tolerance. */
		printf("# %s: %u parts with morph targets, the weights move vertices up to %.3g of the diagonal\n", path,
		       morphed_parts, worst_shift);
		CHECK_MSG(morphed_parts > 0 && worst_shift > 1e-3, "%s: no morph to compare (%u parts, %g)", path,
		          morphed_parts, worst_shift);
	}
	free(rp), free(rn), free(bp), free(bn), free(mp), free(local), free(world), free(sm);
	mlod_rt_scratch_destroy(ctx, sc);
	mlod_rt_close(ctx);
	conv_free(&v);
	mlod_character_free(&c);
}

/* Through a pack: mesh level 0 and one coarser level (half the
 * triangles), the skeleton and clips at level 0. */
static void morph_pack(const char *path)
{
	size_t size;
	void *data = test_read_file(path, &size);
	CHECK_MSG(data, "cannot read %s", path);
	mlod_gltf *doc = NULL;
	mlod_character c;
	mlod_format fmt;
	CHECK_OK(mlod_load(data, size, "samples", &doc, &c, &fmt, &terr));
	mlod_pack_options opt;
	mlod_pack_options_default(&opt);
	opt.codec = MLOD_CODEC_NONE; /* level 0 in the input's vertex order */
	opt.ratio_count = 1;
	opt.ratios[0] = 0.5;
	opt.no_skeleton_levels = opt.no_motion_levels = 1;
	void *pk = NULL;
	size_t pn = 0;
	CHECK_OK(mlod_pack_write(doc, &c, fmt, data, size, &opt, &pk, &pn, NULL, &terr));
	free(data);
	mlod_rt_ctx *ctx = NULL;
	CHECK_OK(mlod_rt_open_memory(pk, pn, NULL, &ctx, &terr));
	CHECK(mlod_rt_level_count(ctx, MLOD_RT_MESH) == 2);
	for (uint32_t l = 0; l < 2; l++)
		CHECK_OK(mlod_rt_request(ctx, MLOD_RT_MESH, l, 0, &terr));
	CHECK_OK(mlod_rt_stream(ctx, SIZE_MAX, NULL, &terr));
	conv v;
	conv_build(&c, &v);
	const mlod_skeleton *s = &c.skeleton;
	CHECK_MSG(mlod_rt_mesh_part_count(ctx, 0) == v.mesh.part_count && mlod_rt_mesh_part_count(ctx, 1) == v.mesh.part_count,
	          "the pack has %u and %u parts, the character %u", mlod_rt_mesh_part_count(ctx, 0),
	          mlod_rt_mesh_part_count(ctx, 1), v.mesh.part_count);
	uint32_t with_targets = 0;
	for (uint32_t p = 0; p < v.mesh.part_count; p++) {
		CHECK_MSG(mlod_rt_morph_target_count(ctx, p) == v.parts[p].rec.target_count,
		          "part %u: %u morph targets in the pack, %u in the input", p, mlod_rt_morph_target_count(ctx, p),
		          v.parts[p].rec.target_count);
		with_targets += v.parts[p].rec.target_count > 0;
	}
	CHECK(with_targets > 0);
	mlod_rt_scratch *sc = mlod_rt_scratch_create(ctx);
	CHECK(sc != NULL);
	const uint32_t nv = mlod_rt_max_vertex_count(ctx);
	float *ra = malloc((size_t)nv * 12 + 12), *rb = malloc((size_t)nv * 12 + 12), *na = malloc((size_t)nv * 12 + 12);
	float *bp = malloc((size_t)nv * 12 + 12), *bn = malloc((size_t)nv * 12 + 12), *mp = malloc((size_t)nv * 12 + 12);
	mlod_trs *local = malloc(sizeof *local * (size_t)s->joint_count);
	mlod_mat4 *world = malloc(sizeof *world * (size_t)s->joint_count);
	int maxskin = 1;
	for (int k = 0; k < s->skin_count; k++)
		maxskin = s->skins[k].joint_count > maxskin ? s->skins[k].joint_count : maxskin;
	mlod_mat4 *sm = malloc(sizeof *sm * (size_t)maxskin);
	mlod_rt_select sel;
	mlod_rt_select_default(&sel);
	const float t = c.clip_count ? 0.4f * c.clips[0].duration : 0.0f;
	double worst[2] = { 0, 0 }, shift[2] = { 0, 0 }, diag = 0; /* [0]: no weights, [1]: weights */
	long dropped[2] = { 0, 0 };
	for (uint32_t level = 0; level < 2; level++) {
		uint32_t ids[2];
		sel.force_level = (int)level;
		for (int i = 0; i < 2; i++) {
			CHECK_OK(mlod_rt_instance_create(ctx, 0, t, 0, &ids[i], &terr));
			float d = 1;
			CHECK_OK(mlod_rt_update(ctx, &sel, &ids[i], &d, 1, 0.0f, &terr));
		}
		for (uint32_t p = 0; p < v.mesh.part_count; p++) {
			float w[64];
			const uint32_t nt = mlod_rt_morph_target_count(ctx, p);
			CHECK(nt <= 64);
			for (uint32_t k = 0; k < nt; k++)
				w[k] = morph_weight(v.parts[p].rec.instance, (int)k, 3);
			CHECK_OK(mlod_rt_instance_set_morph_weights(ctx, ids[0], p, w, nt, &terr));
		}
		uint32_t n0, n1;
		CHECK_OK(mlod_rt_skin(ctx, sc, ids[0], ra, 12, na, 12, nv, &n0, &terr));
		CHECK_OK(mlod_rt_skin(ctx, sc, ids[1], rb, 12, NULL, 12, nv, &n1, &terr));
		CHECK(n0 == n1 && n0 == mlod_rt_mesh_vertex_count(ctx, level));
		/* the morph moves the coarse level too */
		float lo[3] = { 1e30f, 1e30f, 1e30f }, hi[3] = { -1e30f, -1e30f, -1e30f };
		for (uint32_t i = 0; i < n1; i++)
			for (int k = 0; k < 3; k++)
				lo[k] = rb[3 * i + k] < lo[k] ? rb[3 * i + k] : lo[k], hi[k] = rb[3 * i + k] > hi[k] ? rb[3 * i + k] : hi[k];
		diag = sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
		            (hi[2] - lo[2]) * (hi[2] - lo[2]));
		for (uint32_t i = 0; i < 3 * n0; i++) {
			double d = fabs((double)ra[i] - rb[i]) / diag;
			shift[level] = d > shift[level] ? d : shift[level];
		}
		if (level == 0) { /* against the bake side, vertex by vertex */
			CHECK(n0 == nv);
			mlod_pose_rest(s, local);
			if (c.clip_count)
				mlod_clip_sample(&c.clips[0], t, local);
			mlod_pose_world(s, local, world);
			/* The pack's level keeps the input's triangles in order with
			 * codec none, but its vertices are those the triangles use,
			 * in first-use order (layout b2): compared corner by corner.
			 * It drops the triangles quantisation makes degenerate (mlod(5)
			 * MESH levels): an input triangle that matches no decoded one
			 * must have two corners within the bound of each other. */
			for (uint32_t p = 0; p < v.mesh.part_count; p++) {
				const mlod_pack_part *pt = &v.parts[p];
				const mlod_primitive *q0 = v.prims[p];
				mlod_primitive qm = *q0;
				mlod_rt_part_info info;
				CHECK_OK(mlod_rt_mesh_part(ctx, 0, p, &info, &terr));
				uint32_t ni = q0->index_count > 0 ? (uint32_t)q0->index_count : (uint32_t)q0->vertex_count;
				ni -= ni % 3;
				CHECK(info.index_count <= ni);
				for (int morphed = 0; morphed < 2; morphed++) {
					if (morphed && q0->target_count > 0)
						qm.positions = (float *)bake_morph(q0, pt->rec.instance, 3, mp);
					bake_part(s, pt, &qm, world, sm, bp, bn);
					const float *r = morphed ? ra : rb;
					uint32_t kin = 0, kout = 0;
					while (kin < ni) {
						size_t iv[3];
						double dt = kout < info.index_count ? 0 : INFINITY, close = INFINITY;
						for (int c3 = 0; c3 < 3; c3++) {
							iv[c3] = q0->index_count > 0 ? (size_t)q0->indices[kin + c3] : kin + c3;
							size_t rv = kout < info.index_count ? (size_t)info.first_vertex + info.indices[kout + c3] : 0;
							for (int a = 0; kout < info.index_count && a < 3; a++)
								dt = fmax(dt, fabs((double)r[3 * rv + a] - bp[3 * iv[c3] + a]) / diag);
						}
						if (dt <= 2.5e-4) {
							worst[morphed] = dt > worst[morphed] ? dt : worst[morphed];
							kin += 3, kout += 3;
							continue;
						}
						for (int c3 = 0; c3 < 3; c3++) {
							double dc = 0;
							for (int a = 0; a < 3; a++)
								dc = fmax(dc, fabs((double)bp[3 * iv[c3] + a] - bp[3 * iv[(c3 + 1) % 3] + a]) / diag);
							close = fmin(close, dc);
						}
						CHECK_MSG(close <= 2.5e-4, "%s part %u: input triangle %u matches no decoded one (%g off) and "
						          "is not degenerate (its nearest corners %g apart)", path, p, kin / 3, dt, close);
						if (!(close <= 2.5e-4))
							break;
						kin += 3, dropped[morphed]++;
					}
					CHECK_MSG(kout == info.index_count, "%s part %u: %u of %u decoded indices matched", path, p, kout,
					          info.index_count);
				}
			}
		}
		for (int i = 0; i < 2; i++)
			mlod_rt_instance_destroy(ctx, ids[i]);
	}
	printf("# %s through a pack: level 0 against the bake side %.3g of the diagonal without morph, %.3g with; "
	       "the morph moves level 0 up to %.3g, level 1 up to %.3g; %ld input triangles dropped as degenerate\n",
	       path, worst[0], worst[1], shift[0], shift[1], dropped[0]);
	/* the pack's quantisation: positions to 1/65535 of a part's extent,
	 * morph deltas to half a step of their scale */
	CHECK_MSG(worst[0] <= 2.5e-4 && worst[1] <= 2.5e-4, "%s: the pack's runtime differs by %g (%g with morph)", path,
	          worst[0], worst[1]);
	CHECK_MSG(shift[0] > 10 * worst[1] && shift[1] > 10 * worst[1], "%s: the morph moves levels 0 and 1 by %g, %g",
	          path, shift[0], shift[1]);
	free(ra), free(rb), free(na), free(bp), free(bn), free(mp), free(local), free(world), free(sm);
	mlod_rt_scratch_destroy(ctx, sc);
	mlod_rt_close(ctx);
	mlod_free(pk);
	conv_free(&v);
	mlod_character_free(&c);
	mlod_gltf_free(doc);
}

TEST(rt_equals_bake_tubeman) { compare_sample("samples/tubeman.glb", 0); }
TEST(rt_equals_bake_robot) { compare_sample("samples/RobotExpressive.glb", 0); }
TEST(rt_morph_equals_bake_robot) { compare_sample("samples/RobotExpressive.glb", 1); }
TEST(rt_morph_pack_robot) { morph_pack("samples/RobotExpressive.glb"); }

int main(void)
{
	RUN(rt_equals_bake_tubeman);
	RUN(rt_equals_bake_robot);
	RUN(rt_morph_equals_bake_robot);
	RUN(rt_morph_pack_robot);
	TEST_EXIT();
}
