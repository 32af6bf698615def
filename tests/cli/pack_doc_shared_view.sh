# A buffer view that many accessors share, of which the DOC chunk keeps a
# few: gltf-transform 4.5.1 (pinned in tests/node) writes RobotExpressive
# with every animation's keys in one view (221 inputs and 221 outputs,
# 131,740 bytes), and the DOC chunk keeps only the morph weights channels
# (the joint channels go to the MOTION chunks). The view was kept whole:
# a DOC of 53,959 bytes and a pack of 140,183 (the sample's own layout:
# DOC 5,128, pack 92,120). The prune now trims a view to the bytes its
# accessors left read: DOC 4,504, pack 90,728. -x gives the morph weights
# keys back bit for bit, and a glb without validator error.
set -e
gt=$ROOT/tests/node/node_modules/.bin/gltf-transform
[ -x "$gt" ] || { echo "gltf-transform is not installed in tests/node (scripts/install-deps)" >&2; exit 77; }
"$gt" copy "$ROOT/samples/RobotExpressive.glb" gt.glb > /dev/null 2>&1
# The layout this test is about: one view holding every sampler's keys.
node -e '
const b = require("fs").readFileSync("gt.glb"), j = JSON.parse(b.subarray(20, 20 + b.readUInt32LE(12)));
const views = new Set(j.animations.flatMap((a) => a.samplers.flatMap((s) => [s.input, s.output])).map((i) => j.accessors[i].bufferView));
if (views.size !== 1) throw new Error(`the keys lie in ${views.size} views`);
'
"$BIN/mlod-pack" -o gt.mlod gt.glb 2> /dev/null
doc=$("$BIN/mlod-pack" --info gt.mlod --json | grep -o '"type": "DOC"[^}]*' | grep -o '"stored": [0-9]*' | grep -o '[0-9]*$')
[ "$doc" -le 6000 ] || { echo "DOC chunk: $doc bytes" >&2; exit 1; }
"$BIN/mlod-pack" -x gt.mlod -o x.glb
node "$ROOT/tests/validate.mjs" x.glb > /dev/null
# Every morph weights channel, by animation name and node name: the same
# key times and values; every channel -x adds holds one of them.
node -e '
const fs = require("fs");
const keys = (f) => {
	const b = fs.readFileSync(f), jl = b.readUInt32LE(12), j = JSON.parse(b.subarray(20, 20 + jl)), bin = 28 + jl;
	const read = (i) => { const a = j.accessors[i], v = j.bufferViews[a.bufferView];
		if (a.componentType !== 5126) throw new Error(`${f}: accessor ${i} is not float`);
		const n = a.count * { SCALAR: 1, VEC3: 3, VEC4: 4 }[a.type], o = bin + (v.byteOffset || 0) + (a.byteOffset || 0);
		return Array.from({ length: n }, (_, k) => b.readFloatLE(o + 4 * k)); };
	const out = {};
	for (const a of j.animations)
		for (const c of a.channels)
			if (c.target.path === "weights") {
				const s = a.samplers[c.sampler];
				out[`${a.name}/${j.nodes[c.target.node].name}`] = JSON.stringify([read(s.input), read(s.output)]);
			}
	return out;
};
const a = keys("gt.glb"), b = keys("x.glb"), names = Object.keys(a);
if (names.length === 0) throw new Error("no morph weights channel");
for (const n of names) if (a[n] !== b[n]) throw new Error(`${n}: keys differ`);
/* (the nodes of the levels each get a copy of the channels of their level-0 node) */
for (const n of Object.keys(b)) if (!Object.values(a).includes(b[n])) throw new Error(`${n}: keys of no input channel`);
'
