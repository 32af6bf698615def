# Level nodes that keep morph targets morph like their node: every
# animation channel of a node's weights is there for each of its level
# nodes too (RobotExpressive: 3 heads, 42 weight channels), with the same
# sampler; the glb validates.
set -e
"$BIN/mlod-bgm" -R 0.5,0.35,0.3 -o out.glb "$ROOT/samples/RobotExpressive.glb"
node "$ROOT/tests/validate.mjs" out.glb > /dev/null
node - "$ROOT/samples/RobotExpressive.glb" <<'JS'
const fs = require('fs');
const glb = (f) => { const b = fs.readFileSync(f); return JSON.parse(b.subarray(20, 20 + b.readUInt32LE(12)).toString()); };
const a = glb(process.argv[2]), o = glb('out.glb');
const weights = (j) => j.animations.flatMap((an, i) => an.channels.filter((c) => c.target.path === 'weights').map((c) => [i, c.sampler, c.target.node]));
if (weights(a).length !== 42) throw new Error('input weight channels: ' + weights(a).length);
const w = weights(o);
if (w.length !== 42 * 4) throw new Error('weight channels: ' + w.length);
let morphing = 0;
for (const [n, node] of o.nodes.entries()) {
	if (!node.extensions || !node.extensions.MSFT_lod) continue;
	const own = w.filter((c) => c[2] === n).map((c) => c[0] + ':' + c[1]).join();
	if (!own) continue;
	morphing++;
	for (const id of node.extensions.MSFT_lod.ids) {
		const lv = o.nodes[id], m = o.meshes[lv.mesh];
		if (m.primitives.some((p) => (p.targets || []).length !== 3)) throw new Error('level lost its targets');
		if (w.filter((c) => c[2] === id).map((c) => c[0] + ':' + c[1]).join() !== own) throw new Error(`level node ${id} does not morph like node ${n}`);
	}
}
if (morphing !== 3) throw new Error('morphing nodes with levels: ' + morphing);
JS
