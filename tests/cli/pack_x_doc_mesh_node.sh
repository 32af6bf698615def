# A pack whose DOC chunk points a node that has no MESH part (joint node
# 3) at mesh 0, whose triangles the DOC lost to the MESH chunks: -x
# exits 2 naming the DOC chunk and writes nothing. It wrote a glb the
# validator refuses (EMPTY_ENTITY: a primitive without attributes) and
# exited 0. The DOC's glb JSON is edited in place, the same length (the
# asset's generator goes), the CRCs made to match.
"$BIN/mlod-pack" --codec none --entropy none "$ROOT/samples/tubeman.glb" -o plain.mlod 2> /dev/null || exit 9
python3 "$ROOT/tests/pack-edit.py" plain.mlod bad.mlod "
g = glb(entry(b'DOC '))
n = struct.unpack_from('<I', x, g + 12)[0]
j = json.loads(bytes(x[g + 20:g + 20 + n]))
assert 'mesh' not in j['nodes'][3] and 'generator' in j['asset']
j['nodes'][3]['mesh'] = 0
del j['asset']['generator']
text = json.dumps(j, separators=(',', ':')).encode()
assert len(text) <= n, (len(text), n)
x[g + 20:g + 20 + n] = text + b' ' * (n - len(text))" || exit 9
"$BIN/mlod-pack" -x bad.mlod -o bad.glb
rc=$?
[ ! -e bad.glb ] || exit 9
exit $rc
