# More than one whole frame after the count 'Frames:' announces is an
# error, exit 2, as too few frames are: the count is wrong, not off by one
# (label_extra_frames: one frame more is ignored with a note), and the
# motion after it would be dropped. 'Frames: 3' over the walk's 524 rows
# was read as 3 frames without a word on standard error.
sed 's/^Frames:.*/Frames: 3/' "$ROOT/samples/cmu_12_01_walk.bvh" > three.bvh || exit 1
"$BIN/mlod-label" -o out.glb three.bvh
