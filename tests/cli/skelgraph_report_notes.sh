# mlod-skelgraph's JSON report has "notes", as the other tools' do: the
# note said on stderr when no level fits the bound (the joint's name quoted),
# and the input's notes; the table has it as "# note:".
set -e
cd "$ROOT"
"$BIN/mlod-skelgraph" --report=json -e 0.001 samples/RobotExpressive.glb > "$OLDPWD/r.json" 2> /dev/null
"$BIN/mlod-skelgraph" --report -e 0.001 samples/RobotExpressive.glb > "$OLDPWD/r.txt" 2> /dev/null
"$BIN/mlod-skelgraph" --report=json samples/cmu_12_01_walk.bvh > "$OLDPWD/w.json"
cd "$OLDPWD"
grep -q '^  "notes": "no skeleton level within --max-error 0.001%: removing \\"[^"]*\\" alone costs [0-9.]*%; ' r.json
grep -q '^# note: no skeleton level within --max-error 0.001%: removing "[^"]*" alone costs' r.txt
grep -q '^  "notes": ""$' w.json
node -e 'for (const f of ["r.json", "w.json"]) JSON.parse(require("fs").readFileSync(f, "utf8"))'
