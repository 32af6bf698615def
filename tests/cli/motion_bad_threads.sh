"$BIN/mlod-motion" -j 0 "$ROOT/samples/cmu_12_01_walk.bvh"
