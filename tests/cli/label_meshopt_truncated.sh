# A meshopt-compressed buffer view whose stream is cut short (its byteLength
# made 10 bytes) is malformed input: exit 2, naming the view.
set -e
node "$ROOT/tests/glb-edit.mjs" "$ROOT/tests/data/meshopt.glb" truncated.glb \
	'j.bufferViews[0].extensions.EXT_meshopt_compression.byteLength = 10'
"$BIN/mlod-label" truncated.glb
