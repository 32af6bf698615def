mlod-pack: less\.mlod: MESH level 0: 4860 vertices, more than INFO's max_vertex_count 4859 \(the largest level's\)
mlod-pack: less\.mlod: MESH level 0: 4860 vertices, more than INFO's max_vertex_count 4859 \(the largest level's\)
mlod-pack: more\.mlod: INFO: max_vertex_count 4861, but the largest MESH level has 4860 vertices
mlod-pack: more\.mlod: INFO: max_vertex_count 4861, but the largest MESH level has 4860 vertices
mlod-pack: huge\.mlod: INFO: max_vertex_count 1000000000 is more than its 5 MESH levels can hold \([0-9]+ vertices at most\)
mlod-pack: huge\.mlod: INFO: max_vertex_count 1000000000 is more than its 5 MESH levels can hold \([0-9]+ vertices at most\)
