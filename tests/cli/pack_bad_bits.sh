"$BIN/mlod-pack" --normal-bits 5 "$ROOT/samples/tubeman.glb"
