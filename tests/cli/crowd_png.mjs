// tests/cli/crowd_png.mjs FILE W H LEVELS: checks that FILE is a PNG of W x H
// pixels (8-bit RGB, as bench/crowd writes it) and prints, for each of the
// first LEVELS mesh level colours of bench/crowd, how many pixels above the
// legend strip (the bottom 32 rows) have that hue: the characters, shaded.
// Decodes with node's zlib (inflate) and the five PNG row filters.
import { readFileSync } from 'node:fs';
import { inflateSync } from 'node:zlib';

const [file, W, H, LEVELS] = process.argv.slice(2);
const b = readFileSync(file);
const fail = (m) => { console.error(`crowd_png.mjs: ${file}: ${m}`); process.exit(1); };
if (!b.subarray(0, 8).equals(Buffer.from([137, 80, 78, 71, 13, 10, 26, 10]))) fail('no PNG signature');
let off = 8, w = 0, h = 0;
const idat = [];
while (off + 8 <= b.length) {
  const len = b.readUInt32BE(off), type = b.toString('latin1', off + 4, off + 8);
  const data = b.subarray(off + 8, off + 8 + len);
  if (type === 'IHDR') {
    w = data.readUInt32BE(0); h = data.readUInt32BE(4);
    if (data[8] !== 8 || data[9] !== 2 || data[12] !== 0) fail('not 8-bit RGB, non-interlaced');
  } else if (type === 'IDAT') idat.push(data);
  else if (type === 'IEND') break;
  off += 12 + len;
}
if (w !== Number(W) || h !== Number(H)) fail(`size ${w}x${h}, expected ${W}x${H}`);
const raw = inflateSync(Buffer.concat(idat));
if (raw.length !== h * (1 + 3 * w)) fail(`${raw.length} bytes of pixel data, expected ${h * (1 + 3 * w)}`);
const px = Buffer.alloc(w * h * 3), stride = 3 * w;
for (let y = 0; y < h; y++) {
  const f = raw[y * (stride + 1)], row = raw.subarray(y * (stride + 1) + 1, (y + 1) * (stride + 1));
  for (let x = 0; x < stride; x++) {
    const a = x >= 3 ? px[y * stride + x - 3] : 0, up = y ? px[(y - 1) * stride + x] : 0;
    const c = x >= 3 && y ? px[(y - 1) * stride + x - 3] : 0;
    let p;
    switch (f) {
      case 0: p = 0; break;
      case 1: p = a; break;
      case 2: p = up; break;
      case 3: p = (a + up) >> 1; break;
      case 4: { const q = a + up - c, pa = Math.abs(q - a), pb = Math.abs(q - up), pc = Math.abs(q - c);
        p = pa <= pb && pa <= pc ? a : pb <= pc ? up : c; break; }
      default: fail(`row ${y}: filter ${f}`);
    }
    px[y * stride + x] = (row[x] + p) & 255;
  }
}
// bench/crowd's level colours (level_rgb), compared by hue: each colour
// divided by its largest channel.
const levels = [[0.86, 0.20, 0.18], [0.96, 0.58, 0.12], [0.93, 0.86, 0.20], [0.30, 0.72, 0.30]];
const norm = (c) => { const m = Math.max(...c); return c.map((v) => v / m); };
const ref = levels.slice(0, Number(LEVELS)).map(norm);
const count = ref.map(() => 0);
for (let y = 0; y < h - 32; y++)
  for (let x = 0; x < w; x++) {
    const c = [0, 1, 2].map((k) => px[3 * (y * w + x) + k] / 255);
    if (Math.max(...c) < 0.15) continue;
    const n = norm(c);
    ref.forEach((r, l) => { if (r.every((v, k) => Math.abs(v - n[k]) < 0.1)) count[l]++; });
  }
console.log(count.join(' '));
