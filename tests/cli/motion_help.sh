set -e
"$BIN/mlod-motion" --help | grep -q "^usage: mlod-motion"
"$BIN/mlod-motion" --version | grep -q "^mlod-motion (mlod) "
