# mlod-skelgraph refuses a joint's label record that is there but
# malformed (exit 2), naming the node and the key.
set -e
"$BIN/mlod-label" "$ROOT/samples/tubeman.glb" > labelled.glb
node "$ROOT/tests/glb-edit.mjs" labelled.glb bad.glb 'j.nodes[0].extras.mlod.label = "chief"'
"$BIN/mlod-skelgraph" bad.glb > out.glb
