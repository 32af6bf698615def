/*
 * load.c: recognises glb, glTF and BVH input and loads it into a document
 * and a character.
 *
 * Detection looks only at the first bytes: "glTF" is a glb; a '{' after an
 * optional UTF-8 byte order mark and blanks is glTF JSON; "HIERARCHY" after
 * the same is BVH. A BVH gets a glTF document built from its character, so
 * every tool can write glb whatever it read. The loaded character is
 * validated before it is handed out; on any failure nothing stays
 * allocated.
 */
#include <stdio.h>
#include <string.h>

#include "io/mlod_io.h"

/* Skips a UTF-8 byte order mark and blanks; returns the offset reached. */
static size_t skip_bom_and_blanks(const unsigned char *p, size_t size)
{
	size_t i = 0;
	if (size >= 3 && p[0] == 0xEF && p[1] == 0xBB && p[2] == 0xBF)
		i = 3;
	while (i < size && (p[i] == ' ' || p[i] == '\t' || p[i] == '\r' || p[i] == '\n' || p[i] == '\f' ||
	                    p[i] == '\v'))
		i++;
	return i;
}

mlod_format mlod_detect_format(const void *data, size_t size)
{
	const unsigned char *p = data;
	if (!p)
		return MLOD_FORMAT_UNKNOWN;
	if (size >= 4 && memcmp(p, "glTF", 4) == 0)
		return MLOD_FORMAT_GLB;
	size_t i = skip_bom_and_blanks(p, size);
	if (i < size && p[i] == '{')
		return MLOD_FORMAT_GLTF;
	static const char kw[] = "HIERARCHY";
	size_t n = sizeof kw - 1;
	if (size - i >= n) {
		size_t k = 0;
		while (k < n && (p[i + k] & ~0x20) == (unsigned char)kw[k])
			k++;
		/* The keyword must end there. */
		if (k == n && (i + n == size || p[i + n] <= ' '))
			return MLOD_FORMAT_BVH;
	}
	return MLOD_FORMAT_UNKNOWN;
}

mlod_result mlod_load(const void *data, size_t size, const char *base_dir, mlod_gltf **doc, mlod_character *c,
                      mlod_format *format, mlod_error *err)
{
	if (doc)
		*doc = NULL;
	if (format)
		*format = MLOD_FORMAT_UNKNOWN;
	if (!c || (!data && size))
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_load: NULL argument");
	memset(c, 0, sizeof *c);
	if (size == 0 || skip_bom_and_blanks(data, size) == size)
		return mlod_fail(err, MLOD_ERR_PARSE, "empty input");

	mlod_format f = mlod_detect_format(data, size);
	if (format)
		*format = f;
	mlod_gltf *d = NULL;
	mlod_result r;
	switch (f) {
	case MLOD_FORMAT_BVH:
		r = mlod_bvh_read(data, size, c, err);
		if (r == MLOD_OK)
			r = mlod_character_validate(c, err);
		if (r == MLOD_OK && doc)
			r = mlod_gltf_from_character(c, &d, err);
		/* mlod_gltf_from_character makes joint i node i. */
		for (int i = 0; r == MLOD_OK && d && i < c->skeleton.joint_count; i++)
			c->skeleton.joints[i].node = i;
		/* and an animation of each clip with channels: its frame time,
		 * which glTF has no place for, goes into its
		 * extras.mlod_bvh.frame_time (mlod-record(5)), so that the clip
		 * read back from the glb is sampled at the same frames. */
		for (int i = 0, a = 0; r == MLOD_OK && d && i < c->clip_count; i++) {
			if (c->clips[i].channel_count == 0)
				continue;
			if (c->clips[i].frame_time > 0.0f) {
				char mark[64];
				snprintf(mark, sizeof mark, "{\"frame_time\":%.9g}", (double)c->clips[i].frame_time);
				r = mlod_gltf_set_extra(d, MLOD_GLTF_ANIMATION, a, "mlod_bvh", mark, err);
			}
			a++;
		}
		break;
	case MLOD_FORMAT_GLB:
	case MLOD_FORMAT_GLTF:
		r = mlod_gltf_read(data, size, base_dir, &d, err);
		/* A document the caller keeps (to write back) takes the skin
		 * weights the reader makes valid: level 0 of every tool's output
		 * passes the validator as its levels do. */
		if (r == MLOD_OK)
			r = doc ? mlod_gltf_to_character_fix(d, c, err) : mlod_gltf_to_character(d, c, err);
		if (r == MLOD_OK)
			r = mlod_character_validate(c, err);
		break;
	default:
		return mlod_fail(err, MLOD_ERR_UNSUPPORTED, "not a glTF, glb or BVH file");
	}
	if (r != MLOD_OK) {
		mlod_gltf_free(d);
		mlod_character_free(c);
		return r;
	}
	if (doc)
		*doc = d;
	else
		mlod_gltf_free(d);
	return MLOD_OK;
}
