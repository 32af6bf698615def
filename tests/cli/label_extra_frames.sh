# Whole frames after the declared count are ignored, with a note in the
# report and a warning on stderr from every tool, with or without a
# report (it was in the report only).
set -e
"$BIN/mlod-label" --report "$ROOT/tests/data/extra_frame.bvh" > report.txt 2> /dev/null
grep -q "^# note: 1 frame after the 2 that 'Frames:' announces (from line 30) ignored" report.txt
for t in mlod-label mlod-motion mlod-pack; do
	"$BIN/$t" "$ROOT/tests/data/extra_frame.bvh" -o out.bin 2> err.txt
	grep -q -x -F "$t: $ROOT/tests/data/extra_frame.bvh: 1 frame after the 2 that 'Frames:' announces (from line 30) ignored" err.txt
done
