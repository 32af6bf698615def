# --split writes one valid glb per level, each with fewer triangles: the
# input document with the level meshes in place (materials, textures,
# names, extras, skins and animations kept), the full meshes pruned; the
# same run gives the same bytes.
set -e
mkdir lods again
"$BIN/mlod-bgm" -s lods -R 0.5,0.2 -o out.glb "$ROOT/samples/tubeman.glb"
# One command a line: set -e does not stop at a failure inside an && list.
test -f lods/tubeman.lod1.glb
test -f lods/tubeman.lod2.glb
test ! -f lods/tubeman.lod3.glb
node "$ROOT/tests/validate.mjs" lods/tubeman.lod1.glb lods/tubeman.lod2.glb > /dev/null
"$BIN/mlod-bgm" --report=json lods/tubeman.lod2.glb > r.json
node -e 'const r = JSON.parse(require("fs").readFileSync("r.json")); if (r.triangles > Math.ceil(0.2 * 7776)) process.exit(1)'
"$BIN/mlod-bgm" -s again -R 0.5,0.2 -o out2.glb "$ROOT/samples/tubeman.glb"
cmp lods/tubeman.lod1.glb again/tubeman.lod1.glb
cmp lods/tubeman.lod2.glb again/tubeman.lod2.glb

"$BIN/mlod-bgm" -s lods -R 0.5,0.35,0.3 --report=json "$ROOT/samples/RobotExpressive.glb" > robot.json
node "$ROOT/tests/validate.mjs" lods/RobotExpressive.lod1.glb lods/RobotExpressive.lod2.glb lods/RobotExpressive.lod3.glb > /dev/null
node - "$ROOT/samples/RobotExpressive.glb" robot.json lods/RobotExpressive.lod*.glb <<'JS'
const fs = require('fs');
const [input, report, ...levels] = process.argv.slice(2);
const glb = (f) => { const b = fs.readFileSync(f); return JSON.parse(b.subarray(20, 20 + b.readUInt32LE(12)).toString()); };
const canon = (v) => Array.isArray(v) ? v.map(canon) : v && typeof v === 'object'
	? Object.fromEntries(Object.keys(v).sort().map((k) => [k, canon(v[k])])) : v;
const same = (a, b) => JSON.stringify(canon(a)) === JSON.stringify(canon(b));
const a = glb(input), r = JSON.parse(fs.readFileSync(report));
if (levels.length !== 3 || r.levels.length !== 3) throw new Error('levels: ' + levels.length);
levels.forEach((f, k) => {
	const s = glb(f);
	for (const key of ['materials', 'textures', 'images', 'samplers', 'asset'])
		if (!same(a[key], s[key])) throw new Error(`${f}: ${key} differ`);
	if (s.materials.length !== 3) throw new Error('materials');
	if (s.skins.length !== a.skins.length || s.animations.length !== a.animations.length) throw new Error(`${f}: skins or animations`);
	a.animations.forEach((an, i) => {
		if (an.name !== s.animations[i].name || an.channels.length !== s.animations[i].channels.length)
			throw new Error(`${f}: animation ${i}`);
	});
	if (!same(a.nodes.map((n) => [n.name, n.skin, n.children, n.extras]), s.nodes.map((n) => [n.name, n.skin, n.children, n.extras])))
		throw new Error(`${f}: nodes differ`);
	if (s.meshes.length !== 19) throw new Error(`${f}: ${s.meshes.length} meshes, the full ones not pruned`);
	let triangles = 0;
	for (const n of s.nodes) if (n.mesh !== undefined) {
		const m = s.meshes[n.mesh], o = a.meshes[a.nodes[s.nodes.indexOf(n)].mesh];
		if (!same(m.extras, o.extras) || m.primitives.length !== o.primitives.length) throw new Error(`${f}: mesh extras`);
		m.primitives.forEach((p, i) => {
			if (p.material !== o.primitives[i].material) throw new Error(`${f}: material of a primitive`);
			if ((n.skin === undefined) !== (p.attributes.JOINTS_0 === undefined)) throw new Error(`${f}: weights without skin`);
			triangles += s.accessors[p.indices].count / 3;
		});
	}
	if (triangles !== r.levels[k].triangles) throw new Error(`${f}: ${triangles} triangles, the report says ${r.levels[k].triangles}`);
	if (s.scenes[0].extras.mlod.mesh_level.level !== k + 1) throw new Error(`${f}: extras.mlod.mesh_level`);
	if (fs.statSync(f).size >= fs.statSync(input).size) throw new Error(`${f}: not smaller than the input`);
});
JS
