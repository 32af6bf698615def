# The stages in any order give the pack of mlod-pack alone (mlod-pack(1)
# DESCRIPTION; issue 11): the six orders of mlod-skelgraph, mlod-bgm and
# mlod-motion --precision full on the tubeman, three of them after
# mlod-label, then mlod-pack --name tubeman. With mlod-bgm before
# mlod-skelgraph the pack is mlod-pack's alone, byte for byte; after it
# (mesh levels weighted on the skeleton levels' skins, as mlod-pack(1)
# says) the three orders give one pack, with mlod-pack's motion chunks.
# The stages after mlod-motion used to take its level animations for
# clips: four packs (85,579, 85,451, 84,683 and 85,819 bytes).
set -e
"$BIN/mlod-pack" -o direct.mlod "$ROOT/samples/tubeman.glb"
tool() {
	case $1 in L) echo mlod-label ;; S) echo mlod-skelgraph ;; B) echo mlod-bgm ;; M) echo mlod-motion ;; esac
}
for o in LSBM SMB LBSM BMS LMSB MBS; do
	cp "$ROOT/samples/tubeman.glb" in.glb
	for s in $(echo $o | sed 's/./& /g'); do
		opt=
		[ $s = M ] && opt="--precision full"
		"$BIN/$(tool $s)" $opt in.glb > out.glb 2>> stderr.txt
		mv out.glb in.glb
	done
	"$BIN/mlod-pack" --name tubeman -o $o.mlod in.glb
	case $o in
	*S*B*) cmp LSBM.mlod $o.mlod ;;
	*) cmp direct.mlod $o.mlod ;;
	esac
done
"$BIN/mlod-pack" --info direct.mlod | grep '^ANIM' > direct.anim
"$BIN/mlod-pack" --info LSBM.mlod | grep '^ANIM' > piped.anim
cmp direct.anim piped.anim
# The stages after mlod-motion count the input's clip alone.
"$BIN/mlod-motion" "$ROOT/samples/tubeman.glb" > m.glb
"$BIN/mlod-skelgraph" --report m.glb | head -n 1 | grep -q '; 1 clips;'
"$BIN/mlod-label" --report m.glb | head -n 1 | grep -q ', 1 clips;'
"$BIN/mlod-bgm" --report m.glb | sed -n 2p | grep -q 'error over 13 poses'
