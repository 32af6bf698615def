# mlod-pack alone on a glb: every layer computed with its defaults; the
# container checks out (tests/cli/pack_check.mjs: CRCs, alignment, order,
# INFO) with 2 skeleton levels (the default chain stops where the next one
# would pass 2% of the height), 4 mesh and 3 motion levels beyond level 0, and the
# report says the levels were computed. A finer mesh level stores its
# indices in its own numbering with its map (IMAP, index sequence codec).
# Its skeleton levels store the palette as references (PALR, PALX; 7.0),
# and the entropy stage chose byte planes and weights without their sums
# (stream codecs 4 to 6) for some streams.
set -e
"$BIN/mlod-pack" "$ROOT/samples/tubeman.glb" -o tubeman.mlod --report=json > r.json
node "$ROOT/tests/cli/pack_check.mjs" tubeman.mlod > c.json
node - <<'JS'
const fs = require('fs');
const c = JSON.parse(fs.readFileSync('c.json')), r = JSON.parse(fs.readFileSync('r.json'));
const want = { joints: 31, skins: 1, skeleton_levels: 3, mesh_levels: 5, clips: 1, motion_levels: 4, parts: 1, name: 'tubeman' };
for (const k in want) if (c[k] !== want[k]) throw new Error(`${k}: ${c[k]}`);
for (const t of ['KEPT', 'PALR', 'PALX', 'POSQ', 'NRMQ', 'JNT8', 'WGT8', 'IDX ', 'IMAP', 'CHAN', 'STEP', 'ROTQ']) if (!c.tags.includes(t)) throw new Error('no ' + t);
if (c.tags.includes('PALJ') || c.tags.includes('PALB')) throw new Error('PALJ or PALB in a 7.0 pack');
if (!c.tags.includes('TIME') && !c.tags.includes('TICK') && !c.tags.includes('TBIT')) throw new Error('no key times');
if (JSON.stringify(c.stream_codecs) !== '[0,1,2,3,4,5,6]') throw new Error('stream codecs ' + c.stream_codecs);
if (!(c.planes > 0) || !(c.sums > 0)) throw new Error(`planes ${c.planes}, sums ${c.sums}`);
if (JSON.stringify(c.entropy) !== '[0,1,2]') throw new Error('entropy stages ' + c.entropy);
const levels = { skeleton: 3, mesh: 5, motion: 4 };
for (const l in levels) if (r.layers[l].source !== 'computed' || r.layers[l].levels !== levels[l]) throw new Error(l);
if (r.total !== fs.statSync('tubeman.mlod').size) throw new Error('report total');
if (!(c.first_drawable < c.size / 4)) throw new Error('first_drawable ' + c.first_drawable);
JS
