# mlod-pack --info --json (and --info --report=json, the same) parses; its
# totals equal the file size: the layers' stored bytes plus header, TOC and
# padding, and the chunks' stored bytes sum to the layers'; its skeleton
# lists every joint's name and parent, and its rest bounds have INFO's
# diagonal.
set -e
for s in tubeman.glb RobotExpressive.glb cmu_12_01_walk.bvh; do
	n=${s%.*}
	"$BIN/mlod-pack" "$ROOT/samples/$s" -o "$n.mlod" 2> /dev/null
	"$BIN/mlod-pack" --info "$n.mlod" --json > "$n.json"
	"$BIN/mlod-pack" --info "$n.mlod" --report=json > "$n.r.json"
	cmp "$n.json" "$n.r.json"
	node - "$n.mlod" "$n.json" <<'JS'
const fs = require('fs');
const [pack, file] = process.argv.slice(2);
const j = JSON.parse(fs.readFileSync(file, 'utf8'));
const size = fs.statSync(pack).size;
if (j.size !== size || j.total !== size) throw new Error(`size ${j.size}, total ${j.total}, file ${size}`);
let layers = 0;
for (const l of Object.values(j.layers)) layers += l.stored;
if (layers + j.overhead !== size) throw new Error(`layers ${layers} + overhead ${j.overhead} != ${size}`);
const chunks = j.chunks.reduce((a, c) => a + c.stored, 0);
if (chunks !== layers || j.stored !== chunks) throw new Error('chunk sum');
if (!(j.first_drawable > 0 && j.first_drawable <= size)) throw new Error('first_drawable');
for (const c of j.chunks) {
	if (c.type === 'ANIM' && typeof c.clip !== 'string') throw new Error('ANIM without a clip name');
	if (c.level > 0 && c.type !== 'DOC' && !(c.distance >= 0 && c.error >= 0)) throw new Error('error/distance');
}
// the joints' names and parents (parents first) and the rest bounds, whose diagonal INFO gives
if (j.skeleton.length !== j.joints || j.skeleton[0].parent !== -1) throw new Error('skeleton');
j.skeleton.forEach((s, i) => {
	if (typeof s.joint !== 'string' || !(s.parent < i)) throw new Error(`joint ${i}`);
});
const d = Math.hypot(...j.bounds_max.map((x, k) => x - j.bounds_min[k]));
if (!(Math.abs(d - j.diagonal) <= 1e-4 * j.diagonal)) throw new Error(`bounds' diagonal ${d}, INFO ${j.diagonal}`);
JS
grep -q '"joint": "Hips", "parent": -1' tubeman.json
done
