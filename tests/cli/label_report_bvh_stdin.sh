# BVH from stdin: the CMU walk's hips are the root, the chest region has a hub.
set -e
"$BIN/mlod-label" --report < "$ROOT/samples/cmu_12_01_walk.bvh" > report.txt
grep -Eq '^Hips +- +0 .*root' report.txt
grep -Eq '(major|extreme)' report.txt
