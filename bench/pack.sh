#!/bin/sh
# bench/pack.sh: pack sizes and times (run by bench/run.sh, which sets
# BUILD and INPUTS; alone: BUILD=build/release INPUTS="samples/x.glb ..."
# sh bench/pack.sh). Per input: the whole `mlod-pack` run with each codec,
# the pack's bytes raw, gzip -9 and zstd -19, and gltfpack -cc of the
# full-detail input alone (one level) for comparison. A BVH goes to
# gltfpack as the glb mlod reads it as.
set -eu
gltfpack="node tests/node/node_modules/gltfpack/cli.js"
tmp=$(mktemp -d "${TMPDIR:-/tmp}/mlod-bench-pack.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
now() { date +%s.%N; }
sizes() { # raw gzip zstd
	raw=$(wc -c < "$1")
	gz=$(gzip -9 -c "$1" | wc -c)
	if command -v zstd > /dev/null 2>&1; then zs=$(zstd -19 -q -c "$1" | wc -c); else zs=-; fi
	echo "$raw | $gz | $zs"
}
echo "## Pack: sizes and time"
echo
echo "Every level of every layer, computed with the defaults. Bytes raw | gzip -9 | zstd -19."
echo
echo "| input | meshopt | gzip | zstd | none | gzip | zstd | gltfpack -cc | gzip | zstd | mlod-pack s (meshopt) | s (none) | gltfpack s |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|"
for f in $INPUTS; do
	name=$(basename "$f")
	row="| $name"
	for codec in meshopt none; do
		t0=$(now)
		"$BUILD/bin/mlod-pack" --codec $codec "$f" -o "$tmp/$codec.mlod" 2> /dev/null
		t1=$(now)
		eval "t_$codec=\$(printf '%.2f' \"\$(echo \"\$t1 - \$t0\" | bc)\")"
		row="$row | $(sizes "$tmp/$codec.mlod")"
	done
	in=$f
	case $f in *.bvh) "$BUILD/bin/mlod-bgm" "$f" > "$tmp/in.glb" 2> /dev/null; in=$tmp/in.glb ;; esac
	t0=$(now)
	if [ -d tests/node/node_modules/gltfpack ] && $gltfpack -i "$in" -o "$tmp/gp.glb" -cc > /dev/null 2>&1; then
		t1=$(now)
		row="$row | $(sizes "$tmp/gp.glb") | $t_meshopt | $t_none | $(printf '%.2f' "$(echo "$t1 - $t0" | bc)")"
	else
		row="$row | - | - | - | $t_meshopt | $t_none | -"
	fi
	echo "$row |"
done
echo
