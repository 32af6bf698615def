# The table: a header, level 0 and one row per level. The robot's open
# part borders now collapse along themselves, so the default 0.03 level is
# kept (it stopped at 678 of 3237 triangles while they were locked), but
# its parts keep their holes: it stops at about 6% of its triangles, and a
# ratio below that is dropped with a note when the level before already got
# there.
set -e
"$BIN/mlod-bgm" --report "$ROOT/samples/RobotExpressive.glb" > report.txt
test "$(grep -vc '^#' report.txt)" -eq 6
grep -q 'morph targets' report.txt
if grep -q 'dropped' report.txt; then exit 1; fi
grep -q 'budget per character' report.txt
grep -q '^    3     0.1 ' report.txt
# Level 3 keeps at most 10% of the triangles, level 4 fewer.
awk '$1 == 3 && $2 == "0.1" { l3 = $3 } $1 == 4 && $2 == "0.03" { l4 = $3 }
     END { exit !(l3 > 0 && l3 <= 324 && l4 > 0 && l4 < l3) }' report.txt
"$BIN/mlod-bgm" --report -R 0.5,0.02,0.01 "$ROOT/samples/RobotExpressive.glb" > floor.txt
test "$(grep -vc '^#' floor.txt)" -eq 4
grep -q 'ratio 0.01 gives no fewer triangles than 0.02: dropped' floor.txt
"$BIN/mlod-bgm" --report -B primitive "$ROOT/samples/RobotExpressive.glb" > primitive.txt
test "$(grep -vc '^#' primitive.txt)" -eq 6
grep -q '^    3     0.1 ' primitive.txt
