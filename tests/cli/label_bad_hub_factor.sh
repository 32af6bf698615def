"$BIN/mlod-label" --hub-factor abc "$ROOT/samples/cmu_12_01_walk.bvh"
