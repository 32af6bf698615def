# The reader's notes (one a line) come out of mlod-label's, mlod-skelgraph's,
# mlod-bgm's and mlod-motion's table reports one "# note:" or "# input:" line
# each, not joined by a literal "\n" (as they were), and mlod-pack's note
# line has them as notes of their own ("; " between). Two notes here: a mesh node
# outside the default scene, and joints without a skin.
python3 - <<'PY' || exit 1
import base64, json, struct
pos = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0.5, 0.5, 1)]
idx = [0, 1, 2, 0, 2, 3, 0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0, 4]
ib = b''.join(struct.pack('<H', i) for i in idx)
pb = b''.join(struct.pack('<3f', *p) for p in pos)
tb = struct.pack('<2f', 0, 1) + struct.pack('<6f', 0, 0, 0, 0, 1, 0)
buf = ib + pb + tb
json.dump({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0, 2]}],
           "nodes": [{"mesh": 0, "name": "prop"}, {"mesh": 0, "name": "outside"},
                     {"name": "hips", "children": [3]}, {"name": "spine", "translation": [0, 1, 0]}],
           "meshes": [{"primitives": [{"attributes": {"POSITION": 1}, "indices": 0}]}],
           "animations": [{"name": "up", "samplers": [{"input": 2, "output": 3}],
                           "channels": [{"sampler": 0, "target": {"node": 3, "path": "translation"}}]}],
           "buffers": [{"byteLength": len(buf),
                        "uri": "data:application/octet-stream;base64," + base64.b64encode(buf).decode()}],
           "bufferViews": [{"buffer": 0, "byteLength": len(ib)},
                           {"buffer": 0, "byteOffset": len(ib), "byteLength": len(pb)},
                           {"buffer": 0, "byteOffset": len(ib) + len(pb), "byteLength": 8},
                           {"buffer": 0, "byteOffset": len(ib) + len(pb) + 8, "byteLength": 24}],
           "accessors": [{"bufferView": 0, "componentType": 5123, "count": len(idx), "type": "SCALAR"},
                         {"bufferView": 1, "componentType": 5126, "count": 5, "type": "VEC3",
                          "min": [0, 0, 0], "max": [1, 1, 1]},
                         {"bufferView": 2, "componentType": 5126, "count": 2, "type": "SCALAR",
                          "min": [0], "max": [1]},
                         {"bufferView": 3, "componentType": 5126, "count": 2, "type": "VEC3"}]},
          open("two.gltf", "w"))
PY
for t in label:note skelgraph:note bgm:input motion:note; do
	tool=${t%:*} prefix=${t#*:}
	"$BIN/mlod-$tool" --report two.gltf > $tool.txt 2> /dev/null || { echo "mlod-$tool failed" >&2; exit 1; }
	grep -q '\\n' $tool.txt && { echo "mlod-$tool: a literal \\n" >&2; cat $tool.txt >&2; exit 1; }
	grep -q "^# $prefix: 1 nodes with a mesh are not in the default scene" $tool.txt &&
		grep -q "^# $prefix: the document has no skins" $tool.txt || { cat $tool.txt >&2; exit 1; }
done
"$BIN/mlod-pack" --report two.gltf -o two.mlod > pack.txt 2> /dev/null || { echo "mlod-pack failed" >&2; exit 1; }
grep -q '\\n' pack.txt && { echo "mlod-pack: a literal \\n" >&2; cat pack.txt >&2; exit 1; }
grep -Eq '^# note: (.*; )?1 nodes with a mesh are not in the default scene[^;]*: they are not instances(;|$)' pack.txt &&
	grep -Eq '^# note: (.*; )?the document has no skins: its 1 joints are[^;]*(;|$)' pack.txt ||
	{ cat pack.txt >&2; exit 1; }
exit 0
