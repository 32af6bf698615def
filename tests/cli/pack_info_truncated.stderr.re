mlod-pack: cut\.mlod: (SKELETON|MESH|MOTION|INFO|DOC)[^:]*: truncated: .*
mlod-pack: cut\.mlod: (SKELETON|MESH|MOTION|INFO|DOC)[^:]*: truncated: .*
