#!/bin/sh
# bench/mesh.sh: mesh layer benchmarks (run by bench/run.sh, which sets
# BUILD and INPUTS): paper Table 1, speed against meshopt_simplify, and
# posed quality against meshopt_simplify and gltfpack 1.3.
set -eu
glbs=
for f in $INPUTS; do
	case $f in *.glb) glbs="$glbs $f" ;; esac
done
[ -n "$glbs" ] || exit 0
gltfpack="node tests/node/node_modules/gltfpack/cli.js"
tmp=$(mktemp -d "${TMPDIR:-/tmp}/mlod-bench-mesh.XXXXXX")
trap 'rm -rf "$tmp"' EXIT INT TERM

echo "## Mesh layer: paper Table 1 (BGM build and 10 triangle collapses)"
echo
# shellcheck disable=SC2086
"$BUILD/bench/bench_mesh" table1 $glbs
echo
echo "## Mesh layer: speed against meshopt_simplify (the 50/25/10% chain)"
echo
# shellcheck disable=SC2086
"$BUILD/bench/bench_mesh" speed $glbs
echo
echo "## Mesh layer: the posed chain's CPU time against meshopt_simplify"
echo
# shellcheck disable=SC2086
"$BUILD/bench/bench_mesh" chain $glbs
echo
echo "## Mesh layer: posed quality at 50%, 25% and 10% of the triangles"
echo
echo "Reference for Ely at 25%, random poses, measured elsewhere: meshopt_simplify mean 0.053%, Hausdorff 1.21%;"
echo "gltfpack mean 0.081%, Hausdorff 0.77%."
for f in $glbs; do
	name=$(basename "$f" .glb)
	files=
	for r in 0.5 0.25 0.1; do
		out="$tmp/$name-$r.glb"
		if [ -d tests/node/node_modules/gltfpack ] && $gltfpack -i "$f" -o "$out" -si $r -se 1 -noq > /dev/null 2>&1; then
			files="$files $out"
		else
			files="$files $tmp/missing.glb"
		fi
	done
	# shellcheck disable=SC2086
	"$BUILD/bench/bench_mesh" quality "$f" $files 2> "$tmp/stderr" || cat "$tmp/stderr" >&2
	echo
done
echo "mlod rows are the library with each cost, collapse, placement and eligibility rule; levels keep 50/25/10%"
echo "of the triangles (posed cost: of the whole character, shared by cost as mlod-bgm does; compactness: of each"
echo "primitive). gltfpack and the paper's rules may stop short: see the tris columns. The default row's ratios"
echo "against the peers are given where the triangle counts match within 1%."
echo
echo "## Mesh layer: spread of the posed error over pose seeds and sampling density"
echo
echo "mlod's default chain (as mlod-bgm makes it), meshopt_simplify and gltfpack (-si R -se 1 -noq, as above),"
echo "each over 5 pose seeds (2008..2012) of 8 random poses, with both posed meshes split into D = 1, 4, 16"
echo "triangles per triangle before measuring (D = 1 is mlod_posed_error). Verdicts: better/worse when every"
echo "seed's mean ratio is below/above 1, else a tie."
for f in $glbs; do
	name=$(basename "$f" .glb)
	files='' n=0
	for r in 0.5 0.25 0.1; do
		out="$tmp/$name-$r.glb"
		if [ -f "$out" ]; then files="$files $out" n=$((n + 1)); fi
	done
	[ "$n" -eq 3 ] || files= # the three gltfpack levels or none
	# shellcheck disable=SC2086
	"$BUILD/bench/bench_spread" "$f" $files 2> "$tmp/stderr" || cat "$tmp/stderr" >&2
	echo
done
