// tests/cli/crowd_plot.mjs FILE W H R,G,B ...: checks that FILE is a PNG of
// W x H pixels (8-bit RGB, as bench/crowd --plot writes it) and prints, for
// each colour given, how many pixels have exactly that colour (a series'
// lines and points). Decodes with png-rgb.mjs.
import { readRgbPng } from './png-rgb.mjs';

const [file, W, H, ...colours] = process.argv.slice(2);
const { w, h, px } = readRgbPng(file, Number(W), Number(H), 'crowd_plot.mjs');
const counts = colours.map((c) => {
  const [r, g, bl] = c.split(',').map(Number);
  let n = 0;
  for (let i = 0; i < w * h; i++) if (px[3 * i] === r && px[3 * i + 1] === g && px[3 * i + 2] === bl) n++;
  return n;
});
console.log(counts.join(' '));
