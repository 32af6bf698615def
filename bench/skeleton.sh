#!/bin/sh
# bench/skeleton.sh: skeleton layer benchmarks (run by bench/run.sh, which
# sets BUILD and INPUTS).
set -eu
echo "## Skeleton layer: graph and levels (paper: under 1 ms)"
echo
# shellcheck disable=SC2086
"$BUILD/bench/bench_skeleton" graph $INPUTS
echo
echo "## Skeleton layer: crowd pose cost (paper Figure 15: 2x at 50 skeletons)"
echo
"$BUILD/bench/bench_skeleton" crowd samples/cmu_12_01_walk.bvh
echo
