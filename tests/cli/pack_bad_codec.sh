"$BIN/mlod-pack" --codec zip "$ROOT/samples/tubeman.glb"
