# KHR_draco_mesh_compression input, made by gltf-transform 4.5.1 (pinned in
# tests/node) from tubeman and RobotExpressive: edgebreaker (its default)
# goes through every stage and mlod-pack with 0 validator errors; the
# sequential method (triangles kept in order) gives positions within half
# of Draco's quantisation step (14 bits, gltf-transform's default) of the
# plain file's, joint indices equal.
set -e
gt=$ROOT/tests/node/node_modules/.bin/gltf-transform
[ -x "$gt" ] || { echo "gltf-transform is not installed in tests/node (scripts/install-deps)" >&2; exit 77; }
for s in tubeman RobotExpressive; do
	"$gt" draco "$ROOT/samples/$s.glb" $s.draco.glb > /dev/null 2>&1
	"$gt" draco --method sequential "$ROOT/samples/$s.glb" $s.seq.glb > /dev/null 2>&1
	grep -q KHR_draco_mesh_compression $s.draco.glb
	for t in label skelgraph bgm motion; do
		"$BIN/mlod-$t" -o $s.$t.glb $s.draco.glb 2> /dev/null
	done
	node "$ROOT/tests/validate.mjs" $s.label.glb $s.skelgraph.glb $s.bgm.glb $s.motion.glb > /dev/null
	! grep -q KHR_draco_mesh_compression $s.label.glb
	"$BIN/mlod-pack" -o $s.mlod $s.draco.glb 2> /dev/null
	"$BIN/mlod-pack" -x $s.mlod -o $s.x.glb
	node "$ROOT/tests/validate.mjs" $s.x.glb > /dev/null
	"$BIN/mlod-label" -o $s.seq.l.glb $s.seq.glb 2> /dev/null
	node "$ROOT/tests/cli/decoded_compare.cjs" "$ROOT/samples/$s.glb" $s.seq.l.glb --draco 14 > $s.compare.txt
done
