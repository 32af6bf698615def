# An input with MSFT_lod levels of its own (a low-resolution copy of the
# tubeman on node 39, listed by node 38): mlod-bgm replaces them with its
# levels and says so (the user's node stays in the glb, outside the list);
# mlod-pack says it does not keep them. Both were silent.
node "$ROOT/tests/glb-edit.mjs" "$ROOT/samples/tubeman.glb" lod.glb \
	'j.meshes.push(JSON.parse(JSON.stringify(j.meshes[0]))); j.meshes[1].name = "tubeman_lowres";
	 j.nodes.push({ name: "tubeman_userlod1", mesh: 1, skin: j.nodes[38].skin });
	 j.nodes[38].extensions = { MSFT_lod: { ids: [j.nodes.length - 1] } };
	 j.extensionsUsed = (j.extensionsUsed || []).concat(["MSFT_lod"]);' || exit 1
"$BIN/mlod-bgm" -o bgm.glb lod.glb || exit 1
node "$ROOT/tests/validate.mjs" bgm.glb | grep -q ' 0 errors' || exit 1
"$BIN/mlod-pack" -o lod.mlod lod.glb || exit 1
