# A glTF without a scene (valid: a library of nodes) gets one from the
# reader, with every root node but MSFT_lod levels (a note in --report
# says so), so the stage record has a home and the nodes the stages add
# for levels stay out of view: the piped pipeline packs one part with
# the stages' levels, as from the same input with its scene (before, the
# skeleton stage exited 4 "the document has no scene", and a pack of
# mlod-bgm's scene-less output counted each MSFT_lod level as a part).
set -e
node "$ROOT/tests/glb-edit.mjs" "$ROOT/samples/tubeman.glb" noscene.glb 'delete j.scenes; delete j.scene'
"$BIN/mlod-label" noscene.glb --report | grep -q -F '# note: the input has no scene: scene 0 added with its 2 root nodes, for the stage record'
"$BIN/mlod-label" noscene.glb | "$BIN/mlod-skelgraph" | "$BIN/mlod-bgm" | "$BIN/mlod-motion" > piped.glb
node "$ROOT/tests/validate.mjs" piped.glb | grep -q ': 0 errors'
"$BIN/mlod-pack" piped.glb -o piped.mlod --report > report.txt
grep -q -F ': 31 joints, 1 skins, 1 parts, 1 clips;' report.txt
grep -E -q '^skeleton +3 +input ' report.txt
grep -E -q '^mesh +5 +input ' report.txt
grep -E -q '^motion +4 +input ' report.txt
# mlod-bgm's levels in a document whose scene was then removed: still one part
"$BIN/mlod-bgm" "$ROOT/samples/tubeman.glb" -o levels.glb
node "$ROOT/tests/glb-edit.mjs" levels.glb levels-noscene.glb 'delete j.scenes; delete j.scene'
"$BIN/mlod-pack" levels-noscene.glb -o levels.mlod --report | grep -q -F ': 31 joints, 1 skins, 1 parts, 1 clips;'
