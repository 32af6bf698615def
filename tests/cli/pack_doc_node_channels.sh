# The DOC chunk keeps every animation channel the MOTION chunks do not
# hold: here a "walk" channel moving a node that is no joint (a prop, or
# a Blender armature's object-level root motion), beside the 32 joint
# channels. It stays in the DOC with its sampler and accessors, and -x
# gives it back in its animation: 33 channels (the pack before this
# dropped it without a word: 32). The glb validates, and packed again and
# unpacked it keeps the channel.
set -e
node "$ROOT/tests/glb-edit.mjs" "$ROOT/samples/tubeman.glb" prop.glb '
j.nodes.push({name: "prop", translation: [0, 1, 0]});
j.scenes[0].nodes.push(j.nodes.length - 1);
const walk = j.animations.find((a) => a.name === "walk");
const s = walk.channels.find((c) => c.target.path === "translation").sampler;
walk.channels.push({sampler: s, target: {node: j.nodes.length - 1, path: "translation"}});'
"$BIN/mlod-pack" prop.glb -o prop.mlod
node "$ROOT/tests/cli/pack_check.mjs" prop.mlod --doc doc.glb > /dev/null
"$BIN/mlod-pack" -x prop.mlod -o prop-x.glb
node "$ROOT/tests/validate.mjs" prop-x.glb > /dev/null
"$BIN/mlod-pack" prop-x.glb -o again.mlod
"$BIN/mlod-pack" -x again.mlod -o again.glb
python3 - doc.glb prop-x.glb again.glb <<'PY'
import json, struct, sys
def glb(f):
    d = open(f, 'rb').read()
    return json.loads(d[20:20 + struct.unpack_from('<I', d, 12)[0]])
doc, x, again = (glb(f) for f in sys.argv[1:])
prop = len(x['nodes']) and [i for i, n in enumerate(x['nodes']) if n.get('name') == 'prop'][0]
walk = [a for a in doc['animations'] if a.get('name') == 'walk']
assert len(walk) == 1 and [c['target'] for c in walk[0]['channels']] == [{'node': prop, 'path': 'translation'}], walk
for j in (x, again):
    walk = [a for a in j['animations'] if a.get('name') == 'walk']
    targets = [(c['target'].get('node'), c['target']['path']) for c in walk[0]['channels']]
    assert len(targets) == 33 and len(set(targets)) == 33 and (prop, 'translation') in targets, targets
PY
