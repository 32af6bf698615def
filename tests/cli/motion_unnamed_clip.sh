# An unnamed clip (the tubeman's walk with its name removed): mlod-motion
# names its levels animation_0@lod1.. (three.js's name for the clip), and
# mlod-pack -x names them after the clip's index in its output; both wrote
# "@lod1", "@lod2", "@lod3" before.
node "$ROOT/tests/glb-edit.mjs" "$ROOT/samples/tubeman.glb" noname.glb 'for (const a of j.animations) delete a.name;' ||
	exit 1
"$BIN/mlod-motion" noname.glb -o motion.glb || exit 1
"$BIN/mlod-pack" noname.glb -o noname.mlod || exit 1
"$BIN/mlod-pack" -x noname.mlod -o x.glb || exit 1
for f in motion x; do
	node -e '
const b = require("fs").readFileSync(process.argv[1]), j = JSON.parse(b.subarray(20, 20 + b.readUInt32LE(12)));
const names = j.animations.map((a) => a.name === undefined ? "(none)" : a.name).join(",");
if (names !== "(none),animation_0@lod1,animation_0@lod2,animation_0@lod3") {
	console.error(`${process.argv[1]}: ${names}`);
	process.exit(1);
}' $f.glb || exit 1
	node "$ROOT/tests/validate.mjs" $f.glb | grep -q ' 0 errors' || exit 1
done
