# bench/crowd --mode all --plot: figure 15 has a column for full detail and
# one per mode (seven series), and each row's frame rates are the same run's
# as the table above it: a mode's rate over full's is that mode's speed-up.
# (The panel once held five series: the sixth and seventh overwrote the
# next row's full detail and the series' names, and 32 sizes crashed.)
set -eu
crowd=$BIN/../bench/crowd
"$BIN/mlod-pack" -o t.mlod "$ROOT/samples/tubeman.glb"
"$crowd" -n 1,2,3,4 -s 0.05 --mode all --no-skin-bench --plot p.png t.mlod > out.txt
sed -n '/^figure 15 /,/^$/p' out.txt > f15.txt
grep -q '^ *N *full *skeleton *alpha *pixels *toc *stale *split$' f15.txt ||
	{ echo "figure 15 columns:"; cat f15.txt; exit 1; } >&2
# the table's speed-ups, one line per N: alpha pixels toc skeleton stale split
awk '$2 == "full" { if (row) print row; row = $1; next }
     row && $1 ~ /^(alpha|pixels|toc|skeleton|stale|split)$/ { sub(/x$/, "", $3); row = row " " $3 }
     /^streaming/ { print row; exit }' out.txt > table.txt
awk 'NR == FNR { for (i = 2; i <= NF; i++) s[$1, i] = $i; next }
     NF == 8 && $1 ~ /^[0-9]+$/ {
	n++
	# figure 15 columns: full skeleton alpha pixels toc stale split; table
	# columns: alpha pixels toc skeleton stale split
	split("4 5 6 3 7 8", col, " ") # the fields of figure 15 row
	for (m = 1; m <= 6; m++) {
		want = s[$1, m + 1]; got = $(col[m]) / $2
		if (got < want * 0.99 - 0.01 || got > want * 1.01 + 0.01) {
			printf "N %s: figure 15 gives %.3fx for table mode %d, the table %sx\n", $1, got, m, want
			bad = 1
		}
	}
     }
     END { if (n != 4) { print "figure 15: " n " rows, not 4"; bad = 1 } exit bad }' table.txt f15.txt >&2 ||
	{ cat f15.txt table.txt; exit 1; } >&2
counts=$(node "$ROOT/tests/cli/crowd_plot.mjs" p.png 1280 560 200,30,30 110,110,110)
for k in $counts; do
	[ "$k" -ge 50 ] || { echo "series pixels (full, split): $counts" >&2; exit 1; }
done
"$crowd" -n "$(seq -s, 1 32)" -s 0.01 --mode all --no-skin-bench --plot p32.png t.mlod > out32.txt
[ "$(sed -n '/^figure 15 /,/^$/p' out32.txt | grep -c '^ *[0-9]')" = 32 ] ||
	{ echo "32 sizes: not 32 rows"; exit 1; } >&2
