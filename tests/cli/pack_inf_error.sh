# Finite coordinates too large for a level's error (a BVH offset of 1e25:
# the motion error overflows to inf): mlod-pack refuses before writing
# rather than write a TOC entry its reader refuses (exit 2, no output).
sed '0,/OFFSET 2.10660 -1.59283 1.11709/s//OFFSET 1e25 0 0/' "$ROOT/samples/cmu_12_01_walk.bvh" > big.bvh
cmp -s big.bvh "$ROOT/samples/cmu_12_01_walk.bvh" && exit 9
"$BIN/mlod-pack" big.bvh -o big.mlod
rc=$?
[ ! -e big.mlod ] || exit 9
exit $rc
