# Extensions a pack's DOC chunk can strip around. A document using an
# extension mlod did not know kept the input whole in the DOC chunk
# (tubeman: about 316,200 bytes against 79,963, format 9.0). Three more are known now:
# EXT_materials_bump (three.js's exporter writes it: a factor and a
# texture), KHR_node_visibility (a boolean) and KHR_animation_pointer when
# each pointer names a node, material, camera or light (its channels are
# core channels, their samplers renumbered as any): each gives a stripped
# DOC without the note, and -x gives back the extension, a valid glb, and
# a pointer channel's keys exactly. A pointer into an unknown extension's
# data keeps the document whole, as before, and so does a pointer to a
# mesh: -x puts level 0 in a new mesh, and the pointer named the old one,
# left empty (the validator's EMPTY_ENTITY).
set -e
T="$ROOT/samples/tubeman.glb"
node "$ROOT/tests/glb-edit.mjs" "$T" bump.glb \
	'j.materials[0].extensions = { EXT_materials_bump: { bumpFactor: 0.5 } }; j.extensionsUsed = ["EXT_materials_bump"];'
node "$ROOT/tests/glb-edit.mjs" "$T" vis.glb \
	'j.nodes[0].extensions = { KHR_node_visibility: { visible: true } }; j.extensionsUsed = ["KHR_node_visibility"];'
pointer() {
	node "$ROOT/tests/glb-edit.mjs" "$T" "$1" '
const a = j.animations[0], rc = a.channels.find((c) => c.target.path === "rotation");
a.channels.push({ sampler: rc.sampler, target: { path: "pointer", extensions: { KHR_animation_pointer: { pointer: "'"$2"'" } } } });
j.extensionsUsed = ["KHR_animation_pointer"];'
}
pointer ptr.glb /materials/0/pbrMetallicRoughness/baseColorFactor
pointer foo.glb /extensions/EXT_foo/things/0/color
pointer mesh.glb /meshes/0/weights
# The keys of the pointer channel of a glb's first animation.
keys() {
	node -e '
const b = require("fs").readFileSync(process.argv[1]);
const jl = b.readUInt32LE(12), j = JSON.parse(b.subarray(20, 20 + jl)), bin = 28 + jl;
const acc = (i) => {
	const a = j.accessors[i], v = j.bufferViews[a.bufferView], n = { SCALAR: 1, VEC4: 4 }[a.type], st = v.byteStride || 4 * n, out = [];
	for (let k = 0; k < a.count; k++)
		for (let c = 0; c < n; c++) out.push(b.readFloatLE(bin + (v.byteOffset || 0) + (a.byteOffset || 0) + k * st + 4 * c));
	return out;
};
const an = j.animations[0], ch = an.channels.find((c) => c.target.path === "pointer"), s = an.samplers[ch.sampler];
console.log(ch.target.extensions.KHR_animation_pointer.pointer, JSON.stringify([acc(s.input), acc(s.output)]));
' "$1"
}
for f in bump vis ptr; do
	"$BIN/mlod-pack" -o $f.mlod $f.glb 2> $f.err
	[ ! -s $f.err ] || { cat $f.err >&2; exit 1; }
	size=$(wc -c < $f.mlod)
	[ "$size" -lt 100000 ] || { echo "$f: $size bytes" >&2; exit 1; }
	"$BIN/mlod-pack" -x $f.mlod -o $f-x.glb
	node "$ROOT/tests/validate.mjs" $f-x.glb > /dev/null
done
node -e '
const fs = require("fs");
const doc = (f) => { const b = fs.readFileSync(f); return JSON.parse(b.subarray(20, 20 + b.readUInt32LE(12))); };
if (JSON.stringify(doc("bump-x.glb").materials[0].extensions) !== "{\"EXT_materials_bump\":{\"bumpFactor\":0.5}}") throw new Error("bump");
if (JSON.stringify(doc("vis-x.glb").nodes[0].extensions) !== "{\"KHR_node_visibility\":{\"visible\":true}}") throw new Error("visibility");
'
[ "$(keys ptr.glb)" = "$(keys ptr-x.glb)" ]
for f in foo mesh; do
	"$BIN/mlod-pack" -o $f.mlod $f.glb 2> $f.err
	grep -qxF "mlod-pack: $f.glb: the document chunk holds the input whole: extension KHR_animation_pointer may refer to meshes or accessors: the document is not stripped" $f.err
	[ "$(wc -c < $f.mlod)" -gt 300000 ]
	"$BIN/mlod-pack" -x $f.mlod -o $f-x.glb
	node "$ROOT/tests/validate.mjs" $f-x.glb > /dev/null
done
