"$BIN/mlod-motion" --frobnicate x.glb
