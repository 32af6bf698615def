# A node rotation further from unit length than the glTF validator takes
# (0.5, 0.5, 0.5, 0.6: length 1.0536) is normalised at read, with a note
# in the reports and a warning on stderr from every tool, with or without
# a report (it was in the reports only): every stage's output and
# mlod-pack -x's glb validate (each kept the input's numbers, and the
# validator's ROTATION_NON_UNIT error with them). A rotation of length 0
# has no direction: exit 2.
set -e
node "$ROOT/tests/glb-edit.mjs" "$ROOT/samples/tubeman.glb" bad.glb \
	'j.nodes[j.skins[0].joints[1]].rotation = [0.5, 0.5, 0.5, 0.6]'
node "$ROOT/tests/validate.mjs" bad.glb | grep -q 'ROTATION_NON_UNIT' || exit 9
note='# note: 1 node rotation normalised (not unit quaternions: node 1 "LHipJoint" has length 1.05357)'
"$BIN/mlod-label" --report bad.glb 2> /dev/null | grep -q -F "$note"
"$BIN/mlod-pack" --report bad.glb -o bad.mlod 2> /dev/null | grep -q -F "$note"
"$BIN/mlod-pack" -x bad.mlod -o x.glb
warning='1 node rotation normalised (not unit quaternions: node 1 "LHipJoint" has length 1.05357)'
for t in mlod-label mlod-skelgraph mlod-bgm mlod-motion mlod-pack; do
	"$BIN/$t" bad.glb -o "$t.out" 2> "$t.err"
	[ "$(cat "$t.err")" = "$t: bad.glb: $warning" ] || exit 9
	[ "$t" = mlod-pack ] || node "$ROOT/tests/validate.mjs" "$t.out" | grep -q ': 0 errors'
done
# a piped pipeline says it once: the first stage's output is repaired
"$BIN/mlod-label" < bad.glb 2> pipe.err | "$BIN/mlod-skelgraph" 2>> pipe.err | "$BIN/mlod-pack" -o pipe.mlod 2>> pipe.err
[ "$(cat pipe.err)" = "mlod-label: <stdin>: $warning" ] || exit 9
node "$ROOT/tests/validate.mjs" x.glb | grep -q ': 0 errors'
# the input's numbers are kept where the validator takes them (length 1.005)
node "$ROOT/tests/glb-edit.mjs" "$ROOT/samples/tubeman.glb" near.glb \
	'j.nodes[j.skins[0].joints[1]].rotation = [0.5025, 0.5025, 0.5025, 0.5025]'
"$BIN/mlod-label" near.glb -o near-label.glb
node "$ROOT/tests/glb-edit.mjs" near-label.glb /dev/null \
	'if (JSON.stringify(j.nodes[1].rotation) !== "[0.5025,0.5025,0.5025,0.5025]") throw new Error("changed")'
"$BIN/mlod-label" --report near.glb | grep -q -F 'normalised' && exit 9
node "$ROOT/tests/glb-edit.mjs" "$ROOT/samples/tubeman.glb" zero.glb \
	'j.nodes[j.skins[0].joints[1]].rotation = [0, 0, 0, 0]'
set +e
"$BIN/mlod-label" zero.glb -o zero-label.glb
