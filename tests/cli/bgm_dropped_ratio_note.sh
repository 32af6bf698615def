# A requested ratio that gives no coarser level is dropped; the note that
# --report prints goes to stderr too, where a shell user sees it (before,
# only --report said so). The robot's parts stop at about 6% of their
# triangles: 0.01 gives no fewer than 0.02. A ratio that is kept gives no
# note, and --report keeps the note in the report alone.
set -e
"$BIN/mlod-bgm" -R 0.5,0.02,0.01 "$ROOT/samples/RobotExpressive.glb" -o out.glb 2> dropped.err
test "$(cat dropped.err)" = "mlod-bgm: $ROOT/samples/RobotExpressive.glb: ratio 0.01 gives no fewer triangles than 0.02: dropped"
"$BIN/mlod-bgm" -R 0.5,0.02 "$ROOT/samples/RobotExpressive.glb" -o kept.glb 2> kept.err
test ! -s kept.err
"$BIN/mlod-bgm" --report -R 0.5,0.02,0.01 "$ROOT/samples/RobotExpressive.glb" > report.txt 2> report.err
grep -q 'ratio 0.01 gives no fewer triangles than 0.02: dropped' report.txt
test ! -s report.err
