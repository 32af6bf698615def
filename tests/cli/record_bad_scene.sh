# A malformed stage record on the scene is an error naming the key (exit 2),
# not silently ignored.
node "$ROOT/tests/glb-edit.mjs" "$ROOT/samples/tubeman.glb" bad.glb \
	'j.scenes[0].extras = { mlod: { skeleton_levels: "three" } }'
"$BIN/mlod-bgm" bad.glb > out.glb
