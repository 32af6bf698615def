// tests/cli/level-vertices.mjs [--strict] INPUT.glb LEVEL.glb...: counts the
// vertices the levels' triangles use (mlod-bgm --split glbs, the nodes'
// meshes in the input's order) that are not a vertex of the input's same
// primitive, bit for bit in every attribute and morph target offset
// (normalised integers decoded), and prints that count. With --strict it
// names the first three and exits 1 when there is any. Fewer than 1,000
// vertices checked is an error (the check would say little).
import fs from 'fs';

const args = process.argv.slice(2), strict = args[0] === '--strict';
const [input, ...levels] = strict ? args.slice(1) : args;
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
				if (known.has(S.out[Number(k)])) continue;
				if (strict && bad < 3) console.error(`${f}: mesh ${n.mesh} primitive ${pi}: vertex ${k} is not an input vertex`);
				bad++;
			}
		});
	});
}
if (checked < 1000) throw new Error(`only ${checked} vertices checked`);
if (strict && bad) {
	console.error(`${bad} of ${checked} level vertices are not input vertices`);
	process.exit(1);
}
console.log(bad);
