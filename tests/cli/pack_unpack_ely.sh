# The pack round trip on ../shared/data/Ely.glb (make test-extended): pack,
# -x, and the unpacked glb validates with zero errors and keeps the
# lossless fields (pack_unpack_lossless.mjs).
set -e
if [ -z "${MLOD_SHARED_DATA:-}" ] || [ ! -f "$MLOD_SHARED_DATA/Ely.glb" ]; then
	echo "needs ../shared/data/Ely.glb (make test-extended)" >&2
	exit 77
fi
"$BIN/mlod-pack" "$MLOD_SHARED_DATA/Ely.glb" -o ely.mlod 2> /dev/null
"$BIN/mlod-pack" --info ely.mlod > info.txt
grep -q '^# total ' info.txt
"$BIN/mlod-pack" -x ely.mlod -o ely.x.glb
node "$ROOT/tests/validate.mjs" ely.x.glb >&2
node "$ROOT/tests/cli/pack_unpack_lossless.mjs" "$MLOD_SHARED_DATA/Ely.glb" ely.x.glb
