# The piped stages and mlod-pack alone (mlod-pack(1) DESCRIPTION): with
# mlod-motion --precision full and the same --name, the pipeline without
# mlod-skelgraph gives the same pack byte for byte; with mlod-skelgraph the
# motion chunks are still the same and the mesh chunks differ (the level
# skins); mlod-motion's default precision gives other motion chunks.
set -e
cp "$ROOT/samples/tubeman.glb" .
"$BIN/mlod-pack" -o direct.mlod tubeman.glb
"$BIN/mlod-label" < tubeman.glb | "$BIN/mlod-bgm" | "$BIN/mlod-motion" --precision full |
	"$BIN/mlod-pack" --name tubeman -o piped.mlod
cmp direct.mlod piped.mlod
"$BIN/mlod-label" < tubeman.glb | "$BIN/mlod-skelgraph" | "$BIN/mlod-bgm" > lod.glb
"$BIN/mlod-motion" --precision full lod.glb | "$BIN/mlod-pack" --name tubeman -o full.mlod
"$BIN/mlod-motion" lod.glb | "$BIN/mlod-pack" --name tubeman -o auto.mlod
for f in direct full auto; do
	"$BIN/mlod-pack" --info $f.mlod > $f.txt
	grep '^ANIM' $f.txt | sed 's/  */ /g' > $f.anim
	grep '^MESH' $f.txt | sed 's/  */ /g' > $f.mesh
done
cmp direct.anim full.anim
if cmp -s direct.mesh full.mesh; then exit 1; fi
if cmp -s direct.anim auto.anim; then exit 1; fi
# The rounded levels cost motion bytes: the auto pack's are more.
motion() { awk '$1 == "#" && $3 == "motion" { print $7 }' "$1" | tr -d ,; }
test "$(motion auto.txt)" -gt "$(motion direct.txt)"
