# A pack whose DOC chunk's glb declares an accessor of 2^31 MAT4s (the
# chunk rebuilt, every CRC and offset made to match): --info and -x exit 2
# (bad input, as any tool reading that glb does) naming the DOC chunk; they
# exited 4, "the output could not be written".
"$BIN/mlod-pack" --codec none --entropy none "$ROOT/samples/tubeman.glb" -o t.mlod 2> /dev/null || exit 9
python3 "$ROOT/tests/pack-edit.py" t.mlod huge.mlod "
assert toc[-1][0] == b'DOC '
g = x[glb(toc[-1]):]
jl = struct.unpack_from('<I', g, 12)[0]
j = json.loads(g[20:20 + jl])
j['accessors'].append({'componentType': 5126, 'type': 'MAT4', 'count': 2 ** 31})
t = json.dumps(j, separators=(',', ':')).encode()
t += b' ' * (-len(t) % 4)
rest = g[20 + jl:struct.unpack_from('<I', g, 8)[0]]
g = struct.pack('<III', 0x46546C67, 2, 20 + len(t) + len(rest)) + struct.pack('<II', len(t), 0x4E4F534A) + t + rest
put_last(struct.pack('<I', 1) + struct.pack('<4sIHBBI', b'GLB ', len(g), 1, 0, 0, len(g)) + g + b'\\0' * (-len(g) % 4))" || exit 9
"$BIN/mlod-pack" -x huge.mlod -o huge.glb
x=$?
[ ! -e huge.glb ] || exit 9
"$BIN/mlod-pack" --info huge.mlod > info.txt
i=$?
[ ! -s info.txt ] || exit 9
exit $(( x == 2 && i == 2 ? 2 : 9 ))
