"$BIN/mlod-skelgraph" --level 2 "$ROOT/samples/cmu_12_01_walk.bvh"
