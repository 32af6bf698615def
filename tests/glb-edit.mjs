// glb-edit.mjs: writes a copy of a glb with its JSON changed, for tests
// that need a crafted input.
//
//   node tests/glb-edit.mjs in.glb out.glb 'BODY'
//
// BODY is JavaScript run with `j`, the parsed JSON chunk, to change in
// place, and `bin`, the BIN chunk's bytes (a Buffer; empty without one),
// whose bytes may be changed in place (not its length).
import { readFileSync, writeFileSync } from 'node:fs';

const [src, dst, body] = process.argv.slice(2);
const b = readFileSync(src);
if (b.readUInt32LE(0) !== 0x46546c67) throw new Error(`${src}: not a glb`);
const jl = b.readUInt32LE(12);
const j = JSON.parse(b.subarray(20, 20 + jl).toString('utf8'));
const binStart = 20 + jl + 8 <= b.length ? 20 + jl + 8 : b.length;
new Function('j', 'bin', body)(j, b.subarray(binStart));
let text = Buffer.from(JSON.stringify(j));
text = Buffer.concat([text, Buffer.alloc((4 - (text.length % 4)) % 4, 0x20)]);
const bin = b.subarray(20 + jl), head = Buffer.alloc(20);
head.writeUInt32LE(0x46546c67, 0);
head.writeUInt32LE(2, 4);
head.writeUInt32LE(20 + text.length + bin.length, 8);
head.writeUInt32LE(text.length, 12);
head.writeUInt32LE(0x4e4f534a, 16);
writeFileSync(dst, Buffer.concat([head, text, bin]));
