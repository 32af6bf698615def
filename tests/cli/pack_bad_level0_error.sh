"$BIN/mlod-pack" --motion-level0-error 0% "$ROOT/samples/tubeman.glb"
