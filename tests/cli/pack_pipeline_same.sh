# The levels the piped stages leave are the levels mlod-pack computes
# alone (mlod-motion with --precision full: mlod-pack keeps the clip's own
# values at every motion level, mlod(5) MOTION levels): on RobotExpressive (no skeleton level within the default bound,
# so the mesh levels follow none), every MESH and ANIM chunk of the piped
# pack is byte-identical to the direct pack's (same CRC, same place). So
# is the DOC chunk (the piped input's level nodes, skins and meshes, level
# animations and records do not go in it), and the two packs' sizes differ
# by the name alone ("" piped, "RobotExpressive" direct: 16 bytes).
set -e
"$BIN/mlod-label" < "$ROOT/samples/RobotExpressive.glb" | "$BIN/mlod-skelgraph" 2>/dev/null | "$BIN/mlod-bgm" |
	"$BIN/mlod-motion" --precision full | "$BIN/mlod-pack" -o piped.mlod
"$BIN/mlod-pack" "$ROOT/samples/RobotExpressive.glb" -o direct.mlod
node "$ROOT/tests/cli/pack_check.mjs" piped.mlod > p.json
node "$ROOT/tests/cli/pack_check.mjs" direct.mlod > d.json
node - <<'JS'
const fs = require('fs');
const p = JSON.parse(fs.readFileSync('p.json')).toc, d = JSON.parse(fs.readFileSync('d.json')).toc;
if (p.length !== d.length) throw new Error('chunk counts');
const levels = (t) => t.filter((x) => /^(MESH|ANIM|SKEL)/.test(x));
if (levels(p).join() !== levels(d).join()) throw new Error('level chunks differ: ' + levels(p).filter((x, i) => x !== levels(d)[i]).join(', '));
if (levels(p).length !== 1 + 5 + 14 * 4) throw new Error('levels: ' + levels(p).length);
const doc = (t) => t.filter((x) => /^DOC/.test(x)).join();
if (doc(p) !== doc(d)) throw new Error('DOC chunks differ: ' + doc(p) + ' ' + doc(d));
const sp = fs.statSync('piped.mlod').size, sd = fs.statSync('direct.mlod').size;
if (sd - sp !== 16) throw new Error('sizes: piped ' + sp + ', direct ' + sd);
JS
