# The stage record (mlod-record(5)) survives every stage: the stages run
# in the orders a pipeline could use (mlod-skelgraph after mlod-bgm among
# them), and after each one every earlier stage's record is still there,
# unchanged, with the version; the outputs validate.
set -e
orders="LSBM SBM LBSM BS LMSB BMLS MBSL SMB"
tool() {
	case $1 in L) echo mlod-label ;; S) echo mlod-skelgraph ;; B) echo mlod-bgm ;; M) echo mlod-motion ;; esac
}
for o in $orders; do
	prev="$ROOT/samples/tubeman.glb"
	i=0
	for s in $(echo $o | sed 's/./& /g'); do
		i=$((i + 1))
		out=$o.$i.glb
		"$BIN/$(tool $s)" "$prev" > "$out" 2>> stderr.txt
		prev=$out
	done
done
node "$ROOT/tests/validate.mjs" BS.2.glb LSBM.4.glb BMLS.4.glb > /dev/null
node - $orders <<'JS'
const fs = require('fs');
const glb = (f) => { const b = fs.readFileSync(f); return JSON.parse(b.subarray(20, 20 + b.readUInt32LE(12)).toString()); };
const rec = (o) => (o && o.extras && o.extras.mlod) || undefined;
// What each stage records, as read from a document.
const parts = {
	L: (j) => j.nodes.map((n) => rec(n) && rec(n).label !== undefined ? rec(n) : null),
	S: (j) => [rec(j.scenes[0]).skeleton_levels, (j.skins || []).map((s) => rec(s) || null)],
	B: (j) => [rec(j.scenes[0]).mesh_levels, j.nodes.map((n) => rec(n) && rec(n).mesh_level ? rec(n) : null)],
	M: (j) => j.animations.map((a) => rec(a) || null),
};
// Only the entries the stage made: later stages may add nodes, skins or animations.
const prefix = (later, made) => JSON.stringify(later).startsWith(JSON.stringify(made).replace(/\]$/, '')) || JSON.stringify(later) === JSON.stringify(made);
const same = (a, b) => {
	if (Array.isArray(b) && Array.isArray(a)) return b.every((x, i) => same(a[i], x));
	return JSON.stringify(a) === JSON.stringify(b);
};
for (const order of process.argv.slice(2)) {
	const made = {};
	[...order].forEach((stage, k) => {
		const j = glb(`${order}.${k + 1}.glb`);
		const r = rec(j.scenes[0]);
		if (!r || r.version !== 4) throw new Error(`${order} after ${stage}: scene record version ${r && r.version}`);
		made[stage] = parts[stage](j);
		const found = {
			L: made.L && made.L.some((x) => x), S: made.S && made.S[0] && made.S[0].length > 0,
			B: made.B && made.B[0] && made.B[0].length === 4, M: made.M && made.M.some((x) => x && x.motion_level),
		};
		if (!found[stage]) throw new Error(`${order}: ${stage} recorded nothing`);
		for (const [s, was] of Object.entries(made))
			if (!same(parts[s](j), was)) throw new Error(`${order}: ${stage} changed or dropped the record of ${s}`);
	});
}
JS
