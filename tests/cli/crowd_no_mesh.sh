# bench/crowd on a pack without a mesh (a BVH's, as make demo writes)
# measures the pose, saying so, instead of failing on mlod_rt_skin (a
# new-user probe's bug 3); --mode all runs every rule (it ran alpha and
# pixels only).
set -eu
crowd=$BIN/../bench/crowd
"$BIN/mlod-pack" -o walk.mlod "$ROOT/samples/cmu_12_01_walk.bvh" 2> /dev/null
"$crowd" -n 1,20 -s 0.1 --max-wall 60 --mode all walk.mlod > out.txt
grep -q '; work: pose (motion sampling, pose and palette; no skinning); modes: full, alpha' out.txt ||
	{ echo "no pose work on the header line:"; cat out.txt; exit 1; } >&2
for m in alpha pixels toc skeleton; do
	test "$(grep -c "^ *\(20 \)\? *$m " out.txt)" = 2 || { echo "not two $m rows:"; cat out.txt; exit 1; } >&2
done
