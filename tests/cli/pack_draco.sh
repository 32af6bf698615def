# mlod-pack --codec draco on the glb samples: every MESH chunk is Draco
# (codec 2; its own zstd stage at most, never the prefix stage), the other
# chunks meshopt; --info and --info --json say so; -x unpacks to a glb that
# passes the Khronos validator with MSFT_lod levels, as the meshopt pack's
# does, with the same lossless fields (pack_unpack_lossless.mjs) and the
# same triangle counts per level; one and two threads give the same bytes.
# tests/unit/test_pack_draco.c compares the decoded levels attribute by
# attribute.
set -e
"$BIN/mlod-pack" --codec draco -j 1 "$ROOT/samples/RobotExpressive.glb" -o j1.mlod 2> /dev/null
"$BIN/mlod-pack" --codec draco -j 2 "$ROOT/samples/RobotExpressive.glb" -o j2.mlod 2> /dev/null
cmp j1.mlod j2.mlod
for s in tubeman.glb RobotExpressive.glb; do
	n=${s%.*}
	"$BIN/mlod-pack" --codec draco "$ROOT/samples/$s" -o "$n.d.mlod" 2> /dev/null
	"$BIN/mlod-pack" "$ROOT/samples/$s" -o "$n.m.mlod" 2> /dev/null
	"$BIN/mlod-pack" --info "$n.d.mlod" > "$n.txt"
	grep -q "^MESH  mesh         0  -  *draco" "$n.txt"
	# every MESH line draco (with zstd or without), none with the prefix stage
	[ "$(grep -c '^MESH ' "$n.txt")" = "$(grep -c -E '^MESH .* draco(\+zstd)? ' "$n.txt")" ]
	! grep -q -E '^(MESH .*zstd-prefix|SKEL .*draco|ANIM .*draco)' "$n.txt"
	grep -q "^SKEL  skeleton     0  -  *meshopt" "$n.txt"
	"$BIN/mlod-pack" --info "$n.d.mlod" --json > "$n.json"
	node -e '
const j = JSON.parse(require("fs").readFileSync(process.argv[1]));
const mesh = j.chunks.filter(c => c.type === "MESH");
if (!mesh.length || mesh.some(c => c.codec !== "draco" || c.entropy === "zstd-prefix")) throw new Error("json codecs");
' "$n.json"
	"$BIN/mlod-pack" -x "$n.d.mlod" -o "$n.d.glb"
	"$BIN/mlod-pack" -x "$n.m.mlod" -o "$n.m.glb"
	node "$ROOT/tests/validate.mjs" "$n.d.glb" >&2
	node "$ROOT/tests/cli/pack_unpack_lossless.mjs" "$ROOT/samples/$s" "$n.d.glb"
	node - "$n.d.glb" "$n.m.glb" <<'JS'
const fs = require('fs');
const gl = f => { const b = fs.readFileSync(f); return JSON.parse(b.subarray(20, 20 + b.readUInt32LE(12)).toString()); };
const [d, m] = process.argv.slice(2).map(gl);
const lod = j => (j.nodes || []).filter(n => n.extensions && n.extensions.MSFT_lod).map(n => n.extensions.MSFT_lod.ids.length);
if (!lod(d).length || JSON.stringify(lod(d)) !== JSON.stringify(lod(m))) throw new Error('MSFT_lod levels differ');
// per mesh, per primitive: the index count (triangles) as meshopt's
const tri = j => j.meshes.map(me => me.primitives.map(p => p.indices === undefined ? -1 : j.accessors[p.indices].count));
if (JSON.stringify(tri(d)) !== JSON.stringify(tri(m))) throw new Error('triangle counts differ');
JS
done
