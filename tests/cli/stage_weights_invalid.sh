# Skin weights glTF does not allow (the tubeman with every 97th vertex's
# weights zeroed, 51 vertices, and every 89th from vertex 1 halved, 55:
# the validator finds 106 ACCESSOR_WEIGHTS_NON_NORMALIZED errors). The
# stages copied them into the levels they wrote, which failed the
# validator too (mlod-bgm's four levels 236 more errors, mlod-skelgraph's
# two 102), and said nothing. The reader applies mlod's one rule
# (mlod_primitive_fix_weights): a vertex without weight goes on the
# skin's root joint, weights off 1 are scaled to 1, with a warning each
# on stderr in every tool. The levels carry the rule's weights, and so
# does level 0, the input's own JOINTS_0 and WEIGHTS_0 (they kept the
# input's 106 errors): every glb a stage writes passes the validator, a
# stage reading another's output finds nothing to change and says
# nothing, and a pack unpacks to a glb without error. Level 0 keeps the
# input's accessors and their number format: floats stay floats,
# normalised unsigned bytes and shorts (tried on a strided view) keep
# theirs with every vertex summing to exactly 255 or 65535, the vertices
# the rule left alone byte for byte. A mesh that two skins with their
# roots at different entries of their joint lists use cannot name one
# root for both: its vertices without weight stay so, with a warning
# (they went on the first skin's entry, another joint of the second
# skin). Two meshes that share the accessors, each with its own skin and
# root entry, each get their own root: the shared WEIGHTS_0 is written
# once, mesh 1 gets a JOINTS_0 of its own.
set -e
node -e '
const fs = require("fs");
const b = Buffer.from(fs.readFileSync(process.argv[1]));
const jl = b.readUInt32LE(12), j = JSON.parse(b.subarray(20, 20 + jl));
const a = j.accessors[j.meshes[0].primitives[0].attributes.WEIGHTS_0], v = j.bufferViews[a.bufferView];
const at = 28 + jl + (v.byteOffset || 0) + (a.byteOffset || 0);
for (let i = 0; i < a.count; i++)
	for (let c = 0; c < 4; c++) {
		const o = at + 16 * i + 4 * c;
		if (i % 97 === 0) b.writeFloatLE(0, o);
		else if (i % 89 === 1) b.writeFloatLE(b.readFloatLE(o) * 0.5, o);
	}
fs.writeFileSync("bad.glb", b);
' "$ROOT/samples/tubeman.glb"
# The validator's errors of a file: their count, and how many are the
# input's own (level 0's WEIGHTS_0).
errors() {
	node "$ROOT/tests/validate.mjs" "$1" > v.txt || true
	echo "$(grep -c '^  error ' v.txt) $(grep -c '^  error ACCESSOR_WEIGHTS_NON_NORMALIZED: .*(/meshes/0/primitives/0/attributes/WEIGHTS_0)$' v.txt)"
}
[ "$(errors bad.glb)" = "106 106" ]
expect() {
	printf '%s: bad.glb: mesh 0 primitive 0: 51 vertices have no weight (vertex 0 the first): they follow the skin'"'"'s root joint "Hips"\n' "$1"
	printf '%s: bad.glb: mesh 0 primitive 0: the weights of 55 vertices do not sum to 1 (vertex 1 the first: 0.5): scaled to 1\n' "$1"
}
for t in label skelgraph bgm motion; do
	"$BIN/mlod-$t" -o "$t.glb" bad.glb 2> "$t.err"
	expect "mlod-$t" | cmp - "$t.err"
	[ "$(errors $t.glb)" = "0 0" ] || { echo "mlod-$t: $(errors $t.glb)" >&2; exit 1; }
