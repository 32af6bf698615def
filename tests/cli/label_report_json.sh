# --report=json is valid JSON with one entry per joint of the CMU walk (31),
# labelled as the table says (root 1, end-effector 7, major 1, minor 22),
# each leaf an end-effector and each parent named before its children.
set -e
"$BIN/mlod-label" --report=json "$ROOT/samples/cmu_12_01_walk.bvh" > r.json
node -e '
const r = JSON.parse(require("fs").readFileSync("r.json"));
const fail = (m) => { console.error(m); process.exit(1); };
if (r.joints.length !== 31) fail("joints " + r.joints.length);
if (r.joints[0].name !== "Hips" || r.joints[0].label !== "root" || r.joints[0].parent !== null) fail("root");
const count = {};
const seen = new Set();
for (const j of r.joints) {
	count[j.label] = (count[j.label] || 0) + 1;
	if (j.parent !== null && !seen.has(j.parent)) fail(j.name + " before its parent " + j.parent);
	if ((j.children === 0) !== (j.label === "end-effector")) fail(j.name + ": " + j.children + " children, " + j.label);
	if (!(j.energy >= 0)) fail(j.name + ": energy " + j.energy);
	seen.add(j.name);
}
const want = { root: 1, "end-effector": 7, major: 1, minor: 22 };
for (const k of Object.keys(want)) if (count[k] !== want[k]) fail(k + ": " + count[k]);
if (count.extreme) fail("extreme: " + count.extreme);
'
