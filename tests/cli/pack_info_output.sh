# --info prints to stdout; -o with it is refused rather than ignored.
set -e
"$BIN/mlod-pack" -o w.mlod "$ROOT/samples/cmu_12_01_walk.bvh"
"$BIN/mlod-pack" --info w.mlod --json -o x.json
