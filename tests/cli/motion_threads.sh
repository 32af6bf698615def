# The motion levels do not depend on the thread count: -j 1, -j 2 and -j 3
# give the same bytes and the same report, on a character of 14 clips
# (clips in parallel) and on a BVH of one clip (its two methods in
# parallel).
set -e
f="$ROOT/samples/RobotExpressive.glb"
"$BIN/mlod-motion" -j 1 -o robot.1.glb "$f"
"$BIN/mlod-motion" -j 2 -o robot.2.glb "$f"
"$BIN/mlod-motion" --threads 3 -o robot.3.glb "$f"
cmp robot.1.glb robot.2.glb
cmp robot.1.glb robot.3.glb
b="$ROOT/samples/cmu_12_01_walk.bvh"
for j in 1 2 3; do
	"$BIN/mlod-motion" -j $j -o walk.$j.glb "$b"
	"$BIN/mlod-motion" -j $j -m frames -e 1% -o walk.frames.$j.glb "$b"
	"$BIN/mlod-motion" -j $j --report=json "$b" >walk.$j.json
done
for j in 2 3; do
	cmp walk.1.glb walk.$j.glb
	cmp walk.frames.1.glb walk.frames.$j.glb
	cmp walk.1.json walk.$j.json
done
