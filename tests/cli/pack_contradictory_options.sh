# Options that cannot all be used are refused before anything is read: a
# layer's level option with --no-*-levels for that layer, and an option
# that bakes a pack with --info or -x, which read one.
W=$ROOT/samples/cmu_12_01_walk.bvh
"$BIN/mlod-pack" -R 0.5 --no-mesh-levels "$W" && exit 9
"$BIN/mlod-pack" --no-skeleton-levels --skeleton-max-error 1 "$W" && exit 9
"$BIN/mlod-pack" --motion-max-error 1% --no-motion-levels "$W" && exit 9
"$BIN/mlod-pack" --info w.mlod --codec none && exit 9
"$BIN/mlod-pack" -x w.mlod -R 0.5 -o w.glb
