#!/bin/sh
# bench/crowd.sh: the runtime's crowd (paper Figures 15 and 16; run by
# bench/run.sh, which sets BUILD and INPUTS): each glb input packed with
# mlod-pack's defaults, then bench/crowd with N = 1 .. 10,000 instances at
# 2..200 m (every character taken as 1.8 m tall) spread over the ground,
# full detail against LoD by the paper's alpha and by projected error
# (1 px at 1080 lines, 60 degrees), one core; the skinning kernel against a
# plain scalar loop; and the paper's Figures 15 and 16 as data (--figures:
# frames per second against N with skeletal LoD alone too, and one
# character at each mesh level).
set -eu
bin=$BUILD/bin
[ -x "$BUILD/bench/crowd" ] || exit 0
tmp=$(mktemp -d "${TMPDIR:-/tmp}/mlod-bench-crowd.XXXXXX")
trap 'rm -rf "$tmp"' EXIT INT TERM
echo "## Runtime: crowds with and without LoD (bench/crowd)"
echo
for f in $INPUTS; do
	case $f in *.glb) ;; *) continue ;; esac
	name=$(basename "$f" .glb)
	"$bin/mlod-pack" -o "$tmp/$name.mlod" "$f" 2> /dev/null
	echo '```'
	"$BUILD/bench/crowd" -n 1,10,50,250,1000,10000 -s 1 --max-wall 3 --mode all --figures "$tmp/$name.mlod"
	echo '```'
	echo
done
