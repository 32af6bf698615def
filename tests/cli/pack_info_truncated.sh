# A truncated pack: --info and -x exit 2 naming the chunk cut short.
"$BIN/mlod-pack" "$ROOT/samples/tubeman.glb" -o t.mlod 2> /dev/null || exit 9
head -c 20000 t.mlod > cut.mlod
"$BIN/mlod-pack" --info cut.mlod > /dev/null
rc=$?
"$BIN/mlod-pack" -x cut.mlod -o cut.glb
rc2=$?
[ $rc = 2 ] && [ $rc2 = 2 ] && [ ! -e cut.glb ] || exit 9
exit 2
