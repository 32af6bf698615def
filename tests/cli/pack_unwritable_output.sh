"$BIN/mlod-pack" -o no/such/dir/out.mlod "$ROOT/samples/cmu_12_01_walk.bvh"
