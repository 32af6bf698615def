head -c 100 "$ROOT/samples/tubeman.glb" > bad.glb
"$BIN/mlod-pack" -o out.mlod bad.glb
