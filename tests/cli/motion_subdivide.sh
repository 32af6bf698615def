# --subdivide: the report says where the bounds were checked (midpoints
# by default, frames only with 1), extras.mlod records it, and every
# level stays within its bound. (More samples do not always keep more
# keys: the search can take another path.)
set -e
cd "$ROOT"
"$BIN/mlod-motion" --report=json samples/cmu_12_01_walk.bvh > "$OLDPWD/def.json"
"$BIN/mlod-motion" --report=json --subdivide 1 samples/cmu_12_01_walk.bvh > "$OLDPWD/one.json"
"$BIN/mlod-motion" --report samples/cmu_12_01_walk.bvh > "$OLDPWD/def.txt"
grep -q '1 time between each two (--subdivide 2)' "$OLDPWD/def.txt"
"$BIN/mlod-motion" -e 1% -o "$OLDPWD/out.glb" samples/RobotExpressive.glb
cd "$OLDPWD"
node -e '
const fs = require("fs");
const d = JSON.parse(fs.readFileSync("def.json")), o = JSON.parse(fs.readFileSync("one.json"));
if (d.subdivide !== 2 || o.subdivide !== 1) throw new Error("subdivide " + d.subdivide + " " + o.subdivide);
d.clips[0].levels.forEach((l, i) => {
	if (!(l.joint_error.max <= l.bound)) throw new Error("level " + l.level + " over its bound");
	if (!(o.clips[0].levels[i].joint_error.max <= o.clips[0].levels[i].bound)) throw new Error("frames-only level over its bound");
});
const b = fs.readFileSync("out.glb");
const j = JSON.parse(b.subarray(20, 20 + b.readUInt32LE(12)).toString());
const lv = j.animations.filter((a) => a.name.includes("@lod"));
if (lv.length !== 14 || lv.some((a) => a.extras.mlod.subdivide !== 2)) throw new Error("extras");
'
node "$ROOT/tests/validate.mjs" out.glb > /dev/null
