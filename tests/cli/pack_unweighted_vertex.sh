# A skinned vertex whose weights are all 0 (tubeman's vertex 0; glTF
# wants them to sum to 1, and the validator says so of the input) made
# mlod-pack fail, exit 2, with its own reader's check ("the pack as
# written fails its reader's check: ... weights sum to 0, not 255"): the
# pack stores such a vertex on the skin's root joint, which it follows,
# with a note in the report and a warning on stderr (with or without
# --report), and the pack reads back; -x gives a glb the validator
# takes, which packs again.
set -e
python3 - "$ROOT/samples/tubeman.glb" zero.glb <<'PY'
import json, struct, sys
d = bytearray(open(sys.argv[1], 'rb').read())
n = struct.unpack_from('<I', d, 12)[0]
j = json.loads(d[20:20 + n])
bin0 = 20 + n + 8
a = j['accessors'][j['meshes'][0]['primitives'][0]['attributes']['WEIGHTS_0']]
v = j['bufferViews'][a['bufferView']]
size = {5126: 4, 5123: 2, 5121: 1}[a['componentType']]
at = bin0 + v.get('byteOffset', 0) + a.get('byteOffset', 0)
d[at:at + 4 * size] = bytes(4 * size)
open(sys.argv[2], 'wb').write(d)
PY
"$BIN/mlod-pack" --report zero.glb -o zero.mlod > report.txt 2> /dev/null
grep -q -F 'mesh 0 primitive 0: vertex 0 has no weight: it follows the skin'"'"'s root joint "Hips"' report.txt
"$BIN/mlod-pack" zero.glb -o zero2.mlod 2> stderr.txt
[ "$(cat stderr.txt)" = "mlod-pack: zero.glb: mesh 0 primitive 0: vertex 0 has no weight: it follows the skin's root joint \"Hips\"" ]
"$BIN/mlod-pack" --info zero.mlod > /dev/null
"$BIN/mlod-pack" -x zero.mlod -o zero-x.glb
node "$ROOT/tests/validate.mjs" zero-x.glb > /dev/null
"$BIN/mlod-pack" zero-x.glb -o again.mlod
