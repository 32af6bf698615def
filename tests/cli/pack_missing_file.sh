"$BIN/mlod-pack" no-such-file.glb
