"$BIN/mlod-bgm" -o no/such/dir/out.glb "$ROOT/samples/tubeman.glb"
