# -o on a FIFO writes into the pipe (its reader gets the same bytes as a
# normal output) and leaves the FIFO in place, as on a Unix socket (a
# listener gets the bytes, the socket stays); -o on a symbolic link
# replaces the file it points to and keeps the link; a dangling link is
# refused. Never a device: a wrong fix would destroy it.
set -e
"$BIN/mlod-bgm" -o plain.glb "$ROOT/samples/tubeman.glb"
mkfifo pipe.glb
cat pipe.glb > got.glb &
reader=$!
"$BIN/mlod-bgm" -o pipe.glb "$ROOT/samples/tubeman.glb" || { kill $reader; exit 1; }
# A replaced FIFO leaves its reader waiting on the old pipe: end it.
test -p pipe.glb || { kill $reader; exit 1; }
wait $reader
cmp plain.glb got.glb
test "$(ls -A | grep -c '\.tmp\.')" -eq 0
# The pack through a FIFO too (binary, written by another tool).
"$BIN/mlod-pack" -o plain.mlod "$ROOT/samples/cmu_12_01_walk.bvh"
cat pipe.glb > got.mlod &
reader=$!
"$BIN/mlod-pack" -o pipe.glb "$ROOT/samples/cmu_12_01_walk.bvh" || { kill $reader; exit 1; }
test -p pipe.glb || { kill $reader; exit 1; }
wait $reader
cmp plain.mlod got.mlod
# A Unix stream socket: connected to and written; it stays a socket.
node - <<'JS'
const net = require('net'), fs = require('fs'), cp = require('child_process');
const chunks = [];
let code = null, ended = false;
const done = () => {
	if (code === null || !ended) return;
	if (code !== 0) throw new Error(`mlod-bgm exited ${code}`);
	if (!Buffer.concat(chunks).equals(fs.readFileSync('plain.glb'))) throw new Error('the socket got other bytes');
	if (!fs.lstatSync('sock.glb').isSocket()) throw new Error('sock.glb is no longer a socket');
	process.exit(0);
};
setTimeout(() => { console.error('no connection: the socket was replaced?'); process.exit(1); }, 60000).unref();
const srv = net.createServer((c) => {
	c.on('data', (d) => chunks.push(d));
	c.on('end', () => { ended = true; done(); });
});
srv.listen('sock.glb', () => {
	const p = cp.spawn(`${process.env.BIN}/mlod-bgm`, ['-o', 'sock.glb', `${process.env.ROOT}/samples/tubeman.glb`],
	                   {stdio: 'inherit'});
	p.on('exit', (c) => { code = c; if (c !== 0) { console.error(`mlod-bgm exited ${c}`); process.exit(1); } done(); });
});
JS
# A symbolic link: its target is replaced, the link stays a link.
mkdir sub
printf 'old' > sub/target.glb
ln -s sub/target.glb link.glb
"$BIN/mlod-bgm" -o link.glb "$ROOT/samples/tubeman.glb"
test -L link.glb
test "$(readlink link.glb)" = sub/target.glb
cmp plain.glb sub/target.glb
test "$(ls -A sub | grep -c '\.tmp\.')" -eq 0
# A dangling link is refused and left as it is.
ln -s nowhere/x.glb dangling.glb
if "$BIN/mlod-bgm" -o dangling.glb "$ROOT/samples/tubeman.glb" 2> err.txt; then exit 1; fi
grep -qx 'mlod-bgm: dangling.glb: symbolic link to nothing that can be written (No such file or directory)' err.txt
test -L dangling.glb
# -o /dev/stdout with stdout redirected to a file: written through the
# descriptor, after what the shell wrote there, and before what follows
# (never the file replaced by name, which would lose HEAD and TAIL).
{ echo HEAD; "$BIN/mlod-bgm" -o /dev/stdout "$ROOT/samples/tubeman.glb"; echo TAIL; } > mixed.out
{ echo HEAD; cat plain.glb; echo TAIL; } > mixed.want
cmp mixed.want mixed.out
# A FIFO whose reader goes away early: exit 4 with a message, not SIGPIPE.
head -c 10 pipe.glb > /dev/zero &
reader=$!
set +e
"$BIN/mlod-bgm" -o pipe.glb "$ROOT/samples/tubeman.glb" 2> early.txt
code=$?
set -e
wait $reader
[ "$code" -eq 4 ] || { echo "reader gone early: exit $code, want 4" >&2; cat early.txt >&2; exit 1; }
grep -qx 'mlod-bgm: pipe.glb: write error: Broken pipe' early.txt || { cat early.txt >&2; exit 1; }
