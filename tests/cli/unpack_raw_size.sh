# mlod-pack -x on a pack found by make fuzz (tests/fuzz/regress/pack): CRC
# valid, but its MESH level 0 says 721 MB raw for 2724 stored bytes. It
# used to allocate the 721 MB; now a parse error naming the chunk.
cp "$ROOT/tests/fuzz/regress/pack/oom-toc-raw-size.mlod" bad.mlod
"$BIN/mlod-pack" -x bad.mlod -o out.glb
