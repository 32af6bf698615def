# mlod-pack -x on every sample: pack, unpack, and the unpacked glb passes
# the Khronos validator with zero errors; it holds MSFT_lod level nodes
# (glb samples), "<clip>@lod<k>" animations and, for tubeman, the
# skeleton-level skins ("<skin>@lod<k>"); the glb samples' lossless
# fields come back exactly (pack_unpack_lossless.mjs). tests/unit/test_unpack.c
# measures the geometry and the clips against the input.
set -e
for s in tubeman.glb RobotExpressive.glb cmu_12_01_walk.bvh; do
	n=${s%.*}
	"$BIN/mlod-pack" "$ROOT/samples/$s" -o "$n.mlod" 2> /dev/null
	"$BIN/mlod-pack" -x "$n.mlod" -o "$n.x.glb"
	node "$ROOT/tests/validate.mjs" "$n.x.glb" >&2
	node - "$n.x.glb" "$s" <<'JS'
const fs = require('fs');
const [file, sample] = process.argv.slice(2);
const b = fs.readFileSync(file);
const json = JSON.parse(b.subarray(20, 20 + b.readUInt32LE(12)).toString());
const anims = (json.animations || []).map(a => a.name);
if (!anims.some(n => /@lod1$/.test(n))) throw new Error(`${sample}: no <clip>@lod1 animation: ${anims}`);
if (sample.endsWith('.glb')) {
	const lod = (json.nodes || []).filter(n => n.extensions && n.extensions.MSFT_lod);
	if (!lod.length) throw new Error(`${sample}: no MSFT_lod node`);
	for (const n of lod)
		if (!n.extras || n.extras.MSFT_screencoverage.length !== n.extensions.MSFT_lod.ids.length + 1)
			throw new Error(`${sample}: MSFT_screencoverage`);
	if (!json.extensionsUsed.includes('MSFT_lod')) throw new Error('extensionsUsed');
}
if (sample === 'tubeman.glb' && !json.skins.some(s => /@lod1$/.test(s.name || '')))
	throw new Error('tubeman: no skeleton-level skin');
JS
	case $s in
	*.glb) node "$ROOT/tests/cli/pack_unpack_lossless.mjs" "$ROOT/samples/$s" "$n.x.glb" ;;
	esac
done
