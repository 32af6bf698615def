# --help and --version print on stdout and exit 0, with nothing on stderr
# (a pipe into grep would hide a failing exit code).
set -e
"$BIN/mlod-bgm" --help > help.txt 2> help.err
grep -q '^usage: mlod-bgm' help.txt
test ! -s help.err
"$BIN/mlod-bgm" --version > version.txt 2> version.err
grep -qx 'mlod-bgm (mlod) [0-9][0-9.]*' version.txt
test ! -s version.err
