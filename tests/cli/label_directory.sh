mkdir -p somedir
"$BIN/mlod-label" somedir
