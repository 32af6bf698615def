# --report prints to stdout: an -o that names stdout too ('-', /dev/stdout,
# the file stdout goes to) would put the pack and the report in one stream.
# Each is refused before the input is read; an -o FILE with a report works.
set -e
for o in - /dev/stdout p.mlod; do
	if "$BIN/mlod-pack" --report -o "$o" "$ROOT/samples/cmu_12_01_walk.bvh" > p.mlod 2> err.txt; then exit 1; fi
	grep -qx "mlod-pack: --report prints to stdout, and -o names stdout too: the pack and the report would share one stream (write the pack to a file, or drop -o for the report alone)" err.txt
	test ! -s p.mlod
done
"$BIN/mlod-pack" --report -o w.mlod "$ROOT/samples/cmu_12_01_walk.bvh" > report.txt
"$BIN/mlod-pack" --info w.mlod > /dev/null
grep -q '^# total' report.txt
"$BIN/mlod-pack" --report -o /dev/null "$ROOT/samples/cmu_12_01_walk.bvh" > /dev/null
