// gltf-same.mjs: checks that two glb files hold the same glTF document.
//
//   node tests/gltf-same.mjs [--ignore-extras KEY] a.glb b.glb
//
// The JSON must be equal after dropping the extras key KEY everywhere and
// the asset's generator; each accessor must hold the same bytes, and each
// bufferView-backed image the same bytes, even if buffers were re-laid out.
// Prints the first difference and exits 1 when they differ.
import { readFileSync } from 'node:fs';

function parseGlb(path) {
  const b = readFileSync(path);
  if (b.readUInt32LE(0) !== 0x46546c67) throw new Error(`${path}: not a glb`);
  let off = 12, json = null, bin = Buffer.alloc(0);
  while (off + 8 <= b.length) {
    const len = b.readUInt32LE(off), type = b.readUInt32LE(off + 4);
    const chunk = b.subarray(off + 8, off + 8 + len);
    if (type === 0x4e4f534a) json = JSON.parse(chunk.toString('utf8'));
    else if (type === 0x004e4942) bin = chunk;
    off += 8 + len;
  }
  return { json, bin };
}

function strip(v, key) {
  if (Array.isArray(v)) return v.map((x) => strip(x, key));
  if (v && typeof v === 'object') {
    const out = {};
    for (const [k, x] of Object.entries(v)) {
      if (k === 'extras' && x && typeof x === 'object') {
        const e = strip(x, key);
        delete e[key];
        if (Object.keys(e).length) out[k] = e;
      } else out[k] = strip(x, key);
    }
    return out;
  }
  return v;
}

// The bytes of a bufferView (only the GLB-embedded buffer 0 is supported).
function viewBytes(doc, bin, i) {
  const v = doc.bufferViews[i];
  return bin.subarray(v.byteOffset || 0, (v.byteOffset || 0) + v.byteLength);
}

const SIZE = { SCALAR: 1, VEC2: 2, VEC3: 3, VEC4: 4, MAT2: 4, MAT3: 9, MAT4: 16 };
const BYTES = { 5120: 1, 5121: 1, 5122: 2, 5123: 2, 5125: 4, 5126: 4 };

// The elements of an accessor, packed (independent of stride and offset).
function accessorBytes(doc, bin, a) {
  if (a.bufferView === undefined) return Buffer.alloc(0);
  const view = doc.bufferViews[a.bufferView];
  const elem = SIZE[a.type] * BYTES[a.componentType];
  const stride = view.byteStride || elem;
  const src = viewBytes(doc, bin, a.bufferView);
  const out = Buffer.alloc(a.count * elem);
  for (let i = 0; i < a.count; i++) src.copy(out, i * elem, (a.byteOffset || 0) + i * stride, (a.byteOffset || 0) + i * stride + elem);
  return out;
}

const args = process.argv.slice(2);
let ignore = null;
if (args[0] === '--ignore-extras') { ignore = args[1]; args.splice(0, 2); }
const [pa, pb] = args;
const A = parseGlb(pa), B = parseGlb(pb);
const fail = (msg) => { console.error(`gltf-same: ${msg}`); process.exit(1); };

const ja = strip(A.json, ignore), jb = strip(B.json, ignore);
for (const j of [ja, jb]) { delete j.asset.generator; delete j.buffers; delete j.bufferViews; }
for (const j of [ja, jb]) for (const a of j.accessors || []) { delete a.bufferView; delete a.byteOffset; }
for (const j of [ja, jb]) for (const im of j.images || []) delete im.bufferView;

function compare(x, y, path) {
  if (typeof x !== typeof y || Array.isArray(x) !== Array.isArray(y)) fail(`${path}: ${JSON.stringify(x)} != ${JSON.stringify(y)}`);
  if (x && typeof x === 'object') {
    const keys = new Set([...Object.keys(x), ...Object.keys(y)]);
    for (const k of keys) {
      if (!(k in x) || !(k in y)) fail(`${path}.${k}: present in only one file`);
      compare(x[k], y[k], `${path}.${k}`);
    }
  } else if (x !== y) fail(`${path}: ${JSON.stringify(x)} != ${JSON.stringify(y)}`);
}
compare(ja, jb, '$');

(A.json.accessors || []).forEach((a, i) => {
  if (!accessorBytes(A.json, A.bin, a).equals(accessorBytes(B.json, B.bin, B.json.accessors[i]))) fail(`accessors[${i}]: data differs`);
});
(A.json.images || []).forEach((im, i) => {
  const other = B.json.images[i];
  if (im.bufferView !== undefined && !viewBytes(A.json, A.bin, im.bufferView).equals(viewBytes(B.json, B.bin, other.bufferView))) fail(`images[${i}]: data differs`);
});
