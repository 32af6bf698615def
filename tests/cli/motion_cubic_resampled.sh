# CUBICSPLINE and channels on different times: resampled to a common
# timeline, said on stderr; the output is valid and its levels LINEAR or
# STEP (the STEP translation stays STEP).
set -e
cd "$ROOT"
"$BIN/mlod-motion" tests/data/motion_cubic_mismatched.gltf > "$OLDPWD/out.glb" 2> "$OLDPWD/err"
cd "$OLDPWD"
grep -q 'clip "wave": resampled to 75 common frames (3 channels on other times, 1 CUBICSPLINE)' err
node "$ROOT/tests/validate.mjs" out.glb > /dev/null
node -e '
const b = require("fs").readFileSync("out.glb");
const j = JSON.parse(b.subarray(20, 20 + b.readUInt32LE(12)).toString());
const lv = j.animations.filter((a) => a.name.startsWith("wave@lod"));
if (lv.length !== 3) throw new Error("levels " + lv.length);
for (const a of lv) a.channels.forEach((c) => {
	const i = a.samplers[c.sampler].interpolation;
	if (i !== (c.target.path === "translation" ? "STEP" : "LINEAR")) throw new Error(a.name + " " + i);
});
'
