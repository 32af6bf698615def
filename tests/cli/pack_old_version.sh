# A format 1.0 pack (the version of a new pack set back to 1.0, the
# header CRC made again): --info and -x refuse it with what to do, exit 3
# (unsupported), and write nothing. Format 2.0 changed the MESH layout;
# there is no 1.x decode.
"$BIN/mlod-pack" "$ROOT/samples/tubeman.glb" -o t.mlod 2> /dev/null || exit 9
node - <<'JS' || exit 9
const fs = require('fs');
const b = fs.readFileSync('t.mlod');
b.writeUInt16LE(1, 4);
b.writeUInt16LE(0, 6);
let c = 0xffffffff;
for (let i = 0; i < 28; i++) {
	c ^= b[i];
	for (let k = 0; k < 8; k++) c = c & 1 ? 0xedb88320 ^ (c >>> 1) : c >>> 1;
}
b.writeUInt32LE((c ^ 0xffffffff) >>> 0, 28);
fs.writeFileSync('old.mlod', b);
JS
"$BIN/mlod-pack" --info old.mlod > /dev/null
rc=$?
"$BIN/mlod-pack" -x old.mlod -o old.glb
rc2=$?
[ $rc = 3 ] && [ $rc2 = 3 ] && [ ! -e old.glb ] || exit 9
exit 3
