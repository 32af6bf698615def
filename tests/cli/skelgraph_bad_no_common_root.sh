# A skin over two separate hierarchies is a documented repair: two roots, and a note.
set -e
"$BIN/mlod-skelgraph" --report "$ROOT/tests/data/bad/no_common_root.gltf" > report.txt
grep -q '^# note: .*no common root' report.txt
