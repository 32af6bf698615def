# A glb of mlod-pack -x whose motion level 0 record is malformed is bad
# input (exit 2), the message naming the animation and the key.
"$BIN/mlod-pack" "$ROOT/samples/tubeman.glb" -o in.mlod --no-mesh-levels 2> /dev/null || exit 9
"$BIN/mlod-pack" -x in.mlod -o x.glb || exit 9
node "$ROOT/tests/glb-edit.mjs" x.glb bad.glb 'j.animations[0].extras.mlod.motion_level0.pack_error = -1'
"$BIN/mlod-pack" bad.glb -o out.mlod
