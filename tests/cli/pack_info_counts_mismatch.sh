# INFO's counts are checked against what the other chunks hold: a pack
# whose INFO says 1000 or 0 joints (SKELETON has 31), 2 instances (MESH
# has 1 part) or first_drawable 0 (the CRCs made to match) is refused by
# --info with a message naming INFO, exit 2 (a new-user probe saw them
# pass --info, -x and the runtime; the runtime's open: test_rt_edges).
"$BIN/mlod-pack" --entropy none "$ROOT/samples/tubeman.glb" -o t.mlod 2> /dev/null || exit 9
edit() { # field offset in INFO's record, value, output
	python3 "$ROOT/tests/pack-edit.py" t.mlod "$3" "
e = entry(b'INFO')
struct.pack_into('<I', x, e[7] + 4 + 16 * struct.unpack_from('<I', x, e[7])[0] + $1, $2)" || exit 9
}
edit 0 1000 j1000.mlod
edit 0 0 j0.mlod
edit 24 2 i2.mlod
edit 64 0 fd0.mlod
for f in j1000 j0 i2 fd0; do
	"$BIN/mlod-pack" --info $f.mlod > /dev/null
	[ $? = 2 ] || exit 9
done
# -x checks the same (it unpacked each)
for f in j1000 i2; do
	"$BIN/mlod-pack" -x $f.mlod -o $f.glb
	[ $? = 2 ] && [ ! -e $f.glb ] || exit 9
done
exit 2
