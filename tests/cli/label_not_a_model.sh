printf 'hello, world\n' > text.txt
"$BIN/mlod-label" text.txt
