# --clip, like --level, chooses what a .bvh output writes: without one it
# is a usage error (-c 5 -o y.glb was accepted and ignored; issue 13 item 5).
"$BIN/mlod-skelgraph" -c 5 -o y.glb "$ROOT/samples/tubeman.glb"
