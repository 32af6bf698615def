# A pack whose DOC chunk points a node that has no MESH part (joint node
# 3) at mesh 0, whose triangles the DOC lost to the MESH chunks: -x
# exits 2 naming the DOC chunk and writes nothing. It wrote a glb the
# validator refuses (EMPTY_ENTITY: a primitive without attributes) and
# exited 0. The DOC's glb JSON is edited in place, the same length (the
# asset's generator goes), the CRCs made to match.
"$BIN/mlod-pack" --codec none --entropy none "$ROOT/samples/tubeman.glb" -o plain.mlod 2> /dev/null || exit 9
python3 - plain.mlod bad.mlod <<'PY' || exit 9
import json, struct, sys, zlib
x = bytearray(open(sys.argv[1], 'rb').read())
cnt = struct.unpack_from('<I', x, 12)[0]
toc = [struct.unpack_from('<4sBBHHHIQIIIffI', x, 32 + 48 * i) for i in range(cnt)]
doc = [t for t in toc if t[0] == b'DOC '][0]
g = x.index(b'glTF', doc[7])
n = struct.unpack_from('<I', x, g + 12)[0]
j = json.loads(bytes(x[g + 20:g + 20 + n]))
assert 'mesh' not in j['nodes'][3] and 'generator' in j['asset']
j['nodes'][3]['mesh'] = 0
del j['asset']['generator']
text = json.dumps(j, separators=(',', ':')).encode()
assert len(text) <= n, (len(text), n)
x[g + 20:g + 20 + n] = text + b' ' * (n - len(text))
for i, t in enumerate(toc):
    struct.pack_into('<I', x, 32 + 48 * i + 32, zlib.crc32(bytes(x[t[7]:t[7] + t[8]])))
struct.pack_into('<I', x, 24, zlib.crc32(bytes(x[32:32 + 48 * cnt])))
struct.pack_into('<I', x, 28, zlib.crc32(bytes(x[0:28])))
open(sys.argv[2], 'wb').write(x)
PY
"$BIN/mlod-pack" -x bad.mlod -o bad.glb
rc=$?
[ ! -e bad.glb ] || exit 9
exit $rc
