# meshopt-compressed input is unsupported, exit 3.
"$BIN/mlod-bgm" "$ROOT/tests/data/bad/meshopt.glb"
