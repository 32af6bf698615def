# A glb is never written to a terminal (script(1) gives the tool a tty).
command -v script > /dev/null || { echo "script(1) is missing" >&2; exit 1; }
script -qec "\"$BIN/mlod-label\" \"$ROOT/samples/cmu_12_01_walk.bvh\"" /dev/null > tty.txt
rc=$?
grep -q 'refusing to write binary output to a terminal' tty.txt || exit 9
exit $rc
