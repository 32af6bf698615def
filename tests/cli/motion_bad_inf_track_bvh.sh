"$BIN/mlod-motion" < "$ROOT/tests/data/bad/motion_inf_track.bvh" > /dev/null
