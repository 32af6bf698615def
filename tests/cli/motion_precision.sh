# --precision: auto (the default) rounds the levels' key values within each
# bound, full keeps them as read. Both outputs pass the validator, auto is
# byte-identical from run to run, and each level records its grid in
# extras.mlod (0 at full precision).
set -e
"$BIN/mlod-motion" "$ROOT/samples/RobotExpressive.glb" > auto.glb
"$BIN/mlod-motion" --precision auto --precision-share 0.1 "$ROOT/samples/RobotExpressive.glb" > again.glb
cmp auto.glb again.glb
"$BIN/mlod-motion" --precision full "$ROOT/samples/RobotExpressive.glb" > full.glb
node "$ROOT/tests/validate.mjs" auto.glb full.glb > /dev/null
node - auto.glb full.glb <<'JS'
const fs = require('fs');
const levels = (path) => {
	const b = fs.readFileSync(path);
	const json = JSON.parse(b.subarray(20, 20 + b.readUInt32LE(12)).toString('utf8'));
	return json.animations.filter((a) => a.extras && a.extras.mlod).map((a) => a.extras.mlod);
};
const fail = (m) => { console.error(m); process.exit(1); };
const auto = levels(process.argv[2]), full = levels(process.argv[3]);
if (auto.length !== 42 || full.length !== 42) fail(`levels: ${auto.length} and ${full.length}`);
for (const l of full) if (l.grid !== 0) fail(`full precision level with grid ${l.grid}`);
for (const l of auto) {
	if (!(l.grid > 0)) fail(`auto precision level without a grid`);
	if (!(l.point_error <= l.bound && l.joint_error.max <= l.bound)) fail('auto level over its bound');
}
JS
