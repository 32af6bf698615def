"$BIN/mlod-pack" --ratios 0.5,2 "$ROOT/samples/tubeman.glb"
