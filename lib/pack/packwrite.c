/*
 * packwrite.c: gathers the levels of every layer and writes the .mlod
 * pack (mlod_pack_write.h; the layout is rt/mlod_pack.h's). The pack
 * writer's files are listed in packwrite_internal.h.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "pack/packwrite_internal.h"

static double now_seconds(void)
{
	struct timespec ts;
	timespec_get(&ts, TIME_UTC);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

void mlod_pack_options_default(mlod_pack_options *opt)
{
	static const double ratios[] = {MLOD_MESH_RATIOS_DEFAULT}, bounds[] = {MLOD_PACK_MOTION_BOUNDS_DEFAULT};
	memset(opt, 0, sizeof *opt);
	opt->codec = MLOD_CODEC_MESHOPT;
	opt->entropy = MLOD_ENTROPY_ZSTD;
	opt->skel_max_error = MLOD_SKEL_MAX_ERROR_DEFAULT;
	opt->ratio_count = (int)(sizeof ratios / sizeof *ratios);
	memcpy(opt->ratios, ratios, sizeof ratios);
	opt->mesh_max_error = -1.0;
	opt->position_bits = MLOD_PACK_POSITION_BITS_DEFAULT;
	opt->normal_bits = MLOD_PACK_NORMAL_BITS_DEFAULT;
	opt->uv_bits = MLOD_PACK_UV_BITS_DEFAULT;
	opt->coarse_share = MLOD_PACK_COARSE_SHARE;
	opt->motion_bound_count = (int)(sizeof bounds / sizeof *bounds);
	opt->motion_level0_error = MLOD_PACK_MOTION_LEVEL0_DEFAULT;
	opt->motion_level0_percent = 1;
	for (int i = 0; i < opt->motion_bound_count; i++) {
		opt->motion_bounds[i] = bounds[i];
		opt->motion_percent[i] = 1;
	}
}

static void ctx_free(struct ctx *x)
{
	pack_mesh_parts_free(x);
	for (int k = 0; k < MLOD_SKEL_MAX_LEVELS; k++) {
		free(x->kept[k]);
		free(x->remap[k]);
	}
	for (int k = 0; k < MLOD_MESH_MAX_LEVELS; k++)
		free(x->level_node[k]);
	if (x->has_ML)
		mlod_mesh_levels_free(&x->ML);
	for (int i = 0; i < x->owned_count; i++)
		mlod_motion_level_free(&x->owned_levels[i]);
	free(x->owned_levels);
	for (int q = 0; x->level0_owned && q < x->v.clip_count; q++)
		mlod_motion_level_free(&x->level0_owned[q]);
	free(x->level0_owned);
	for (int q = 0; x->clips && q < x->v.clip_count; q++) {
		for (int k = 0; k <= MLOD_PACK_MAX_MOTION_LEVELS; k++)
			mlod_motion_level_free(&x->clips[q].remade[k]);
		free(x->clips[q].shift), free(x->clips[q].tgrid), free(x->clips[q].at), free(x->clips[q].world);
	}
	for (int i = 0; x->motion_imgs && i < 2 * x->v.clip_count; i++)
		pack_motion_img_free(&x->motion_imgs[i]);
	free(x->motion_imgs);
	free(x->clips);
	free(x->world);
	free(x->view_skin);
	free(x->v.skeleton.skins);
	free(x->v.instances);
	free(x->v.clips);
	mlod_record_free(&x->rec);
}

static uint64_t layer_bytes(const chunks *ch, int layer, int raw)
{
	uint64_t n = 0;
	for (int i = 0; i < ch->n; i++)
		if (ch->c[i].layer == layer)
			n += raw ? ch->c[i].raw : ch->c[i].size;
	return n;
}

/* Level 0 is the finest motion level: its bound (motion_level0_error)
 * must be below the smallest of the coarser levels' (motion_bounds),
 * each in units or % of the character's height. */
