"$BIN/mlod-motion" --threads 1.5 "$ROOT/samples/cmu_12_01_walk.bvh"
