# bench/crowd --height takes metres (> 0) or 0 for scene units: a negative
# height is a usage error, named before the pack is opened.
"$BIN/../bench/crowd" --height -1 no-such.mlod
