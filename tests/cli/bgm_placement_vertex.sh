# -p vertex: each collapse keeps one of its vertices whole, so every vertex
# of every level is a vertex of the input (level 0) with the same position,
# normal, UVs, tangent, colour, joints, weights and morph target offsets,
# bit for bit: checked on the split glbs against the input's accessors
# (the tubeman, smooth; the robot, hard normal edges and 19 primitives).
# The same check fails on the default placement's levels.
set -e
"$BIN/mlod-bgm" --report=json -p vertex "$ROOT/samples/tubeman.glb" > r.json
node -e 'const r = JSON.parse(require("fs").readFileSync("r.json")); if (r.options.placement !== "vertex" || r.levels.length < 3) process.exit(1)'
cat > check.js <<'JS'
const fs = require('fs');
const [input, ...levels] = process.argv.slice(2);
const load = (f) => {
	const b = fs.readFileSync(f), jl = b.readUInt32LE(12);
	return { j: JSON.parse(b.subarray(20, 20 + jl).toString()), bin: b.subarray(20 + jl + 8) };
};
const N = { SCALAR: 1, VEC2: 2, VEC3: 3, VEC4: 4 };
const T = { 5120: [1, 'getInt8'], 5121: [1, 'getUint8'], 5122: [2, 'getInt16'], 5123: [2, 'getUint16'], 5125: [4, 'getUint32'], 5126: [4, 'getFloat32'] };
/* An accessor's elements as strings of their stored values (normalised integers decoded). */
const read = (g, i) => {
	const a = g.j.accessors[i], v = g.j.bufferViews[a.bufferView], [sz, fn] = T[a.componentType], n = N[a.type];
	const stride = v.byteStride || sz * n, base = (v.byteOffset || 0) + (a.byteOffset || 0);
	const dv = new DataView(g.bin.buffer, g.bin.byteOffset), out = [];
	for (let k = 0; k < a.count; k++) {
		const e = [];
		for (let c = 0; c < n; c++) {
			let x = dv[fn](base + k * stride + c * sz, true);
			if (a.normalized) x = { getUint8: x / 255, getUint16: x / 65535, getInt8: Math.max(x / 127, -1), getInt16: Math.max(x / 32767, -1) }[fn];
			e.push(Math.fround(x));
		}
		out.push(e.join(','));
	}
	return out;
};
const verts = (g, p) => {
	const names = Object.keys(p.attributes).sort(), cols = names.map((n) => read(g, p.attributes[n]));
	(p.targets || []).forEach((t, ti) => Object.keys(t).sort().forEach((n) => { names.push(`t${ti}.${n}`); cols.push(read(g, t[n])); }));
	const out = [];
	for (let k = 0; k < cols[0].length; k++) out.push(cols.map((c) => c[k]).join(';'));
	return { names: names.join(' '), out };
};
const a = load(input);
let checked = 0, bad = 0;
for (const f of levels) {
	const s = load(f);
	s.j.nodes.forEach((n, ni) => {
		if (n.mesh === undefined) return;
		const m = s.j.meshes[n.mesh], o = a.j.meshes[a.j.nodes[ni].mesh];
		m.primitives.forEach((p, pi) => {
			const A = verts(a, o.primitives[pi]), S = verts(s, p);
			if (A.names !== S.names) throw new Error(`${f}: attributes ${S.names}, input ${A.names}`);
			const known = new Set(A.out);
			for (const k of new Set(read(s, p.indices))) {
				checked++;
				if (!known.has(S.out[Number(k)]) && bad++ < 3) console.error(`${f}: mesh ${n.mesh} primitive ${pi}: vertex ${k} is not an input vertex`);
			}
		});
	});
}
if (checked < 1000) throw new Error(`only ${checked} vertices checked`);
if (bad) { console.error(`${bad} of ${checked} level vertices are not input vertices`); process.exit(1); }
JS
for f in tubeman RobotExpressive; do
	mkdir "$f" "$f.default"
	"$BIN/mlod-bgm" -p vertex -s "$f" -o "$f.glb" "$ROOT/samples/$f.glb"
	test -f "$f/$f.lod3.glb"
	node check.js "$ROOT/samples/$f.glb" "$f"/*.glb
	"$BIN/mlod-bgm" -s "$f.default" -o "$f.default.glb" "$ROOT/samples/$f.glb"
	if node check.js "$ROOT/samples/$f.glb" "$f.default"/*.glb 2> /dev/null; then
		echo "$f: the default placement's levels passed: the check cannot tell" >&2
		exit 1
	fi
done
# mlod-pack takes the option too; same bytes twice.
"$BIN/mlod-pack" -p vertex -o a.mlod "$ROOT/samples/tubeman.glb"
"$BIN/mlod-pack" -p vertex -j 1 -o b.mlod "$ROOT/samples/tubeman.glb"
cmp a.mlod b.mlod
