# An accessor whose byteOffset is -8 (tinygltf reads it without a word) is
# malformed glTF: mlod-pack exits 2 naming the property, writes no pack.
"$BIN/mlod-pack" "$ROOT/tests/data/bad/negative_offset.gltf" -o out.mlod
