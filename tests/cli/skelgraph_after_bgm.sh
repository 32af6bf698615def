# mlod-skelgraph after mlod-bgm keeps the mesh levels in MSFT_lod, with a
# note on stderr, and its skeleton levels in the record. It used to
# replace them with its own level nodes: mlod-pack then baked five default
# mesh levels instead of the one asked for, and the unpacked glb had
# validator errors.
set -e
"$BIN/mlod-bgm" -j 1 -R 0.7 "$ROOT/samples/tubeman.glb" | "$BIN/mlod-skelgraph" > out.glb
node "$ROOT/tests/validate.mjs" out.glb > /dev/null
node -e '
const b = require("fs").readFileSync("out.glb");
const j = JSON.parse(b.subarray(20, 20 + b.readUInt32LE(12)).toString());
const x = j.scenes[j.scene || 0].extras.mlod;
if (!x.skeleton_levels || x.skeleton_levels.length < 1 || x.mesh_levels.length !== 1) throw new Error("record");
const node = j.nodes.find(n => n.extensions && n.extensions.MSFT_lod);
const ids = node.extensions.MSFT_lod.ids;
if (ids.length !== 1 || j.nodes[ids[0]].extras.mlod.mesh_level !== 1) throw new Error("MSFT_lod " + JSON.stringify(ids));
'
"$BIN/mlod-pack" -j 1 -o out.mlod out.glb
"$BIN/mlod-pack" --info out.mlod | grep -q "levels: skeleton 3, mesh 2, motion"
"$BIN/mlod-pack" -x out.mlod -o x.glb
node "$ROOT/tests/validate.mjs" x.glb > /dev/null
