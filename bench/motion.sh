#!/bin/sh
# bench/motion.sh: motion layer benchmarks (run by bench/run.sh, which sets
# BUILD and INPUTS).
set -eu
bench=$BUILD/bench/bench_motion
tmp=$(mktemp -d "${TMPDIR:-/tmp}/mlod-bench-motion.XXXXXX")
trap 'rm -rf "$tmp"' EXIT INT TERM
gltfpack="node tests/node/node_modules/gltfpack/cli.js"

echo "## Motion layer: against gltfpack (same error function, same codecs)"
echo
if [ -f tests/node/node_modules/gltfpack/cli.js ]; then
	echo "gltfpack $($gltfpack -v 2>&1 | head -n 1 | sed 's/^gltfpack //'), with -noq at its defaults (30 Hz resampling) and with -af 15, and without -noq (quantised) at its defaults."
	echo "gltfpack's bytes are those its glb stores (bench/anim-keys.mjs): rotations as normalised shorts, even with -noq."
	echo
	"$bench" convert samples/cmu_12_01_walk.bvh "$tmp/cmu_12_01_walk.glb"
	for f in samples/RobotExpressive.glb "$tmp/cmu_12_01_walk.glb"; do
		b=$(basename "$f" .glb)
		$gltfpack -i "$f" -o "$tmp/$b-noq.glb" -noq > /dev/null
		$gltfpack -i "$f" -o "$tmp/$b-noq-af15.glb" -noq -af 15 > /dev/null
		$gltfpack -i "$f" -o "$tmp/$b-q.glb" > /dev/null
		for g in noq noq-af15 q; do node bench/anim-keys.mjs "$tmp/$b-$g.glb" "$tmp/$b-$g.keys"; done
		"$bench" peers "$f" "gltfpack -noq=$tmp/$b-noq.glb@$tmp/$b-noq.keys" \
			"gltfpack -noq -af 15=$tmp/$b-noq-af15.glb@$tmp/$b-noq-af15.keys" "gltfpack=$tmp/$b-q.glb@$tmp/$b-q.keys"
	done
else
	echo "gltfpack is not installed (scripts/install-deps): skipped."
	echo
fi

echo "## Motion layer: pack level 0 against gltfpack -cc (point error, mlod-pack's --motion-level0-error)"
echo
if [ -f tests/node/node_modules/gltfpack/cli.js ] && [ -x "$BUILD/bin/mlod-pack" ]; then
	echo "gltfpack -cc's output made readable by gltfpack -noq -af 0 (no resampling; it adds its own 16-bit"
	echo "rounding, shown as 'noise floor': gltfpack -noq -af 0 of the input); mlod: mlod-pack at its default"
	echo "level-0 bound, unpacked (mlod-pack -x). Both sampled at the input's frames and midpoints."
	echo
	for f in samples/tubeman.glb samples/RobotExpressive.glb samples/cmu_12_01_walk.bvh; do
		b=$(basename "$f"); b=${b%.*}; glb=$f
		case $f in *.bvh) glb=$tmp/$b.glb; "$BUILD/bin/mlod-label" -o "$glb" "$f" 2> /dev/null ;; esac
		$gltfpack -i "$glb" -o "$tmp/$b-cc.glb" -cc > /dev/null
		$gltfpack -i "$tmp/$b-cc.glb" -o "$tmp/$b-ccd.glb" -noq -af 0 > /dev/null 2>&1
		$gltfpack -i "$glb" -o "$tmp/$b-floor.glb" -noq -af 0 > /dev/null 2>&1
		"$BUILD/bin/mlod-pack" "$f" -o "$tmp/$b.mlod" 2> /dev/null
		"$BUILD/bin/mlod-pack" -x "$tmp/$b.mlod" -o "$tmp/$b.x.glb"
		"$bench" pointerr "$f" "gltfpack -cc=$tmp/$b-ccd.glb" "noise floor=$tmp/$b-floor.glb" "mlod-pack level 0=$tmp/$b.x.glb"
	done
fi

echo "## Motion layer: value precision (keys method; the share of each bound left to rounding)"
echo
# shellcheck disable=SC2086
"$bench" precision samples/RobotExpressive.glb samples/cmu_12_01_walk.bvh

echo "## Motion layer: the paper's tree (removal, averaging) against key reduction"
echo
echo "Keys and key bytes kept by levels within 0.2%, 1% and 3% of the skeleton height (point error)."
echo
samples=
for f in $INPUTS; do case $f in samples/*) samples="$samples $f" ;; esac; done
long=
for f in /usr/share/assimp/models/BVH/01_01.bvh /usr/share/assimp/models/BVH/Boxing_Toes.bvh; do
	[ -f "$f" ] || continue
	long="$long $f" # Boxing_Toes holds one frame past its announced 3069: mlod ignores it with a note
done
# shellcheck disable=SC2086
"$bench" methods $samples $long

echo "## Motion layer: the bound between frames (--subdivide)"
echo
# shellcheck disable=SC2086
"$bench" between $samples $long

echo "## Motion layer: speed (default levels: 0.2%, 1%, 3% of the height)"
echo
if [ -z "$long" ]; then
	echo "The long Debian clips are missing (apt-get install assimp-testmodels)."
	echo
fi
# shellcheck disable=SC2086
"$bench" speed $long $samples
