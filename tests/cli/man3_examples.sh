# Every EXAMPLES block of the runtime's man3 pages is a complete C11
# translation unit that compiles against the header, warning-free under
# -Wall -Wextra -Wpedantic (a new-user probe, issue 12, found the examples
# to be fragments: statements outside any function, undeclared variables,
# a continue outside a loop). The blocks are the .Bd -literal ... .Ed
# between ".Sh EXAMPLES" and the next .Sh, with the roff escapes \e and \&
# undone. At least the two pages that have one must give a block.
set -e
n=0
for page in "$ROOT"/man/man3/*.3; do
	base=$(basename "$page" .3)
	awk -v out="$base" '
		/^\.Sh / { ex = ($2 == "EXAMPLES"); next }
		ex && /^\.Bd -literal/ { k++; f = out "_" k ".c"; inb = 1; next }
		inb && /^\.Ed/ { inb = 0; close(f); next }
		inb { gsub(/\\&/, ""); gsub(/\\e/, "\\"); print > f }
	' "$page"
done
for c in *.c; do
	[ -f "$c" ] || continue
	cc -std=c11 -Wall -Wextra -Wpedantic -Werror -I"$ROOT/lib/core" -I"$ROOT/lib/rt" -c "$c" -o "${c%.c}.o" ||
		{ echo "$c: the EXAMPLES block does not compile" >&2; exit 1; }
	n=$((n + 1))
done
test -f mlod_rt_1.c && test -f mlod_rt_info_1.c
test "$n" -ge 2
