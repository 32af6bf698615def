"$BIN/mlod-skelgraph" --report "$ROOT/tests/data/bad/nan_track.gltf"
