# The piped stages and mlod-pack alone (mlod-pack(1) DESCRIPTION): with
# mlod-motion --precision full and the same --name, the pipeline gives the
# same pack byte for byte, with or without mlod-skelgraph (whose skeleton
# levels mlod-bgm binds its mesh levels to: mlod-pack makes them again on
# the full skin, issue 11); mlod-motion's default precision gives other
# motion chunks.
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
done
cmp direct.mlod full.mlod
if cmp -s direct.anim auto.anim; then exit 1; fi
# The rounded levels cost motion bytes: the auto pack's are more.
motion() { awk '$1 == "#" && $3 == "motion" { print $7 }' "$1" | tr -d ,; }
test "$(motion auto.txt)" -gt "$(motion direct.txt)"
