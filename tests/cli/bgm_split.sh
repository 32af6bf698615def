# --split writes one valid glb per level, each with fewer triangles.
set -e
mkdir lods
"$BIN/mlod-bgm" -s lods -R 0.5,0.2 -o out.glb "$ROOT/samples/tubeman.glb"
test -f lods/tubeman.lod1.glb && test -f lods/tubeman.lod2.glb && test ! -f lods/tubeman.lod3.glb
node "$ROOT/tests/validate.mjs" lods/tubeman.lod1.glb lods/tubeman.lod2.glb > /dev/null
"$BIN/mlod-bgm" --report=json lods/tubeman.lod2.glb > r.json
node -e 'const r = JSON.parse(require("fs").readFileSync("r.json")); if (r.triangles > Math.ceil(0.2 * 7776)) process.exit(1)'
