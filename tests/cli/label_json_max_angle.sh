# The JSON report's max_angle is in degrees, as --max-angle takes it (it
# was in radians: 3.14159... for the default 180).
set -e
"$BIN/mlod-label" --report=json "$ROOT/samples/cmu_12_01_walk.bvh" > a.json
grep -qx '  "max_angle": 180,' a.json
"$BIN/mlod-label" --report=json --max-angle 90 "$ROOT/samples/cmu_12_01_walk.bvh" > b.json
grep -qx '  "max_angle": 90,' b.json
