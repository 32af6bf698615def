# A pack whose DOC chunk's glb JSON is not JSON (its first '{' made 'X',
# the CRCs made to match): --info reads the DOC's glb as -x does
# (mlod_pack_check_doc) and exits 2 with -x's message; it passed.
"$BIN/mlod-pack" --entropy none "$ROOT/samples/tubeman.glb" -o en.mlod 2> /dev/null || exit 9
python3 "$ROOT/tests/pack-edit.py" en.mlod bad.mlod "x[x.index(b'{', entry(b'DOC ')[7])] = ord('X')" || exit 9
"$BIN/mlod-pack" --info bad.mlod > /dev/null
rc=$?
"$BIN/mlod-pack" -x bad.mlod -o bad.glb
rc2=$?
[ $rc = 2 ] && [ $rc2 = 2 ] && [ ! -e bad.glb ] || exit 9
exit 2
