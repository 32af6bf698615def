# A layer option that the input's own levels leave unused (mlod-bgm's mesh
# levels with -R, mlod-motion's with --motion-max-error, mlod-skelgraph's
# with --skeleton-max-error) is said on stderr; the pack is written.
set -e
"$BIN/mlod-bgm" "$ROOT/samples/tubeman.glb" > bgm.glb 2> /dev/null
"$BIN/mlod-pack" -R 0.3 bgm.glb -o bgm.mlod
"$BIN/mlod-pack" --info bgm.mlod > /dev/null
"$BIN/mlod-motion" "$ROOT/samples/cmu_12_01_walk.bvh" > motion.glb
"$BIN/mlod-pack" --motion-max-error 5% motion.glb -o motion.mlod
"$BIN/mlod-skelgraph" "$ROOT/samples/cmu_12_01_walk.bvh" > skel.glb
"$BIN/mlod-pack" --skeleton-max-error 5 -e 1 skel.glb -o skel.mlod
