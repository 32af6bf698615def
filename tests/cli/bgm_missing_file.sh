"$BIN/mlod-bgm" no-such-file.glb
