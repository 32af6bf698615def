# A stage run again on its own output passes it through, unchanged, with
# a note (exit 0): mlod-skelgraph, mlod-bgm and mlod-motion used to stack
# new levels on the old ones (skins 3 -> 9; meshes 5 -> 9 with the old
# level nodes left unused; 'walk@lod1@lod1' animations baked from the old
# levels).
set -e
"$BIN/mlod-skelgraph" "$ROOT/samples/tubeman.glb" -o s1.glb
"$BIN/mlod-skelgraph" s1.glb -o s2.glb 2> s.err
cmp s1.glb s2.glb
grep -q -F 'mlod-skelgraph: s1.glb: the input already has 2 skeleton levels: written unchanged; run mlod-skelgraph on the input without them to bake them again' s.err
"$BIN/mlod-bgm" "$ROOT/samples/tubeman.glb" -o g1.glb
"$BIN/mlod-bgm" g1.glb -o g2.glb 2> g.err
cmp g1.glb g2.glb
grep -q -F 'mlod-bgm: g1.glb: the input already has 4 mesh levels (MSFT_lod): written unchanged; run mlod-bgm on the input without them to bake them again' g.err
"$BIN/mlod-motion" "$ROOT/samples/tubeman.glb" -o m1.glb
"$BIN/mlod-motion" m1.glb -o m2.glb 2> m.err
cmp m1.glb m2.glb
grep -q -F 'mlod-motion: m1.glb: the input already has 3 motion levels (<clip>@lod<k>): written unchanged; run mlod-motion on the input without them to bake them again' m.err
# the other stages still add their levels to such a file
"$BIN/mlod-motion" g1.glb -o gm.glb 2> gm.err
test ! -s gm.err
"$BIN/mlod-pack" gm.glb -o gm.mlod --report | grep -E -q '^motion +4 +input '
