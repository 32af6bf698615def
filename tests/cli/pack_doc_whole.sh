# A document using an extension that may refer to accessors cannot be
# stripped safely: the DOC chunk holds the input glb byte for byte, and the
# report says why.
set -e
node "$ROOT/tests/glb-edit.mjs" "$ROOT/samples/tubeman.glb" ext.glb 'j.extensionsUsed = (j.extensionsUsed || []).concat(["EXT_example_refs"]);'
"$BIN/mlod-pack" --no-skeleton-levels --no-mesh-levels --no-motion-levels ext.glb -o ext.mlod --report=json > r.json
node "$ROOT/tests/cli/pack_check.mjs" ext.mlod --doc doc.glb > /dev/null
cmp doc.glb ext.glb
grep -q 'the document chunk holds the input whole: extension EXT_example_refs may refer to meshes or accessors' r.json
