/*
 * fuzz_io.c: libFuzzer target for the bake side's input (make fuzz-io
 * FUZZ_TARGET=io; not part of make test). Each input is what a tool reads
 * from a file or stdin: glb, glTF JSON or BVH text, told apart by its
 * first bytes (mlod_detect_format, inside mlod_load). It is loaded with
 * mlod_record_load as tools/common.c does (no base directory: only data:
 * URIs, as from stdin; the source read or written, the motion levels left
 * out of the clips), then every record a later stage reads back is read
 * (fuzz_read.h) and everything is freed, so that LeakSanitizer reports
 * what a reader leaks.
 */
#include <stddef.h>
#include <stdint.h>

#include "fuzz_read.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	mlod_gltf *doc = NULL;
	mlod_character c;
	mlod_record_input in;
	mlod_error e;
	if (mlod_record_load(data, size, NULL, MLOD_RECORD_INPUT_CLIPS, &doc, &c, &in, &e) != MLOD_OK)
		return 0;
	read_records(doc, &c);
	mlod_gltf_free(doc);
	mlod_character_free(&c);
	return 0;
}
