# A static pyramid of 6 triangles plus 2 that repeat a vertex index (no
# area): mlod-bgm leaves the 2 out of its levels and says so, and drops a
# first level that would remove only them (it kept one, 6 triangles
# against the input's 8, at error 0); mlod-pack's report says level 0
# does not store them (before, it counted them as triangles quantisation
# made degenerate, or said nothing), and -x gives back the 6.
python3 - <<'PY' || exit 1
import base64, json, struct
pos = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0.5, 0.5, 1)]
idx = [0, 1, 2, 0, 2, 3, 0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0, 4, 1, 1, 2, 3, 3, 3]
ib = b''.join(struct.pack('<H', i) for i in idx)
pb = b''.join(struct.pack('<3f', *p) for p in pos)
buf = ib + pb
json.dump({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
           "nodes": [{"mesh": 0, "name": "prop"}],
           "meshes": [{"primitives": [{"attributes": {"POSITION": 1}, "indices": 0}]}],
           "buffers": [{"byteLength": len(buf),
                        "uri": "data:application/octet-stream;base64," + base64.b64encode(buf).decode()}],
           "bufferViews": [{"buffer": 0, "byteLength": len(ib)},
                           {"buffer": 0, "byteOffset": len(ib), "byteLength": len(pb)}],
           "accessors": [{"bufferView": 0, "componentType": 5123, "count": len(idx), "type": "SCALAR"},
                         {"bufferView": 1, "componentType": 5126, "count": 5, "type": "VEC3",
                          "min": [0, 0, 0], "max": [1, 1, 1]}]}, open("rep.gltf", "w"))
PY
"$BIN/mlod-bgm" --report rep.gltf > report.txt || exit 1
grep -q '^# note: .*2 triangle(s) with two corners at one position (no area) left out of the levels' report.txt ||
	{ cat report.txt >&2; exit 1; }
grep -q 'ratio 0.5 removes nothing: dropped' report.txt || { cat report.txt >&2; exit 1; }
[ "$(grep -c '^ *[0-9]' report.txt)" = 1 ] || { cat report.txt >&2; exit 1; } # level 0 alone
"$BIN/mlod-pack" rep.gltf -o rep.mlod --report > pack.txt || exit 1
grep -q 'mesh level 0: 2 triangles that repeat a vertex (no area) not stored' pack.txt || { cat pack.txt >&2; exit 1; }
grep -q 'quantisation made degenerate' pack.txt && { cat pack.txt >&2; exit 1; }
"$BIN/mlod-pack" -x rep.mlod -o x.glb || exit 1
node -e '
const b = require("fs").readFileSync("x.glb"), j = JSON.parse(b.subarray(20, 20 + b.readUInt32LE(12)));
const n = j.accessors[j.meshes[0].primitives[0].indices].count;
if (n !== 18) { console.error(`x.glb: ${n} indices, not 18`); process.exit(1); }' || exit 1
