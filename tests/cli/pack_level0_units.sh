# The level-0 bound is compared with the smallest --motion-max-error bound
# in scene units, a percentage taken of the height (tubeman: 22.33): 0.01
# units (0.045%) is below 0.2% and packs; 0.05 units is above 0.2%
# (0.0447) and is refused, as is 0.2% itself.
set -e
"$BIN/mlod-pack" --motion-level0-error 0.01 -o a.mlod "$ROOT/samples/tubeman.glb"
test -s a.mlod
if "$BIN/mlod-pack" --motion-level0-error 0.05 -o b.mlod "$ROOT/samples/tubeman.glb" 2> err1; then exit 1; fi
grep -q "is not below the first motion level's bound, 0.2%" err1
if "$BIN/mlod-pack" --motion-level0-error 0.2% --motion-max-error 3%,0.2%,1% -o b.mlod "$ROOT/samples/tubeman.glb" 2> err2; then exit 1; fi
grep -q "is not below the first motion level's bound, 0.2%" err2
test ! -e b.mlod
# Without motion levels there is nothing to be below.
"$BIN/mlod-pack" --no-motion-levels --motion-level0-error 5% -o c.mlod "$ROOT/samples/tubeman.glb"
