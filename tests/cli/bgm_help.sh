set -e
"$BIN/mlod-bgm" --help | grep -q '^usage: mlod-bgm'
"$BIN/mlod-bgm" --version | grep -q '^mlod-bgm (mlod) '
