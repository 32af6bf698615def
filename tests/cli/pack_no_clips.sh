# A character without clips: a valid pack without motion chunks, with a note.
set -e
node "$ROOT/tests/glb-edit.mjs" "$ROOT/samples/RobotExpressive.glb" still.glb 'delete j.animations;'
"$BIN/mlod-pack" still.glb -o still.mlod --ratios 0.5 2> err
grep -qx 'mlod-pack: still.glb: no animation: the pack has no motion levels' err
node "$ROOT/tests/cli/pack_check.mjs" still.mlod > c.json
node -e '
const c = JSON.parse(require("fs").readFileSync("c.json"));
if (c.clips !== 0 || c.motion_levels !== 0 || c.count.ANIM || c.mesh_levels !== 2 || c.joints !== 43) throw new Error(JSON.stringify(c));
'
