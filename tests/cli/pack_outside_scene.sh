# Meshes the default scene does not show (the character in a second
# scene, a prop on a node no scene lists) stay whole in the document
# chunk, with a warning, and -x gives them back: they lost their
# triangles to a stripped DOC before, and -x refused the pack ("DOC: node
# 38 has mesh 0, whose triangles no MESH part of that node holds").
node "$ROOT/tests/glb-edit.mjs" "$ROOT/samples/tubeman.glb" scenes.glb \
	'j.nodes.push({ name: "marker" });
	 j.scenes = [{ nodes: [j.nodes.length - 1] }, { nodes: j.scenes[j.scene || 0].nodes }]; j.scene = 0;' || exit 1
node "$ROOT/tests/glb-edit.mjs" "$ROOT/samples/tubeman.glb" orphan.glb \
	'j.meshes.push(JSON.parse(JSON.stringify(j.meshes[0]))); j.meshes[1].name = "prop";
	 delete j.meshes[1].primitives[0].attributes.JOINTS_0; delete j.meshes[1].primitives[0].attributes.WEIGHTS_0;
	 j.nodes.push({ name: "prop", mesh: 1 });' || exit 1
for f in scenes orphan; do
	"$BIN/mlod-pack" -o $f.mlod $f.glb || exit 1
	"$BIN/mlod-pack" -x $f.mlod -o $f.x.glb || exit 1
	node "$ROOT/tests/validate.mjs" $f.x.glb > val.txt || { cat val.txt >&2; exit 1; }
	grep -q ' 0 errors' val.txt || { cat val.txt >&2; exit 1; }
done
# the kept meshes have their triangles (23,328 indices each)
node -e '
const fs = require("fs");
for (const [f, name] of [["scenes.x.glb", "tubeman"], ["orphan.x.glb", "prop"]]) {
	const b = fs.readFileSync(f), j = JSON.parse(b.subarray(20, 20 + b.readUInt32LE(12)));
	const m = j.meshes.filter(m => m.name === name && m.primitives[0].indices !== undefined &&
		j.accessors[m.primitives[0].indices].count === 23328);
	if (m.length < 1) throw new Error(f + ": mesh " + name + " lost its triangles");
}' || exit 1
