# The glb keeps every original animation byte for byte and adds
# <clip>@lod<k> animations with extras.mlod, each within its bound, with
# fewer bytes level after level, morph weights channels on the same nodes
# as the clip's; the Khronos validator accepts it.
set -e
"$BIN/mlod-motion" "$ROOT/samples/RobotExpressive.glb" > out.glb
node "$ROOT/tests/validate.mjs" out.glb > /dev/null
node - "$ROOT/samples/RobotExpressive.glb" out.glb <<'JS'
const fs = require('fs');
function glb(path) {
	const b = fs.readFileSync(path);
	const jlen = b.readUInt32LE(12);
	const json = JSON.parse(b.subarray(20, 20 + jlen).toString('utf8'));
	const bin = b.subarray(20 + jlen + 8);
	const bytes = (a) => {
		const acc = json.accessors[a], view = json.bufferViews[acc.bufferView];
		const n = { SCALAR: 1, VEC3: 3, VEC4: 4 }[acc.type] * 4 * acc.count;
		const off = (view.byteOffset || 0) + (acc.byteOffset || 0);
		return bin.subarray(off, off + n);
	};
	return { json, bytes };
}
const a = glb(process.argv[2]), b = glb(process.argv[3]);
const orig = a.json.animations, out = b.json.animations;
const fail = (m) => { console.error(m); process.exit(1); };
orig.forEach((an, i) => {
	const bn = out[i];
	if (bn.name !== an.name || bn.channels.length !== an.channels.length) fail(`animation ${i} changed`);
	an.samplers.forEach((s, k) => {
		const t = bn.samplers[k];
		if (s.interpolation !== t.interpolation) fail(`animation ${i} sampler ${k}: interpolation changed`);
		if (!a.bytes(s.input).equals(b.bytes(t.input)) || !a.bytes(s.output).equals(b.bytes(t.output)))
			fail(`animation ${i} sampler ${k}: keys changed`);
	});
});
const height = 5.78149; // the robot's skeleton height (mlod_skeleton_size)
const bounds = [0.002, 0.01, 0.03].map((p) => p * height);
for (const an of orig) {
	let prevBytes = Infinity;
	for (let k = 1; k <= 3; k++) {
		const lv = out.find((x) => x.name === `${an.name}@lod${k}`);
		if (!lv) fail(`no ${an.name}@lod${k}`);
		const m = lv.extras && lv.extras.mlod;
		if (!m || m.motion_level !== k || out[m.source_animation].name !== an.name) fail(`${lv.name}: bad extras.mlod`);
		if (!(Math.abs(m.bound - bounds[k - 1]) < 1e-5 * height)) fail(`${lv.name}: bound ${m.bound}`);
		if (!(m.joint_error.max <= m.bound && m.point_error <= m.bound)) fail(`${lv.name}: error over its bound`);
		if (!(m.bytes <= prevBytes)) fail(`${lv.name}: ${m.bytes} bytes after ${prevBytes}`);
		prevBytes = m.bytes;
		for (const s of lv.samplers) if (s.interpolation !== 'LINEAR') fail(`${lv.name}: ${s.interpolation}`);
		// Morph weights on the same nodes as the source's (reduced copies).
		const wn = (x) => x.channels.filter((c) => c.target.path === 'weights').map((c) => c.target.node).join();
		if (wn(lv) !== wn(an)) fail(`${lv.name}: weights on ${wn(lv)}, not ${wn(an)}`);
	}
}
JS
