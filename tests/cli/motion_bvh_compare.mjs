// motion_bvh_compare.mjs: compares the world joint positions of two BVH
// files frame by frame, with forward kinematics written independently of
// mlod (a check on mlod's reader and writer, not a use of them).
//
//   node motion_bvh_compare.mjs a.bvh b.bvh TOL
//
// Joints and End Sites are matched by order; TOL is a fraction of the
// skeleton height as mlod-motion(1) defines it (the extent along +Y of the
// rest-pose joint origins, End Sites left out; the largest extent when
// that is under a quarter of it), computed here independently. Prints the
// largest difference as that fraction; exits 1 when it is over TOL or the
// files differ in joints or frames.
import { readFileSync } from 'node:fs';

function parse(path) {
	const tok = readFileSync(path, 'utf8').split(/\s+/).filter((s) => s.length);
	let i = 0;
	const joints = [], stack = [];
	while (tok[i] !== 'MOTION') {
		if (i >= tok.length) throw new Error(`${path}: no MOTION section`);
		const t = tok[i++];
		if (t === 'ROOT' || t === 'JOINT') {
			const parent = stack.length ? stack[stack.length - 1] : -1;
			joints.push({ parent, offset: [0, 0, 0], channels: [], end: null });
			while (tok[i] !== '{') i++; // names may hold spaces
			i++;
			stack.push(joints.length - 1);
		} else if (t === 'End') {
			i += 2; // Site {
			if (tok[i++] !== 'OFFSET') throw new Error('End Site without OFFSET');
			joints[stack[stack.length - 1]].end = [+tok[i], +tok[i + 1], +tok[i + 2]];
			i += 4; // the three numbers and '}'
		} else if (t === 'OFFSET') {
			joints[stack[stack.length - 1]].offset = [+tok[i], +tok[i + 1], +tok[i + 2]];
			i += 3;
		} else if (t === 'CHANNELS') {
			const n = +tok[i++];
			joints[stack[stack.length - 1]].channels = tok.slice(i, i + n);
			i += n;
		} else if (t === '}') {
			stack.pop();
		}
	}
	i++; // MOTION
	const frames = +tok[i + 1];
	i += 5; // Frames: n Frame Time: t
	const per = joints.reduce((s, j) => s + j.channels.length, 0);
	const values = tok.slice(i, i + frames * per).map(Number);
	return { joints, frames, per, values };
}

const mul = (a, b) => {
	const r = new Array(16).fill(0);
	for (let c = 0; c < 4; c++) for (let k = 0; k < 4; k++) for (let rr = 0; rr < 4; rr++) r[c * 4 + rr] += a[k * 4 + rr] * b[c * 4 + k];
	return r;
};
function rot(axis, deg) {
	const a = (deg * Math.PI) / 180, c = Math.cos(a), s = Math.sin(a);
	const m = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1];
	const [p, q] = axis === 0 ? [1, 2] : axis === 1 ? [2, 0] : [0, 1];
	m[p * 4 + p] = c; m[q * 4 + q] = c; m[p * 4 + q] = s; m[q * 4 + p] = -s;
	return m;
}
function points(b, f, origins = null) {
	const out = [], world = [];
	let v = f * b.per;
	for (const j of b.joints) {
		const t = j.offset.slice();
		let r = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1];
		for (const ch of j.channels) {
			const x = f < 0 ? 0 : b.values[v++], axis = 'XYZ'.indexOf(ch[0]);
			if (ch.endsWith('position')) { if (f >= 0) t[axis] = x; }
			else r = mul(r, rot(axis, x));
		}
		r[12] = t[0]; r[13] = t[1]; r[14] = t[2];
		const w = j.parent < 0 ? r : mul(world[j.parent], r);
		world.push(w);
		out.push([w[12], w[13], w[14]]);
		if (origins) origins.push([w[12], w[13], w[14]]);
		if (j.end) {
			const e = j.end;
			out.push([0, 1, 2].map((k) => w[k] * e[0] + w[4 + k] * e[1] + w[8 + k] * e[2] + w[12 + k]));
		}
	}
	return out;
}

const [pa, pb, tol] = process.argv.slice(2);
const a = parse(pa), b = parse(pb);
if (a.joints.length !== b.joints.length || a.frames !== b.frames) {
	console.log(`joints ${a.joints.length}/${b.joints.length}, frames ${a.frames}/${b.frames}`);
	process.exit(1);
}
const origins = [];
points(a, -1, origins);
const extent = (k) => Math.max(...origins.map((p) => p[k])) - Math.min(...origins.map((p) => p[k]));
const largest = Math.max(extent(0), extent(1), extent(2));
const size = extent(1) >= 0.25 * largest ? extent(1) : largest > 0 ? largest : 1;
let worst = 0;
for (let f = 0; f < a.frames; f++) {
	const x = points(a, f), y = points(b, f);
	for (let p = 0; p < x.length; p++) worst = Math.max(worst, Math.hypot(x[p][0] - y[p][0], x[p][1] - y[p][1], x[p][2] - y[p][2]));
}
console.log((worst / size).toExponential(3));
process.exit(worst / size <= +tol ? 0 : 1);
