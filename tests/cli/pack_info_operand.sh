# --info and -x take the pack as the operand, in any order with --json and
# -o ("--info --json X.mlod" took "--json" as the pack: exit 1), as well as
# the option's value (--info=X, -xX) and standard input; a pack named twice
# is refused.
set -e
"$BIN/mlod-pack" "$ROOT/samples/cmu_12_01_walk.bvh" -o w.mlod
"$BIN/mlod-pack" --info=w.mlod --json > a.json
"$BIN/mlod-pack" --info --json w.mlod > b.json
"$BIN/mlod-pack" --json --info w.mlod > c.json
"$BIN/mlod-pack" --info --json < w.mlod > d.json
cmp a.json b.json && cmp a.json c.json
sed 's/"<stdin>"/"w.mlod"/' d.json | cmp - a.json
"$BIN/mlod-pack" --info w.mlod > a.txt
"$BIN/mlod-pack" w.mlod --info > b.txt
cmp a.txt b.txt
"$BIN/mlod-pack" -x w.mlod -o a.glb
"$BIN/mlod-pack" -x -o b.glb w.mlod
"$BIN/mlod-pack" -xw.mlod -o c.glb
"$BIN/mlod-pack" --extract=w.mlod -o d.glb
cmp a.glb b.glb && cmp a.glb c.glb && cmp a.glb d.glb
! "$BIN/mlod-pack" --info=w.mlod w.mlod
! "$BIN/mlod-pack" --info w.mlod -x w.mlod
