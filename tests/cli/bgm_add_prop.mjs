// bgm_add_prop.mjs: writes a copy of a glb with one more root node, a
// static prop (no skin, under no joint) showing mesh MESH through a
// matrix (scale 0.5, translation 2 0 0), for the static-mesh tests.
//
//   node bgm_add_prop.mjs in.glb MESH out.glb
import { readFileSync, writeFileSync } from 'node:fs';

const [input, mesh, output] = process.argv.slice(2);
const b = readFileSync(input);
const jsonLength = b.readUInt32LE(12);
const j = JSON.parse(b.subarray(20, 20 + jsonLength).toString('utf8'));
const rest = b.subarray(20 + jsonLength);
j.nodes.push({ name: 'prop', mesh: Number(mesh), matrix: [0.5, 0, 0, 0, 0, 0.5, 0, 0, 0, 0, 0.5, 0, 2, 0, 0, 1] });
j.scenes[j.scene || 0].nodes.push(j.nodes.length - 1);
let text = Buffer.from(JSON.stringify(j), 'utf8');
text = Buffer.concat([text, Buffer.alloc((4 - (text.length % 4)) % 4, 0x20)]);
const head = Buffer.alloc(20);
head.writeUInt32LE(0x46546c67, 0);
head.writeUInt32LE(2, 4);
head.writeUInt32LE(20 + text.length + rest.length, 8);
head.writeUInt32LE(text.length, 12);
head.writeUInt32LE(0x4e4f534a, 16);
writeFileSync(output, Buffer.concat([head, text, rest]));
