# meshopt-compressed input (made by gltfpack -c from tubeman.glb) is unsupported, exit 3.
cd "$ROOT" && "$BIN/mlod-label" tests/data/bad/meshopt.glb
