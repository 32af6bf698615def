# A pack given where a character is read is pointed to --info and -x (it
# was "not a glTF, glb or BVH file"); --info and -x with no pack on a
# terminal say a pack, not a glb, glTF or BVH.
"$BIN/mlod-pack" -o w.mlod "$ROOT/samples/cmu_12_01_walk.bvh" || exit 99
"$BIN/mlod-bgm" w.mlod > /dev/null && exit 9
command -v script > /dev/null || { echo "script(1) is missing" >&2; exit 127; }
script -qec "\"$BIN/mlod-pack\" --info -" /dev/null > tty.txt
tr -d '\r' < tty.txt >&2
"$BIN/mlod-pack" w.mlod > /dev/null
