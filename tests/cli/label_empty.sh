: > empty.glb
"$BIN/mlod-label" empty.glb
