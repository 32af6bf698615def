# --entropy: zstd (the default) puts every chunk but INFO through zstd where
# that stores fewer bytes; none stores the codec's bytes alone. The zstd
# pack is smaller, both check out (tests/cli/pack_check.mjs undoes the
# stage with the zstd tool), and both unpack to the same glb byte for byte.
# Format 6.0: the robot's finer MESH levels are smaller coded on the coarser
# ones (entropy stage 2, zstd-prefix; pack_check.mjs decodes them with the
# zstd tool's --patch-from), the coarsest MESH level never is.
set -e
"$BIN/mlod-pack" "$ROOT/samples/RobotExpressive.glb" -o z.mlod 2> /dev/null
"$BIN/mlod-pack" --entropy zstd "$ROOT/samples/RobotExpressive.glb" -o z2.mlod 2> /dev/null
"$BIN/mlod-pack" --entropy none "$ROOT/samples/RobotExpressive.glb" -o n.mlod 2> /dev/null
cmp z.mlod z2.mlod
node "$ROOT/tests/cli/pack_check.mjs" z.mlod > z.json
node "$ROOT/tests/cli/pack_check.mjs" n.mlod > n.json
node - <<'JS'
const fs = require('fs');
const z = JSON.parse(fs.readFileSync('z.json')), n = JSON.parse(fs.readFileSync('n.json'));
if (JSON.stringify(z.entropy) !== '[0,1,2]' || JSON.stringify(n.entropy) !== '[0]') throw new Error(`entropy ${z.entropy} / ${n.entropy}`);
if (!(z.size < 0.6 * n.size)) throw new Error(`zstd ${z.size}, none ${n.size}`);
for (const k of ['joints', 'skeleton_levels', 'mesh_levels', 'motion_levels', 'clips', 'parts']) if (z[k] !== n[k]) throw new Error(k);
if (!(z.first_drawable < n.first_drawable)) throw new Error(`first_drawable ${z.first_drawable} / ${n.first_drawable}`);
JS
"$BIN/mlod-pack" -x z.mlod -o z.glb
"$BIN/mlod-pack" -x n.mlod -o n.glb
cmp z.glb n.glb
# --info: the DOC line says none+zstd in one, none in the other
"$BIN/mlod-pack" --info z.mlod | grep -q "^DOC   none         0  -  *none+zstd  "
"$BIN/mlod-pack" --info n.mlod | grep -q "^DOC   none         0  -  *none  "
"$BIN/mlod-pack" --info z.mlod --json | grep -q '"type": "DOC", .*"codec": "none", "entropy": "zstd"'
# --info: MESH level 2 says meshopt+zstd-prefix, the coarsest MESH level (4) meshopt+zstd
"$BIN/mlod-pack" --info z.mlod | grep -q "^MESH  mesh         2  -  *meshopt+zstd-prefix  "
"$BIN/mlod-pack" --info z.mlod | grep -q "^MESH  mesh         4  -  *meshopt+zstd  "
"$BIN/mlod-pack" --info z.mlod --json | grep -q '"type": "MESH", "layer": "mesh", "level": 2, .*"entropy": "zstd-prefix"'
