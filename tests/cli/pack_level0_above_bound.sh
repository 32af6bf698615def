# --motion-level0-error at or above the first motion level's bound is
# refused (level 0 is the finest level); the message names both values.
cp "$ROOT/samples/tubeman.glb" .
"$BIN/mlod-pack" --motion-level0-error 5% -o x.mlod tubeman.glb
