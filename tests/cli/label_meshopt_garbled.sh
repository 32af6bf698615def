# A meshopt stream whose header byte is garbled is malformed input: exit 2.
set -e
node "$ROOT/tests/glb-edit.mjs" "$ROOT/tests/data/meshopt.glb" garbled.glb \
	'bin[j.bufferViews[0].extensions.EXT_meshopt_compression.byteOffset || 0] = 0x17'
"$BIN/mlod-label" garbled.glb
