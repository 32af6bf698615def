# gltfpack -cf writes a fallback buffer (fallback: true) beside the
# compressed one, for readers without EXT_meshopt_compression. mlod decodes
# the compressed views and never reads it: the file may be absent.
set -e
gp=$ROOT/tests/node/node_modules/.bin/gltfpack
[ -x "$gp" ] || { echo "gltfpack is not installed in tests/node (scripts/install-deps)" >&2; exit 77; }
mkdir cf
"$gp" -i "$ROOT/samples/tubeman.glb" -o cf/t.gltf -noq -cf > /dev/null
grep -q '"fallback":true' cf/t.gltf
rm cf/t.fallback.bin
"$BIN/mlod-label" -o t.l.glb cf/t.gltf
node "$ROOT/tests/validate.mjs" t.l.glb > /dev/null
