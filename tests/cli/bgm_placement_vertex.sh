# -p vertex: each collapse keeps one of its vertices whole, so every vertex
# of every level is a vertex of the input (level 0) with the same position,
# normal, UVs, tangent, colour, joints, weights and morph target offsets,
# bit for bit: checked on the split glbs against the input's accessors
# (the tubeman, smooth; the robot, hard normal edges and 19 primitives).
# The same check fails on the default placement's levels.
set -e
"$BIN/mlod-bgm" --report=json -p vertex "$ROOT/samples/tubeman.glb" > r.json
node -e 'const r = JSON.parse(require("fs").readFileSync("r.json")); if (r.options.placement !== "vertex" || r.levels.length < 3) process.exit(1)'
for f in tubeman RobotExpressive; do
	mkdir "$f" "$f.default"
	"$BIN/mlod-bgm" -p vertex -s "$f" -o "$f.glb" "$ROOT/samples/$f.glb"
	test -f "$f/$f.lod3.glb"
	node "$ROOT/tests/cli/level-vertices.mjs" --strict "$ROOT/samples/$f.glb" "$f"/*.glb > /dev/null
	"$BIN/mlod-bgm" -s "$f.default" -o "$f.default.glb" "$ROOT/samples/$f.glb"
	if node "$ROOT/tests/cli/level-vertices.mjs" --strict "$ROOT/samples/$f.glb" "$f.default"/*.glb > /dev/null 2>&1; then
		echo "$f: the default placement's levels passed: the check cannot tell" >&2
		exit 1
	fi
done
# mlod-pack takes the option too; same bytes twice.
"$BIN/mlod-pack" -p vertex -o a.mlod "$ROOT/samples/tubeman.glb"
"$BIN/mlod-pack" -p vertex -j 1 -o b.mlod "$ROOT/samples/tubeman.glb"
cmp a.mlod b.mlod
