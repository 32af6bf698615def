# meshopt-compressed input is unsupported, exit 3.
cd "$ROOT" && "$BIN/mlod-bgm" tests/data/bad/meshopt.glb
