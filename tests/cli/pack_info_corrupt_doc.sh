# A pack whose DOC chunk's glb JSON is not JSON (its first '{' made 'X',
# the CRCs made to match): --info reads the DOC's glb as -x does
# (mlod_pack_check_doc) and exits 2 with -x's message; it passed.
"$BIN/mlod-pack" --entropy none "$ROOT/samples/tubeman.glb" -o en.mlod 2> /dev/null || exit 9
python3 - en.mlod bad.mlod <<'PY' || exit 9
import struct, sys, zlib
x = bytearray(open(sys.argv[1], 'rb').read())
cnt = struct.unpack_from('<I', x, 12)[0]
toc = [struct.unpack_from('<4sBBHHHIQIIIffI', x, 32 + 48 * i) for i in range(cnt)]
for t in toc:
    if t[0] == b'DOC ':
        j = x.index(b'{', t[7])
        x[j] = ord('X')
for i, t in enumerate(toc):
    struct.pack_into('<I', x, 32 + 48 * i + 32, zlib.crc32(bytes(x[t[7]:t[7] + t[8]])))
struct.pack_into('<I', x, 24, zlib.crc32(bytes(x[32:32 + 48 * cnt])))
struct.pack_into('<I', x, 28, zlib.crc32(bytes(x[0:28])))
open(sys.argv[2], 'wb').write(x)
PY
"$BIN/mlod-pack" --info bad.mlod > /dev/null
rc=$?
"$BIN/mlod-pack" -x bad.mlod -o bad.glb
rc2=$?
[ $rc = 2 ] && [ $rc2 = 2 ] && [ ! -e bad.glb ] || exit 9
exit 2
