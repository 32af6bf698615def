"$BIN/mlod-bgm" -j 0 "$ROOT/samples/tubeman.glb"
