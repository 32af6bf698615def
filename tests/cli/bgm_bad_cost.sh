"$BIN/mlod-bgm" --cost qem "$ROOT/samples/tubeman.glb"
