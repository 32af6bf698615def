#!/bin/sh
# tests/run.sh: runs mlod's whole test suite and ends with the line
# "N passed, N failed, N skipped".
#
#   tests/run.sh --build build/release [--sanitize-build build/sanitize]
#                [--nodraco-build build/release-nodraco] [--extended]
#
# Stages:
#   unit       every build/<config>/tests/test_* program and every runtime
#              test program build/<config>/tests/rt/* (one PASS/FAIL/SKIP
#              line per test); every tests/unit/test_*.c and tests/rt/*.c
#              must be built
#   cli        tests/cli/NAME.sh, checked against NAME.exit and NAME.stderr
#              or NAME.stderr.re (below)
#   validate   glb written by the tools, checked by the Khronos glTF validator
#   sanitize   the unit and runtime tests again, built with ASan and UBSan
#   nodraco    the runtime tests again, on a runtime built without its
#              Draco decode (make MLOD_DRACO=0 rt-unit)
# The unit tests that need ../shared/data get it whenever it is present;
# --extended also feeds it to every CLI stage. Its absolute path is exported
# as MLOD_SHARED_DATA. A MLOD_SHARED_DATA already set names another directory
# instead (relative to the repository root); a missing one counts as absent
# (MLOD_SHARED_DATA=/nonexistent shows the SKIPs).
#
# SKIP: a test that needs ../shared/data and does not have it says so
# instead of passing. A unit test prints "SKIP name: reason" (NEED_SHARED()
# in tests/unit/test.h); a CLI script exits 77 (as automake's tests do) with
# the reason as the last line of its stderr. Skipping is only for absent
# data: a SKIP while MLOD_SHARED_DATA is set counts as a failure.
#
# CLI expectations: NAME.exit holds the expected exit code (0 without it).
# NAME.stderr is the exact stderr expected. NAME.stderr.re holds one
# extended regular expression per line of stderr, each matching the whole
# line, for messages with measured numbers or machine-dependent parts. A
# test that expects a non-zero exit must have one of the two: the exit code
# alone does not tell its error from an unknown option or a missing file.
set -u

build=build/release
san=
nodraco=
extended=0
while [ $# -gt 0 ]; do
	case $1 in
	--build) build=$2; shift ;;
	--sanitize-build) san=$2; shift ;;
	--nodraco-build) nodraco=$2; shift ;;
	--extended) extended=1 ;;
	*) echo "usage: tests/run.sh --build DIR [--sanitize-build DIR] [--nodraco-build DIR] [--extended]" >&2; exit 1 ;;
	esac
	shift
done

root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root" || exit 1
export LC_ALL=C
# The unit tests that need ../shared/data run whenever it is present (and
# SKIP, with the reason, where it is absent); --extended also feeds it to
# every CLI stage.
shared=${MLOD_SHARED_DATA:-../shared/data}
if [ -d "$shared" ]; then
	MLOD_SHARED_DATA=$(cd "$shared" && pwd)
	export MLOD_SHARED_DATA
	echo "== shared data: $MLOD_SHARED_DATA"
else
	echo "== shared data: $shared is absent: the tests that need it SKIP"
	unset MLOD_SHARED_DATA
fi

work=$(mktemp -d "${TMPDIR:-/tmp}/mlod-test.XXXXXX")
# A signal ends the run (a trap that returns would go on without $work).
trap 'rm -rf "$work"' EXIT
trap 'exit 130' INT
trap 'exit 143' TERM
passed=0
failed=0
skipped=0
failures=
skips=

