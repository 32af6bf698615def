"$BIN/mlod-bgm" -j 1.5 "$ROOT/samples/tubeman.glb"
