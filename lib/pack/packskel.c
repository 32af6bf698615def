/*
 * packskel.c: the skeleton levels (mlod-skelgraph's, or computed) and
 * their SKELETON chunks (packwrite_internal.h).
 */
#include <stdlib.h>
#include <string.h>

#include "pack/packwrite_internal.h"

/* ------------------------------------------------------------------ */
/* Skeleton                                                            */
/* ------------------------------------------------------------------ */

mlod_result pack_skeleton_levels(struct ctx *x)
{
	const mlod_skeleton *s = &x->v.skeleton;
	int n = s->joint_count;
	mlod_result r = MLOD_OK;
	if (n == 0 || x->opt->no_skeleton_levels)
		return MLOD_OK;
	/* An empty list: an unpacked pack that had level 0 alone. */
	if (x->rec.has_skel_levels && x->rec.skel_level_count == 0 && x->rec.has_pack) {
		x->st->skeleton.from_input = 1;
		return MLOD_OK;
	}
	if (x->rec.skel_level_count > 0) {
		x->st->skeleton.from_input = 1;
		for (int k = 0; k < x->rec.skel_level_count && k < MLOD_SKEL_MAX_LEVELS; k++) {
			const mlod_record_skel_level *l = &x->rec.skel_levels[k];
			unsigned char *kept = calloc((size_t)n, 1);
			int *remap = malloc(sizeof(int) * (size_t)n);
			if (!kept || !remap) {
				free(kept);
				free(remap);
				return mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
			}
			x->kept[k] = kept;
			x->remap[k] = remap;
			x->skel_count = k + 1;
			for (int i = 0; i < l->kept_count; i++) {
				int j = pack_joint_of_node(s, l->kept[i]);
				if (j < 0)
					return mlod_fail(x->err, MLOD_ERR_PARSE,
					                 "skeleton level %d: kept node %d is not a joint", k + 1, l->kept[i]);
				kept[j] = 1;
			}
			for (int j = 0; j < n; j++)
				if (s->joints[j].parent < 0)
					kept[j] = 1; /* every root is kept */
			for (int j = 0; j < n; j++)
				remap[j] = kept[j] ? j : -1;
			for (int i = 0; i < l->remap_count; i++) {
				int a = pack_joint_of_node(s, l->remap_from[i]), b = pack_joint_of_node(s, l->remap_to[i]);
				if (a < 0 || b < 0 || !kept[b])
					return mlod_fail(x->err, MLOD_ERR_PARSE, "skeleton level %d: remap %d -> %d is not a kept joint",
					                 k + 1, l->remap_from[i], l->remap_to[i]);
				if (!kept[a])
					remap[a] = b;
			}
			for (int j = 0; j < n; j++) /* parents first: the nearest kept ancestor */
				if (remap[j] < 0)
					remap[j] = remap[s->joints[j].parent];
			/* The pack error a record from mlod-pack -x gives, else the
			 * measured errors (version 3 may have neither). */
			if (!l->has_pack_error && !l->has_vertex_error && l->missing_joint_error)
				return mlod_fail(x->err, MLOD_ERR_PARSE,
				                 "the scene's extras.mlod.skeleton_levels[%d]: no error (pack_error, "
				                 "vertex_error_percent or joint_error)",
				                 k);
			x->skel_error[k] = (float)(l->has_pack_error     ? l->pack_error
			                           : l->has_vertex_error ? l->vertex_error.max * x->diag / 100.0
			                                                 : l->joint_error.max);
		}
		return MLOD_OK;
	}
	/* Computed: labels (the record's when there), then the default chain. */
	mlod_joint_info *info = calloc((size_t)n, sizeof *info);
	mlod_skel_levels L;
	int found = 0;
	memset(&L, 0, sizeof L);
	if (!info)
		return mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
	r = mlod_label_skeleton(&x->v, &x->opt->label, info, x->err);
	if (r == MLOD_OK && x->doc)
		r = mlod_record_read_joints(x->doc, &x->v, info, &found, x->err);
	if (r == MLOD_OK)
		r = mlod_skel_levels_init(&L, &x->v, info, x->err);
	if (r == MLOD_OK)
		r = mlod_skel_levels_default(&L, x->opt->skel_max_error, x->err);
	if (r == MLOD_ERR_UNSUPPORTED) {
		/* A character the skeleton layer cannot reduce (a mesh skinned
		 * by two skins): the other layers still pack, the skeleton at
		 * level 0 alone, with a warning (mlod-skelgraph refuses it). */
		char text[MLOD_ERROR_MESSAGE_SIZE + 64];
		snprintf(text, sizeof text, "no skeleton levels: %s", x->err ? x->err->message : "unsupported character");
		pack_warn(x, text);
		mlod_skel_levels_free(&L);
		memset(&L, 0, sizeof L);
		r = MLOD_OK;
	}
	for (int k = 0; r == MLOD_OK && k < L.count; k++) {
		const mlod_skel_built *b = &L.levels[k];
		x->kept[k] = malloc((size_t)n);
		x->remap[k] = malloc(sizeof(int) * (size_t)n);
		x->skel_count = k + 1;
		if (!x->kept[k] || !x->remap[k]) {
			r = mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
			break;
		}
		memcpy(x->kept[k], b->skel.kept, (size_t)n);
		memcpy(x->remap[k], b->skel.remap, sizeof(int) * (size_t)n);
		x->skel_error[k] = (float)(b->has_mesh_error ? b->vertex.max * x->diag / 100.0 : b->joint.max);
	}
	if (r == MLOD_OK && L.count == 0 && L.minor_count > 0)
		pack_note(x, "no skeleton level within the skeleton's max error");
	mlod_skel_levels_free(&L);
	free(info);
	return r;
}

