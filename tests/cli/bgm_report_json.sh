# --report=json: the default levels at 50%, 25%, 10% and 3% of the triangles,
# ordered (fewer triangles, larger error), each measured.
set -e
"$BIN/mlod-bgm" --report=json "$ROOT/samples/tubeman.glb" > r.json
node -e '
const r = JSON.parse(require("fs").readFileSync("r.json"));
const L = r.levels;
if (L.length !== 4) throw new Error("levels: " + L.length);
const want = [0.5, 0.25, 0.1, 0.03];
let prev = {triangles: r.triangles, error_percent: {mean: 0, max: 0}};
L.forEach((l, k) => {
  if (l.ratio !== want[k]) throw new Error("ratio " + l.ratio);
  if (l.triangles > Math.ceil(want[k] * r.triangles)) throw new Error("level " + k + ": " + l.triangles + " triangles");
  if (!(l.triangles < prev.triangles)) throw new Error("triangles not decreasing");
  if (!(l.error_percent.mean > prev.error_percent.mean && l.error_percent.max >= prev.error_percent.max))
    throw new Error("errors not increasing at level " + (k + 1));
  if (!(l.build_ms > 0 && l.collapse_ms > 0 && l.caps >= 0 && l.vertices > 0)) throw new Error("fields");
  prev = l;
});
if (r.options.cost !== "posed" || r.options.eligibility !== "all") throw new Error("defaults");
if (!(r.measure_ms > 0)) throw new Error("measure_ms: " + r.measure_ms);
'
