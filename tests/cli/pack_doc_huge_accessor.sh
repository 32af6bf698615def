# A pack whose DOC chunk's glb declares an accessor of 2^31 MAT4s (the
# chunk rebuilt, every CRC and offset made to match): --info and -x exit 2
# (bad input, as any tool reading that glb does) naming the DOC chunk; they
# exited 4, "the output could not be written".
"$BIN/mlod-pack" --codec none --entropy none "$ROOT/samples/tubeman.glb" -o t.mlod 2> /dev/null || exit 9
python3 - t.mlod huge.mlod <<'PY' || exit 9
import json, struct, sys, zlib
b = open(sys.argv[1], 'rb').read()
TOC = '<4sBBHHHIQIIIffI'
magic, maj, mino, flags, cnt, fsize, _ = struct.unpack_from('<4sHHIIQI', b, 0)
toc = [list(struct.unpack_from(TOC, b, 32 + 48 * i)) for i in range(cnt)]
d = [i for i, e in enumerate(toc) if e[0] == b'DOC '][0]
assert d == cnt - 1
c = b[toc[d][7]:toc[d][7] + toc[d][8]]
n = struct.unpack_from('<I', c, 8)[0]   # the container's one stream: the glb
g = c[20:20 + n]
jl = struct.unpack_from('<I', g, 12)[0]
j = json.loads(g[20:20 + jl])
j['accessors'].append({'componentType': 5126, 'type': 'MAT4', 'count': 2 ** 31})
t = json.dumps(j, separators=(',', ':')).encode()
t += b' ' * (-len(t) % 4)
rest = g[20 + jl:]
g = struct.pack('<III', 0x46546C67, 2, 20 + len(t) + len(rest)) + struct.pack('<II', len(t), 0x4E4F534A) + t + rest
c = struct.pack('<I', 1) + struct.pack('<4sIHBBI', b'GLB ', len(g), 1, 0, 0, len(g)) + g + b'\0' * (-len(g) % 4)
e = toc[d]
e[6], e[8], e[9], e[10] = 0, len(c), len(c), zlib.crc32(c)
tocb = b''.join(struct.pack(TOC, *x) for x in toc)
hdr = struct.pack('<4sHHIIQI', magic, maj, mino, flags, cnt, e[7] + len(c), zlib.crc32(tocb))
out = hdr + struct.pack('<I', zlib.crc32(hdr)) + tocb + b[32 + 48 * cnt:e[7]] + c
open(sys.argv[2], 'wb').write(out)
PY
"$BIN/mlod-pack" -x huge.mlod -o huge.glb
x=$?
[ ! -e huge.glb ] || exit 9
"$BIN/mlod-pack" --info huge.mlod > info.txt
i=$?
[ ! -s info.txt ] || exit 9
exit $(( x == 2 && i == 2 ? 2 : 9 ))
