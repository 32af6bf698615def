/*
 * record_seed.c: writes the extras.mlod of every object of a glb (or glTF,
 * or BVH) in the form fuzz_record.c reads, as a seed for it:
 *
 *   record_seed in.glb > seed.json
 *
 * Built by make fuzz-io with the release library.
 */
#include <stdio.h>
#include <stdlib.h>

#include "io/mlod_io.h"

int main(int argc, char **argv)
{
	if (argc != 2) {
		fprintf(stderr, "usage: record_seed in.glb\n");
		return 1;
	}
	FILE *f = fopen(argv[1], "rb");
	if (!f) {
		perror(argv[1]);
		return 2;
	}
	size_t cap = 1 << 20, n = 0, got;
	char *buf = malloc(cap);
	while (buf && (got = fread(buf + n, 1, cap - n, f)) > 0)
		if ((n += got) == cap) {
			char *grown = realloc(buf, cap *= 2);
			if (!grown)
				free(buf);
			buf = grown;
		}
	fclose(f);
	mlod_gltf *doc;
	mlod_character c;
	mlod_error e;
	if (!buf || mlod_load(buf, n, NULL, &doc, &c, NULL, &e) != MLOD_OK) {
		fprintf(stderr, "record_seed: %s: %s\n", argv[1], buf ? e.message : "out of memory");
		return 2;
	}
	free(buf);
	static const struct { const char *name; mlod_gltf_kind kind; } kinds[] = {
		{"scene", MLOD_GLTF_SCENE}, {"asset", MLOD_GLTF_ASSET}, {"node", MLOD_GLTF_NODE},
		{"skin", MLOD_GLTF_SKIN}, {"mesh", MLOD_GLTF_MESH}, {"animation", MLOD_GLTF_ANIMATION},
	};
	const char *sep = "{";
	for (size_t k = 0; k < sizeof kinds / sizeof kinds[0]; k++) {
		int single = kinds[k].kind == MLOD_GLTF_SCENE || kinds[k].kind == MLOD_GLTF_ASSET;
		int count = single ? 1 : mlod_gltf_count(doc, kinds[k].kind);
		for (int i = 0; i < count; i++) {
			char *json = NULL;
			if (mlod_gltf_get_extra(doc, kinds[k].kind, single && kinds[k].kind == MLOD_GLTF_SCENE ? -1 : i,
			                        "mlod", &json, &e) != MLOD_OK) {
				fprintf(stderr, "record_seed: %s: %s\n", argv[1], e.message);
				return 2;
			}
			if (!json)
				continue;
			if (single)
				printf("%s\"%s\":%s", sep, kinds[k].name, json);
			else
				printf("%s\"%s %d\":%s", sep, kinds[k].name, i, json);
			sep = ",";
			mlod_free(json);
		}
	}
	printf("%s}\n", *sep == '{' ? "{" : "");
	mlod_gltf_free(doc);
	mlod_character_free(&c);
	return 0;
}
