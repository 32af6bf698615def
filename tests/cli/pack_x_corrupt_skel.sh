# A pack whose SKELETON chunk names glTF nodes and skins the DOC chunk
# does not have (the CRCs made to match): --info and -x exit 2 naming the
# chunk (mlod_pack_check_doc); -x exited 1 (usage) with lib/io's
# 'skin "tubeman@lod1": joint 0 (0) has no node in the document', and
# --info, which decoded each chunk alone, passed.
"$BIN/mlod-pack" --codec none --entropy none "$ROOT/samples/tubeman.glb" -o t.mlod 2> /dev/null || exit 9
# set.py IN OUT STREAM OFFSET VALUE: SKELETON's stream STREAM, an int32
# at byte OFFSET set to VALUE, every CRC fixed
cat > set.py <<'PY'
import struct, sys, zlib
x = bytearray(open(sys.argv[1], 'rb').read())
tag, o, v = sys.argv[3].encode(), int(sys.argv[4]), int(sys.argv[5])
cnt = struct.unpack_from('<I', x, 12)[0]
toc = [struct.unpack_from('<4sBBHHHIQIIIffI', x, 32 + 48 * i) for i in range(cnt)]
base = [t for t in toc if t[0] == b'SKEL' and t[3] == 0][0][7]
n = struct.unpack_from('<I', x, base)[0]
p = base + 4 + 16 * n
for i in range(n):
    st, _, _, _, stored = struct.unpack_from('<4sIHBxI', x, base + 4 + 16 * i)
    if st == tag:
        struct.pack_into('<i', x, p + o, v)
    p += (stored + 3) & ~3
for i, t in enumerate(toc):
    struct.pack_into('<I', x, 32 + 48 * i + 32, zlib.crc32(bytes(x[t[7]:t[7] + t[8]])))
struct.pack_into('<I', x, 24, zlib.crc32(bytes(x[32:32 + 48 * cnt])))
struct.pack_into('<I', x, 28, zlib.crc32(bytes(x[0:28])))
open(sys.argv[2], 'wb').write(x)
PY
# joint 0's node (the last field of its 116-byte record), skin 0's glTF skin
python3 set.py t.mlod node.mlod JNTS 112 1000 || exit 9
python3 set.py t.mlod skin.mlod SKIN 8 7 || exit 9
"$BIN/mlod-pack" --info node.mlod > /dev/null
i1=$?
"$BIN/mlod-pack" -x node.mlod -o node.glb
x1=$?
"$BIN/mlod-pack" --info skin.mlod > /dev/null
i2=$?
"$BIN/mlod-pack" -x skin.mlod -o skin.glb
x2=$?
[ $i1 = 2 ] && [ $x1 = 2 ] && [ $i2 = 2 ] && [ $x2 = 2 ] && [ ! -e node.glb ] && [ ! -e skin.glb ] || exit 9
exit 2
