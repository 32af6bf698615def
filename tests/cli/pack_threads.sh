# The pack does not depend on the thread count: -j 1 and -j 2 give the same
# bytes (the mesh levels' primitives and measured poses run in parallel,
# gathered in order).
set -e
for f in RobotExpressive tubeman; do
	"$BIN/mlod-pack" -j 1 -o "$f.1.mlod" "$ROOT/samples/$f.glb" 2> /dev/null
	"$BIN/mlod-pack" --threads 2 -o "$f.2.mlod" "$ROOT/samples/$f.glb" 2> /dev/null
	cmp "$f.1.mlod" "$f.2.mlod"
done
