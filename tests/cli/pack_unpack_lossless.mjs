// pack_unpack_lossless.mjs: the fields a pack keeps whole come back
// exactly from mlod-pack -x (the input's glb vs the unpacked glb):
// materials, textures, samplers, images (their bytes too), the scenes, and
// for each input node its name, children, transform, skin and extras; each
// input skin's joints, name and inverse bind matrices (bytes); each input
// animation's name in order.
//
//   node pack_unpack_lossless.mjs input.glb unpacked.glb
import { readFileSync } from 'node:fs';

function glb(path) {
  const b = readFileSync(path);
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

const [a, b] = process.argv.slice(2).map(glb);
// JSON with sorted keys: the writer may order an object's keys otherwise.
const canon = (v) => Array.isArray(v) ? v.map(canon)
  : v && typeof v === 'object' ? Object.fromEntries(Object.keys(v).sort().map((k) => [k, canon(v[k])])) : v;
const same = (x, y, what) => {
  if (JSON.stringify(canon(x)) !== JSON.stringify(canon(y))) throw new Error(`${what}: ${JSON.stringify(x)?.slice(0, 200)} vs ${JSON.stringify(y)?.slice(0, 200)}`);
};
// The scenes without extras.mlod: the stage record is not kept whole (the
// pack's DOC drops it; -x writes the record of what the pack stores,
// mlod-record(5) version 3).
const noRecord = (scenes) => scenes && scenes.map((sc) => {
  const c = { ...sc };
  if (c.extras) {
    c.extras = { ...c.extras };
    delete c.extras.mlod;
    if (!Object.keys(c.extras).length) delete c.extras;
  }
  return c;
});
for (const k of ['materials', 'textures', 'samplers', 'scene'])
  same(a.json[k], b.json[k], k);
same(noRecord(a.json.scenes), noRecord(b.json.scenes), 'scenes');
const imageBytes = (g, im) => {
  const v = g.json.bufferViews[im.bufferView];
  return g.bin.subarray(v.byteOffset || 0, (v.byteOffset || 0) + v.byteLength).toString('base64');
};
(a.json.images || []).forEach((im, i) => {
  const jm = b.json.images[i];
  same(im.name, jm.name, `image ${i} name`);
  same(im.mimeType, jm.mimeType, `image ${i} mimeType`);
  same(im.uri, jm.uri, `image ${i} uri`);
  if (im.bufferView !== undefined && imageBytes(a, im) !== imageBytes(b, jm)) throw new Error(`image ${i} bytes`);
});
a.json.nodes.forEach((n, i) => {
  const m = b.json.nodes[i];
  for (const k of ['name', 'children', 'translation', 'rotation', 'scale', 'matrix', 'skin', 'camera'])
    same(n[k], m[k], `node ${i} ${k}`);
  const ex = (x) => { const e = { ...(x || {}) }; delete e.MSFT_screencoverage; return e; };
  same(ex(n.extras), ex(m.extras), `node ${i} extras`);
  if ((n.mesh === undefined) !== (m.mesh === undefined)) throw new Error(`node ${i} mesh`);
});
(a.json.skins || []).forEach((s, i) => {
  same(s.joints, b.json.skins[i].joints, `skin ${i} joints`);
  same(s.name, b.json.skins[i].name, `skin ${i} name`);
  same(s.skeleton, b.json.skins[i].skeleton, `skin ${i} skeleton`);
  // the inverse bind matrices (the pack's DOC leaves them to SKEL)
  const ibm = (g, sk) => {
    if (sk.inverseBindMatrices === undefined) return 'none';
    const acc = g.json.accessors[sk.inverseBindMatrices], v = g.json.bufferViews[acc.bufferView];
    const at = (v.byteOffset || 0) + (acc.byteOffset || 0);
    return g.bin.subarray(at, at + 64 * acc.count).toString('base64');
  };
  if (ibm(a, s) !== ibm(b, b.json.skins[i])) throw new Error(`skin ${i} inverse bind matrices`);
});
same((a.json.animations || []).map((x) => x.name), (b.json.animations || []).slice(0, (a.json.animations || []).length).map((x) => x.name), 'animation names');
