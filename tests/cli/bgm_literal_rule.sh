# The literal 4.2.2 rule freezes the rigid parts (weight 1 is never below
# the average): the robot hardly simplifies; a larger tau frees them.
set -e
"$BIN/mlod-bgm" --report=json -E literal "$ROOT/samples/RobotExpressive.glb" > lit.json
"$BIN/mlod-bgm" --report=json -E literal -t 1.5 "$ROOT/samples/RobotExpressive.glb" > tau.json
node -e '
const fs = require("fs");
const a = JSON.parse(fs.readFileSync("lit.json")), b = JSON.parse(fs.readFileSync("tau.json"));
const last = r => r.levels.length ? r.levels[r.levels.length - 1].triangles : r.triangles;
if (!(last(a) > 0.9 * a.triangles)) throw new Error("literal simplified " + last(a));
if (!(last(b) < 0.5 * b.triangles)) throw new Error("tau 1.5 kept " + last(b));
'
