# A pack whose SKELETON chunk gives a joint a rest rotation that is not a
# unit quaternion (the CRCs made to match): the reader refuses it, exit 2
# naming the joint. It passed --info and -x, whose glb the validator
# rejected, and the runtime built its rest matrices from it (a component
# of -1.7e38 overflows them).
"$BIN/mlod-pack" --codec none --entropy none "$ROOT/samples/tubeman.glb" -o t.mlod 2> /dev/null || exit 9
# set.py IN OUT OFFSET VALUE: the f32 at byte OFFSET of SKELETON's JNTS
# stream set to VALUE, every CRC fixed
cat > set.py <<'PY'
import struct, sys, zlib
x = bytearray(open(sys.argv[1], 'rb').read())
o, v = int(sys.argv[3]), float(sys.argv[4])
cnt = struct.unpack_from('<I', x, 12)[0]
toc = [struct.unpack_from('<4sBBHHHIQIIIffI', x, 32 + 48 * i) for i in range(cnt)]
base = [t for t in toc if t[0] == b'SKEL' and t[3] == 0][0][7]
n = struct.unpack_from('<I', x, base)[0]
p = base + 4 + 16 * n
for i in range(n):
    st, _, _, _, stored = struct.unpack_from('<4sIHBxI', x, base + 4 + 16 * i)
    if st == b'JNTS':
        struct.pack_into('<f', x, p + o, v)
    p += (stored + 3) & ~3
for i, t in enumerate(toc):
    struct.pack_into('<I', x, 32 + 48 * i + 32, zlib.crc32(bytes(x[t[7]:t[7] + t[8]])))
struct.pack_into('<I', x, 24, zlib.crc32(bytes(x[32:32 + 48 * cnt])))
struct.pack_into('<I', x, 28, zlib.crc32(bytes(x[0:28])))
open(sys.argv[2], 'wb').write(x)
PY
# joint 1's rotation w (record of 116 bytes: parent, name, t[3], r[4] from byte 20)
python3 set.py t.mlod long.mlod $((116 + 32)) 1.5 || exit 9
python3 set.py t.mlod huge.mlod $((116 + 20)) -1.7e38 || exit 9
"$BIN/mlod-pack" --info t.mlod > /dev/null || exit 9
"$BIN/mlod-pack" -x huge.mlod -o huge.glb 2> /dev/null
[ $? = 2 ] && [ ! -e huge.glb ] || exit 9
"$BIN/mlod-pack" -x long.mlod -o long.glb
x1=$?
[ ! -e long.glb ] || exit 9
"$BIN/mlod-pack" --info long.mlod > /dev/null
exit $(( $? == 2 && x1 == 2 ? 2 : 9 ))
