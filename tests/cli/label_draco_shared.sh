# A Draco buffer view that something else also uses keeps its bytes: an
# image on the view of gltf-transform's Draco tubeman (the written glb
# validates, the image's view as long as the Draco view), and a plain
# accessor on it (read, not refused as past the end of an emptied view).
set -e
gt=$ROOT/tests/node/node_modules/.bin/gltf-transform
[ -x "$gt" ] || { echo "gltf-transform is not installed in tests/node (scripts/install-deps)" >&2; exit 77; }
"$gt" draco "$ROOT/samples/tubeman.glb" draco.glb > /dev/null 2>&1
node "$ROOT/tests/glb-edit.mjs" draco.glb image.glb '
const dv = j.meshes[0].primitives[0].extensions.KHR_draco_mesh_compression.bufferView;
j.images = (j.images || []).concat([{ bufferView: dv, mimeType: "image/png" }]);'
node "$ROOT/tests/glb-edit.mjs" draco.glb accessor.glb '
const dv = j.meshes[0].primitives[0].extensions.KHR_draco_mesh_compression.bufferView;
j.accessors.push({ bufferView: dv, byteOffset: 4, componentType: 5121, count: 16, type: "SCALAR" });'
for f in image accessor; do
	"$BIN/mlod-label" -o $f.l.glb $f.glb
	node "$ROOT/tests/validate.mjs" $f.l.glb > /dev/null
done
node -e '
const fs = require("fs");
const json = (f) => { const b = fs.readFileSync(f); return JSON.parse(b.subarray(20, 20 + b.readUInt32LE(12))); };
const a = json("image.glb"), b = json("image.l.glb");
const want = a.bufferViews[a.images[a.images.length - 1].bufferView].byteLength;
const got = b.bufferViews[b.images[b.images.length - 1].bufferView].byteLength;
if (want !== got) { console.error(`image view: ${got} bytes, not ${want}`); process.exit(1); }'
