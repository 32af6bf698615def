// tests/cli/crowd_png.mjs FILE W H LEVELS: checks that FILE is a PNG of W x H
// pixels (8-bit RGB, as bench/crowd writes it) and prints, for each of the
// first LEVELS mesh level colours of bench/crowd, how many pixels above the
// legend strip (the bottom 32 rows) have that hue: the characters, shaded.
// Decodes with png-rgb.mjs.
import { readRgbPng } from './png-rgb.mjs';

const [file, W, H, LEVELS] = process.argv.slice(2);
const { w, h, px } = readRgbPng(file, Number(W), Number(H), 'crowd_png.mjs');
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
