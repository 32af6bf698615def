"$BIN/mlod-pack" --motion-max-error 1%,x "$ROOT/samples/tubeman.glb"
