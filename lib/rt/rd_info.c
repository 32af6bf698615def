/*
 * rd_info.c: the pack reader's INFO and DOC chunks, and the checks over
 * the whole pack (mlod_pack_check).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MLOD_PACK_READER /* pack_internal.h: the reader's own part */
#include "pack_internal.h"

/* ------------------------------------------------------------------ */
/* INFO                                                                */
/* ------------------------------------------------------------------ */

/* The most vertices a MESH level of this TOC can have, over its levels
 * (INFO's max_vertex_count is at most this; at most UINT32_MAX / 2, the
 * runtime's limit). A layout b2 level's vertices are the prefix vertices
 * its indices use: at most its index count, each index at least 2 decoded
 * bytes of its raw size, and at most the prefix's vertices, each 8 bytes
 * of 'POSQ' in it or a coarser level (the MESH chunks stand coarsest
 * first: the sum of the raw sizes so far). A Draco level's part records
 * claim at most PACK_DRACO_MAX_EXPAND times its container decoded
 * (rd_mesh.c), at least 12 bytes of positions per vertex; its raw size is
 * its container's. */
static uint64_t info_max_vertices_bound(const mlod_pack *p)
{
	uint64_t best = 0, prefix = 0;
	for (uint32_t i = 0; i < p->chunk_count; i++) {
		const mlod_pack_chunk *c = &p->chunks[i];
		if (c->type != MLOD_CHUNK_MESH)
			continue;
		prefix += c->raw_size;
		uint64_t v = c->codec == MLOD_CODEC_DRACO ? (uint64_t)PACK_DRACO_MAX_EXPAND * c->raw_size / 12
		                                          : (c->raw_size / 2 < prefix / 8 ? c->raw_size / 2 : prefix / 8);
		best = v > best ? v : best;
	}
	return best < UINT32_MAX / 2 ? best : UINT32_MAX / 2;
}

