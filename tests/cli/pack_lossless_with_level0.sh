# --lossless-motion and --motion-level0-error are alternatives (synopsis).
"$BIN/mlod-pack" --lossless-motion --motion-level0-error 0.1% -o x.mlod "$ROOT/samples/tubeman.glb"
