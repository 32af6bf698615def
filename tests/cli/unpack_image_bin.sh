# A glb holds its images in the BIN chunk: mlod-pack -x of a .gltf with an
# external PNG (BoxTextured.gltf, assimp-testmodels) writes the image as a
# buffer view with its media type, the PNG's own bytes, not as a data: URI
# (the validator's DATA_URI_GLB warning): zero errors and zero warnings.
F=/usr/share/assimp/models/glTF2/BoxTextured-glTF/BoxTextured.gltf
[ -f "$F" ] || exit 77
set -e
"$BIN/mlod-pack" "$F" -o box.mlod 2> /dev/null
"$BIN/mlod-pack" -x box.mlod -o box.glb
node "$ROOT/tests/validate.mjs" box.glb > report
cat report >&2
grep -q '^box.glb: 0 errors, 0 warnings,' report
node - box.glb "$(dirname "$F")/CesiumLogoFlat.png" <<'JS'
const fs = require('fs');
const [file, png] = process.argv.slice(2);
const b = fs.readFileSync(file);
const jl = b.readUInt32LE(12);
const j = JSON.parse(b.subarray(20, 20 + jl).toString());
const bin = b.subarray(20 + jl + 8);
const im = j.images[0];
if (im.uri !== undefined || !(im.bufferView >= 0) || im.mimeType !== 'image/png')
	throw new Error(`image: ${JSON.stringify(im)}`);
const v = j.bufferViews[im.bufferView];
if (!bin.subarray(v.byteOffset || 0, (v.byteOffset || 0) + v.byteLength).equals(fs.readFileSync(png)))
	throw new Error('the image bytes are not the PNG');
JS
