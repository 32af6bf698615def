"$BIN/mlod-bgm" -p hybrid=0 -o out.glb "$ROOT/samples/tubeman.glb"
