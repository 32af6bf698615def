# The mesh levels do not depend on the thread count: -j 1, -j 2 and -j 3
# give the same bytes (primitives and measured poses run in parallel, their
# results gathered in order), on a character of 19 primitives and on one of
# a single primitive.
set -e
for f in RobotExpressive tubeman; do
	"$BIN/mlod-bgm" -j 1 -o "$f.1.glb" "$ROOT/samples/$f.glb"
	"$BIN/mlod-bgm" -j 2 -o "$f.2.glb" "$ROOT/samples/$f.glb"
	"$BIN/mlod-bgm" --threads 3 -o "$f.3.glb" "$ROOT/samples/$f.glb"
	cmp "$f.1.glb" "$f.2.glb"
	cmp "$f.1.glb" "$f.3.glb"
done
