# A mesh animated by morph target weights alone, without joints
# (AnimatedMorphCube.gltf, assimp-testmodels): mlod-pack keeps the
# animation as the document's own (nothing for the motion layer: no
# joints) and exits 0, as with --no-motion-levels; -x gives it back with
# the input's key times and weights, and the glb validates; mlod-motion
# passes the input through with exit 0.
F=/usr/share/assimp/models/glTF2/glTF-Sample-Models/AnimatedMorphCube-glTF/AnimatedMorphCube.gltf
[ -f "$F" ] || exit 77
set -e
"$BIN/mlod-pack" "$F" -o cube.mlod 2> /dev/null
"$BIN/mlod-pack" --no-motion-levels "$F" -o cube2.mlod 2> /dev/null
"$BIN/mlod-motion" "$F" -o cube.m.glb 2> /dev/null
for p in cube cube2; do
	"$BIN/mlod-pack" -x $p.mlod -o $p.x.glb
	node "$ROOT/tests/validate.mjs" $p.x.glb >&2
	node - "$F" $p.x.glb <<'JS'
const fs = require('fs'), path = require('path');
const [input, file] = process.argv.slice(2);
const inp = JSON.parse(fs.readFileSync(input));
const inBin = fs.readFileSync(path.join(path.dirname(input), inp.buffers[0].uri));
const b = fs.readFileSync(file);
const jl = b.readUInt32LE(12);
const out = JSON.parse(b.subarray(20, 20 + jl).toString());
const outBin = b.subarray(20 + jl + 8);
const floats = (j, bin, a) => {
	const acc = j.accessors[a], v = j.bufferViews[acc.bufferView];
	const n = acc.count * { SCALAR: 1, VEC3: 3, VEC4: 4 }[acc.type];
	const at = (v.byteOffset || 0) + (acc.byteOffset || 0);
	return Array.from({ length: n }, (_, i) => bin.readFloatLE(at + 4 * i)).join(',');
};
const a0 = inp.animations[0];
const a1 = (out.animations || []).find(a => a.name === a0.name);
if (!a1) throw new Error(`${file}: no animation "${a0.name}"`);
const c0 = a0.channels[0], s0 = a0.samplers[c0.sampler];
const c1 = a1.channels.find(c => c.target.node === c0.target.node && c.target.path === 'weights');
if (!c1) throw new Error(`${file}: no weights channel on node ${c0.target.node}`);
const s1 = a1.samplers[c1.sampler];
for (const k of ['input', 'output'])
	if (floats(inp, inBin, s0[k]) !== floats(out, outBin, s1[k])) throw new Error(`${file}: sampler ${k} differs`);
if ((s1.interpolation || 'LINEAR') !== (s0.interpolation || 'LINEAR')) throw new Error('interpolation');
JS
done
