# Reading glTF is linear in the length of its arrays: a glb with 300,000
# empty nodes more than tubeman (a 1.5 MB file) is read and written back in
# 0.5 s of CPU (measured on the 2-core test machine, loaded). The JSON depth
# limit used to be a callback of nlohmann's parser, which rescans the
# enclosing array at every closing object: 40,000 nodes took 3.8 s of CPU and
# 300,000 did not finish in 120 s. The CPU limit below is a hang guard, not
# a timing assertion: it is 40 times the linear reader's time, and the
# quadratic reader needs about 200 s (ten times the limit), so no machine
# slow enough to fail a linear reader passes a quadratic one.
set -e
node "$ROOT/tests/glb-edit.mjs" "$ROOT/samples/tubeman.glb" many.glb \
	'for (let i = 0; i < 300000; i++) j.nodes.push({});'
(ulimit -t 20 && "$BIN/mlod-label" -o out.glb many.glb)
node -e '
const b = require("fs").readFileSync("out.glb");
const j = JSON.parse(b.subarray(20, 20 + b.readUInt32LE(12)).toString("utf8"));
const a = require("fs").readFileSync(process.argv[1]);
const k = JSON.parse(a.subarray(20, 20 + a.readUInt32LE(12)).toString("utf8"));
if (j.nodes.length !== k.nodes.length + 300000) throw new Error(`${j.nodes.length} nodes`);
' "$ROOT/samples/tubeman.glb"
