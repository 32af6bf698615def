# A primitive whose every triangle repeats a corner (its indices all 0:
# valid glTF, nothing to simplify or measure) is left as it is: with no
# other triangles mlod-bgm passes the input through with its note, and
# mlod-pack packs the skeleton and motion levels, with no part to draw
# (both exited 1, "deviation: mesh b is empty"); -x gives the mesh back.
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
# -x gives the mesh back whole (the document chunk keeps a mesh no MESH
# part holds; it was stripped, and -x refused the pack)
"$BIN/mlod-pack" -x degen.mlod -o degen.x.glb
node "$ROOT/tests/validate.mjs" degen.x.glb | grep -q ' 0 errors'
# Every position one point (valid glTF, no triangle with an area): the
# same, where mlod-bgm and mlod-pack exited 1 ("deviation: mesh b is
# empty").
python3 - "$ROOT/samples/tubeman.glb" flat.glb <<'PY'
import json, struct, sys
b = bytearray(open(sys.argv[1], 'rb').read())
jl = struct.unpack_from('<I', b, 12)[0]
j = json.loads(b[20:20 + jl])
binat = 20 + jl + 8
for m in j['meshes']:
    for p in m['primitives']:
        a = j['accessors'][p['attributes']['POSITION']]
        v = j['bufferViews'][a['bufferView']]
        o = binat + v.get('byteOffset', 0) + a.get('byteOffset', 0)
        b[o:o + 12 * a['count']] = bytes(12 * a['count'])
        a['min'] = a['max'] = [0, 0, 0]
t = json.dumps(j).encode()
t += b' ' * (-len(t) % 4)
out = bytearray(b[:12]) + struct.pack('<II', len(t), 0x4E4F534A) + t + b[20 + jl:]
struct.pack_into('<I', out, 8, len(out))
open(sys.argv[2], 'wb').write(out)
PY
"$BIN/mlod-bgm" flat.glb -o flat.out.glb 2> bgm.err
grep -q -F 'mlod-bgm: flat.glb: no triangle mesh; written unchanged' bgm.err
"$BIN/mlod-pack" flat.glb -o flat.mlod 2> /dev/null
"$BIN/mlod-pack" -x flat.mlod -o flat.x.glb
node "$ROOT/tests/validate.mjs" flat.x.glb | grep -q ' 0 errors'
