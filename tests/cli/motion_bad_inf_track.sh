cd "$ROOT" && "$BIN/mlod-motion" tests/data/bad/motion_inf_track.gltf > /dev/null
