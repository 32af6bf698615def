cd "$ROOT" && "$BIN/mlod-motion" tests/data/bad/motion_decreasing_times.gltf > /dev/null
