# --influence-budget is not with -e (--help, mlod-pack(1)).
"$BIN/mlod-pack" --influence-budget 2 -e 1 -o x.mlod "$ROOT/samples/tubeman.glb"
