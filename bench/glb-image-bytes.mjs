// glb-image-bytes.mjs: prints the bytes a glb spends on images (the buffer
// views its images use, and the bytes of data: or external image URIs it
// embeds), so bench/pack.sh can give sizes with and without textures.
//
//   node bench/glb-image-bytes.mjs in.glb
import { readFileSync } from 'node:fs';

const input = process.argv[2];
if (!input) {
	console.error('usage: node bench/glb-image-bytes.mjs in.glb');
	process.exit(2);
}
const b = readFileSync(input);
if (b.toString('latin1', 0, 4) !== 'glTF') {
	console.error(`glb-image-bytes: ${input}: not a glb`);
	process.exit(2);
}
const json = JSON.parse(b.subarray(20, 20 + b.readUInt32LE(12)).toString('utf8'));
let total = 0;
const views = new Set();
for (const img of json.images || []) {
	if (img.bufferView !== undefined) views.add(img.bufferView);
	else if (img.uri && img.uri.startsWith('data:')) total += img.uri.length;
}
for (const v of views) total += json.bufferViews[v].byteLength;
console.log(total);
