# A glTF of one node (no joint, no mesh): mlod-pack still writes a pack
# (exit 0), and says on stderr that there was nothing to pack, as the other
# stages do ("nothing to label", "no triangle mesh"); it said nothing.
printf '{"asset":{"version":"2.0"},"nodes":[{"name":"a"}],"scenes":[{"nodes":[0]}]}' > one.gltf
"$BIN/mlod-pack" one.gltf -o one.mlod || exit 1
"$BIN/mlod-pack" --info=one.mlod > info.txt || exit 1
grep -q '^# total ' info.txt || { cat info.txt >&2; exit 1; }
