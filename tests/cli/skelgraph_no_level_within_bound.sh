# When no level fits the bound, say so on stderr and still succeed.
"$BIN/mlod-skelgraph" --report -e 0.001 "$ROOT/samples/tubeman.glb" > /dev/null
