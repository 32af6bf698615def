"$BIN/mlod-label" --frobnicate x.glb
