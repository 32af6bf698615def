# mlod-skelgraph -j is --joints (fractions), while -j is --threads in
# mlod-bgm, mlod-motion and mlod-pack: "-j 2" says so plainly (it said only
# "out of range [0, 1]").
"$BIN/mlod-skelgraph" -j 2 "$ROOT/samples/tubeman.glb"
