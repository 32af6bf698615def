"$BIN/mlod-motion" -o no/such/dir/out.glb "$ROOT/samples/cmu_12_01_walk.bvh"
