head -c 5000 "$ROOT/samples/RobotExpressive.glb" > truncated.glb
"$BIN/mlod-bgm" truncated.glb
