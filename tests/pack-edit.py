#!/usr/bin/env python3
# pack-edit.py IN OUT CODE: runs the Python statements CODE on the pack IN
# and writes OUT with every CRC made to match again (each chunk's, the
# TOC's and the header's, mlod(5)), so that a test's hostile pack reaches
# the checks past the CRCs. The tests of the pack reader use it as
# tests/glb-edit.mjs is used for glb. CODE sees:
#   x            the pack, a bytearray, to edit in place
#   toc          the TOC entries as mutable lists, in mlod(5)'s field order:
#                [type, layer, codec, level, item, flags, coded, offset,
#                 stored, raw, crc, error, distance, reserved]
#   entry(t, level=0)   the first entry of chunk type t (b'SKEL', b'DOC ')
#                       at that level
#   stream(e, tag)      the offset in x of stream tag's bytes (b'JNTS') in
#                       entry e's stream container (codec none, no
#                       entropy stage)
#   glb(e)              the offset in x of the glb a DOC chunk holds
#   put_last(data)      replaces the last chunk's stored bytes with data
#                       (codec none, no entropy stage), its sizes and the
#                       file size following
# Struct helpers: struct, json and zlib are imported.
import json
import struct
import sys
import zlib

TOC = '<4sBBHHHIQIIIffI'
x = bytearray(open(sys.argv[1], 'rb').read())
count = struct.unpack_from('<I', x, 12)[0]
toc = [list(struct.unpack_from(TOC, x, 32 + 48 * i)) for i in range(count)]


def entry(t, level=0):
    return [e for e in toc if e[0] == t and e[3] == level][0]


def stream(e, tag):
    base = e[7]
    n = struct.unpack_from('<I', x, base)[0]
    p = base + 4 + 16 * n
    for i in range(n):
        st, _, _, _, stored = struct.unpack_from('<4sIHBxI', x, base + 4 + 16 * i)
        if st == tag:
            return p
        p += (stored + 3) & ~3
    raise KeyError(tag)


def glb(e):
    return x.index(b'glTF', e[7])


def put_last(data):
    global x
    e = toc[-1]
    del x[e[7]:]
    x += data
    e[2], e[6], e[8], e[9] = 0, 0, len(data), len(data)


exec(sys.argv[3])
for i, e in enumerate(toc):
    e[10] = zlib.crc32(bytes(x[e[7]:e[7] + e[8]]))
    struct.pack_into(TOC, x, 32 + 48 * i, *e)
struct.pack_into('<Q', x, 16, len(x))
struct.pack_into('<I', x, 24, zlib.crc32(bytes(x[32:32 + 48 * count])))
struct.pack_into('<I', x, 28, zlib.crc32(bytes(x[0:28])))
open(sys.argv[2], 'wb').write(x)
