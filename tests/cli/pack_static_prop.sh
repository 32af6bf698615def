# A static prop (one mesh, no skin, no joints, no clips) through the whole
# pipeline: every stage passes it through with a note, and the pack is
# valid with mesh levels only.
set -e
node "$ROOT/tests/glb-edit.mjs" "$ROOT/samples/RobotExpressive.glb" prop.glb \
	'j.nodes = [{ name: "prop", mesh: 18 }]; j.scenes = [{ nodes: [0] }]; j.scene = 0; delete j.skins; delete j.animations;'
"$BIN/mlod-label" prop.glb 2> e1 | "$BIN/mlod-skelgraph" 2> e2 | "$BIN/mlod-bgm" 2> e3 | "$BIN/mlod-motion" 2> e4 |
	"$BIN/mlod-pack" -o piped.mlod 2> e5
grep -q 'no joints: nothing to label; written unchanged' e1
grep -q 'no joints: no skeleton levels; written unchanged' e2
grep -q 'no animation: nothing to reduce; written unchanged' e4
test ! -s e5
"$BIN/mlod-pack" prop.glb -o prop.mlod
for f in piped.mlod prop.mlod; do
	node "$ROOT/tests/cli/pack_check.mjs" $f > c.json
	node -e '
const c = JSON.parse(require("fs").readFileSync("c.json"));
if (c.joints !== 0 || c.skins !== 0 || c.clips !== 0 || c.motion_levels !== 0 || c.skeleton_levels !== 1) throw new Error(JSON.stringify(c));
if (c.parts !== 1 || c.mesh_levels < 2 || !(c.diagonal > 0)) throw new Error("mesh");
'
done
