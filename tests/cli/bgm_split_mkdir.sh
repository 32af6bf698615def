# --split DIR makes DIR when it is missing (the README's command) and names
# the files after the input; from stdin after -o, else "stdin".
set -e
"$BIN/mlod-bgm" -R 0.5,0.25 -s lods -o full.glb "$ROOT/samples/tubeman.glb"
test -d lods
test "$(ls lods)" = "tubeman.lod1.glb
tubeman.lod2.glb"
"$BIN/mlod-bgm" -R 0.5,0.25 -s lods2 -o named.glb < "$ROOT/samples/tubeman.glb"
test "$(ls lods2)" = "named.lod1.glb
named.lod2.glb"
cmp lods/tubeman.lod1.glb lods2/named.lod1.glb
"$BIN/mlod-bgm" -R 0.5 -s lods3 < "$ROOT/samples/tubeman.glb" > out.glb
test "$(ls lods3)" = "stdin.lod1.glb"
# An existing directory is used as it is.
"$BIN/mlod-bgm" -R 0.5,0.25 -s lods -o full.glb "$ROOT/samples/tubeman.glb"
