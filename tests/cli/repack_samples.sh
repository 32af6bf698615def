# Issue 11: a pack unpacked with mlod-pack -x and packed again has the
# first pack's levels: on each sample the same character line (name,
# joints, skins, parts, clips, levels per layer, height, diagonal) and,
# chunk for chunk, the same type, layer, level, clip, error and switch
# distance (only the stored bytes may differ: mlod-pack(1) BUGS), every
# layer with levels taken from the input, each clip's level 0 kept. The
# coarse mesh levels of a pack with skeleton levels (tubeman's) too:
# -x writes them with the weights the pack stores (the full skin), and
# the packer keeps them with their errors. Before, -x wrote them on the
# skeleton levels' skins and the packer measured them again: tubeman's
# four stated 2.189, 2.153, 2.129 and 1.850 against 0.07738, 0.174,
# 0.4604 and 1.191. The unpacked glb, with its stage record, passes the
# glTF validator.
set -e
for s in tubeman.glb RobotExpressive.glb cmu_12_01_walk.bvh; do
	n=${s%.*}
	"$BIN/mlod-pack" "$ROOT/samples/$s" -o "$n.mlod" 2> /dev/null
	"$BIN/mlod-pack" -x "$n.mlod" -o "$n.x.glb"
	node "$ROOT/tests/validate.mjs" "$n.x.glb" > /dev/null
	"$BIN/mlod-pack" "$n.x.glb" -o "$n.again.mlod" --report > "$n.report.txt"
	for f in "$n.mlod" "$n.again.mlod"; do
		"$BIN/mlod-pack" --info "$f" > "$f.txt"
		sed -n 2p "$f.txt" > "$f.character"
		awk '/^(INFO|SKEL|MESH|ANIM|DOC) /{print $1, $2, $3, $4, ($1 == "MESH" && $3 > 0 ? "-" : $8 " " $9 " " $10)}' \
			"$f.txt" > "$f.levels"
		awk '$1 == "MESH" && $3 > 0 {print $3, $8, $10}' "$f.txt" > "$f.mesh"
	done
	cmp "$n.mlod.character" "$n.again.mlod.character"
	cmp "$n.mlod.levels" "$n.again.mlod.levels"
	cmp "$n.mlod.mesh" "$n.again.mlod.mesh"
	# the layers with levels came from the input, none computed
	if grep -q ' computed ' "$n.report.txt"; then cat "$n.report.txt" >&2; exit 1; fi
	grep -q "are a pack's motion level 0: kept as they are" "$n.report.txt"
done
grep -q "^# character 'tubeman': 31 joints, 1 skins, 1 parts, 1 clips; levels: skeleton 3, mesh 5, motion 4;" \
	tubeman.again.mlod.txt
grep -q "^# character 'RobotExpressive': 43 joints, 4 skins, 19 parts, 14 clips; levels: skeleton 1, mesh 5, motion 4;" \
	RobotExpressive.again.mlod.txt
# --name still names the pack packed again
"$BIN/mlod-pack" tubeman.x.glb -o named.mlod --name other 2> /dev/null
"$BIN/mlod-pack" --info named.mlod | grep -q "^# character 'other': "
