# --influence-budget takes a fraction >= 0 (0: off).
"$BIN/mlod-bgm" --influence-budget -1 "$ROOT/samples/tubeman.glb"
