"$BIN/mlod-bgm" --cost compactness --collapse edge "$ROOT/samples/tubeman.glb"
