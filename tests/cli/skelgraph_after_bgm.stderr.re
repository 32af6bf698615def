mlod-skelgraph: <stdin>: the input.s 1 mesh level\(s\) stay in MSFT_lod, weighted on the full skeleton; run mlod-skelgraph before mlod-bgm for mesh levels on the skeleton levels
