# A stage record of a newer version than this mlod reads is refused as
# unsupported (exit 3), with both versions named.
node "$ROOT/tests/glb-edit.mjs" "$ROOT/samples/tubeman.glb" new.glb 'j.scenes[0].extras = { mlod: { version: 5 } }'
"$BIN/mlod-bgm" new.glb > out.glb
