# mlod-pack -x unpacks every pack mlod-pack writes: inputs whose stripped
# document once kept emptied buffers (simple_skin.gltf: a second buffer,
# an empty data: URI; BoxBadNormals.glb: an empty buffer 0 in a glb) pack,
# unpack with exit 0 and validate with zero errors (test_gltf
# strip_drops_emptied_buffers: the DOC keeps no such buffer). Old packs that hold such buffers unpack too
# (tests/data/emptied_buffer.mlod: BoxBadNormals.glb packed by 192e53c).
M=/usr/share/assimp/models/glTF2
[ -f "$M/simple_skin/simple_skin.gltf" ] || exit 77
set -e
for f in simple_skin/simple_skin.gltf BoxBadNormals-glTF-Binary/BoxBadNormals.glb; do
	n=$(basename "$f")
	"$BIN/mlod-pack" "$M/$f" -o "$n.mlod" 2> /dev/null
	"$BIN/mlod-pack" -x "$n.mlod" -o "$n.x.glb"
	node "$ROOT/tests/validate.mjs" "$n.x.glb" >&2
done
"$BIN/mlod-pack" -x "$ROOT/tests/data/emptied_buffer.mlod" -o old.x.glb
node "$ROOT/tests/validate.mjs" old.x.glb >&2
