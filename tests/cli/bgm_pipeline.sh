# After mlod-skelgraph, mesh level k uses skeleton level k's skin, and the
# skeleton levels stay in the scene extras.
set -e
"$BIN/mlod-skelgraph" "$ROOT/samples/tubeman.glb" | "$BIN/mlod-bgm" -o out.glb
node "$ROOT/tests/validate.mjs" out.glb > /dev/null
node -e '
const b = require("fs").readFileSync("out.glb");
const j = JSON.parse(b.subarray(20, 20 + b.readUInt32LE(12)).toString());
const x = j.scenes[j.scene || 0].extras.mlod;
if (!x.skeleton_levels || x.mesh_levels.length !== 3) throw new Error("extras");
const node = j.nodes.find(n => n.extensions && n.extensions.MSFT_lod);
node.extensions.MSFT_lod.ids.forEach((id, k) => {
  const want = x.skeleton_levels[Math.min(k, x.skeleton_levels.length - 1)].skins[0];
  if (j.nodes[id].skin !== want) throw new Error("level " + (k + 1) + " skin " + j.nodes[id].skin + ", not " + want);
});
'
