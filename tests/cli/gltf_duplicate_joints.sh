# A skin that lists one node twice (invalid glTF: the validator's
# DUPLICATE_ELEMENTS) is refused by every tool as it reads the file, exit
# 2. It was accepted, and the stages' level skins repeated the duplicate
# (their glbs failed the validator).
node "$ROOT/tests/glb-edit.mjs" "$ROOT/samples/tubeman.glb" dup.glb \
	'j.skins[0].joints.push(j.skins[0].joints[5]);' || exit 1
for t in label skelgraph bgm motion pack; do
	rc=0
	"$BIN/mlod-$t" -o out dup.glb || rc=$?
	[ $rc = 2 ] || exit 1
	[ ! -e out ] || exit 1
done
exit 2
