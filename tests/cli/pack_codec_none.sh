# --codec none --entropy none: every chunk and stream raw, and a larger
# pack than meshopt's. Its skeleton levels' palettes (format 7.0, raw
# 'PALR' that pack_check.mjs reads): every skin joint a reference, the
# kept ones to their own bind, some removed ones to another joint's.
set -e
"$BIN/mlod-pack" --codec none --entropy none --ratios 0.5 "$ROOT/samples/tubeman.glb" -o none.mlod
"$BIN/mlod-pack" --codec meshopt --ratios 0.5 "$ROOT/samples/tubeman.glb" -o mo.mlod
node "$ROOT/tests/cli/pack_check.mjs" none.mlod > n.json
node "$ROOT/tests/cli/pack_check.mjs" mo.mlod > m.json
node - <<'JS'
const fs = require('fs');
const n = JSON.parse(fs.readFileSync('n.json')), m = JSON.parse(fs.readFileSync('m.json'));
if (JSON.stringify(n.codecs) !== '[0]' || JSON.stringify(n.stream_codecs) !== '[0]' || JSON.stringify(n.entropy) !== '[0]') throw new Error('none has codecs');
if (n.mesh_levels !== 2 || m.mesh_levels !== 2) throw new Error('--ratios 0.5');
if (!(m.size < n.size)) throw new Error(`meshopt ${m.size} >= none ${n.size}`);
if (n.palette.length !== n.skeleton_levels - 1 || n.palette.some((k) => !k || k[0] + k[1] + k[2] !== 31)) throw new Error(`palette ${JSON.stringify(n.palette)}`);
if (!n.palette.some((k) => k[1] > 0) || !n.palette.every((k) => k[0] > 0)) throw new Error(`palette ${JSON.stringify(n.palette)}`);
JS
