# The glb output holds one real skin per level per skin, and validates.
set -e
"$BIN/mlod-skelgraph" -j 0.8,0.6 -o out.glb "$ROOT/samples/RobotExpressive.glb"
node "$ROOT/tests/validate.mjs" out.glb > /dev/null
node -e '
const b = require("fs").readFileSync("out.glb");
const j = JSON.parse(b.subarray(20, 20 + b.readUInt32LE(12)).toString());
if (j.skins.length !== 4 * 3) throw new Error("skins: " + j.skins.length);
const levels = j.scenes[j.scene || 0].extras.mlod.skeleton_levels;
if (levels.length !== 2) throw new Error("levels: " + levels.length);
if (!j.extensionsUsed.includes("MSFT_lod")) throw new Error("no MSFT_lod");
'
