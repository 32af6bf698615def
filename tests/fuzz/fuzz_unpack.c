/*
 * fuzz_unpack.c: libFuzzer target for mlod-pack -x (make fuzz-unpack; not
 * part of make test): mlod_pack_unpack (lib/pack/unpack.c) builds a glTF
 * document from the pack, read through the runtime's reader, and
 * mlod_gltf_write serialises it as glb, as the tool does. The custom
 * mutator (fuzz_restamp.h) re-stamps the CRCs on half of the runs, so
 * hostile but CRC-valid packs reach the unpacker.
 */
#include <stddef.h>
#include <stdint.h>

#include "fuzz_restamp.h"
#include "io/mlod_io.h"
#include "pack/mlod_pack_write.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	mlod_gltf *doc = NULL;
	mlod_error e;
	if (mlod_pack_unpack(data, size, &doc, &e) != MLOD_OK)
		return 0;
	void *out = NULL;
	size_t n = 0;
	if (mlod_gltf_write(doc, 1, &out, &n, &e) == MLOD_OK)
		mlod_free(out);
	mlod_gltf_free(doc);
	return 0;
}
