// meshopt_zeros.mjs: writes a small glb whose four buffer views decode
// one meshopt stream (131,072 zero vertices of 8 bytes: about 17 KB
// compressed, 1 MiB decoded) under its four filters, for
// label_meshopt_amplify.sh: each view is a distinct source, so together
// they pass mlod's decoded-bytes budget (64 times the input plus 1 MiB).
//
//   node tests/cli/meshopt_zeros.mjs ROOT out.glb
import { writeFileSync } from 'node:fs';
import { createRequire } from 'node:module';
const require = createRequire(import.meta.url);
const { MeshoptEncoder } = require(process.argv[2] + '/tests/node/node_modules/meshoptimizer');
await MeshoptEncoder.ready;
const count = 131072, stride = 8;
const stream = MeshoptEncoder.encodeVertexBufferLevel(new Uint8Array(count * stride), count, stride, 2, 0);
const pad = (n) => (4 - (n % 4)) % 4;
const bin = Buffer.concat([Buffer.from(stream), Buffer.alloc(pad(stream.length))]);
const ext = (filter) => ({ buffer: 0, byteLength: stream.length, byteStride: stride, count, mode: 'ATTRIBUTES', filter });
const j = {
	asset: { version: '2.0' }, extensionsUsed: ['EXT_meshopt_compression'], extensionsRequired: ['EXT_meshopt_compression'],
	buffers: [{ byteLength: bin.length }, { byteLength: count * stride, extensions: { EXT_meshopt_compression: { fallback: true } } }],
	bufferViews: ['NONE', 'OCTAHEDRAL', 'QUATERNION', 'EXPONENTIAL'].map((f) => ({
		buffer: 1, byteLength: count * stride, byteStride: stride, extensions: { EXT_meshopt_compression: ext(f) } })),
};
let text = Buffer.from(JSON.stringify(j));
text = Buffer.concat([text, Buffer.alloc(pad(text.length), 0x20)]);
const head = Buffer.alloc(20), bh = Buffer.alloc(8);
head.writeUInt32LE(0x46546c67, 0); head.writeUInt32LE(2, 4);
head.writeUInt32LE(20 + text.length + 8 + bin.length, 8); head.writeUInt32LE(text.length, 12); head.writeUInt32LE(0x4e4f534a, 16);
bh.writeUInt32LE(bin.length, 0); bh.writeUInt32LE(0x004e4942, 4);
writeFileSync(process.argv[3], Buffer.concat([head, text, bh, bin]));
