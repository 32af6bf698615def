# An external image outside the input's directory (../textures/x.png) is
# refused, exit 3, as such a buffer is: it was kept as a relative URI the
# written glb no longer reaches (the validator's IO_ERROR).
mkdir -p model textures
cp "$ROOT/samples/tubeman.glb" model/t.glb
node "$ROOT/tests/glb-edit.mjs" model/t.glb model/img.glb \
	'j.images = [{ uri: "../textures/red.png" }]; j.textures = [{ source: 0 }];' || exit 1
printf 'not read' > textures/red.png
rc=0
(cd model && "$BIN/mlod-label" -o ../out.glb img.glb) || rc=$?
[ $rc = 3 ] && [ ! -e out.glb ] || exit 1
rc=0
"$BIN/mlod-pack" -o out.mlod model/img.glb || rc=$?
[ $rc = 3 ] && [ ! -e out.mlod ] || exit 1
exit 3