pass() { passed=$((passed + 1)); echo "PASS $1"; }
fail() { failed=$((failed + 1)); failures="$failures
  $1"; echo "FAIL $1${2:+: $2}"; }
# A test that could not run: only for absent ../shared/data, with a reason.
skip() {
	if [ -z "$2" ]; then
		fail "$1" "skipped without a reason"
	elif [ -n "${MLOD_SHARED_DATA:-}" ]; then
		fail "$1" "skipped, but ../shared/data is present ($MLOD_SHARED_DATA): $2"
	else
		skipped=$((skipped + 1))
		skips="$skips
  $1: $2"
		echo "SKIP $1: $2"
	fi
}

# Checks stderr ($2) line by line against the whole-line extended regular
# expressions of $1; prints the first mismatch.
stderr_matches() {
	[ -s "$1" ] || { echo "$1 is empty"; return 1; }
	awk 'NR == FNR { re[++n] = $0; next }
	{
		m++
		if (m > n) { print "unexpected line " m ": " $0; bad = 1; exit }
		if ($0 !~ ("^(" re[m] ")$")) { print "line " m ": \"" $0 "\" does not match " re[m]; bad = 1; exit }
	}
	END {
		if (!bad && m < n) { print "missing line " (m + 1) ": " re[m + 1]; bad = 1 }
		exit bad
	}' "$1" "$2"
}

# Runs the unit test programs in dir (with a third argument "rt", the
# runtime's alone); counts their PASS/FAIL/SKIP lines.
run_unit() {
	stage=$1 dir=$2 only=${3:-}
	# A test program that was not built must not go unnoticed.
	for src in tests/unit/test_*.c; do
		[ -f "$src" ] && [ "$only" != rt ] || continue
		name=$(basename "$src" .c)
		[ -x "$dir/tests/$name" ] || fail "$stage/$name" "$dir/tests/$name was not built"
	done
	for src in tests/rt/*.c; do
		[ -f "$src" ] || continue
		name=$(basename "$src" .c)
		[ -x "$dir/tests/rt/$name" ] || fail "$stage/rt/$name" "$dir/tests/rt/$name was not built"
	done
	for t in "$dir"/tests/test_* "$dir"/tests/rt/*; do
		[ -f "$t" ] && [ -x "$t" ] || continue
		case $only:$t in rt:*/tests/test_*) continue ;; esac
		case $t in
		*/tests/rt/*) name=rt/$(basename "$t") src=tests/rt/$(basename "$t").c ;;
		*/tests/test_openmesh) name=$(basename "$t") src=tests/openmesh/test_openmesh.cpp ;;
		*) name=$(basename "$t") src=tests/unit/$(basename "$t").c ;;
		esac
		# a program left in the build from a test since renamed or removed
		# (build/ outlives checkouts) is not this tree's test
		[ -f "$src" ] || continue
		out=$("$t" 2>"$work/stderr"; echo "rc=$?")
		rc=${out##*rc=}
		echo "$out" | grep -E '^(PASS|FAIL|SKIP) ' > "$work/lines"
		while IFS= read -r line; do
			case $line in
			PASS\ *) pass "$stage/$name/${line#PASS }" ;;
			FAIL\ *) l=${line#FAIL }; fail "$stage/$name/${l%%:*}" "${l#*: }" ;;
			SKIP\ *:\ *) l=${line#SKIP }; skip "$stage/$name/${l%%:*}" "${l#*: }" ;;
			SKIP\ *) skip "$stage/$name/${line#SKIP }" "" ;;
			esac
		done < "$work/lines"
		if [ "$rc" != 0 ] && ! grep -q '^FAIL ' "$work/lines"; then
			fail "$stage/$name" "exited $rc without a FAIL line: $(tail -n 5 "$work/stderr")"
		elif [ "$rc" = 0 ] && grep -q '^FAIL ' "$work/lines"; then
			fail "$stage/$name" "reported FAIL but exited 0"
		elif [ "$rc" = 0 ] && [ ! -s "$work/lines" ]; then
			fail "$stage/$name" "exited 0 without a PASS, FAIL or SKIP line"
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
	exp=tests/cli/$name
	out=$work/cli/$name
	expect_rc=0
	[ -f "$exp.exit" ] && expect_rc=$(cat "$exp.exit")
	mkdir -p "$out"
	( cd "$out" && ROOT=$root sh "$root/$t" ) > "$out/.stdout" 2> "$out/.stderr" < /dev/null
	rc=$?
	if [ "$rc" = 77 ] && [ "$expect_rc" != 77 ]; then
		skip "cli/$name" "$(tail -n 1 "$out/.stderr")"
	elif [ "$rc" != "$expect_rc" ]; then
		fail "cli/$name" "exit $rc, expected $expect_rc; stderr: $(head -c 400 "$out/.stderr")"
	elif [ -f "$exp.stderr" ] && [ -f "$exp.stderr.re" ]; then
		fail "cli/$name" "both $name.stderr and $name.stderr.re: keep one"
	elif [ -f "$exp.stderr" ]; then
		if cmp -s "$exp.stderr" "$out/.stderr"; then
			pass "cli/$name"
		else
			fail "cli/$name" "stderr differs: $(diff "$exp.stderr" "$out/.stderr" | head -n 6 | tr '\n' ' ')"
		fi
	elif [ -f "$exp.stderr.re" ]; then
		if why=$(stderr_matches "$exp.stderr.re" "$out/.stderr"); then
			pass "cli/$name"
		else
			fail "cli/$name" "stderr does not match $name.stderr.re: $why"
		fi
	elif [ "$expect_rc" != 0 ]; then
		fail "cli/$name" "expects exit $expect_rc but has no $name.stderr or $name.stderr.re: the message is not checked"
	else
		pass "cli/$name"
	fi
done
# An expectation without its script would never be checked.
for f in tests/cli/*.exit tests/cli/*.stderr tests/cli/*.stderr.re; do
	[ -f "$f" ] || continue
	name=$(basename "$f")
	name=${name%.exit}
	name=${name%.re}
	name=${name%.stderr}
	[ -f "tests/cli/$name.sh" ] || fail "cli/$name" "$f has no script tests/cli/$name.sh"
done

echo "== validate"
validator="node tests/validate.mjs"
# The tools whose default output is a glb.
glb_tools="mlod-label mlod-skelgraph mlod-bgm mlod-motion"
inputs="samples/*.glb samples/*.bvh"
[ $extended = 1 ] && [ -n "${MLOD_SHARED_DATA:-}" ] && inputs="$inputs $MLOD_SHARED_DATA/*.glb $MLOD_SHARED_DATA/*.bvh"
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
			if [ ! -x "$BIN/$tool" ]; then
				fail "validate/$tool/$base" "$BIN/$tool was not built"
				continue
			fi
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
for page in man/man3/*.3 man/man5/*.5; do
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

if [ -n "$nodraco" ]; then
	echo "== nodraco ($nodraco)"
	run_unit nodraco "$nodraco" rt
fi

if [ $skipped -gt 0 ]; then
	printf '\nSkipped:%s\n' "$skips"
fi
if [ $failed -gt 0 ]; then
	printf '\nFailures:%s\n' "$failures"
fi
echo "$passed passed, $failed failed, $skipped skipped"
[ $failed = 0 ]
