# --max-error: every level within the bound, coarser ones first failing it.
set -e
"$BIN/mlod-bgm" --max-error 1 --report=json "$ROOT/samples/tubeman.glb" > r.json
node -e '
const r = JSON.parse(require("fs").readFileSync("r.json"));
if (r.levels.length < 2) throw new Error("levels: " + r.levels.length);
for (const l of r.levels) if (l.error_percent.max > 1) throw new Error("over the bound: " + l.error_percent.max);
'
# The paper's compactness order has no level this close (the default's
# edge collapses along the capsules' straight sides cost nothing).
"$BIN/mlod-bgm" --max-error 0.001 --cost compactness -o out.glb "$ROOT/samples/tubeman.glb" 2> err.txt
grep -q 'no mesh level within --max-error' err.txt
node "$ROOT/tests/validate.mjs" out.glb > /dev/null
