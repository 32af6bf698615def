# --report=json is valid JSON with one entry per joint.
set -e
"$BIN/mlod-label" --report=json "$ROOT/samples/cmu_12_01_walk.bvh" > r.json
node -e 'const r = JSON.parse(require("fs").readFileSync("r.json")); if (r.joints.length < 2 || r.joints[0].label !== "root") process.exit(1)'
