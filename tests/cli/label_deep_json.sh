# JSON nested deeper than 100 levels is valid JSON that mlod does not
# handle (tinygltf converts it recursively): unsupported, exit 3, not
# malformed input (exit 2).
node -e '
process.stdout.write("{\"asset\":{\"version\":\"2.0\"},\"extras\":" + "[".repeat(200) + "]".repeat(200) + "}");
' > deep.gltf
"$BIN/mlod-label" deep.gltf
