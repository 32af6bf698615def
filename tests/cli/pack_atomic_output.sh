# A failing run leaves an existing output untouched and no temporary file.
set -e
printf 'keep me' > out.mlod
head -c 100 "$ROOT/samples/tubeman.glb" > bad.glb
if "$BIN/mlod-pack" -o out.mlod bad.glb 2>/dev/null; then exit 1; fi
test "$(cat out.mlod)" = "keep me"
test "$(ls | grep -c tmp)" -eq 0
