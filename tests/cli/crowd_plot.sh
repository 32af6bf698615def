# bench/crowd --plot: the paper's Figures 15 and 16 as data and as a PNG
# line plot (1280x560): a row per N in figure 15 (full, skeleton, alpha),
# a row per mesh level in figure 16, and in the picture the lines of full
# (red), skeleton (orange), alpha (green) and figure 16 (blue).
set -eu
crowd=$BIN/../bench/crowd
"$BIN/mlod-pack" -o t.mlod "$ROOT/samples/tubeman.glb"
"$crowd" -n 1,10,40 -s 0.1 --mode alpha --no-skin-bench --plot p.png t.mlod > out.txt
grep -q '^figure 15 ' out.txt || { echo "no figure 15:"; cat out.txt; exit 1; } >&2
sed -n '/^figure 15 /,/^$/p' out.txt > f15.txt
grep -q '^ *N *full *skeleton *alpha$' f15.txt || { echo "figure 15 columns:"; cat f15.txt; exit 1; } >&2
[ "$(grep -c '^ *[0-9][0-9]* *[0-9.]* *[0-9.]* *[0-9.]*$' f15.txt)" = 3 ] || { echo "figure 15 rows:"; cat f15.txt; exit 1; } >&2
levels=$(sed -n 's/.*levels: skeleton [0-9]*, mesh \([0-9]*\),.*/\1/p' out.txt)
sed -n '/^figure 16 /,$p' out.txt > f16.txt
[ "$(grep -c '^ *[0-9][0-9]* *[0-9][0-9]* *[0-9][0-9]* *[0-9.]* *[0-9]* *[0-9.]*x$' f16.txt)" = "$levels" ] ||
	{ echo "figure 16: not one row per mesh level ($levels):"; cat f16.txt; exit 1; } >&2
# fewer triangles at each coarser level
awk '/^ *[0-9]+ +[0-9]+ +[0-9]+ +[0-9.]+ +[0-9]+ +[0-9.]+x$/ { if (n++ && $2 >= last) bad = 1; last = $2 } END { exit bad }' f16.txt ||
	{ echo "figure 16: triangles not decreasing:"; cat f16.txt; exit 1; } >&2
grep -q '^plot: p.png, 1280x560' out.txt || { echo "no plot line:"; cat out.txt; exit 1; } >&2
counts=$(node "$ROOT/tests/cli/crowd_plot.mjs" p.png 1280 560 200,30,30 235,140,20 40,150,60 40,90,200)
for k in $counts; do
	[ "$k" -ge 50 ] || { echo "series pixels (full, skeleton, alpha, figure 16): $counts" >&2; exit 1; }
done