mlod_result mlod_pack_decode_info(const mlod_pack *p, const void *data, size_t size, mlod_pack_info *out,
                                  mlod_error *err)
{
	int ci;
	mlod_result r = pk_find_one(p, MLOD_CHUNK_INFO, out, sizeof *out, "mlod_pack_decode_info", &ci, err);
	if (r != MLOD_OK)
		return r;
	cx x;
	bump b = {0};
	stream s_info, s_name;
	const uint8_t *src;
	r = pk_cx_begin(p, (uint32_t)ci, MLOD_CHUNK_INFO, data, size, &x, err);
	if (r != MLOD_OK)
		return r;
	TRY(pk_cx_expect(&x, &s_info, MLOD_STREAM_INFO, sizeof(mlod_pack_info_rec), 1, "", "one record", err));
	TRY(pk_cx_expect(&x, &s_name, MLOD_STREAM_NAME, 1, UINT64_MAX, "", "", err));
	TRY(pk_cx_end(&x, err));
	TRY(pk_cx_temp(&x, 0, err));
	TRY(pk_cx_load(&x, &s_info, &src, err));
	mlod_pack_info_rec rec;
	memcpy(&rec, src, sizeof rec);
	if (!all_finite(rec.bounds_min, 3) || !all_finite(rec.bounds_max, 3) || !isfinite(rec.height) ||
	    !isfinite(rec.diagonal))
		FAIL("%s: the bounds, height and diagonal must be finite", x.label);
	if ((rec.mesh_levels == 0) != (rec.instance_count == 0))
		FAIL("%s: %u mesh levels with %u instances (0 mesh levels means no instances)", x.label, rec.mesh_levels,
		     rec.instance_count);
	if ((rec.motion_levels == 0) != (rec.clip_count == 0))
		FAIL("%s: %u motion levels with %u clips (0 motion levels means no clips)", x.label, rec.motion_levels,
		     rec.clip_count);
	/* max_vertex_count (format 8.1; reserved bytes before, which a reader
	 * ignores): at most what the MESH chunks' TOC raw sizes can hold, so
	 * that a caller sizing its skinning buffers from it at open never
	 * sizes more than those sizes allow (claims until each chunk decodes:
	 * mlod_rt.h says what that leaves a caller of untrusted packs); each
	 * level is checked against it as it decodes (mlod_pack_info_check_mesh,
	 * the runtime's rt_mesh_reserve). */
	if (!mlod_pack_version_has_max_vertices(p->major, p->minor))
		rec.max_vertex_count = 0;
	else if (rec.max_vertex_count > info_max_vertices_bound(p))
		FAIL("%s: max_vertex_count %u is more than its %u MESH levels can hold (%llu vertices at most)", x.label,
		     rec.max_vertex_count, rec.mesh_levels, (unsigned long long)info_max_vertices_bound(p));
	if (rec.first_drawable > p->file_size)
		FAIL("%s: first_drawable %u is past the file's end (%llu)", x.label, rec.first_drawable,
		     (unsigned long long)p->file_size);
	/* first_drawable: where the last of INFO, SKELETON and the coarsest
	 * level of each layer (of every clip) ends */
	uint64_t drawable = 0;
	for (uint32_t i = 0; i < p->chunk_count; i++) {
		const mlod_pack_chunk *c = &p->chunks[i];
		const int coarse = c->type == MLOD_CHUNK_INFO ||
		                   (c->type == MLOD_CHUNK_SKELETON && (c->level == 0 || c->level + 1u == rec.skeleton_levels)) ||
		                   (c->type == MLOD_CHUNK_MESH && c->level + 1u == rec.mesh_levels) ||
		                   (c->type == MLOD_CHUNK_MOTION && c->level + 1u == rec.motion_levels);
		if (coarse && c->offset + c->stored_size > drawable)
			drawable = c->offset + c->stored_size;
	}
	if (rec.first_drawable != drawable)
		FAIL("%s: first_drawable %u, but INFO, SKELETON and the coarsest levels end at byte %llu", x.label,
		     rec.first_drawable, (unsigned long long)drawable);
	/* The TOC holds exactly the levels INFO counts (open made them unique). */
	uint64_t nskel = 0, nmesh = 0, nmotion = 0;
	for (uint32_t i = 0; i < p->chunk_count; i++) {
		const mlod_pack_chunk *c = &p->chunks[i];
		char label[64];
		pk_chunk_label(c->type, c->level, c->item, label, sizeof label);
		if (c->type == MLOD_CHUNK_SKELETON) {
			if (c->level >= rec.skeleton_levels)
				FAIL("%s: the TOC has %s, but INFO counts %u skeleton levels", x.label, label, rec.skeleton_levels);
			nskel++;
		} else if (c->type == MLOD_CHUNK_MESH) {
			if (c->level >= rec.mesh_levels)
				FAIL("%s: the TOC has %s, but INFO counts %u mesh levels", x.label, label, rec.mesh_levels);
			nmesh++;
		} else if (c->type == MLOD_CHUNK_MOTION) {
			if (c->level >= rec.motion_levels || c->item >= rec.clip_count)
				FAIL("%s: the TOC has %s, but INFO counts %u motion levels of %u clips", x.label, label,
				     rec.motion_levels, rec.clip_count);
			nmotion++;
		}
	}
	if (nskel != rec.skeleton_levels || nmesh != rec.mesh_levels ||
	    nmotion != (uint64_t)rec.motion_levels * rec.clip_count)
		FAIL("%s: it counts %u skeleton, %u mesh and %u motion levels of %u clips, but the TOC has %llu SKELETON, "
		     "%llu MESH and %llu MOTION chunks",
		     x.label, rec.skeleton_levels, rec.mesh_levels, rec.motion_levels, rec.clip_count,
		     (unsigned long long)nskel, (unsigned long long)nmesh, (unsigned long long)nmotion);
	/* Every clip name takes at least its NUL. */
	if (rec.clip_count > s_name.count)
		FAIL("%s: %u clips, but the string table 'NAME' has only %u bytes", x.label, rec.clip_count, s_name.count);
	TRY(pk_bump_alloc(&b, &x, round8((uint64_t)rec.clip_count * sizeof(char *)) + round8((uint64_t)s_name.count + 1),
	                  err));
	const char **clip_names;
	char *names;
	TAKE(clip_names, (uint64_t)rec.clip_count * sizeof(char *));
	TRY(pk_load_names(&x, &b, &s_name, &names, err));
	const char *name = NULL;
	TRY(pk_name_at(&x, names, s_name.count, rec.name, &name, "the character", err));
	/* The clips' names follow the character's, one after the other. */
	size_t pos = (size_t)rec.name + strlen(name) + 1;
	for (uint32_t c = 0; c < rec.clip_count; c++) {
		if (pos >= s_name.count)
			FAIL("%s: the string table 'NAME' ends before clip %u's name", x.label, c);
		clip_names[c] = names + pos;
		pos += strlen(names + pos) + 1;
	}
	pk_cx_done(&x);
	out->rec = rec;
	out->has_max_vertices = mlod_pack_version_has_max_vertices(p->major, p->minor);
	out->name = name;
	out->clip_names = clip_names;
	out->block = b.base;
	return MLOD_OK;
fail:
	return pk_undo(&x, &b, r);
}

void mlod_pack_info_free(mlod_pack_info *x)
{
	if (x)
		pk_block_release(x->block, x, sizeof *x);
}

/* ------------------------------------------------------------------ */
/* DOC                                                                 */
/* ------------------------------------------------------------------ */

