# --level beyond the last level names the valid range (the walk has levels
# 0..3, and -l 3 works).
set -e
"$BIN/mlod-skelgraph" -l 3 -o ok.bvh "$ROOT/samples/cmu_12_01_walk.bvh"
test -s ok.bvh
"$BIN/mlod-skelgraph" -l 4 -o x.bvh "$ROOT/samples/cmu_12_01_walk.bvh"
