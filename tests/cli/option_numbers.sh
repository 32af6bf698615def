# Values documented in percent take a trailing '%' (mlod-bgm -e,
# mlod-skelgraph -e, mlod-pack -e and --skeleton-max-error, as
# --motion-max-error does); a whole-number option says a fraction is not a
# whole number whatever its range; an open range is said open.
set -e
T=$ROOT/samples/tubeman.glb
"$BIN/mlod-bgm" -e 1% -o a.glb "$T"
"$BIN/mlod-bgm" -e 1 -o b.glb "$T"
cmp a.glb b.glb
"$BIN/mlod-skelgraph" -e 3% -o a.glb "$T"
"$BIN/mlod-skelgraph" -e 3 -o b.glb "$T"
cmp a.glb b.glb
"$BIN/mlod-pack" --skeleton-max-error 1% -e 0.5% -o a.mlod "$T"
"$BIN/mlod-pack" --skeleton-max-error 1 -e 0.5 -o b.mlod "$T"
cmp a.mlod b.mlod
! "$BIN/mlod-pack" --uv-bits 16.5 "$T"
! "$BIN/mlod-skelgraph" --level 1.5 -o x.bvh "$T"
! "$BIN/mlod-motion" --precision-share 0 "$T"
! "$BIN/mlod-motion" --precision-share 1 "$T"
