"$BIN/mlod-bgm" --cost compactness --budget character "$ROOT/samples/tubeman.glb"
