/*
 * fuzz_record.c: libFuzzer target for the stage record, extras.mlod (make
 * fuzz-io FUZZ_TARGET=record; not part of make test). A staged document
 * (the pipeline's output on a small character, MLOD_FUZZ_BASE, made by
 * make fuzz-io) is loaded once; each input is a JSON object whose members
 * give the extras.mlod of its objects:
 *
 *   {"scene": {...}, "node 3": {...}, "skin 0": {...}, "animation 1": {...}}
 *
 * ("asset" and "mesh N" too). Each member is set on a copy of the document
 * with mlod_gltf_set_extra, as a glTF holding that record would have it,
 * and then every record a later stage reads is read back with the stages'
 * own calls (fuzz_read.h). tests/fuzz/record_seed.c writes this form from
 * a staged glb. Mutating the record alone, rather than the whole glb, puts
 * every execution in the record readers and lib/record/json.c.
 */
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz_read.h"
#include "record/json.h"

int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static mlod_gltf *base;
static mlod_character base_c;

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
	(void)argc, (void)argv;
	const char *path = getenv("MLOD_FUZZ_BASE");
	if (!path)
		path = "build/fuzz/stage/tiny.staged.glb";
	FILE *f = fopen(path, "rb");
	if (!f) {
		fprintf(stderr, "fuzz_record: %s: cannot open (set MLOD_FUZZ_BASE to a staged glb)\n", path);
		exit(1);
	}
	size_t cap = 1 << 20, n = 0, got;
	char *buf = malloc(cap);
	while (buf && (got = fread(buf + n, 1, cap - n, f)) > 0)
		if ((n += got) == cap)
			buf = realloc(buf, cap *= 2);
	fclose(f);
	mlod_error e;
	if (!buf || mlod_load(buf, n, NULL, &base, &base_c, NULL, &e) != MLOD_OK) {
		fprintf(stderr, "fuzz_record: %s: %s\n", path, buf ? e.message : "out of memory");
		exit(1);
	}
	free(buf);
	return 0;
}

static int parse_key(const char *key, mlod_gltf_kind *kind, int *index)
{
	static const struct { const char *name; mlod_gltf_kind kind; } kinds[] = {
		{"scene", MLOD_GLTF_SCENE}, {"asset", MLOD_GLTF_ASSET}, {"node ", MLOD_GLTF_NODE},
		{"skin ", MLOD_GLTF_SKIN}, {"mesh ", MLOD_GLTF_MESH}, {"animation ", MLOD_GLTF_ANIMATION},
	};
	for (size_t i = 0; i < sizeof kinds / sizeof kinds[0]; i++) {
		size_t n = strlen(kinds[i].name);
		if (strncmp(key, kinds[i].name, n) != 0)
			continue;
		*kind = kinds[i].kind;
		*index = kinds[i].kind == MLOD_GLTF_SCENE ? -1 : 0;
		if (key[n] == '\0')
			return kinds[i].kind == MLOD_GLTF_SCENE || kinds[i].kind == MLOD_GLTF_ASSET;
		char *end;
		long v = strtol(key + n, &end, 10);
		if (*end || v < 0 || v >= mlod_gltf_count(base, *kind))
			return 0;
		*index = (int)v;
		return 1;
	}
	return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	mj in;
	char why[128];
	if (mj_parse((const char *)data, size, &in, why, sizeof why) != 0)
		return 0;
	/* Written back, the value reads the same (json.h: numbers keep their
	 * text). */
	char *text = NULL, *again = NULL;
	if (mj_write(&in, &text) == 0) {
		mj re;
		if (mj_parse(text, strlen(text), &re, why, sizeof why) != 0)
			abort();
		if (mj_write(&re, &again) != 0 || strcmp(text, again) != 0)
			abort();
		mj_free(&re);
	}
	free(text);
	free(again);
	mlod_gltf *doc = NULL;
	mlod_error e;
	if (in.type == MJ_OBJECT && mlod_gltf_copy(base, &doc, &e) == MLOD_OK) {
		for (int i = 0; i < in.count; i++) {
			mlod_gltf_kind kind;
			int index;
			char *value = NULL;
			if (parse_key(in.keys[i], &kind, &index) && mj_write(&in.items[i], &value) == 0)
				mlod_gltf_set_extra(doc, kind, index, "mlod", value, &e);
			free(value);
		}
		read_records(doc, &base_c);
		mlod_gltf_free(doc);
	}
	mj_free(&in);
	return 0;
}
