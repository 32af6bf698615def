# A failing run leaves an existing output untouched and no temporary file.
set -e
printf 'keep me' > out.glb
head -c 100 "$ROOT/samples/tubeman.glb" > bad.glb
if "$BIN/mlod-bgm" -o out.glb bad.glb 2>/dev/null; then exit 1; fi
test "$(cat out.glb)" = "keep me"
test "$(ls | grep -c tmp)" -eq 0
"$BIN/mlod-bgm" -o out.glb "$ROOT/samples/tubeman.glb"
test "$(head -c 4 out.glb)" = glTF
