// anim-keys.mjs: writes the animation key data of a glb as it is stored
// (bench/motion.sh uses it for gltfpack's quantised output, whose rotations
// are normalised integers): per animation, each distinct sampler input
// accessor once, then the output accessors, in sampler order; the same
// layout bench_motion writes for float clips.
//
//   node bench/anim-keys.mjs in.glb out.bin
import { readFileSync, writeFileSync } from 'node:fs';

const [input, output] = process.argv.slice(2);
if (!input || !output) {
	console.error('usage: node bench/anim-keys.mjs in.glb out.bin');
	process.exit(2);
}
const b = readFileSync(input);
const jlen = b.readUInt32LE(12);
const json = JSON.parse(b.subarray(20, 20 + jlen).toString('utf8'));
const bin = b.subarray(20 + jlen + 8);
const size = { 5120: 1, 5121: 1, 5122: 2, 5123: 2, 5125: 4, 5126: 4 };
const comps = { SCALAR: 1, VEC2: 2, VEC3: 3, VEC4: 4 };
const bytes = (a) => {
	const acc = json.accessors[a], view = json.bufferViews[acc.bufferView];
	const elem = size[acc.componentType] * comps[acc.type];
	const stride = view.byteStride || elem, off = (view.byteOffset || 0) + (acc.byteOffset || 0);
	const parts = [];
	for (let i = 0; i < acc.count; i++) parts.push(bin.subarray(off + i * stride, off + i * stride + elem));
	return Buffer.concat(parts);
};
const out = [];
for (const an of json.animations || []) {
	const inputs = [];
	for (const s of an.samplers) if (!inputs.includes(s.input)) inputs.push(s.input);
	for (const i of inputs) out.push(bytes(i));
	for (const s of an.samplers) out.push(bytes(s.output));
}
writeFileSync(output, Buffer.concat(out));
