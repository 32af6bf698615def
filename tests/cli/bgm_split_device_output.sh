# --split names its files after the input, from stdin after -o's file: a
# regular or new file's name, not a device's (-o /dev/null made
# null.lod1.glb) nor standard output's.
set -e
mkdir lods
"$BIN/mlod-bgm" -s lods -R 0.5 -o /dev/null < "$ROOT/samples/tubeman.glb"
"$BIN/mlod-bgm" -s lods -R 0.5 -o /dev/stdout < "$ROOT/samples/tubeman.glb" > out.glb
test "$(ls lods)" = stdin.lod1.glb
"$BIN/mlod-bgm" -s lods -R 0.5 -o named.glb < "$ROOT/samples/tubeman.glb"
test -f lods/named.lod1.glb
