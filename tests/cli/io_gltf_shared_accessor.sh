# A 57 KB glTF whose one mesh lists the same 1998-vertex accessors in
# 800 primitives: each primitive decodes them again, 1.6 million vertices
# from 24 KB of buffer. Such a list may not make mlod allocate without
# bound (found reading the glTF reader, not by the fuzzer: 3000
# primitives of 20000 vertices in 1.4 MB made mlod-label use 2.8 GB and
# 28-57 s).
V=1998 P=800
# Positions (zeros), then key times 0 and 1 s and two translations (zeros).
{ head -c $((V * 12)) /dev/zero; printf '\000\000\000\000\000\000\200\077'; head -c 24 /dev/zero; } > data.bin
{
	printf '{"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"children":[1]},{"mesh":0}],'
	printf '"animations":[{"channels":[{"sampler":0,"target":{"node":0,"path":"translation"}}],'
	printf '"samplers":[{"input":1,"output":2}]}],'
	printf '"buffers":[{"byteLength":%d,"uri":"data:application/octet-stream;base64,%s"}],' \
		$((V * 12 + 32)) "$(base64 -w 0 data.bin)"
	printf '"bufferViews":[{"buffer":0,"byteLength":%d},{"buffer":0,"byteOffset":%d,"byteLength":32}],' $((V * 12)) $((V * 12))
	printf '"accessors":[{"bufferView":0,"componentType":5126,"count":%d,"type":"VEC3","min":[0,0,0],"max":[0,0,0]},' $V
	printf '{"bufferView":1,"componentType":5126,"count":2,"type":"SCALAR","byteOffset":0,"min":[0],"max":[0]},'
	printf '{"bufferView":1,"componentType":5126,"count":2,"type":"VEC3","byteOffset":8}],'
	printf '"meshes":[{"primitives":['
	i=0
	while [ $i -lt $P ]; do
		[ $i -gt 0 ] && printf ','
		printf '{"attributes":{"POSITION":0}}'
		i=$((i + 1))
	done
	printf ']}]}'
} > shared.gltf
"$BIN/mlod-label" --report shared.gltf > /dev/null
