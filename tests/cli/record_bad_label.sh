# mlod-skelgraph refuses a joint's label record that is there but
# malformed (exit 2), naming the node and the key.
set -e
"$BIN/mlod-label" "$ROOT/samples/tubeman.glb" > labelled.glb
node - labelled.glb bad.glb <<'JS'
const fs = require('fs');
const [src, dst] = process.argv.slice(2);
const b = fs.readFileSync(src), jl = b.readUInt32LE(12);
const j = JSON.parse(b.subarray(20, 20 + jl).toString());
const n = j.nodes.findIndex((x) => x.extras && x.extras.mlod && x.extras.mlod.label);
j.nodes[n].extras.mlod.label = 'chief';
let text = Buffer.from(JSON.stringify(j));
text = Buffer.concat([text, Buffer.alloc((4 - text.length % 4) % 4, 0x20)]);
const bin = b.subarray(20 + jl), head = Buffer.alloc(20);
head.writeUInt32LE(0x46546c67, 0); head.writeUInt32LE(2, 4); head.writeUInt32LE(20 + text.length + bin.length, 8);
head.writeUInt32LE(text.length, 12); head.writeUInt32LE(0x4e4f534a, 16);
fs.writeFileSync(dst, Buffer.concat([head, text, bin]));
JS
"$BIN/mlod-skelgraph" bad.glb > out.glb
