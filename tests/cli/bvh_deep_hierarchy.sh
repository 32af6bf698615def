# BVH joints nested 1000 levels deep are read; 1001 levels are refused with
# exit 3 (a limit of mlod's, MLOD_MAX_HIERARCHY_DEPTH, as for a glTF node
# hierarchy: cli/gltf_deep_hierarchy) and the line that goes too deep. It
# was exit 2, as if the file were malformed.
bvh() {
	awk -v n="$1" 'BEGIN {
		print "HIERARCHY"
		for (i = 0; i < n; i++) {
			print (i ? "JOINT" : "ROOT") " j" i
			print "{"
			print "OFFSET 0 1 0"
			print (i ? "CHANNELS 3 Zrotation Xrotation Yrotation" : "CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation")
		}
		print "End Site"; print "{"; print "OFFSET 0 1 0"; print "}"
		for (i = 0; i < n; i++) print "}"
		print "MOTION"; print "Frames: 1"; print "Frame Time: 0.0333333"
		line = "0 0 0"
		for (i = 0; i < n; i++) line = line " 0 0 0"
		print line
	}' > "$2"
}
bvh 1000 ok.bvh && bvh 1001 deep.bvh || exit 1
"$BIN/mlod-label" ok.bvh -o ok.glb || exit 1
"$BIN/mlod-label" deep.bvh -o deep.glb
