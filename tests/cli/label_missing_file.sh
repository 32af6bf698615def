"$BIN/mlod-label" no-such-file.glb
