# The character budget (the default with the posed cost) shares a level's
# triangles among the primitives by posed cost: at the same total, the
# robot's posed error is lower than with each primitive at the ratio
# (the totals match within 1%: edge collapses remove one or two faces).
set -e
"$BIN/mlod-bgm" --report=json -R 0.5 "$ROOT/samples/RobotExpressive.glb" > character.json
"$BIN/mlod-bgm" --report=json -R 0.5 -B primitive "$ROOT/samples/RobotExpressive.glb" > primitive.json
node -e '
const fs = require("fs");
const c = JSON.parse(fs.readFileSync("character.json")), p = JSON.parse(fs.readFileSync("primitive.json"));
if (c.options.budget !== "character" || p.options.budget !== "primitive") throw new Error("options");
const a = c.levels[0], b = p.levels[0];
if (Math.abs(a.triangles - b.triangles) > 0.01 * b.triangles) throw new Error(`triangles ${a.triangles} and ${b.triangles}`);
if (!(a.error_percent.mean < b.error_percent.mean && a.error_percent.max < b.error_percent.max))
  throw new Error(`character ${JSON.stringify(a.error_percent)}, primitive ${JSON.stringify(b.error_percent)}`);
'
"$BIN/mlod-bgm" --report=json -c compactness "$ROOT/samples/tubeman.glb" > compactness.json
grep -q '"budget": "primitive"' compactness.json
