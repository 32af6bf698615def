# The DOC chunk: the input document without what the other chunks hold.
# Node, mesh, skin and material counts are the input's (the piped input's
# level nodes, level meshes and the records go); primitives keep their
# material but no attributes or indices; no MSFT_lod; animations keep
# only morph weights channels (RobotExpressive has 3 per clip); skins
# without inverse bind matrices and most joint nodes without their rest
# TRS (SKEL holds both); far smaller than the input.
set -e
"$BIN/mlod-label" < "$ROOT/samples/RobotExpressive.glb" | "$BIN/mlod-bgm" -R 0.5 > piped.glb
"$BIN/mlod-pack" --no-motion-levels piped.glb -o robot.mlod
node "$ROOT/tests/cli/pack_check.mjs" robot.mlod --doc doc.glb > /dev/null
node - "$ROOT/samples/RobotExpressive.glb" <<'JS'
const fs = require('fs');
const glb = (f) => { const b = fs.readFileSync(f); return JSON.parse(b.subarray(20, 20 + b.readUInt32LE(12)).toString()); };
const d = glb('doc.glb'), p = glb('piped.glb'), i = glb(process.argv[2]);
for (const k of ['nodes', 'meshes', 'skins', 'materials']) if (d[k].length !== i[k].length) throw new Error(k);
if (!(p.nodes.length > i.nodes.length)) throw new Error('the piped input has no level nodes');
if (d.skins.slice(0, i.skins.length).some((s) => s.inverseBindMatrices !== undefined)) throw new Error('inverse bind matrices left');
const joints = new Set(d.skins.slice(0, i.skins.length).flatMap((s) => s.joints));
/* one number style per document: 10 of the 43 joints keep parts written otherwise */
const kept = [...joints].filter((k) => d.nodes[k].rotation || d.nodes[k].translation || d.nodes[k].scale).length;
if (!(kept * 4 < joints.size)) throw new Error('joint TRS left on ' + kept + ' of ' + joints.size);
if (JSON.stringify(d.nodes.map((n) => n.extras)).includes('"mlod"')) throw new Error('records left');
for (const m of d.meshes) for (const q of m.primitives) if (Object.keys(q.attributes).length || q.indices !== undefined || q.targets) throw new Error('geometry left');
i.meshes.forEach((m, k) => m.primitives.forEach((q, t) => { if (d.meshes[k].primitives[t].material !== q.material) throw new Error('material of mesh ' + k); }));
if (JSON.stringify(d).includes('MSFT_lod')) throw new Error('MSFT_lod left');
if (d.animations.length !== i.animations.length) throw new Error('animations');
for (const a of d.animations) if (a.channels.length !== 3 || a.channels.some((c) => c.target.path !== 'weights')) throw new Error('channels of ' + a.name);
if (!(fs.statSync('doc.glb').size * 4 < fs.statSync(process.argv[2]).size)) throw new Error('doc size ' + fs.statSync('doc.glb').size);
JS
