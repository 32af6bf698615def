# meshopt-compressed input (made by gltfpack -c from tubeman.glb) is unsupported, exit 3.
"$BIN/mlod-label" "$ROOT/tests/data/bad/meshopt.glb"
