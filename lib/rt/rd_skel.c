/*
 * rd_skel.c: the pack reader's SKELETON chunk and its skeleton levels.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MLOD_PACK_READER /* pack_internal.h: the reader's own part */
#include "pack_internal.h"

/* ------------------------------------------------------------------ */
/* SKELETON                                                            */
/* ------------------------------------------------------------------ */

mlod_result mlod_pack_decode_skeleton(const mlod_pack *p, const void *data, size_t size, mlod_pack_skeleton *out,
                                      mlod_error *err)
{
	int ci;
	mlod_result r = pk_find_one(p, MLOD_CHUNK_SKELETON, out, sizeof *out, "mlod_pack_decode_skeleton", &ci, err);
	if (r != MLOD_OK)
		return r;
	cx x;
	bump b = {0};
	stream sj, sn, ss, sk, si;
	const uint8_t *src;
	r = pk_cx_begin(p, (uint32_t)ci, MLOD_CHUNK_SKELETON, data, size, &x, err);
	if (r != MLOD_OK)
		return r;
	TRY(pk_cx_expect(&x, &sj, MLOD_STREAM_JNTS, sizeof(mlod_pack_joint_rec), UINT64_MAX, "", "", err));
	TRY(pk_cx_expect(&x, &sn, MLOD_STREAM_NAME, 1, UINT64_MAX, "", "", err));
	TRY(pk_cx_expect(&x, &ss, MLOD_STREAM_SKIN, sizeof(mlod_pack_skin_rec), UINT64_MAX, "", "", err));
	TRY(pk_cx_expect(&x, &sk, MLOD_STREAM_SKJT, 4, UINT64_MAX, "", "", err));
	TRY(pk_cx_expect(&x, &si, MLOD_STREAM_IBMS, 64, sk.count, "", "one per skin joint in 'SKJT'", err));
	TRY(pk_cx_end(&x, err));
	uint64_t J = sj.count, N = sn.count, S = ss.count, K = sk.count;
	TRY(pk_cx_temp(&x, 0, err));
	TRY(pk_bump_alloc(&b, &x,
	                  round8(J * sizeof(mlod_pack_joint_rec)) + round8(J * sizeof(char *)) + round8(N + 1) +
	                          round8(S * sizeof(mlod_pack_skin_rec)) + 3 * round8(S * sizeof(void *)) + round8(K * 4) +
	                          round8(K * 64),
	                  err));
	mlod_pack_joint_rec *joints;
	const char **joint_names, **skin_names;
	mlod_pack_skin_rec *skins;
	const uint32_t **skin_joints;
	const float **inverse_bind;
	uint32_t *skjt;
	float *ibms;
	char *names;
	TAKE(joints, J * sizeof *joints);
	TAKE(joint_names, J * sizeof *joint_names);
	TAKE(skins, S * sizeof *skins);
	TAKE(skin_names, S * sizeof *skin_names);
	TAKE(skin_joints, S * sizeof *skin_joints);
	TAKE(inverse_bind, S * sizeof *inverse_bind);
	TAKE(skjt, K * 4);
	TAKE(ibms, K * 64);
	TRY(pk_cx_load(&x, &sj, &src, err));
	if (J)
		memcpy(joints, src, J * sizeof *joints);
	TRY(pk_load_names(&x, &b, &sn, &names, err));
	for (uint32_t j = 0; j < J; j++) {
		const mlod_pack_joint_rec *jt = &joints[j];
		char what[48];
		snprintf(what, sizeof what, "joint %u", j);
		if (jt->parent < -1 || jt->parent >= (int32_t)j)
			FAIL("%s: joint %u: parent %d is not -1 or an earlier joint", x.label, j, jt->parent);
		if (!all_finite(jt->t, 3) || !all_finite(jt->r, 4) || !all_finite(jt->s, 3) || !all_finite(jt->base, 16))
			FAIL("%s: joint %u: a rest transform or base value is not finite", x.label, j);
		const double len = mlod_quat4_length(jt->r[0], jt->r[1], jt->r[2], jt->r[3]);
		if (!(fabs(len - 1.0) <= MLOD_UNIT_QUAT_TOLERANCE))
			FAIL("%s: joint %u: its rest rotation has length %g, not a unit quaternion (within %g)", x.label, j, len,
			     MLOD_UNIT_QUAT_TOLERANCE);
		if (jt->node < -1)
			FAIL("%s: joint %u: node %d is not -1 or a node", x.label, j, jt->node);
		TRY(pk_name_at(&x, names, sn.count, jt->name, &joint_names[j], what, err));
	}
	TRY(pk_cx_load(&x, &ss, &src, err));
	if (S)
		memcpy(skins, src, S * sizeof *skins);
	uint64_t sum = 0;
	for (uint32_t k = 0; k < S; k++) {
		char what[48];
		snprintf(what, sizeof what, "skin %u", k);
		if (skins[k].gltf_index < -1)
			FAIL("%s: skin %u: glTF skin %d is not -1 or a skin", x.label, k, skins[k].gltf_index);
		TRY(pk_name_at(&x, names, sn.count, skins[k].name, &skin_names[k], what, err));
		skin_joints[k] = skjt + sum;
		inverse_bind[k] = ibms + 16 * sum;
		sum += skins[k].joint_count;
		if (sum > K)
			FAIL("%s: skin %u: its joints run past the %llu in 'SKJT'", x.label, k, (unsigned long long)K);
	}
	if (sum != K)
		FAIL("%s: the skins have %llu joints, but 'SKJT' has %llu", x.label, (unsigned long long)sum,
		     (unsigned long long)K);
	TRY(pk_cx_load(&x, &sk, &src, err));
	if (K)
		memcpy(skjt, src, K * 4);
	for (uint32_t k = 0, i = 0; k < S; k++)
		for (uint32_t m = 0; m < skins[k].joint_count; m++, i++)
			if (skjt[i] >= J)
				FAIL("%s: skin %u: joint %u is %u, not below the joint count %llu", x.label, k, m, skjt[i],
				     (unsigned long long)J);
	TRY(pk_cx_load(&x, &si, &src, err));
	if (K)
		memcpy(ibms, src, K * 64);
	if (!all_finite(ibms, (size_t)K * 16))
		FAIL("%s: an inverse bind matrix is not finite", x.label);
	pk_cx_done(&x);
	out->joint_count = (uint32_t)J;
	out->joints = joints;
	out->joint_names = joint_names;
	out->skin_count = (uint32_t)S;
	out->skins = skins;
	out->skin_names = skin_names;
	out->skin_joints = skin_joints;
	out->inverse_bind = inverse_bind;
	out->block = b.base;
	return MLOD_OK;
fail:
	return pk_undo(&x, &b, r);
}

