# bench/crowd --png: a picture of the last measured frame, from a small pack
# of the tubeman sample, 40 instances 2..40 m along a line under the alpha
# rule: a PNG of the size asked (signature and IHDR read with od, then
# decoded by crowd_png.mjs), with at least two mesh level colours among the
# characters, the same bytes on a second run; the header gives the scale
# in metres (tubeman is 22.33 units tall: 12.4 units per metre at 1.8 m).
set -eu
crowd=$BIN/../bench/crowd
"$BIN/mlod-pack" -o t.mlod "$ROOT/samples/tubeman.glb"
run() {
	"$crowd" -n 1,40 -s 0.2 --spread line --far 40 --mode alpha --no-skin-bench \
		--png "$1" --png-size 320x180 t.mlod > "$1.out"
}
run a.png
grep -q '^scale 12.4 scene units per metre .*distances 2\.\.40 m spread along a line$' a.png.out ||
	{ echo "no scale in metres on the header line:"; cat a.png.out; exit 1; } >&2
grep -q '^picture: a.png, 320x180, N = 40, mode alpha, the last measured frame: [1-9][0-9]* instances drawn' a.png.out ||
	{ echo "no picture line:"; cat a.png.out; exit 1; } >&2
[ "$(od -An -tx1 -N8 a.png | tr -d ' \n')" = 89504e470d0a1a0a ] || { echo "a.png: no PNG signature" >&2; exit 1; }
# IHDR first: its length and type at 8, then width at 16 and height at 20
# (big-endian).
[ "$(od -An -tx1 -j8 -N12 a.png | tr -d ' \n')" = 0000000d4948445200000140 ] ||
	{ echo "a.png: IHDR is not first, or the width is not 320" >&2; exit 1; }
[ "$(od -An -tx1 -j20 -N4 a.png | tr -d ' \n')" = 000000b4 ] || { echo "a.png: height is not 180" >&2; exit 1; }
counts=$(node "$ROOT/tests/cli/crowd_png.mjs" a.png 320 180 4)
colours=0
for k in $counts; do
	[ "$k" -ge 20 ] && colours=$((colours + 1))
done
[ "$colours" -ge 2 ] || { echo "pixels per level colour: $counts: fewer than two levels drawn" >&2; exit 1; }
run b.png
cmp a.png b.png || { echo "two runs wrote different pictures" >&2; exit 1; }
