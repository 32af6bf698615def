mlod-pack: bad\.mlod: TOC entry 5 \(MESH level 0\): raw size 721422752 is more than 64 times its 2724-byte container \(the stream codecs expand no more\)
