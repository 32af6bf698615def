# A glTF whose external image is missing (or read from standard input,
# with no directory to find it in): the output keeps the URI, as
# documented, and the tool now says so, naming the URI (it was silent, and
# the output's URI dangled without a word).
printf '{"asset":{"version":"2.0"},"images":[{"uri":"nothere.png"}],"nodes":[{"name":"a"}],"scenes":[{"nodes":[0]}]}' > miss.gltf
"$BIN/mlod-label" miss.gltf -o out.glb || exit 1
"$BIN/mlod-label" < miss.gltf > out2.glb || exit 1
grep -q nothere.png out.glb || exit 1
