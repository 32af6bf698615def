# A BVH has no mesh: it passes through as glb, with a note, exit 0.
set -e
"$BIN/mlod-bgm" -o out.glb "$ROOT/samples/cmu_12_01_walk.bvh" 2> err.txt
grep -q 'no triangle mesh; written unchanged' err.txt
test "$(head -c 4 out.glb)" = glTF
node "$ROOT/tests/validate.mjs" out.glb > /dev/null
node -e '
const b = require("fs").readFileSync("out.glb");
const j = JSON.parse(b.subarray(20, 20 + b.readUInt32LE(12)).toString());
if (JSON.stringify(j).includes("MSFT_lod") || j.meshes) throw new Error("changed");
'