static mlod_result check_level0_bound(const mlod_pack_options *o, const mlod_character *c, mlod_error *err)
{
	if (o->lossless_motion || o->no_motion_levels || c->clip_count == 0 || !(o->motion_level0_error > 0.0))
		return MLOD_OK;
	double h = c->skeleton.joint_count > 0 ? mlod_skeleton_height(&c->skeleton) : 0.0, e1 = 0.0;
	double e0 = o->motion_level0_percent ? o->motion_level0_error * h / 100.0 : o->motion_level0_error;
	int first = -1;
	for (int b = 0; b < o->motion_bound_count; b++) {
		double e = o->motion_percent[b] ? o->motion_bounds[b] * h / 100.0 : o->motion_bounds[b];
		if (first < 0 || e < e1)
			first = b, e1 = e;
	}
	if (!(first >= 0 && e0 >= e1))
		return MLOD_OK;
	return mlod_fail(err, MLOD_ERR_INVALID_ARG,
	                 "motion level 0's bound %g%s (%.4g units) is not below the first motion level's bound, "
	                 "%g%s (%.4g units of a height of %.4g): level 0 is the finest",
	                 o->motion_level0_error, o->motion_level0_percent ? "%" : "", e0, o->motion_bounds[first],
	                 o->motion_percent[first] ? "%" : "", e1, h);
}

