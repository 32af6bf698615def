"$BIN/mlod-motion" --precision half x.glb
