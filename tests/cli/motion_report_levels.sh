# JSON report: every level within its bound (bounds given unsorted come out
# sorted), bytes non-increasing, the duration and the key counts coherent;
# stdin input; both methods and a forced one.
set -e
for method in auto frames keys; do
	"$BIN/mlod-motion" -m $method -e '1%,0.05,3%' --report=json < "$ROOT/samples/cmu_12_01_walk.bvh" > $method.json
	node - $method.json $method <<'JS'
const r = JSON.parse(require('fs').readFileSync(process.argv[2]));
const fail = (m) => { console.error(process.argv[3] + ': ' + m); process.exit(1); };
if (r.input !== '<stdin>') fail('input ' + r.input);
const c = r.clips[0];
if (c.frames !== 524 || c.resampled) fail('timeline');
const want = [0.05, 0.01 * r.height, 0.03 * r.height];
let prev = c.bytes;
c.levels.forEach((l, i) => {
	if (!l.ok) fail(`level ${l.level} missing`);
	if (Math.abs(l.bound - want[i]) > 1e-6 * r.height) fail(`level ${l.level}: bound ${l.bound}`);
	if (!(l.joint_error.max <= l.bound && l.point_error <= l.bound)) fail(`level ${l.level}: error over bound`);
	if (!(l.bytes <= prev)) fail(`level ${l.level}: bytes grew`);
	if (process.argv[3] !== 'auto' && l.method !== process.argv[3]) fail(`level ${l.level}: method ${l.method}`);
	prev = l.bytes;
});
JS
done
