# -o with a name of 255 bytes (NAME_MAX on most file systems): the
# temporary file it is written through (DIR/.mlod-XXXXXX) is short, so the
# name can be made, and replaced; no temporary file is left.
set -e
name=$(printf 'a%.0s' $(seq 251)).glb
"$BIN/mlod-label" -o "$name" "$ROOT/samples/cmu_12_01_walk.bvh"
test "$(head -c 4 "$name")" = glTF
"$BIN/mlod-label" -o "sub/../$name" "$ROOT/samples/cmu_12_01_walk.bvh" 2>/dev/null && exit 1
mkdir sub
"$BIN/mlod-label" -o "sub/../$name" "$ROOT/samples/cmu_12_01_walk.bvh"
test "$(head -c 4 "$name")" = glTF
test "$(ls -A | grep -c '^\.mlod-')" -eq 0
test "$(ls -A sub | wc -l)" -eq 0
