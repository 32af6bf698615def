# --precision: auto (the default) stores the levels' rotations as normalised
# shorts and rounds the other values within each bound, float rounds every
# value as float32, full keeps them as read. Every output passes the
# validator, auto is byte-identical from run to run, and each level records
# its grid in extras.mlod (0 at full precision).
set -e
"$BIN/mlod-motion" "$ROOT/samples/RobotExpressive.glb" > auto.glb
"$BIN/mlod-motion" --precision auto --precision-share 0.1 "$ROOT/samples/RobotExpressive.glb" > again.glb
cmp auto.glb again.glb
"$BIN/mlod-motion" --precision float "$ROOT/samples/RobotExpressive.glb" > float.glb
"$BIN/mlod-motion" --precision full "$ROOT/samples/RobotExpressive.glb" > full.glb
node "$ROOT/tests/validate.mjs" auto.glb float.glb full.glb > /dev/null
node - auto.glb float.glb full.glb <<'JS'
const fs = require('fs');
const fail = (m) => { console.error(m); process.exit(1); };
const check = (path, mode) => {
	const b = fs.readFileSync(path);
	const json = JSON.parse(b.subarray(20, 20 + b.readUInt32LE(12)).toString('utf8'));
	const levels = json.animations.filter((a) => a.extras && a.extras.mlod);
	if (levels.length !== 42) fail(`${mode}: ${levels.length} levels`);
	for (const an of levels) {
		const l = an.extras.mlod;
		if (mode === 'full' ? l.grid !== 0 : !(l.grid > 0)) fail(`${mode}: ${an.name} grid ${l.grid}`);
		if (!(l.point_error <= l.bound && l.joint_error.max <= l.bound)) fail(`${mode}: ${an.name} over its bound`);
		for (const c of an.channels) {
			const out = json.accessors[an.samplers[c.sampler].output];
			const short = out.componentType === 5122 && out.normalized === true;
			if (c.target.path === 'rotation' && short !== (mode === 'auto')) fail(`${mode}: ${an.name} rotation as ${out.componentType}`);
			if (c.target.path !== 'rotation' && out.componentType !== 5126) fail(`${mode}: ${an.name} ${c.target.path} not float`);
		}
	}
};
check(process.argv[2], 'auto');
check(process.argv[3], 'float');
check(process.argv[4], 'full');
JS
