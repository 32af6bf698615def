# A meshopt filter mlod does not know (KHR_meshopt_compression's COLOR, or
# any other) is unsupported: exit 3, naming it.
set -e
node "$ROOT/tests/glb-edit.mjs" "$ROOT/tests/data/meshopt.glb" color.glb \
	'j.bufferViews[0].extensions.EXT_meshopt_compression.filter = "COLOR"'
"$BIN/mlod-bgm" color.glb
