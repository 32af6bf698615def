"$BIN/mlod-label" "$ROOT/tests/data/bad/missing_brace.bvh"
