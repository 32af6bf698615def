"$BIN/mlod-motion" --level 1 "$ROOT/samples/cmu_12_01_walk.bvh"
