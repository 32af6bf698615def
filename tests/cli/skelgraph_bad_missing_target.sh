cd "$ROOT" && "$BIN/mlod-skelgraph" --report tests/data/bad/missing_target.gltf
