// tests/cli/png-rgb.mjs: decodes a PNG as bench/crowd writes it (8-bit
// RGB, non-interlaced) with node's zlib and the five row filters, for the
// crowd tests: readRgbPng(file, W, H, who) returns { w, h, px } (px: RGB
// bytes, row after row) or exits 1 with "who: file: what is wrong" when the
// file is not such a PNG of W x H pixels.
import { readFileSync } from 'node:fs';
import { inflateSync } from 'node:zlib';

export function readRgbPng(file, W, H, who) {
  const fail = (m) => { console.error(`${who}: ${file}: ${m}`); process.exit(1); };
  const b = readFileSync(file);
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
  return { w, h, px };
}
