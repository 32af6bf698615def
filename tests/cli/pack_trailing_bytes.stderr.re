mlod-pack: w\.mlod: 1 bytes after the pack's end \(byte [0-9]+\), which no CRC covers
mlod-pack: w\.mlod: 1 bytes after the pack's end \(byte [0-9]+\), which no CRC covers
