# A mesh skinned by two different skins (the tubeman's mesh on a second
# node with a copy of its skin): mlod-skelgraph refuses it (exit 3), as its
# levels would transfer the mesh's weights two ways; mlod-pack, which was
# refused the same way, now packs the mesh and motion levels with skeleton
# level 0 alone and a warning, and the pack unpacks to a valid glb.
node "$ROOT/tests/glb-edit.mjs" "$ROOT/samples/tubeman.glb" two.glb \
	'j.skins.push(JSON.parse(JSON.stringify(j.skins[0])));
	 j.nodes.push({ name: "tubeman2", mesh: 0, skin: 1, translation: [10, 0, 0] });
	 j.scenes[0].nodes.push(j.nodes.length - 1);' || exit 1
"$BIN/mlod-skelgraph" two.glb -o s.glb 2> s.err && exit 1
grep -qxF 'mlod-skelgraph: two.glb: mesh 0 "tubeman" is skinned by two different skins (0 and 1)' s.err || exit 1
"$BIN/mlod-pack" two.glb -o two.mlod || exit 1
"$BIN/mlod-pack" --info two.mlod | grep -q '^# character .two.: 31 joints, 2 skins, 2 parts, 1 clips; levels: skeleton 1, mesh 5, motion 4;' ||
	exit 1
"$BIN/mlod-pack" -x two.mlod -o x.glb || exit 1
node "$ROOT/tests/validate.mjs" x.glb | grep -q ' 0 errors' || exit 1
