# A small file must not make mlod decode or copy without bound. Two
# crafted files read as before, each shared range once: gltfpack -noq -c
# tubeman with 2,000 more copies of its largest meshopt buffer view, and
# the plain tubeman with 300 more views over its whole BIN chunk while
# extensionsUsed names EXT_meshopt_compression. A third names one meshopt
# stream under its four filters, four distinct decodings of 1 MiB from a
# 17 KB file: past the decoded-bytes budget, exit 2 with its message.
set -e
gp=$ROOT/tests/node/node_modules/.bin/gltfpack
[ -x "$gp" ] || { echo "gltfpack is not installed in tests/node (scripts/install-deps)" >&2; exit 77; }
"$gp" -i "$ROOT/samples/tubeman.glb" -o packed.glb -noq -c > /dev/null
node "$ROOT/tests/glb-edit.mjs" packed.glb copies.glb '
let best = -1;
j.bufferViews.forEach((v, i) => {
	if (v.extensions && v.extensions.EXT_meshopt_compression && (best < 0 || v.byteLength > j.bufferViews[best].byteLength))
		best = i;
});
for (let k = 0; k < 2000; k++) j.bufferViews.push(JSON.parse(JSON.stringify(j.bufferViews[best])));'
node "$ROOT/tests/glb-edit.mjs" "$ROOT/samples/tubeman.glb" overlap.glb '
for (let k = 0; k < 300; k++) j.bufferViews.push({ buffer: 0, byteLength: j.buffers[0].byteLength });
j.extensionsUsed = (j.extensionsUsed || []).concat(["EXT_meshopt_compression"]);'
"$BIN/mlod-label" -o copies.l.glb copies.glb
"$BIN/mlod-label" -o overlap.l.glb overlap.glb
node "$ROOT/tests/cli/meshopt_zeros.mjs" "$ROOT" zeros.glb
set +e
"$BIN/mlod-label" -o zeros.l.glb zeros.glb
