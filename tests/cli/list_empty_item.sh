# An empty item in a list option is a usage error in every tool (strtok
# skipped it: -R 0.5,,0.25 and -R 0.5, were taken as 0.5,0.25 and 0.5);
# an empty list too.
T=$ROOT/samples/tubeman.glb
"$BIN/mlod-bgm" -R 0.5,,0.25 "$T" && exit 9
"$BIN/mlod-bgm" -R 0.5, "$T" && exit 9
"$BIN/mlod-skelgraph" -j ,0.5 "$T" && exit 9
"$BIN/mlod-motion" -e 1%,,3% "$T" && exit 9
"$BIN/mlod-pack" --motion-max-error 1%, "$T" && exit 9
"$BIN/mlod-bgm" -R '' "$T"
