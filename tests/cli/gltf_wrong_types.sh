# The glTF validator's wrongTypes files (assimp-testmodels), each valid but
# for one property of the wrong type, which tinygltf skips or reads as 0:
# mlod-pack exits 2 naming it and writes no pack; then mlod-label.
M=/usr/share/assimp/models/glTF2/wrongTypes
[ -f "$M/badArray.gltf" ] || exit 77
check() { # file, message
	rc=0
	"$BIN/$tool" "$M/$1" -o wrong.out 2> err || rc=$?
	[ "$rc" = 2 ] || { echo "$tool $1: exit $rc, not 2" >&2; exit 1; }
	[ ! -e wrong.out ] || { echo "$tool $1: wrote output" >&2; exit 1; }
	grep -qxF "$tool: $M/$1: $2" err || { echo "$tool $1: message: $(cat err)" >&2; exit 1; }
}
for tool in mlod-pack mlod-label; do
	check badArray.gltf "meshes[0].primitives: not an array"
	check badExtension.gltf "materials[0].pbrMetallicRoughness.baseColorTexture.extensions.KHR_texture_transform: not an object"
	check badNumber.gltf "materials[0].normalTexture.scale: not a number"
	check badObject.gltf "materials[0].pbrMetallicRoughness: not an object"
	check badString.gltf "scenes[0].name: not a string"
	check badUint.gltf "materials[0].pbrMetallicRoughness.baseColorTexture.index: not an index (a non-negative integer)"
done
