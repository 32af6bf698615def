# Morph weights: every level of RobotExpressive's clips animates the same
# weights nodes as its clip, with fewer keys, extras.mlod says what was
# done, and the keys count them; the glb stays valid.
set -e
cd "$ROOT"
"$BIN/mlod-motion" -e 1% -o "$OLDPWD/out.glb" samples/RobotExpressive.glb
"$BIN/mlod-motion" -e 1% --report=json samples/RobotExpressive.glb > "$OLDPWD/r.json"
cd "$OLDPWD"
node "$ROOT/tests/validate.mjs" out.glb > /dev/null
node -e '
const fs = require("fs");
const b = fs.readFileSync("out.glb");
const j = JSON.parse(b.subarray(20, 20 + b.readUInt32LE(12)).toString());
const nodes = (a) => a.channels.filter((c) => c.target.path === "weights").map((c) => c.target.node).join(",");
let n = 0;
for (const a of j.animations) {
	if (!a.name.endsWith("@lod1")) continue;
	const src = j.animations[a.extras.mlod.source_animation], w = a.extras.mlod.morph_weights;
	if (nodes(a) !== nodes(src) || nodes(a) === "") throw new Error(a.name + ": weights on " + nodes(a));
	if (w.channels !== 3 || w.copied !== 0 || !(w.keys < w.source_keys) || !(w.error <= w.bound))
		throw new Error(a.name + ": " + JSON.stringify(w));
	n++;
}
if (n !== 14) throw new Error("levels " + n);
const r = JSON.parse(fs.readFileSync("r.json"));
for (const c of r.clips) {
	const l = c.levels[0];
	if (!l.morph_weights || l.morph_weights.keys !== 3) throw new Error(c.name + " weights keys");
	if (l.keys < l.morph_weights.keys) throw new Error(c.name + " keys do not count the weights");
}
'
