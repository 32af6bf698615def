"$BIN/mlod-pack" --frobnicate x.glb
