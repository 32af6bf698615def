# 179 -> -179 degrees is a 2 degree step: at a threshold just over 2
# degrees of the arm's weighted distance (0.5 * 2/180 = 0.0056) only that
# pair of frames fuses, so the arm keeps 8 of its 9 frames (a 358 degree
# step would fuse nothing). Root channels are constant: one key each.
set -e
"$BIN/mlod-motion" -t 0.006 --report=json "$ROOT/tests/data/motion_wrap.bvh" > r.json
node -e '
const r = JSON.parse(require("fs").readFileSync("r.json"));
const l = r.clips[0].levels[0];
if (l.keys !== 1 + 1 + 8) throw new Error("keys " + l.keys);
'
