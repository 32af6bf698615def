# The default (posed) cost beats the paper's compactness order on posed
# error at equal triangle counts on the sample, as measured for the default.
set -e
"$BIN/mlod-bgm" --report=json "$ROOT/samples/tubeman.glb" > posed.json
"$BIN/mlod-bgm" --report=json --cost compactness -E all "$ROOT/samples/tubeman.glb" > paper.json
node -e '
const fs = require("fs");
const a = JSON.parse(fs.readFileSync("posed.json")), b = JSON.parse(fs.readFileSync("paper.json"));
if (b.options.placement !== "barycenter") throw new Error("compactness places at the barycenter");
let compared = 0;
a.levels.forEach((l, k) => {
  const m = b.levels[k];
  if (!m || l.triangles !== m.triangles) return; /* compactness may stop early */
  compared++;
  if (!(l.error_percent.mean < m.error_percent.mean)) throw new Error("level " + (k + 1) + ": posed not better");
});
if (compared < 2) throw new Error("compared " + compared + " levels");
'
