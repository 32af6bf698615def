cd "$ROOT" && "$BIN/mlod-motion" tests/data/bad/motion_negative_frame_time.bvh > /dev/null
