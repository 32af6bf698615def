# A JSON error quotes what the parser last read: bytes of the file that
# are not printable ASCII are written as \xNN, never raw to the terminal
# (a new-user probe: an ill-formed UTF-8 byte went to stderr as is).
node -e '
const fs = require("fs");
const b = fs.readFileSync(process.argv[1]);
const jl = b.readUInt32LE(12);
const at = b.indexOf("\"name\"", 20) + 9; /* inside the first name string */
b[at] = 0xff;
fs.writeFileSync("bad.glb", b);' "$ROOT/samples/tubeman.glb" || exit 1
rc=0
"$BIN/mlod-label" -o out.glb bad.glb 2> err.txt || rc=$?
[ $rc = 2 ] || exit 1
LC_ALL=C grep -q "$(printf '\377')" err.txt && exit 1
grep -q 'ill-formed UTF-8 byte; last read: .*\\xff' err.txt || { cat err.txt >&2; exit 1; }
exit 0
