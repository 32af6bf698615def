cd "$ROOT" && "$BIN/mlod-motion" tests/data/bad/motion_long_track.gltf > /dev/null
