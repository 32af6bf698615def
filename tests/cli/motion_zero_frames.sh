# "Frames: 0": no clip; the BVH passes through as glb with a note (exit 0),
# and asking for a BVH level of it is a clear error.
set -e
cd "$ROOT"
"$BIN/mlod-motion" tests/data/bad/motion_zero_frames.bvh > "$OLDPWD/out.glb" 2> "$OLDPWD/err"
if "$BIN/mlod-motion" tests/data/bad/motion_zero_frames.bvh -o "$OLDPWD/out.bvh" 2> "$OLDPWD/err2"; then exit 1; fi
cd "$OLDPWD"
test "$(cat err)" = "mlod-motion: tests/data/bad/motion_zero_frames.bvh: no animation (the BVH has 'Frames: 0'): nothing to reduce; written unchanged"
test "$(cat err2)" = "mlod-motion: tests/data/bad/motion_zero_frames.bvh: no animation (the BVH has 'Frames: 0'): no clip to write as BVH"
test "$(head -c 4 out.glb)" = glTF
node "$ROOT/tests/validate.mjs" out.glb > /dev/null
