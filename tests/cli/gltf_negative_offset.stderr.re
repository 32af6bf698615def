mlod-pack: .*/tests/data/bad/negative_offset\.gltf: accessors\[0\]\.byteOffset: not a non-negative integer
