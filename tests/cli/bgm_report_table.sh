# The table: a header, level 0 and one row per default level.
set -e
"$BIN/mlod-bgm" --report "$ROOT/samples/RobotExpressive.glb" > report.txt
test "$(grep -vc '^#' report.txt)" -eq 5
grep -q 'morph targets' report.txt
grep -q '^    3     0.1 ' report.txt
