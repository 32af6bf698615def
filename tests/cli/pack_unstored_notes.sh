# What mlod-pack does not keep, said on stderr with exit 0: morph target
# normal deltas (the pack stores position deltas; they went silently),
# and a glTF whose default scene has no triangle list (a mesh of
# triangle strips only: the pack had no mesh levels, and said nothing).
node "$ROOT/tests/glb-edit.mjs" "$ROOT/samples/RobotExpressive.glb" morph.glb \
	'for (const t of j.meshes[3].primitives[0].targets) t.NORMAL = t.POSITION;' || exit 1
"$BIN/mlod-pack" -o morph.mlod morph.glb || exit 1
node "$ROOT/tests/glb-edit.mjs" "$ROOT/samples/tubeman.glb" strip.glb \
	'for (const m of j.meshes) for (const p of m.primitives) p.mode = 5;' || exit 1
"$BIN/mlod-pack" -o strip.mlod strip.glb || exit 1
