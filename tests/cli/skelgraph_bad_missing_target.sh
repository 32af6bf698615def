"$BIN/mlod-skelgraph" --report "$ROOT/tests/data/bad/missing_target.gltf"
