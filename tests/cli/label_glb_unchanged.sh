# mlod-label < x.glb > y.glb keeps everything but the joints' extras.mlod.
set -e
"$BIN/mlod-label" < "$ROOT/samples/RobotExpressive.glb" > y.glb
node "$ROOT/tests/gltf-same.mjs" --ignore-extras mlod "$ROOT/samples/RobotExpressive.glb" y.glb
node "$ROOT/tests/validate.mjs" y.glb > /dev/null
