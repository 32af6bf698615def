# make clean removes the builds but not build/deps, the OpenMesh headers
# scripts/install-deps unpacks there (only install-deps puts them back:
# after `make clean` the unit tests could not build; a new-user probe).
# make -n: what it would run, without removing the tree under test.
set -e
cmd=$(make -s -n -C "$ROOT" clean)
case "$cmd" in
*build/deps*|*"rm -rf build"|*"rm -rf build "*) echo "make clean would run: $cmd" >&2; exit 1 ;;
esac
case "$cmd" in
*build/release*) ;;
*) echo "make clean would not remove build/release: $cmd" >&2; exit 1 ;;
esac
