set -e
"$BIN/mlod-pack" --help | grep -q "^usage: mlod-pack"
"$BIN/mlod-pack" --help | grep -q -- "--motion-max-error"
"$BIN/mlod-pack" --version | grep -q "^mlod-pack (mlod) "
"$BIN/mlod-pack" --help | grep -q -- "--info \\[FILE\\]"
"$BIN/mlod-pack" --help | grep -q -- "-x, --extract \\[FILE\\]"
"$BIN/mlod-pack" --help | grep -q -- "--normal-bits N"
