# --clip, like --level, chooses what a .bvh output writes: without one it
# is a usage error (it was ignored; issue 13 item 5).
"$BIN/mlod-motion" -c 1 -o out.glb "$ROOT/samples/tubeman.glb"
