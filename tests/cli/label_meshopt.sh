# meshopt-compressed input (EXT_meshopt_compression) reads as the plain
# file: gltfpack -noq of tubeman, with and without -c (the same processing,
# compressed buffer views), gives the same mesh data after mlod-label, the
# triangles up to the rotation meshopt's index codec makes. The written glb
# is plain and validates. gltfpack 1.3 is pinned in tests/node.
set -e
gp=$ROOT/tests/node/node_modules/.bin/gltfpack
[ -x "$gp" ] || { echo "gltfpack is not installed in tests/node (scripts/install-deps)" >&2; exit 77; }
"$gp" -i "$ROOT/samples/tubeman.glb" -o plain.glb -noq > /dev/null
"$gp" -i "$ROOT/samples/tubeman.glb" -o packed.glb -noq -c > /dev/null
grep -q EXT_meshopt_compression packed.glb
"$BIN/mlod-label" -o plain.l.glb plain.glb
"$BIN/mlod-label" -o packed.l.glb packed.glb
node "$ROOT/tests/cli/decoded_compare.cjs" plain.l.glb packed.l.glb > compare.txt
grep -q 'POSITION: max difference 0.000$' compare.txt
node "$ROOT/tests/validate.mjs" packed.l.glb > /dev/null
! grep -q meshopt packed.l.glb
