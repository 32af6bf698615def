# mlod-pack --info on each sample's pack: the header line, one line per
# chunk (INFO, SKEL, MESH, ANIM with the clip's name, DOC), the totals per
# layer, and a total that is the file's size.
set -e
for s in tubeman.glb RobotExpressive.glb cmu_12_01_walk.bvh; do
	n=${s%.*}
	"$BIN/mlod-pack" "$ROOT/samples/$s" -o "$n.mlod" 2> /dev/null
	"$BIN/mlod-pack" --info "$n.mlod" > "$n.txt"
	size=$(wc -c < "$n.mlod" | tr -d ' ')
	grep -q "^# $n.mlod: mlod 9\.0, $size bytes, [0-9]* chunks$" "$n.txt"
	grep -q "^INFO  none " "$n.txt"
	# the codec column names the entropy stage: INFO has none, DOC zstd
	grep -q "^INFO  none         0  -  *none  " "$n.txt"
	grep -q "^DOC   none         0  -  *none+zstd  " "$n.txt"
	grep -q "^SKEL  skeleton     0  -  *meshopt+zstd  " "$n.txt"
	grep -q "^SKEL  skeleton     0 " "$n.txt"
	grep -q "^DOC   none " "$n.txt"
	grep -q "^# total $size bytes: " "$n.txt"
	grep -q "^# first drawable level: [0-9]* bytes$" "$n.txt"
	for l in none skeleton mesh motion; do grep -q "^# total $l " "$n.txt"; done
	case $s in
	*.glb) grep -q "^MESH  mesh         0 " "$n.txt" ;;
	esac
	# the chunk lines: as many as the header says
	chunks=$(sed -n 's/^# .* bytes, \([0-9]*\) chunks$/\1/p' "$n.txt")
	lines=$(grep -c -E '^(INFO|SKEL|MESH|ANIM|DOC) ' "$n.txt")
	[ "$chunks" = "$lines" ]
done
grep -q "^ANIM  motion       0  walk " tubeman.txt
grep -q "^ANIM  motion       0  Dance " RobotExpressive.txt
