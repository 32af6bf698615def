# A document using an extension that may refer to accessors cannot be
# stripped safely: the DOC chunk holds the input document whole (the same
# JSON, as written by the glTF writer, and the same binary chunk), and
# the report and standard error say why.
set -e
node "$ROOT/tests/glb-edit.mjs" "$ROOT/samples/tubeman.glb" ext.glb 'j.extensionsUsed = (j.extensionsUsed || []).concat(["EXT_example_refs"]);'
"$BIN/mlod-pack" --no-skeleton-levels --no-mesh-levels --no-motion-levels ext.glb -o ext.mlod --report=json > r.json 2> err.txt
node "$ROOT/tests/cli/pack_check.mjs" ext.mlod --doc doc.glb > /dev/null
python3 - doc.glb ext.glb <<'PY'
import json, struct, sys
def glb(f):
    d = open(f, 'rb').read()
    n = struct.unpack_from('<I', d, 12)[0]
    return json.loads(d[20:20 + n]), d[20 + n:]
(a, abin), (b, bbin) = (glb(f) for f in sys.argv[1:])
assert a == b and abin == bbin
PY
grep -q 'the document chunk holds the input whole: extension EXT_example_refs may refer to meshes or accessors' r.json
[ "$(cat err.txt)" = "mlod-pack: ext.glb: the document chunk holds the input whole: extension EXT_example_refs may refer to meshes or accessors: the document is not stripped" ]
