"$BIN/mlod-pack" -p quadric -o out.mlod "$ROOT/samples/tubeman.glb"
