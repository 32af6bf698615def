"$BIN/mlod-skelgraph" --report "$ROOT/tests/data/bad/cycle.gltf"
