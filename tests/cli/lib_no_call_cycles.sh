# No file of the library calls a function of a file that calls back into
# it, and no part (core, model, io, ...) another that calls back:
# scripts/check-call-cycles on this build's objects. The checker must also
# catch a crafted cycle between two object files (in two parts), so that
# this test can fail.
set -e
"$ROOT/scripts/check-call-cycles" "$BIN/../lib" > /dev/null
mkdir -p crafted/one crafted/two
printf 'int two_fn(void);\nint one_fn(void) { return two_fn(); }\n' > one.c
printf 'int one_fn(void);\nint two_fn(void) { return one_fn() + 1; }\n' > two.c
${CC:-cc} -c one.c -o crafted/one/one.o
${CC:-cc} -c two.c -o crafted/two/two.o
if "$ROOT/scripts/check-call-cycles" crafted > out 2> err; then
	echo "a crafted cycle was not caught" >&2
	exit 1
fi
grep -q 'files under crafted call each other' err
grep -q 'parts under crafted call each other' err
grep -q 'one/one.o' err
grep -q 'two/two.o' err
