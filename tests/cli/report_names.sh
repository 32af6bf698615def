# mlod-label, mlod-skelgraph and mlod-bgm print the names they take from
# the input through the tools' one escaper (tool_put_name,
# tool_json_string, as mlod-pack does: pack_info_names): a joint named
# with a quote, a newline, a tab, a backslash and a non-ASCII character,
# and an input file whose name holds a byte that is not UTF-8, keep every
# table line whole and mlod-label's columns in place; --report=json
# stays valid JSON with the names as given (the byte as U+FFFD).
set -e
node "$ROOT/tests/glb-edit.mjs" "$ROOT/samples/tubeman.glb" odd.glb \
	'j.nodes[1].name = "L\"Hip\nJo\tint\\ \u00e9"'
in=$(printf 'o\377d.glb')
cp odd.glb "$in"
# mlod-label: a header, 31 joint rows and the counts: no name broke a
# line, and every row is as wide as the column header (in characters)
"$BIN/mlod-label" "$in" --report > label.txt
python3 - label.txt <<'PY'
import sys
lines = open(sys.argv[1], encoding='utf-8', errors='replace').read().splitlines()
assert lines[0].startswith('# o\\xffd.glb: 31 joints'), lines[0]
rows = [l for l in lines if not l.startswith('# ')]
assert len(rows) == 32, len(rows)
assert len({len(r) for r in rows}) == 1, {len(r) for r in rows}
assert rows[2].startswith('L"Hip\\nJo\\tint\\\\ \u00e9  Hips  '), rows[2]
assert rows[3].startswith('LeftUpLeg           L"Hip\\nJo\\tint\\\\ \u00e9  '), rows[3]
PY
"$BIN/mlod-label" "$in" --report=json > label.json
python3 - label.json <<'PY'
import json, sys
j = json.load(open(sys.argv[1], encoding='utf-8'))
assert j['input'] == 'o\ufffdd.glb', repr(j['input'])
assert j['joints'][1]['name'] == 'L"Hip\nJo\tint\\ \u00e9', repr(j['joints'][1])
assert j['joints'][2]['parent'] == 'L"Hip\nJo\tint\\ \u00e9', repr(j['joints'][2])
PY
# mlod-skelgraph: the removed joints' lines and the header
"$BIN/mlod-skelgraph" "$in" --report > skel.txt
grep -q -F '# o\xffd.glb: 31 joints' skel.txt
grep -q -F '# level 1 removes: L"Hip\nJo\tint\\ é RHipJoint' skel.txt
if grep -v -E '^(# |level |    0 |    [1-9] )' skel.txt; then exit 1; fi
"$BIN/mlod-skelgraph" "$in" --report=json > skel.json
python3 -m json.tool skel.json > /dev/null
# mlod-bgm: the header
"$BIN/mlod-bgm" "$in" --report > bgm.txt
grep -q -F '# o\xffd.glb: 7776 triangles' bgm.txt
"$BIN/mlod-bgm" "$in" --report=json > bgm.json
python3 - bgm.json <<'PY'
import json, sys
j = json.load(open(sys.argv[1], encoding='utf-8'))
assert j['input'] == 'o\ufffdd.glb', repr(j['input'])
PY