/* The DOC chunk's 'GLB ' stream, checked; x is left open (pk_cx_done). */
static mlod_result doc_begin(const mlod_pack *p, const void *data, size_t size, cx *x, stream *s, mlod_error *err)
{
	if (!p)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_pack_doc: the pack is NULL");
	int ci = mlod_pack_find(p, MLOD_CHUNK_DOC, 0, 0);
	if (ci < 0)
		return mlod_fail(err, MLOD_ERR_PARSE, "the pack has no DOC chunk");
	mlod_result r = pk_cx_begin(p, (uint32_t)ci, MLOD_CHUNK_DOC, data, size, x, err);
	if (r != MLOD_OK)
		return r;
	r = pk_cx_expect(x, s, MLOD_STREAM_GLB, 1, UINT64_MAX, "", "", err);
	if (r == MLOD_OK)
		r = pk_cx_end(x, err);
	if (r == MLOD_OK && s->codec != MLOD_SCODEC_RAW)
		r = mlod_fail(err, MLOD_ERR_PARSE, "DOC: the 'GLB ' stream must be stored raw");
	if (r != MLOD_OK)
		pk_cx_done(x);
	return r;
}

mlod_result mlod_pack_doc(const mlod_pack *p, const void *data, size_t size, const void **glb, size_t *glb_size,
                          mlod_error *err)
{
	if (!glb || !glb_size)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_pack_doc: glb or glb_size is NULL");
	*glb = NULL;
	*glb_size = 0;
	int ci = p ? mlod_pack_find(p, MLOD_CHUNK_DOC, 0, 0) : -1;
	if (ci >= 0 && p->chunks[ci].entropy != MLOD_ENTROPY_NONE)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG,
		                 "DOC: stored with the %s entropy stage, so its bytes are not in the file: use "
		                 "mlod_pack_decode_doc",
		                 mlod_pack_entropy_name(p->chunks[ci].entropy));
	cx x;
	stream s;
	mlod_result r = doc_begin(p, data, size, &x, &s, err);
	if (r != MLOD_OK)
		return r;
	*glb = s.src;
	*glb_size = s.count;
	pk_cx_done(&x);
	return MLOD_OK;
}

mlod_result mlod_pack_decode_doc(const mlod_pack *p, const void *data, size_t size, mlod_pack_doc_bytes *out,
                                 mlod_error *err)
{
	if (!out)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_pack_decode_doc: out is NULL");
	memset(out, 0, sizeof *out);
	cx x;
	stream s;
	mlod_result r = doc_begin(p, data, size, &x, &s, err);
	if (r != MLOD_OK)
		return r;
	bump b = {0};
	r = pk_bump_alloc(&b, &x, round8((uint64_t)s.count), err);
	if (r == MLOD_OK) {
		uint8_t *g = bump_take(&b, s.count);
		if (s.count)
			memcpy(g, s.src, s.count);
		out->glb = g;
		out->size = s.count;
		out->block = b.base;
	}
	pk_cx_done(&x);
	return r;
}

void mlod_pack_doc_free(mlod_pack_doc_bytes *x)
{
	if (x)
		pk_block_release(x->block, x, sizeof *x);
}

/* Every chunk decoded in TOC order and released, stopping at the first
 * failure (whose message names the chunk); unknown types are skipped. */
mlod_result mlod_pack_check_padding(const mlod_pack *p, const void *data, size_t size, mlod_error *err)
{
	if (!p || (!data && size))
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_pack_check_padding: NULL argument");
	/* no CRC covers it: a whole file has no other bytes than the header,
	 * the TOC, the chunks and the zero padding before each chunk */
	const uint8_t *d = data;
	uint64_t at = MLOD_PACK_HEADER_SIZE + (uint64_t)p->chunk_count * MLOD_PACK_TOC_ENTRY_SIZE;
	for (uint32_t i = 0; i < p->chunk_count; i++) {
		const mlod_pack_chunk *c = &p->chunks[i];
		for (uint64_t b = at; b < c->offset && b < size; b++)
			if (d[b]) {
				char label[48];
				pk_chunk_label(c->type, c->level, c->item, label, sizeof label);
				return mlod_fail(err, MLOD_ERR_PARSE, "%s: padding byte %llu before the chunk is not zero", label,
				                 (unsigned long long)b);
			}
		at = c->offset + c->stored_size;
	}
	if (size > p->file_size)
		return mlod_fail(err, MLOD_ERR_PARSE, "%llu bytes after the pack's end (byte %llu), which no CRC covers",
		                 (unsigned long long)(size - p->file_size), (unsigned long long)p->file_size);
	return MLOD_OK;
}

mlod_result mlod_pack_info_check_skeleton(const mlod_pack_info *info, const mlod_pack_skeleton *skel,
                                          mlod_error *err)
{
	if (info->rec.joint_count != skel->joint_count || info->rec.skin_count != skel->skin_count)
		return mlod_fail(err, MLOD_ERR_PARSE, "INFO: %u joints and %u skins, but SKELETON has %u and %u",
		                 info->rec.joint_count, info->rec.skin_count, skel->joint_count, skel->skin_count);
	return MLOD_OK;
}

