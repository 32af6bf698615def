# The table: a header, level 0 and one row per level. With the character
# budget the robot's default 25% already reaches as far as it goes, so its
# 10% is dropped with a note; with the primitive budget each part stops at
# its ratio and all three default levels are there.
set -e
"$BIN/mlod-bgm" --report "$ROOT/samples/RobotExpressive.glb" > report.txt
test "$(grep -vc '^#' report.txt)" -eq 4
grep -q 'morph targets' report.txt
grep -q 'budget per character' report.txt
grep -q 'ratio 0.1 gives no fewer triangles than 0.25: dropped' report.txt
"$BIN/mlod-bgm" --report -B primitive "$ROOT/samples/RobotExpressive.glb" > primitive.txt
test "$(grep -vc '^#' primitive.txt)" -eq 5
grep -q '^    3     0.1 ' primitive.txt
