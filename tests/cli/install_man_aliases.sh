# make install puts a man3 link per function each page names (its NAME's
# .Nm lines), and every mlod page a man page cross-references (.Xr NAME 3)
# is then installed (a new-user probe found "man mlod_rt_update" giving
# "No manual entry": only the 6 group pages were installed).
set -e
make -s -C "$ROOT" install DESTDIR="$PWD/inst" PREFIX=/usr > /dev/null
m=inst/usr/share/man/man3
count=0
for p in "$ROOT"/man/man3/*.3; do
	for n in $(sed -n '/^\.Sh NAME/,/^\.Nd/s/^\.Nm \([A-Za-z0-9_]*\).*/\1/p' "$p"); do
		test -f "$m/$n.3" || { echo "man3 page for $n (${p##*/}) is not installed" >&2; exit 1; }
		grep -q "^\.Nm $n\( ,\)*\$" "$m/$n.3" || { echo "$m/$n.3 does not name $n" >&2; exit 1; }
		count=$((count + 1))
	done
done
test "$count" -ge 50
for x in $(grep -ho 'Xr mlod[a-z_0-9]* 3' "$ROOT"/man/man*/* | sort -u | cut -d' ' -f2); do
	test -f "$m/$x.3" || { echo "$x(3) is cross-referenced but not installed" >&2; exit 1; }
done
