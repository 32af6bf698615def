# The report on the robot: 43 joints, one root, the leaves (one neighbour)
# are the end-effectors, and only they.
set -e
"$BIN/mlod-label" --report "$ROOT/samples/RobotExpressive.glb" > report.txt
rows=$(grep -vc '^#' report.txt)
test "$rows" -eq 44   # header + 43 joints
grep -v '^#' report.txt | awk '$1 != "joint"' > joints.txt
test "$(grep -c ' root ' joints.txt)" -eq 1
grep -q '^Bone  *-  *0  *[0-9][0-9]*  *[^ ]* root ' joints.txt
test "$(awk '$4 == 1' joints.txt | wc -l)" -eq 15
test "$(awk '($4 == 1) != ($6 == "end-effector")' joints.txt | wc -l)" -eq 0
grep -q '^# root 1, end-effector 15, ' report.txt
