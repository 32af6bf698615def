# --influence-budget: off (0) leaves every level's influences and errors as
# they are; on, the levels drop influences (the notes say how many), no
# level's Hausdorff error rises, and the option is reported.
set -e
"$BIN/mlod-bgm" --report=json --influence-budget 0 "$ROOT/samples/RobotExpressive.glb" > off.json
"$BIN/mlod-bgm" --report=json --influence-budget 2 "$ROOT/samples/RobotExpressive.glb" > on.json
node -e '
const fs = require("fs");
const off = JSON.parse(fs.readFileSync("off.json")), on = JSON.parse(fs.readFileSync("on.json"));
if (off.options.influence_budget !== 0 || on.options.influence_budget !== 2) throw new Error("options");
if (/fewer influences/.test(off.notes)) throw new Error("off prunes: " + off.notes);
const dropped = on.notes.match(/level [0-9]+: [0-9]+ fewer influences/g) || [];
if (dropped.length < 2) throw new Error("on: " + on.notes);
if (off.levels.length !== on.levels.length) throw new Error("levels");
on.levels.forEach((l, k) => {
  const o = off.levels[k];
  if (l.triangles !== o.triangles || l.vertices !== o.vertices) throw new Error("level " + l.level + " changed shape");
  if (l.error_percent.max > o.error_percent.max) throw new Error("level " + l.level + ": Hausdorff rose");
});
'
