# A triangle list's attributes a part does not store (_ID, any other
# custom name, a second colour set) went silently: --report notes each,
# naming the mesh and primitive (the attributes sorted by name, as lib/io
# lists them), after the reader's own note on COLOR_1, and each is a
# warning on stderr with or without --report (they were in the report
# only). A standard input has no such note.
set -e
node "$ROOT/tests/glb-edit.mjs" "$ROOT/samples/tubeman.glb" custom.glb \
	'const a = j.meshes[0].primitives[0].attributes; a._ID = a.POSITION; a.FOO = a.POSITION; a.COLOR_1 = a.POSITION;'
"$BIN/mlod-pack" --report custom.glb -o custom.mlod > report.txt 2> /dev/null
grep -q -F '# note: mesh 0 primitive 0: attribute "COLOR_1" is not decoded (sets are numbered from 0, JOINTS_n with WEIGHTS_n, at most 8); mesh 0 primitive 0: attribute "COLOR_1" is not stored in the pack; mesh 0 primitive 0: attribute "FOO" is not stored in the pack; mesh 0 primitive 0: attribute "_ID" is not stored in the pack' report.txt
"$BIN/mlod-pack" --report=json custom.glb -o custom.mlod > report.json 2> /dev/null
grep -q -F '"notes": "mesh 0 primitive 0: attribute \"COLOR_1\" is not decoded (sets are numbered from 0, JOINTS_n with WEIGHTS_n, at most 8); mesh 0 primitive 0: attribute \"COLOR_1\" is not stored in the pack; mesh 0 primitive 0: attribute \"FOO\" is not stored in the pack; mesh 0 primitive 0: attribute \"_ID\" is not stored in the pack' report.json
"$BIN/mlod-pack" custom.glb -o custom2.mlod 2> stderr.txt
cat > want.txt <<'EOF'
mlod-pack: custom.glb: mesh 0 primitive 0: attribute "COLOR_1" is not decoded (sets are numbered from 0, JOINTS_n with WEIGHTS_n, at most 8)
mlod-pack: custom.glb: mesh 0 primitive 0: attribute "COLOR_1" is not stored in the pack
mlod-pack: custom.glb: mesh 0 primitive 0: attribute "FOO" is not stored in the pack
mlod-pack: custom.glb: mesh 0 primitive 0: attribute "_ID" is not stored in the pack
EOF
cmp want.txt stderr.txt
"$BIN/mlod-pack" --report "$ROOT/samples/tubeman.glb" -o plain.mlod > plain.txt
if grep -q 'is not stored in the pack' plain.txt; then exit 1; fi
