# A primitive whose every triangle repeats a corner (its indices all 0),
# or has no area (every position one point): valid glTF, nothing to
# simplify or measure, so it is left as it is. With no other triangles
# mlod-bgm passes the input through with its note, mlod-pack packs the
# skeleton and motion levels with no part to draw (both exited 1,
# "deviation: mesh b is empty"), and -x gives the mesh back whole (the
# document chunk keeps a mesh no MESH part holds; it was stripped, and -x
# refused the pack).
set -e
# zero.py IN OUT indices|positions: the tubeman with that attribute's
# bytes all 0 (positions: their min and max too)
cat > zero.py <<'PY'
import json, struct, sys
b = bytearray(open(sys.argv[1], 'rb').read())
jl = struct.unpack_from('<I', b, 12)[0]
j = json.loads(b[20:20 + jl])
binat = 20 + jl + 8
for m in j['meshes']:
    for p in m['primitives']:
        a = j['accessors'][p['indices'] if sys.argv[3] == 'indices' else p['attributes']['POSITION']]
        v = j['bufferViews'][a['bufferView']]
        size = {5121: 1, 5123: 2, 5125: 4, 5126: 12}[a['componentType']]
        o = binat + v.get('byteOffset', 0) + a.get('byteOffset', 0)
        b[o:o + size * a['count']] = bytes(size * a['count'])
        if sys.argv[3] == 'positions':
            a['min'] = a['max'] = [0, 0, 0]
t = json.dumps(j).encode()
t += b' ' * (-len(t) % 4)
out = bytearray(b[:12]) + struct.pack('<II', len(t), 0x4E4F534A) + t + b[20 + jl:]
struct.pack_into('<I', out, 8, len(out))
open(sys.argv[2], 'wb').write(out)
PY
python3 zero.py "$ROOT/samples/tubeman.glb" degen.glb indices
python3 zero.py "$ROOT/samples/tubeman.glb" flat.glb positions
for f in degen flat; do
	"$BIN/mlod-bgm" $f.glb -o $f.out.glb 2> bgm.err
	grep -q -F "mlod-bgm: $f.glb: no triangle mesh; written unchanged" bgm.err
	"$BIN/mlod-pack" $f.glb -o $f.mlod --report 2> /dev/null > report.txt
	grep -q -F ': 31 joints, 1 skins, 0 parts, 1 clips;' report.txt
	grep -E -q '^mesh +0 ' report.txt
	"$BIN/mlod-pack" --info $f.mlod > /dev/null
	"$BIN/mlod-pack" -x $f.mlod -o $f.x.glb
	node "$ROOT/tests/validate.mjs" $f.x.glb | grep -q ' 0 errors'
done
