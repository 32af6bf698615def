# --influence-budget is for ratio levels: not with -e (--help, mlod-bgm(1)).
"$BIN/mlod-bgm" -I 2 -e 1 -o x.glb "$ROOT/samples/tubeman.glb"