done
# Level 0 keeps its accessors (same indices, float weights), written in
# place: the JSON is the input's but for what mlod-label adds.
node -e '
const fs = require("fs"), json = (f) => { const b = fs.readFileSync(f); return JSON.parse(b.subarray(20, 20 + b.readUInt32LE(12))); };
const a = json("bad.glb"), b = json("label.glb");
const p = JSON.stringify(a.meshes[0].primitives), q = JSON.stringify(b.meshes[0].primitives);
if (p !== q || JSON.stringify(a.accessors) !== JSON.stringify(b.accessors)) throw new Error(`level 0 changed: ${q}`);
'
# Every level holds the rule, level 0 too: vertex 0 on "Hips" alone,
# vertex 1's weights summing to 1 (mlod-skelgraph's levels keep every
# vertex in its place).
node -e '
const b = require("fs").readFileSync("skelgraph.glb");
const jl = b.readUInt32LE(12), j = JSON.parse(b.subarray(20, 20 + jl)), bin = 28 + jl;
const view = (a) => { const x = j.accessors[a], v = j.bufferViews[x.bufferView]; return bin + (v.byteOffset || 0) + (x.byteOffset || 0); };
const skin = j.skins[j.nodes.find((n) => n.mesh === 0).skin];
const hips = skin.joints.findIndex((n) => j.nodes[n].name === "Hips");
for (let m = 0; m < j.meshes.length; m++) {
	const p = j.meshes[m].primitives[0].attributes, jt = j.accessors[p.JOINTS_0].componentType;
	const w = view(p.WEIGHTS_0), jo = view(p.JOINTS_0), js = jt === 5121 ? 1 : 2;
	const rd = (o) => (js === 1 ? b.readUInt8(o) : b.readUInt16LE(o));
	const w0 = [0, 1, 2, 3].map((c) => b.readFloatLE(w + 4 * c)), j0 = rd(jo);
	if (String(w0) !== "1,0,0,0" || j0 !== hips) throw new Error(`mesh ${m}: vertex 0 joint ${j0} weights ${w0}, Hips is ${hips}`);
	const s1 = [0, 1, 2, 3].reduce((s, c) => Math.fround(s + b.readFloatLE(w + 16 + 4 * c)), 0);
	if (Math.abs(s1 - 1) > 8e-7) throw new Error(`mesh ${m}: vertex 1 weights sum to ${s1}`);
}
'
# A stage reading another's output finds valid weights: no warning.
"$BIN/mlod-label" bad.glb 2> /dev/null | "$BIN/mlod-skelgraph" -o piped.glb 2> piped.err
[ ! -s piped.err ]
[ "$(errors piped.glb)" = "0 0" ]
"$BIN/mlod-pack" -o bad.mlod bad.glb 2> pack.err
expect mlod-pack | cmp - pack.err
"$BIN/mlod-pack" -x bad.mlod -o x.glb
[ "$(errors x.glb)" = "0 0" ]
# The same mesh on a second node, with a second skin whose joint list is
# the first's turned by one (its root at entry 1, not 0).
node "$ROOT/tests/glb-edit.mjs" bad.glb two.glb '
const n = j.nodes.findIndex((x) => x.mesh === 0), s = j.skins[j.nodes[n].skin];
const joints = s.joints.slice(1).concat(s.joints.slice(0, 1));
j.skins.push(Object.assign({}, s, { joints, name: "turned" }));
j.nodes.push({ name: "second", mesh: 0, skin: j.skins.length - 1 });
j.scenes[j.scene || 0].nodes.push(j.nodes.length - 1);'
"$BIN/mlod-label" -o two-label.glb two.glb 2> two.err
grep -qxF 'mlod-label: two.glb: mesh 0 primitive 0: 51 vertices have no weight (vertex 0 the first), and the skins that use the mesh have no common root joint: they stay without weight' two.err
! grep -q "follow the skin's root joint" two.err
[ "$(errors two-label.glb)" = "51 51" ]
# Normalised unsigned bytes and shorts: WEIGHTS_0 re-encoded in the first
# bytes of each 16-byte float element (a strided view), the valid
# vertices summing to exactly 255 or 65535 (largest remainder).
for ct in 5121 5123; do
	node -e '
