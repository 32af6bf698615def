#!/bin/sh
# tests/run.sh: runs mlod's whole test suite and ends with "N passed, N failed".
#
#   tests/run.sh --build build/release [--sanitize-build build/sanitize] [--extended]
#
# Stages:
#   unit       every build/<config>/tests/test_* program (one PASS/FAIL line per test)
#   cli        tests/cli/NAME.sh, checked against NAME.exit and NAME.stderr
#   validate   glb written by the tools, checked by the Khronos glTF validator
#   sanitize   the unit tests again, built with ASan and UBSan
# --extended also feeds ../shared/data (when present) to every stage.
set -u

build=build/release
san=
extended=0
while [ $# -gt 0 ]; do
	case $1 in
	--build) build=$2; shift ;;
	--sanitize-build) san=$2; shift ;;
	--extended) extended=1 ;;
	*) echo "usage: tests/run.sh --build DIR [--sanitize-build DIR] [--extended]" >&2; exit 1 ;;
	esac
	shift
done

root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root" || exit 1
export LC_ALL=C
if [ $extended = 1 ] && [ -d ../shared/data ]; then
	MLOD_SHARED_DATA=$(cd ../shared/data && pwd)
	export MLOD_SHARED_DATA
else
	unset MLOD_SHARED_DATA
fi

work=$(mktemp -d "${TMPDIR:-/tmp}/mlod-test.XXXXXX")
trap 'rm -rf "$work"' EXIT INT TERM
passed=0
failed=0
failures=

