# Default levels on the CMU walk: nested, the last near 39% removed.
set -e
"$BIN/mlod-skelgraph" --report=json "$ROOT/samples/cmu_12_01_walk.bvh" > r.json
node -e '
const r = JSON.parse(require("fs").readFileSync("r.json"));
if (r.levels.length < 1) throw new Error("no levels");
let prev = r.joints;
for (const l of r.levels) { if (l.kept >= prev) throw new Error("levels not decreasing"); prev = l.kept; }
const last = r.levels[r.levels.length - 1];
const removed = 1 - last.kept / r.joints;
if (removed > 0.45) throw new Error("removed " + removed);
'
