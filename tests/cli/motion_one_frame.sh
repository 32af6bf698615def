# One frame: nothing to reduce; the glb is written back without levels, and says so.
set -e
cd "$ROOT"
"$BIN/mlod-motion" tests/data/bad/motion_one_frame.bvh > "$OLDPWD/out.glb" 2> "$OLDPWD/err"
cd "$OLDPWD"
grep -q "has 1 frame: nothing to reduce" err
node "$ROOT/tests/validate.mjs" out.glb > /dev/null
