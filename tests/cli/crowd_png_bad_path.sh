# bench/crowd checks that --png and --plot can be written before measuring
# (it failed after the whole measurement, exit 4, without the reason):
# exit 4 with strerror, nothing measured on stdout.
"$BIN/mlod-pack" -o t.mlod "$ROOT/samples/tubeman.glb" || exit 99
"$BIN/../bench/crowd" -n 1 -s 0.1 --no-skin-bench --plot no/such/dir.png t.mlod > out.txt && exit 9
test ! -s out.txt || exit 8
"$BIN/../bench/crowd" -n 1 -s 0.1 --no-skin-bench --png no/such/dir.png t.mlod > out.txt
