# A clip that animates no joint (a camera's "dolly", morph weights alone in
# "blink") is kept as it is with a note, not refused: mlod-motion and
# mlod-pack exited 2 ("clip \"dolly\": no channels to reduce"), so a piped
# pipeline stopped there while the other stages took the file.
set -e
node "$ROOT/tests/glb-edit.mjs" "$ROOT/samples/tubeman.glb" in.glb '
const n = j.accessors[j.meshes[0].primitives[0].attributes.POSITION].count, b = Buffer.alloc(n * 12 + 60);
b.writeFloatLE(0.1, 0);
[0, 1, 2, 0, 0, 10, 0, 1, 10, 0, 2, 10, 0, 1, 0].forEach((v, i) => b.writeFloatLE(v, n * 12 + 4 * i));
j.buffers.push({byteLength: b.length, uri: "data:application/octet-stream;base64," + b.toString("base64")});
const B = j.buffers.length - 1, V = j.bufferViews.length, A = j.accessors.length;
const view = (o, l) => ({buffer: B, byteOffset: o, byteLength: l});
j.bufferViews.push(view(0, n * 12), view(n * 12, 12), view(n * 12 + 12, 36), view(n * 12 + 48, 12));
j.accessors.push({bufferView: V, componentType: 5126, count: n, type: "VEC3", min: [0, 0, 0], max: [0.1, 0, 0]},
  {bufferView: V + 1, componentType: 5126, count: 3, type: "SCALAR", min: [0], max: [2]},
  {bufferView: V + 2, componentType: 5126, count: 3, type: "VEC3"},
  {bufferView: V + 3, componentType: 5126, count: 3, type: "SCALAR"});
j.meshes[0].primitives[0].targets = [{POSITION: A}];
j.meshes[0].weights = [0];
j.cameras = [{type: "perspective", perspective: {yfov: 1, znear: 0.1}}];
j.nodes.push({name: "cam", camera: 0});
j.scenes[0].nodes.push(j.nodes.length - 1);
j.animations.push({name: "dolly", samplers: [{input: A + 1, output: A + 2}],
  channels: [{sampler: 0, target: {node: j.nodes.length - 1, path: "translation"}}]});
j.animations.push({name: "blink", samplers: [{input: A + 1, output: A + 3}],
  channels: [{sampler: 0, target: {node: 38, path: "weights"}}]});
'
"$BIN/mlod-motion" in.glb > out.glb 2> err
cat > want <<'EOF'
mlod-motion: in.glb: clip "dolly" animates no joint and no morph weights: nothing to reduce, no levels (the animation is kept as it is)
mlod-motion: in.glb: clip "blink" animates no joint, only morph weights (1 channel): no levels (the animation is kept as it is)
EOF
diff want err
node "$ROOT/tests/validate.mjs" out.glb > /dev/null
# walk gets its levels; dolly and blink are there as they were, without levels.
node -e '
const fs = require("fs");
const read = (f) => { const b = fs.readFileSync(f); return JSON.parse(b.subarray(20, 20 + b.readUInt32LE(12)).toString()); };
const i = read("in.glb"), o = read("out.glb");
const names = o.animations.map((a) => a.name).join(",");
if (names !== "walk,dolly,blink,walk@lod1,walk@lod2,walk@lod3") throw new Error(names);
for (const k of [1, 2]) {
	const a = i.animations[k], b = o.animations[k];
	if (JSON.stringify(a.channels) !== JSON.stringify(b.channels) || b.samplers.length !== a.samplers.length)
		throw new Error(a.name + " changed");
}
'
# The report lists the clips; mlod-pack writes the pack with all three clips.
"$BIN/mlod-motion" --report in.glb > table 2> /dev/null
grep -q "^dolly  *0 " table
"$BIN/mlod-pack" in.glb -o c.mlod 2> /dev/null
"$BIN/mlod-pack" --info c.mlod > info
test "$(grep -c '^ANIM .* dolly ' info)" -ge 1
test "$(grep -c '^ANIM .* blink ' info)" -ge 1
# -x gives them back from the document (it exited 2: "clip \"dolly\": no
# channels (a glTF animation needs one)"), without levels; the glb validates
# and packs again.
"$BIN/mlod-pack" -x c.mlod -o x.glb
node "$ROOT/tests/validate.mjs" x.glb | grep -q ': 0 errors'
node -e '
const fs = require("fs");
const b = fs.readFileSync("x.glb"), o = JSON.parse(b.subarray(20, 20 + b.readUInt32LE(12)).toString());
const names = o.animations.map((a) => a.name).sort().join(",");
if (names !== "blink,dolly,walk,walk@lod1,walk@lod2,walk@lod3") throw new Error(names);
const d = o.animations.find((a) => a.name === "dolly");
if (d.channels.length !== 1 || o.nodes[d.channels[0].target.node].name !== "cam") throw new Error("dolly");
'
"$BIN/mlod-pack" x.glb -o re.mlod 2> /dev/null
