# The same input and options give byte-identical packs, with either codec.
set -e
"$BIN/mlod-pack" "$ROOT/samples/RobotExpressive.glb" -o a.mlod
"$BIN/mlod-pack" "$ROOT/samples/RobotExpressive.glb" -o b.mlod
cmp a.mlod b.mlod
"$BIN/mlod-pack" --codec none "$ROOT/samples/cmu_12_01_walk.bvh" -o c.mlod
"$BIN/mlod-pack" --codec none "$ROOT/samples/cmu_12_01_walk.bvh" -o d.mlod
cmp c.mlod d.mlod