mlod_result pack_skeleton_chunk(struct ctx *x, chunks *out)
{
	const mlod_skeleton *s = &x->v.skeleton;
	chunkb cb = {0};
	mlod_buf names = MLOD_BUF_INIT;
	int n = s->joint_count;
	mlod_pack_joint_rec *j = calloc((size_t)n + 1, sizeof *j);
	mlod_pack_skin_rec *sk = calloc((size_t)s->skin_count + 1, sizeof *sk);
	size_t pal = 0;
	for (int i = 0; i < s->skin_count; i++)
		pal += (size_t)s->skins[i].joint_count;
	uint32_t *skjt = malloc(sizeof(uint32_t) * (pal + 1));
	float *ibms = malloc(sizeof(float) * 16 * (pal + 1));
	mlod_result r = MLOD_OK;
	if (!j || !sk || !skjt || !ibms) {
		r = mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
		goto done;
	}
	for (int i = 0; i < n; i++) {
		const mlod_joint *q = &s->joints[i];
		j[i].parent = q->parent;
		j[i].name = pack_str_add(&names, q->name);
		j[i].t[0] = q->rest.t.x, j[i].t[1] = q->rest.t.y, j[i].t[2] = q->rest.t.z;
		j[i].r[0] = q->rest.r.x, j[i].r[1] = q->rest.r.y, j[i].r[2] = q->rest.r.z, j[i].r[3] = q->rest.r.w;
		j[i].s[0] = q->rest.s.x, j[i].s[1] = q->rest.s.y, j[i].s[2] = q->rest.s.z;
		memcpy(j[i].base, q->base.m, sizeof j[i].base);
		j[i].node = q->node;
	}
	size_t e = 0;
	for (int i = 0; i < s->skin_count; i++) {
		const mlod_skin *k = &s->skins[i];
		sk[i].joint_count = (uint32_t)k->joint_count;
		sk[i].name = pack_str_add(&names, k->name);
		sk[i].gltf_index = k->gltf_index;
		for (int q = 0; q < k->joint_count; q++, e++) {
			skjt[e] = (uint32_t)k->joints[q];
			memcpy(ibms + 16 * e, k->inverse_bind[q].m, 64);
		}
	}
	if (names.status != MLOD_OK) {
		r = mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
		goto done;
	}
	pack_cb_add(&cb, MLOD_STREAM_JNTS, (uint32_t)n, sizeof *j, j, 0);
	pack_cb_add(&cb, MLOD_STREAM_NAME, (uint32_t)names.size, 1, names.data, 0);
	pack_cb_add(&cb, MLOD_STREAM_SKIN, (uint32_t)s->skin_count, sizeof *sk, sk, 0);
	pack_cb_add(&cb, MLOD_STREAM_SKJT, (uint32_t)pal, 4, skjt, 0);
	pack_cb_add(&cb, MLOD_STREAM_IBMS, (uint32_t)pal, 64, ibms, 0);
	r = pack_cb_finish(&cb, x->opt->codec, out, MLOD_CHUNK_SKELETON, MLOD_LAYER_SKELETON, 0, 0, 0.0f, x->err);
done:
	pack_cb_free(&cb);
	mlod_buf_free(&names);
	free(j);
	free(sk);
	free(skjt);
	free(ibms);
	return r;
}

/* Skeleton level k (1-based): KEPT, and the palette binds (as PALR and
 * PALX, format 7.0; the palette joints the reader derives) as fold.c's skin
 * transfer makes it (reduce_skin): a kept skin joint keeps its bind; a
 * removed one uses its stand-in's entry in the level skin: the stand-in's
 * own bind when the skin has it, else R(stand-in -> joint) * IBM(joint)
 * of the first removed joint of the skin that brought it in. */
