# Whole frames after the declared count are ignored, with a note.
set -e
"$BIN/mlod-label" --report "$ROOT/tests/data/extra_frame.bvh" > report.txt
grep -q "^# note: 1 frame after the 2 that 'Frames:' announces (from line 30) ignored" report.txt
