mlod-pack: j1000\.mlod: INFO: 1000 joints and 1 skins, but SKELETON has 31 and 1
mlod-pack: j0\.mlod: INFO: 0 joints and 1 skins, but SKELETON has 31 and 1
mlod-pack: i2\.mlod: INFO: 2 instances, but MESH level 4 has 1 parts
mlod-pack: fd0\.mlod: INFO: first_drawable 0, but INFO, SKELETON and the coarsest levels end at byte [0-9]+
mlod-pack: j1000\.mlod: INFO: 1000 joints and 1 skins, but SKELETON has 31 and 1
mlod-pack: i2\.mlod: INFO: 2 instances, but MESH level 4 has 1 parts
