/*
 * rd_motion.c: the pack reader's MOTION levels (each clip's, nested on
 * the coarser ones).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MLOD_PACK_READER /* pack_internal.h: the reader's own part */
#include "pack_internal.h"

/* ------------------------------------------------------------------ */
/* MOTION level k of clip c                                            */
/* ------------------------------------------------------------------ */

/* The base channel of a rotation channel: the base's non-cubic rotation
 * of the same joint, or NULL. */
static const mlod_pack_channel *base_channel(const mlod_pack_motion *base, uint32_t joint)
{
	for (uint32_t i = 0; base && i < base->channel_count; i++)
		if (base->channels[i].rec.joint == joint && base->channels[i].rec.path == 1 && base->channels[i].rec.interp != 2)
			return &base->channels[i];
	return NULL;
}

/* The same for a non-cubic translation or scale channel (path). */
static const mlod_pack_channel *base_vec_channel(const mlod_pack_motion *base, const mlod_pack_channel_rec *rc)
{
	for (uint32_t i = 0; base && rc->interp != 2 && i < base->channel_count; i++)
		if (base->channels[i].rec.joint == rc->joint && base->channels[i].rec.path == rc->path &&
		    base->channels[i].rec.interp != 2)
			return &base->channels[i];
	return NULL;
}

/* The index of time t in a base channel's times (increasing), or -1. */
/* The key of base channel bc at time t, or -1. *from: where the search
 * starts, the previous call's key slot on the same channel (0 for the
 * first): a channel's keys are visited in time order, so the search gallops
 * forward from there, and the whole channel costs linear time instead of
 * a binary search per key (the probe's 50,000-frame clip spent 71% of its
 * decoding here). The key found is the same as a search from 0 (when the
 * time before *from is below t; else it searches from 0). */
static int64_t base_key(const mlod_pack_channel *bc, float t, uint32_t *from)
{
	uint32_t n = bc ? bc->rec.key_count : 0, lo = *from < n ? *from : n, hi, step = 1;
	if (lo > 0 && !(bc->times[lo - 1] < t))
		lo = 0;
	/* the key is at lo or after (times[lo - 1] < t); gallop until a time
	 * at hi is not below t, then search [lo, hi) */
	for (hi = lo; hi < n && bc->times[hi] < t; step *= 2)
		lo = hi + 1, hi = n - hi > step ? hi + step : n;
	while (lo < hi) {
		uint32_t mid = lo + (hi - lo) / 2;
		if (bc->times[mid] < t)
			lo = mid + 1;
		else
			hi = mid;
	}
	*from = lo;
	return lo < n && bc->times[lo] == t ? (int64_t)lo : -1;
}

mlod_result mlod_pack_decode_motion(const mlod_pack *p, uint32_t chunk, const void *data, size_t size,
                                    const mlod_pack_skeleton *skel, mlod_pack_motion *out, mlod_error *err)
{
	if (!out)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_pack_decode_motion: out is NULL");
	memset(out, 0, sizeof *out);
	if (!p || chunk >= p->chunk_count || p->chunks[chunk].type != MLOD_CHUNK_MOTION ||
	    !(p->chunks[chunk].flags & MLOD_PACK_CHUNK_NESTED))
		return mlod_pack_decode_motion_on(p, chunk, data, size, skel, NULL, out, err);
	/* The chain of levels it builds on, decoded from the coarsest up. */
	const mlod_pack_chunk *c = &p->chunks[chunk];
	unsigned top = c->level;
	int ci = (int)chunk;
	while (ci >= 0 && (p->chunks[ci].flags & MLOD_PACK_CHUNK_NESTED)) {
		if (top - c->level >= MLOD_PACK_MAX_NESTING)
			return mlod_fail(err, MLOD_ERR_PARSE, "MOTION level %u of clip %u: more than %d nested levels in a row",
			                 (unsigned)c->level, (unsigned)c->item, MLOD_PACK_MAX_NESTING);
		if (top == 65535 || (ci = mlod_pack_find(p, MLOD_CHUNK_MOTION, top + 1, c->item)) < 0)
			return mlod_fail(err, MLOD_ERR_PARSE, "MOTION level %u of clip %u: builds on level %u, which the pack lacks",
			                 top, (unsigned)c->item, top + 1);
		top++;
	}
	mlod_pack_motion base = {0}, next;
	for (unsigned l = top + 1; l-- > c->level;) {
		int k = l == c->level ? (int)chunk : mlod_pack_find(p, MLOD_CHUNK_MOTION, l, c->item);
		mlod_result r = mlod_pack_decode_motion_on(p, (uint32_t)k, data, size, skel, l == top ? NULL : &base,
		                                           l == c->level ? out : &next, err);
		mlod_pack_motion_free(&base);
		if (r != MLOD_OK)
			return r;
		if (l > c->level)
			base = next;
	}
	return MLOD_OK;
}

