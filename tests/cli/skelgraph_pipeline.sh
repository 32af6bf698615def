# mlod-label | mlod-skelgraph --report: labels come from the extras.
set -e
"$BIN/mlod-label" < "$ROOT/samples/RobotExpressive.glb" | "$BIN/mlod-skelgraph" --report -j 0.9 > report.txt
grep -q 'labels from extras' report.txt
grep -q '^    1 ' report.txt
