# A failing run leaves an existing output untouched and no temporary file
# (the temporary is DIR/.mlod-XXXXXX).
set -e
printf 'keep me' > out.glb
head -c 100 "$ROOT/samples/tubeman.glb" > bad.glb
if "$BIN/mlod-bgm" -o out.glb bad.glb 2>/dev/null; then exit 1; fi
test "$(cat out.glb)" = "keep me"
test "$(ls -A | grep -c "^\.mlod-")" -eq 0
# An output that is a directory is refused before anything is written and
# leaves no temporary file either.
mkdir -p taken/inside
if "$BIN/mlod-bgm" -o taken "$ROOT/samples/tubeman.glb" 2> err.txt; then exit 1; fi
grep -qx "mlod-bgm: taken: is a directory" err.txt
test -d taken/inside
test "$(ls -A | grep -c "^\.mlod-")" -eq 0
"$BIN/mlod-bgm" -o out.glb "$ROOT/samples/tubeman.glb"
test "$(head -c 4 out.glb)" = glTF