const fs = require("fs"), ct = +process.argv[1], S = ct === 5121 ? 255 : 65535, size = ct === 5121 ? 1 : 2;
const b = Buffer.from(fs.readFileSync("bad.glb"));
const jl = b.readUInt32LE(12), j = JSON.parse(b.subarray(20, 20 + jl));
const ai = j.meshes[0].primitives[0].attributes.WEIGHTS_0, a = j.accessors[ai], v = j.bufferViews[a.bufferView];
const at = 28 + jl + (v.byteOffset || 0) + (a.byteOffset || 0);
for (let i = 0; i < a.count; i++) {
	const w = [0, 1, 2, 3].map((c) => b.readFloatLE(at + 16 * i + 4 * c)), sum = w.reduce((s, x) => s + x, 0);
	let q = w.map((x) => Math.round(x * S));
	if (Math.abs(sum - 1) < 1e-3) {
		const x = w.map((y) => (y / sum) * S);
		q = x.map(Math.floor);
		let left = S - q.reduce((s, y) => s + y, 0);
		[0, 1, 2, 3].sort((p, r) => x[r] - q[r] - (x[p] - q[p]) || p - r).forEach((c) => { if (left-- > 0) q[c]++; });
	}
	b.fill(0, at + 16 * i, at + 16 * i + 16);
	q.forEach((y, c) => (size === 1 ? b.writeUInt8(y, at + 16 * i + c) : b.writeUInt16LE(y, at + 16 * i + 2 * c)));
}
Object.assign(a, { componentType: ct, normalized: true });
v.byteStride = 16;
let text = Buffer.from(JSON.stringify(j));
text = Buffer.concat([text, Buffer.alloc((4 - (text.length % 4)) % 4, 0x20)]);
const head = Buffer.from(b.subarray(0, 20));
head.writeUInt32LE(20 + text.length + b.length - 20 - jl, 8);
head.writeUInt32LE(text.length, 12);
fs.writeFileSync(`u${ct}.glb`, Buffer.concat([head, text, b.subarray(20 + jl)]));
' $ct
	[ "$(errors u$ct.glb)" = "106 106" ]
	"$BIN/mlod-label" -o u$ct-label.glb u$ct.glb 2> u$ct.err
	[ "$(grep -c 'scaled to 1$' u$ct.err)" = 1 ] && [ "$(grep -c "follow the skin's root joint" u$ct.err)" = 1 ]
	[ "$(errors u$ct-label.glb)" = "0 0" ]
	node -e '
const fs = require("fs"), ct = +process.argv[1], S = ct === 5121 ? 255 : 65535, size = ct === 5121 ? 1 : 2;
const rd = (f) => { const b = fs.readFileSync(f), jl = b.readUInt32LE(12), j = JSON.parse(b.subarray(20, 20 + jl));
	const a = j.accessors[j.meshes[0].primitives[0].attributes.WEIGHTS_0], v = j.bufferViews[a.bufferView];
	return { a, v, q: (i, c) => { const o = 28 + jl + (v.byteOffset || 0) + (a.byteOffset || 0) + (v.byteStride || 4 * size) * i + size * c;
		return size === 1 ? b.readUInt8(o) : b.readUInt16LE(o); } }; };
const x = rd(`u${ct}.glb`), y = rd(`u${ct}-label.glb`);
if (y.a.componentType !== ct || !y.a.normalized || y.v.byteStride !== 16) throw new Error(`WEIGHTS_0 is ${JSON.stringify(y.a)}`);
for (let i = 0; i < x.a.count; i++) {
	const q = [0, 1, 2, 3].map((c) => y.q(i, c)), p = [0, 1, 2, 3].map((c) => x.q(i, c));
	if (q.reduce((s, z) => s + z, 0) !== S) throw new Error(`vertex ${i}: ${q} do not sum to ${S}`);
	if (i % 97 !== 0 && i % 89 !== 1 && String(p) !== String(q)) throw new Error(`vertex ${i}: ${p} became ${q}`);
	if (i === 0 && String(q) !== `${S},0,0,0`) throw new Error(`vertex 0: ${q}`);
}
' $ct
done
# Mesh 1 a copy of mesh 0 (the same accessors) on a second node with the
# turned skin: the shared WEIGHTS_0 holds both, each mesh's vertex 0 goes
# on "Hips" of its own skin.
node "$ROOT/tests/glb-edit.mjs" bad.glb shared.glb '
const n = j.nodes.findIndex((x) => x.mesh === 0), s = j.skins[j.nodes[n].skin];
const joints = s.joints.slice(1).concat(s.joints.slice(0, 1));
j.skins.push(Object.assign({}, s, { joints, name: "turned" }));
j.meshes.push(JSON.parse(JSON.stringify(j.meshes[0])));
j.nodes.push({ name: "second", mesh: 1, skin: j.skins.length - 1 });
j.scenes[j.scene || 0].nodes.push(j.nodes.length - 1);'
"$BIN/mlod-label" -o shared-label.glb shared.glb 2> shared.err
[ "$(errors shared-label.glb)" = "0 0" ]
node -e '
const b = require("fs").readFileSync("shared-label.glb");
const jl = b.readUInt32LE(12), j = JSON.parse(b.subarray(20, 20 + jl)), bin = 28 + jl;
const view = (a) => { const x = j.accessors[a], v = j.bufferViews[x.bufferView]; return bin + (v.byteOffset || 0) + (x.byteOffset || 0); };
const p = j.meshes.map((m) => m.primitives[0].attributes);
if (p[0].WEIGHTS_0 !== p[1].WEIGHTS_0 || p[0].JOINTS_0 === p[1].JOINTS_0) throw new Error(JSON.stringify(p));
for (let m = 0; m < 2; m++) {
	const skin = j.skins[j.nodes.find((n) => n.mesh === m).skin];
	const hips = skin.joints.findIndex((n) => j.nodes[n].name === "Hips"), j0 = b.readUInt16LE(view(p[m].JOINTS_0));
	if (j0 !== hips) throw new Error(`mesh ${m}: vertex 0 on joint ${j0}, Hips is ${hips}`);
}
'
# A sparse WEIGHTS_0 (the input's vertex 0 zeroed by its sparse part)
# cannot be written in place: the primitive gets a new accessor and the
# old one, with its two sparse views, goes.
node -e '
const fs = require("fs"), b = fs.readFileSync(process.argv[1]), jl = b.readUInt32LE(12), j = JSON.parse(b.subarray(20, 20 + jl));
let bin = Buffer.concat([b.subarray(28 + jl, 28 + jl + b.readUInt32LE(20 + jl)), Buffer.alloc(20)]);
j.bufferViews.push({ buffer: 0, byteOffset: bin.length - 20, byteLength: 2 }, { buffer: 0, byteOffset: bin.length - 16, byteLength: 16 });
j.buffers[0].byteLength = bin.length;
const n = j.bufferViews.length;
j.accessors[j.meshes[0].primitives[0].attributes.WEIGHTS_0].sparse = { count: 1, indices: { bufferView: n - 2, componentType: 5123 }, values: { bufferView: n - 1 } };
let text = Buffer.from(JSON.stringify(j));
text = Buffer.concat([text, Buffer.alloc((4 - (text.length % 4)) % 4, 0x20)]);
const h = Buffer.alloc(28);
[0x46546c67, 2, 28 + text.length + bin.length, text.length, 0x4e4f534a].forEach((x, i) => h.writeUInt32LE(x, 4 * i));
fs.writeFileSync("sparse.glb", Buffer.concat([h.subarray(0, 20), text, Buffer.from([bin.length, bin.length >> 8, bin.length >> 16, bin.length >>> 24, 0x42, 0x49, 0x4e, 0]), bin]));
' "$ROOT/samples/tubeman.glb"
[ "$(errors sparse.glb)" = "1 1" ]
"$BIN/mlod-label" -o sparse-label.glb sparse.glb 2> sparse.err
grep -qxF "mlod-label: sparse.glb: mesh 0 primitive 0: vertex 0 has no weight: it follows the skin's root joint \"Hips\"" sparse.err
[ "$(errors sparse-label.glb)" = "0 0" ]
node -e '
const fs = require("fs"), json = (f) => { const b = fs.readFileSync(f); return JSON.parse(b.subarray(20, 20 + b.readUInt32LE(12))); };
const a = json("sparse.glb"), b = json("sparse-label.glb"), w = b.accessors[b.meshes[0].primitives[0].attributes.WEIGHTS_0];
if (w.sparse || b.accessors.length !== a.accessors.length || b.bufferViews.length !== a.bufferViews.length - 2)
	throw new Error(`${a.accessors.length}/${a.bufferViews.length} accessors/views became ${b.accessors.length}/${b.bufferViews.length}`);
'
