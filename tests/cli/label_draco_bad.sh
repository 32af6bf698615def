# Draco input that does not decode: a Draco buffer view cut in half, one
# whose bytes are garbled (not Draco), and a POSITION accessor whose count
# differs from the Draco mesh's points: each exit 2 with its message.
gt=$ROOT/tests/node/node_modules/.bin/gltf-transform
[ -x "$gt" ] || { echo "gltf-transform is not installed in tests/node (scripts/install-deps)" >&2; exit 77; }
"$gt" draco "$ROOT/samples/tubeman.glb" draco.glb > /dev/null 2>&1 || exit 1
node "$ROOT/tests/glb-edit.mjs" draco.glb cut.glb '
const v = j.bufferViews[j.meshes[0].primitives[0].extensions.KHR_draco_mesh_compression.bufferView];
v.byteLength = v.byteLength >> 1' || exit 1
node "$ROOT/tests/glb-edit.mjs" draco.glb garbled.glb '
const v = j.bufferViews[j.meshes[0].primitives[0].extensions.KHR_draco_mesh_compression.bufferView];
bin.fill(0x55, v.byteOffset || 0, (v.byteOffset || 0) + 64)' || exit 1
node "$ROOT/tests/glb-edit.mjs" draco.glb count.glb 'j.accessors[j.meshes[0].primitives[0].attributes.POSITION].count -= 1' || exit 1
for f in cut garbled count; do
	"$BIN/mlod-label" $f.glb
	echo "exit $?" >&2
done
exit 2
