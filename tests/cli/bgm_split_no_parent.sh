# --split makes its directory but not its parents: a missing parent is an
# output failure that names the directory.
"$BIN/mlod-bgm" -R 0.5 -s missing/lods -o out.glb "$ROOT/samples/tubeman.glb"
