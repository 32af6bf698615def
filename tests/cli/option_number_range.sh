# A number too large for a double (1e400, as a typo of 1e-4 may give) is
# out of range, not "not a number" (it is one), on a percent option, a
# whole-number option and a list; one too close to 0 for any double says
# so, while a subnormal one (1e-310) is a double and is taken.
T=$ROOT/samples/tubeman.glb
! "$BIN/mlod-pack" -e 1e400 "$T"
! "$BIN/mlod-bgm" -j 1e400 "$T"
! "$BIN/mlod-bgm" --ratios 0.5,1e400 "$T"
! "$BIN/mlod-skelgraph" -e 1e-400 "$T"
"$BIN/mlod-skelgraph" -e 1e-310 "$T" > /dev/null 2>&1 || { echo "1e-310 refused" >&2; exit 1; }