mlod_result mlod_pack_info_check_mesh(const mlod_pack_info *info, const mlod_pack_mesh *mesh, unsigned level,
                                      mlod_error *err)
{
	if (info->rec.instance_count != mesh->part_count)
		return mlod_fail(err, MLOD_ERR_PARSE, "INFO: %u instances, but MESH level %u has %u parts",
		                 info->rec.instance_count, level, mesh->part_count);
	uint64_t v = 0;
	for (uint32_t i = 0; i < mesh->part_count; i++)
		v += mesh->parts[i].rec.vertex_count;
	return mlod_pack_info_check_vertices(info, v, level, err);
}

mlod_result mlod_pack_info_check_vertices(const mlod_pack_info *info, uint64_t vertices, unsigned level,
                                          mlod_error *err)
{
	if (info->has_max_vertices && vertices > info->rec.max_vertex_count)
		return mlod_fail(err, MLOD_ERR_PARSE,
		                 "MESH level %u: %llu vertices, more than INFO's max_vertex_count %u (the largest level's)",
		                 level, (unsigned long long)vertices, info->rec.max_vertex_count);
	return MLOD_OK;
}

mlod_result mlod_pack_check(const mlod_pack *p, const void *data, size_t size, mlod_error *err)
{
	if (!p || (!data && size))
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_pack_check: NULL argument");
	mlod_pack_skeleton skel;
	memset(&skel, 0, sizeof skel);
	mlod_pack_info info; /* INFO stands first (mlod_pack_open checks the order) */
	memset(&info, 0, sizeof info);
	int have_skel = 0, have_info = 0;
	uint64_t max_vertices = 0; /* of the MESH levels so far */
	mlod_result r = MLOD_OK;
	if ((r = mlod_pack_check_padding(p, data, size, err)) != MLOD_OK)
		return r;
	for (uint32_t i = 0; r == MLOD_OK && i < p->chunk_count; i++) {
		const mlod_pack_chunk *c = &p->chunks[i];
		const mlod_pack_skeleton *s = have_skel ? &skel : NULL;
		if (c->type == MLOD_CHUNK_INFO) {
			r = mlod_pack_decode_info(p, data, size, &info, err);
			have_info = r == MLOD_OK;
		} else if (c->type == MLOD_CHUNK_SKELETON && c->level == 0) {
			r = mlod_pack_decode_skeleton(p, data, size, &skel, err);
			have_skel = r == MLOD_OK;
			/* INFO's counts against what the chunks hold */
			if (have_skel && have_info)
				r = mlod_pack_info_check_skeleton(&info, &skel, err);
		} else if (c->type == MLOD_CHUNK_SKELETON) {
			mlod_pack_skel_level x;
			memset(&x, 0, sizeof x);
			r = mlod_pack_decode_skel_level(p, i, data, size, s, &x, err);
			mlod_pack_skel_level_free(&x);
		} else if (c->type == MLOD_CHUNK_MESH) {
			mlod_pack_mesh x;
			memset(&x, 0, sizeof x);
			r = mlod_pack_decode_mesh(p, i, data, size, s, &x, err);
			if (r == MLOD_OK && have_info)
				r = mlod_pack_info_check_mesh(&info, &x, c->level, err);
			uint64_t v = 0;
			for (uint32_t k = 0; r == MLOD_OK && k < x.part_count; k++)
				v += x.parts[k].rec.vertex_count;
			max_vertices = v > max_vertices ? v : max_vertices;
			mlod_pack_mesh_free(&x);
		} else if (c->type == MLOD_CHUNK_MOTION) {
			mlod_pack_motion x;
			memset(&x, 0, sizeof x);
			r = mlod_pack_decode_motion(p, i, data, size, s, &x, err);
			mlod_pack_motion_free(&x);
		} else if (c->type == MLOD_CHUNK_DOC) {
			mlod_pack_doc_bytes x;
			memset(&x, 0, sizeof x);
			r = mlod_pack_decode_doc(p, data, size, &x, err);
			mlod_pack_doc_free(&x);
		}
	}
	/* INFO's max_vertex_count is exactly the largest level's (each level
	 * was checked not to pass it) */
	if (r == MLOD_OK && have_info && info.has_max_vertices && max_vertices != info.rec.max_vertex_count)
		r = mlod_fail(err, MLOD_ERR_PARSE, "INFO: max_vertex_count %u, but the largest MESH level has %llu vertices",
		              info.rec.max_vertex_count, (unsigned long long)max_vertices);
	mlod_pack_skeleton_free(&skel);
	mlod_pack_info_free(&info);
	return r;
}
