# When no level fits the bound, say so on stderr and still succeed, with
# level 0 alone. (Not tubeman: its first level removes four joints at no
# cost, within any bound.)
set -e
cd "$ROOT"
"$BIN/mlod-skelgraph" --report -e 0.001 samples/RobotExpressive.glb > "$OLDPWD/report.txt"
cd "$OLDPWD"
grep -q '^    0  ' report.txt
test "$(grep -c '^    1  ' report.txt)" -eq 0
