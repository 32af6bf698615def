# INFO's max_vertex_count (format 8.1): mlod-pack --info prints the
# largest mesh level's vertices and --json its max_vertex_count, the
# runtime's largest mlod_rt_mesh_vertex_count (tubeman's 4860 in the
# per-level line of bench/crowd); an 8.0 pack (the field 0 and the
# version 8.0, CRCs made to match: what 8.0's mlod-pack wrote) says "not
# stated" and null, and still unpacks. (That one is of the tubeman with
# one key per sampler, whose MOTION bytes read the same in 8.0 as in 9.0,
# which predicts a channel's later keys: its coarsest level has 317
# vertices, the walk's tubeman 312.) A pack whose INFO says one vertex
# fewer than its largest level, or one more, or more than its MESH chunks
# hold, is refused by --info and -x (exit 2) with a message naming it.
"$BIN/mlod-pack" --entropy none "$ROOT/samples/tubeman.glb" -o t.mlod 2> /dev/null || exit 9
"$BIN/mlod-pack" --info t.mlod > t.txt || exit 9
grep -q '^# largest mesh level: 4860 vertices$' t.txt || exit 9
"$BIN/mlod-pack" --info t.mlod --json > t.json || exit 9
grep -q '"max_vertex_count": 4860$' t.json || exit 9
# the bench's largest level as the runtime loads it
"$BIN/../bench/crowd" -n 1 -s 1 --max-wall 0.1 --mode alpha t.mlod > crowd.txt 2> /dev/null || exit 9
grep -q '^vertices skinned per mesh level: 4860 ' crowd.txt || exit 9
grep -q '^skinning buffers: 4860 vertices, sized once at open' crowd.txt || exit 9
edit() { # value, minor version, output[, input, major version]
	python3 "$ROOT/tests/pack-edit.py" "${4:-t.mlod}" "$3" "
e = entry(b'INFO')
struct.pack_into('<I', x, e[7] + 4 + 16 * struct.unpack_from('<I', x, e[7])[0] + 68, $1)
struct.pack_into('<H', x, 4, ${5:-9})
struct.pack_into('<H', x, 6, $2)" || exit 9
}
node "$ROOT/tests/glb-edit.mjs" "$ROOT/samples/tubeman.glb" one.glb 'for (const a of j.animations) for (const s of a.samplers) {
	const i = j.accessors[s.input], o = j.accessors[s.output];
	i.count = 1, i.max = i.min.slice(), o.count = 1;
	delete o.max, delete o.min;
}' || exit 9
"$BIN/mlod-pack" --entropy none one.glb -o one.mlod 2> /dev/null || exit 9
edit 0 0 old.mlod one.mlod 8
"$BIN/mlod-pack" --info old.mlod > old.txt || exit 9
grep -q '^# old.mlod: mlod 8\.0, ' old.txt || exit 9
grep -q '^# largest mesh level: not stated (format 8\.0, before 8\.1)$' old.txt || exit 9
"$BIN/mlod-pack" --info old.mlod --json | grep -q '"max_vertex_count": null$' || exit 9
"$BIN/mlod-pack" -x old.mlod -o old.glb 2> /dev/null && [ -s old.glb ] || exit 9
"$BIN/../bench/crowd" -n 1 -s 1 --max-wall 0.1 --mode alpha old.mlod 2> /dev/null |
	grep -q '^skinning buffers: 317 vertices at open, 4860 once every level loaded' || exit 9
edit 4859 1 less.mlod
edit 4861 1 more.mlod
edit 1000000000 1 huge.mlod
for f in less more huge; do
	"$BIN/mlod-pack" --info $f.mlod > /dev/null
	[ $? = 2 ] || exit 9
	"$BIN/mlod-pack" -x $f.mlod -o $f.glb
	[ $? = 2 ] && [ ! -e $f.glb ] || exit 9
done
exit 2
