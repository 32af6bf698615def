# A pack whose SKELETON chunk gives a joint a rest rotation that is not a
# unit quaternion (the CRCs made to match): the reader refuses it, exit 2
# naming the joint. It passed --info and -x, whose glb the validator
# rejected, and the runtime built its rest matrices from it (a component
# of -1.7e38 overflows them).
"$BIN/mlod-pack" --codec none --entropy none "$ROOT/samples/tubeman.glb" -o t.mlod 2> /dev/null || exit 9
# set IN OUT OFFSET VALUE: the f32 at byte OFFSET of SKELETON's JNTS
# stream set to VALUE, every CRC fixed
set_f32() {
	python3 "$ROOT/tests/pack-edit.py" "$1" "$2" \
		"struct.pack_into('<f', x, stream(entry(b'SKEL'), b'JNTS') + $3, $4)"
}
# joint 1's rotation w (record of 116 bytes: parent, name, t[3], r[4] from byte 20)
set_f32 t.mlod long.mlod $((116 + 32)) 1.5 || exit 9
set_f32 t.mlod huge.mlod $((116 + 20)) -1.7e38 || exit 9
"$BIN/mlod-pack" --info t.mlod > /dev/null || exit 9
"$BIN/mlod-pack" -x huge.mlod -o huge.glb 2> /dev/null
[ $? = 2 ] && [ ! -e huge.glb ] || exit 9
"$BIN/mlod-pack" -x long.mlod -o long.glb
x1=$?
[ ! -e long.glb ] || exit 9
"$BIN/mlod-pack" --info long.mlod > /dev/null
exit $(( $? == 2 && x1 == 2 ? 2 : 9 ))
