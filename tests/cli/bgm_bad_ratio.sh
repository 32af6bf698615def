# A ratio must be in (0, 1].
"$BIN/mlod-bgm" --ratios 0.5,1.5 "$ROOT/samples/tubeman.glb"
