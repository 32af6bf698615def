# Default levels on the CMU walk: three, nested (fewer joints each), the
# first removing 13% of the 31 joints (4) and the last between 26% and
# the default chain's 39%, each within the default 2% bound.
set -e
"$BIN/mlod-skelgraph" --report=json "$ROOT/samples/cmu_12_01_walk.bvh" > r.json
node -e '
const r = JSON.parse(require("fs").readFileSync("r.json"));
if (r.joints !== 31) throw new Error("joints " + r.joints);
if (r.levels.length !== 3) throw new Error("levels " + r.levels.length);
let prev = r.joints;
for (const l of r.levels) {
	if (l.kept >= prev) throw new Error("levels not decreasing");
	if (!(l.joint_error.max_percent_height <= 2)) throw new Error("level " + l.level + " over 2%");
	prev = l.kept;
}
if (r.levels[0].kept !== 27) throw new Error("first level keeps " + r.levels[0].kept);
const removed = 1 - r.levels[2].kept / r.joints;
if (removed < 0.26 || removed > 0.39 + 1e-9) throw new Error("removed " + removed);
'
