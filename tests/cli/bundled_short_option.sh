# An unknown short option, alone or inside a bundle, is named by its letter
# (it was reported as the program's name or the argument before it); a
# missing value names the option that lacks it. Each tool exits 1.
bad() {
	"$BIN/$@" cmu_12_01_walk.bvh 2> err.txt > /dev/null
	rc=$?
	head -n 1 err.txt >&2
	test $rc = 1 || echo "exit $rc" >&2
}
cp "$ROOT/samples/cmu_12_01_walk.bvh" .
bad mlod-label -j1
bad mlod-motion -e 1% -Fj 2
bad mlod-skelgraph -Zr
bad mlod-bgm -bq
bad mlod-pack -Z
bad mlod-motion -e
"$BIN/mlod-motion" -Fe 2> err.txt
head -n 1 err.txt >&2
"$BIN/mlod-label" -o 2> err.txt
head -n 1 err.txt >&2
