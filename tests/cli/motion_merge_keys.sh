# --merge is for the frames method: refused with --method keys.
"$BIN/mlod-motion" --merge average -m keys -o x.glb "$ROOT/samples/tubeman.glb"
