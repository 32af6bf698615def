# "Frames: 0": no clip, a clear error.
cd "$ROOT" && "$BIN/mlod-motion" tests/data/bad/motion_zero_frames.bvh > /dev/null
