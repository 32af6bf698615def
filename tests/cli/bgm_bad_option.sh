"$BIN/mlod-bgm" --frobnicate x.glb
