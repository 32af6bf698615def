# A failing run leaves an existing output untouched and no temporary file
# (the temporary is DIR/.mlod-XXXXXX).
set -e
printf 'keep me' > out.glb
: > empty.bvh
if "$BIN/mlod-label" -o out.glb empty.bvh 2>/dev/null; then exit 1; fi
test "$(cat out.glb)" = "keep me"
test "$(ls -A | grep -c "^\.mlod-")" -eq 0
# An output that is a directory is refused before anything is written and
# leaves no temporary file either.
mkdir -p taken/inside
if "$BIN/mlod-label" -o taken "$ROOT/samples/cmu_12_01_walk.bvh" 2> err.txt; then exit 1; fi
grep -qx 'mlod-label: taken: is a directory' err.txt
test -d taken/inside
test "$(ls -A | grep -c "^\.mlod-")" -eq 0
# A good run replaces it.
"$BIN/mlod-label" -o out.glb "$ROOT/samples/cmu_12_01_walk.bvh"
test "$(head -c 4 out.glb)" = glTF
