# After mlod-skelgraph, mesh level k uses skeleton level k's skin, and the
# skeleton levels stay in the scene extras.
set -e
"$BIN/mlod-skelgraph" "$ROOT/samples/tubeman.glb" | "$BIN/mlod-bgm" -o out.glb
node "$ROOT/tests/validate.mjs" out.glb > /dev/null
node -e '
const b = require("fs").readFileSync("out.glb");
const j = JSON.parse(b.subarray(20, 20 + b.readUInt32LE(12)).toString());
const x = j.scenes[j.scene || 0].extras.mlod;
if (!x.skeleton_levels || x.mesh_levels.length !== 4) throw new Error("extras");
const node = j.nodes.find(n => n.extensions && n.extensions.MSFT_lod);
node.extensions.MSFT_lod.ids.forEach((id, k) => {
  const want = x.skeleton_levels[Math.min(k, x.skeleton_levels.length - 1)].skins[0];
  if (j.nodes[id].skin !== want) throw new Error("level " + (k + 1) + " skin " + j.nodes[id].skin + ", not " + want);
});
'
# The split glb hold one level each: the mesh node on skeleton level k's
# skin, without the skeleton levels' MSFT_lod nodes and their full meshes.
mkdir lods
"$BIN/mlod-skelgraph" "$ROOT/samples/tubeman.glb" > skel.glb
"$BIN/mlod-bgm" -s lods -o out2.glb skel.glb
node "$ROOT/tests/validate.mjs" lods/skel.lod1.glb lods/skel.lod2.glb lods/skel.lod3.glb lods/skel.lod4.glb > /dev/null
node -e '
const glb = (f) => { const b = require("fs").readFileSync(f); return JSON.parse(b.subarray(20, 20 + b.readUInt32LE(12)).toString()); };
const x = glb("skel.glb").scenes[0].extras.mlod;
for (let k = 0; k < 4; k++) {
  const s = glb("lods/skel.lod" + (k + 1) + ".glb"), shown = s.nodes.filter((n) => n.mesh !== undefined);
  const want = x.skeleton_levels[Math.min(k, x.skeleton_levels.length - 1)].skins[0];
  if (shown.length !== 1 || shown[0].skin !== want || shown[0].extensions || s.meshes.length !== 1 || s.extensionsUsed)
    throw new Error("split level " + (k + 1) + ": " + JSON.stringify(shown));
}
'
