# issue 11: a glb without animation passes through mlod-motion unchanged,
# with a note on stderr (that speaks of no BVH), exit 0.
set -e
node "$ROOT/tests/glb-edit.mjs" "$ROOT/samples/RobotExpressive.glb" still.glb 'delete j.animations;'
"$BIN/mlod-label" still.glb | "$BIN/mlod-skelgraph" 2>/dev/null | "$BIN/mlod-bgm" > in.glb
"$BIN/mlod-motion" in.glb > out.glb 2> err
test "$(cat err)" = "mlod-motion: in.glb: no animation: nothing to reduce; written unchanged"
cmp in.glb out.glb || node "$ROOT/tests/gltf-same.mjs" in.glb out.glb
node "$ROOT/tests/validate.mjs" out.glb > /dev/null