mlod_result mlod_pack_write(const mlod_gltf *doc, const mlod_character *c, mlod_format format, const void *input,
                            size_t input_size, const mlod_pack_options *opt, void **out, size_t *out_size,
                            mlod_pack_stats *stats, mlod_error *err)
{
	struct ctx x;
	mlod_pack_stats local_stats;
	chunks body = {0}, head = {0};
	mlod_result r;
	double t0;
	if (!c || !opt || !out || !out_size)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_pack_write: c, opt, out and out_size must not be NULL");
	*out = NULL;
	*out_size = 0;
	if (opt->codec != MLOD_CODEC_NONE && opt->codec != MLOD_CODEC_MESHOPT && opt->codec != MLOD_CODEC_DRACO)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "unknown codec %d", (int)opt->codec);
	if (opt->entropy != MLOD_ENTROPY_NONE && opt->entropy != MLOD_ENTROPY_ZSTD)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "unknown entropy stage %d", opt->entropy);
	if ((r = check_level0_bound(opt, c, err)) != MLOD_OK)
		return r;
	memset(&x, 0, sizeof x);
	x.doc = doc;
	x.in = c;
	x.format = format;
	/* Draco codes the MESH chunks; the other chunks take meshopt. */
	mlod_pack_options mopt = *opt;
	x.draco = opt->codec == MLOD_CODEC_DRACO;
	if (x.draco)
		mopt.codec = MLOD_CODEC_MESHOPT;
	x.opt = &mopt;
	x.st = stats ? stats : &local_stats;
	x.err = err;
	memset(x.st, 0, sizeof *x.st);
	/* The reader's notes first, one note per line of them. */
	size_t len;
	for (const char *w = c->notes, *l; (l = mlod_next_line(&w, &len));)
		if (len > 0)
			pack_note_n(&x, l, len);
	if (doc && (r = mlod_record_read(doc, &x.rec, err)) != MLOD_OK)
		return r;
	if ((r = pack_make_view(&x)) != MLOD_OK || (r = pack_measure(&x)) != MLOD_OK)
		goto done;
	if (mlod_mesh_triangle_primitives(&x.v) > 0 && (r = pack_note_unstored_attributes(&x, doc)) != MLOD_OK)
		goto done;
	pack_note_unweighted(&x);

	/* The levels of each layer. */
	t0 = now_seconds();
	if ((r = pack_skeleton_levels(&x)) != MLOD_OK)
		goto done;
	x.st->skeleton.seconds = now_seconds() - t0;
	t0 = now_seconds();
	if ((r = pack_mesh_levels(&x)) != MLOD_OK)
		goto done;
	x.st->mesh.seconds = now_seconds() - t0;
	t0 = now_seconds();
	if ((r = pack_motion_levels(&x)) != MLOD_OK)
		goto done;
	int A = 0; /* motion levels counting level 0 */
	for (int q = 0; q < x.v.clip_count; q++)
		A = x.clips[q].count + 1 > A ? x.clips[q].count + 1 : A;
	for (int q = 0; q < x.v.clip_count; q++) /* a clip with fewer levels repeats its coarsest */
		for (int k = x.clips[q].count; k < A - 1; k++) {
			x.clips[q].clip[k] = k ? x.clips[q].clip[k - 1] : x.clips[q].level0;
			x.clips[q].error[k] = k ? x.clips[q].error[k - 1] : x.clips[q].error0;
		}
	if ((r = pack_motion_shift_choice(&x, A)) != MLOD_OK)
		goto done;
	x.st->motion.seconds = now_seconds() - t0;
	if (!(x.motion_imgs = calloc(2 * (size_t)x.v.clip_count + 1, sizeof *x.motion_imgs))) {
		r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
		goto done;
	}

	/* The chunks after INFO, in file order. */
	int S = 1 + x.skel_count;
	int M = mlod_mesh_triangle_primitives(&x.v) > 0 ? 1 + x.mesh_count : 0;
	int parts0 = 0;
	t0 = now_seconds();
	if ((r = pack_skeleton_chunk(&x, &body)) != MLOD_OK)
		goto done;
	for (int k = S - 1; k >= 1; k--)
		if ((r = pack_skel_level_chunk(&x, k, &body)) != MLOD_OK)
			goto done;
	x.st->skeleton.seconds += now_seconds() - t0;
	/* Rank i from the coarsest: mesh level M - 1 - i, then motion level
	 * A - 1 - i of every clip, so that the coarsest of both layers come
	 * first however many levels each has (mlod(5) Chunk order). */
	int top = (M > A ? M : A) - 1;
	for (int i = 0; i <= top; i++) {
		int mk = M - 1 - i, k = A - 1 - i;
		t0 = now_seconds();
		if (mk >= 0) {
			int np = 0;
			if ((r = pack_mesh_chunk(&x, mk, &body, &np)) != MLOD_OK)
				goto done;
			if (mk == 0)
				parts0 = np;
		}
		x.st->mesh.seconds += now_seconds() - t0;
		t0 = now_seconds();
		for (int q = 0; k >= 0 && q < x.v.clip_count; q++) {
			const mlod_clip *cl = k == 0 ? x.clips[q].level0 : x.clips[q].clip[k - 1];
			motion_img *mi = &x.motion_imgs[2 * q + (k & 1)], *base = k + 1 < A ? &x.motion_imgs[2 * q + !(k & 1)] : NULL;
			if ((r = pack_motion_chunk(&x, cl, k, q, k == 0 ? x.clips[q].error0 : x.clips[q].error[k - 1], base, mi,
			                           &body)) != MLOD_OK)
				goto done;
			/* The TOC error of a level with one (not the clip as read):
			 * the level's as the reader returns it (its keys on the
			 * lattices and grids), when above that of the values given
			 * (mlod(5) QUANTISATION), and its switch distance with it.
			 * A pack's level 0 and its levels (mlod-pack -x) keep that
			 * pack's errors: their keys come back as read
			 * (motion_shift_choice), measured against its level 0. */
			if (body.c[body.n - 1].error > 0.0f && !x.clips[q].packed) {
				double me = pack_img_error(&x, q, cl, mi, err);
				if (me < 0) {
					r = MLOD_ERR_NOMEM;
					goto done;
				}
				if ((float)me > body.c[body.n - 1].error) {
					body.c[body.n - 1].error = (float)me;
					body.c[body.n - 1].distance = k > 0 ? mlod_pack_switch_distance((float)me) : 0.0f;
					if (!isfinite((float)me) || !isfinite(body.c[body.n - 1].distance)) {
						r = mlod_fail(err, MLOD_ERR_PARSE,
						              "MOTION level %d of clip %d: error %g as read back is not finite or gives a "
						              "switch distance that is not (are the input's coordinates too large?)",
						              k, q, me);
						goto done;
					}
				}
			}
			x.clips[q].toc[k] = body.c[body.n - 1].error;
			/* A reduced level 0 that stores more than the clip as read
			 * gives way to it (error 0). */
			if (k == 0 && cl != &x.v.clips[q]) {
				chunks alt = {0};
				motion_img alt_img = {0};
				r = pack_motion_chunk(&x, &x.v.clips[q], 0, q, 0.0f, base, &alt_img, &alt);
				if (r == MLOD_OK && alt.c[0].size < body.c[body.n - 1].size) {
					x.clips[q].toc[0] = 0.0f;
					free(body.c[body.n - 1].data);
					body.c[body.n - 1] = alt.c[0];
					alt.n = 0;
					x.clips[q].level0 = &x.v.clips[q];
					x.clips[q].error0 = 0.0f;
				}
				for (int i = 0; i < alt.n; i++)
					free(alt.c[i].data);
				free(alt.c);
				pack_motion_img_free(&alt_img);
				if (r != MLOD_OK)
					goto done;
			}
		}
		x.st->motion.seconds += now_seconds() - t0;
	}
	/* DOC: the input without what the levels hold (mlod_gltf_strip_levels),
	 * or as read when it cannot be stripped. */
	{
		chunkb cb = {0};
		void *glb = NULL;
		size_t glb_size = 0;
		mlod_gltf *copy = NULL;
		mlod_error serr = {0};
		mlod_result sr = doc ? pack_doc_copy(&x, doc, &copy, &serr) : MLOD_ERR_INVALID_ARG;
		int *joint_nodes = malloc(sizeof(int) * ((size_t)c->skeleton.joint_count + 1)), jn = 0;
		if (!joint_nodes)
			sr = mlod_fail(&serr, MLOD_ERR_NOMEM, "out of memory");
		for (int j = 0; joint_nodes && j < c->skeleton.joint_count; j++)
			joint_nodes[jn++] = c->skeleton.joints[j].node;
		unsigned char *strip = NULL;
		if (sr == MLOD_OK && !opt->doc_whole && (sr = pack_doc_strip_flags(&x, copy, &strip, &serr)) == MLOD_OK)
			sr = mlod_gltf_strip_levels(copy, joint_nodes, jn, strip, &serr);
		free(strip);
		free(joint_nodes);
		if (sr == MLOD_OK && !opt->doc_whole)
			sr = pack_doc_dedupe(&x, copy, 0, &serr);
		if (sr == MLOD_OK)
			sr = mlod_gltf_write(copy, 1, &glb, &glb_size, &serr);
		mlod_gltf_free(copy);
		copy = NULL;
		int whole = 0;
		if (sr == MLOD_ERR_UNSUPPORTED && doc && !opt->doc_whole) {
			/* An extension mlod does not know may hold any index: the
			 * document stays whole, but for what goes without moving an
			 * index (mlod_gltf_keep_indices): the stages' records and
			 * MSFT_lod, and the levels the stages and -x append at the
			 * ends of the arrays, so that unpacking and packing again
			 * gives the same document. */
			mlod_error werr = {0};
			mlod_result wr = mlod_gltf_copy(doc, &copy, &werr);
			mlod_free(glb);
			glb = NULL;
			if (wr == MLOD_OK) {
				mlod_gltf_keep_indices(copy, 1);
				for (int n = 0; wr == MLOD_OK && n < mlod_gltf_count(copy, MLOD_GLTF_NODE); n++)
					wr = mlod_gltf_clear_lod(copy, n, &werr);
			}
			if (wr == MLOD_OK)
				wr = pack_doc_dedupe(&x, copy, 1, &werr);
			if (wr == MLOD_OK)
				wr = mlod_gltf_write(copy, 1, &glb, &glb_size, &werr);
			mlod_gltf_free(copy);
			if (wr == MLOD_ERR_NOMEM) {
				mlod_free(glb);
				r = mlod_fail(err, wr, "%s", werr.message);
				goto done;
			}
			whole = wr == MLOD_OK;
		}
		if (sr != MLOD_OK && (whole || (format == MLOD_FORMAT_GLB && input) || doc)) {
			snprintf(x.st->doc_note, sizeof x.st->doc_note, "the document chunk holds the input whole: %s",
			         serr.message);
			pack_note(&x, x.st->doc_note);
		}
		if (sr == MLOD_OK) {
			pack_cb_add(&cb, MLOD_STREAM_GLB, (uint32_t)glb_size, 1, glb, 0);
			x.st->doc_stripped = !opt->doc_whole;
		} else if (whole) {
			pack_cb_add(&cb, MLOD_STREAM_GLB, (uint32_t)glb_size, 1, glb, 0);
		} else if (format == MLOD_FORMAT_GLB && input) {
			pack_cb_add(&cb, MLOD_STREAM_GLB, (uint32_t)input_size, 1, input, 0);
		} else if (doc) {
			mlod_free(glb);
			glb = NULL;
			if ((r = mlod_gltf_write(doc, 1, &glb, &glb_size, err)) != MLOD_OK)
				goto done;
			pack_cb_add(&cb, MLOD_STREAM_GLB, (uint32_t)glb_size, 1, glb, 0);
		} else {
			pack_cb_add(&cb, MLOD_STREAM_GLB, 0, 1, NULL, 0);
		}
		mlod_free(glb);
		if ((r = pack_cb_finish(&cb, MLOD_CODEC_NONE, &body, MLOD_CHUNK_DOC, MLOD_LAYER_NONE, 0, 0, 0.0f, err)) !=
		    MLOD_OK)
			goto done;
	}

	/* The stream codecs by the entropy stage's bytes. */
	for (int i = 0; opt->entropy == MLOD_ENTROPY_ZSTD && i < body.n; i++)
		if ((r = pack_chunk_stream_choice(&body.c[i], err)) != MLOD_OK)
			goto done;

	/* The entropy stage, after every choice above was made on the codec's
	 * bytes (INFO has none: its size must not depend on the offsets). */
	/* Finest first, so that the coarser MESH levels, a finer level's
	 * prefix, and SKELETON, a skeleton level's, are still their containers. */
	for (int i = body.n - 1; opt->entropy == MLOD_ENTROPY_ZSTD && i >= 0; i--) {
		size_t np = 0;
		uint8_t *pre = NULL;
		if (body.c[i].type == MLOD_CHUNK_MESH && body.c[i].codec != MLOD_CODEC_DRACO) { /* Draco: standalone */
			for (int j = 0; j < i; j++)
				if (body.c[j].type == MLOD_CHUNK_MESH)
					np += body.c[j].size;
			if (np && !(pre = malloc(np))) {
				r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory writing the pack");
				goto done;
			}
			for (size_t j = 0, o = 0; (int)j < i; j++)
				if (body.c[j].type == MLOD_CHUNK_MESH)
					memcpy(pre + o, body.c[j].data, body.c[j].size), o += body.c[j].size;
		}
		if (body.c[i].type == MLOD_CHUNK_SKELETON && body.c[i].level > 0)
			for (int j = 0; j < i && !np; j++)
				if (body.c[j].type == MLOD_CHUNK_SKELETON && body.c[j].level == 0) {
					if (!(pre = malloc(body.c[j].size))) {
						r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory writing the pack");
						goto done;
					}
					memcpy(pre, body.c[j].data, body.c[j].size);
					np = body.c[j].size;
				}
		r = pack_chunk_entropy(&body.c[i], pre, np, err);
		free(pre);
		if (r != MLOD_OK)
			goto done;
	}

	/* INFO: its size does not depend on its values (its streams are raw). */
	mlod_buf names = MLOD_BUF_INIT;
	mlod_pack_info_rec info;
	memset(&info, 0, sizeof info);
	info.name = pack_str_add(&names, opt->name                   ? opt->name
	                                 : x.rec.has_pack            ? x.rec.pack_name
	                                 : opt->default_name         ? opt->default_name
	                                                             : "");
	for (int q = 0; q < x.v.clip_count; q++)
		pack_str_add(&names, x.v.clips[q].name);
	if (names.status != MLOD_OK) {
		mlod_buf_free(&names);
		r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
		goto done;
	}
	info.joint_count = (uint32_t)x.v.skeleton.joint_count;
	info.skin_count = (uint32_t)x.v.skeleton.skin_count;
	info.skeleton_levels = (uint32_t)S;
	info.mesh_levels = (uint32_t)M;
	info.clip_count = (uint32_t)x.v.clip_count;
	info.motion_levels = (uint32_t)A;
	info.instance_count = (uint32_t)parts0;
	if (x.max_vertices > UINT32_MAX / 2) { /* the runtime's limit of a level's vertices */
		mlod_buf_free(&names);
		r = mlod_fail(err, MLOD_ERR_LIMIT, "a mesh level of %llu vertices: more than a pack holds (%u)",
		              (unsigned long long)x.max_vertices, UINT32_MAX / 2);
		goto done;
	}
	info.max_vertex_count = (uint32_t)x.max_vertices;
	for (int a = 0; a < 3; a++) {
		info.bounds_min[a] = x.bmin[a];
		info.bounds_max[a] = x.bmax[a];
	}
	info.height = x.height;
	info.diagonal = x.diag;
	size_t info_size = 4 + 2 * 16 + ((sizeof info + 3) & ~(size_t)3) + ((names.size + 3) & ~(size_t)3);
	/* Offsets. */
	uint64_t off = MLOD_PACK_HEADER_SIZE + (uint64_t)MLOD_PACK_TOC_ENTRY_SIZE * (uint64_t)(body.n + 1);
	off = (off + 15) & ~(uint64_t)15;
	uint64_t info_off = off;
	off += info_size;
	uint64_t first = off;
	for (int i = 0; i < body.n; i++) {
		off = (off + 15) & ~(uint64_t)15;
		body.c[i].offset = off;
		off += body.c[i].size;
		chunk *ch = &body.c[i];
		int needed = ch->type == MLOD_CHUNK_SKELETON ? ch->level == 0 || ch->level == S - 1
		             : ch->type == MLOD_CHUNK_MESH    ? ch->level == M - 1
		             : ch->type == MLOD_CHUNK_MOTION  ? ch->level == A - 1
		                                              : 0;
		if (needed && off > first)
			first = off;
	}
	uint64_t file_size = off;
	if (file_size > UINT32_MAX || body.n + 1 > MLOD_PACK_MAX_CHUNKS) {
		mlod_buf_free(&names);
		r = mlod_fail(err, MLOD_ERR_LIMIT, "the pack would be larger than 4 GiB");
		goto done;
	}
	info.first_drawable = (uint32_t)first;
	{
		chunkb cb = {0};
		pack_cb_add(&cb, MLOD_STREAM_INFO, 1, sizeof info, &info, 0);
		pack_cb_add(&cb, MLOD_STREAM_NAME, (uint32_t)names.size, 1, names.data, 0);
		mlod_buf_free(&names);
		if ((r = pack_cb_finish(&cb, MLOD_CODEC_NONE, &head, MLOD_CHUNK_INFO, MLOD_LAYER_NONE, 0, 0, 0.0f, err)) !=
		    MLOD_OK)
			goto done;
		head.c[0].offset = info_off;
	}

	/* Header, TOC, chunks. */
	{
		mlod_buf f = MLOD_BUF_INIT;
		int n = body.n + 1;
		mlod_buf_append_zeros(&f, MLOD_PACK_HEADER_SIZE + (size_t)MLOD_PACK_TOC_ENTRY_SIZE * (size_t)n);
		if (f.status != MLOD_OK) {
			r = mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
			goto done;
		}
		for (int i = 0; i < n; i++) {
			chunk *ch = i == 0 ? &head.c[0] : &body.c[i - 1];
			buf_pad(&f, MLOD_PACK_ALIGN);
			if (f.status != MLOD_OK || f.size != ch->offset)
				break;
			uint8_t *e = f.data + MLOD_PACK_HEADER_SIZE + (size_t)MLOD_PACK_TOC_ENTRY_SIZE * (size_t)i;
			put_u32(e, ch->type);
			e[4] = ch->layer;
			e[5] = (uint8_t)(ch->codec | ch->entropy << 4);
			put_u32(e + 12, ch->entropy ? ch->coded : 0);
			put_u16(e + 6, ch->level);
			put_u16(e + 8, ch->item);
			put_u16(e + 10, ch->flags);
			put_u64(e + 16, ch->offset);
			put_u32(e + 24, (uint32_t)ch->size);
			put_u32(e + 28, ch->raw);
			put_u32(e + 32, mlod_pack_crc32(0, ch->data, ch->size));
			put_f32(e + 36, ch->error);
			put_f32(e + 40, ch->distance);
			mlod_buf_append(&f, ch->data, ch->size);
		}
		if (f.status != MLOD_OK || f.size != file_size) {
			r = mlod_fail(err, f.status != MLOD_OK ? MLOD_ERR_NOMEM : MLOD_ERR_INVALID_ARG,
			              "writing the pack: layout mismatch");
			mlod_buf_free(&f);
			goto done;
		}
		memcpy(f.data, MLOD_PACK_MAGIC, 4);
		put_u16(f.data + 4, MLOD_PACK_MAJOR);
		put_u16(f.data + 6, MLOD_PACK_MINOR);
		put_u32(f.data + 8, 0);
		put_u32(f.data + 12, (uint32_t)n);
		put_u64(f.data + 16, file_size);
		put_u32(f.data + 24, mlod_pack_crc32(0, f.data + MLOD_PACK_HEADER_SIZE, (size_t)MLOD_PACK_TOC_ENTRY_SIZE * (size_t)n));
		put_u32(f.data + 28, mlod_pack_crc32(0, f.data, 28));
		/* The pack through its reader's own rules (mlod_pack_open's TOC,
		 * mlod_pack_check's chunks): never a pack the reader refuses. */
		mlod_pack rp;
		mlod_error rerr = {0};
		mlod_result rr = mlod_pack_open(f.data, f.size, &rp, &rerr);
		if (rr == MLOD_OK) {
			rr = mlod_pack_check(&rp, f.data, f.size, &rerr);
			mlod_pack_close(&rp);
		}
		if (rr != MLOD_OK) {
			mlod_buf_free(&f);
			r = mlod_fail(err, rr == MLOD_ERR_NOMEM ? rr : MLOD_ERR_LIMIT,
			              "the pack as written fails its reader's check: %s", rerr.message);
			goto done;
		}
		*out = f.data;
		*out_size = f.size;
	}

	/* Stats. */
	{
		mlod_pack_stats *st = x.st;
		st->skeleton.levels = S;
		st->mesh.levels = M;
		st->motion.levels = A;
		for (int k = 1; k < S; k++)
			st->skeleton.errors[k] = x.skel_error[k - 1];
		for (int k = 1; k < M; k++)
			st->mesh.errors[k] = x.mesh_error[k - 1];
		for (int k = 0; k < A; k++)
			for (int q = 0; q < x.v.clip_count; q++) {
				float e = x.clips[q].toc[k];
				st->motion.errors[k] = e > st->motion.errors[k] ? e : st->motion.errors[k];
			}
		st->skeleton.stored = layer_bytes(&body, MLOD_LAYER_SKELETON, 0);
		st->skeleton.raw = layer_bytes(&body, MLOD_LAYER_SKELETON, 1);
		st->mesh.stored = layer_bytes(&body, MLOD_LAYER_MESH, 0);
		st->mesh.raw = layer_bytes(&body, MLOD_LAYER_MESH, 1);
		st->motion.stored = layer_bytes(&body, MLOD_LAYER_MOTION, 0);
		st->motion.raw = layer_bytes(&body, MLOD_LAYER_MOTION, 1);
		st->info_bytes = head.c[0].size;
		st->doc_bytes = body.c[body.n - 1].size;
		st->total = file_size;
		st->chunks = (uint32_t)(body.n + 1);
		st->first_drawable = info.first_drawable;
		st->joints = x.v.skeleton.joint_count;
		st->skins = x.v.skeleton.skin_count;
		st->parts = parts0;
		st->clips = x.v.clip_count;
		st->height = x.height;
		st->diagonal = x.diag;
	}
	r = MLOD_OK;
done:
	for (int i = 0; i < body.n; i++)
		free(body.c[i].data);
	free(body.c);
	for (int i = 0; i < head.n; i++)
		free(head.c[i].data);
	free(head.c);
	ctx_free(&x);
	return r;
}
