# Clip names with control characters and ANSI escapes reach the terminal
# escaped: in the --report table (C escapes, as the other tools' tables)
# and in the notes and messages on stderr (quoted as JSON strings); they
# were printed raw, so a name could break lines or recolour the terminal.
set -e
node "$ROOT/tests/glb-edit.mjs" "$ROOT/samples/tubeman.glb" in.glb '
j.animations[0].name = "w\nalk\u001b[31mRED";
const a = j.animations[0], s = a.samplers[a.channels[0].sampler];
j.cameras = [{type: "perspective", perspective: {yfov: 1, znear: 0.1}}];
j.nodes.push({name: "cam", camera: 0});
j.scenes[0].nodes.push(j.nodes.length - 1);
j.animations.push({name: "d\nolly\u001b[31m", samplers: [{input: s.input, output: s.output}],
  channels: [{sampler: 0, target: {node: j.nodes.length - 1, path: a.channels[0].target.path}}]});
'
"$BIN/mlod-motion" -e 1% --report in.glb > table 2> err
grep -q '^w\\nalk\\x1b\[31mRED  *0 ' table
grep -q '^d\\nolly\\x1b\[31m  *0 ' table
test "$(grep -c "$(printf '\033')" table)" = 0
cat > want <<'EOF'
mlod-motion: in.glb: clip "d\nolly\u001b[31m" animates no joint and no morph weights: nothing to reduce, no levels (the animation is kept as it is)
EOF
diff want err
test "$(grep -c "$(printf '\033')" err)" = 0
