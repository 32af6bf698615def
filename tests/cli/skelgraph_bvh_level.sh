# --level K -o out.bvh: the level re-reads with its joint count and every frame.
set -e
"$BIN/mlod-skelgraph" -j 0.7 --level 1 -o level.bvh "$ROOT/samples/cmu_12_01_walk.bvh"
kept=$("$BIN/mlod-skelgraph" -j 0.7 --report=json "$ROOT/samples/cmu_12_01_walk.bvh" | node -e 'let s="";process.stdin.on("data",d=>s+=d).on("end",()=>console.log(JSON.parse(s).levels[0].kept))')
joints=$(grep -cE '^\s*(ROOT|JOINT)' level.bvh)
test "$joints" -eq "$kept"
grep -q '^Frames: 524' level.bvh
"$BIN/mlod-label" --report level.bvh > /dev/null
