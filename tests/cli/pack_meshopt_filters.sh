# gltfpack -cc input: quantised (KHR_mesh_quantization) and meshopt-compressed
# with the OCTAHEDRAL, QUATERNION and EXPONENTIAL filters, through every
# stage and the pack: each stage's glb validates with 0 errors, and the pack
# has its levels. Positions decode to within gltfpack's quantisation of the
# original (its -cc keeps 14 bits).
set -e
gp=$ROOT/tests/node/node_modules/.bin/gltfpack
[ -x "$gp" ] || { echo "gltfpack is not installed in tests/node (scripts/install-deps)" >&2; exit 77; }
"$gp" -i "$ROOT/samples/tubeman.glb" -o cc.glb -cc > /dev/null
node -e '
const b = require("fs").readFileSync("cc.glb"), j = JSON.parse(b.subarray(20, 20 + b.readUInt32LE(12)).toString());
const f = new Set(j.bufferViews.map((v) => v.extensions && v.extensions.EXT_meshopt_compression && v.extensions.EXT_meshopt_compression.filter));
for (const want of ["OCTAHEDRAL", "QUATERNION", "EXPONENTIAL"]) if (!f.has(want)) throw new Error("no " + want);
'
"$BIN/mlod-label" cc.glb > s1.glb
"$BIN/mlod-skelgraph" s1.glb > s2.glb
"$BIN/mlod-bgm" s2.glb > s3.glb
"$BIN/mlod-motion" s3.glb > s4.glb
node "$ROOT/tests/validate.mjs" s1.glb s2.glb s3.glb s4.glb > /dev/null
"$BIN/mlod-pack" -o cc.mlod s4.glb
"$BIN/mlod-pack" --info cc.mlod > info.txt
grep -q 'levels: skeleton 3, mesh 5, motion 4' info.txt
