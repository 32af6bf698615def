/*
 * roundtrip.c: reads a .glb or .gltf and writes it back as .glb through
 * mlod_gltf_read and mlod_gltf_write, for checking the output with the
 * glTF validator (tests/validate.mjs) or against the input.
 *
 *   roundtrip [--via-character] in.glb|in.gltf out.glb
 *
 * --via-character writes the document mlod_gltf_from_character makes
 * from the character mlod_gltf_to_character reads instead.
 * Exit status: 0 on success, 1 on usage errors, 2 when reading or
 * writing fails.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mlod.h"

/* The directory part of path ("." when there is none), in buf. */
static const char *dir_of(const char *path, char *buf, size_t size)
{
	const char *slash = strrchr(path, '/');
	if (!slash)
		return ".";
	size_t n = (size_t)(slash - path);
	if (n >= size)
		n = size - 1;
	memcpy(buf, path, n);
	buf[n] = 0;
	return n ? buf : "/";
}

static void *read_file(const char *path, size_t *size)
{
	FILE *f = fopen(path, "rb");
	if (!f)
		return NULL;
	size_t cap = 1 << 20, n = 0;
	char *buf = malloc(cap);
	for (;;) {
		if (n == cap) {
			cap *= 2;
			buf = realloc(buf, cap);
		}
		size_t got = fread(buf + n, 1, cap - n, f);
		if (got == 0)
			break;
		n += got;
	}
	fclose(f);
	*size = n;
	return buf;
}

int main(int argc, char **argv)
{
	int via_character = argc == 4 && strcmp(argv[1], "--via-character") == 0;
	if (argc != 3 + via_character) {
		fprintf(stderr, "usage: roundtrip [--via-character] in.glb|in.gltf out.glb\n");
		return 1;
	}
	const char *in = argv[1 + via_character], *out = argv[2 + via_character];
	size_t size;
	void *bytes = read_file(in, &size);
	if (!bytes) {
		fprintf(stderr, "roundtrip: %s: cannot read\n", in);
		return 2;
	}
	char dir[4096];
	mlod_error err;
	mlod_gltf *doc = NULL;
	mlod_result r = mlod_gltf_read(bytes, size, dir_of(in, dir, sizeof dir), &doc, &err);
	free(bytes);
	if (r == MLOD_OK && via_character) {
		mlod_character c = { 0 };
		mlod_gltf *built = NULL;
		r = mlod_gltf_to_character(doc, &c, &err);
		if (r == MLOD_OK)
			r = mlod_gltf_from_character(&c, &built, &err);
		mlod_character_free(&c);
		mlod_gltf_free(doc);
		doc = built;
	}
	void *glb = NULL;
	size_t glb_size = 0;
	if (r == MLOD_OK)
		r = mlod_gltf_write(doc, 1, &glb, &glb_size, &err);
	mlod_gltf_free(doc);
	if (r != MLOD_OK) {
		fprintf(stderr, "roundtrip: %s: %s\n", in, err.message);
		return 2;
	}
	FILE *f = fopen(out, "wb");
	int ok = f && fwrite(glb, 1, glb_size, f) == glb_size;
	if (f && fclose(f) != 0)
		ok = 0;
	mlod_free(glb);
	if (!ok) {
		fprintf(stderr, "roundtrip: %s: cannot write\n", out);
		return 2;
	}
	return 0;
}
