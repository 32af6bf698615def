# bench/crowd --work takes skin or pose: anything else is a usage error.
"$BIN/../bench/crowd" --work gpu no-such.mlod
