mlod-pack: bad\.mlod: (SKELETON|MESH|MOTION) level [0-9]+( of clip [0-9]+)?: CRC mismatch \(stored 0x[0-9a-f]+, computed 0x[0-9a-f]+\)
mlod-pack: bad\.mlod: (SKELETON|MESH|MOTION) level [0-9]+( of clip [0-9]+)?: CRC mismatch \(stored 0x[0-9a-f]+, computed 0x[0-9a-f]+\)
