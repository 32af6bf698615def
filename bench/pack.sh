#!/bin/sh
# bench/pack.sh: the pack against gltfpack (run by bench/run.sh, which sets
# BUILD and INPUTS). First the mesh codecs (bench_codec) and the mesh level
# layouts (bench_layout) on the glb inputs. Then per input, raw, gzip -9
# and zstd -19 bytes of:
#   pack        mlod-pack of the input: every level of every layer (with
#               its own zstd entropy stage per chunk, the default)
#   pack --entropy none   the same without the entropy stage
#   gltfpack    gltfpack -cc of the input: full detail, one level
#   gltfpack*L  gltfpack -cc, then -cc -si R for each mesh ratio the pack
#               holds (mlod-bgm's defaults): what a user does today to get
#               the same mesh levels (it has no skeleton or motion levels)
#   pipeline    the piped glb (mlod-label | mlod-skelgraph | mlod-bgm |
#               mlod-motion) that the pack replaces
# with textures, and without (the bytes of the input's images taken off
# each: the pack stores them verbatim), and the pack's size over each
# file's as stored (raw / raw), gzip -9'd and zstd -19'd (the pack's own
# gzip or zstd against the file's), so that the pack, which compresses its
# chunks itself, is also compared with gltfpack's output compressed whole.
# A BVH input is made a glb first (mlod-label) for gltfpack. Pack time is
# the whole mlod-pack run.
set -eu
bin=$BUILD/bin
[ -x "$bin/mlod-pack" ] || exit 0
gltfpack="node tests/node/node_modules/gltfpack/cli.js"
tmp=$(mktemp -d "${TMPDIR:-/tmp}/mlod-bench-pack.XXXXXX")
trap 'rm -rf "$tmp"' EXIT INT TERM
ratios="0.5 0.25 0.1 0.03" # the mesh levels mlod-pack makes by default (MLOD_MESH_RATIOS_DEFAULT)
levels=$(( $(echo $ratios | wc -w) + 1 ))

sizes() { # sizes FILE: raw gzip zstd
	printf '%s %s %s' "$(wc -c < "$1")" "$(gzip -9 -c "$1" | wc -c)" "$(zstd -19 -q -c "$1" | wc -c)"
}
ratio() { awk -v a="$1" -v b="$2" 'BEGIN { if (b > 0) printf "%.2fx", a / b; else printf "-" }'; }

echo "## Pack: mesh codecs on the same quantised data (meshoptimizer 0.18, Draco 1.5)"
echo
glbs=
for f in $INPUTS; do
	case $f in *.glb) glbs="$glbs $f" ;; esac
done
# shellcheck disable=SC2086
[ -z "$glbs" ] || "$BUILD/bench/bench_codec" $glbs
echo
echo "## Pack: mesh level layouts, (a) per level as stored against (b) one prefix buffer per part"
echo
# shellcheck disable=SC2086
[ -z "$glbs" ] || "$BUILD/bench/bench_layout" -c $glbs || echo "bench_layout failed (exit $?): see its message above"
echo
echo "## Pack: every level in one file, against gltfpack 1.3"
echo
echo "| input | file | raw | gzip -9 | zstd -19 | raw, no textures | pack / file (raw / raw) | (gzip / gzip) | (zstd / zstd) |"
echo "|---|---|---|---|---|---|---|---|---|"
for f in $INPUTS; do
	name=$(basename "$f"); name=${name%.*}
	case $f in
	*.bvh) glb=$tmp/$name.glb; "$bin/mlod-label" -o "$glb" "$f" 2> /dev/null ;;
	*) glb=$f ;;
	esac
	images=$(node bench/glb-image-bytes.mjs "$glb")
	start=$(date +%s.%N)
	"$bin/mlod-pack" -o "$tmp/$name.mlod" "$f" 2> /dev/null
	end=$(date +%s.%N)
	"$bin/mlod-pack" --codec none --entropy none -o "$tmp/$name.none.mlod" "$f" 2> /dev/null
	"$bin/mlod-pack" --entropy none -o "$tmp/$name.noent.mlod" "$f" 2> /dev/null
	"$bin/mlod-label" < "$f" 2> /dev/null | "$bin/mlod-skelgraph" 2> /dev/null | "$bin/mlod-bgm" 2> /dev/null |
		"$bin/mlod-motion" > "$tmp/$name.pipe.glb" 2> /dev/null
	$gltfpack -i "$glb" -o "$tmp/$name.gp.glb" -cc > /dev/null 2>&1 || continue
	cp "$tmp/$name.gp.glb" "$tmp/$name.gpl.bin"
	for r in $ratios; do
		$gltfpack -i "$glb" -o "$tmp/$name.gp$r.glb" -cc -si "$r" -se 1 > /dev/null 2>&1
		cat "$tmp/$name.gp$r.glb" >> "$tmp/$name.gpl.bin"
	done
	set -- $(sizes "$tmp/$name.mlod"); pr=$1 pg=$2 pz=$3
	for row in "pack:$tmp/$name.mlod:1" "pack --entropy none:$tmp/$name.noent.mlod:1" "pack --codec none --entropy none:$tmp/$name.none.mlod:1" "gltfpack -cc:$tmp/$name.gp.glb:1" "gltfpack -cc, per level:$tmp/$name.gpl.bin:$levels" "pipeline glb:$tmp/$name.pipe.glb:1"; do
		label=${row%%:*}; rest=${row#*:}; file=${rest%:*}; copies=${rest##*:}
		set -- $(sizes "$file")
		echo "| $name | $label | $1 | $2 | $3 | $(( $1 - images * copies )) | $(ratio "$pr" "$1") | $(ratio "$pg" "$2") | $(ratio "$pz" "$3") |"
	done
	echo "| $name | pack time | $(awk -v a="$start" -v b="$end" 'BEGIN { printf "%.2f s", b - a }') | | | | | | |"
done
echo
echo "Goal (issue 11): the pack at most 1.3x 'gltfpack -cc' and at most 0.6x 'gltfpack -cc, per level' (raw / raw);"
echo "zstd / zstd compares the pack zstd'd whole with gltfpack's file zstd'd whole."
echo "gltfpack's levels are meshes only; the pack also holds the skeleton and motion levels."
echo
