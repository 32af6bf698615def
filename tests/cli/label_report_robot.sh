# The report on the robot: 43 joints, one root, the leaves are end-effectors.
set -e
"$BIN/mlod-label" --report "$ROOT/samples/RobotExpressive.glb" > report.txt
rows=$(grep -vc '^#' report.txt)
test "$rows" -eq 44   # header + 43 joints
test "$(grep -c ' root ' report.txt)" -ge 1
grep -q '^# root 1, end-effector' report.txt
