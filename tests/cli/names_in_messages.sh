# A file's name in a message on stderr is escaped as the reports escape it
# (tool_put_name): a newline or an escape sequence in it cannot break the
# line or drive the terminal; the refusal to write to a terminal names
# <stdout>. Each tool, then a note that goes on (a prop with no joints).
for t in mlod-label mlod-skelgraph mlod-bgm mlod-motion mlod-pack; do
	"$BIN/$t" "$(printf 'a\nb\033[2J.glb')" && exit 9
done
printf 'glTF' > "$(printf 'c\td.glb')"
"$BIN/mlod-label" "$(printf 'c\td.glb')" && exit 9
"$BIN/mlod-pack" -o out.mlod "$(printf 'c\td.glb')" && exit 9
cp "$ROOT/samples/cmu_12_01_walk.bvh" "$(printf 'w\nalk.bvh')"
"$BIN/mlod-bgm" "$(printf 'w\nalk.bvh')" > out.glb