void mlod_pack_skeleton_free(mlod_pack_skeleton *x)
{
	if (x)
		pk_block_release(x->block, x, sizeof *x);
}

/* ------------------------------------------------------------------ */
/* SKELETON level k                                                    */
/* ------------------------------------------------------------------ */

mlod_result mlod_pack_decode_skel_level(const mlod_pack *p, uint32_t chunk, const void *data, size_t size,
                                        const mlod_pack_skeleton *skel, mlod_pack_skel_level *out, mlod_error *err)
{
	return mlod_pack_decode_skel_level_reserve(p, chunk, data, size, skel, NULL, NULL, out, err);
}

mlod_result mlod_pack_decode_skel_level_reserve(const mlod_pack *p, uint32_t chunk, const void *data, size_t size,
                                                const mlod_pack_skeleton *skel, mlod_pack_skel_reserve_fn reserve,
                                                void *reserve_user, mlod_pack_skel_level *out, mlod_error *err)
{
	if (!out)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_pack_decode_skel_level: out is NULL");
	memset(out, 0, sizeof *out);
	if (!skel)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_pack_decode_skel_level: the full skeleton is NULL");
	cx x;
	bump b = {0};
	stream sk, sj, sb;
	const uint8_t *src;
	int refs = p->major >= 7; /* 'PALR' and 'PALX'; 'PALJ' derived (format 7.0) */
	mlod_result r = pk_cx_begin_skel_level(p, chunk, data, size, &x, err);
	if (r != MLOD_OK)
		return r;
	if (x.c->level == 0)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG,
		                 "pack decode: chunk %u is the full SKELETON: use mlod_pack_decode_skeleton", chunk);
	uint64_t J = skel->joint_count, P = 0;
	for (uint32_t k = 0; k < skel->skin_count; k++)
		P += skel->skins[k].joint_count;
	TRY(pk_cx_expect(&x, &sk, MLOD_STREAM_KEPT, 4, UINT64_MAX, "", "", err));
	if (refs) {
		TRY(pk_cx_expect(&x, &sj, MLOD_STREAM_PALR, 4, P, "", "the skins' joints", err));
		TRY(pk_cx_expect(&x, &sb, MLOD_STREAM_PALX, 64, UINT64_MAX, "", "", err));
		if (sb.count > P)
			FAIL("%s: %u bind matrices in 'PALX', more than the %llu skin joints", x.label, sb.count,
			     (unsigned long long)P);
	} else {
		TRY(pk_cx_expect(&x, &sj, MLOD_STREAM_PALJ, 4, P, "", "the skins' joints", err));
		TRY(pk_cx_expect(&x, &sb, MLOD_STREAM_PALB, 64, P, "", "the skins' joints", err));
	}
	TRY(pk_cx_end(&x, err));
	uint64_t Kc = sk.count;
	if (Kc > J)
		FAIL("%s: %llu kept joints of a skeleton of %llu", x.label, (unsigned long long)Kc, (unsigned long long)J);
	/* Scratch: the kept joints and the palette's joints (the records,
	 * read and checked before the block is sized and allocated), each
	 * joint's nearest kept ancestor (or itself); from 7.0 also 'PALR' and
	 * each skin joint's 'IBMS' entry. */
	const uint64_t a_kept = round8(Kc * 4), a_near = round8(J * 4), a_palj = round8(P * 4),
	               a_palr = refs ? round8(P * 4) : 0;
	TRY(pk_cx_temp(&x, a_kept + a_near + a_palj + a_palr + (refs ? P * sizeof(float *) : 0), err));
	uint32_t *rkept = x.temp ? (uint32_t *)(void *)x.temp : NULL;
	uint32_t *nearest = x.temp ? (uint32_t *)(void *)(x.temp + a_kept) : NULL;
	uint32_t *rpalj = x.temp ? (uint32_t *)(void *)(x.temp + a_kept + a_near) : NULL;
	uint32_t *palr = refs && x.temp ? (uint32_t *)(void *)(x.temp + a_kept + a_near + a_palj) : NULL;
	const float **ibm = refs && x.temp ? (const float **)(void *)(x.temp + a_kept + a_near + a_palj + a_palr) : NULL;
	TRY(pk_cx_load(&x, &sk, &src, err));
	if (Kc)
		memcpy(rkept, src, Kc * 4);
	for (uint64_t i = 0; i < Kc; i++) {
		if (rkept[i] >= J)
			FAIL("%s: kept joint %llu is %u, not below the joint count %llu", x.label, (unsigned long long)i,
			     rkept[i], (unsigned long long)J);
		if (i > 0 && rkept[i] <= rkept[i - 1])
			FAIL("%s: kept joints are not increasing (%u after %u)", x.label, rkept[i], rkept[i - 1]);
	}
	for (uint32_t j = 0, ki = 0; j < J; j++) {
		int is_kept = ki < Kc && rkept[ki] == j;
		if (is_kept)
			ki++;
		int32_t parent = skel->joints[j].parent;
		if (parent >= (int32_t)j)
			FAIL("%s: the given skeleton's joint %u has parent %d, not an earlier joint", x.label, j, parent);
		if (parent < 0 && !is_kept)
			FAIL("%s: root joint %u is not kept (every root is)", x.label, j);
		nearest[j] = is_kept ? j : nearest[parent];
	}
	if (!refs) {
		TRY(pk_cx_load(&x, &sj, &src, err));
		if (P)
			memcpy(rpalj, src, P * 4);
	}
	for (uint32_t k = 0, i = 0; k < skel->skin_count; k++)
		for (uint32_t m = 0; m < skel->skins[k].joint_count; m++, i++) {
			uint32_t joint = skel->skin_joints[k][m];
			if (joint >= J)
				FAIL("%s: the given skeleton's skin %u joint %u is %u, not below its joint count", x.label, k, m,
				     joint);
			if (refs) {
				rpalj[i] = nearest[joint];
				ibm[i] = skel->inverse_bind[k] + 16 * (size_t)m;
				continue;
			}
			uint32_t v = rpalj[i];
			if (v >= J || nearest[v] != v)
				FAIL("%s: palette entry %u (skin %u joint %u): joint %u is not a kept joint", x.label, i, k, m, v);
			if (v != nearest[joint])
				FAIL("%s: palette entry %u (skin %u joint %u): joint %u, but the nearest kept ancestor of joint %u "
				     "is %u",
				     x.label, i, k, m, v, joint, nearest[joint]);
		}
	/* 0: the own IBMS entry; 1..P: IBMS entry v - 1; then 'PALX'. */
	if (refs && P) {
		TRY(pk_cx_load_into(&x, &sj, (uint8_t *)palr, err));
		for (uint64_t i = 0; i < P; i++)
			if (palr[i] > P && palr[i] - P - 1 >= sb.count)
				FAIL("%s: palette entry %llu refers to bind matrix %u, beyond the %llu skin joints and %u in "
				     "'PALX'",
				     x.label, (unsigned long long)i, palr[i], (unsigned long long)P, sb.count);
	}
	/* The block, exactly, from the checked counts: nothing a stream claims
	 * beyond them sizes it (the kept count is at most the joints', the
	 * palette the skeleton's). */
	const uint64_t total = round8(Kc * 4) + round8(P * 4) + round8(P * 64);
	if (reserve)
		TRY(reserve(reserve_user, (uint32_t)Kc, (uint32_t)P, BLOCK_HEAD + total, err));
	TRY(pk_bump_alloc(&b, &x, total, err));
	uint32_t *kept, *palj;
	float *palb;
	TAKE(kept, Kc * 4);
	TAKE(palj, P * 4);
	TAKE(palb, P * 64);
	if (Kc)
		memcpy(kept, rkept, Kc * 4);
	if (P)
		memcpy(palj, rpalj, P * 4);
	TRY(pk_cx_load(&x, &sb, &src, err));
	if (refs) {
		for (uint64_t i = 0; i < P; i++) {
			uint64_t v = palr[i];
			const void *from = v == 0 ? (const void *)ibm[i] : v <= P ? (const void *)ibm[v - 1]
			                                                          : (const void *)(src + 64 * (v - P - 1));
			memcpy(palb + 16 * i, from, 64);
		}
	} else if (P) {
		memcpy(palb, src, P * 64);
	}
	if (!all_finite(palb, (size_t)P * 16))
		FAIL("%s: a palette bind matrix is not finite", x.label);
	pk_cx_done(&x);
	out->kept_count = (uint32_t)Kc;
	out->kept = kept;
	out->palette_size = (uint32_t)P;
	out->palette_joint = palj;
	out->palette_bind = palb;
	out->block = b.base;
	return MLOD_OK;
fail:
	return pk_undo(&x, &b, r);
}

void mlod_pack_skel_level_free(mlod_pack_skel_level *x)
{
	if (x)
		pk_block_release(x->block, x, sizeof *x);
}
