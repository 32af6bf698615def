cd "$ROOT" && "$BIN/mlod-label" tests/data/bad/missing_brace.bvh
