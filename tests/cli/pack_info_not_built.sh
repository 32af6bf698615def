printf MLOD > x.mlod
"$BIN/mlod-pack" --info x.mlod
