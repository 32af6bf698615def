// decoded_compare.cjs: compares the mesh data of two glb, primitive by
// primitive and attribute by attribute (accessors found through the
// meshes, so the files may order their accessors differently).
//
//   node decoded_compare.cjs plain.glb decoded.glb [--draco POSITION_BITS]
//
// Without --draco every attribute and morph target must be equal, and the
// indices the same triangles, each maybe rotated (meshopt's index codec
// rotates a triangle's corners, keeping its winding). With --draco (a
// sequential-method Draco file: the triangles and their corners keep their
// order, the vertices are renumbered) vertices are paired through the
// triangles' corners; JOINTS_* must be equal and each POSITION within half
// a quantisation step of its pair's: step = the largest extent of the
// primitive's positions / (2^bits - 1). Prints one line per attribute with its largest difference (and, for
// POSITION, that difference in steps); exits 1 on a failed check.
const fs = require('fs');
function load(f) {
	const b = fs.readFileSync(f), jl = b.readUInt32LE(12);
	return { j: JSON.parse(b.subarray(20, 20 + jl).toString()), bin: b.subarray(28 + jl) };
}
const CT = { 5120: [1, 'getInt8'], 5121: [1, 'getUint8'], 5122: [2, 'getInt16'], 5123: [2, 'getUint16'], 5125: [4, 'getUint32'], 5126: [4, 'getFloat32'] };
const NC = { SCALAR: 1, VEC2: 2, VEC3: 3, VEC4: 4, MAT4: 16 };
function values(d, i) {
	const a = d.j.accessors[i], [cs, get] = CT[a.componentType], n = NC[a.type];
	const out = new Float64Array(a.count * n);
	if (a.bufferView === undefined) return { out, n };
	const v = d.j.bufferViews[a.bufferView], stride = v.byteStride || cs * n;
	const dv = new DataView(d.bin.buffer, d.bin.byteOffset + (v.byteOffset || 0) + (a.byteOffset || 0));
	for (let e = 0; e < a.count; e++) for (let c = 0; c < n; c++) out[e * n + c] = dv[get](e * stride + c * cs, true);
	return { out, n };
}
function triangles(x) {
	const t = [];
	for (let k = 0; k + 2 < x.length; k += 3) {
		const r = [x[k], x[k + 1], x[k + 2]], m = r.indexOf(Math.min(...r));
		t.push([r[m], r[(m + 1) % 3], r[(m + 2) % 3]].join(','));
	}
	return t.join(';');
}
const [fa, fb, flag, bits] = process.argv.slice(2);
const draco = flag === '--draco';
const a = load(fa), b = load(fb);
let failed = 0;
a.j.meshes.forEach((mesh, m) => mesh.primitives.forEach((pa, p) => {
	const pb = b.j.meshes[m].primitives[p], at = `mesh ${m} primitive ${p}`;
	let pairs = null; /* [plain vertex, decoded vertex] */
	if (pa.indices !== undefined) {
		const x = values(a, pa.indices).out, y = values(b, pb.indices).out;
		if (draco) {
			if (x.length !== y.length) { failed++; console.log(`${at}: ${x.length} indices, ${y.length}`); return; }
			const seen = new Set();
			pairs = [];
			for (let k = 0; k < x.length; k++)
				if (!seen.has(x[k] + ',' + y[k])) seen.add(x[k] + ',' + y[k]), pairs.push([x[k], y[k]]);
		} else if (triangles(x) !== triangles(y)) {
			failed++;
			console.log(`${at} indices differ`);
		}
	}
	const sets = [[pa.attributes, pb.attributes, '']].concat((pa.targets || []).map((t, k) => [t, pb.targets[k], `target ${k} `]));
	for (const [sa, sb, prefix] of sets) for (const name of Object.keys(sa)) {
		const { out: x, n } = values(a, sa[name]), y = values(b, sb[name]).out;
		if (x.length !== y.length) { failed++; console.log(`${at} ${prefix}${name}: ${x.length} values, ${y.length}`); continue; }
		let d = 0;
		if (pairs && !prefix)
			for (const [u, w] of pairs) for (let c = 0; c < n; c++) d = Math.max(d, Math.abs(x[u * n + c] - y[w * n + c]));
		else
			for (let k = 0; k < x.length; k++) d = Math.max(d, Math.abs(x[k] - y[k]));
		let line = `${at} ${prefix}${name}: max difference ${d.toPrecision(4)}`;
		if (!draco || prefix || name.startsWith('JOINTS_')) {
			if (d !== 0) failed++, line += ' (must be 0)';
		} else if (name === 'POSITION') {
			let extent = 0;
			for (let c = 0; c < n; c++) {
				let lo = Infinity, hi = -Infinity;
				for (let k = c; k < x.length; k += n) lo = Math.min(lo, x[k]), hi = Math.max(hi, x[k]);
				extent = Math.max(extent, hi - lo);
			}
			const step = extent / (2 ** Number(bits) - 1);
			line += ` = ${(d / step).toFixed(4)} steps of ${step.toPrecision(4)}`;
			if (d > step / 2 * (1 + 1e-3)) failed++, line += ' (more than half a step)';
		}
		console.log(line);
	}
}));
process.exit(failed ? 1 : 0);
