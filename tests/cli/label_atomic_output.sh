# A failing run leaves an existing output untouched and no temporary file.
set -e
printf 'keep me' > out.glb
: > empty.bvh
if "$BIN/mlod-label" -o out.glb empty.bvh 2>/dev/null; then exit 1; fi
test "$(cat out.glb)" = "keep me"
test "$(ls | grep -c tmp)" -eq 0
# A good run replaces it.
"$BIN/mlod-label" -o out.glb "$ROOT/samples/cmu_12_01_walk.bvh"
test "$(head -c 4 out.glb)" = glTF
