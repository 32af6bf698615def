"$BIN/mlod-motion" --subdivide 0 x.glb
