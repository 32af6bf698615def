# An unknown meshopt mode is unsupported: exit 3, naming it.
set -e
node "$ROOT/tests/glb-edit.mjs" "$ROOT/tests/data/meshopt.glb" mode.glb \
	'j.bufferViews[0].extensions.EXT_meshopt_compression.mode = "POINTS"'
"$BIN/mlod-label" mode.glb
