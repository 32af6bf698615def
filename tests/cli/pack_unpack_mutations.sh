# Truncated prefixes and single-byte changes of a sample pack: --info and
# -x exit 2 every time (never a crash, never 0), and -x writes nothing.
# (The same loop was run by hand over the sanitizer build.)
set -u
"$BIN/mlod-pack" "$ROOT/samples/tubeman.glb" -o t.mlod 2> /dev/null || exit 9
size=$(wc -c < t.mlod | tr -d ' ')
i=0
while [ $i -lt 60 ]; do
	i=$((i + 1))
	head -c $(( (i * 6823 + 17) % size )) t.mlod > m.mlod
	for mode in --info -x; do
		o=; [ $mode = -x ] && o="-o m.glb" # --info prints to stdout only
		"$BIN/mlod-pack" $mode m.mlod $o > /dev/null 2> m.err
		rc=$?
		[ $rc = 2 ] || { echo "truncated at $(wc -c < m.mlod): $mode exited $rc: $(cat m.err)" >&2; exit 9; }
	done
	cp t.mlod m.mlod
	printf "\\$(printf %o $(( (i * 37 + 1) % 256 )))" | dd of=m.mlod bs=1 seek=$(( (i * 6661 + 5) % size )) conv=notrunc 2> /dev/null
	cmp -s m.mlod t.mlod && continue
	for mode in --info -x; do
		rm -f m.glb
		o=; [ $mode = -x ] && o="-o m.glb" # --info prints to stdout only
		"$BIN/mlod-pack" $mode m.mlod $o > /dev/null 2> m.err
		rc=$?
		[ $rc = 2 ] && [ ! -e m.glb ] || { echo "byte $(( (i * 6661 + 5) % size )) changed: $mode exited $rc: $(cat m.err)" >&2; exit 9; }
	done
done
