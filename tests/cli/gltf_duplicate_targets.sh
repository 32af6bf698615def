# Two channels of one animation that target the same node and path
# (invalid glTF: the validator's ANIMATION_DUPLICATE_TARGETS) are refused
# by every tool as it reads the file, exit 2. They were accepted, and
# mlod-pack wrote a pack its own reader refuses.
node "$ROOT/tests/glb-edit.mjs" "$ROOT/samples/tubeman.glb" dup.glb \
	'const a = j.animations[0]; a.channels.push(Object.assign({}, a.channels[0]));' || exit 1
for t in label skelgraph bgm motion pack; do
	rc=0
	"$BIN/mlod-$t" -o out dup.glb || rc=$?
	[ $rc = 2 ] || exit 1
	[ ! -e out ] || exit 1
done
exit 2
