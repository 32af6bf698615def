# The input file's name in the --report table's first line is escaped as
# the other tools' tables write names (C escapes: \n, \xHH for another
# control character or a byte that is not UTF-8): a name with a newline,
# an ANSI escape and a byte 0xff was printed raw, so it broke the table's
# first line in two and recoloured the terminal. --report=json writes it
# as a JSON string with the byte as U+FFFD, as lib/record's writer does (it
# wrote the byte raw: not UTF-8, so not JSON text).
set -e
in=$(printf 'w\nalk\033[31m\377.bvh')
cp "$ROOT/samples/cmu_12_01_walk.bvh" "$in"
"$BIN/mlod-motion" -e 2% --report "$in" > table
head -n 1 table | grep -q -F '# w\nalk\x1b[31m\xff.bvh: 31 joints, height '
test "$(grep -c "$(printf '\033')" table)" = 0
test "$(grep -c -v -E '^(# |clip |[^ ]+ +[0-9]+ )' table)" = 0
"$BIN/mlod-motion" -e 2% --report=json "$in" > table.json
python3 - table.json <<'PY'
import json, sys
j = json.load(open(sys.argv[1], encoding='utf-8'))
assert j['input'] == 'w\nalk\x1b[31m\ufffd.bvh', repr(j['input'])
PY