mlod_result pack_skel_level_chunk(struct ctx *x, int k, chunks *out)
{
	const mlod_skeleton *s = &x->v.skeleton;
	const unsigned char *kept = x->kept[k - 1];
	const int *remap = x->remap[k - 1];
	int n = s->joint_count;
	size_t pal = 0, e = 0;
	int maxsk = 0;
	for (int i = 0; i < s->skin_count; i++) {
		pal += (size_t)s->skins[i].joint_count;
		maxsk = s->skins[i].joint_count > maxsk ? s->skins[i].joint_count : maxsk;
	}
	uint32_t *keptv = malloc(sizeof(uint32_t) * ((size_t)n + 1)), kc = 0;
	uint32_t *palr = malloc(sizeof(uint32_t) * (pal + 1));
	float *palb = malloc(sizeof(float) * 16 * (pal + 1));
	float *palx = malloc(sizeof(float) * 16 * (pal + 1));
	float *ibmf = malloc(sizeof(float) * 16 * (pal + 1)); /* SKELETON's 'IBMS' */
	size_t nx = 0;
	int *lj = malloc(sizeof(int) * ((size_t)maxsk + 1));          /* the level skin's joints */
	mlod_mat4 *lb = malloc(sizeof(mlod_mat4) * ((size_t)maxsk + 1)); /* and binds */
	chunkb cb = {0};
	mlod_result r = MLOD_OK;
	if (!keptv || !palr || !palb || !palx || !ibmf || !lj || !lb) {
		r = mlod_fail(x->err, MLOD_ERR_NOMEM, "out of memory");
		goto done;
	}
	for (int j = 0; j < n; j++)
		if (kept[j])
			keptv[kc++] = (uint32_t)j;
	for (int i = 0; i < s->skin_count; i++) {
		const mlod_skin *sk = &s->skins[i];
		int ln = 0;
		for (int q = 0; q < sk->joint_count; q++)
			if (kept[sk->joints[q]]) {
				lj[ln] = sk->joints[q];
				lb[ln++] = sk->inverse_bind[q];
			}
		for (int q = 0; q < sk->joint_count; q++, e++) {
			int j = sk->joints[q];
			mlod_mat4 bind = sk->inverse_bind[q];
			if (!kept[j]) { /* its palette joint, the stand-in, the reader derives */
				int stand = remap[j], at = -1;
				for (int t = 0; t < ln; t++)
					if (lj[t] == stand)
						at = t;
				if (at < 0) {
					mlod_mat4 inv, rel;
					if (mlod_mat4_invert(&x->world[stand], &inv) != 0) {
						r = mlod_fail(x->err, MLOD_ERR_PARSE, "joint \"%s\" has a singular rest transform",
						              s->joints[stand].name);
						goto done;
					}
					rel = mlod_mat4_mul(&inv, &x->world[j]);
					lj[ln] = stand;
					lb[ln] = mlod_mat4_mul(&rel, &sk->inverse_bind[q]);
					at = ln++;
				}
				bind = lb[at];
			}
			memcpy(palb + 16 * e, bind.m, 64);
			memcpy(ibmf + 16 * e, sk->inverse_bind[q].m, 64);
		}
	}
	/* Format 7.0: each bind matrix as a reference (palr, mlod(5)): 0 for
	 * the joint's own IBMS entry, 1 + the first IBMS entry over all skins
	 * that holds the same bytes, else P + 1 + its index in PALX (each
	 * matrix once, in first-use order). */
	for (size_t i = 0, xe = 0, g = 0; i < pal; i++) {
		const float *m = palb + 16 * i;
		if (memcmp(m, ibmf + 16 * i, 64) == 0) {
			palr[i] = 0;
			continue;
		}
		for (g = 0; g < pal && memcmp(m, ibmf + 16 * g, 64) != 0; g++)
			;
		if (g < pal) {
			palr[i] = (uint32_t)(g + 1);
			continue;
		}
		for (g = 0; g < xe && memcmp(m, palx + 16 * g, 64) != 0; g++)
			;
		if (g == xe)
			memcpy(palx + 16 * xe++, m, 64);
		palr[i] = (uint32_t)(pal + 1 + g);
		nx = xe;
	}
	pack_cb_add(&cb, MLOD_STREAM_KEPT, kc, 4, keptv, 0);
	pack_cb_add(&cb, MLOD_STREAM_PALR, (uint32_t)pal, 4, palr, 0);
	pack_cb_add(&cb, MLOD_STREAM_PALX, (uint32_t)nx, 64, palx, 0);
	r = pack_cb_finish(&cb, x->opt->codec, out, MLOD_CHUNK_SKELETON, MLOD_LAYER_SKELETON, k, 0, x->skel_error[k - 1],
	                   x->err);
done:
	pack_cb_free(&cb);
	free(keptv);
	free(palr);
	free(palb);
	free(palx);
	free(ibmf);
	free(lj);
	free(lb);
	return r;
}
