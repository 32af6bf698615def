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

echo "## Skeleton layer: graph and levels (paper: under 1 ms)"
echo
# shellcheck disable=SC2086
"$build/bench/bench_skeleton" graph $inputs
echo
echo "## Skeleton layer: crowd pose cost (paper Figure 15: 2x at 50 skeletons)"
echo
"$build/bench/bench_skeleton" crowd samples/cmu_12_01_walk.bvh
