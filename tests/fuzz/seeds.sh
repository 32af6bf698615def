#!/bin/sh
# seeds.sh: the seed corpora of make fuzz-io (tests/fuzz/fuzz_io.c,
# fuzz_record.c), from the bundled samples and each stage's output.
#
#   tests/fuzz/seeds.sh BIN HELPERS OUT RECORD_SEED
#
# BIN holds the mlod-* tools, HELPERS gen_tubeman, RECORD_SEED is the
# record_seed helper (release builds). Writes OUT/stage/ (each stage's glb
# on a tiny tubeman, on RobotExpressive and on a 4-frame BVH walk),
# OUT/seeds-bvh, OUT/seeds-gltf, OUT/seeds-record and OUT/seeds-pack.
set -eu
BIN=$1 HELPERS=$2 OUT=$3 RECORD_SEED=$4
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
S=$OUT/stage
mkdir -p "$S" "$OUT/seeds-bvh" "$OUT/seeds-gltf" "$OUT/seeds-record"

# A short walk (the hierarchy and 4 frames) and a tiny tubeman swept over
# it: small seeds run fast.
awk '/^Frames:/ { print "Frames: 4"; next } { print } /^Frame Time:/ { n = 4; while (n-- > 0 && (getline line) > 0) print line; exit }' \
	"$ROOT/samples/cmu_12_01_walk.bvh" > "$S/walk4.bvh"
"$HELPERS/gen_tubeman" "$S/walk4.bvh" "$S/tiny.glb" --segments 3 --rings 2

stage() { # name input
	"$BIN/mlod-label" "$2" > "$S/$1.label.glb"
	"$BIN/mlod-skelgraph" "$S/$1.label.glb" > "$S/$1.skel.glb" 2>/dev/null
	"$BIN/mlod-bgm" "$S/$1.skel.glb" > "$S/$1.bgm.glb"
	"$BIN/mlod-motion" "$S/$1.bgm.glb" > "$S/$1.staged.glb"
}
stage tiny "$S/tiny.glb"
stage robot "$ROOT/samples/RobotExpressive.glb"
"$BIN/mlod-label" "$S/walk4.bvh" > "$S/walk4.label.glb"
"$BIN/mlod-skelgraph" "$S/walk4.label.glb" > "$S/walk4.skel.glb"
"$BIN/mlod-motion" "$S/walk4.skel.glb" > "$S/walk4.staged.glb"
# --split files (mesh_level rather than mesh_levels).
mkdir -p "$S/split"
"$BIN/mlod-bgm" --split "$S/split" "$S/tiny.skel.glb" > /dev/null
for f in "$S"/split/*.glb; do cp "$f" "$S/split-$(basename "$f")"; done

cp "$ROOT/samples/cmu_12_01_walk.bvh" "$S/walk4.bvh" "$ROOT"/tests/data/*.bvh "$ROOT"/tests/data/bad/*.bvh "$OUT/seeds-bvh/"
# Of the robot's stages only the last (it adds the morph weights records):
# a 2 MB input runs at about 10 executions a second, the tiny ones at 100s.
GLB="$S/tiny*.glb $S/split-*.glb $S/walk4*.glb $S/robot.staged.glb"
cp "$ROOT/samples/tubeman.glb" "$ROOT/samples/RobotExpressive.glb" $GLB "$ROOT"/tests/data/*.gltf \
	"$ROOT"/tests/data/bad/*.gltf "$OUT/seeds-gltf/"
for f in $GLB; do
	"$RECORD_SEED" "$f" > "$OUT/seeds-record/$(basename "$f" .glb).json"
done
# Compressed input (lib/io/gltf_decompress.cpp): the tiny tubeman through
# gltfpack -c and -cc (meshopt, -cc with its filters) and gltf-transform's
# Draco, where tests/node has them (scripts/install-deps).
NB=$ROOT/tests/node/node_modules/.bin
cp "$ROOT/tests/data/meshopt.glb" "$OUT/seeds-gltf/"
if [ -x "$NB/gltfpack" ]; then
	"$NB/gltfpack" -i "$S/tiny.glb" -o "$OUT/seeds-gltf/tiny.meshopt.glb" -c > /dev/null
	"$NB/gltfpack" -i "$S/tiny.glb" -o "$OUT/seeds-gltf/tiny.meshopt-cc.glb" -cc > /dev/null
fi
if [ -x "$NB/gltf-transform" ]; then
	"$NB/gltf-transform" draco "$S/tiny.glb" "$OUT/seeds-gltf/tiny.draco.glb" > /dev/null 2>&1
fi

# Pack seeds (make fuzz, make fuzz-unpack): the tiny tubeman packed with
# each codec (draco: MESH levels as Draco meshes) and without the entropy
# stage; two mesh levels keep them small.
mkdir -p "$OUT/seeds-pack"
for c in meshopt none draco; do
	"$BIN/mlod-pack" --codec $c -R 0.5,0.25 -o "$OUT/seeds-pack/tiny.$c.mlod" "$S/tiny.staged.glb"
done
"$BIN/mlod-pack" --codec draco --entropy none -R 0.5 -o "$OUT/seeds-pack/tiny.draco-raw.mlod" "$S/tiny.staged.glb"
