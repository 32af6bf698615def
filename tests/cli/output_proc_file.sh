# An existing file whose directory takes no new file (/proc/version: the
# temporary file of the atomic replace cannot be made) names that cause,
# not the file's. Nothing is written: /proc refuses the temporary file.
"$BIN/mlod-bgm" -R 0.5 -o /proc/version "$ROOT/samples/tubeman.glb"
