cd "$ROOT" && "$BIN/mlod-skelgraph" --report tests/data/bad/nan_track.gltf
