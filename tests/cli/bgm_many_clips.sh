# Past 16 clips the mesh layer's training and measuring poses come from 16
# of them, evenly spaced: every pose holds a posed copy of the mesh, and
# 100 clips made 209 measuring poses (839 MB at 50k triangles; a scale
# probe). The robot with its 14 clips twice over (28): 1 rest pose + 16
# clips x 2 frames + 8 random = 41 measuring poses (57 before), with a
# note; the robot's own 14 clips keep 37.
set -e
node "$ROOT/tests/glb-edit.mjs" "$ROOT/samples/RobotExpressive.glb" many.glb \
	'const n = j.animations.length; for (let i = 0; i < n; i++) { const a = JSON.parse(JSON.stringify(j.animations[i])); a.name += "_copy"; j.animations.push(a); }'
"$BIN/mlod-bgm" --report many.glb > many.txt
grep -q 'error over 41 poses' many.txt
grep -q '^# note: 28 clips: the posed cost and the measures take the frames of 16 of them, evenly spaced' many.txt
"$BIN/mlod-bgm" --report "$ROOT/samples/RobotExpressive.glb" > robot.txt
grep -q 'error over 37 poses' robot.txt
if grep -q 'evenly spaced' robot.txt; then exit 1; fi
