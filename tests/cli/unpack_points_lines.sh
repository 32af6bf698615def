# mlod-pack -x keeps points and lines (and strips and fans), which the
# pack's levels do not hold, through the document chunk: the unpacked
# glb of Mesh_PrimitiveMode_01 (lines), _07 (indexed points) and _11
# (indexed strip) validates with zero errors and keeps the primitive's
# mode and POSITION; a mesh of a triangle list and a line list keeps both.
M=/usr/share/assimp/models/glTF2/glTF-Asset-Generator/Mesh_PrimitiveMode
[ -f "$M/Mesh_PrimitiveMode_01.gltf" ] || exit 77
set -e
cp "$M/Mesh_PrimitiveMode_06.gltf" "$M/Mesh_PrimitiveMode_06.bin" .
node - <<'JS'
const fs = require('fs');
const d = JSON.parse(fs.readFileSync('Mesh_PrimitiveMode_06.gltf'));
const p = Object.assign({}, d.meshes[0].primitives[0], { mode: 1 });
delete p.indices;
d.meshes[0].primitives.push(p);
fs.writeFileSync('mixed.gltf', JSON.stringify(d));
JS
for f in "$M/Mesh_PrimitiveMode_01.gltf" "$M/Mesh_PrimitiveMode_07.gltf" "$M/Mesh_PrimitiveMode_11.gltf" mixed.gltf; do
	n=$(basename "$f" .gltf)
	"$BIN/mlod-pack" "$f" -o "$n.mlod" 2> /dev/null
	"$BIN/mlod-pack" -x "$n.mlod" -o "$n.x.glb"
	node "$ROOT/tests/validate.mjs" "$n.x.glb" >&2
	node - "$f" "$n.x.glb" <<'JS'
const fs = require('fs');
const [input, file] = process.argv.slice(2);
const b = fs.readFileSync(file);
const out = JSON.parse(b.subarray(20, 20 + b.readUInt32LE(12)).toString());
const inp = JSON.parse(fs.readFileSync(input));
const modes = j => j.meshes.flatMap(m => m.primitives.map(p => p.mode ?? 4)).sort().join(',');
if (modes(out) !== modes(inp)) throw new Error(`${file}: modes ${modes(out)}, input ${modes(inp)}`);
for (const m of out.meshes)
	for (const p of m.primitives)
		if (!(p.attributes.POSITION >= 0)) throw new Error(`${file}: a primitive without POSITION`);
JS
done