pass() { passed=$((passed + 1)); echo "PASS $1"; }
fail() { failed=$((failed + 1)); failures="$failures
  $1"; echo "FAIL $1${2:+: $2}"; }

# Runs the unit test programs in dir; counts their PASS/FAIL lines.
run_unit() {
	stage=$1 dir=$2
	for t in "$dir"/tests/test_*; do
		[ -x "$t" ] || continue
		name=$(basename "$t")
		out=$("$t" 2>"$work/stderr"; echo "rc=$?")
		rc=${out##*rc=}
		echo "$out" | grep -E '^(PASS|FAIL) ' > "$work/lines"
		while IFS= read -r line; do
			case $line in
			PASS\ *) pass "$stage/$name/${line#PASS }" ;;
			FAIL\ *) l=${line#FAIL }; fail "$stage/$name/${l%%:*}" "${l#*: }" ;;
			esac
		done < "$work/lines"
		if [ "$rc" != 0 ] && ! grep -q '^FAIL ' "$work/lines"; then
			fail "$stage/$name" "exited $rc without a FAIL line: $(tail -n 5 "$work/stderr")"
		elif [ "$rc" = 0 ] && grep -q '^FAIL ' "$work/lines"; then
			fail "$stage/$name" "reported FAIL but exited 0"
		fi
	done
}

echo "== unit ($build)"
run_unit unit "$build"

echo "== cli"
BIN=$root/$build/bin
HELPERS=$root/$build/tests/helpers
export BIN HELPERS
for t in tests/cli/*.sh; do
	[ -f "$t" ] || continue
	name=$(basename "$t" .sh)
	expect_rc=0
	[ -f "tests/cli/$name.exit" ] && expect_rc=$(cat "tests/cli/$name.exit")
	mkdir -p "$work/cli/$name"
	( cd "$work/cli/$name" && ROOT=$root sh "$root/$t" ) > "$work/cli/$name/.stdout" 2> "$work/cli/$name/.stderr" < /dev/null
	rc=$?
	if [ "$rc" != "$expect_rc" ]; then
		fail "cli/$name" "exit $rc, expected $expect_rc; stderr: $(head -c 400 "$work/cli/$name/.stderr")"
	elif [ -f "tests/cli/$name.stderr" ] && ! cmp -s "tests/cli/$name.stderr" "$work/cli/$name/.stderr"; then
		fail "cli/$name" "stderr differs: $(diff "tests/cli/$name.stderr" "$work/cli/$name/.stderr" | head -n 6 | tr '\n' ' ')"
	else
		pass "cli/$name"
	fi
done

echo "== validate"
validator="node tests/validate.mjs"
# The tools whose default output is a glb.
glb_tools="mlod-label mlod-skelgraph mlod-bgm mlod-motion"
inputs="samples/*.glb samples/*.bvh"
[ -n "${MLOD_SHARED_DATA:-}" ] && inputs="$inputs $MLOD_SHARED_DATA/*.glb $MLOD_SHARED_DATA/*.bvh"
if [ ! -d tests/node/node_modules/gltf-validator ]; then
	fail "validate" "gltf-validator is not installed (run scripts/install-deps)"
else
	for f in $inputs; do
		[ -f "$f" ] || continue
		base=$(basename "$f")
		# The shim itself: read and write back, and rebuild from the character.
		for mode in "" --via-character; do
			out="$work/validate-roundtrip$mode-$base.glb"
			case $f in *.bvh) continue ;; esac
			if ! "$HELPERS/roundtrip" $mode "$f" "$out" 2> "$work/stderr"; then
				fail "validate/roundtrip$mode/$base" "$(head -c 300 "$work/stderr")"
			elif msg=$($validator "$out" 2>&1); then
				pass "validate/roundtrip$mode/$base"
			else
				fail "validate/roundtrip$mode/$base" "$(echo "$msg" | head -n 8 | tr '\n' ' ')"
			fi
		done
		for tool in $glb_tools; do
			[ -x "$BIN/$tool" ] || continue
			out="$work/validate-$tool-$base.glb"
			split=
			# mlod-bgm also writes one glb per level (--split): each must validate.
			if [ $tool = mlod-bgm ]; then
				split="$work/split-$base"
				mkdir -p "$split"
			fi
			if ! "$BIN/$tool" ${split:+--split "$split"} "$f" > "$out" 2> "$work/stderr"; then
				fail "validate/$tool/$base" "$tool failed: $(head -c 300 "$work/stderr")"
			elif msg=$($validator "$out" 2>&1); then
				pass "validate/$tool/$base"
			else
				fail "validate/$tool/$base" "$(echo "$msg" | head -n 8 | tr '\n' ' ')"
			fi
			for lod in ${split:+"$split"/*.glb}; do
				[ -f "$lod" ] || continue
				if msg=$($validator "$lod" 2>&1); then
					pass "validate/$tool-split/$(basename "$lod")"
				else
					fail "validate/$tool-split/$(basename "$lod")" "$(echo "$msg" | head -n 8 | tr '\n' ' ')"
				fi
			done
		done
	done
fi

echo "== man"
for src in tools/mlod-*.c; do
	t=$(basename "$src" .c)
	page=man/man1/$t.1
	if [ ! -f "$page" ]; then
		fail "man/$t" "no man page $page"
	elif ! command -v mandoc >/dev/null 2>&1; then
		fail "man/$t" "mandoc is not installed (run scripts/install-deps)"
	elif msg=$(mandoc -T lint -W warning "$page" 2>&1) && [ -z "$msg" ]; then
		pass "man/$t"
	else
		fail "man/$t" "$(echo "$msg" | head -n 3 | tr '\n' ' ')"
	fi
done
for page in man/man5/*.5; do
	[ -f "$page" ] || continue
	if msg=$(mandoc -T lint -W warning "$page" 2>&1) && [ -z "$msg" ]; then
		pass "man/$(basename "$page")"
	else
		fail "man/$(basename "$page")" "$(echo "$msg" | head -n 3 | tr '\n' ' ')"
	fi
done

if [ -n "$san" ]; then
	echo "== sanitize ($san)"
	ASAN_OPTIONS=detect_leaks=1:abort_on_error=0 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
	export ASAN_OPTIONS UBSAN_OPTIONS
	run_unit sanitize "$san"
fi

if [ $failed -gt 0 ]; then
	printf '\nFailures:%s\n' "$failures"
fi
echo "$passed passed, $failed failed"
[ $failed = 0 ]
