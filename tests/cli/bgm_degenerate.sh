# A primitive whose every triangle repeats a corner (its indices all 0:
# valid glTF, nothing to simplify or measure) is left as it is: with no
# other triangles mlod-bgm passes the input through with its note, and
# mlod-pack packs the skeleton and motion levels, with no part to draw
# (both exited 1, "deviation: mesh b is empty").
set -e
python3 - "$ROOT/samples/tubeman.glb" degen.glb <<'PY'
import json, struct, sys
b = bytearray(open(sys.argv[1], 'rb').read())
jl = struct.unpack_from('<I', b, 12)[0]
j = json.loads(b[20:20 + jl])
binat = 20 + jl + 8
for m in j['meshes']:
    for p in m['primitives']:
        a = j['accessors'][p['indices']]
        v = j['bufferViews'][a['bufferView']]
        size = {5121: 1, 5123: 2, 5125: 4}[a['componentType']]
        o = binat + v.get('byteOffset', 0) + a.get('byteOffset', 0)
        b[o:o + size * a['count']] = bytes(size * a['count'])
open(sys.argv[2], 'wb').write(b)
PY
"$BIN/mlod-bgm" degen.glb -o out.glb 2> bgm.err
grep -q -F 'mlod-bgm: degen.glb: no triangle mesh; written unchanged' bgm.err
"$BIN/mlod-pack" degen.glb -o degen.mlod --report > report.txt
grep -q -F ': 31 joints, 1 skins, 0 parts, 1 clips;' report.txt
grep -E -q '^mesh +0 ' report.txt
"$BIN/mlod-pack" --info degen.mlod > /dev/null
