# A pack whose SKELETON chunk names glTF nodes and skins the DOC chunk
# does not have (the CRCs made to match): --info and -x exit 2 naming the
# chunk (mlod_pack_check_doc); -x exited 1 (usage) with lib/io's
# 'skin "tubeman@lod1": joint 0 (0) has no node in the document', and
# --info, which decoded each chunk alone, passed.
"$BIN/mlod-pack" --codec none --entropy none "$ROOT/samples/tubeman.glb" -o t.mlod 2> /dev/null || exit 9
# set_i32 IN OUT STREAM OFFSET VALUE: SKELETON's stream STREAM, an int32
# at byte OFFSET set to VALUE, every CRC fixed
set_i32() {
	python3 "$ROOT/tests/pack-edit.py" "$1" "$2" \
		"struct.pack_into('<i', x, stream(entry(b'SKEL'), b'$3') + $4, $5)"
}
# joint 0's node (the last field of its 116-byte record), skin 0's glTF skin
set_i32 t.mlod node.mlod JNTS 112 1000 || exit 9
set_i32 t.mlod skin.mlod SKIN 8 7 || exit 9
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
