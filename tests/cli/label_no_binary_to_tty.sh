# A glb is never written to a terminal (script(1) gives the tool a tty).
# What the tool printed on the terminal goes to stderr for the runner to
# compare; exit 127 if script(1) is missing (not 1, the expected code).
command -v script > /dev/null || { echo "script(1) is missing" >&2; exit 127; }
script -qec "\"$BIN/mlod-label\" \"$ROOT/samples/cmu_12_01_walk.bvh\"" /dev/null > tty.txt
rc=$?
tr -d '\r' < tty.txt >&2
exit $rc
