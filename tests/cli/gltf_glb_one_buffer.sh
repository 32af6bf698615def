# A glb holds one BIN chunk: tubeman as a glTF (three/tubeman.gltf: the
# pack keeps the name) with its bytes in three .bin files (each file's views
# 4-byte aligned in it, a view at offset 0 without a byteOffset) comes out
# of every tool as a glb with one buffer, the three appended to it, rather
# than buffers 1 and 2 as base64 data: URIs (a third larger; measured in
# bench/RESULTS.md). The document is the one the single-buffer glb gives,
# and the validator finds no error. An extension that names a buffer by its
# index keeps the buffers as they are.
set -e
mkdir three
node -e '
const fs = require("fs");
const b = fs.readFileSync(process.argv[1]);
const jl = b.readUInt32LE(12);
const j = JSON.parse(b.subarray(20, 20 + jl).toString("utf8"));
const bin = b.subarray(28 + jl, 28 + jl + b.readUInt32LE(20 + jl));
const parts = [[], [], []], sizes = [0, 0, 0];
j.bufferViews.forEach((v, i) => {
	const k = i % 3, at = (sizes[k] + 3) & ~3;
	parts[k].push(Buffer.alloc(at - sizes[k]), bin.subarray(v.byteOffset || 0, (v.byteOffset || 0) + v.byteLength));
	v.buffer = k;
	if (at) v.byteOffset = at; else delete v.byteOffset;
	sizes[k] = at + v.byteLength;
});
j.buffers = parts.map((p, k) => {
	fs.writeFileSync(`three/part${k}.bin`, Buffer.concat(p));
	return { uri: `part${k}.bin`, byteLength: sizes[k] };
});
fs.writeFileSync("three/tubeman.gltf", JSON.stringify(j));
' "$ROOT/samples/tubeman.glb"
one_buffer() {
	node -e '
const b = require("fs").readFileSync(process.argv[1]);
const j = JSON.parse(b.subarray(20, 20 + b.readUInt32LE(12)).toString("utf8"));
if (j.buffers.length !== 1 || j.buffers[0].uri !== undefined)
	throw new Error(`${process.argv[1]}: buffers ${JSON.stringify(j.buffers.map((x) => (x.uri || "").slice(0, 40)))}`);
for (const v of j.bufferViews)
	if (v.buffer !== 0 || (v.byteOffset || 0) % 4) throw new Error(`${process.argv[1]}: view ${JSON.stringify(v)}`);
' "$1"
}
for t in label skelgraph bgm motion; do
	"$BIN/mlod-$t" -o "$t-one.glb" "$ROOT/samples/tubeman.glb"
	"$BIN/mlod-$t" -o "$t-three.glb" three/tubeman.gltf
	one_buffer "$t-three.glb"
	node "$ROOT/tests/gltf-same.mjs" "$t-one.glb" "$t-three.glb"
done
"$BIN/mlod-pack" -o one.mlod "$ROOT/samples/tubeman.glb"
"$BIN/mlod-pack" -o three.mlod three/tubeman.gltf
"$BIN/mlod-pack" -x one.mlod -o pack-one.glb
"$BIN/mlod-pack" -x three.mlod -o pack-three.glb
one_buffer pack-three.glb
node "$ROOT/tests/gltf-same.mjs" pack-one.glb pack-three.glb
node "$ROOT/tests/validate.mjs" label-three.glb skelgraph-three.glb bgm-three.glb motion-three.glb pack-three.glb > /dev/null
node -e '
const fs = require("fs");
const j = JSON.parse(fs.readFileSync("three/tubeman.gltf", "utf8"));
j.bufferViews[0].extensions = { EXT_mlod_test: { buffer: 2 } };
j.extensionsUsed = (j.extensionsUsed || []).concat(["EXT_mlod_test"]);
fs.writeFileSync("three/named.gltf", JSON.stringify(j));
'
"$BIN/mlod-label" -o named.glb three/named.gltf
node -e '
const b = require("fs").readFileSync("named.glb");
const j = JSON.parse(b.subarray(20, 20 + b.readUInt32LE(12)).toString("utf8"));
if (j.buffers.length !== 3 || j.bufferViews[0].extensions.EXT_mlod_test.buffer !== 2)
	throw new Error(`buffers ${j.buffers.length}, ${JSON.stringify(j.bufferViews[0])}`);
'
