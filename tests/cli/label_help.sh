set -e
"$BIN/mlod-label" --help | grep -q '^usage: mlod-label'
"$BIN/mlod-label" --version | grep -q '^mlod-label (mlod) '
