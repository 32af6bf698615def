# The whole pipeline through pipes: every layer's levels end up in one valid glb.
set -e
"$BIN/mlod-label" < "$ROOT/samples/tubeman.glb" | "$BIN/mlod-skelgraph" | "$BIN/mlod-bgm" | "$BIN/mlod-motion" > out.glb
node "$ROOT/tests/validate.mjs" out.glb > /dev/null
node -e '
const b = require("fs").readFileSync("out.glb");
const j = JSON.parse(b.subarray(20, 20 + b.readUInt32LE(12)).toString());
const scene = j.scenes[j.scene || 0];
if (!scene.extras.mlod.skeleton_levels.length) throw new Error("no skeleton levels");
if (!j.nodes.some((n) => n.extensions && n.extensions.MSFT_lod)) throw new Error("no MSFT_lod");
if (!j.animations.some((a) => /@lod1$/.test(a.name))) throw new Error("no motion levels");
if (!j.nodes.some((n) => n.extras && n.extras.mlod && n.extras.mlod.label)) throw new Error("no labels");
'
