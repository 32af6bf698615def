# Two channels of one animation that target the same node and path
# (invalid glTF: the validator's ANIMATION_DUPLICATE_TARGETS) are refused
# by every tool as it reads the file, exit 2. They were accepted, and
# mlod-pack wrote a pack its own reader refuses.
node -e '
const fs = require("fs");
const b = fs.readFileSync(process.argv[1]);
const n = b.readUInt32LE(12);
const j = JSON.parse(b.subarray(20, 20 + n).toString("utf8"));
const a = j.animations[0];
a.channels.push(Object.assign({}, a.channels[0]));
let text = Buffer.from(JSON.stringify(j), "utf8");
text = Buffer.concat([text, Buffer.alloc((4 - (text.length % 4)) % 4, 0x20)]);
const rest = b.subarray(20 + n);
const head = Buffer.alloc(20);
head.writeUInt32LE(0x46546c67, 0);
head.writeUInt32LE(2, 4);
head.writeUInt32LE(20 + text.length + rest.length, 8);
head.writeUInt32LE(text.length, 12);
head.writeUInt32LE(0x4e4f534a, 16);
fs.writeFileSync("dup.glb", Buffer.concat([head, text, rest]));
' "$ROOT/samples/tubeman.glb" || exit 1
for t in label skelgraph bgm motion pack; do
	rc=0
	"$BIN/mlod-$t" -o out dup.glb || rc=$?
	[ $rc = 2 ] || exit 1
	[ ! -e out ] || exit 1
done
exit 2
