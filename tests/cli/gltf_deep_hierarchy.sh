# A node hierarchy 1000 levels deep is read (mlod-label's reader took time
# quadratic in the depth: each skin joint walked up to its root); one 1001
# levels deep is refused with exit 3 and a message, as the BVH reader
# refuses joints nested deeper than 1000 levels (the later stages walk
# joints to their roots too).
chain() {
	python3 -c '
import json, sys
n = int(sys.argv[1])
nodes = [{"name": "n%d" % i, "translation": [0, 1, 0]} for i in range(n)]
for i in range(n - 1):
    nodes[i]["children"] = [i + 1]
json.dump({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": nodes,
           "skins": [{"joints": list(range(n))}]}, open(sys.argv[2], "w"))' "$@"
}
chain 1000 ok.gltf && chain 1001 deep.gltf || exit 1
"$BIN/mlod-label" ok.gltf -o ok.glb || exit 1
"$BIN/mlod-label" deep.gltf -o deep.glb
