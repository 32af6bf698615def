cd "$ROOT" && "$BIN/mlod-skelgraph" --report tests/data/bad/cycle.gltf
