# Every mesh node of the robot (rigid parts and skinned hands) gets
# MSFT_lod with one node per level and decreasing screen coverage; rigid
# parts are skinned to their joint; the glb validates.
set -e
"$BIN/mlod-bgm" -R 0.5,0.35,0.3 -o out.glb "$ROOT/samples/RobotExpressive.glb"
node "$ROOT/tests/validate.mjs" out.glb > /dev/null
node -e '
const b = require("fs").readFileSync("out.glb");
const j = JSON.parse(b.subarray(20, 20 + b.readUInt32LE(12)).toString());
const scene = j.scenes[j.scene || 0];
const lod = j.nodes.filter(n => n.mesh !== undefined && n.extensions && n.extensions.MSFT_lod);
if (lod.length !== 19) throw new Error("nodes with MSFT_lod: " + lod.length);
for (const n of lod) {
  const ids = n.extensions.MSFT_lod.ids, cov = n.extras.MSFT_screencoverage;
  if (ids.length !== 3 || cov.length !== 4) throw new Error("levels");
  for (let k = 1; k < cov.length; k++) if (cov[k] > cov[k - 1]) throw new Error("coverage");
  for (const id of ids) {
    const l = j.nodes[id];
    if (l.skin === undefined) throw new Error("level node without skin");
    if (n.skin !== undefined && l.skin !== n.skin) throw new Error("skinned level with another skin");
    if (n.skin === undefined && j.skins[l.skin].joints.length !== 1) throw new Error("rigid part skin");
  }
}
if (scene.extras.mlod.mesh_levels.length !== 3) throw new Error("extras");
'
