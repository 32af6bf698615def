"$BIN/mlod-pack" --ratios 0.5 --max-error 1 "$ROOT/samples/tubeman.glb"
