# A static prop (a mesh on no joint and no skin, placed by a matrix) gets
# levels too: MSFT_lod level nodes at the node's transform, without skin,
# with no more triangles level after level (fewer than the input); the report counts it; the glb
# and the split glb validate.
set -e
node "$ROOT/tests/cli/bgm_add_prop.mjs" "$ROOT/samples/RobotExpressive.glb" 2 prop.glb
"$BIN/mlod-bgm" -R 0.5,0.35,0.3 --report=json prop.glb > r.json
mkdir lods
"$BIN/mlod-bgm" -R 0.5,0.35,0.3 -s lods -o out.glb prop.glb
node "$ROOT/tests/validate.mjs" out.glb lods/prop.lod1.glb lods/prop.lod3.glb > /dev/null
node - <<'JS'
const fs = require('fs');
const glb = (f) => { const b = fs.readFileSync(f); return JSON.parse(b.subarray(20, 20 + b.readUInt32LE(12)).toString()); };
const r = JSON.parse(fs.readFileSync('r.json'));
if (r.static_primitives !== 1 || !/1 primitive\(s\) of static meshes/.test(r.notes)) throw new Error('report: ' + r.notes);
const o = glb('out.glb');
const tris = (j, mesh) => j.meshes[mesh].primitives.reduce((t, p) => t + j.accessors[p.indices].count / 3, 0);
const prop = o.nodes.find((n) => n.name === 'prop');
const ids = prop.extensions.MSFT_lod.ids;
if (ids.length !== 3) throw new Error('prop levels');
const full = tris(o, prop.mesh);
let last = full;
for (const id of ids) {
	const l = o.nodes[id], t = tris(o, l.mesh);
	if (l.skin !== undefined) throw new Error('static level with a skin');
	if (JSON.stringify(l.translation) !== '[2,0,0]' || JSON.stringify(l.scale) !== '[0.5,0.5,0.5]') throw new Error('level transform: ' + JSON.stringify(l));
	if (!(t <= last && t < full)) throw new Error(`level with ${t} triangles after ${last}`);
	last = t;
}
const s = glb('lods/prop.lod3.glb'), sp = s.nodes.find((n) => n.name === 'prop');
if (tris(s, sp.mesh) !== last || sp.matrix === undefined || sp.skin !== undefined) throw new Error('split prop');
JS
