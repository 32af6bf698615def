# The piped pipeline ending in mlod-pack: every layer's levels come from
# the input (the report says so), and the level skins and "@lod" animations
# are not packed as skins or clips of their own.
set -e
"$BIN/mlod-label" < "$ROOT/samples/tubeman.glb" | "$BIN/mlod-skelgraph" | "$BIN/mlod-bgm" | "$BIN/mlod-motion" |
	"$BIN/mlod-pack" -o piped.mlod --report=json > r.json
node "$ROOT/tests/cli/pack_check.mjs" piped.mlod > c.json
node - <<'JS'
const fs = require('fs');
const c = JSON.parse(fs.readFileSync('c.json')), r = JSON.parse(fs.readFileSync('r.json'));
// mlod-skelgraph's default chain stops where a level would pass 2% of the
// height: tubeman keeps 2 coarser levels (3 with the full skeleton).
const levels = { skeleton: 3, mesh: 5, motion: 4 };
for (const l in levels) if (r.layers[l].source !== 'input' || r.layers[l].levels !== levels[l]) throw new Error(l + ': ' + JSON.stringify(r.layers[l]));
const want = { joints: 31, skins: 1, skeleton_levels: 3, mesh_levels: 5, clips: 1, motion_levels: 4, parts: 1 };
for (const k in want) if (c[k] !== want[k]) throw new Error(`${k}: ${c[k]}`);
if (JSON.stringify(c.clip_names) !== '["walk"]') throw new Error('clips ' + c.clip_names);
JS
# A subset of the stages: mlod-motion alone before the pack.
"$BIN/mlod-motion" "$ROOT/samples/cmu_12_01_walk.bvh" | "$BIN/mlod-pack" --report=json -o walk.mlod > r2.json
node -e '
const r = JSON.parse(require("fs").readFileSync("r2.json"));
if (r.layers.motion.source !== "input" || r.layers.skeleton.source !== "computed") throw new Error("sources");
'
node "$ROOT/tests/cli/pack_check.mjs" walk.mlod > /dev/null
