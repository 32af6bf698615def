# RobotExpressive: 4 skins, rigid parts under joints, 14 clips and morph
# targets; no skeleton level within the default bound (so level 0 only).
set -e
"$BIN/mlod-pack" "$ROOT/samples/RobotExpressive.glb" -o robot.mlod 2> err.txt
node "$ROOT/tests/cli/pack_check.mjs" robot.mlod > c.json
node - <<'JS'
const fs = require('fs');
const c = JSON.parse(fs.readFileSync('c.json'));
const want = { joints: 43, skins: 4, skeleton_levels: 1, mesh_levels: 5, clips: 14, motion_levels: 4, parts: 19 };
for (const k in want) if (c[k] !== want[k]) throw new Error(`${k}: ${c[k]}`);
if (c.clip_names[0] !== 'Dance' || c.clip_names.length !== 14) throw new Error('clip names');
for (const t of ['MTSC', 'MTPQ', 'ROTQ']) if (!c.tags.includes(t)) throw new Error('no ' + t);
JS
