"$BIN/mlod-pack" --entropy zip "$ROOT/samples/tubeman.glb"
