# --level beyond the clip's last level names the valid range (the walk has
# motion levels 0..3, and -l 3 works).
set -e
"$BIN/mlod-motion" -l 3 -o ok.bvh "$ROOT/samples/cmu_12_01_walk.bvh"
test -s ok.bvh
"$BIN/mlod-motion" -l 4 -o x.bvh "$ROOT/samples/cmu_12_01_walk.bvh"
