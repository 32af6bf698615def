# The table: a header, level 0 and one row per level. The robot's open
# part borders stop it at about a fifth of its triangles: a ratio below
# that is dropped with a note when the level before already got there.
set -e
"$BIN/mlod-bgm" --report "$ROOT/samples/RobotExpressive.glb" > report.txt
test "$(grep -vc '^#' report.txt)" -eq 5
grep -q 'morph targets' report.txt
grep -q 'ratio 0.03 gives no fewer triangles than 0.1: dropped' report.txt
grep -q 'budget per character' report.txt
grep -q '^    3     0.1 ' report.txt
"$BIN/mlod-bgm" --report -R 0.5,0.02,0.01 "$ROOT/samples/RobotExpressive.glb" > floor.txt
test "$(grep -vc '^#' floor.txt)" -eq 4
grep -q 'ratio 0.01 gives no fewer triangles than 0.02: dropped' floor.txt
"$BIN/mlod-bgm" --report -B primitive "$ROOT/samples/RobotExpressive.glb" > primitive.txt
test "$(grep -vc '^#' primitive.txt)" -eq 6
grep -q '^    3     0.1 ' primitive.txt
