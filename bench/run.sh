#!/bin/sh
# bench/run.sh BUILD_DIR: runs mlod's benchmarks against the peers, in one
# run, and prints Markdown; `make bench` calls it. Record the output and the
# machine in bench/RESULTS.md.
set -eu
build=${1:-build/release}
cd "$(dirname "$0")/.."
shared=../shared/data

echo "# mlod benchmarks"
echo
echo "Machine: $(uname -m), $(grep -m1 'model name' /proc/cpuinfo 2>/dev/null | sed 's/.*: //'), $(nproc) cores; $(cc --version | head -n 1)"
echo "Date: $(date -u +%Y-%m-%d)"
echo

inputs="samples/cmu_12_01_walk.bvh samples/RobotExpressive.glb"
[ -f samples/tubeman.glb ] && inputs="$inputs samples/tubeman.glb"
if [ -d "$shared" ]; then
	for f in "$shared"/Ely.glb "$shared"/bvh_test3.bvh; do [ -f "$f" ] && inputs="$inputs $f"; done
fi
for f in /usr/share/assimp/models/BVH/*.bvh; do [ -f "$f" ] && inputs="$inputs $f"; done

# Each layer's benchmarks live in bench/<layer>.sh and print their sections.
export BUILD="$build" INPUTS="$inputs"
for section in bench/skeleton.sh bench/mesh.sh bench/motion.sh bench/pack.sh bench/big.sh bench/crowd.sh; do
	[ -f "$section" ] && sh "$section"
done
