# Bytes after a pack's end (its header's file size) are covered by no CRC:
# -x refuses them as --info does, exit 2 naming the count and the end
# (mlod_pack_check_padding), and writes no glb.
"$BIN/mlod-pack" "$ROOT/samples/cmu_12_01_walk.bvh" -o w.mlod 2> /dev/null || exit 9
"$BIN/mlod-pack" -x w.mlod -o ok.glb 2> /dev/null || exit 9
size=$(wc -c < w.mlod | tr -d ' ')
printf 'X' >> w.mlod
"$BIN/mlod-pack" --info w.mlod > /dev/null
rc=$?
"$BIN/mlod-pack" -x w.mlod -o bad.glb
rc2=$?
[ $rc = 2 ] && [ $rc2 = 2 ] && [ ! -e bad.glb ] || exit 9
exit 2
