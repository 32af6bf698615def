# A pack with one byte flipped inside a chunk: --info and -x exit 2 with
# the reader's CRC message naming the chunk (whichever level chunk the
# byte falls in as the format's sizes change).
"$BIN/mlod-pack" "$ROOT/samples/tubeman.glb" -o t.mlod 2> /dev/null || exit 9
cp t.mlod bad.mlod
# (the middle of the file: a MESH or MOTION level, whatever the sizes)
size=$(wc -c < t.mlod | tr -d ' ')
printf '\377' | dd of=bad.mlod bs=1 seek=$((size / 2)) conv=notrunc 2> /dev/null
cmp -s t.mlod bad.mlod && exit 9
"$BIN/mlod-pack" --info bad.mlod > /dev/null
rc=$?
"$BIN/mlod-pack" -x bad.mlod -o bad.glb
rc2=$?
[ $rc = 2 ] && [ $rc2 = 2 ] && [ ! -e bad.glb ] || exit 9
exit 2
