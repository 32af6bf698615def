# A triangle list's attributes a part does not store (_ID, any other
# custom name, a second colour set) went silently: --report notes each,
# naming the mesh and primitive (the attributes sorted by name, as lib/io
# lists them; the reader's notes come first: COLOR_1 is not decoded). A
# standard input has no such note.
set -e
node "$ROOT/tests/glb-edit.mjs" "$ROOT/samples/tubeman.glb" custom.glb \
	'const a = j.meshes[0].primitives[0].attributes; a._ID = a.POSITION; a.FOO = a.POSITION; a.COLOR_1 = a.POSITION;'
"$BIN/mlod-pack" --report custom.glb -o custom.mlod > report.txt
grep -q -F 'mesh 0 primitive 0: attribute COLOR_1 is not stored in the pack; mesh 0 primitive 0: attribute FOO is not stored in the pack; mesh 0 primitive 0: attribute _ID is not stored in the pack' report.txt
"$BIN/mlod-pack" --report=json custom.glb -o custom.mlod > report.json
grep -q -F 'mesh 0 primitive 0: attribute COLOR_1 is not stored in the pack; mesh 0 primitive 0: attribute FOO is not stored in the pack; mesh 0 primitive 0: attribute _ID is not stored in the pack' report.json
"$BIN/mlod-pack" --report "$ROOT/samples/tubeman.glb" -o plain.mlod > plain.txt
if grep -q 'is not stored in the pack' plain.txt; then exit 1; fi
