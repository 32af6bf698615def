# BVH from stdin: the CMU walk's hips are the root, the chest region has a
# hub (Spine1, four neighbours, major).
set -e
"$BIN/mlod-label" --report < "$ROOT/samples/cmu_12_01_walk.bvh" > report.txt
grep -Eq '^Hips +- +0 .*root' report.txt
grep -Eq '^Spine1 +Spine +[0-9]+ +4 +[^ ]+ major ' report.txt
