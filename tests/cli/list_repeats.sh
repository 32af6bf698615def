# A value given twice in a level list would bake two identical levels, and
# mlod-skelgraph --joints 1 a level that removes no joint (packed with switch
# distance 0): each is dropped with a note, as mlod-bgm drops a repeated
# ratio and ratio 1.
set -e
T=$ROOT/samples/tubeman.glb
W=$ROOT/samples/cmu_12_01_walk.bvh
test "$("$BIN/mlod-skelgraph" -j 0.5,0.5 --report=json "$T" | grep -c '"level"')" = 1
test "$("$BIN/mlod-skelgraph" -t 0.1,0.1 --report=json "$T" | grep -c '"level"')" = 1
test "$("$BIN/mlod-skelgraph" -j 1 --report=json "$T" | grep -c '"level"')" = 0
test "$("$BIN/mlod-skelgraph" -j 1,0.5,1 --report=json "$T" | grep -c '"level"')" = 1
test "$("$BIN/mlod-motion" -k 0.5,0.2,0.5 --report=json "$W" | grep -c '"level"')" = 2
test "$("$BIN/mlod-motion" -e 1%,1 --report=json "$W" | grep -c '"level"')" = 2
"$BIN/mlod-pack" --motion-max-error 1%,1% -o w.mlod "$W"
test "$("$BIN/mlod-pack" --info w.mlod | grep -c '^ANIM')" = 2
