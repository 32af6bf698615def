# A 400-byte glTF whose accessors have no buffer view (glTF reads them as
# zeros) but claim a million elements each: a small input may not make
# mlod allocate without bound (found reading the glTF reader while the
# fuzz targets ran; they had not hit it: with 60 million elements
# mlod-label used 5 GB and 52-75 s, then succeeded).
cat > dataless.gltf <<'GLTF'
{"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0,1]}],
"nodes":[{"mesh":0,"skin":0},{"name":"root"}],
"skins":[{"joints":[1]}],
"meshes":[{"primitives":[{"attributes":{"POSITION":0,"JOINTS_0":1,"WEIGHTS_0":2}}]}],
"accessors":[{"componentType":5126,"count":1000000,"type":"VEC3"},
{"componentType":5121,"count":1000000,"type":"VEC4"},
{"componentType":5126,"count":1000000,"type":"VEC4"}]}
GLTF
"$BIN/mlod-label" dataless.gltf > out.glb
