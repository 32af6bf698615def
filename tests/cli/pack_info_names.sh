# mlod-pack --info and --report print the names they take from the input
# or the pack escaped (one place, tool_put_name in tools/common.c): a clip and a character named
# with a quote, a backslash, a newline, a tab, control characters, DEL, a
# non-ASCII character and a byte that is not UTF-8 keep every table line
# whole and the columns after the name in place (\n, \t, \\, \xHH); --json
# and --report=json stay valid JSON with the names as given (the byte that
# is not UTF-8 as U+FFFD).
set -e
node "$ROOT/tests/glb-edit.mjs" "$ROOT/samples/tubeman.glb" odd.glb \
	'j.animations[0].name = "w\"a\\l\nk\t\u0001\u007f \u00e9"'
name=$(printf 't"u\\b\ne\tm\002\377')
"$BIN/mlod-pack" odd.glb -o odd.mlod --name "$name" --no-mesh-levels --no-motion-levels > /dev/null 2>&1
"$BIN/mlod-pack" --info odd.mlod > info.txt
# every line is a header, a chunk or a total: no name broke one
if grep -v -E '^(# |type  |INFO  |SKEL  |MESH  |ANIM  |DOC   )' info.txt; then exit 1; fi
cat > want.txt <<'EOF'
# character 't"u\\b\ne\tm\x02\xff': 31 joints
ANIM  motion       0  w"a\\l\nk\t\x01\x7f é meshopt+zstd
EOF
while IFS= read -r line; do grep -q -F -e "$line" info.txt; done < want.txt
"$BIN/mlod-pack" --info odd.mlod --json > info.json
python3 -m json.tool info.json > /dev/null
python3 - info.json <<'PY'
import json, sys
j = json.load(open(sys.argv[1], encoding='utf-8'))
assert j['name'] == 't"u\\b\ne\tm\x02\ufffd', repr(j['name'])
clips = {c['clip'] for c in j['chunks'] if c['clip'] is not None}
assert clips == {'w"a\\l\nk\t\x01\x7f \u00e9'}, clips
PY
# --report: the input's name and the notes through the same escapes
cp odd.glb "$(printf 'o\td"d.glb')"
"$BIN/mlod-pack" "$(printf 'o\td"d.glb')" -o /dev/null --no-mesh-levels --report > report.txt
grep -q -F '# o\td"d.glb: 31 joints' report.txt
"$BIN/mlod-pack" "$(printf 'o\td"d.glb')" -o /dev/null --no-mesh-levels --report=json > report.json
python3 - report.json <<'PY'
import json, sys
j = json.load(open(sys.argv[1], encoding='utf-8'))
assert j['input'] == 'o\td"d.glb', repr(j['input'])
PY
