"$BIN/mlod-motion" -m keys -t 0.1 "$ROOT/samples/cmu_12_01_walk.bvh"
