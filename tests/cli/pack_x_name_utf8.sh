# -x of a pack whose name is not UTF-8 (--name, or a Latin-1 file name
# as the default): the stage record's name has each such byte as U+FFFD
# (as lib/io reads names), so the record stays JSON and -x exits 0
# (it exited 1: 'extras "mlod": not JSON: ... ill-formed UTF-8 byte').
set -e
"$BIN/mlod-pack" "$ROOT/samples/tubeman.glb" --name "$(printf 'bad\377')" --no-mesh-levels -o bad.mlod
"$BIN/mlod-pack" -x bad.mlod -o bad.glb
cp "$ROOT/samples/tubeman.glb" "$(printf 'caf\351.glb')"
"$BIN/mlod-pack" "$(printf 'caf\351.glb')" --no-mesh-levels -o cafe.mlod
"$BIN/mlod-pack" -x cafe.mlod -o cafe.glb
node "$ROOT/tests/validate.mjs" bad.glb cafe.glb > /dev/null
python3 - bad.glb cafe.glb <<'PY'
import json, struct, sys
for f, want in zip(sys.argv[1:], ['bad\ufffd', 'caf\ufffd']):
    d = open(f, 'rb').read()
    n = struct.unpack_from('<I', d, 12)[0]
    j = json.loads(d[20:20 + n].decode('utf-8'))
    name = j['scenes'][j.get('scene', 0)]['extras']['mlod']['pack']['name']
    assert name == want, (f, name)
PY
# packed again, the name is the record's
"$BIN/mlod-pack" bad.glb -o again.mlod
"$BIN/mlod-pack" --info again.mlod --json > again.json
python3 -c 'import json, sys; n = json.load(open(sys.argv[1], encoding="utf-8"))["name"]; assert n == "bad\ufffd", n' again.json
