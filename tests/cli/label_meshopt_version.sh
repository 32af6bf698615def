# A meshopt vertex stream of a newer codec version (header 0xa1) than
# meshoptimizer 0.18 decodes is unsupported: exit 3, naming the version.
set -e
node "$ROOT/tests/glb-edit.mjs" "$ROOT/tests/data/meshopt.glb" v1.glb \
	'bin[j.bufferViews[0].extensions.EXT_meshopt_compression.byteOffset || 0] = 0xa1'
"$BIN/mlod-label" v1.glb
