# A BVH: skeleton and motion levels, no mesh chunk; the DOC chunk holds the
# BVH as a glb.
set -e
"$BIN/mlod-pack" "$ROOT/samples/cmu_12_01_walk.bvh" > walk.mlod
node "$ROOT/tests/cli/pack_check.mjs" walk.mlod > c.json
node - <<'JS'
const c = JSON.parse(require('fs').readFileSync('c.json'));
const want = { joints: 31, skins: 0, mesh_levels: 0, parts: 0, clips: 1, motion_levels: 4, name: 'cmu_12_01_walk' };
for (const k in want) if (c[k] !== want[k]) throw new Error(`${k}: ${c[k]}`);
if (c.skeleton_levels < 2 || c.count.MESH) throw new Error('levels');
if (!(c.doc > 0)) throw new Error('doc');
JS
