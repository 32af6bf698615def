"$BIN/mlod-pack" --codec draco -o x.mlod "$ROOT/samples/tubeman.glb"
