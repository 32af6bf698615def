# mlod-label < x.glb > y.glb keeps everything but the joints' extras.mlod.
set -e
"$BIN/mlod-label" < "$ROOT/samples/RobotExpressive.glb" > y.glb
node "$ROOT/tests/gltf-same.mjs" --ignore-extras mlod "$ROOT/samples/RobotExpressive.glb" y.glb
node "$ROOT/tests/validate.mjs" y.glb > /dev/null
# BVH input: the joint nodes of the glb carry the labels.
"$BIN/mlod-label" "$ROOT/samples/cmu_12_01_walk.bvh" > walk.glb
node -e '
const b = require("fs").readFileSync("walk.glb");
const j = JSON.parse(b.subarray(20, 20 + b.readUInt32LE(12)).toString());
if (j.nodes[0].extras.mlod.label !== "root") throw new Error("no label on the root node");
'
