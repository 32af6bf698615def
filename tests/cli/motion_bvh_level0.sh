# --level 0 writes the clip as read: re-read, its joint positions are the
# input's within 1e-4 of the skeleton height, at every frame. Level 1 stays
# near the input (its bound is 0.2% of the height), level 3 does not.
set -e
"$BIN/mlod-motion" --level 0 -o l0.bvh "$ROOT/samples/cmu_12_01_walk.bvh"
node "$ROOT/tests/cli/motion_bvh_compare.mjs" "$ROOT/samples/cmu_12_01_walk.bvh" l0.bvh 1e-4
"$BIN/mlod-motion" --level 0 -o w0.bvh "$ROOT/tests/data/motion_wrap.bvh"
node "$ROOT/tests/cli/motion_bvh_compare.mjs" "$ROOT/tests/data/motion_wrap.bvh" w0.bvh 1e-4
"$BIN/mlod-motion" --level 1 -o l1.bvh "$ROOT/samples/cmu_12_01_walk.bvh"
node "$ROOT/tests/cli/motion_bvh_compare.mjs" "$ROOT/samples/cmu_12_01_walk.bvh" l1.bvh 0.002
"$BIN/mlod-motion" --level 3 -o l3.bvh "$ROOT/samples/cmu_12_01_walk.bvh"
grep -q '^Frames: 524' l3.bvh
# (Not "! node ...": set -e ignores a command that starts with "!".) The
# comparison must run and measure more than 0.002: a number, exit 1.
if worst=$(node "$ROOT/tests/cli/motion_bvh_compare.mjs" "$ROOT/samples/cmu_12_01_walk.bvh" l3.bvh 0.002); then
	echo "level 3 within 0.002 of the input: $worst" >&2
	exit 1
fi
node -e 'const w = +process.argv[1]; if (!(w > 0.002)) { console.error("level 3 not compared: " + process.argv[1]); process.exit(1); }' "$worst"