mlod_result mlod_pack_decode_motion_on(const mlod_pack *p, uint32_t chunk, const void *data, size_t size,
                                       const mlod_pack_skeleton *skel, const mlod_pack_motion *base,
                                       mlod_pack_motion *out, mlod_error *err)
{
	return mlod_pack_decode_motion_reserve(p, chunk, data, size, skel, base, NULL, NULL, out, err);
}

mlod_result mlod_pack_decode_motion_reserve(const mlod_pack *p, uint32_t chunk, const void *data, size_t size,
                                            const mlod_pack_skeleton *skel, const mlod_pack_motion *base,
                                            mlod_pack_motion_reserve_fn reserve, void *reserve_user,
                                            mlod_pack_motion *out, mlod_error *err)
{
	if (!out)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_pack_decode_motion: out is NULL");
	memset(out, 0, sizeof *out);
	cx x;
	bump b = {0};
	stream s;
	const uint8_t *src;
	mlod_result r = pk_cx_begin(p, chunk, MLOD_CHUNK_MOTION, data, size, &x, err);
	if (r != MLOD_OK)
		return r;
	const int nested = (x.c->flags & MLOD_PACK_CHUNK_NESTED) != 0;
	if (!nested)
		base = NULL;
	else if (!base)
		FAIL("%s: builds on level %u, which was not given", x.label, (unsigned)x.c->level + 1);
	uint32_t J = skel ? skel->joint_count : 0;
	stream sc, sstep;
	TRY(pk_cx_expect(&x, &sc, MLOD_STREAM_CHAN, sizeof(mlod_pack_channel_rec), UINT64_MAX, "", "", err));
	TRY(pk_cx_expect(&x, &sstep, MLOD_STREAM_STEP, 8, 1, "", "one step", err));
	/* An upper bound of the block from the stream headers alone: what
	 * the channel records may claim (below) before the block is sized
	 * from them. Each channel's values are taken on their own: up to 8
	 * bytes of rounding each. */
	uint64_t C = sc.count, bound = round8(C * sizeof(mlod_pack_channel)) + 8 * C;
	while (cx_next(&x, &s)) {
		/* 'TBIT': each key but an array's first takes a bit at least */
		uint64_t per = s.tag == MLOD_STREAM_TBIT                                 ? 4 * 32
		               : s.tag == MLOD_STREAM_TIME || s.tag == MLOD_STREAM_TICK ? 4
		               : s.tag == MLOD_STREAM_ROTQ || s.tag == MLOD_STREAM_ROTD || s.tag == MLOD_STREAM_ROTF ? 16
		               : s.tag == MLOD_STREAM_VEC3 || s.tag == MLOD_STREAM_VECD   ? 12
		                                                                          : 0;
		if (!per)
			FAIL("%s: stream %u is '%s', not a motion stream", x.label, s.index, tagn(s.tag).s);
		bound += round8(per * s.count);
	}
	cx_rewind(&x);
	/* Scratch: one byte per joint and path (to find a second channel),
	 * the channel records, and each time array's key count and keys, so
	 * that the records are checked and the block sized from them before
	 * it is allocated. */
	const uint64_t a_seen = round8((uint64_t)J * 3), a_recs = round8(C * sizeof(mlod_pack_channel_rec)),
	               a_count = round8(C * 4);
	TRY(pk_cx_temp(&x, a_seen + a_recs + a_count + C * sizeof(float *), err));
	uint8_t *seen = x.temp;
	mlod_pack_channel_rec *recs = x.temp ? (mlod_pack_channel_rec *)(void *)(x.temp + a_seen) : NULL;
	uint32_t *tcount = x.temp ? (uint32_t *)(void *)(x.temp + a_seen + a_recs) : NULL;
	const float **tarr = x.temp ? (const float **)(void *)(x.temp + a_seen + a_recs + a_count) : NULL;
	mlod_pack_channel *chans;
	TRY(pk_cx_expect(&x, &sc, MLOD_STREAM_CHAN, sizeof(mlod_pack_channel_rec), UINT64_MAX, "", "", err));
	TRY(pk_cx_load(&x, &sc, &src, err));
	if (C)
		memcpy(recs, src, (size_t)C * sizeof *recs);
	TRY(pk_cx_expect(&x, &sstep, MLOD_STREAM_STEP, 8, 1, "", "one step", err));
	TRY(pk_cx_load(&x, &sstep, &src, err));
	double step;
	{
		uint64_t bits = rd64(src);
		memcpy(&step, &bits, 8);
	}
	if (!isfinite(step) || !(step >= 0))
		FAIL("%s: step %g is not finite and >= 0", x.label, step);
	float duration = 0;
	static const char *const path_names[3] = {"translation", "rotation", "scale"};
	/* The channels; the time arrays' counts, in first-use order; the
	 * values' bytes, each channel's array on its own. */
	uint64_t T = 0, nt = 0, nq = 0, nf = 0, nv = 0, vbytes = 0;
	for (uint32_t i = 0; i < C; i++) {
		const mlod_pack_channel_rec *rc = &recs[i];
		uint32_t K = rc->key_count;
		if (rc->joint >= J)
			FAIL("%s: channel %u: joint %u is not below the skeleton's %u joints", x.label, i, rc->joint, J);
		if (rc->path > 2)
			FAIL("%s: channel %u: path %u is not 0, 1 or 2", x.label, i, rc->path);
		if (rc->interp > 2)
			FAIL("%s: channel %u: interpolation %u is not 0, 1 or 2", x.label, i, rc->interp);
		if (K == 0)
			FAIL("%s: channel %u: no keys", x.label, i);
		if (seen[3 * (size_t)rc->joint + rc->path])
			FAIL("%s: channel %u: a second %s channel of joint %u", x.label, i, path_names[rc->path], rc->joint);
		seen[3 * (size_t)rc->joint + rc->path] = 1;
		if (rc->time > T)
			FAIL("%s: channel %u: time array %u is not below %llu (the arrays go in first-use order)", x.label, i,
			     rc->time, (unsigned long long)T + 1);
		if (rc->time == T) {
			tcount[T++] = K;
			nt += K;
		} else if (tcount[rc->time] != K) {
			FAIL("%s: channel %u: %u keys, but time array %u has %u", x.label, i, K, rc->time, tcount[rc->time]);
		}
		uint64_t m = rc->interp == 2 ? 3 : 1;
		if (rc->path == 1 && m == 1)
			nq += K;
		else if (rc->path == 1)
			nf += 3 * (uint64_t)K;
		else
			nv += m * K;
		vbytes += round8((rc->path == 1 ? 16 : 12) * m * K);
	}
	/* The key times: one stream, the arrays one after the other. */
	if (!cx_next(&x, &s))
		FAIL("%s: missing its key times", x.label);
	if (step > 0 ? s.tag != MLOD_STREAM_TICK && s.tag != MLOD_STREAM_TBIT : s.tag != MLOD_STREAM_TIME)
		FAIL("%s: stream %u is '%s', expected '%s' (step %g)", x.label, s.index, tagn(s.tag).s,
		     step > 0 ? "TICK' or 'TBIT" : "TIME", step);
	if (s.tag == MLOD_STREAM_TICK ? s.elsize != 2 && s.elsize != 4 : s.elsize != 4)
		FAIL("%s: stream %u '%s' has elements of %u bytes, expected %s", x.label, s.index, tagn(s.tag).s, s.elsize,
		     s.tag == MLOD_STREAM_TICK ? "2 or 4" : "4");
	if (s.tag == MLOD_STREAM_TBIT ? s.count < T : s.count != nt)
		FAIL("%s: stream %u '%s' has %u elements, expected %s%llu (the time arrays' %s)", x.label, s.index,
		     tagn(s.tag).s, s.count, s.tag == MLOD_STREAM_TBIT ? "at least " : "",
		     (unsigned long long)(s.tag == MLOD_STREAM_TBIT ? T : nt),
		     s.tag == MLOD_STREAM_TBIT ? "first ticks" : "keys");
	/* The block, exactly: the channels, the key times, the values. A pack
	 * whose streams hold them is within the bound (each value and time an
	 * element of its stream, a 'TBIT' element 32 keys at most), so records
	 * claiming more are corrupt: they size nothing, the block is the
	 * bound's (as a pack's claims cannot make it larger than its streams),
	 * and the decode fails below where a stream falls short, saying which. */
	const uint64_t total = round8(C * sizeof(mlod_pack_channel)) + round8(nt * 4) + vbytes;
	if (reserve && total <= bound)
		TRY(reserve(reserve_user, recs, (uint32_t)C, BLOCK_HEAD + total, err));
	TRY(pk_bump_alloc(&b, &x, total <= bound ? total : bound, err));
	TAKE(chans, C * sizeof *chans);
	for (uint64_t i = 0; i < C; i++)
		chans[i].rec = recs[i];
	TRY(pk_cx_load(&x, &s, &src, err));
	float *all;
	TAKE(all, nt * 4);
	if (s.tag == MLOD_STREAM_TIME) {
		memcpy(all, src, (size_t)nt * 4);
	} else if (s.tag == MLOD_STREAM_TBIT) { /* each array's first tick, then a bit per tick after it */
		uint64_t nbits = 32 * ((uint64_t)s.count - T), b = 0;
		for (uint64_t t = 0, k = 0; t < T; t++) {
			uint64_t tick = rd32(src + 4 * t);
			for (uint32_t q = 0; q < tcount[t]; q++, k++) {
				while (q > 0) { /* to the next set bit */
					if (b == nbits)
						FAIL("%s: stream %u 'TBIT': time array %u: key %u: the bits run out", x.label, s.index,
						     (unsigned)t, q);
					tick++;
					uint32_t w = rd32(src + 4 * (T + b / 32));
					if (w >> (b++ % 32) & 1u)
						break;
				}
				if (tick > UINT32_MAX)
					FAIL("%s: stream %u 'TBIT': time array %u: key %u: tick %llu is above 2^32 - 1", x.label,
					     s.index, (unsigned)t, q, (unsigned long long)tick);
				all[k] = (float)((double)tick * step);
			}
		}
		if ((b + 31) / 32 != (uint64_t)s.count - T)
			FAIL("%s: stream %u 'TBIT' has %u elements, expected %llu (the arrays' first ticks and bits)", x.label,
			     s.index, s.count, (unsigned long long)(T + (b + 31) / 32));
	} else /* each array's first tick, then each next's difference */
		for (uint64_t t = 0, k = 0; t < T; t++) {
			uint64_t tick = 0;
			for (uint32_t q = 0; q < tcount[t]; q++, k++) {
				tick += s.elsize == 2 ? rd16(src + 2 * k) : rd32(src + 4 * k);
				if (tick > UINT32_MAX)
					FAIL("%s: stream %u '%s': time array %u: key %u: tick %llu is above 2^32 - 1", x.label,
					     s.index, tagn(s.tag).s, (unsigned)t, q, (unsigned long long)tick);
				all[k] = (float)((double)tick * step);
			}
		}
	for (uint64_t t = 0, at = 0; t < T; at += tcount[t++]) {
		const float *times = all + at;
		for (uint32_t k = 0; k < tcount[t]; k++) {
			if (!isfinite(times[k]))
				FAIL("%s: time array %u: key %u: time is not finite", x.label, (unsigned)t, k);
			if (k > 0 && !(times[k] > times[k - 1]))
				FAIL("%s: time array %u: key %u: time %g is not after %g", x.label, (unsigned)t, k,
				     (double)times[k], (double)times[k - 1]);
		}
		tarr[t] = times;
	}
	for (uint32_t i = 0; i < C; i++) {
		mlod_pack_channel *ch = &chans[i];
		const mlod_pack_channel_rec *rc = &ch->rec;
		uint32_t K = rc->key_count;
		const float *times = tarr[rc->time];
		if (times[K - 1] > duration)
			duration = times[K - 1];
		ch->times = times;
	}
	/* The values: 'ROTQ', 'ROTF', 'VEC3', each the keys of its channels
	 * one channel after the other, in channel order. */
	/* 'ROTQ' holds the rotation keys on their own, 'ROTD' those on a key
	 * of the base at the same time (mlod_pack_rotq_key): each element goes
	 * to its key's slot, then every key is decoded in place. */
	uint64_t nd = 0;
	for (uint32_t i = 0; i < C; i++) {
		mlod_pack_channel *ch = &chans[i];
		if (ch->rec.path != 1 || ch->rec.interp == 2)
			continue;
		TAKE(ch->values, (uint64_t)ch->rec.key_count * 16);
		const mlod_pack_channel *bc = base_channel(base, ch->rec.joint);
		uint32_t from = 0;
		for (uint32_t k = 0; bc && k < ch->rec.key_count; k++)
			nd += base_key(bc, ch->times[k], &from) >= 0;
	}
	for (int pass = 0; pass < 2; pass++) {
		if (pass == 0)
			TRY(pk_cx_expect(&x, &s, MLOD_STREAM_ROTQ, 8, nq - nd, "", "rotation keys without a base key", err));
		else
			TRY(pk_cx_expect(&x, &s, MLOD_STREAM_ROTD, 8, nd, "", "rotation keys on a base key", err));
		TRY(pk_cx_load(&x, &s, &src, err));
		for (uint32_t i = 0; i < C; i++) {
			mlod_pack_channel *ch = &chans[i];
			if (ch->rec.path != 1 || ch->rec.interp == 2)
				continue;
			const mlod_pack_channel *bc = base_channel(base, ch->rec.joint);
			uint32_t from = 0;
			for (uint32_t k = 0; k < ch->rec.key_count; k++)
				if ((base_key(bc, ch->times[k], &from) >= 0) == pass) {
					memcpy(ch->values + 4 * (size_t)k, src, 8);
					src += 8;
				}
		}
	}
	for (uint32_t i = 0; i < C; i++) {
		mlod_pack_channel *ch = &chans[i];
		if (ch->rec.path != 1 || ch->rec.interp == 2)
			continue;
		const mlod_pack_channel *bc = base_channel(base, ch->rec.joint);
		int16_t n[4], prev[4], bn[4], nx[4];
		uint32_t from = 0, from_w = 0, w = 0; /* w: the next key after k on a base key (format 9.0) */
		int64_t at_w = -1;
		for (uint32_t k = 0; k < ch->rec.key_count; k++) {
			const uint8_t *e = (const uint8_t *)(ch->values + 4 * (size_t)k);
			int16_t el[4];
			for (int c = 0; c < 4; c++)
				el[c] = rdi16(e + 2 * c);
			int64_t at = base_key(bc, ch->times[k], &from);
			if (at >= 0 && p->major >= 9) /* format 9.0: 'ROTD' zigzagged */
				for (int c = 0; c < 4; c++)
					el[c] = mlod_pack_unzigzag16(el[c]);
			if (at >= 0)
				for (int c = 0; c < 4; c++)
					bn[c] = (int16_t)lrint((double)bc->values[4 * at + c] * 32767.0);
			else if (el[3] < 0 || el[3] > (p->major >= 4 ? 4 * MLOD_PACK_ROTQ_SHIFT_MAX + 3 : 3))
				FAIL("%s: channel %u: rotation key %u: component index and shift %d out of range", x.label, i,
				     k, el[3]);
			if (at < 0 && k > 0 && p->major >= 9) {
				/* the stored components are the differences to
				 * the prediction (mlod_pack_rotq_predict),
				 * zigzagged */
				if (w <= k) { /* the next one, and its key (nx) */
					for (w = k + 1, at_w = -1; w < ch->rec.key_count &&
					                           (at_w = base_key(bc, ch->times[w], &from_w)) < 0;
					     w++)
						;
					if (w < ch->rec.key_count) {
						const uint8_t *ew = (const uint8_t *)(ch->values + 4 * (size_t)w);
						int16_t elw[4], bw[4];
						for (int c = 0; c < 4; c++) {
							elw[c] = mlod_pack_unzigzag16(rdi16(ew + 2 * c));
							bw[c] = (int16_t)lrint((double)bc->values[4 * at_w + c] * 32767.0);
						}
						mlod_pack_rotq_key(elw, bw, NULL, nx);
					}
				}
				int16_t pred[3];
				double f = 0.0;
				if (w < ch->rec.key_count)
					f = ((double)ch->times[k] - (double)ch->times[k - 1]) /
					    ((double)ch->times[w] - (double)ch->times[k - 1]);
				mlod_pack_rotq_predict(el[3], prev, w < ch->rec.key_count ? nx : NULL, f, pred);
				for (int c = 0; c < 3; c++)
					el[c] = (int16_t)(uint16_t)((uint16_t)mlod_pack_unzigzag16(el[c]) + (uint16_t)pred[c]);
			}
			if (at < 0)
				for (int c = 0; c < 3; c++)
					if (el[c] > (32767 >> (el[3] >> 2)) || el[c] < -(32767 >> (el[3] >> 2)))
						FAIL("%s: channel %u: rotation key %u: component %d past the lattice", x.label, i,
						     k, el[c]);
			mlod_pack_rotq_key(el, at >= 0 ? bn : NULL, k > 0 ? prev : NULL, n);
			for (int c = 0; c < 4; c++)
				ch->values[4 * (size_t)k + c] = (float)(n[c] / 32767.0);
			memcpy(prev, n, sizeof prev);
		}
	}
	TRY(pk_cx_expect(&x, &s, MLOD_STREAM_ROTF, 16, nf, "", "3 values per key of the cubic rotations", err));
	TRY(pk_cx_load(&x, &s, &src, err));
	for (uint32_t i = 0; i < C; i++) {
		mlod_pack_channel *ch = &chans[i];
		if (ch->rec.path != 1 || ch->rec.interp != 2)
			continue;
		uint64_t values = 3 * (uint64_t)ch->rec.key_count;
		TAKE(ch->values, values * 16);
		memcpy(ch->values, src, values * 16);
		src += values * 16;
		if (!all_finite(ch->values, values * 4))
			FAIL("%s: channel %u: a rotation value is not finite", x.label, i);
	}
	/* 'VEC3' holds the translation and scale keys without a base key,
	 * 'VECD' those with one (non-cubic, the base's channel of the joint
	 * and path keying the same time) as the differences of their f32 bit
	 * patterns, each wrapped to 32 bits. */
	uint64_t nvd = 0;
	for (uint32_t i = 0; i < C; i++) {
		mlod_pack_channel *ch = &chans[i];
		if (ch->rec.path == 1)
			continue;
		const mlod_pack_channel *bc = base_vec_channel(base, &ch->rec);
		uint32_t from = 0;
		for (uint32_t k = 0; bc && k < ch->rec.key_count; k++)
			nvd += base_key(bc, ch->times[k], &from) >= 0;
	}
	TRY(pk_cx_expect(&x, &s, MLOD_STREAM_VEC3, 12, nv - nvd, "", "translation and scale keys without a base key", err));
	TRY(pk_cx_load(&x, &s, &src, err));
	for (uint32_t i = 0; i < C; i++) {
		mlod_pack_channel *ch = &chans[i];
		if (ch->rec.path == 1)
			continue;
		const mlod_pack_channel *bc = base_vec_channel(base, &ch->rec);
		uint32_t per = ch->rec.interp == 2 ? 3 : 1;
		TAKE(ch->values, (uint64_t)per * ch->rec.key_count * 12);
		uint32_t from = 0;
		for (uint32_t k = 0; k < ch->rec.key_count; k++)
			if (base_key(bc, ch->times[k], &from) < 0) {
				memcpy(ch->values + 3 * (size_t)per * k, src, 12 * (size_t)per);
				src += 12 * (size_t)per;
			}
	}
	TRY(pk_cx_expect(&x, &s, MLOD_STREAM_VECD, 12, nvd, "", "translation and scale keys on a base key", err));
	TRY(pk_cx_load(&x, &s, &src, err));
	for (uint32_t i = 0; i < C; i++) {
		mlod_pack_channel *ch = &chans[i];
		if (ch->rec.path == 1)
			continue;
		const mlod_pack_channel *bc = base_vec_channel(base, &ch->rec);
		uint32_t from = 0;
		for (uint32_t k = 0; bc && k < ch->rec.key_count; k++) {
			int64_t at = base_key(bc, ch->times[k], &from);
			if (at < 0)
				continue;
			for (int c = 0; c < 3; c++) {
				uint32_t bb, v;
				memcpy(&bb, bc->values + 3 * at + c, 4);
				v = bb + rd32(src + 4 * c);
				memcpy(ch->values + 3 * (size_t)k + c, &v, 4);
			}
			src += 12;
		}
		uint64_t values = (ch->rec.interp == 2 ? 3 : 1) * (uint64_t)ch->rec.key_count;
		if (!all_finite(ch->values, values * 3))
			FAIL("%s: channel %u: a %s value is not finite", x.label, i, path_names[ch->rec.path]);
	}
	TRY(pk_cx_end(&x, err));
	pk_cx_done(&x);
	out->channel_count = (uint32_t)C;
	out->channels = chans;
	out->duration = duration;
	out->block = b.base;
	return MLOD_OK;
fail:
	return pk_undo(&x, &b, r);
}

void mlod_pack_motion_free(mlod_pack_motion *x)
{
	if (x)
		pk_block_release(x->block, x, sizeof *x);
}
