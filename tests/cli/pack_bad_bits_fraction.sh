"$BIN/mlod-pack" --position-bits 12.5 "$ROOT/samples/tubeman.glb"
